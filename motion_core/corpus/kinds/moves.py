"""Moves on the spot or sideways: march in place, spin around, jump sideways, arm circles."""

from __future__ import annotations

import numpy as np

from ..actions import Spec, Timeline, _arm, _sides, bump, hop_sequence, leg_lift
from ..rig import SIDES
from .base import Kind, default_count, register


def march_in_place(spec: Spec, tl: Timeline, t0: int, t1: int) -> None:
    """Knees up in turn without going anywhere, arms swinging against the legs."""
    n = t1 - t0
    r = tl.rng
    count = default_count(spec, tl, n, 0.6, 4, 8)  # knee lifts in all, both legs together
    h = r.uniform(0.22, 0.32)  # ankle height at the top of a lift
    lead, tail = 0.08, 0.08
    step = (1 - lead - tail) / count
    first = "l" if r.random() < 0.5 else "r"
    lifts = {"l": [], "r": []}
    for k in range(count):
        s = first if k % 2 == 0 else ("r" if first == "l" else "l")
        a = lead + k * step
        lifts[s].append((a, a + step))
    osc = np.zeros(n)
    u = (np.arange(n) + 0.5) / n
    for s in SIDES:
        keys = [(0.0, 0.0, 0.0, 0.0)]
        for a, b in lifts[s]:
            # up with the knee forward, down onto the same spot (ends before the next lift starts)
            keys += [(a + 0.02 * step, 0.0, 0.0, 0.0), (a + 0.45 * step, 0.0, h, 0.1), (b - 0.02, 0.0, 0.0, 0.0)]
            m = (u >= a) & (u < b)
            osc[m] += (1 if s == "r" else -1) * np.sin(np.pi * (u[m] - a) / (b - a))
        keys.append((1.0, 0.0, 0.0, 0.0))
        leg_lift(tl, t0, t1, s, keys, toe_pitch=0.45)
    tl.arm_swing[t0:t1] = 0.0
    e = bump(n, 0.1, 0.1, 0.0, 1.0)
    for s, sg in (("l", 1.0), ("r", -1.0)):  # the left arm forward as the right knee comes up
        _arm(tl, s, t0, t1, flex=sg * 0.45 * osc, elbow=0.9 * e)
    tl.ch.pelvis_y[t0:t1] -= 0.015 * np.abs(osc)


def spin(spec: Spec, tl: Timeline, t0: int, t1: int) -> None:
    """A full turn on the spot (360 degrees) to the left or right, stepping round."""
    n = t1 - t0
    ang = 2 * np.pi * (1 if spec.direction == "left" else -1)
    w = bump(n, 0.25, 0.25, 0.05, 0.95)
    tl.yaw_rate[t0:t1] += ang * w / (w.sum() / tl.fps)
    tl.ch.spine_twist[t0:t1] += 0.2 * np.sign(ang) * bump(n, 0.2, 0.3, 0.03, 0.8)  # the shoulders lead
    tl.gait.cadence[t0:t1] = 2.4  # quick little steps
    for s in SIDES:
        _arm(tl, s, t0, t1, abduct=0.3 * w, elbow=0.4 * w)


def jump_sideways(spec: Spec, tl: Timeline, t0: int, t1: int) -> None:
    """Two-footed jumps to the left or right, landing with the feet apart as they took off."""
    n = t1 - t0
    r = tl.rng
    count = spec.count or 1
    sg = 1.0 if spec.direction == "left" else -1.0
    d = [r.uniform(0.35, 0.6) for _ in range(count)]
    lead = round(0.08 * n)
    before_v = tl.vel[t0:t1, 1].copy()
    before_bend, before_pitch = tl.ch.spine_bend[t0:t1].copy(), tl.ch.pelvis_pitch[t0:t1].copy()
    hop_sequence(tl, t0 + lead, t1 - lead, [{"h": r.uniform(0.14, 0.22), "fwd": x, "crouch": 0.15} for x in d], SIDES)
    # hop_sequence travels forward: turn its travel to the side, and keep the trunk upright
    tl.vel[t0:t1, 0] += sg * (tl.vel[t0:t1, 1] - before_v)
    tl.vel[t0:t1, 1] = before_v
    tl.ch.spine_bend[t0:t1] = before_bend + 0.4 * (tl.ch.spine_bend[t0:t1] - before_bend)
    tl.ch.pelvis_pitch[t0:t1] = before_pitch + 0.4 * (tl.ch.pelvis_pitch[t0:t1] - before_pitch)
    tl.ch.spine_side[t0:t1] += sg * 0.06 * bump(n, 0.2, 0.2, 0.05, 0.95)


