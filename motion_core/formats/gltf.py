"""Animated skeleton as binary glTF 2.0 (GLB), for the viewer, three.js and Blender.

Layout (checked with the Khronos validator, 0 errors, and played by three.js's GLTFLoader):

* one node per joint, nested by the skeleton's parent list, named after the joint; rest
  translation = the fitted bone offset (``ik.fit_rig``), so the rest pose is a proper rig;
* one animation, LINEAR samplers on one strictly increasing time accessor: per joint a
  ``rotation`` (fitted local rotation, quaternions kept in one hemisphere so interpolation
  takes the short way) and a ``translation`` (the exact offset from the parent in the
  parent's frame, so the animated joints land on the input positions even where a
  generated motion's bones stretch; the root's is its world position);
* a ``skin`` over the joints with inverse bind matrices, and a small skinned mesh (a box
  per bone, rigidly bound to the bone's parent joint) on its own scene-root node: three.js
  marks nodes as bones only when a skin lists them, and Blender imports a skin as an
  armature;
* ``scenes[0].extras``: fps, frame count, the timeline's segments (text, start/end frame),
  key frames and the method, which three.js exposes as ``gltf.scene.userData``.

glTF is +Y up and in metres, as HumanML3D is, so positions are written unchanged.
"""

from __future__ import annotations

import json
import struct
from pathlib import Path
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

from ..body.ik import fit_rig
from ..body.skeleton import HUMANML3D, Skeleton

_FLOAT, _USHORT, _UINT = 5126, 5123, 5125
_ARRAY_BUFFER, _ELEMENT_ARRAY_BUFFER = 34962, 34963


class _Builder:
    """Accumulates one binary buffer and the accessors into it."""

    def __init__(self) -> None:
        self.blob = bytearray()
        self.views: list[dict[str, Any]] = []
        self.accessors: list[dict[str, Any]] = []

    def add(
        self,
        data: np.ndarray,
        kind: str,
        component: int = _FLOAT,
        target: int | None = None,
        minmax: bool = False,
    ) -> int:
        dtype = {_FLOAT: "<f4", _USHORT: "<u2", _UINT: "<u4"}[component]
        arr = np.ascontiguousarray(data, dtype=dtype)
        while len(self.blob) % 4:
            self.blob.append(0)
        view: dict[str, Any] = {"buffer": 0, "byteOffset": len(self.blob), "byteLength": arr.nbytes}
        if target is not None:
            view["target"] = target
        self.blob.extend(arr.tobytes())
        self.views.append(view)
        width = {"SCALAR": 1, "VEC3": 3, "VEC4": 4, "MAT4": 16}[kind]
        flat = arr.reshape(-1, width)
        acc: dict[str, Any] = {
            "bufferView": len(self.views) - 1,
            "componentType": component,
            "count": int(flat.shape[0]),
            "type": kind,
        }
        if minmax:
            acc["min"] = [float(v) if component == _FLOAT else int(v) for v in flat.min(axis=0)]
            acc["max"] = [float(v) if component == _FLOAT else int(v) for v in flat.max(axis=0)]
        self.accessors.append(acc)
        return len(self.accessors) - 1


