#!/usr/bin/env bash
# The test-split tables a denoiser stage needs before it ships, for a candidate checkpoint,
# written to OUT without touching results/ or motion_core/weights/:
#
#   bash tools/candidate_tables.sh KIND CANDIDATE.pt DATA OUT
#   e.g. bash tools/candidate_tables.sh ftmomamba stages/ftmomamba.pt data/corpus_real /tmp/ftm_tables
#
# The core reads the candidate through MMS_WEIGHTS_DIR: a folder of links to the shipped
# weights with KIND.pt the candidate (a fast student distilled from other weights is left out
# by the registry, so the row is KIND's quality sampler). It writes:
#   OUT/candidate.json                                        the file read (sha256, its steps)
#   OUT/proc_S/verifier.json, OUT/real_S/verifier_real.json   the verifier at seeds SEEDS (0 1 2)
#   OUT/verifier_seeds.json, OUT/verifier_real_seeds.json     their three-seed tables (tools/seed_table.py)
#   OUT/metrics_proc/, OUT/metrics_real/                      R-precision, FID and the rest (seed 0)
#   OUT/timelines/timelines.json                              the 50 multi-segment timelines
# then the shipped rows are compared with these, and merged with tools/merge_results.py
# where the candidate ships. SAMPLER=fast tables KIND's fast sampler instead (rows
# "KIND:fast"): the consistency student in motion_core/weights/KIND_fast.pt, which must have
# been distilled from the candidate. N (200) prompts per table; ONLY="verifier" skips the metrics and
# timelines. One torch thread, as the recorded tables: on the 2-core VM the whole set took
# 7.5 minutes for FTMoMamba.
set -euo pipefail
kind=$1 cand=$2 data=$3 out=$4
n=${N:-200} seeds=${SEEDS:-0 1 2} py=${PY:-python}
root=$(cd "$(dirname "$0")/.." && pwd)
[ -f "$cand" ] || { echo "no candidate checkpoint $cand" >&2; exit 2; }
[ -d "$data" ] || { echo "no corpus directory $data" >&2; exit 2; }
# absolute before the cd below: relative paths are the caller's
mkdir -p "$out"
out=$(cd "$out" && pwd) data=$(cd "$data" && pwd)
weights=$(mktemp -d)
trap 'rm -rf "$weights"' EXIT
for f in "$root"/motion_core/weights/*; do ln -s "$f" "$weights/"; done
ln -sfn "$(cd "$(dirname "$cand")" && pwd)/$(basename "$cand")" "$weights/$kind.pt"
export MMS_WEIGHTS_DIR=$weights OMP_NUM_THREADS=1 HF_HUB_OFFLINE=1 TRANSFORMERS_OFFLINE=1
cd "$root"
sampler=${SAMPLER:-quality}
case $sampler in
  quality) row=$kind ;;
  fast) row=$kind:fast ;;
  *) echo "SAMPLER is quality or fast, not $sampler" >&2; exit 2 ;;
esac
method="$kind:$sampler"
# what the core reads as KIND.pt through MMS_WEIGHTS_DIR: the candidate, recorded with the tables
"$py" - "$kind" "$cand" "$sampler" >"$out/candidate.json" <<'PY'
import hashlib, json, sys
from motion_core.inference import checkpoints
from motion_core.inference.base import WEIGHTS
kind, cand, sampler = sys.argv[1:4]
def read(path):
    return {"sha256": hashlib.sha256(path.read_bytes()).hexdigest(), "steps": checkpoints.read_float32(path)["meta"].get("steps")}
doc = {"kind": kind, "candidate": cand, "sampler": sampler, **read(WEIGHTS / f"{kind}.pt")}
if sampler == "fast":  # the student is what the fast rows sample
    doc["student"] = {"file": f"{kind}_fast.pt", **read(WEIGHTS / f"{kind}_fast.pt")}
print(json.dumps(doc))
PY
cat "$out/candidate.json"
proc=() real=()
for s in $seeds; do
  "$py" -m motion_core.eval --methods "$method" --data "$data" --n "$n" --seed "$s" --verifier-only --out "$out/proc_$s"
  "$py" -m motion_core.eval --methods "$method" --data "$data" --n "$n" --seed "$s" --verifier-only --source real \
    --out "$out/real_$s"
  proc+=("$out/proc_$s/verifier.json")
  real+=("$out/real_$s/verifier_real.json")
done
# shellcheck disable=SC2086  # the seeds are words
"$py" tools/seed_table.py "${proc[@]}" --seeds $seeds --methods "$row" --out "$out/verifier_seeds.json"
# shellcheck disable=SC2086
"$py" tools/seed_table.py "${real[@]}" --seeds $seeds --methods "$row" --out "$out/verifier_real_seeds.json"
if [ "${ONLY:-}" != verifier ]; then
  "$py" -m motion_core.eval --methods "$method" --data "$data" --n "$n" --out "$out/metrics_proc"
  "$py" -m motion_core.eval --methods "$method" --data "$data" --n "$n" --source real --no-extended \
    --out "$out/metrics_real"
  "$py" -m motion_core.eval --methods "$method" --data "$data" --n "$n" --timelines --out "$out/timelines"
fi
echo "tables of $kind ($cand) in $out"
