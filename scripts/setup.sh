#!/usr/bin/env bash
# Installs what the project needs, idempotently: a virtual environment with the pinned
# Python packages, the npm `three` package for the viewer and, with --dev, the test tools
# and Debian's chromium for the browser tests. Safe to run again: each step is skipped
# when what it installs is already there and its inputs have not changed.
set -euo pipefail
cd "$(dirname "$0")/.."

DEV=0
[ "${1:-}" = "--dev" ] && DEV=1

PY=${PYTHON:-}
if [ -z "$PY" ]; then
  # torch==2.13.0's CPU wheel on this kind of machine is built for CPython 3.11.
  if command -v python3.11 >/dev/null 2>&1; then PY=python3.11; else PY=python3; fi
fi

if [ ! -x .venv/bin/python ]; then
  echo "[setup] creating .venv with $PY"
  "$PY" -m venv .venv
fi

req=requirements.txt
[ "$DEV" = 1 ] && req=requirements-dev.txt
stamp=".setup-stamp-$(basename "$req" .txt)"
want=$(cat requirements.txt "$req" | sha256sum | cut -c1-16)
if [ "$(cat "$stamp" 2>/dev/null)" != "$want" ]; then
  echo "[setup] installing Python packages from $req"
  .venv/bin/python -m pip install --quiet --upgrade pip
  .venv/bin/python -m pip install --quiet -r "$req"
  echo "$want" > "$stamp"
fi

if [ ! -f node_modules/three/build/three.module.js ] || [ package.json -nt node_modules/.package-lock.json ]; then
  if command -v npm >/dev/null 2>&1; then
    echo "[setup] installing npm packages"
    npm ci --no-audit --no-fund --loglevel=error 2>/dev/null || npm install --no-audit --no-fund --loglevel=error
  else
    echo "[setup] WARNING: npm not found; the 3D viewer needs node_modules/three (apt-get install npm)" >&2
  fi
fi

if [ "$DEV" = 1 ] && [ ! -x /usr/bin/chromium ]; then
  echo "[setup] installing Debian chromium for the browser tests"
  SUDO=""
  [ "$(id -u)" != 0 ] && command -v sudo >/dev/null 2>&1 && SUDO=sudo
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq chromium chromium-driver >/dev/null
fi
echo "[setup] done"