def arm_circles(spec: Spec, tl: Timeline, t0: int, t1: int) -> None:
    """Arms straight out to the sides, drawing circles, forwards or backwards."""
    n = t1 - t0
    r = tl.rng
    count = default_count(spec, tl, n, 0.8, 3, 6)
    e = bump(n, 0.15, 0.15, 0.02, 0.98)
    u = np.clip(((np.arange(n) + 0.5) / n - 0.17) / 0.66, 0, 1)
    ramp = np.sin(np.pi * np.clip(u / 0.15, 0, 1) / 2) * np.sin(np.pi * np.clip((1 - u) / 0.15, 0, 1) / 2)
    phase = 2 * np.pi * count * u * (1 if spec.direction == "forward" else -1)
    amp = r.uniform(0.4, 0.55) * ramp
    tl.arm_swing[t0:t1] = 0.0
    for s in _sides(spec.side or "both"):
        # the wrist goes round a circle in the plane across the arm: up at the back, down at the front
        _arm(
            tl,
            s,
            t0,
            t1,
            flex=amp * np.sin(phase),
            abduct=1.45 * e - 0.12 + amp * (np.cos(phase) - 1) * 0.9 + 0.12,
            elbow=-0.15 * e,
        )


SIDE_DIR = [{"direction": d} for d in ("left", "right")]

register(
    Kind(
        name="march_in_place",
        family="moves",
        catalogue={"variants": [{}], "dur": (3.0, 7.0), "count": (4, 8), "per_count": 0.6},
        generate=march_in_place,
        captions=(
            "{who} marches in place{cnt}",
            "{who} marches on the spot, lifting the knees",
            "{who} is marching in place, arms swinging",
            "{who} lifts the knees in turn, marching without moving forward",
            "{who} does high knees on the spot, slowly",
        ),
        looks="knees come up in turn with the opposite arm swinging forward; the feet land where they were",
    )
)
register(
    Kind(
        name="spin",
        family="moves",
        catalogue={"variants": SIDE_DIR, "dur": (2.5, 4.5)},
        generate=spin,
        captions=(
            "{who} spins around to the {side}",
            "{who} turns a full circle on the spot, to the {side}",
            "{who} spins in place to the {side}",
            "{who} does a full 360 degree turn to the {side}",
            "{who} twirls around once, turning {side}",
        ),
        looks="a full turn on the spot with small quick steps, shoulders leading, arms a little out",
    )
)
register(
    Kind(
        name="jump_sideways",
        family="moves",
        catalogue={"variants": SIDE_DIR, "dur": (2.0, 4.5), "count": (1, 2), "per_count": 1.6},
        generate=jump_sideways,
        captions=(
            "{who} jumps sideways to the {side}{cnt}",
            "{who} jumps to the {side}{cnt}",
            "{who} hops sideways with both feet to the {side}{cnt}",
            "{who} leaps to the {side} side{cnt}",
            "{who} does a lateral jump to the {side}{cnt}",
        ),
        looks="crouch, two-footed jump that lands half a metre to the side, arms swinging up, facing kept",
    )
)
register(
    Kind(
        name="arm_circles",
        family="moves",
        catalogue={
            "variants": [{"side": "both", "direction": d} for d in ("forward", "backward")],
            "dur": (3.5, 7.0),
            "count": (3, 6),
            "per_count": 0.8,
        },
        generate=arm_circles,
        captions=(
            "{who} does arm circles{cnt}",
            "{who} holds the arms out to the sides and circles them",
            "{who} makes circles with both arms stretched out",
            "{who} rotates the outstretched arms in small circles{cnt}",
            "{who} warms up the shoulders with arm circles",
        ),
        looks="arms out straight to the sides, the hands draw circles",
    )
)
