"""Scripted steps: kinds that must place every footfall themselves (a stumble, recovery steps
after a push, heel-to-toe on a line) drive the pelvis along a displacement profile and set
both feet with one foot override, step by step, each step an eased swing (``gait.swing``:
lift, travel only once clear of the floor, set down). Between steps a foot is planted
exactly where it landed.

Positions are along the heading at the window's start, relative to where each foot stood
then: ``fwd`` forward, ``lat`` to the body's left (not mirrored per side).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..actions import Timeline
from ..gait import FootOverride, Plant, swing
from ..rig import FOOT_PITCH_FLAT, SIDES, SIGN, Channels, ankle_height_flat


@dataclass(frozen=True)
class Step:
    """One foot's step: lift off at frame ``a``, land at frame ``b`` (both relative to the
    window's start), on (fwd, lat) from the foot's plant at the window's start."""

    side: str
    a: int
    b: int
    fwd: float
    lat: float = 0.0
    lift: float = 0.08
    bulge: float = 0.0  # the swing bows this far outwards at mid-swing (passing the other foot)


def drive_path(tl: Timeline, t0: int, disp: np.ndarray, lateral: np.ndarray | None = None) -> None:
    """Pelvis travel over frames [t0, t0 + n): forward ``disp`` (n,) metres from its place at t0
    (and ``lateral`` to the body's left), as body-frame velocity."""
    n = len(disp)
    tl.vel[t0 : t0 + n, 1] += np.gradient(disp) * tl.fps
    if lateral is not None:
        tl.vel[t0 : t0 + n, 0] += np.gradient(lateral) * tl.fps


def set_steps(tl: Timeline, t0: int, t1: int, steps: list[Step]) -> None:
    """Both feet follow ``steps`` over [t0, t1) (steps of one foot in time order, not overlapping)."""
    n = t1 - t0

    def fn(start: int, end: int, plants: dict[str, Plant], chn: Channels):
        h = float(chn.heading[start])
        fwd = np.array([np.sin(h), np.cos(h)])
        left = np.array([np.cos(h), -np.sin(h)])
        out = {}
        for s in SIDES:
            p0 = plants[s]
            y0 = ankle_height_flat(s)
            a = np.tile([p0.xz[0], y0, p0.xz[1]], (n, 1))
            yw = np.full(n, p0.yaw)
            pt = np.full(n, FOOT_PITCH_FLAT)
            cur = p0
            for st in (x for x in steps if x.side == s):
                ia, ib = st.a, max(st.a + 3, st.b)
                tgt = Plant(p0.xz + st.fwd * fwd + st.lat * left, p0.yaw)
                sa, sy, sp = swing(cur, tgt, ib - ia, st.lift, s)
                if st.bulge:
                    u = np.arange(1, ib - ia + 1) / (ib - ia)
                    bow = SIGN[s] * st.bulge * np.sin(np.pi * u)
                    sa[:, 0] += bow * left[0]
                    sa[:, 2] += bow * left[1]
                a[ia:ib], yw[ia:ib], pt[ia:ib] = sa[: n - ia], sy[: n - ia], sp[: n - ia]
                a[ib:] = (tgt.xz[0], y0, tgt.xz[1])
                yw[ib:] = tgt.yaw
                pt[ib:] = FOOT_PITCH_FLAT
                cur = tgt
            out[s] = (a[: end - start], yw[: end - start], pt[: end - start])
        return out

    tl.overrides.append(FootOverride(t0, t1, SIDES, fn))


def walk_steps(
    disp: np.ndarray,
    fps: float,
    cadence: float,
    first: str,
    duty: float = 0.62,
    lift: float = 0.08,
    lat: dict[str, float] | None = None,
    start: int = 0,
    until: int | None = None,
    plants: dict[str, float] | None = None,
    bulge: float = 0.0,
) -> tuple[list[Step], dict[str, float]]:
    """Alternating steps that keep up with the pelvis's forward travel ``disp`` (n,): on each
    beat of the cadence from frame ``start`` (to ``until``), the foot whose turn it is steps to
    where the pelvis will be at its mid-stance, if that is more than 3 cm from where it stands
    (feet at ``plants``, forward metres; 0 by default). ``lat``: a lateral place per foot;
    ``bulge``: each swing bows out that far (past a foot set on the same line).
    Returns the steps and where each foot then stands."""
    n = len(disp)
    until = n if until is None else until
    lat = lat or {"l": 0.0, "r": 0.0}
    pos = dict(plants or {"l": 0.0, "r": 0.0})
    cycle = 2.0 / cadence
    sw = max(3, round((1 - duty) * cycle * fps))
    stance = duty * cycle
    steps: list[Step] = []
    side = first
    t = float(start)
    while t + sw < until:
        a = round(t)
        b = a + sw
        target = float(disp[min(n - 1, round(b + 0.5 * stance * fps))])
        if abs(target - pos[side]) > 0.03:
            steps.append(Step(side, a, b, target, lat[side], lift, bulge))
            pos[side] = target
        side = "r" if side == "l" else "l"
        t += fps / cadence
    return steps, pos
