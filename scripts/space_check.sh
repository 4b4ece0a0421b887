#!/usr/bin/env bash
# Reproduce a pip-only hosted space from a clean clone and check it in a browser:
#   a clone of this checkout's HEAD (committed files only: no node_modules, no .venv),
#   a fresh venv with `pip install -r requirements.txt` and nothing else (no npm),
#   three.js from a local HTTP mirror laid out like the CDN, given through MMS_THREE_URL,
#   `python app.py` as the space runs it, and Debian's chromium as its visitor.
# It measures the cold start (process start to the first generation served) and checks that
# a generated motion plays in the demo's viewer and that the study page's two viewers play.
# The browser side runs from this checkout's .venv (playwright is a dev tool, not the space's).
#   bash scripts/space_check.sh [--keep]     (--keep leaves the work folder for a look)
set -euo pipefail
cd "$(dirname "$0")/.."
SRC=$(pwd)
PY=${PYTHON:-}
if [ -z "$PY" ]; then
  if command -v python3.11 >/dev/null 2>&1; then PY=python3.11; else PY=python3; fi
fi
[ -x .venv/bin/python ] && .venv/bin/python -c "import playwright" 2>/dev/null \
  || { echo "the browser side needs this checkout's dev tools: bash scripts/setup.sh --dev"; exit 2; }
[ -x /usr/bin/chromium ] || { echo "Debian chromium is missing: bash scripts/setup.sh --dev"; exit 2; }

W=$(mktemp -d /tmp/mms-space.XXXXXX)
[ "${1:-}" = "--keep" ] || trap 'rm -rf "$W"' EXIT
echo "[space] work folder $W"

git clone -q "$SRC" "$W/space"
git -C "$W/space" checkout -q "$(git rev-parse HEAD)"

t0=$(date +%s)
"$PY" -m venv "$W/venv"
"$W/venv/bin/python" -m pip install --quiet -r "$W/space/requirements.txt"
echo "[space] pip install -r requirements.txt: $(( $(date +%s) - t0 )) s"

# the mirror: the npm tarball of the pinned version (what the CDN serves), else this
# checkout's node_modules/three (byte-identical when installed from package-lock.json)
VERSION=$(python3 -c "import json; print(json.load(open('$W/space/app/three_manifest.json'))['version'])")
mkdir -p "$W/cdn"
if [ -f node_modules/three/build/three.module.js ] \
  && [ "$(python3 -c "import json; print(json.load(open('node_modules/three/package.json'))['version'])")" = "$VERSION" ]; then
  cp -r node_modules/three "$W/cdn/three@$VERSION"
else
  (cd "$W/cdn" && npm pack --silent "three@$VERSION" >/dev/null && tar xzf "three-$VERSION.tgz" && mv package "three@$VERSION")
fi

# a cold start: drop the OS file cache when allowed (root on a VM; not inside most containers)
if sync && echo 3 > /proc/sys/vm/drop_caches 2>/dev/null; then echo "[space] dropped the OS file cache"
else echo "[space] could not drop the OS file cache: the start is cold for the process, not the disk"; fi

HF_HUB_OFFLINE=1 TRANSFORMERS_OFFLINE=1 .venv/bin/python scripts/space_check.py \
  --space "$W/space" --python "$W/venv/bin/python" --mirror "$W/cdn" --shots "$W/shots"
if [ "${1:-}" = "--keep" ]; then echo "[space] kept: $W (screenshots in $W/shots)"; fi
