"""Blender's own render of one of our GLBs, mid-motion: the imported armature and its skinned
body, lit, on a floor, seen from the front-left.

    .venv-blender/bin/python tools/blender_render.py motion.glb out.png [seconds]

Cycles on the CPU (headless bpy has no GPU context for Eevee), 24 samples, 960 x 640.
"""

from __future__ import annotations

import math
import os
import sys

import bpy
from mathutils import Vector


def main() -> int:
    glb, png = sys.argv[1], sys.argv[2]
    seconds = float(sys.argv[3]) if len(sys.argv) > 3 else None
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.fps = 20
    bpy.ops.import_scene.gltf(filepath=glb)
    arm = next(o for o in scene.objects if o.type == "ARMATURE")
    for o in list(scene.objects):  # the importer's bone display shapes
        if o.type == "MESH" and not o.find_armature():
            bpy.data.objects.remove(o)
    start, end = arm.animation_data.action.frame_range
    frame = round(seconds * 20) if seconds is not None else int((start + end) / 2)
    scene.frame_set(frame)
    pelvis = arm.matrix_world @ arm.pose.bones[0].head

    bpy.ops.mesh.primitive_plane_add(size=30, location=(pelvis.x, pelvis.y, 0))
    floor = bpy.context.object
    mat = bpy.data.materials.new("floor")
    mat.use_nodes = True
    mat.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (0.93, 0.91, 0.86, 1)
    floor.data.materials.append(mat)

    target = Vector((pelvis.x, pelvis.y, 0.9))
    cam_data = bpy.data.cameras.new("camera")
    cam_data.lens = 45
    cam = bpy.data.objects.new("camera", cam_data)
    scene.collection.objects.link(cam)
    # front-left of the body, which faces -y in Blender's frame (+z in ours)
    cam.location = target + Vector((-2.6, -4.2, 0.9))
    cam.rotation_euler = (target - cam.location).to_track_quat("-Z", "Y").to_euler()
    scene.camera = cam

    sun_data = bpy.data.lights.new("sun", type="SUN")
    sun_data.energy = 3.5
    sun = bpy.data.objects.new("sun", sun_data)
    sun.rotation_euler = (math.radians(50), 0, math.radians(-35))
    scene.collection.objects.link(sun)
    world = bpy.data.worlds.new("world")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.95, 0.94, 0.92, 1)
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.8
    scene.world = world

    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = 24
    scene.render.resolution_x, scene.render.resolution_y = 960, 640
    scene.render.filepath = png
    bpy.ops.render.render(write_still=True)
    print(f"rendered frame {frame} of {int(start)}-{int(end)} to {png}")
    return 0


if __name__ == "__main__":
    code = main()
    sys.stdout.flush()
    os._exit(code)  # bpy as a module can crash in the interpreter's teardown (4.2)
