"""Ground that is not flat: stair treads and platforms, found from where the feet stand.

A motion carries no floor of its own, only joints. Where a foot stands still at a height,
something holds it there. On flat ground that is the floor, y = 0. On stairs it is a tread,
and the motion shows it: the two feet stand still at the same time at heights a step
apart, flat, each leg straight and under the body. Nothing else a body does shows that:

* vertical drift (a decoded motion's root error) moves the whole body, both feet alike, so it
  never puts two feet planted at the same frames at different heights;
* a foot held up (standing on one leg, a hop, a kick) is bent at the knee, out in front of
  the body or moving;
* a foot on its toes, or lying with the toes up, is not flat.

The rule, for joints with the floor at y = 0 (``canonicalize`` or ``ground`` put it there):

1. **Plants**, per foot: runs of at least ``min_frames`` frames where the slower of the foot's
   two points (ankle, toe) moves slower than ``speed`` (``ground``'s support speed). A plant's
   height is the lowest its sole gets over the run: the toe's height, or the ankle's less its
   flat-foot height above the toe, whichever is lower. A plant is *flat* when the ankle's
   median height over the toe is within ``flat`` of a flat foot's, and *bears weight* when
   the body comes over it: at some frame of it the hip is above the ankle by ``reach`` of the
   thigh and shin together (the leg straight and under the body; a foot kicked out or held
   up, or one set on something and taken back without the body coming over it, is not).
2. **Levels**: two flat, weight-bearing plants of different feet that overlap in time, their
   soles at least ``rise`` apart in height over the frames they share (the median of the
   difference), stand on different levels. Their heights are levels, except a height under
   ``rise / 2``, which is the floor.
3. **Raised plants**: every flat, weight-bearing plant within ``level_tol`` of a level (the
   two that found it, the trailing foot joining the leading one on the top step, ...).
4. **Surface** under each foot, per frame: a raised plant's own height during it, 0 during
   any other plant, and between plants the lower of the plant it left and the one it lands
   on (a swinging foot is in the air above the lower one).

A motion with no raised plant is flat: ``surface`` returns None, and every reader that uses it
(``ground``, the verifier's foot rules, the realism figures) does exactly what it did before.
``steps`` turns the raised plants into boxes for the viewer.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from itertools import pairwise

import numpy as np

from .foot import FOOT_PITCH_FLAT
from .skeleton import HUMANML3D, Skeleton


@dataclass(frozen=True)
class TerrainConfig:
    speed: float = 0.3  # m/s: the slower foot point moves slower than this in a plant (ground's support speed)
    min_frames: int = 4  # 0.2 s at 20 fps: shorter stops are a foot passing through
    flat: float = 0.035  # m: the ankle over the toe within this of a flat foot's 5.9 cm
    # the hip's height over the ankle / (thigh + shin) at some frame of a plant: it bears weight.
    # The stairs kinds' plants on treads reach 0.92-0.97; generated motions' kicks held at the
    # top (0.39) and feet set on something and taken back (0.67-0.75) do not
    reach: float = 0.85
    rise: float = 0.1  # m: two planted feet this far apart in height stand on different levels
    level_tol: float = 0.04  # m: a plant this close to a level's height stands on that level
    fps: float = 20.0


@dataclass(frozen=True)
class FootPlant:
    """One foot standing still: frames [start, end), ``foot`` 0 = left, 1 = right."""

    foot: int
    start: int
    end: int
    height: float  # m: the sole's lowest height over the plant
    flat: bool
    bears_weight: bool
    xz: np.ndarray  # (2, 2): mean ankle and toe (x, z) over the plant
    sole: np.ndarray = field(repr=False, default_factory=lambda: np.zeros(0))  # (end - start,) per frame


def _runs(mask: np.ndarray, min_len: int) -> list[tuple[int, int]]:
    """[start, end) of every run of True at least min_len long."""
    m = np.concatenate([[False], mask, [False]])
    d = np.diff(m.astype(np.int8))
    starts, ends = np.nonzero(d == 1)[0], np.nonzero(d == -1)[0]
    return [(int(a), int(b)) for a, b in zip(starts, ends, strict=True) if b - a >= min_len]


def _leg(skeleton: Skeleton, ankle: int) -> tuple[int, int]:
    knee = skeleton.parents[ankle]
    return skeleton.parents[knee], knee


def ankle_over_toe(skeleton: Skeleton = HUMANML3D) -> tuple[float, float]:
    """Per foot, the ankle's height above the toe when the foot is flat (m)."""
    lengths = skeleton.bone_lengths
    return tuple(float(lengths[toe] * np.sin(FOOT_PITCH_FLAT)) for _, toe in skeleton.feet)  # type: ignore[return-value]


