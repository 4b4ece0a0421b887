"""Skeleton registry: the one source of truth for joints, parents, offsets and chains.

Two skeletons are described:

* ``HUMANML3D``: the 22-joint SMPL-derived skeleton of HumanML3D, 20 fps, y up, metres,
  facing +z. Every module of this project (features, corpus, exports, viewer) reads its
  joint names, parents and bone lengths from here.
* ``KIT``: the 21-joint KIT-ML skeleton (12.5 fps, 251-dim features), described so that the
  readers can validate KIT directories; no model of ours is trained on it.

``raw_directions`` are the unit bone directions HumanML3D uses as the reference of its
inverse kinematics (a straight, arms-down rest pose). ``rest_offsets`` are the metric bone
vectors of our rest pose: the HumanML3D bone lengths (measured on the real fixture
``012314.npy``; every HumanML3D motion is retargeted to one skeleton, so they are the data
set's own lengths) along natural directions (hips apart and down, collars out, arms down).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np

HUMANML3D_JOINT_NAMES: tuple[str, ...] = (
    "pelvis",
    "left_hip",
    "right_hip",
    "spine1",
    "left_knee",
    "right_knee",
    "spine2",
    "left_ankle",
    "right_ankle",
    "spine3",
    "left_foot",
    "right_foot",
    "neck",
    "left_collar",
    "right_collar",
    "head",
    "left_shoulder",
    "right_shoulder",
    "left_elbow",
    "right_elbow",
    "left_wrist",
    "right_wrist",
)


@dataclass(frozen=True)
class Skeleton:
    """A kinematic tree and its conventions.

    Attributes:
        name: registry key.
        joint_names: (J,) names, index = joint id.
        parents: (J,) parent index per joint, -1 for the root.
        raw_directions: (J, 3) unit reference direction of the bone parent->joint (IK reference).
        rest_offsets: (J, 3) metric rest-pose bone vectors in metres, or None if unknown.
        chains: kinematic chains, each a list of joint ids from a chain root outwards.
        feet: ((left ankle, left toe), (right ankle, right toe)) used for foot contact.
        face_joints: (right hip, left hip, right shoulder, left shoulder) for the facing vector.
        fps: frames per second of the data set.
    """

    name: str
    joint_names: tuple[str, ...]
    parents: tuple[int, ...]
    raw_directions: np.ndarray
    chains: tuple[tuple[int, ...], ...]
    feet: tuple[tuple[int, int], tuple[int, int]]
    face_joints: tuple[int, int, int, int]
    fps: float
    rest_offsets: np.ndarray | None = field(default=None)

    @property
    def n_joints(self) -> int:
        return len(self.parents)

    @property
    def feature_dim(self) -> int:
        return feature_dim(self.n_joints)

    @property
    def bone_lengths(self) -> np.ndarray:
        """(J,) rest bone length per joint (0 for the root)."""
        if self.rest_offsets is None:
            raise ValueError(f"skeleton {self.name!r} has no metric rest offsets")
        return np.linalg.norm(self.rest_offsets, axis=-1)

    def measure_bone_lengths(self, joints: np.ndarray) -> np.ndarray:
        """Bone lengths of a motion: (..., J, 3) joints -> (..., J-1) lengths, bone j-1 = parent(j)->j."""
        child = np.arange(1, self.n_joints)
        parent = np.asarray(self.parents[1:])
        return np.linalg.norm(joints[..., child, :] - joints[..., parent, :], axis=-1)

    def index(self, joint_name: str) -> int:
        return self.joint_names.index(joint_name)

    def rest_joints(self) -> np.ndarray:
        """(J, 3) global joint positions of the rest pose, pelvis at the origin."""
        if self.rest_offsets is None:
            raise ValueError(f"skeleton {self.name!r} has no metric rest offsets")
        out = np.zeros((self.n_joints, 3))
        for j, p in enumerate(self.parents):
            if p >= 0:
                out[j] = out[p] + self.rest_offsets[j]
        return out

    def bones(self) -> list[tuple[int, int]]:
        """(parent, child) pairs, the segments a viewer draws."""
        return [(p, j) for j, p in enumerate(self.parents) if p >= 0]

    def mirror_map(self) -> np.ndarray:
        """(J,) index of each joint's left/right mirror (itself for central joints)."""
        out = np.arange(self.n_joints)
        for j, name in enumerate(self.joint_names):
            for a, b in (("left", "right"), ("right", "left")):
                if name.startswith(a):
                    out[j] = self.joint_names.index(b + name[len(a) :])
        return out


