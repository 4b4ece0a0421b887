"""Open our GLB and BVH exports in Blender (the PyPI `bpy` module) and compare the joints.

Usage (bpy is ~500 MB, so it lives in its own environment, not in the default test run):
    python3.11 -m venv .venv-blender && .venv-blender/bin/pip install bpy==4.2.0 numpy
    .venv-blender/bin/python tools/blender_check.py motion.glb motion.bvh [humanoid.glb humanoid.bvh] motion_joints.npy

Imports each file with Blender's own importers, steps through every frame and reads the
armature's bone heads in world space (Blender is Z-up: (x, y, z)_blender = (x, -z, y)_ours),
then prints, per file, the number of bones and frames and the largest joint error in mm
against the joints .npy. For the GLB it also checks the skinned body: one mesh bound to the
armature (an Armature modifier), a vertex group per joint that moves it, and the deformed
mesh following the motion: at several frames the vertices bound mostly to the head, the
wrists and the ankles sit around those joints. Exit status 1 when a file does not import,
is off by > 1 mm, or the body does not follow.
"""

from __future__ import annotations

import json
import os
import sys

import bpy
import numpy as np
from mathutils import Vector

JOINTS = [
    "pelvis", "left_hip", "right_hip", "spine1", "left_knee", "right_knee", "spine2", "left_ankle",
    "right_ankle", "spine3", "left_foot", "right_foot", "neck", "left_collar", "right_collar", "head",
    "left_shoulder", "right_shoulder", "left_elbow", "right_elbow", "left_wrist", "right_wrist",
]  # fmt: skip
# the same joints as a humanoid rig names them (motion_core.skeleton.HUMANOID), same order
HUMANOID = [
    "Hips", "LeftUpLeg", "RightUpLeg", "Spine", "LeftLeg", "RightLeg", "Spine1", "LeftFoot",
    "RightFoot", "Spine2", "LeftToeBase", "RightToeBase", "Neck", "LeftShoulder", "RightShoulder", "Head",
    "LeftArm", "RightArm", "LeftForeArm", "RightForeArm", "LeftHand", "RightHand",
]  # fmt: skip
FPS = 20


def names_of(arm) -> list[str]:
    """The armature's joints in the motion's order, under whichever names the file uses."""
    return HUMANOID if "Hips" in arm.pose.bones else JOINTS


def _reset() -> None:
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.context.scene.render.fps = FPS
    bpy.context.scene.render.fps_base = 1.0


def _sample(arm, n_frames: int, first: int) -> np.ndarray:
    out = np.zeros((n_frames, len(names_of(arm)), 3))
    for f in range(n_frames):
        bpy.context.scene.frame_set(first + f)
        for j, name in enumerate(names_of(arm)):
            p = arm.matrix_world @ arm.pose.bones[name].head
            out[f, j] = (p.x, p.z, -p.y)  # back to y-up
    return out


def check_body(arm, joints: np.ndarray) -> dict:
    """The skinned mesh: bound to the armature, vertex groups, and deformed with the motion."""
    bodies = [o for o in bpy.context.scene.objects if o.type == "MESH" and o.find_armature() == arm]
    if len(bodies) != 1:
        return {"meshes": len(bodies), "ok": False}
    body = bodies[0]
    mods = [m for m in body.modifiers if m.type == "ARMATURE" and m.object == arm]
    groups = {g.index: g.name for g in body.vertex_groups}
    # each vertex's strongest group; 'bound' = vertices bound mostly (> 0.9) to one joint
    strongest: dict[str, list[int]] = {}
    for v in body.data.vertices:
        if v.groups:
            g = max(v.groups, key=lambda e: e.weight)
            if g.weight > 0.9:
                strongest.setdefault(groups[g.group], []).append(v.index)
    # a part bound to one joint moves rigidly with it: its centroid keeps its distance to the
    # joint from frame to frame (the mesh is built around the rest joints, so that distance
    # is the part's own: a hand's centre lies a few cm past the wrist)
    dist: dict[str, list[float]] = {}
    frames = np.linspace(0, len(joints) - 1, 5).astype(int)
    for f in frames:
        bpy.context.scene.frame_set(int(f))
        mesh = body.evaluated_get(bpy.context.evaluated_depsgraph_get()).to_mesh()
        world = np.array([tuple(body.matrix_world @ v.co) for v in mesh.vertices])
        body.evaluated_get(bpy.context.evaluated_depsgraph_get()).to_mesh_clear()
        world = world[:, [0, 2, 1]] * np.array([1.0, 1.0, -1.0])  # back to y-up
        for j in (JOINTS.index(n) for n in ("head", "left_wrist", "right_wrist", "left_ankle", "right_ankle")):
            name = names_of(arm)[j]
            if name in strongest:
                dist.setdefault(name, []).append(float(np.linalg.norm(world[strongest[name]].mean(0) - joints[f, j])))
    worst = max((max(d) - min(d) for d in dist.values()), default=float("inf"))
    near = max((max(d) for d in dist.values()), default=float("inf"))
    return {
        "meshes": 1,
        "vertices": len(body.data.vertices),
        "armature_modifier": len(mods) == 1,
        "vertex_groups": len(groups),
        "parts_checked": sorted(dist),
        "part_to_joint_m": near,
        "part_to_joint_change_m": worst,
        "ok": len(mods) == 1 and len(groups) >= 20 and len(dist) == 5 and near < 0.2 and worst < 0.01,
    }


def check_glb(path: str, joints: np.ndarray) -> dict:
    _reset()
    bpy.ops.import_scene.gltf(filepath=path)
    arm = next(o for o in bpy.context.scene.objects if o.type == "ARMATURE")
    # Blender's glTF importer keys time t at frame t * fps (frame 0 first); BVH starts at 1
    got = _sample(arm, len(joints), 0)
    return {
        "names": "humanoid" if names_of(arm) is HUMANOID else "humanml3d",
        "bones": len(arm.pose.bones),
        "frames": len(joints),
        "max_err_mm": float(np.abs(got - joints).max() * 1000),
        "body": check_body(arm, joints),
    }


def check_bvh(path: str, joints: np.ndarray) -> dict:
    _reset()
    bpy.ops.import_anim.bvh(filepath=path, global_scale=0.01, update_scene_fps=True, update_scene_duration=True)
    arm = next(o for o in bpy.context.scene.objects if o.type == "ARMATURE")
    got = _sample(arm, len(joints), 1)
    return {"bones": len(arm.pose.bones), "frames": len(joints), "max_err_mm": float(np.abs(got - joints).max() * 1000)}


def main() -> int:
    """GLB BVH [GLB BVH ...] JOINTS.npy: every pair checked against the same joints."""
    *files, npy = sys.argv[1:]
    joints = np.load(npy).astype(np.float64)
    report: dict = {"blender": bpy.app.version_string}
    bad = False
    for glb, bvh in zip(files[::2], files[1::2], strict=True):
        r = {"glb": check_glb(glb, joints), "bvh": check_bvh(bvh, joints)}
        report[glb.rsplit("/", 1)[-1]] = r
        bad |= any(x["max_err_mm"] > 1.0 for x in r.values() if isinstance(x, dict)) or not r["glb"]["body"]["ok"]
    print(json.dumps(report))
    return int(bad)


if __name__ == "__main__":
    Vector  # noqa: B018 (mathutils must import inside Blender's Python)
    code = main()
    sys.stdout.flush()
    os._exit(code)  # bpy as a module can crash in the interpreter's teardown (4.2)
