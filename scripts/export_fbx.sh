#!/usr/bin/env bash
# GLB -> FBX with Blender's own FBX exporter, then the FBX imported back and its joints
# compared with the motion's (when the _joints.npy the demo downloads beside it is given).
#
#   bash scripts/export_fbx.sh motion.glb [motion.fbx] [motion_joints.npy]
#
# Blender comes from PyPI (bpy 4.2, ~500 MB) in its own .venv-blender/, so it is not part of
# the default install or test run.
set -euo pipefail
repo="$(cd "$(dirname "$0")/.." && pwd)"
glb="$(realpath "$1")"
fbx="$(realpath -m "${2:-${1%.glb}.fbx}")"
npy="${3:-}"
[ -n "$npy" ] && npy="$(realpath "$npy")"
cd "$repo"
if [ ! -x .venv-blender/bin/python ]; then
  python3.11 -m venv .venv-blender
  .venv-blender/bin/pip install --quiet bpy==4.2.0 numpy
fi
.venv-blender/bin/python tools/blender_fbx.py "$glb" "$fbx" $npy | tail -1
echo "wrote $fbx"
