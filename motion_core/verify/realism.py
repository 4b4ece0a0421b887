"""Realism figures of motions, with the bounds a corpus must stay within.

Figures are computed on joints recovered from the stored features (so the whole
features path is checked too), with the floor at y = 0 as the format defines it:

* bone-length deviation: max |measured - skeleton| over every bone and frame (m)
* foot slide: for every contact phase of every ankle and toe joint (a run of frames with
  the joint within 2.5 cm of its flat-foot height), the largest horizontal distance from
  where the phase began (m)
* penetration: the lowest joint height above the floor the feet stand on (m, negative =
  below it). The format puts y = 0 at the clip's lowest joint, which would hide a body
  sinking through the floor; the contact floor is instead where the feet stand (see
  :func:`contact_floor`).
* max joint speed (m/s)
* joint limits: largest knee and elbow flexion (degrees; 180 would fold the limb flat)

On stairs the ground is not flat: a foot standing on a tread stands on the ground there. The
foot figures (contact, slide, penetration) then read each foot's height above the ground under
it (``body.terrain.surface``, the tread it stands on); every other joint's above y = 0. A motion
on flat ground (no raised plant) gets exactly the figures it got before.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..body.foot import FOOT, FOOT_PITCH_FLAT
from ..body.skeleton import HUMANML3D
from ..body.terrain import heights_above, surface
from .rules import episodes

J = HUMANML3D.joint_names.index
# Flat-foot heights above the floor (the toe is the lowest joint when standing).
CONTACT_JOINTS = {
    J("left_foot"): 0.0,
    J("right_foot"): 0.0,
    J("left_ankle"): FOOT[0] * float(np.sin(FOOT_PITCH_FLAT)),
    J("right_ankle"): FOOT[1] * float(np.sin(FOOT_PITCH_FLAT)),
}
CONTACT_BAND = 0.025

BOUNDS = {
    "bone_dev_m": 0.005,
    "foot_slide_m": 0.02,
    "penetration_m": -0.02,  # lower bound
    "max_joint_speed_ms": 15.0,
    "max_knee_flex_deg": 165.0,
    "max_elbow_flex_deg": 165.0,
}


@dataclass
class Realism:
    bone_dev_m: float
    foot_slide_m: float
    penetration_m: float
    max_joint_speed_ms: float
    max_knee_flex_deg: float
    max_elbow_flex_deg: float
    contact_phases: int

    def violations(self) -> list[str]:
        out = []
        for k, bound in BOUNDS.items():
            v = getattr(self, k)
            bad = v < bound if k == "penetration_m" else v > bound
            if bad:
                out.append(f"{k}={v:.4f} (bound {bound})")
        return out


def _flexion(j: np.ndarray, a: int, b: int, c: int) -> np.ndarray:
    u = j[:, a] - j[:, b]
    v = j[:, c] - j[:, b]
    cos = (u * v).sum(-1) / (np.linalg.norm(u, axis=-1) * np.linalg.norm(v, axis=-1)).clip(1e-9)
    return 180.0 - np.degrees(np.arccos(np.clip(cos, -1, 1)))


def heights(joints: np.ndarray) -> np.ndarray:
    """(T, 22) every joint's height above the ground: y, except for a foot on a raised level
    (``body.terrain``), whose ankle and toe are measured from the level under it."""
    surf = surface(joints)
    return joints[..., 1] if surf is None else heights_above(joints, surf)


def foot_slides(joints: np.ndarray, y: np.ndarray | None = None) -> list[float]:
    """Horizontal slide of every contact phase, joints (T, 22, 3) with the floor at y = 0;
    ``y``: their :func:`heights` where the caller has them."""
    y = heights(joints) if y is None else y
    slides = []
    for jid, flat in CONTACT_JOINTS.items():
        contact = y[:, jid] < flat + CONTACT_BAND
        for s, t in episodes(contact, min_len=2, min_gap=1):  # min_gap=1: phases never merge
            xz = joints[s:t, jid][:, [0, 2]]
            slides.append(float(np.linalg.norm(xz - xz[0], axis=-1).max()))
    return slides


def contact_floor(joints: np.ndarray, y: np.ndarray | None = None) -> float:
    """Height of the floor the feet stand on. joints: (T, 22, 3); ``y``: their :func:`heights`
    where the caller has them (on stairs, the heights over the treads).

    Per foot, the 10th percentile over frames of its lowest joint (relative to that joint's
    flat-foot height): a low percentile because runs and jumps spend much of a clip in the
    air. The floor is the higher of the two feet, so a foot that sits below the other one
    throughout counts as penetrating, and a body sinking until a knee touches y = 0 is seen.
    """
    y = heights(joints) if y is None else y
    per_foot = []
    for ankle, toe in HUMANML3D.feet:
        h = np.minimum(y[:, ankle] - CONTACT_JOINTS[ankle], y[:, toe] - CONTACT_JOINTS[toe])
        per_foot.append(np.percentile(h, 10))
    return float(max(per_foot))


def realism(joints: np.ndarray, fps: float = 20.0) -> Realism:
    """Figures for one motion (T, 22, 3)."""
    j = np.asarray(joints, dtype=np.float64)
    y = heights(j)
    floor = contact_floor(j, y)
    bl = HUMANML3D.measure_bone_lengths(j)
    slides = foot_slides(j, y)
    speed = np.linalg.norm(np.diff(j, axis=0), axis=-1) * fps if len(j) > 1 else np.zeros(1)
    knee = max(
        _flexion(j, J("left_hip"), J("left_knee"), J("left_ankle")).max(),
        _flexion(j, J("right_hip"), J("right_knee"), J("right_ankle")).max(),
    )
    elbow = max(
        _flexion(j, J("left_shoulder"), J("left_elbow"), J("left_wrist")).max(),
        _flexion(j, J("right_shoulder"), J("right_elbow"), J("right_wrist")).max(),
    )
    return Realism(
        bone_dev_m=float(np.abs(bl - HUMANML3D.bone_lengths[1:]).max()),
        foot_slide_m=max(slides) if slides else 0.0,
        penetration_m=float(y.min() - floor),
        max_joint_speed_ms=float(speed.max()),
        max_knee_flex_deg=float(knee),
        max_elbow_flex_deg=float(elbow),
        contact_phases=len(slides),
    )


def summarize(figures: list[Realism]) -> dict:
    """Worst case and 99th percentile of each figure over a set of motions."""
    out: dict = {"clips": len(figures), "contact_phases": int(sum(f.contact_phases for f in figures))}
    for k in BOUNDS:
        vals = np.array([getattr(f, k) for f in figures])
        worst = vals.min() if k == "penetration_m" else vals.max()
        q = np.percentile(vals, 1 if k == "penetration_m" else 99)
        out[k] = {"worst": float(worst), "p99": float(q), "bound": BOUNDS[k]}
    out["violating_clips"] = int(sum(bool(f.violations()) for f in figures))
    return out
