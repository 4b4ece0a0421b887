#!/usr/bin/env bash
# The PostgreSQL part of the default test run on its own: the study-storage and study-logic
# tests on a throw-away PostgreSQL cluster (tests/conftest.py: postgres) and the two-replica
# test (two `app.py` processes on one database; a long check, hence `-m "long or not long"`:
# long checks run only where -m names them). `bash scripts/test.sh` runs the first,
# `bash scripts/test.sh --long` the second.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh --dev
export HF_HUB_OFFLINE=1 TRANSFORMERS_OFFLINE=1
.venv/bin/python -m pytest tests/test_study.py tests/test_study_replicas.py -k "postgresql or replicas" -m "long or not long" -p no:cacheprovider "$@"
