"""Animated, skinned body as binary glTF 2.0 (GLB), for the viewer, three.js and Blender.

The document is built with pygltflib's classes (nodes, skin, mesh, animation, accessors
into one binary buffer); its layout (checked with the Khronos validator, 0 errors and 0
warnings, and played by three.js's GLTFLoader and Blender's importer):

* one node per joint, nested by the skeleton's parent list, named after the joint; rest
  translation = the fitted bone offset (``ik.fit_rig``), so the rest pose is a proper rig;
* one animation, LINEAR samplers on one strictly increasing time accessor: per joint a
  ``rotation`` (fitted local rotation, quaternions kept in one hemisphere so interpolation
  takes the short way) and a ``translation`` (the exact offset from the parent in the
  parent's frame, so the animated joints land on the input positions even where a
  generated motion's bones stretch; the root's is its world position);
* a ``skin`` over the joints with inverse bind matrices, and the skinned mannequin
  (``mannequin.build_mannequin`` on the fitted rest pose, so its proportions are the
  motion's; up to 4 joints per vertex, the body's left side tinted blue and right red
  through COLOR_0) on its own scene-root node: three.js marks nodes as bones only when a
  skin lists them, and Blender imports a skin as an armature with the mesh bound to it;
* ``scenes[0].extras``: fps, frame count, the timeline's segments (text, start/end frame),
  key frames, the method, the joint names and ``body``, which three.js exposes as
  ``gltf.scene.userData``; for a motion on stairs also ``steps``, the boxes under its feet.

glTF is +Y up and in metres, as HumanML3D is, so positions are written unchanged.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pygltflib as gl
from scipy.spatial.transform import Rotation

from ..body.ik import RigFit, fit_rig
from ..body.mannequin import build_mannequin
from ..body.skeleton import HUMANML3D, Skeleton

_WIDTH = {gl.SCALAR: 1, gl.VEC3: 3, gl.VEC4: 4, gl.MAT4: 16}
_DTYPE = {gl.FLOAT: "<f4", gl.UNSIGNED_SHORT: "<u2", gl.UNSIGNED_INT: "<u4"}
SIDE_TINT = {"left": (0.30, 0.48, 0.88), "right": (0.88, 0.36, 0.30), "centre": (0.82, 0.80, 0.76)}


class _Buffer:
    """One binary buffer for a pygltflib document, and accessors into it."""

    def __init__(self, doc: gl.GLTF2) -> None:
        self.doc = doc
        self.blob = bytearray()

    def add(
        self, data: np.ndarray, kind: str, component: int = gl.FLOAT, target: int | None = None, minmax: bool = False
    ) -> int:
        arr = np.ascontiguousarray(data, dtype=_DTYPE[component])
        self.blob.extend(b"\0" * (-len(self.blob) % 4))  # accessors start 4-byte aligned
        self.doc.bufferViews.append(
            gl.BufferView(buffer=0, byteOffset=len(self.blob), byteLength=arr.nbytes, target=target)
        )
        self.blob.extend(arr.tobytes())
        flat = arr.reshape(-1, _WIDTH[kind])
        num = float if component == gl.FLOAT else int
        self.doc.accessors.append(
            gl.Accessor(
                bufferView=len(self.doc.bufferViews) - 1,
                componentType=component,
                count=int(flat.shape[0]),
                type=kind,
                min=[num(v) for v in flat.min(axis=0)] if minmax else None,
                max=[num(v) for v in flat.max(axis=0)] if minmax else None,
            )
        )
        return len(self.doc.accessors) - 1

    def finish(self) -> None:
        self.blob.extend(b"\0" * (-len(self.blob) % 4))
        self.doc.buffers = [gl.Buffer(byteLength=len(self.blob))]
        self.doc.set_binary_blob(bytes(self.blob))


def _continuous_quats(rot: np.ndarray) -> np.ndarray:
    """(T, J, 3, 3) -> (T, J, 4) xyzw quaternions, each joint's sign-flipped so neighbouring
    frames have a positive dot.

    The sign a frame gets is the running product of the signs of the raw neighbours' dots
    (one cumprod for all joints, not a Python loop per frame and joint); a dot of exactly 0
    keeps its frame unflipped, which a product cannot express, so that rare case takes the
    frame-by-frame loop."""
    T, J = rot.shape[:2]
    q = Rotation.from_matrix(rot.reshape(-1, 3, 3)).as_quat().reshape(T, J, 4)
    dots = np.einsum("tjk,tjk->tj", q[1:], q[:-1])
    if np.any(dots == 0):
        for t in range(1, T):
            flip = np.einsum("jk,jk->j", q[t], q[t - 1]) < 0
            q[t, flip] = -q[t, flip]
        return q
    sign = np.concatenate([np.ones((1, J)), np.cumprod(np.where(dots < 0, -1.0, 1.0), axis=0)])
    return q * sign[..., None]


def _side(name: str) -> str:
    n = name.lower()
    return "left" if n.startswith("left") else "right" if n.startswith("right") else "centre"


def glb_bytes(
    joints: np.ndarray,
    fps: float,
    skeleton: Skeleton = HUMANML3D,
    extras: dict[str, Any] | None = None,
    fit: RigFit | None = None,
) -> bytes:
    """GLB of a (T, J, 3) joint-position motion in metres at ``fps`` (T >= 2), the joints
    named and resting as ``skeleton`` says (``skeleton.HUMANOID`` for humanoid rig names and
    a T-pose). ``fit``: ``fit_rig(joints, skeleton)`` where the caller has it already (the
    BVH of the same motion needs the same fit)."""
    joints = np.asarray(joints, dtype=np.float64)
    T, J, _ = joints.shape
    if T < 2:
        raise ValueError("a glTF animation needs at least 2 frames")
    if fit is None:
        fit = fit_rig(joints, skeleton)
    parents = fit.parents
    rest_world = np.zeros((J, 3))
    for j, p in enumerate(parents):
        if p >= 0:
            rest_world[j] = rest_world[p] + fit.offsets[j]
    root = parents.index(-1)

    doc = gl.GLTF2(asset=gl.Asset(version="2.0", generator="motion_core.formats.gltf"))
    buf = _Buffer(doc)
    times = buf.add(np.arange(T) / fps, gl.SCALAR, minmax=True)
    anim = gl.Animation(name="motion")
    quats = _continuous_quats(fit.local_rot)
    for j in range(J):
        trans = buf.add(fit.local_trans[:, j], gl.VEC3)
        rot = buf.add(quats[:, j], gl.VEC4)
        for path, acc in (("translation", trans), ("rotation", rot)):
            anim.samplers.append(gl.AnimationSampler(input=times, output=acc, interpolation=gl.ANIM_LINEAR))
            anim.channels.append(
                gl.AnimationChannel(sampler=len(anim.samplers) - 1, target=gl.AnimationChannelTarget(node=j, path=path))
            )
    doc.animations.append(anim)

    ibm = np.tile(np.eye(4), (J, 1, 1))
    ibm[:, :3, 3] = -rest_world
    ibm_acc = buf.add(np.transpose(ibm, (0, 2, 1)), gl.MAT4)  # column-major

    body = build_mannequin(rest_world, skeleton)
    tint = np.array([SIDE_TINT[_side(skeleton.joint_names[j])] for j in range(J)])
    colour = np.einsum("vk,vkc->vc", body.weights, tint[body.joints])
    n_vert = len(body.vertices)
    attrs = gl.Attributes(
        POSITION=buf.add(body.vertices, gl.VEC3, target=gl.ARRAY_BUFFER, minmax=True),
        NORMAL=buf.add(body.normals, gl.VEC3, target=gl.ARRAY_BUFFER),
        COLOR_0=buf.add(colour, gl.VEC3, target=gl.ARRAY_BUFFER),
        JOINTS_0=buf.add(body.joints, gl.VEC4, gl.UNSIGNED_SHORT, target=gl.ARRAY_BUFFER),
        WEIGHTS_0=buf.add(body.weights, gl.VEC4, target=gl.ARRAY_BUFFER),
    )
    index_type = gl.UNSIGNED_SHORT if n_vert < 65536 else gl.UNSIGNED_INT
    indices = buf.add(body.faces.reshape(-1), gl.SCALAR, index_type, target=gl.ELEMENT_ARRAY_BUFFER)
    doc.meshes.append(gl.Mesh(name="body", primitives=[gl.Primitive(attributes=attrs, indices=indices, material=0)]))
    doc.materials.append(
        gl.Material(
            name="body",
            pbrMetallicRoughness=gl.PbrMetallicRoughness(
                baseColorFactor=[1.0, 1.0, 1.0, 1.0], metallicFactor=0.0, roughnessFactor=0.65
            ),
        )
    )
    doc.skins.append(gl.Skin(name="skeleton", joints=list(range(J)), skeleton=root, inverseBindMatrices=ibm_acc))

    for j in range(J):
        kids = [c for c, p in enumerate(parents) if p == j]
        translation = fit.root_pos[0] if parents[j] < 0 else fit.offsets[j]
        doc.nodes.append(
            gl.Node(name=skeleton.joint_names[j], translation=[float(v) for v in translation], children=kids)
        )
    doc.nodes.append(gl.Node(name="body", mesh=0, skin=0))
    doc.scenes.append(gl.Scene(name="motion", nodes=[root, J], extras={**(extras or {}), "body": "mannequin"}))
    doc.scene = 0
    buf.finish()
    return b"".join(doc.save_to_bytes())


def write_glb(path: str | Path, joints: np.ndarray, fps: float, **kw: Any) -> Path:
    path = Path(path)
    path.write_bytes(glb_bytes(joints, fps, **kw))
    return path


def read_glb_joints(data: bytes) -> tuple[np.ndarray, dict[str, Any]]:
    """Joint positions (T, J, 3) by forward kinematics of a GLB written by ``glb_bytes``,
    and its scene extras. A reader for our own files (tests, round trips), not a general
    glTF importer."""
    if data[:4] != b"glTF":
        raise ValueError("not a GLB file")
    doc = gl.GLTF2.load_from_bytes(data)
    blob = doc.binary_blob()

    def acc(i: int) -> np.ndarray:
        a = doc.accessors[i]
        v = doc.bufferViews[a.bufferView]
        width = _WIDTH[a.type]
        arr = np.frombuffer(blob, _DTYPE[a.componentType], a.count * width, (v.byteOffset or 0) + (a.byteOffset or 0))
        return arr.reshape(a.count, width) if width > 1 else arr

    skin = doc.skins[0].joints
    parent = {c: p for p, n in enumerate(doc.nodes) for c in (n.children or [])}
    anim = doc.animations[0]
    T = doc.accessors[anim.samplers[0].input].count
    trans: dict[int, np.ndarray] = {}
    quat: dict[int, np.ndarray] = {}
    for ch in anim.channels:
        out = acc(anim.samplers[ch.sampler].output).astype(np.float64)
        (trans if ch.target.path == "translation" else quat)[ch.target.node] = out
    g_rot: dict[int, np.ndarray] = {}
    g_pos: dict[int, np.ndarray] = {}
    for n in skin:  # skin lists joints parents first
        r = Rotation.from_quat(quat[n]).as_matrix() if n in quat else np.tile(np.eye(3), (T, 1, 1))
        t = trans[n]
        if n in parent and parent[n] in g_rot:
            p = parent[n]
            g_rot[n] = g_rot[p] @ r
            g_pos[n] = g_pos[p] + np.einsum("tij,tj->ti", g_rot[p], t)
        else:
            g_rot[n], g_pos[n] = r, t
    return np.stack([g_pos[n] for n in skin], axis=1), doc.scenes[0].extras or {}