def foot_plants(
    joints: np.ndarray, skeleton: Skeleton = HUMANML3D, cfg: TerrainConfig = TerrainConfig()
) -> list[FootPlant]:
    """Every plant of either foot, in the order left then right, each by time. joints (T, J, 3)."""
    j = np.asarray(joints, dtype=np.float64)
    out: list[FootPlant] = []
    if len(j) < 2:
        return out
    flat_h = ankle_over_toe(skeleton)
    for f, (ankle, toe) in enumerate(skeleton.feet):
        p = j[:, [ankle, toe]]  # (T, 2, 3)
        step = np.linalg.norm(np.diff(p, axis=0), axis=-1).min(1) * cfg.fps
        v = np.empty(len(j))
        # a frame's speed is the slower of its two steps (as ground.support_frames has it)
        v[:-1] = step
        v[-1] = step[-1]
        v[1:] = np.minimum(v[1:], step)
        sole = np.minimum(p[:, 1, 1], p[:, 0, 1] - flat_h[f])
        hip, knee = _leg(skeleton, ankle)
        legs = np.linalg.norm(j[:, hip] - j[:, knee], axis=-1) + np.linalg.norm(j[:, knee] - j[:, ankle], axis=-1)
        over = (j[:, hip, 1] - j[:, ankle, 1]) / legs.clip(1e-9)
        for a, b in _runs(v < cfg.speed, cfg.min_frames):
            lift = float(np.median(p[a:b, 0, 1] - p[a:b, 1, 1]))
            out.append(
                FootPlant(
                    foot=f,
                    start=a,
                    end=b,
                    height=float(sole[a:b].min()),
                    flat=abs(lift - flat_h[f]) <= cfg.flat,
                    bears_weight=bool(over[a:b].max() >= cfg.reach),
                    xz=p[a:b][..., [0, 2]].mean(0),
                    sole=sole[a:b],
                )
            )
    return out


def _apart(a: FootPlant, b: FootPlant) -> float:
    """How far apart in height two plants stand while both stand (median over the frames they
    share): a body drifting up or down moves both feet alike, so drift does not part them."""
    lo, hi = max(a.start, b.start), min(a.end, b.end)
    if hi <= lo:
        return 0.0
    return float(abs(np.median(a.sole[lo - a.start : hi - a.start] - b.sole[lo - b.start : hi - b.start])))


def _raised(plants: list[FootPlant], cfg: TerrainConfig) -> list[FootPlant]:
    firm = [p for p in plants if p.flat and p.bears_weight]
    levels: list[float] = []
    for a in firm:
        for b in firm:
            if a.foot == 0 and b.foot == 1 and _apart(a, b) >= cfg.rise:
                levels += [h for h in (a.height, b.height) if h >= cfg.rise / 2]
    if not levels:
        return []
    lv = np.array(levels)
    return [p for p in firm if p.height >= cfg.rise / 2 and np.abs(lv - p.height).min() <= cfg.level_tol]


def raised_plants(
    joints: np.ndarray, skeleton: Skeleton = HUMANML3D, cfg: TerrainConfig = TerrainConfig()
) -> list[FootPlant]:
    """The plants that stand on a raised level (a tread, a platform): empty for a flat motion."""
    return _raised(foot_plants(joints, skeleton, cfg), cfg)


def surface(
    joints: np.ndarray, skeleton: Skeleton = HUMANML3D, cfg: TerrainConfig = TerrainConfig()
) -> np.ndarray | None:
    """(T, 2) height of the ground under each foot (left, right) at every frame, or None when
    the motion is flat (no raised plant: the ground is y = 0 everywhere)."""
    plants = foot_plants(joints, skeleton, cfg)
    raised = _raised(plants, cfg)
    if not raised:
        return None
    up = {(p.foot, p.start) for p in raised}
    out = np.zeros((len(joints), 2))
    for f in range(2):
        prev_end, prev_h = 0, None
        for p in (p for p in plants if p.foot == f):  # by time
            h = p.height if (f, p.start) in up else 0.0
            out[prev_end : p.start, f] = h if prev_h is None else min(prev_h, h)
            out[p.start : p.end, f] = h
            prev_end, prev_h = p.end, h
        if prev_h is not None:
            out[prev_end:, f] = prev_h
    return out


