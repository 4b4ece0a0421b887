#!/usr/bin/env bash
# Install (idempotent) and run the whole default test suite: lint, then pytest
# (unit to real-browser). Extra arguments go to pytest.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh --dev
export HF_HUB_OFFLINE=1 TRANSFORMERS_OFFLINE=1
.venv/bin/python -m ruff check .
.venv/bin/python -m pytest "$@"