def _bone_boxes(
    rest_world: np.ndarray, parents: tuple[int, ...], radius: float = 0.025
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """A box around every bone, bound to the bone's parent joint.

    Returns positions (V, 3), normals (V, 3), joint index per vertex (V,), triangles (F*3,).
    """
    pos, nrm, jnt, idx = [], [], [], []
    for c, p in enumerate(parents):
        if p < 0:
            continue
        a, b = rest_world[p], rest_world[c]
        axis = b - a
        length = np.linalg.norm(axis)
        if length < 1e-6:
            continue
        w = axis / length
        u = np.cross(w, [0.0, 0.0, 1.0] if abs(w[1]) > 0.9 else [0.0, 1.0, 0.0])
        u /= np.linalg.norm(u)
        v = np.cross(w, u)
        r = radius * (0.6 if length < 0.15 else 1.0)
        frame = np.stack([u * r, v * r, axis], axis=0)  # box = a + frame.T @ (s, t, h), s,t in +-1, h in 0..1
        lo = np.array([-1.0, -1.0, 0.0])
        for k in range(3):  # the face pair normal to frame axis k
            others = [i for i in range(3) if i != k]
            for side in (0, 1):
                base = len(pos)
                corners = []
                for c1, c2 in ((0, 0), (1, 0), (1, 1), (0, 1)):
                    coef = lo.copy()
                    coef[k] = 1.0 if side else lo[k]
                    coef[others[0]] = 1.0 if c1 else lo[others[0]]
                    coef[others[1]] = 1.0 if c2 else lo[others[1]]
                    corners.append(a + coef @ frame)
                n = frame[k] / np.linalg.norm(frame[k]) * (1 if side else -1)
                # wind counter-clockwise seen from outside (along +n)
                if np.dot(np.cross(corners[1] - corners[0], corners[2] - corners[0]), n) < 0:
                    corners = corners[::-1]
                pos.extend(corners)
                nrm.extend([n] * 4)
                jnt.extend([p] * 4)
                idx.extend([base, base + 1, base + 2, base, base + 2, base + 3])
    return np.array(pos), np.array(nrm), np.array(jnt), np.array(idx)


def _continuous_quats(rot: np.ndarray) -> np.ndarray:
    """(T, 3, 3) -> (T, 4) xyzw quaternions, sign-flipped so neighbours have a positive dot."""
    q = Rotation.from_matrix(rot).as_quat()
    for t in range(1, len(q)):
        if np.dot(q[t], q[t - 1]) < 0:
            q[t] = -q[t]
    return q


def glb_bytes(
    joints: np.ndarray,
    fps: float,
    skeleton: Skeleton = HUMANML3D,
    extras: dict[str, Any] | None = None,
) -> bytes:
    """GLB of a (T, J, 3) joint-position motion in metres at ``fps`` (T >= 2)."""
    joints = np.asarray(joints, dtype=np.float64)
    T, J, _ = joints.shape
    if T < 2:
        raise ValueError("a glTF animation needs at least 2 frames")
    fit = fit_rig(joints, skeleton)
    parents = fit.parents
    rest_world = np.zeros((J, 3))
    for j, p in enumerate(parents):
        if p >= 0:
            rest_world[j] = rest_world[p] + fit.offsets[j]

    g = _Builder()
    times = g.add(np.arange(T) / fps, "SCALAR", minmax=True)
    samplers, channels = [], []
    for j in range(J):
        trans = g.add(fit.local_trans[:, j], "VEC3")
        rot = g.add(_continuous_quats(fit.local_rot[:, j]), "VEC4")
        for path, acc in (("translation", trans), ("rotation", rot)):
            samplers.append({"input": times, "output": acc, "interpolation": "LINEAR"})
            channels.append({"sampler": len(samplers) - 1, "target": {"node": j, "path": path}})

    ibm = np.tile(np.eye(4), (J, 1, 1))
    ibm[:, :3, 3] = -rest_world
    ibm_acc = g.add(np.transpose(ibm, (0, 2, 1)), "MAT4")  # column-major

    pos, nrm, jnt, idx = _bone_boxes(rest_world, parents)
    joints4 = np.zeros((len(pos), 4), dtype=np.uint16)
    joints4[:, 0] = jnt
    weights4 = np.zeros((len(pos), 4))
    weights4[:, 0] = 1.0
    attrs = {
        "POSITION": g.add(pos, "VEC3", target=_ARRAY_BUFFER, minmax=True),
        "NORMAL": g.add(nrm, "VEC3", target=_ARRAY_BUFFER),
        "JOINTS_0": g.add(joints4, "VEC4", _USHORT, target=_ARRAY_BUFFER),
        "WEIGHTS_0": g.add(weights4, "VEC4", target=_ARRAY_BUFFER),
    }
    indices = g.add(idx, "SCALAR", _USHORT if len(pos) < 65536 else _UINT, target=_ELEMENT_ARRAY_BUFFER)

    nodes: list[dict[str, Any]] = []
    for j in range(J):
        node: dict[str, Any] = {"name": skeleton.joint_names[j]}
        node["translation"] = [float(v) for v in (fit.root_pos[0] if parents[j] < 0 else fit.offsets[j])]
        kids = [c for c, p in enumerate(parents) if p == j]
        if kids:
            node["children"] = kids
        nodes.append(node)
    nodes.append({"name": "body", "mesh": 0, "skin": 0})
    root = parents.index(-1)

    doc: dict[str, Any] = {
        "asset": {"version": "2.0", "generator": "motion_core.export_gltf"},
        "scene": 0,
        "scenes": [{"name": "motion", "nodes": [root, J], "extras": extras or {}}],
        "nodes": nodes,
        "meshes": [
            {
                "name": "bones",
                "primitives": [{"attributes": attrs, "indices": indices, "material": 0}],
            }
        ],
        "materials": [
            {
                "name": "bone",
                "pbrMetallicRoughness": {
                    "baseColorFactor": [0.85, 0.55, 0.25, 1.0],
                    "metallicFactor": 0.0,
                    "roughnessFactor": 0.7,
                },
            }
        ],
        "skins": [{"name": "skeleton", "joints": list(range(J)), "skeleton": root, "inverseBindMatrices": ibm_acc}],
        "animations": [{"name": "motion", "samplers": samplers, "channels": channels}],
        "buffers": [{"byteLength": len(g.blob)}],
        "bufferViews": g.views,
        "accessors": g.accessors,
    }
    js = json.dumps(doc, separators=(",", ":")).encode()
    js += b" " * (-len(js) % 4)
    bin_ = bytes(g.blob) + b"\0" * (-len(g.blob) % 4)
    total = 12 + 8 + len(js) + 8 + len(bin_)
    return (
        struct.pack("<4sII", b"glTF", 2, total)
        + struct.pack("<I4s", len(js), b"JSON")
        + js
        + struct.pack("<I4s", len(bin_), b"BIN\0")
        + bin_
    )


def write_glb(path: str | Path, joints: np.ndarray, fps: float, **kw: Any) -> Path:
    path = Path(path)
    path.write_bytes(glb_bytes(joints, fps, **kw))
    return path


def read_glb_joints(data: bytes) -> tuple[np.ndarray, dict[str, Any]]:
    """Joint positions (T, J, 3) by forward kinematics of a GLB written by ``glb_bytes``.

    A reader for our own files (tests, round trips), not a general glTF importer.
    """
    magic, _, _ = struct.unpack_from("<4sII", data, 0)
    if magic != b"glTF":
        raise ValueError("not a GLB file")
    jlen, _ = struct.unpack_from("<I4s", data, 12)
    doc = json.loads(data[20 : 20 + jlen])
    blen, _ = struct.unpack_from("<I4s", data, 20 + jlen)
    blob = data[28 + jlen : 28 + jlen + blen]

    def acc(i: int) -> np.ndarray:
        a = doc["accessors"][i]
        v = doc["bufferViews"][a["bufferView"]]
        width = {"SCALAR": 1, "VEC3": 3, "VEC4": 4, "MAT4": 16}[a["type"]]
        dt = {_FLOAT: "<f4", _USHORT: "<u2", _UINT: "<u4"}[a["componentType"]]
        arr = np.frombuffer(blob, dt, a["count"] * width, v.get("byteOffset", 0))
        return arr.reshape(a["count"], width) if width > 1 else arr

    skin = doc["skins"][0]["joints"]
    parent = {c: p for p, n in enumerate(doc["nodes"]) for c in n.get("children", [])}
    anim = doc["animations"][0]
    T = doc["accessors"][anim["samplers"][0]["input"]]["count"]
    trans: dict[int, np.ndarray] = {}
    quat: dict[int, np.ndarray] = {}
    for ch in anim["channels"]:
        out = acc(anim["samplers"][ch["sampler"]]["output"]).astype(np.float64)
        (trans if ch["target"]["path"] == "translation" else quat)[ch["target"]["node"]] = out
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
    return np.stack([g_pos[n] for n in skin], axis=1), doc["scenes"][0].get("extras", {})
