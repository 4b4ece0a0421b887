"""Retargeting a BVH skeleton onto the HumanML3D 22-joint skeleton.

``retarget(bvh, joint_map)``:

1. forward kinematics of the file, in metres (unit detected or given), resampled to 20 fps;
2. the joint map picks, for every HumanML3D joint, a BVH joint, or a point along a BVH
   chain where the joint counts differ: HumanML3D has three spine joints between pelvis and
   neck, the Bandai Namco skeleton two (Spine, Chest), so spine1..3 are placed along the
   polyline Hips -> Spine -> Chest -> Neck at the arc-length fractions where the HumanML3D
   rest skeleton has them;
3. ``ik.rigidify``: the mapped joints' directions are kept and every bone gets the
   HumanML3D rest length (our proportions, whoever was captured);
4. ``features.canonicalize``: lowest joint over the clip on the floor (y = 0), root at the
   origin, facing +z at the first frame.

The result goes through ``features.joints_to_features`` like any corpus clip. A skeleton
that lacks a mapped joint raises ``RetargetError`` naming every missing joint.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..body.features import canonicalize
from ..body.ik import rigidify
from ..body.skeleton import HUMANML3D, Skeleton
from .bvh import Bvh, bvh_positions_m


class RetargetError(ValueError):
    """The BVH skeleton cannot be mapped (the message names the missing joints)."""


@dataclass(frozen=True)
class JointMap:
    """How one BVH skeleton maps onto HumanML3D.

    Attributes:
        name: the skeleton's name, for messages.
        direct: HumanML3D joint -> BVH joint placed exactly there.
        spine_chain: BVH joints from the pelvis joint to the neck joint (inclusive); the
            HumanML3D spine joints not in ``direct`` are interpolated along it.
    """

    name: str
    direct: dict[str, str]
    spine_chain: tuple[str, ...] = ()
    interpolated: tuple[str, ...] = field(default=("spine1", "spine2", "spine3"))

    def required(self) -> set[str]:
        return set(self.direct.values()) | set(self.spine_chain)


def _sided(hml: str, bvh: str) -> dict[str, str]:
    return {f"left_{hml}": f"{bvh}_L", f"right_{hml}": f"{bvh}_R"}


BANDAI_NAMCO = JointMap(
    name="Bandai Namco Research Motion",
    direct={
        "pelvis": "Hips",
        "neck": "Neck",
        "head": "Head",
        **_sided("hip", "UpperLeg"),
        **_sided("knee", "LowerLeg"),
        **_sided("ankle", "Foot"),
        **_sided("foot", "Toes"),
        **_sided("collar", "Shoulder"),
        **_sided("shoulder", "UpperArm"),
        **_sided("elbow", "LowerArm"),
        **_sided("wrist", "Hand"),
    },
    spine_chain=("Hips", "Spine", "Chest", "Neck"),
)


def _rest_spine_fractions(skeleton: Skeleton, names: tuple[str, ...]) -> np.ndarray:
    """Arc-length fraction of each of ``names`` along pelvis -> ... -> neck in the rest pose."""
    chain = ["pelvis", *names, "neck"]
    lengths = [skeleton.bone_lengths[skeleton.index(n)] for n in chain[1:]]
    return np.cumsum(lengths)[:-1] / np.sum(lengths)


def _along(points: np.ndarray, fractions: np.ndarray) -> np.ndarray:
    """Points at arc-length ``fractions`` of the polylines points (T, K, 3) -> (T, F, 3)."""
    seg = np.linalg.norm(np.diff(points, axis=1), axis=-1)  # (T, K-1)
    cum = np.concatenate([np.zeros((len(points), 1)), np.cumsum(seg, axis=1)], axis=1)
    out = np.empty((len(points), len(fractions), 3))
    for i, f in enumerate(fractions):
        target = f * cum[:, -1]
        k = np.clip((cum[:, 1:] < target[:, None]).sum(axis=1), 0, seg.shape[1] - 1)
        rows = np.arange(len(points))
        w = ((target - cum[rows, k]) / np.maximum(seg[rows, k], 1e-9))[:, None]
        out[:, i] = points[rows, k] * (1 - w) + points[rows, k + 1] * w
    return out


def map_joints(
    positions: np.ndarray, names: list[str], joint_map: JointMap = BANDAI_NAMCO, skeleton: Skeleton = HUMANML3D
) -> np.ndarray:
    """(T, J_bvh, 3) positions named ``names`` -> (T, 22, 3) HumanML3D joints (not yet rigid)."""
    missing = sorted(joint_map.required() - set(names))
    if missing:
        raise RetargetError(f"the skeleton lacks joints the {joint_map.name} map needs: {', '.join(missing)}")
    out = np.full((positions.shape[0], skeleton.n_joints, 3), np.nan)
    for hml, src in joint_map.direct.items():
        out[:, skeleton.index(hml)] = positions[:, names.index(src)]
    if joint_map.spine_chain:
        chain = positions[:, [names.index(n) for n in joint_map.spine_chain]]
        fr = _rest_spine_fractions(skeleton, joint_map.interpolated)
        pts = _along(chain, fr)
        for i, hml in enumerate(joint_map.interpolated):
            out[:, skeleton.index(hml)] = pts[:, i]
    unmapped = [skeleton.joint_names[j] for j in range(skeleton.n_joints) if np.isnan(out[0, j, 0])]
    if unmapped:
        raise RetargetError(f"the {joint_map.name} map leaves HumanML3D joints unmapped: {', '.join(unmapped)}")
    return out


def retarget(
    bvh: Bvh,
    joint_map: JointMap = BANDAI_NAMCO,
    fps: float = 20.0,
    unit: str | None = None,
    skeleton: Skeleton = HUMANML3D,
) -> np.ndarray:
    """A BVH clip as HumanML3D joints: (T, 22, 3) float64 metres at ``fps``, canonical."""
    pos = bvh_positions_m(bvh, fps=fps, unit=unit)
    mapped = map_joints(pos, bvh.names, joint_map, skeleton)
    return canonicalize(rigidify(mapped, skeleton).astype(np.float64), skeleton)
