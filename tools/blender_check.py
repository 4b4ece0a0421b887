"""Open our GLB and BVH exports in Blender (the PyPI `bpy` module) and compare the joints.

Usage (bpy is ~500 MB, so it lives in its own environment, not in the default test run):
    python3.11 -m venv .venv-blender && .venv-blender/bin/pip install bpy==4.2.0 numpy
    .venv-blender/bin/python tools/blender_check.py motion.glb motion.bvh motion_joints.npy

Imports each file with Blender's own importers, steps through every frame and reads the
armature's bone heads in world space (Blender is Z-up: (x, y, z)_blender = (x, -z, y)_ours),
then prints, per file, the number of bones and frames and the largest joint error in mm
against the joints .npy. Exit status 1 when a file does not import or is off by > 1 mm.
"""

from __future__ import annotations

import json
import sys

import bpy
import numpy as np
from mathutils import Vector

JOINTS = [
    "pelvis", "left_hip", "right_hip", "spine1", "left_knee", "right_knee", "spine2", "left_ankle",
    "right_ankle", "spine3", "left_foot", "right_foot", "neck", "left_collar", "right_collar", "head",
    "left_shoulder", "right_shoulder", "left_elbow", "right_elbow", "left_wrist", "right_wrist",
]  # fmt: skip
FPS = 20


def _reset() -> None:
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.context.scene.render.fps = FPS
    bpy.context.scene.render.fps_base = 1.0


def _sample(arm, n_frames: int, first: int) -> np.ndarray:
    out = np.zeros((n_frames, len(JOINTS), 3))
    for f in range(n_frames):
        bpy.context.scene.frame_set(first + f)
        for j, name in enumerate(JOINTS):
            p = arm.matrix_world @ arm.pose.bones[name].head
            out[f, j] = (p.x, p.z, -p.y)  # back to y-up
    return out


def check_glb(path: str, joints: np.ndarray) -> dict:
    _reset()
    bpy.ops.import_scene.gltf(filepath=path)
    arm = next(o for o in bpy.context.scene.objects if o.type == "ARMATURE")
    # Blender's glTF importer keys time t at frame t * fps (frame 0 first); BVH starts at 1
    got = _sample(arm, len(joints), 0)
    return {"bones": len(arm.pose.bones), "frames": len(joints), "max_err_mm": float(np.abs(got - joints).max() * 1000)}


def check_bvh(path: str, joints: np.ndarray) -> dict:
    _reset()
    bpy.ops.import_anim.bvh(filepath=path, global_scale=0.01, update_scene_fps=True, update_scene_duration=True)
    arm = next(o for o in bpy.context.scene.objects if o.type == "ARMATURE")
    got = _sample(arm, len(joints), 1)
    return {"bones": len(arm.pose.bones), "frames": len(joints), "max_err_mm": float(np.abs(got - joints).max() * 1000)}


def main() -> int:
    glb, bvh, npy = sys.argv[-3:]
    joints = np.load(npy).astype(np.float64)
    report = {"blender": bpy.app.version_string, "glb": check_glb(glb, joints), "bvh": check_bvh(bvh, joints)}
    print(json.dumps(report))
    return int(any(r["max_err_mm"] > 1.0 for r in (report["glb"], report["bvh"])))


if __name__ == "__main__":
    Vector  # noqa: B018 (mathutils must import inside Blender's Python)
    sys.exit(main())
