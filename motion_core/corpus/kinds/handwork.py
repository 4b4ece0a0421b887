"""Hands at work in front of the body: wiping a table, stirring a bowl, drinking from a cup.

The working hand is put on its target by the arm IK (a Timeline finisher), so a wiping hand
stays on the table's surface, which is fixed in the world, while the body leans over it.
"""

from __future__ import annotations

import numpy as np

from ..actions import Spec, Timeline, _sides, bump
from ..rig import SIGN, Channels, J, pose
from .base import Kind, body_point, default_count, register
from .gestures import UP, _gesture
from .ik import body_axes, reach_world

NAME = {"l": "left", "r": "right"}


def _on_surface(n: int, fps: float, count: int, circles: bool, size: float, ccw: bool) -> tuple[np.ndarray, ...]:
    """(lateral, forward) offsets (n,) of a hand wiping: ``count`` circles of radius ``size`` or
    back-and-forth strokes of half-length ``size``, easing in from and out to the centre."""
    u = np.clip(((np.arange(n) + 0.5) / n - 0.2) / 0.6, 0, 1)
    amp = np.sin(np.pi * np.clip(u / 0.12, 0, 1) / 2) * np.sin(np.pi * np.clip((1 - u) / 0.12, 0, 1) / 2)
    ph = 2 * np.pi * count * u * (1 if ccw else -1)
    if circles:
        return size * amp * np.sin(ph), size * amp * (1 - np.cos(ph)) * 0.8
    return size * amp * np.sin(ph), 0.03 * amp * np.sin(2 * ph)


def wipe(spec: Spec, tl: Timeline, t0: int, t1: int) -> None:
    """Leaning over a table, one hand wipes its surface: circles, or strokes side to side; the
    hand stays flat on the table (a fixed height in the world); the other hand hangs."""
    n = t1 - t0
    r = tl.rng
    s = _sides(spec.side or "right")[0]
    count = default_count(spec, tl, n, 0.9, 2, 5)
    circles = r.random() < 0.5
    size = r.uniform(0.1, 0.13) if circles else r.uniform(0.12, 0.17)
    dx, dz = _on_surface(n, tl.fps, count, circles, size, r.random() < 0.5)
    down, ahead, inward = r.uniform(0.34, 0.38), r.uniform(0.16, 0.2), r.uniform(0.02, 0.06)
    w = np.clip(bump(n, 0.18, 0.18, 0.03, 0.97) / 0.98, 0, 1)
    lean = bump(n, 0.2, 0.2, 0.0, 1.0)
    ch = tl.ch
    ch.spine_bend[t0:t1] += r.uniform(0.35, 0.45) * lean
    ch.pelvis_pitch[t0:t1] += 0.18 * lean
    ch.neck_pitch[t0:t1] += 0.25 * lean
    ch.pelvis_y[t0:t1] -= 0.02 * lean
    tl.arm_swing[t0:t1] = 0.0
    sl = slice(t0, t1)
    mid = t0 + n // 2

    def finish(c: Channels) -> None:
        j = pose(c)
        fwd, left = body_axes(c)
        sh = j[mid, J(f"{NAME[s]}_shoulder")]
        # the table's spot: in front of and below the shoulder at mid-clip, fixed in the world
        centre = sh + fwd[mid] * ahead - left[mid] * SIGN[s] * inward - UP * down
        target = centre[None] + left[mid][None] * dx[:, None] + fwd[mid][None] * dz[:, None]
        pole = SIGN[s] * 0.8 * left[sl] - 0.3 * fwd[sl] - 0.4 * UP
        reach_world(c, s, sl, target, pole, w, j)

    tl.finishers.append(finish)