def feature_dim(n_joints: int) -> int:
    """HumanML3D-style feature size: 4 root + (J-1)*3 ric + (J-1)*6 rot + J*3 vel + 4 contacts."""
    return 4 + (n_joints - 1) * 9 + n_joints * 3 + 4


def _unit(v: list[list[float]]) -> np.ndarray:
    a = np.asarray(v, dtype=np.float64)
    n = np.linalg.norm(a, axis=-1, keepdims=True)
    return np.divide(a, n, out=np.zeros_like(a), where=n > 0)


_HML_PARENTS = (-1, 0, 0, 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 9, 9, 12, 13, 14, 16, 17, 18, 19)

# HumanML3D's IK reference directions (t2m raw offsets): x is the body's left.
_HML_RAW = _unit(
    [
        [0, 0, 0],
        [1, 0, 0],
        [-1, 0, 0],
        [0, 1, 0],
        [0, -1, 0],
        [0, -1, 0],
        [0, 1, 0],
        [0, -1, 0],
        [0, -1, 0],
        [0, 1, 0],
        [0, 0, 1],
        [0, 0, 1],
        [0, 1, 0],
        [1, 0, 0],
        [-1, 0, 0],
        [0, 0, 1],
        [0, -1, 0],
        [0, -1, 0],
        [0, -1, 0],
        [0, -1, 0],
        [0, -1, 0],
        [0, -1, 0],
    ]
)

# Bone lengths (m) of the HumanML3D target skeleton, measured on the real fixture
# new_joint_vecs/012314.npy (constant over its 170 frames to < 1e-6 m; see
# tests/test_skeleton.py, which re-measures them).
_HML_LENGTHS = np.array(
    [
        0.0,
        0.10307,
        0.10988,
        0.13157,
        0.39362,
        0.39019,
        0.14319,
        0.43243,
        0.42564,
        0.05736,
        0.14338,
        0.14942,
        0.21936,
        0.13749,
        0.14338,
        0.10304,
        0.13161,
        0.12298,
        0.25684,
        0.26309,
        0.26601,
        0.26988,
    ]
)

# Natural rest directions (standing, arms hanging slightly away from the body).
_HML_REST_DIRS = _unit(
    [
        [0, 0, 0],
        [0.55, -0.80, -0.05],  # left hip: out and down from the pelvis centre
        [-0.55, -0.80, -0.05],
        [0.0, 1.0, -0.10],  # spine1
        [0.0, -1.0, 0.0],  # left knee
        [0.0, -1.0, 0.0],
        [0.0, 1.0, 0.05],  # spine2
        [0.0, -1.0, -0.03],  # left ankle
        [0.0, -1.0, -0.03],
        [0.0, 1.0, 0.0],  # spine3
        [0.0, -0.45, 1.0],  # left toe: forward and a little down to the floor
        [0.0, -0.45, 1.0],
        [0.0, 1.0, 0.05],  # neck
        [0.6, 0.8, 0.0],  # left collar: up and out from spine3
        [-0.6, 0.8, 0.0],
        [0.0, 1.0, 0.25],  # head
        [1.0, -0.15, 0.0],  # left shoulder (collar -> shoulder joint)
        [-1.0, -0.15, 0.0],
        [0.12, -1.0, 0.0],  # left elbow
        [-0.12, -1.0, 0.0],
        [0.05, -1.0, 0.08],  # left wrist
        [-0.05, -1.0, 0.08],
    ]
)

HUMANML3D = Skeleton(
    name="humanml3d",
    joint_names=HUMANML3D_JOINT_NAMES,
    parents=_HML_PARENTS,
    raw_directions=_HML_RAW,
    chains=(
        (0, 2, 5, 8, 11),
        (0, 1, 4, 7, 10),
        (0, 3, 6, 9, 12, 15),
        (9, 14, 17, 19, 21),
        (9, 13, 16, 18, 20),
    ),
    feet=((7, 10), (8, 11)),
    face_joints=(2, 1, 17, 16),
    fps=20.0,
    rest_offsets=_HML_REST_DIRS * _HML_LENGTHS[:, None],
)

