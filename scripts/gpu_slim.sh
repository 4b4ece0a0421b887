#!/usr/bin/env bash
# Shrink the working tree a lent-GPU call sends (the device tool takes at most 64 MiB, the
# carried .pack included; the tracked tree alone is about 130 MB): the shipped weights a
# denoiser training job does not read become links for the call, and come back after it.
#
#   bash scripts/gpu_slim.sh            # before the device call (carry .pack)
#   bash scripts/gpu_slim.sh restore    # after it: git restores the linked files
#
# Kept: vae.pt and the three teachers (and stages/ but for the one-recipe stages and the
# grown-corpus stages of KMM and the baseline). Linked out: KMM, the evaluator, the length
# estimator, the fast students (a STUDENT=... --init of a shipped student needs its file:
# KEEP="motion_core/weights/KIND_fast.pt") and
# stages/one_recipe/. ONE_RECIPE=1 keeps stages/one_recipe/ and links out the three teachers
# instead, for a call that goes on with the one-recipe comparison (INIT_DIR=stages/one_recipe).
# A file with uncommitted changes, or one git does not track, is never linked (its content
# would be lost): commit it, or KEEP it.
set -euo pipefail
cd "$(dirname "$0")/.."
files=(motion_core/weights/kmm.pt motion_core/weights/evaluator.pt motion_core/weights/length.pt
  motion_core/weights/motion_mamba_fast.pt motion_core/weights/ftmomamba_fast.pt motion_core/weights/baseline_fast.pt)
teachers=(motion_core/weights/motion_mamba.pt motion_core/weights/ftmomamba.pt motion_core/weights/baseline.pt)
one_recipe=(stages/one_recipe/motion_mamba.pt stages/one_recipe/ftmomamba.pt stages/one_recipe/baseline.pt)
# grown-corpus stages no denoiser call reads: KMM's (tokeniser, generator) and the baseline's
# (the GPU recipe reads stages/<kind>.pt); with them the tree passes the call's 64 MiB
grown_stages=(stages/grown/rvq.pt stages/grown/kmm.pt stages/grown/baseline.pt)
if [ "${1:-}" = restore ]; then
  linked=()
  for f in "${files[@]}" "${teachers[@]}" "${one_recipe[@]}" "${grown_stages[@]}"; do
    if [ -L "$f" ]; then
      rm "$f"
      linked+=("$f")
    fi
  done
  [ ${#linked[@]} -gt 0 ] && git checkout -- "${linked[@]}"
  echo "restored ${#linked[@]} files"
  exit 0
fi
if [ "${ONE_RECIPE:-0}" = 1 ]; then
  files+=("${teachers[@]}")
  kept=("${one_recipe[@]}")
else
  for f in "${one_recipe[@]}"; do [ -L "$f" ] || [ -e "$f" ] && files+=("$f"); done
  kept=("${teachers[@]}")
fi
for f in "${grown_stages[@]}"; do [ -L "$f" ] || [ -e "$f" ] && files+=("$f"); done
# what this call reads must be there, not a link an earlier slim of the other mode left
for f in "${kept[@]}"; do
  if [ -L "$f" ]; then
    echo "$f is a link an earlier slim left: bash scripts/gpu_slim.sh restore first" >&2
    exit 1
  fi
done
slim=()
for f in "${files[@]}"; do
  case " ${KEEP:-} " in *" $f "*) continue ;; esac
  [ -L "$f" ] && continue
  if ! git ls-files --error-unmatch "$f" >/dev/null 2>&1 || ! git diff --quiet HEAD -- "$f"; then
    echo "$f is untracked or has uncommitted changes: nothing linked (commit it, or KEEP it)" >&2
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
