#!/usr/bin/env bash
# Retrain every shipped model from scratch and ship it (motion_core/weights/), then evaluate.
#   bash scripts/train_all.sh             procedural corpus + real Bandai Namco clips
#                                         (weights for non-commercial use: CC BY-NC 4.0)
#   bash scripts/train_all.sh procedural  the procedural corpus alone (no licence limit
#                                         from the training data)
# CPU: about 2 h on 2 cores (the VAE is most of it). Resumable: rerun to continue.
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
$PY -m motion_core.train vae --data "$DATA" --out "$RUNS/vae" --steps 7500 --batch 64 --ship
for m in motion_mamba baseline; do
  $PY -m motion_core.train "$m" --data "$DATA" --vae "$RUNS/vae" --out "$RUNS/$m" --steps 1500 --batch 64 --ship
done
$PY -m motion_core.evaluate --methods motion_mamba,baseline --data "$DATA" --n 200 --out results/
if [ "${1:-combined}" != procedural ]; then
  $PY -m motion_core.evaluate --methods motion_mamba,baseline --data "$DATA" --n 200 --out results/ --source real
fi
