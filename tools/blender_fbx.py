"""GLB -> FBX with Blender's own exporter, checked by importing the FBX back.

Usage (bpy is ~500 MB, so it lives in its own environment: ``bash scripts/export_fbx.sh``
sets it up):
    .venv-blender/bin/python tools/blender_fbx.py motion.glb motion.fbx [motion_joints.npy]

Imports the GLB with Blender's glTF importer (armature, skinned body, animation), writes it
with Blender's FBX exporter (baked animation, the armature's bones as FBX limbs, +Y up as
Unity and Maya expect), then reads the FBX into an empty scene and steps through every
frame. With the joints .npy it prints the largest joint error in mm and exits 1 above 1 mm.
"""

from __future__ import annotations

import json
import os
import struct
import sys

import bpy
import numpy as np


def reset(fps: int) -> None:
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.context.scene.render.fps = fps
    bpy.context.scene.render.fps_base = 1.0


def armature():
    return next(o for o in bpy.context.scene.objects if o.type == "ARMATURE")


def bone_heads(arm, names: list[str], n_frames: int, first: int) -> np.ndarray:
    """(T, J, 3) world positions of the named bones' heads, back in y-up metres."""
    out = np.zeros((n_frames, len(names), 3))
    for f in range(n_frames):
        bpy.context.scene.frame_set(first + f)
        for j, name in enumerate(names):
            p = arm.matrix_world @ arm.pose.bones[name].head
            out[f, j] = (p.x, p.z, -p.y)  # Blender is z-up: (x, y, z)_blender = (x, -z, y)_ours
    return out


def skin_joint_names(glb: str) -> list[str]:
    """The GLB's skin joints by name, in skin order (which our exports keep in the motion's
    joint order)."""
    data = open(glb, "rb").read()
    (length,) = struct.unpack_from("<I", data, 12)
    doc = json.loads(data[20 : 20 + length])
    return [doc["nodes"][n]["name"] for n in doc["skins"][0]["joints"]]


def main() -> int:
    args = sys.argv[sys.argv.index("--") + 1 :] if "--" in sys.argv else sys.argv[1:]
    glb, fbx = args[0], args[1]
    npy = args[2] if len(args) > 2 else None
    reset(20)
    bpy.ops.import_scene.gltf(filepath=glb)
    names = skin_joint_names(glb)
    meshes = [o.name for o in bpy.context.scene.objects if o.type == "MESH" and o.find_armature()]
    # the importer keys time t at frame t * fps from frame 0; the exporter bakes the scene's
    # range, which must be the action's (Blender's default 1-250 would drop frame 0)
    start, end = (round(f) for f in armature().animation_data.action.frame_range)
    bpy.context.scene.frame_start, bpy.context.scene.frame_end = start, end
    frames = end - start + 1
    # the importer's bone display shapes are not part of the motion
    for o in list(bpy.context.scene.objects):
        if o.type == "MESH" and not o.find_armature():
            bpy.data.objects.remove(o)
    bpy.ops.export_scene.fbx(
        filepath=fbx,
        use_selection=False,
        object_types={"ARMATURE", "MESH"},
        add_leaf_bones=False,
        bake_anim=True,
        bake_anim_force_startend_keying=True,
        bake_anim_simplify_factor=0.0,  # keep every frame's key: simplified curves were 1.5 mm off
        axis_forward="-Z",
        axis_up="Y",
    )
    reset(20)
    bpy.ops.import_scene.fbx(filepath=fbx, automatic_bone_orientation=False)
    arm = armature()
    first = round(arm.animation_data.action.frame_range[0])
    report = {
        "blender": bpy.app.version_string,
        "bones": len(arm.data.bones),
        "meshes": [o.name for o in bpy.context.scene.objects if o.type == "MESH" and o.find_armature()],
        "glb_meshes": meshes,
        "frames": frames,
    }
    if npy:
        joints = np.load(npy).astype(np.float64)
        got = bone_heads(arm, names, len(joints), first)
        err = np.linalg.norm(got - joints, axis=-1) * 1000
        report["max_err_mm"] = float(err.max())
        report["mean_err_mm"] = float(err.mean())
        report["worst_frame"] = int(err.max(1).argmax())
    print(json.dumps(report))
    return int(report.get("max_err_mm", 0.0) > 1.0)


if __name__ == "__main__":
    code = main()
    sys.stdout.flush()
    # bpy as a Python module can crash while the interpreter tears it down (seen with 4.2
    # after an FBX import): leave without that teardown, the work being done and printed
    os._exit(code)
