#!/usr/bin/env bash
# Install (idempotent) and launch the demo on the shipped checkpoints.
# Binds 127.0.0.1 by default; HOST and PORT (default 7860) override.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
export HF_HUB_OFFLINE=1 TRANSFORMERS_OFFLINE=1
exec .venv/bin/python app.py "$@"
