#!/usr/bin/env bash
# Go on with the three temporal denoisers' stages on a lent GPU for a fixed time, all three
# at once (one process each), from a pack of the training caches: the GPU machine has
# neither the corpus nor the text encoder.
#
#   here:  python -m motion_core.train pack --data data/corpus_real --vae runs/tvae --out .pack/temporal.npz
#   there: bash scripts/train_on_gpu.sh .pack/temporal.npz SECONDS OUTDIR [BATCH]
#
# Each job starts from its committed stage (stages/*_s4.pt, stages/baseline_s2.pt) with the
# stages' recipe (x_0 target, lr 3e-4 held, weight EMA 0.999) at a larger batch, stops after
# SECONDS of steps, and writes its float16 stage file to OUTDIR, with its log. Validation
# runs back here (the verifier needs the text encoder): python -m motion_core.eval ...
set -euo pipefail
pack=$1 secs=$2 out=$3 batch=${4:-256}
py=${PY:-python3}
mkdir -p runs/gpu/vae "$out"
cp stages/vae_temporal.pt runs/gpu/vae/vae.pt
"$py" -c "import torch; print('torch', torch.__version__, torch.cuda.get_device_name() if torch.cuda.is_available() else 'no GPU')"
common=(--pack "$pack" --vae runs/gpu/vae --prediction sample --warmup 0 --decay constant --lr 3e-4
  --batch "$batch" --ema 0.999 --steps 1000000 --save-every 1000000 --time-limit "$secs")
export PYTHONUNBUFFERED=1 OMP_NUM_THREADS=${OMP_NUM_THREADS:-4}
for job in "motion_mamba motion_mamba_s4 motion_mamba_s5" "ftmomamba ftmomamba_s4 ftmomamba_s5" \
  "baseline baseline_s2 baseline_s3"; do
  set -- $job
  "$py" -m motion_core.train "$1" "${common[@]}" --init "stages/$2.pt" --out "runs/gpu/$1" \
    --stage "$out/$3.pt" >"$out/$1.log" 2>&1 &
done
fail=0
for j in $(jobs -p); do wait "$j" || fail=1; done
for f in "$out"/*.log; do echo "== $f"; tr '\r' '\n' <"$f" | grep -v '^\s*$' | tail -3; done
exit $fail