KIT_JOINT_NAMES: tuple[str, ...] = (
    "root",
    "torso",
    "chest",
    "neck",
    "head",
    "right_shoulder",
    "right_elbow",
    "right_wrist",
    "left_shoulder",
    "left_elbow",
    "left_wrist",
    "right_hip",
    "right_knee",
    "right_ankle",
    "right_heel",
    "right_toe",
    "left_hip",
    "left_knee",
    "left_ankle",
    "left_heel",
    "left_toe",
)

KIT = Skeleton(
    name="kit",
    joint_names=KIT_JOINT_NAMES,
    parents=(-1, 0, 1, 2, 3, 3, 5, 6, 3, 8, 9, 0, 11, 12, 13, 14, 0, 16, 17, 18, 19),
    raw_directions=_unit(
        [
            [0, 0, 0],
            [0, 1, 0],
            [0, 1, 0],
            [0, 1, 0],
            [0, 1, 0],
            [1, 0, 0],
            [0, -1, 0],
            [0, -1, 0],
            [-1, 0, 0],
            [0, -1, 0],
            [0, -1, 0],
            [1, 0, 0],
            [0, -1, 0],
            [0, -1, 0],
            [0, 0, 1],
            [0, 0, 1],
            [-1, 0, 0],
            [0, -1, 0],
            [0, -1, 0],
            [0, 0, 1],
            [0, 0, 1],
        ]
    ),
    chains=(
        (0, 11, 12, 13, 14, 15),
        (0, 16, 17, 18, 19, 20),
        (0, 1, 2, 3, 4),
        (3, 5, 6, 7),
        (3, 8, 9, 10),
    ),
    feet=((19, 20), (14, 15)),
    face_joints=(11, 16, 5, 8),
    fps=12.5,
)

SKELETONS: dict[str, Skeleton] = {"humanml3d": HUMANML3D, "kit": KIT}


def get_skeleton(name: str) -> Skeleton:
    try:
        return SKELETONS[name]
    except KeyError:
        raise ValueError(f"unknown skeleton {name!r}; known: {sorted(SKELETONS)}") from None


# ---------------------------------------------------------------- humanoid rig names
# The joint names the common humanoid rigs use (Mixamo's, without its "mixamorig:" prefix),
# so that retargeting tools (Blender add-ons, Unity's Humanoid avatar, Mixamo pipelines)
# map the bones by name. HumanML3D's "left" is the body's left, as Mixamo's is.
HUMANOID_NAMES: dict[str, str] = {
    "pelvis": "Hips",
    "left_hip": "LeftUpLeg",
    "right_hip": "RightUpLeg",
    "spine1": "Spine",
    "left_knee": "LeftLeg",
    "right_knee": "RightLeg",
    "spine2": "Spine1",
    "left_ankle": "LeftFoot",
    "right_ankle": "RightFoot",
    "spine3": "Spine2",
    "left_foot": "LeftToeBase",
    "right_foot": "RightToeBase",
    "neck": "Neck",
    "left_collar": "LeftShoulder",
    "right_collar": "RightShoulder",
    "head": "Head",
    "left_shoulder": "LeftArm",
    "right_shoulder": "RightArm",
    "left_elbow": "LeftForeArm",
    "right_elbow": "RightForeArm",
    "left_wrist": "LeftHand",
    "right_wrist": "RightHand",
}


def _t_pose(sk: Skeleton) -> np.ndarray:
    """Rest offsets with both arms straight out to the sides (a T-pose), lengths kept: the
    rest pose humanoid retargeting expects (HumanML3D's own rest pose has the arms down)."""
    off = np.array(sk.rest_offsets, dtype=np.float64)
    for side, x in (("left", 1.0), ("right", -1.0)):  # the body's left is +x, facing +z
        for joint in ("shoulder", "elbow", "wrist"):  # the bones collar->shoulder->elbow->wrist
            j = sk.index(f"{side}_{joint}")
            off[j] = np.array([x, 0.0, 0.0]) * np.linalg.norm(off[j])
    return off


# The HumanML3D skeleton as a humanoid rig: the same joints, parents and bone lengths, named as
# above, resting in a T-pose. Exports take it as ``skeleton=HUMANOID`` (motions stay in
# HumanML3D joint order; only names and the rest pose the rotations refer to change).
HUMANOID = dataclasses.replace(
    HUMANML3D,
    name="humanoid",
    joint_names=tuple(HUMANOID_NAMES[n] for n in HUMANML3D_JOINT_NAMES),
    rest_offsets=_t_pose(HUMANML3D),
)
SKELETONS["humanoid"] = HUMANOID
