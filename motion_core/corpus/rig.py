"""A procedural character rig on the HumanML3D skeleton: control channels -> joints.

Every joint is placed by forward kinematics from the skeleton's rest offsets, so bone
lengths are exact by construction; legs are solved by analytic two-bone IK towards ankle
targets (so planted feet stay exactly where they were put), and the pelvis is lowered
wherever a target would otherwise be out of reach.

Conventions (HumanML3D): y up, metres; heading psi rotates +z (the body's front) to
(sin psi, 0, cos psi); +x is the body's left at psi = 0, so a positive heading change
is a turn to the left.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.ndimage import gaussian_filter1d, maximum_filter1d

from ..body.foot import FOOT, FOOT_PITCH_FLAT
from ..body.skeleton import HUMANML3D

SK = HUMANML3D
OFF = SK.rest_offsets
J = SK.joint_names.index

# Leg geometry (left, right) from the skeleton.
THIGH = (float(SK.bone_lengths[J("left_knee")]), float(SK.bone_lengths[J("right_knee")]))
SHIN = (float(SK.bone_lengths[J("left_ankle")]), float(SK.bone_lengths[J("right_ankle")]))
UPPER_ARM = (float(SK.bone_lengths[J("left_elbow")]), float(SK.bone_lengths[J("right_elbow")]))
FOREARM = (float(SK.bone_lengths[J("left_wrist")]), float(SK.bone_lengths[J("right_wrist")]))

TOE_PLANT_Y = 0.02  # toe joint height when the foot is flat on the floor
STAND_PELVIS_Y = 0.94
MAX_KNEE_FLEX = np.radians(158.0)
SIDES = ("l", "r")
SIGN = {"l": 1.0, "r": -1.0}  # +x is the body's left


def rot_x(a: np.ndarray) -> np.ndarray:
    """(T,) -> (T, 3, 3); positive tilts +y towards +z (a forward lean)."""
    c, s = np.cos(a), np.sin(a)
    z, o = np.zeros_like(a), np.ones_like(a)
    return np.stack([np.stack([o, z, z], -1), np.stack([z, c, -s], -1), np.stack([z, s, c], -1)], -2)


def rot_y(a: np.ndarray) -> np.ndarray:
    """(T,) -> (T, 3, 3); maps +z to (sin a, 0, cos a)."""
    c, s = np.cos(a), np.sin(a)
    z, o = np.zeros_like(a), np.ones_like(a)
    return np.stack([np.stack([c, z, s], -1), np.stack([z, o, z], -1), np.stack([-s, z, c], -1)], -2)


def rot_z(a: np.ndarray) -> np.ndarray:
    """(T,) -> (T, 3, 3); positive tilts +y towards -x (the body's right)."""
    c, s = np.cos(a), np.sin(a)
    z, o = np.zeros_like(a), np.ones_like(a)
    return np.stack([np.stack([c, -s, z], -1), np.stack([s, c, z], -1), np.stack([z, z, o], -1)], -2)


def _mv(R: np.ndarray, v: np.ndarray) -> np.ndarray:
    """(T,3,3) x (T,3) or (3,) -> (T,3)."""
    return np.einsum("tij,...tj->ti", R, v) if v.ndim == 2 else np.einsum("tij,j->ti", R, v)


@dataclass
class ArmChannels:
    """Per-frame arm controls (radians). flex: upper arm forward (+) / back (-) from hanging;
    abduct: out to the side (+) / across the body (-); elbow: flexion, 0 = straight;
    twist: rotation of the elbow's bending plane about the upper arm."""

    flex: np.ndarray
    abduct: np.ndarray
    elbow: np.ndarray
    twist: np.ndarray


@dataclass
class FootTrack:
    """ankle: (T, 3) world ankle target; yaw: (T,) foot heading; pitch: (T,) toe-down angle
    (FOOT_PITCH_FLAT = flat on the floor, larger = heel raised, negative = toes up)."""

    ankle: np.ndarray
    yaw: np.ndarray
    pitch: np.ndarray


@dataclass
class Channels:
    """All controls of a clip, each (T,) unless noted."""

    T: int
    root_xz: np.ndarray  # (T, 2) pelvis ground position
    heading: np.ndarray
    pelvis_y: np.ndarray
    pelvis_pitch: np.ndarray  # forward lean of the pelvis (+) / backwards (-)
    pelvis_roll: np.ndarray  # lean to the body's left (+)
    spine_bend: np.ndarray  # forward bend spread over the three spine joints
    spine_side: np.ndarray  # lateral bend to the left (+)
    spine_twist: np.ndarray  # upper body turned to the left (+)
    neck_pitch: np.ndarray  # looking down (+)
    arms: dict[str, ArmChannels] = field(default_factory=dict)
    feet: dict[str, FootTrack] = field(default_factory=dict)

    @classmethod
    def neutral(cls, T: int) -> Channels:
        z = np.zeros(T)
        arms = {
            s: ArmChannels(flex=np.full(T, 0.05), abduct=np.full(T, 0.12), elbow=np.full(T, 0.2), twist=z.copy())
            for s in SIDES
        }
        return cls(
            T=T,
            root_xz=np.zeros((T, 2)),
            heading=z.copy(),
            pelvis_y=np.full(T, STAND_PELVIS_Y),
            pelvis_pitch=np.full(T, 0.03),
            pelvis_roll=z.copy(),
            spine_bend=np.full(T, 0.02),
            spine_side=z.copy(),
            spine_twist=z.copy(),
            neck_pitch=np.full(T, 0.05),
            arms=arms,
        )


def arm_directions(a: ArmChannels, side: str) -> tuple[np.ndarray, np.ndarray]:
    """Upper-arm and forearm unit directions in the chest frame, each (T, 3)."""
    sg = SIGN[side]
    R = rot_x(-a.flex) @ rot_z(sg * a.abduct)
    d = _mv(R, np.array([0.0, -1.0, 0.0]))
    hint = _mv(R, np.array([0.0, 0.0, 1.0]))  # the arm's own front, so bending is always well-defined
    # Twist the bending plane about the upper arm (Rodrigues with d perpendicular to hint).
    tw = sg * a.twist
    hint = hint * np.cos(tw)[:, None] + np.cross(d, hint) * np.sin(tw)[:, None]
    f = d * np.cos(a.elbow)[:, None] + hint * np.sin(a.elbow)[:, None]
    return d, f


def two_bone_ik(
    hip: np.ndarray,
    target: np.ndarray,
    pole: np.ndarray,
    l1: float,
    l2: float,
    max_flex: float = MAX_KNEE_FLEX,
    straight: float = 0.9999,
):
    """Knee and reached ankle for hip (T,3), ankle target (T,3), pole hint (T,3).
    Returns (knee, ankle, reach) with reach = |target - hip| / (l1 + l2). The arm's solve uses
    it too (shoulder, elbow, wrist) with its own flexion cap ``max_flex`` and ``straight``, the
    share of the full length the chain may straighten to."""
    v = target - hip
    dist = np.linalg.norm(v, axis=-1)
    n = v / dist[:, None].clip(1e-9)
    # Knee flexion is capped at MAX_KNEE_FLEX: a target closer to the hip is not reached.
    d_min = np.sqrt(l1**2 + l2**2 - 2 * l1 * l2 * np.cos(np.pi - max_flex))
    d = np.clip(dist, d_min, (l1 + l2) * straight)
    a = (l1**2 - l2**2 + d**2) / (2 * d)
    h = np.sqrt(np.clip(l1**2 - a**2, 0.0, None))
    p = pole - (pole * n).sum(-1, keepdims=True) * n
    p = p / np.linalg.norm(p, axis=-1, keepdims=True).clip(1e-9)
    knee = hip + n * a[:, None] + p * h[:, None]
    ankle = hip + n * d[:, None]
    return knee, ankle, dist / (l1 + l2)


def _pelvis_frame(ch: Channels) -> np.ndarray:
    return rot_y(ch.heading) @ rot_x(ch.pelvis_pitch) @ rot_z(-ch.pelvis_roll)


def hip_positions(ch: Channels, pelvis: np.ndarray | None = None) -> dict[str, np.ndarray]:
    Rp = _pelvis_frame(ch)
    if pelvis is None:
        pelvis = np.stack([ch.root_xz[:, 0], ch.pelvis_y, ch.root_xz[:, 1]], -1)
    return {"l": pelvis + _mv(Rp, OFF[J("left_hip")]), "r": pelvis + _mv(Rp, OFF[J("right_hip")])}


def make_reachable(ch: Channels, max_reach: float = 0.985) -> None:
    """Lower the pelvis (smoothly) wherever an ankle target is out of the leg's reach."""
    hips = hip_positions(ch)
    drop = np.zeros(ch.T)
    for i, s in enumerate(SIDES):
        v = ch.feet[s].ankle - hips[s]
        horiz2 = v[:, 0] ** 2 + v[:, 2] ** 2
        L = (THIGH[i] + SHIN[i]) * max_reach
        max_dy = np.sqrt(np.clip(L**2 - horiz2, 1e-6, None))
        need = (hips[s][:, 1] - ch.feet[s].ankle[:, 1]) - max_dy
        drop = np.maximum(drop, need)
    drop = np.clip(drop, 0.0, None)
    if drop.max() > 0:
        smooth = gaussian_filter1d(maximum_filter1d(drop, size=7), 2.0, mode="nearest")
        ch.pelvis_y = ch.pelvis_y - np.maximum(smooth, drop)


def pose(ch: Channels) -> np.ndarray:
    """Forward kinematics of all channels. Returns joints (T, 22, 3)."""
    T = ch.T
    out = np.zeros((T, SK.n_joints, 3))
    pelvis = np.stack([ch.root_xz[:, 0], ch.pelvis_y, ch.root_xz[:, 1]], -1)
    out[:, 0] = pelvis
    Rp = _pelvis_frame(ch)

    # Spine: bend, side bend and twist spread 30/35/35 over spine1..3.
    def seg(k: float) -> np.ndarray:
        return rot_x(ch.spine_bend * k) @ rot_z(-ch.spine_side * k) @ rot_y(ch.spine_twist * k)

    R1 = Rp @ seg(0.3)
    R2 = R1 @ seg(0.35)
    R3 = R2 @ seg(0.35)
    out[:, J("spine1")] = pelvis + _mv(Rp, OFF[J("spine1")])
    out[:, J("spine2")] = out[:, J("spine1")] + _mv(R1, OFF[J("spine2")])
    out[:, J("spine3")] = out[:, J("spine2")] + _mv(R2, OFF[J("spine3")])
    out[:, J("neck")] = out[:, J("spine3")] + _mv(R3, OFF[J("neck")])
    out[:, J("head")] = out[:, J("neck")] + _mv(R3 @ rot_x(ch.neck_pitch), OFF[J("head")])

    for i, (s, name) in enumerate((("l", "left"), ("r", "right"))):
        collar = out[:, J("spine3")] + _mv(R3, OFF[J(f"{name}_collar")])
        shoulder = collar + _mv(R3, OFF[J(f"{name}_shoulder")])
        d, f = arm_directions(ch.arms[s], s)
        elbow = shoulder + UPPER_ARM[i] * _mv(R3, d)
        wrist = elbow + FOREARM[i] * _mv(R3, f)
        out[:, J(f"{name}_collar")] = collar
        out[:, J(f"{name}_shoulder")] = shoulder
        out[:, J(f"{name}_elbow")] = elbow
        out[:, J(f"{name}_wrist")] = wrist

    hips = hip_positions(ch, pelvis)
    # Knees bend in the plane of the leg and the body's lateral axis L: the pole n x L is the
    # leg direction n turned forward about L, i.e. forward for a hanging leg and up for a leg
    # stretched out in front (sitting on the floor). It turns with the hip's flexion, so it
    # never flips, and it is singular only for a leg pointing straight sideways.
    body_left = np.stack([np.cos(ch.heading), np.zeros(T), -np.sin(ch.heading)], -1)
    for i, (s, name) in enumerate((("l", "left"), ("r", "right"))):
        ft = ch.feet[s]
        n = ft.ankle - hips[s]
        n = n / np.linalg.norm(n, axis=-1, keepdims=True).clip(1e-9)
        pole = np.cross(n, body_left) + 0.15 * SIGN[s] * body_left
        knee, ankle, _ = two_bone_ik(hips[s], ft.ankle, pole, THIGH[i], SHIN[i])
        toe_dir = np.stack(
            [np.cos(ft.pitch) * np.sin(ft.yaw), -np.sin(ft.pitch), np.cos(ft.pitch) * np.cos(ft.yaw)], -1
        )
        out[:, J(f"{name}_hip")] = hips[s]
        out[:, J(f"{name}_knee")] = knee
        out[:, J(f"{name}_ankle")] = ankle
        out[:, J(f"{name}_foot")] = ankle + FOOT[i] * toe_dir
    return out


def ankle_height_flat(side: str) -> float:
    """Ankle height when the foot is flat on the floor."""
    return TOE_PLANT_Y + FOOT[SIDES.index(side)] * float(np.sin(FOOT_PITCH_FLAT))
