#!/usr/bin/env bash
# Go on training the temporal denoisers on a lent GPU for a fixed time, all named kinds at
# once (one process each), from a pack of the training caches: the GPU machine has neither
# the corpus nor the text encoder.
#
#   here:  python -m motion_core.train pack --data data/corpus_real --vae runs/tvae --out .pack/temporal.npz
#   there: KINDS="motion_mamba ftmomamba" bash scripts/train_on_gpu.sh .pack/temporal.npz SECONDS OUTDIR [BATCH]
#
# Each job starts from the shipped weights (motion_core/weights/KIND.pt, or stages/KIND.pt
# where a newer unshipped stage is there) with the stages' recipe (x_0 target, lr 3e-4 held,
# weight EMA 0.999) at batch BATCH (256), stops after SECONDS of steps and writes its float16
# stage to OUTDIR/KIND.pt, with its log. Jobs share the GPU (time-sliced: running kinds one
# after another is as fast). Alone on an H200 with the fused Triton scan, a step at 256 takes
# 0.077 s for Motion Mamba and 0.032 s for FTMoMamba (0.23 / 0.20 s with the chunked scan;
# results/train_loop_gpu_h200.json). Validation runs back here (the verifier needs the text encoder):
# MMS_WEIGHTS_DIR at a folder holding the new files, tools/ddim_steps_sweep.py --steps 5 (the shipped sampler's steps).
#
# FROM_SCRATCH=1 starts every kind from fresh weights instead, with WARMUP (500) steps of
# warm-up: the one-recipe comparison (the same latents, batch, schedule, seed and
# steps for every kind). STEPS=N stops each job at N steps (default: only the time limit);
# a denoiser job the time limit stopped short of N fails the script, as the comparison
# needs every kind at N.
#
# INIT_DIR=DIR starts every kind from DIR/KIND.pt instead (the rate held; WARMUP adds one): how the
# one-recipe comparison goes on from its committed stages (stages/one_recipe/), the same for
# every kind. Not with FROM_SCRATCH=1.
#
# TRAIN_FLAGS adds flags to every job (e.g. --tf32, measured first with step-time --tf32).
# VAE (motion_core/weights/vae.pt) and RUNS (runs/gpu) name the VAE the pack was made with
# and where the jobs' states go (the tests run this script on a tiny corpus's pack).
#
# VAL_EVERY=N scores the denoisers every N steps on the validation prompts the pack holds
# (train pack --val-n 200: both sources, pooled, VAL_STEPS guided DDIM steps at the method's scale, 5 as the
# shipped sampler takes, sampled on the GPU) and makes
# the stage the best-scored weights rather than the last (--stage-best); the curve comes
# back as OUTDIR/KIND.curve.json. A score takes some seconds of the limit.
#
# WARMUP=N sets the warm-up steps: 500 by default from fresh weights, none by default when a
# kind goes on from weights (there the rate is held).
#
# STUDENT=lcm (or guidance) distils the shipped KIND.pt of each named kind into that fast
# student instead (train lcm / train guidance, from a fresh student, the same time limit and
# batch), written as OUTDIR/KIND_$STUDENT.pt (float32, with its log); TEACHER_DIR=DIR distils
# DIR/KIND.pt instead (a stage, e.g. stages/equal_speed); STUDENT_FLAGS adds flags,
# e.g. "--init motion_core/weights/KIND_fast.pt --solver-steps 5 --guidance-range W W" (W: the registry's scale for KIND) to
# go on from the shipped student with the settings it was distilled with (its meta says).
# Validate and ship back here: score the student against its teacher on both
# validation sources (train lcm --init STUDENT --steps 0). Not with INIT_DIR or FROM_SCRATCH=1, which
# name where a teacher starts, nor with TRAIN_FLAGS, VAL_EVERY or WARMUP, which set a
# teacher's training: the script refuses rather than ignore them. VAL_STEPS without VAL_EVERY
# is refused too (it sets how the validation samples).
#
# .pack/ is ignored by git: name it in the device call's carry. The device tool sends at most
# 64 MiB: with the 26 MiB pack, `bash scripts/gpu_slim.sh` replaces the weights the jobs do
# not read by links for the call (`bash scripts/gpu_slim.sh restore` after it).
set -euo pipefail
pack=$1 secs=$2 out=$3 batch=${4:-256}
kinds=${KINDS:-motion_mamba ftmomamba baseline}
py=${PY:-python3}
runs=${RUNS:-runs/gpu}
if [ -n "${STUDENT:-}" ]; then
  case $STUDENT in
    lcm | guidance) ;;
    *) echo "STUDENT must be lcm or guidance (train lcm / train guidance), not $STUDENT" >&2; exit 2 ;;
  esac
  if [ -n "${INIT_DIR:-}" ] || [ "${FROM_SCRATCH:-0}" = 1 ]; then
    # a student is distilled from a trained teacher: those two name where a teacher starts
    echo "STUDENT distils motion_core/weights/KIND.pt (or TEACHER_DIR/KIND.pt): INIT_DIR and FROM_SCRATCH=1 do not apply to it" >&2; exit 2
  fi
  for kind in $kinds; do
    [ -f "${TEACHER_DIR:-motion_core/weights}/$kind.pt" ] || { echo "${TEACHER_DIR:-motion_core/weights} holds no $kind.pt" >&2; exit 2; }
  done
  for v in TRAIN_FLAGS VAL_EVERY VAL_STEPS WARMUP; do
    if [ -n "${!v:-}" ]; then
      echo "$v sets a teacher's training, not a student's: STUDENT_FLAGS carries the student's flags" >&2; exit 2
    fi
  done