def stir(spec: Spec, tl: Timeline, t0: int, t1: int) -> None:
    """One hand holds a bowl in front of the belly, the other stirs in small circles in it."""
    n = t1 - t0
    r = tl.rng
    s = _sides(spec.side or "right")[0]
    o = "r" if s == "l" else "l"
    count = default_count(spec, tl, n, 0.7, 3, 7)
    rad = r.uniform(0.035, 0.055)
    up, depth = r.uniform(0.2, 0.28), r.uniform(0.28, 0.33)
    u = np.clip(((np.arange(n) + 0.5) / n - 0.2) / 0.6, 0, 1)
    amp = np.sin(np.pi * np.clip(u / 0.1, 0, 1) / 2) * np.sin(np.pi * np.clip((1 - u) / 0.1, 0, 1) / 2)
    ph = 2 * np.pi * count * u * (1 if r.random() < 0.5 else -1)
    cx, cz = rad * amp * np.cos(ph), rad * amp * np.sin(ph)

    def where(ch, j, side, sl):
        pel = j[sl, 0]
        if side == o:  # holding the bowl's rim on its own side
            return body_point(ch, sl, pel, SIGN[o] * 0.09, up - 0.04, depth)
        return body_point(ch, sl, pel, SIGN[s] * 0.02 + cx, up + 0.06, depth + cz)

    _gesture(tl, t0, t1, (s, o), where, lambda f, left, side: SIGN[side] * 0.8 * left - UP - 0.2 * f, 0.18, 0.03, 0.97)
    tl.ch.neck_pitch[t0:t1] += 0.35 * bump(n, 0.2, 0.2, 0.03, 0.97)  # looking into the bowl
    tl.ch.spine_bend[t0:t1] += 0.08 * bump(n, 0.2, 0.2, 0.03, 0.97)


def drink(spec: Spec, tl: Timeline, t0: int, t1: int) -> None:
    """A cup to the mouth: the hand comes up in front of the chin, then the elbow lifts and the
    head tips back to drink, held for a swallow or two, and the hand comes down again."""
    n = t1 - t0
    r = tl.rng
    s = _sides(spec.side or "right")[0]
    down, fwd_off = r.uniform(0.12, 0.15), r.uniform(0.11, 0.14)
    sip_a, sip_b = r.uniform(0.3, 0.35), r.uniform(0.68, 0.75)
    sip = bump(n, 0.1, 0.1, sip_a, sip_b)

    def where(ch, j, side, sl):
        return body_point(ch, sl, j[sl, J("head")], SIGN[side] * 0.02, -down, fwd_off)

    def pole(f, left, side):  # the elbow out in front, rising as the cup tips
        return SIGN[side] * 0.4 * left + 0.6 * f + (-0.6 + 1.5 * sip[:, None]) * UP

    _gesture(tl, t0, t1, (s,), where, pole, 0.16, 0.06, 0.94)
    tl.ch.neck_pitch[t0:t1] -= r.uniform(0.4, 0.55) * sip
    tl.ch.spine_bend[t0:t1] -= 0.06 * sip


ARMS_LR = [{"side": x} for x in ("right", "left")]

register(
    Kind(
        name="wipe",
        family="handwork",
        catalogue={"variants": ARMS_LR, "dur": (3.0, 6.0), "count": (2, 5), "per_count": 0.9},
        generate=wipe,
        captions=(
            "{who} wipes a table with {arm}",
            "{who} wipes a flat surface in front of them with {arm}",
            "{who} makes a wiping movement with {arm}{cnt}",
            "{who} leans over and cleans the table with {arm}",
            "{who} is wiping something at waist height with {arm}",
            "using {arm}, {who} wipes in circles on a surface",
        ),
        looks=(
            "leaning over a table, one hand wipes its surface in circles or side to side at one "
            "height; the other hand hangs"
        ),
    )
)
register(
    Kind(
        name="stir",
        family="handwork",
        catalogue={"variants": ARMS_LR, "dur": (3.0, 6.0)},
        generate=stir,
        captions=(
            "{who} stirs something with {arm}",
            "{who} holds a bowl and stirs it with {arm}",
            "{who} performs a stirring motion with {arm}",
            "{who} is stirring something in front of them",
            "{who} stirs a pot, moving {arm} in small circles",
            "{who} mixes something in a bowl with {arm}",
        ),
        looks="one hand holds a bowl in front of the belly, the other stirs small circles in it; the head looks down",
    )
)
register(
    Kind(
        name="drink",
        family="handwork",
        catalogue={"variants": ARMS_LR, "dur": (3.0, 5.0)},
        generate=drink,
        captions=(
            "{who} drinks from a cup, lifting it with {arm}",
            "{who} raises a glass to the mouth with {arm} and drinks",
            "{who} takes a drink from a bottle with {arm}",
            "{who} drinks something, tipping the head back",
            "{who} lifts a cup with {arm} and sips",
            "standing, {who} drinks a glass of water",
        ),
        looks="a hand to the mouth, then the elbow rises and the head tips back to drink, held, and down",
    )
)
