#!/usr/bin/env bash
# Shrink the working tree a lent-GPU call sends (the device tool takes at most 64 MiB, the
# carried .pack included; the tracked tree alone is about 70 MB): the shipped weights a
# denoiser training job does not read become links for the call, and come back after it.
#
#   bash scripts/gpu_slim.sh            # before the device call (carry .pack)
#   bash scripts/gpu_slim.sh restore    # after it: git restores the files
#
# Kept: vae.pt and the three teachers (and stages/). Linked out: KMM, the evaluator, the
# length estimator and the fast students (a STUDENT=... --init of a shipped student needs
# its file back: KEEP="motion_core/weights/KIND_fast.pt").
set -euo pipefail
cd "$(dirname "$0")/.."
files=(motion_core/weights/kmm.pt motion_core/weights/evaluator.pt motion_core/weights/length.pt
  motion_core/weights/motion_mamba_fast.pt motion_core/weights/ftmomamba_fast.pt motion_core/weights/baseline_fast.pt)
if [ "${1:-}" = restore ]; then
  for f in "${files[@]}"; do [ -L "$f" ] && rm "$f"; done
  git checkout -- "${files[@]}"
  echo "restored ${#files[@]} files"
  exit 0
fi
for f in "${files[@]}"; do
  case " ${KEEP:-} " in *" $f "*) continue ;; esac
  [ -L "$f" ] && continue
  ln -sfn "$(basename "$f").absent-for-the-gpu-call" "$f"
done
sent=$( (git ls-files -z; git ls-files -z --others --exclude-standard) | xargs -0 -r du -cbP 2>/dev/null | tail -1 | cut -f1)
pack=$(du -cbL .pack 2>/dev/null | tail -1 | cut -f1 || echo 0)
echo "tree $((sent / 1048576)) MiB + .pack $((pack / 1048576)) MiB (limit 64 MiB); undo: bash scripts/gpu_slim.sh restore"
if [ $((sent + pack)) -gt $((64 * 1048576)) ]; then
  echo "over the device call's 64 MiB: keep fewer files (KEEP) or carry less" >&2
  exit 1
fi
