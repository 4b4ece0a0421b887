"""Moves on the spot or travelling: march in place, spin around, jump sideways, arm circles, a
jump with a turn in the air, a jump backwards, stomping, walking heel to toe along a line."""

from __future__ import annotations

import numpy as np

from ..actions import G, Spec, Timeline, _arm, _sides, bump, hop_sequence, keyframes, leg_lift, smoothstep
from ..gait import FootOverride, Plant
from ..rig import FOOT_PITCH_FLAT, SIDES, SIGN, Channels, ankle_height_flat
from .base import Kind, default_count, register
from .steps import Step, drive_path, set_steps, walk_steps


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


# ----------------------------------------------------------------------------------------
# Jumps with a turn or backwards, stomping, walking heel to toe on a line
# ----------------------------------------------------------------------------------------


def spin_jump(spec: Spec, tl: Timeline, t0: int, t1: int) -> None:
    """A crouch with the shoulders wound the other way, a two-footed jump that turns the body
    ``angle`` degrees in the air (arms pulled in), and a landing that absorbs it, facing the new way."""
    n = t1 - t0
    r = tl.rng
    fps = tl.fps
    sg = 1.0 if spec.direction == "left" else -1.0
    ang = np.radians(spec.angle or 180)
    h = r.uniform(0.17, 0.22) + 0.05 * ang / np.pi
    nf = max(4, round(2 * np.sqrt(2 * h / G) * fps))
    depth = r.uniform(0.14, 0.18)
    f0 = round(r.uniform(0.25, 0.32) * n)
    f1 = min(n - 8, f0 + nf)
    c0 = max(1, f0 - round(0.45 * fps))
    dy = np.zeros(n)
    dy[c0:f0] = -depth * np.sin(np.linspace(0, np.pi / 2, f0 - c0)) ** 2
    push = max(2, (f0 - c0) // 3)
    dy[f0 - push : f0] = -depth * (1 - smoothstep(np.linspace(0, 1, push)))
    tt = (np.arange(f1 - f0) + 0.5) / fps
    vz = G * (f1 - f0) / fps / 2
    dy[f0:f1] = vz * tt - 0.5 * G * tt**2
    land = min(n - f1, round(0.45 * fps))
    dy[f1 : f1 + land] -= 0.8 * depth * np.sin(np.linspace(0, np.pi, land))
    ch = tl.ch
    ch.pelvis_y[t0:t1] += dy
    # the turn happens in the air (eased over the flight, a little before and after)
    wt = np.zeros(n)
    wt[f0 - 1 : f1 + 1] = np.sin(np.linspace(0, np.pi, f1 - f0 + 2)) ** 2
    tl.yaw_rate[t0:t1] += sg * ang * wt / (wt.sum() / fps)
    wind = keyframes(n, [0.0, c0 / n, f0 / n, f1 / n, (f1 + land) / n, 1.0], [0, 0, -1, 0.6, 0, 0])
    ch.spine_twist[t0:t1] += sg * 0.3 * wind
    ch.spine_bend[t0:t1] += 0.3 * np.clip(-dy / depth, 0, 1)
    tuck = keyframes(n, [0.0, c0 / n, f0 / n, (f0 + 2) / n, f1 / n, (f1 + land) / n, 1.0], [0, 0, 0.3, 1, 1, 0, 0])
    for s in SIDES:  # arms swing back in the crouch, in to the chest in the air
        _arm(tl, s, t0, t1, flex=0.6 * tuck - 0.4 * np.clip(-dy / depth, 0, 1) * (1 - tuck), elbow=1.4 * tuck)
    tl.arm_swing[t0:t1] = 0.0

    def fn(start: int, end: int, plants: dict[str, Plant], chn: Channels):
        out = {}
        a0 = t0 + f0
        root0 = chn.root_xz[a0]
        for s in SIDES:
            p0 = plants[s]
            rel = p0.xz - root0
            a, yw, pt = (np.zeros((n, 3)), np.full(n, p0.yaw), np.full(n, FOOT_PITCH_FLAT))
            y0 = ankle_height_flat(s)
            a[:] = (p0.xz[0], y0, p0.xz[1])
            for k in range(f0, n):
                t = t0 + min(k, f1)
                dh = chn.heading[t] - chn.heading[a0]
                c, si = np.cos(dh), np.sin(dh)
                xz = chn.root_xz[t] + np.array([c * rel[0] + si * rel[1], -si * rel[0] + c * rel[1]])
                lift = (max(dy[k], 0.0) + 0.06 * np.sin(np.pi * (k - f0) / max(1, f1 - f0))) if k < f1 else 0.0
                a[k] = (xz[0], y0 + lift, xz[1])
                yw[k] = p0.yaw + dh
            out[s] = (a[: end - start], yw[: end - start], pt[: end - start])
        return out

    tl.overrides.append(FootOverride(t0, t1, SIDES, fn))


def jump_backward(spec: Spec, tl: Timeline, t0: int, t1: int) -> None:
    """A crouch and a two-footed jump backwards, landing half a metre or more behind, facing the same way."""
    n = t1 - t0
    r = tl.rng
    lead = round(0.1 * n)
    hop_sequence(
        tl, t0 + lead, t1 - lead, [{"h": r.uniform(0.14, 0.2), "fwd": -r.uniform(0.5, 0.65), "crouch": 0.16}], SIDES
    )


def stomp(spec: Spec, tl: Timeline, t0: int, t1: int) -> None:
    """One foot comes up (knee bent), then is driven down hard onto the floor where it was, count times."""
    n = t1 - t0
    r = tl.rng
    fps = tl.fps
    s = _sides(spec.side)[0]
    count = spec.count or 1
    per = 0.84 / count
    keys = [(0.0, 0.0, 0.0, 0.0)]
    up_s = r.uniform(0.35, 0.5) * fps / n
    down_s = r.uniform(0.1, 0.14) * fps / n
    hits = []
    slot = min(per, up_s + 0.15 * fps / n + down_s + 0.25 * fps / n)
    for k in range(count):
        a = 0.08 + k * per + 0.5 * (per - slot)  # each stomp in the middle of its share
        top = min(a + up_s, a + 0.6 * per)
        hit = top + r.uniform(0.05, 0.15) * fps / n + down_s
        hy, fw = r.uniform(0.2, 0.3), r.uniform(0.04, 0.1)
        keys += [(a, 0.0, 0.0, 0.0), (top, 0.0, hy, fw), (hit - down_s, 0.0, hy + 0.02, fw), (hit, 0.0, 0.0, 0.0)]
        hits.append(hit)
    keys.append((1.0, 0.0, 0.0, 0.0))
    leg_lift(tl, t0, t1, s, keys, toe_pitch=0.25)
    u = (np.arange(n) + 0.5) / n
    jolt = sum(np.exp(-((((u - h) * n / fps) / 0.1) ** 2)) for h in hits)
    ch = tl.ch
    ch.pelvis_y[t0:t1] -= 0.03 * jolt
    ch.spine_bend[t0:t1] += 0.12 * jolt
    o = "r" if s == "l" else "l"
    tl.pelvis_offset[t0:t1, 0] += SIGN[o] * 0.05 * bump(n, 0.1, 0.1, 0.02, 0.98)  # weight over the other foot
    for a_ in SIDES:
        _arm(tl, a_, t0, t1, abduct=0.2 * bump(n, 0.1) + 0.15 * jolt, flex=-0.15 * jolt, elbow=0.3 * jolt)


def walk_a_line(spec: Spec, tl: Timeline, t0: int, t1: int) -> None:
    """Slowly forward, heel to toe along one line (as on a beam or a rope): each foot set just in
    front of the other on the line, the swing passing outside; arms out to the sides for balance,
    swaying, eyes on the line. Steps off the line at the end."""
    n = t1 - t0
    r = tl.rng
    fps = tl.fps
    v = r.uniform(0.22, 0.32)
    step = r.uniform(0.21, 0.26)
    cad = v / step
    env = bump(n, min(0.45, 0.8 * fps / n))
    disp = np.cumsum(v * env) / fps
    drive_path(tl, t0, disp)
    width = float(tl.gait.width[t0])
    on_line = {"l": -width, "r": width}
    first = "l" if r.random() < 0.5 else "r"
    steps, _ = walk_steps(
        disp,
        fps,
        cad,
        first,
        duty=0.75,
        lift=0.04,
        lat=on_line,
        start=round(0.2 * fps),
        until=n - round(0.9 * fps),
        bulge=0.07,
    )
    # off the line: each foot steps back out beside the other
    last = steps[-1].b if steps else 0
    for k, s in enumerate(("r", "l") if not steps or steps[-1].side == "l" else ("l", "r")):
        a = last + 2 + k * round(0.4 * fps)
        steps.append(Step(s, a, a + round(0.35 * fps), float(disp[-1]), 0.0, 0.05))
    set_steps(tl, t0, t1, steps)
    ch = tl.ch
    e = bump(n, min(0.45, 0.5 * fps / n), min(0.45, 0.6 * fps / n), 0.0, 1.0)
    sway = np.sin(2 * np.pi * np.arange(n) / (fps * r.uniform(1.8, 2.6))) * e
    for s in SIDES:
        _arm(tl, s, t0, t1, abduct=r.uniform(1.2, 1.4) * e + SIGN[s] * 0.15 * sway, elbow=0.15 * e)
    ch.spine_side[t0:t1] += 0.05 * sway
    ch.pelvis_roll[t0:t1] += 0.02 * sway
    ch.neck_pitch[t0:t1] += 0.35 * e
    tl.arm_swing[t0:t1] = 0.0


register(
    Kind(
        name="spin_jump",
        family="moves",
        catalogue={
            "variants": [{"direction": d, "angle": a} for d in ("left", "right") for a in (90, 180, 360)],
            "dur": (2.0, 3.5),
        },
        generate=spin_jump,
        captions=(
            "{who} jumps and turns {angle} degrees to the {side} in the air",
            "{who} jumps up and spins {angle} degrees to the {side}",
            "{who} does a {angle} degree jump turn to the {side}",
            "{who} jumps, rotating {angle} degrees to the {side} before landing",
            "{who} jumps and turns {side} by {angle} degrees mid-air",
        ),
        looks=(
            "a crouch, a two-footed jump that turns 90, 180 or 360 degrees in the air with the "
            "arms pulled in, a soft landing"
        ),
    )
)
register(
    Kind(
        name="jump_backward",
        family="moves",
        catalogue={"variants": [{"direction": "backward"}], "dur": (2.0, 3.5)},
        generate=jump_backward,
        captions=(
            "{who} jumps backwards",
            "{who} jumps back with both feet",
            "{who} hops backwards once",
            "{who} does a jump to the back",
            "{who} leaps backwards",
        ),
        looks="a crouch and a two-footed jump half a metre backwards, arms swinging up, facing kept",
    )
)
register(
    Kind(
        name="stomp",
        family="moves",
        catalogue={
            "variants": [{"side": s} for s in ("left", "right")],
            "dur": (2.0, 3.5),
            "count": (1, 3),
            "per_count": 1.0,
        },
        generate=stomp,
        captions=(
            "{who} stomps with {leg}{cnt}",
            "{who} stomps on the ground with {leg}{cnt}",
            "{who} lifts {leg} and stomps it down{cnt}",
            "{who} stamps hard on the floor with {leg}{cnt}",
            "{who} stomps the ground with {leg}{cnt}",
        ),
        looks="one knee comes up and the foot is driven down hard onto the same spot, once to three times",
    )
)
register(
    Kind(
        name="walk_a_line",
        family="moves",
        catalogue={"variants": [{"direction": "forward"}], "dur": (4.5, 8.0)},
        generate=walk_a_line,
        captions=(
            "{who} walks along a line, heel to toe",
            "{who} walks slowly forward on a line with the arms out for balance",
            "{who} balances along a narrow beam",
            "{who} walks on a tightrope, arms stretched out",
            "{who} puts one foot in front of the other, walking a straight line",
            "{who} walks heel to toe along a line",
        ),
        looks=(
            "slowly forward heel to toe on one line, the swing passing outside, arms out to the sides, eyes on the line"
        ),
    )
)
