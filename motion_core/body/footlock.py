"""Feet that stay planted: foot contacts found from the motion, each planted foot locked in
place by two-bone leg IK, blended in and out over a few frames.

Generated motions skate: a foot that should stand still slides along the floor while the
body moves over it. The fix is the usual one in animation tools (and MoMask's demo toggle):

1. **Contacts**, per foot (ankle + toe): frames where the toe is within ``height`` of the
   floor and moves slower than ``speed`` horizontally; runs shorter than ``min_frames``
   are dropped and gaps of up to ``fill_gap`` frames inside a run are closed.
2. **Anchors**: during a contact phase the toe's horizontal position is held at its mean
   over the phase (the least total correction); the whole foot is moved by that offset, so
   the ankle-toe bone keeps its length and the heel may still lift.
3. **Blending**: the offset ramps in before a phase and out after it (smoothstep) over
   ``blend`` frames, or more where the offset is large, so that the ramp itself never moves
   the foot faster than ``ramp_speed``; overlapping ramps are averaged.
4. **Leg IK**: the hip stays where it is; the knee is placed by the analytic two-bone
   solution in the plane of hip, new ankle and the original knee (the pole), so thigh and
   shin keep their lengths exactly. An ankle the leg cannot reach is placed as far as the
   straight leg allows.

Only the six leg joints below the hips change (knees, ankles, toes): the pelvis, spine,
arms and so the verifier's reading of the upper body are untouched.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .skeleton import HUMANML3D, Skeleton


@dataclass(frozen=True)
class FootLockConfig:
    height: float = 0.05  # m above the floor (y = 0): a toe lower than this may be planted
    # m/s: a toe slower than this horizontally may be planted. Chosen on 200 validation prompts
    # per method (tools/foot_skate.py, 0.25 / 0.35 / 0.5): at 0.5 the diffusion methods' slow
    # glides count as plants that no leg can hold (p95 slide 70-100 cm left as it was), at 0.25
    # KMM's floor-contact slide improves least (3.8 -> 2.1 cm, against 1.8 at 0.35)
    speed: float = 0.35
    min_frames: int = 3  # shorter runs are taps, not plants
    fill_gap: int = 2  # frames of a run's gap closed (a noisy speed estimate)
    blend: int = 4  # frames to ramp the correction in and out, at least
    # the ramp is lengthened so that it never moves the foot faster than this (m/s): a
    # large correction faded out in 4 frames would itself look like a slide
    ramp_speed: float = 0.5
    reach: float = 0.99  # share of the straight leg's length an anchored ankle may be from the hip
    fps: float = 20.0


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """[start, end) of each run of True in a 1-D boolean array."""
    m = np.concatenate([[False], mask, [False]]).astype(np.int8)
    d = np.diff(m)
    return list(zip(np.flatnonzero(d == 1).tolist(), np.flatnonzero(d == -1).tolist(), strict=True))


def contact_phases(joints: np.ndarray, toe: int, cfg: FootLockConfig = FootLockConfig()) -> list[tuple[int, int]]:
    """[start, end) frame ranges where the foot whose toe joint is ``toe`` is planted.
    joints: (T, J, 3), y up, floor at y = 0."""
    p = joints[:, toe]
    v = np.zeros(len(p))
    if len(p) > 1:
        step = np.linalg.norm(np.diff(p[:, [0, 2]], axis=0), axis=-1) * cfg.fps
        # a frame's speed is the slower of its two neighbouring steps: the first and last
        # frames of a plant still count although the foot moves on either side of it
        v[:-1] = step
        v[1:] = np.minimum(v[1:], step) if len(p) > 2 else step
        v[0] = step[0]
    mask = (p[:, 1] < cfg.height) & (v < cfg.speed)
    # close short gaps, then drop short runs
    for s, e in _runs(~mask):
        if 0 < s and e < len(mask) and e - s <= cfg.fill_gap:
            mask[s:e] = True
    return [(s, e) for s, e in _runs(mask) if e - s >= cfg.min_frames]


def _smoothstep(x: np.ndarray) -> np.ndarray:
    x = np.clip(x, 0.0, 1.0)
    return x * x * (3 - 2 * x)


def _anchors(joints: np.ndarray, toe: int, phases: list[tuple[int, int]]) -> np.ndarray:
    """(P, 2) each phase's anchor: the toe's mean horizontal (x, z) position over the phase."""
    # a mean per phase (a handful), not one reduceat: that sums in another order and would
    # move the anchors by an ulp from the loop's
    return np.stack([joints[s:e, toe].mean(0)[[0, 2]] for s, e in phases])


def foot_offsets(
    joints: np.ndarray, toe: int, phases: list[tuple[int, int]], cfg: FootLockConfig = FootLockConfig()
) -> np.ndarray:
    """(T, 3) horizontal offset to add to the foot (ankle and toe) at every frame: the
    anchor minus the toe inside each phase, ramped to zero outside it.

    All phases at once as (P, T) arrays, the same arithmetic as a loop over them: a walk
    has a plant per step, and the loop took 2.5-3.5 ms of a 10 s walk's 17 ms with a 1-step
    student, so a method whose motions walk timed slower than one whose feet never plant
    for the same network cost."""
    T = len(joints)
    if not phases:
        return np.zeros((T, 3))
    s, e = (np.array(x)[:, None] for x in zip(*phases, strict=True))  # (P, 1) each
    t = np.arange(T)[None, :]
    # outside its phase a correction is the one at the phase's edge, fading out: the foot
    # keeps its own motion there, shifted by a shrinking amount
    edge = np.clip(t, s, e - 1)  # (P, T)
    d = np.zeros((len(phases), T, 3))
    d[..., [0, 2]] = _anchors(joints, toe, phases)[:, None, :] - joints[:, toe][:, [0, 2]][edge]
    # smoothstep's steepest slope is 1.5 / ramp length
    rows = np.arange(len(phases))
    b_in, b_out = (
        np.maximum(
            np.ceil(1.5 * np.linalg.norm(d[rows, at[:, 0]], axis=-1) * cfg.fps / cfg.ramp_speed), max(cfg.blend, 1)
        )[:, None]
        for at in (s, e - 1)
    )
    w = np.where(
        t < s,
        _smoothstep(1 - (s - t) / (b_in + 1)),
        np.where(t >= e, _smoothstep(1 - (t - e + 1) / (b_out + 1)), 1.0),
    )
    total = (w[..., None] * d).sum(0)
    return total / np.maximum(w.sum(0), 1.0)[:, None]


def _reachable(
    j: np.ndarray, hip: int, ankle: int, toe: int, phases: list[tuple[int, int]], reach: float
) -> list[tuple[int, int]]:
    """The phases whose locked ankle (the ankle moved by its anchor minus the toe, as
    ``foot_offsets`` moves it inside a phase) stays within ``reach`` of the hip throughout."""
    if not phases:
        return []
    lengths = np.array([e - s for s, e in phases])
    frames = np.concatenate([np.arange(s, e) for s, e in phases])
    target = j[frames, ankle].copy()
    target[:, [0, 2]] += np.repeat(_anchors(j, toe, phases), lengths, axis=0) - j[frames, toe][:, [0, 2]]
    dist = np.linalg.norm(target - j[frames, hip], axis=-1)
    starts = np.cumsum(lengths) - lengths
    return [p for p, far in zip(phases, np.maximum.reduceat(dist, starts), strict=True) if far <= reach]


def two_bone_ik(
    hip: np.ndarray, knee: np.ndarray, target: np.ndarray, thigh: float, shin: float
) -> tuple[np.ndarray, np.ndarray]:
    """Knee and ankle (T, 3) for ankle ``target`` (T, 3) with the hip fixed, bone lengths
    ``thigh`` and ``shin`` kept, the knee bending towards the original ``knee`` (T, 3)."""
    to = target - hip
    dist = np.linalg.norm(to, axis=-1, keepdims=True)
    u = to / np.maximum(dist, 1e-9)
    d = np.clip(dist, abs(thigh - shin) + 1e-6, thigh + shin - 1e-6)
    ankle = hip + u * d
    x = (thigh**2 - shin**2 + d**2) / (2 * d)  # the knee's distance along hip -> ankle
    h = np.sqrt(np.maximum(thigh**2 - x**2, 0.0))
    pole = knee - hip
    pole = pole - (pole * u).sum(-1, keepdims=True) * u
    n = np.linalg.norm(pole, axis=-1, keepdims=True)
    # a straight original leg gives no pole: bend forward (+z of the body is unknown here,
    # so use any direction orthogonal to the leg; the correction is tiny then)
    fallback = np.cross(u, np.array([1.0, 0.0, 0.0]))
    pole = np.where(
        n > 1e-6,
        pole / np.maximum(n, 1e-9),
        fallback / np.maximum(np.linalg.norm(fallback, axis=-1, keepdims=True), 1e-9),
    )
    return hip + u * x + pole * h, ankle


@dataclass
class FootLockResult:
    joints: np.ndarray  # (T, J, 3)
    phases: dict[str, list[tuple[int, int]]]  # "left" / "right" -> [start, end)
    residual_m: float  # largest distance an ankle stayed from its target (unreachable)


def lock_feet(
    joints: np.ndarray, cfg: FootLockConfig = FootLockConfig(), skeleton: Skeleton = HUMANML3D
) -> FootLockResult:
    """Lock planted feet in place. joints: (T, J, 3) rigid, y up, floor at y = 0. Returns
    new joints (float64) where only the knees, ankles and toes have moved."""
    j = np.asarray(joints, np.float64).copy()
    phases: dict[str, list[tuple[int, int]]] = {}
    residual = 0.0
    for side, (ankle, toe) in zip(("left", "right"), skeleton.feet, strict=True):
        knee = skeleton.parents[ankle]
        hip = skeleton.parents[knee]
        thigh = float(np.linalg.norm(j[:, knee] - j[:, hip], axis=-1).mean())
        shin = float(np.linalg.norm(j[:, ankle] - j[:, knee], axis=-1).mean())
        # a phase whose anchor the leg cannot reach is not a plant the body stays over (it
        # slid away from it): left as it is rather than locked with a straightened leg
        ph = _reachable(j, hip, ankle, toe, contact_phases(j, toe, cfg), cfg.reach * (thigh + shin))
        phases[side] = ph
        if not ph:
            continue
        off = foot_offsets(j, toe, ph, cfg)
        target = j[:, ankle] + off
        foot = j[:, toe] - j[:, ankle]
        new_knee, new_ankle = two_bone_ik(j[:, hip], j[:, knee], target, thigh, shin)
        moved = np.linalg.norm(off, axis=-1) > 0
        residual = max(residual, float(np.linalg.norm(new_ankle - target, axis=-1)[moved].max(initial=0.0)))
        j[moved, knee] = new_knee[moved]
        j[moved, ankle] = new_ankle[moved]
        j[moved, toe] = new_ankle[moved] + foot[moved]
    return FootLockResult(j, phases, residual)
