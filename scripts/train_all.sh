#!/usr/bin/env bash
# Retrain every shipped model from scratch and ship it (motion_core/weights/), then evaluate.
#   bash scripts/train_all.sh             procedural corpus + real Bandai Namco clips
#                                         (weights for non-commercial use: CC BY-NC 4.0)
#   bash scripts/train_all.sh procedural  the procedural corpus alone (no licence limit
#                                         from the training data)
# CPU: about 20 h on 2 cores (KMM's generator stages, about 8 h of one thread at 0.5-1 s a step, and the
# three denoisers on the temporal latent, about 10 h at 0.7-2.5 s a step, are most of it; an estimate
# from the stages' own times, not one timed run). Resumable: rerun to continue. KMM comes first: the
# diffusion methods' VAE starts from its tokeniser.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
export HF_HUB_OFFLINE=1 TRANSFORMERS_OFFLINE=1
PY=.venv/bin/python
ARCHIVE=${ARCHIVE:-../shared/data/bandai-namco-motion.tar.xz}
if [ "${1:-combined}" = procedural ]; then
  DATA=data/corpus; RUNS=runs/procedural
  [ -f "$DATA/corpus.json" ] || $PY -m motion_core.corpus build "$DATA"
else
  DATA=data/corpus_real; RUNS=runs/combined
  [ -f "$DATA/corpus.json" ] || $PY -m motion_core.corpus build "$DATA" --real "$ARCHIVE"
fi
# KMM: its own tokeniser, then the masked generator (one CPU thread each ran fastest here)
OMP_NUM_THREADS=1 $PY -m motion_core.train kmm-rvq --data "$DATA" --out "$RUNS/kmm_rvq" --steps 2000 --batch 64
# its decoder alone at a higher rate, encoder and codebooks frozen (the codes stay)
OMP_NUM_THREADS=1 $PY -m motion_core.train kmm-rvq --data "$DATA" --out "$RUNS/kmm_rvq_dec" \
  --init "$RUNS/kmm_rvq/rvq.pt" --decoder-only --steps 3000 --batch 64 --lr 1e-3
OMP_NUM_THREADS=1 $PY -m motion_core.train kmm-generator --data "$DATA" --rvq "$RUNS/kmm_rvq_dec" --out "$RUNS/kmm" \
  --steps 2500 --batch 32 --lr 3e-4 --pair-prob 0.3
# the shipped generator's lineage: stages at a lower rate, each from the one before, the
# segment-phase term (--phase) from the tenth on (docs/training-log.md); the last one ships
PREV="$RUNS/kmm"
STAGES=(1200 1200 800 1200 3000 3000 2000 3000 3000 3000 3000 3000 3000)
for i in "${!STAGES[@]}"; do
  OUT="$RUNS/kmm_more$((i + 1))"
  SHIP=()
  [ "$i" -eq $((${#STAGES[@]} - 1)) ] && SHIP=(--ship)
  PHASE=()
  [ "$i" -ge 9 ] && PHASE=(--phase)
  OMP_NUM_THREADS=1 $PY -m motion_core.train kmm-generator --data "$DATA" --rvq "$RUNS/kmm_rvq_dec" --out "$OUT" \
    --init "$PREV/kmm.pt" --steps "${STAGES[$i]}" --batch 32 --lr 1.5e-4 --pair-prob 0.3 "${PHASE[@]}" "${SHIP[@]}"
  PREV="$OUT"
done
# a second decoder-only stage (the codes stay, so the generator stays valid), swapped into kmm.pt
OMP_NUM_THREADS=1 $PY -m motion_core.train kmm-rvq --data "$DATA" --out "$RUNS/kmm_rvq_dec2" \
  --init "$RUNS/kmm_rvq_dec/rvq.pt" --decoder-only --steps 2000 --batch 64 --lr 3e-4
$PY -m motion_core.train kmm-swap-decoder --rvq "$RUNS/kmm_rvq_dec2" --out motion_core/weights/kmm.pt
# the diffusion methods' VAE: KMM's tokeniser with a 16-channel Gaussian latent per 4 frames
# in place of its quantiser, started from the shipped tokeniser (docs/training-log.md)
OMP_NUM_THREADS=1 $PY -m motion_core.train vae --arch conv --init motion_core/weights/kmm.pt --set z_width=16 \
  --data "$DATA" --out "$RUNS/vae1" --steps 1000 --batch 64
OMP_NUM_THREADS=1 $PY -m motion_core.train vae --init "$RUNS/vae1/vae.pt" --data "$DATA" --out "$RUNS/vae" \
  --steps 2000 --batch 64 --ship
# the denoisers regress x_0 (--prediction sample), at a held rate, shipping a moving average
# of their weights; each one's validation curve goes to $RUNS/$m/curve.json. The shipped
# ones were trained in stages of this recipe from the same VAE, the last at batch 256 on a
# GPU (docs/training-log.md, scripts/train_on_gpu.sh); one run stands for them here
for m in motion_mamba ftmomamba baseline; do
  OMP_NUM_THREADS=1 $PY -m motion_core.train "$m" --data "$DATA" --vae "$RUNS/vae" --out "$RUNS/$m" --steps 6000 \
    --batch 64 --lr 3e-4 --warmup 100 --decay constant --prediction sample --val-every 750 --val-steps 10 --ship
done
METHODS=motion_mamba,kmm,ftmomamba,baseline
$PY -m motion_core.eval --methods $METHODS --data "$DATA" --n 200 --out results/
$PY -m motion_core.eval --methods $METHODS --data "$DATA" --n 200 --out results/ --verifier-only
$PY -m motion_core.eval --methods $METHODS --data "$DATA" --out results/ --timelines
if [ "${1:-combined}" != procedural ]; then
  $PY -m motion_core.eval --methods $METHODS --data "$DATA" --n 200 --out results/ --source real
fi