def heights_above(joints: np.ndarray, surf: np.ndarray, skeleton: Skeleton = HUMANML3D) -> np.ndarray:
    """(T, J) every joint's height above the ground: a foot's ankle and toe above the surface
    under that foot, every other joint above y = 0."""
    y = np.asarray(joints, dtype=np.float64)[..., 1].copy()
    for f, (ankle, toe) in enumerate(skeleton.feet):
        y[:, ankle] -= surf[:, f]
        y[:, toe] -= surf[:, f]
    return y


def steps(
    joints: np.ndarray,
    skeleton: Skeleton = HUMANML3D,
    cfg: TerrainConfig = TerrainConfig(),
    margin: float = 0.08,
    landing: float = 0.3,
) -> list[dict]:
    """Boxes standing on the floor under the raised plants, one per level, for a viewer:
    [{"center": [x, z], "width", "depth", "yaw", "top"}], metres; the box's depth runs along
    the direction of travel, whose heading is ``yaw`` (+z turned by yaw, as ``rig`` turns the
    body), and ``top`` is the level's height. Empty for a flat motion.

    Along the travel the levels sit one after another: the riser between two neighbours is
    half-way between the feet on them. The top level reaches ``landing`` beyond its feet on its
    outer side (the landing at the top of a flight, ahead going up and behind going down; a
    platform's far side), the bottom one ``margin`` beyond its feet. Every box is as wide as all
    the feet on the levels, plus ``margin`` a side."""
    raised = raised_plants(joints, skeleton, cfg)
    if not raised:
        return []
    # levels: raised plants grouped by height
    groups: list[list[FootPlant]] = []
    for p in sorted(raised, key=lambda p: p.height):
        if groups and p.height - groups[-1][-1].height <= cfg.level_tol:
            groups[-1].append(p)
        else:
            groups.append([p])
    pts = [np.concatenate([p.xz for p in g]) for g in groups]  # (2n, 2) ankle and toe points per level
    centre = [x.mean(0) for x in pts]
    j = np.asarray(joints, dtype=np.float64)
    travel = j[-1, 0, [0, 2]] - j[0, 0, [0, 2]]
    if len(groups) > 1:
        by_height = centre[-1] - centre[0]
        # up the stairs the higher levels lie ahead; down them, behind
        travel = by_height if by_height @ travel >= 0 else -by_height
    if np.linalg.norm(travel) < 1e-6:
        travel = np.array([0.0, 1.0])
    fwd = travel / np.linalg.norm(travel)
    left = np.array([fwd[1], -fwd[0]])
    order = np.argsort([c @ fwd for c in centre])
    along = [(pts[i] @ fwd) for i in order]
    across = np.concatenate([pts[i] @ left for i in order])
    lo_x, hi_x = across.min() - margin, across.max() + margin
    # the top level (the landing of a flight, a platform) runs on beyond its feet: ahead going
    # up, behind going down (where the feet came from)
    down = len(order) > 1 and order[0] == len(groups) - 1
    edges = [along[0].min() - (landing if down else margin)]
    for a, b in pairwise(along):
        edges.append(0.5 * (a.max() + b.min()))
    edges.append(along[-1].max() + (margin if down else landing))
    out = []
    yaw = float(np.arctan2(fwd[0], fwd[1]))
    for k, i in enumerate(order):
        a, b = edges[k], edges[k + 1]
        mid = fwd * 0.5 * (a + b) + left * 0.5 * (lo_x + hi_x)
        out.append(
            {
                "center": [round(float(mid[0]), 4), round(float(mid[1]), 4)],
                "width": round(float(hi_x - lo_x), 4),
                "depth": round(float(b - a), 4),
                "yaw": round(yaw, 4),
                "top": round(float(np.median([p.height for p in groups[i]])), 4),
            }
        )
    return out