fi
if [ -n "${TEACHER_DIR:-}" ] && [ -z "${STUDENT:-}" ]; then
  echo "TEACHER_DIR names the teachers a STUDENT is distilled from: set STUDENT, or INIT_DIR to go on training" >&2; exit 2
fi
if [ -n "${VAL_STEPS:-}" ] && [ -z "${VAL_EVERY:-}" ]; then
  echo "VAL_STEPS sets how the validation samples: it needs VAL_EVERY" >&2; exit 2
fi
if [ -n "${INIT_DIR:-}" ]; then
  [ "${FROM_SCRATCH:-0}" = 1 ] && { echo "INIT_DIR and FROM_SCRATCH=1 contradict each other" >&2; exit 2; }
  for kind in $kinds; do
    [ -f "$INIT_DIR/$kind.pt" ] || { echo "INIT_DIR $INIT_DIR holds no $kind.pt" >&2; exit 2; }
  done
fi
# the settings are checked before anything is written
mkdir -p "$runs/vae" "$out"
cp "${VAE:-motion_core/weights/vae.pt}" "$runs/vae/vae.pt"
"$py" -c "import torch; print('torch', torch.__version__, torch.cuda.get_device_name() if torch.cuda.is_available() else 'no GPU')"
warmup=${WARMUP:-0}
[ "${FROM_SCRATCH:-0}" = 1 ] && warmup=${WARMUP:-500}
common=(--pack "$pack" --vae "$runs/vae" --prediction sample --warmup "$warmup" --decay constant --lr 3e-4
  --batch "$batch" --ema 0.999 --steps "${STEPS:-1000000}" --save-every 1000000 --time-limit "$secs" ${TRAIN_FLAGS:-})
[ -n "${VAL_EVERY:-}" ] && common+=(--val-every "$VAL_EVERY" --val-steps "${VAL_STEPS:-5}" --stage-best)
export PYTHONUNBUFFERED=1 OMP_NUM_THREADS=${OMP_NUM_THREADS:-4}
if [ -n "${STUDENT:-}" ]; then
  for kind in $kinds; do
    rm -rf "$runs/${kind}_$STUDENT"
    "$py" -m motion_core.train "$STUDENT" --teacher "${TEACHER_DIR:-motion_core/weights}/$kind.pt" --pack "$pack" --vae "$runs/vae" \
      --out "$runs/${kind}_$STUDENT" --batch "$batch" --steps "${STEPS:-1000000}" --save-every 1000000 --decay constant \
      --time-limit "$secs" ${STUDENT_FLAGS:-} >"$out/${kind}_$STUDENT.log" 2>&1 &
  done
  fail=0
  for j in $(jobs -p); do wait "$j" || fail=1; done
  for kind in $kinds; do
    cp "$runs/${kind}_$STUDENT/${kind}_$STUDENT.pt" "$out/" || fail=1
    echo "== $kind $STUDENT"; tr '\r' '\n' <"$out/${kind}_$STUDENT.log" | grep -v '^\s*$' | tail -2 || true
  done
  exit $fail
fi
for kind in $kinds; do
  init=(--init motion_core/weights/$kind.pt)
  [ -f "stages/$kind.pt" ] && init=(--init "stages/$kind.pt")
  [ -n "${INIT_DIR:-}" ] && init=(--init "$INIT_DIR/$kind.pt")
  [ "${FROM_SCRATCH:-0}" = 1 ] && init=()
  rm -rf "${runs:?}/$kind"  # a state left on a warm machine would resume instead of starting from $init
  "$py" -m motion_core.train "$kind" "${common[@]}" "${init[@]}" --out "$runs/$kind" \
    --stage "$out/$kind.pt" >"$out/$kind.log" 2>&1 &
done
fail=0
for j in $(jobs -p); do wait "$j" || fail=1; done
for kind in $kinds; do
  [ -f "$runs/$kind/curve.json" ] && cp "$runs/$kind/curve.json" "$out/$kind.curve.json"
  echo "== $kind"; tr '\r' '\n' <"$out/$kind.log" | grep -v '^\s*$' | tail -2 || true
  if [ -n "${STEPS:-}" ]; then
    took=$("$py" -c "import sys, torch; print(torch.load(sys.argv[1], map_location='cpu', weights_only=False)['step'])" \
      "$runs/$kind/state.pt" 2>/dev/null || echo none)
    if [ "$took" != "$STEPS" ]; then
      echo "$kind stopped at step $took, not $STEPS: raise the time limit or lower STEPS" >&2
      fail=1
    fi
  fi
done
exit $fail
