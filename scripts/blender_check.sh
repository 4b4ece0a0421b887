#!/usr/bin/env bash
# Opens a freshly generated motion's GLB and BVH in Blender (PyPI bpy 4.2, ~500 MB, kept
# in its own .venv-blender/, so not part of the default test run) and compares the joints,
# under HumanML3D's joint names and under the humanoid rig's (Mixamo-style, T-pose rest);
# for each GLB it also checks the skinned body (tools/blender_check.py).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
if [ ! -x .venv-blender/bin/python ]; then
  python3.11 -m venv .venv-blender
  .venv-blender/bin/pip install --quiet bpy==4.2.0 numpy
fi
out=$(mktemp -d)
export HF_HUB_OFFLINE=1 TRANSFORMERS_OFFLINE=1
.venv/bin/python - "$out" <<'PY'
import sys
import motion_core
from motion_core.formats.export import export_all

m = motion_core.generate([("a person walks forward", 4), ("a person waves with the right hand", 3)], "baseline", seed=0)
print({k: str(v) for k, v in export_all(m, sys.argv[1]).items()})
from motion_core.formats.bvh import joints_to_bvh, write_bvh
from motion_core.formats.gltf import write_glb
from motion_core.body.skeleton import HUMANOID

write_glb(f"{sys.argv[1]}/humanoid.glb", m.joints, m.fps, skeleton=HUMANOID)
write_bvh(f"{sys.argv[1]}/humanoid.bvh", joints_to_bvh(m.joints, m.fps, skeleton=HUMANOID))
PY
.venv-blender/bin/python tools/blender_check.py "$out/motion.glb" "$out/motion.bvh" \
  "$out/humanoid.glb" "$out/humanoid.bvh" "$out/motion_joints.npy" | tail -1
