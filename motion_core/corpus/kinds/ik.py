"""Hands where they must be: analytic arm IK onto the rig's arm channels.

The rig drives arms by channels (flex, abduct, elbow, twist; see ``rig.arm_directions``).
Kinds that put a hand somewhere (on the floor, on the head, on a hip) solve those channels
from a wrist target: the elbow angle from the distance (law of cosines), the elbow's place on
its circle from a pole direction (where the elbow should point), then flex and abduct from
the upper arm's direction and twist from the forearm's. The solution is exact wherever the
target is reachable; an out-of-reach target gets the straight arm pointing at it.

Targets are solved on the final channels (``Timeline.finishers``), so the clip's natural
variation and the path are already in and the hand lands where it was put.
"""

from __future__ import annotations

import numpy as np

from ..rig import FOREARM, SIGN, UPPER_ARM, Channels, J, _pelvis_frame, pose, rot_x, rot_y, rot_z, two_bone_ik

SIDE_NAME = {"l": "left", "r": "right"}
MAX_ELBOW = np.radians(150.0)


def chest_frame(ch: Channels) -> np.ndarray:
    """(T, 3, 3) rotation of spine3 (the frame the arms and the head hang from), as rig.pose has it."""

    def seg(k: float) -> np.ndarray:
        return rot_x(ch.spine_bend * k) @ rot_z(-ch.spine_side * k) @ rot_y(ch.spine_twist * k)

    return _pelvis_frame(ch) @ seg(0.3) @ seg(0.35) @ seg(0.35)


def body_axes(ch: Channels) -> tuple[np.ndarray, np.ndarray]:
    """(T, 3) world forward and left of the path heading (horizontal)."""
    h = ch.heading
    z = np.zeros_like(h)
    return np.stack([np.sin(h), z, np.cos(h)], -1), np.stack([np.cos(h), z, -np.sin(h)], -1)


def solve_arm(
    target: np.ndarray, pole: np.ndarray, side: str, twist_hint: np.ndarray | None = None
) -> dict[str, np.ndarray]:
    """Arm channels putting the wrist at ``target`` (T, 3), given in the chest frame relative to
    the shoulder, with the elbow towards ``pole`` (T, 3) or (3,), chest frame."""
    i = 0 if side == "l" else 1
    U, F = UPPER_ARM[i], FOREARM[i]
    T = len(target)
    pole = np.broadcast_to(np.asarray(pole, dtype=float), (T, 3))
    elbow_pos, wrist, _ = two_bone_ik(np.zeros_like(target), target, pole, U, F, MAX_ELBOW, 0.9995)
    d = elbow_pos / U
    f = (wrist - elbow_pos) / F
    sg = SIGN[side]
    # d = (sin b, -cos(flex) cos b, sin(flex) cos b) with b = sg * abduct (rig.arm_directions).
    b = np.arcsin(np.clip(d[:, 0], -1, 1))
    flex = np.arctan2(d[:, 2], -d[:, 1])
    elbow = np.arccos(np.clip((d * f).sum(-1), -1, 1))
    cf, sf = np.cos(flex), np.sin(flex)
    hint0 = np.stack([np.zeros(T), sf, cf], -1)
    perp = f - (f * d).sum(-1, keepdims=True) * d
    pn = np.linalg.norm(perp, axis=-1)
    tw = np.arctan2((np.cross(d, hint0) * perp).sum(-1), (hint0 * perp).sum(-1))
    twist = sg * tw
    if twist_hint is not None:  # an almost straight arm has no bending plane: keep the hint
        w = np.clip(pn / 0.1, 0, 1)
        twist = w * twist + (1 - w) * twist_hint
    return {"flex": flex, "abduct": sg * b, "elbow": elbow, "twist": twist}


def set_arm(
    ch: Channels,
    side: str,
    sl: slice,
    target_chest: np.ndarray,
    pole_chest: np.ndarray,
    weight: np.ndarray | None = None,
) -> None:
    """Solve the arm over frames ``sl`` and write it; ``weight`` (n,) in [0, 1] blends from the
    channels already there (0) to the solution (1) joint by joint, for reaching in and out."""
    a = ch.arms[side]
    sol = solve_arm(target_chest, pole_chest, side, twist_hint=a.twist[sl])
    w = np.ones(len(target_chest)) if weight is None else weight
    for name, val in sol.items():
        cur = getattr(a, name)[sl]
        delta = val - cur
        if name in ("twist", "flex"):
            delta = (delta + np.pi) % (2 * np.pi) - np.pi
        getattr(a, name)[sl] = cur + w * delta


def reach_world(
    ch: Channels,
    side: str,
    sl: slice,
    target: np.ndarray,
    pole: np.ndarray,
    weight: np.ndarray | None = None,
    joints: np.ndarray | None = None,
) -> None:
    """:func:`set_arm` with the wrist target (n, 3) and the elbow's pole direction (n, 3) in
    world coordinates, for frames ``sl``."""
    j = pose(ch) if joints is None else joints
    R = chest_frame(ch)[sl]
    sh = j[sl, J(f"{SIDE_NAME[side]}_shoulder")]
    tgt = np.einsum("tji,tj->ti", R, target - sh)
    pl = np.einsum("tji,tj->ti", R, np.broadcast_to(pole, target.shape))
    set_arm(ch, side, sl, tgt, pl, weight)
