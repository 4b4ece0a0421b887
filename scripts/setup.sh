#!/usr/bin/env bash
# Installs what the project needs, idempotently: a virtual environment with the pinned
# Python packages, the npm `three` package for the viewer and, with --dev, the test tools,
# Debian's chromium for the browser tests and Debian's postgresql for the study tests (they
# start a throw-away cluster of their own; no server is set up or left running). Safe to run again: each step is skipped
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
stamp=".venv/.setup-stamp-$(basename "$req" .txt)"  # inside the venv: a rebuilt venv installs again
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

if [ "$DEV" = 1 ]; then
  apt=()
  [ -x /usr/bin/chromium ] || apt+=(chromium chromium-driver)
  ls /usr/lib/postgresql/*/bin/initdb >/dev/null 2>&1 || apt+=(postgresql)
  if [ ${#apt[@]} -gt 0 ]; then
    echo "[setup] installing Debian packages for the tests: ${apt[*]}"
    SUDO=""
    [ "$(id -u)" != 0 ] && command -v sudo >/dev/null 2>&1 && SUDO=sudo
    $SUDO apt-get update -qq
    # Debian's postgresql may create (and, with an init system, start) its own "main" cluster;
    # the tests never use it: theirs listens on a private Unix socket only
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "${apt[@]}" >/dev/null
  fi
fi
echo "[setup] done"
