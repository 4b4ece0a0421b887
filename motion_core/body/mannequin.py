"""A low-poly skinned mannequin for the 22-joint skeleton, built procedurally with trimesh.

The body is a union of rounded parts (capsules for the limbs, spine, neck and feet, spheres
for the head and hands) placed on a motion's rest joints, so its proportions follow that
motion's bones. The union (``trimesh.boolean.union`` with the manifold engine) makes it one
watertight mesh. Each vertex is then bound to up to 4 joints with smooth linear-blend
weights: a part is driven by the joint whose rotation moves it (a thigh by the hip, a shin
by the knee), and a vertex near a joint, equally close to the parts on either side, blends
them, so elbows and knees bend without tearing.
"""

from __future__ import annotations

import dataclasses
import functools
from dataclasses import dataclass

import numpy as np
import trimesh

from .skeleton import HUMANML3D, Skeleton, get_skeleton

# radius (m) of the part between a joint and its parent, by the child joint's name
BONE_RADIUS = {
    "left_hip": 0.085,
    "right_hip": 0.085,
    "spine1": 0.11,
    "spine2": 0.115,
    "spine3": 0.12,
    "left_knee": 0.068,
    "right_knee": 0.068,
    "left_ankle": 0.05,
    "right_ankle": 0.05,
    "left_foot": 0.038,
    "right_foot": 0.038,
    "neck": 0.05,
    "left_collar": 0.05,
    "right_collar": 0.05,
    "head": 0.05,
    "left_shoulder": 0.055,
    "right_shoulder": 0.055,
    "left_elbow": 0.046,
    "right_elbow": 0.046,
    "left_wrist": 0.038,
    "right_wrist": 0.038,
}
HEAD_RADIUS = 0.1
HAND = (0.08, 0.035)  # length beyond the wrist along the forearm, radius


@dataclass(frozen=True)
class Mannequin:
    """A skinned mesh in the rest pose it was built on.

    Attributes:
        vertices: (V, 3) float32 metres.
        normals: (V, 3) float32 unit vertex normals.
        faces: (F, 3) uint32 triangles, counter-clockwise seen from outside.
        joints: (V, 4) uint16 skeleton joint indices bound to each vertex.
        weights: (V, 4) float32, each row summing to 1 (unused slots 0).
    """

    vertices: np.ndarray
    normals: np.ndarray
    faces: np.ndarray
    joints: np.ndarray
    weights: np.ndarray


@dataclass(frozen=True)
class _Part:
    a: np.ndarray  # (3,) segment start
    b: np.ndarray  # (3,) segment end (== a for a sphere)
    radius: float
    joint: int  # the joint whose rotation moves it


def _parts(rest: np.ndarray, skeleton: Skeleton) -> list[_Part]:
    # the body's parts are those of the HumanML3D joints, whatever the rig calls them
    # (skeleton.HUMANOID has the same joints in the same order, named as humanoid rigs are)
    names = HUMANML3D.joint_names if skeleton.parents == HUMANML3D.parents else skeleton.joint_names
    parts = []
    for c, p in enumerate(skeleton.parents):
        if p < 0:
            continue
        parts.append(_Part(rest[p], rest[c], BONE_RADIUS[names[c]], p))
    head = names.index("head")
    up = rest[head] - rest[skeleton.parents[head]]
    up /= np.linalg.norm(up)
    centre = rest[head] + 0.5 * HEAD_RADIUS * up
    parts.append(_Part(centre, centre, HEAD_RADIUS, head))
    for side in ("left", "right"):
        wrist = names.index(f"{side}_wrist")
        along = rest[wrist] - rest[skeleton.parents[wrist]]
        along /= np.linalg.norm(along)
        parts.append(_Part(rest[wrist], rest[wrist] + HAND[0] * along, HAND[1], wrist))
    return parts


def _solid(part: _Part) -> trimesh.Trimesh:
    length = float(np.linalg.norm(part.b - part.a))
    if length < 1e-6:
        m = trimesh.creation.icosphere(subdivisions=2, radius=part.radius)
        m.apply_translation(part.a)
        return m
    m = trimesh.creation.capsule(height=length, radius=part.radius, count=[10, 6])
    # trimesh's capsule runs along +z from -h/2 to +h/2
    m.apply_transform(trimesh.geometry.align_vectors([0, 0, 1], (part.b - part.a) / length))
    m.apply_translation((part.a + part.b) / 2)
    return m


def _segment_distance(x: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(V,) distance of points x (V, 3) to the segment a-b."""
    ab = b - a
    denom = float(ab @ ab)
    t = np.zeros(len(x)) if denom < 1e-12 else np.clip((x - a) @ ab / denom, 0.0, 1.0)
    return np.linalg.norm(x - (a + t[:, None] * ab), axis=-1)


def skin_weights(
    vertices: np.ndarray, parts: list[_Part], n_joints: int, falloff: float = 0.01
) -> tuple[np.ndarray, np.ndarray]:
    """(V, 4) joints and weights: each part pulls a vertex by exp(-(distance to its surface
    - the nearest part's) / falloff), summed per driving joint; the 4 strongest joints kept
    and normalised."""
    surf = np.stack([_segment_distance(vertices, p.a, p.b) - p.radius for p in parts], 1)  # (V, P)
    pull = np.exp(-(surf - surf.min(1, keepdims=True)) / falloff)
    per_joint = np.zeros((len(vertices), n_joints))
    for k, p in enumerate(parts):
        per_joint[:, p.joint] += pull[:, k]
    top = np.argsort(-per_joint, axis=1)[:, :4]
    w = np.take_along_axis(per_joint, top, 1)
    w[w < 1e-3 * w[:, :1]] = 0.0  # negligible pulls: fewer influences, same shape
    w /= w.sum(1, keepdims=True)
    top[w == 0] = 0
    return top.astype(np.uint16), w.astype(np.float32)


def build_mannequin(rest_joints: np.ndarray, skeleton: Skeleton = HUMANML3D) -> Mannequin:
    """The mannequin on rest joint positions (J, 3), metres, y up.

    The body is built once per skeleton, on its own rest pose (building takes about 0.2 s,
    the rest of an export a few tens of ms), and then fitted to ``rest_joints`` by its own
    skin: each vertex moves by the weighted displacement of its joints. Every joint of the
    body lands exactly on the motion's, and the parts between stretch or shrink with them.
    """
    base = _build(skeleton.name)
    shift = np.asarray(rest_joints, np.float64) - skeleton.rest_joints()  # (J, 3)
    moved = base.vertices + np.einsum("vk,vkc->vc", base.weights, shift[base.joints]).astype(np.float32)
    moved.flags.writeable = False
    return dataclasses.replace(base, vertices=moved)


@functools.lru_cache(maxsize=4)
def _build(skeleton_name: str) -> Mannequin:
    skeleton = get_skeleton(skeleton_name)
    rest = skeleton.rest_joints()
    parts = _parts(rest, skeleton)
    body = trimesh.boolean.union([_solid(p) for p in parts], engine="manifold")
    joints, weights = skin_weights(body.vertices, parts, len(skeleton.joint_names))
    arrays = {
        "vertices": body.vertices.astype(np.float32),
        "normals": body.vertex_normals.astype(np.float32),
        "faces": body.faces.astype(np.uint32),
        "joints": joints,
        "weights": weights,
    }
    for a in arrays.values():
        a.flags.writeable = False  # cached and shared between exports
    return Mannequin(**arrays)
