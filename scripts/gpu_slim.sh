#!/usr/bin/env bash
# Shrink the working tree a lent-GPU call sends (the device tool takes at most 64 MiB, the
# carried .pack included; the tracked tree alone is about 70 MB): the shipped weights a
# denoiser training job does not read become links for the call, and come back after it.
#
#   bash scripts/gpu_slim.sh            # before the device call (carry .pack)
#   bash scripts/gpu_slim.sh restore    # after it: git restores the linked files
#
# Kept: vae.pt and the three teachers (and stages/). Linked out: KMM, the evaluator, the
# length estimator and the fast students (a STUDENT=... --init of a shipped student needs
# its file: KEEP="motion_core/weights/KIND_fast.pt"). A file with uncommitted changes is
# never linked (its content would be lost): commit it, or KEEP it.
set -euo pipefail
cd "$(dirname "$0")/.."
files=(motion_core/weights/kmm.pt motion_core/weights/evaluator.pt motion_core/weights/length.pt
  motion_core/weights/motion_mamba_fast.pt motion_core/weights/ftmomamba_fast.pt motion_core/weights/baseline_fast.pt)
if [ "${1:-}" = restore ]; then
  linked=()
  for f in "${files[@]}"; do
    if [ -L "$f" ]; then
      rm "$f"
      linked+=("$f")
    fi
  done
  [ ${#linked[@]} -gt 0 ] && git checkout -- "${linked[@]}"
  echo "restored ${#linked[@]} files"
  exit 0
fi
slim=()
for f in "${files[@]}"; do
  case " ${KEEP:-} " in *" $f "*) continue ;; esac
  [ -L "$f" ] && continue
  if ! git diff --quiet HEAD -- "$f"; then
    echo "$f has uncommitted changes: nothing linked (commit it, or KEEP it)" >&2
    exit 1
  fi
  slim+=("$f")
done
for f in ${slim[@]+"${slim[@]}"}; do ln -sfn "$(basename "$f").absent-for-the-gpu-call" "$f"; done
# what travels: tracked and untracked-not-ignored files (links as links), and the carried pack
sent=$( (git ls-files -z; git ls-files -z --others --exclude-standard) | du -cbP --files0-from=- 2>/dev/null | tail -1 | cut -f1 || true)
pack=0
[ -e .pack ] && pack=$(du -cbL .pack | tail -1 | cut -f1)
echo "tree $((${sent:-0} / 1048576)) MiB + .pack $((pack / 1048576)) MiB (limit 64 MiB); undo: bash scripts/gpu_slim.sh restore"
if [ $((${sent:-0} + pack)) -gt $((64 * 1048576)) ]; then
  echo "over the device call's 64 MiB: keep fewer files (KEEP) or carry less" >&2
  exit 1
fi
