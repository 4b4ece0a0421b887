#!/usr/bin/env bash
# The papers' ablations on our data, each arm trained from scratch at one equal budget on the
# shipped VAE's latents, then scored together (results/ablation_*.json):
#   Motion Mamba (its Table 4): HTM scan counts hierarchical 5,3,1 / flat 1,1,1 / ascending
#     1,2,3; BSM bidirectional / single direction
#   FTMoMamba (its Table 2): FreqMamba on/off (off = plain BiMamba), TextMamba on/off (off =
#     linear attention)
#   KMM (its Table 4): key-frame vs random masking, alignment loss on/off; needs a KMM
#     tokeniser run (RVQ, default: the shipped one, extracted) and trains 3 generators to 1,000
#     of 2,500 scheduled steps
# Usage: bash scripts/ablations.sh DATA [STEPS]   (CPU: about 90 min of one core per 600 steps
# for all diffusion arms, 30 min per KMM arm; resumable: finished arms are skipped)
set -euo pipefail
cd "$(dirname "$0")/.."
DATA=${1:?usage: scripts/ablations.sh DATA [STEPS]}
STEPS=${2:-600}
RUNS=${RUNS:-runs/ablations}
export HF_HUB_OFFLINE=1 TRANSFORMERS_OFFLINE=1 OMP_NUM_THREADS=${OMP_NUM_THREADS:-1}
PY=.venv/bin/python
mkdir -p "$RUNS/vae"
cp -n motion_core/weights/vae.pt "$RUNS/vae/vae.pt"
arm() {  # arm NAME KIND [--set FIELD=VALUE ...]
  local name=$1 kind=$2
  shift 2
  [ -f "$RUNS/$name/$kind.pt" ] || $PY -m motion_core.train "$kind" --data "$DATA" --vae "$RUNS/vae" \
    --out "$RUNS/$name" --steps "$STEPS" --batch 64 --save-every 200 "$@"
}
arm mm_full motion_mamba
arm mm_flat motion_mamba --set htm_order=flat
arm mm_ascending motion_mamba --set htm_order=ascending
arm mm_bsm_single motion_mamba --set bsm=single
arm ft_full ftmomamba
arm ft_freq_off ftmomamba --set freq=off
arm ft_text_off ftmomamba --set text=off
$PY -m motion_core.eval --data "$DATA" --ablation --n 100 --out "$RUNS/mm" \
  --arm "full=$RUNS/mm_full" --arm "flat=$RUNS/mm_flat" --arm "ascending=$RUNS/mm_ascending" \
  --arm "bsm_single=$RUNS/mm_bsm_single"
$PY -m motion_core.eval --data "$DATA" --ablation --n 100 --out "$RUNS/ft" \
  --arm "full=$RUNS/ft_full" --arm "freq_off=$RUNS/ft_freq_off" --arm "text_off=$RUNS/ft_text_off"
cp "$RUNS/mm/ablation.json" results/ablation_motion_mamba.json
cp "$RUNS/ft/ablation.json" results/ablation_ftmomamba.json

RVQ=${RVQ:-$RUNS/kmm_rvq}
[ -f "$RVQ/rvq.pt" ] || $PY -m motion_core.train kmm-extract-rvq --out "$RVQ"
kmm() {  # kmm NAME [options]
  local name=$1
  shift
  [ -f "$RUNS/$name/kmm.pt" ] || $PY -m motion_core.train kmm-generator --data "$DATA" --rvq "$RVQ" \
    --out "$RUNS/$name" --steps 2500 --stop-at 1000 --batch 32 --lr 3e-4 --pair-prob 0.3 "$@"
}
kmm kmm_key
kmm kmm_random --mask random
kmm kmm_noalign --no-align
$PY -m motion_core.eval --data "$DATA" --kmm-ablation "key=$RUNS/kmm_key/kmm.pt" \
  "random=$RUNS/kmm_random/kmm.pt" "noalign=$RUNS/kmm_noalign/kmm.pt" --rvq "$RVQ" --n 100 --out "$RUNS/kmm"
cp "$RUNS/kmm/kmm_ablation.json" results/kmm_ablation.json
