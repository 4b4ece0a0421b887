#!/usr/bin/env bash
# Install (idempotent) and run the default test suite: lint, then pytest (unit to
# real-browser), under 15 minutes. `--long` runs the long checks instead (training runs,
# timings and benchmarks, load and soak tests, whole-dataset sweeps; pytest -m long).
# Other arguments go to pytest; a -m among them replaces --long's (pytest's last -m wins),
# and long checks run only where -m names them or the command names the test itself.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh --dev
export HF_HUB_OFFLINE=1 TRANSFORMERS_OFFLINE=1
marker=()
# the default run on two workers, one test file each at a time (a file's module fixtures, such
# as its app server, stay in one process); the long checks alone, since they time things
workers=(-n "${MMS_TEST_WORKERS:-2}" --dist loadfile)
if [[ "${1:-}" == "--long" ]]; then
    shift
    marker=(-m long)
    workers=()
fi
.venv/bin/python -m ruff check .
# (the guarded expansion: an empty array under set -u fails in bash before 4.4)
.venv/bin/python -m pytest ${workers[@]+"${workers[@]}"} ${marker[@]+"${marker[@]}"} "$@"
