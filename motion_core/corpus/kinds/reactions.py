"""Reactions and balance: being pushed, stumbling while walking, dodging a blow.

The feet are scripted step by step (steps.py): a shove sends the pelvis off along a fast
pulse and one foot catches it, then the other; a trip cuts one swing short while the trunk
lurches forward, and a quick long step with the other foot catches the fall.
"""

from __future__ import annotations

import numpy as np

from ..actions import Spec, Timeline, _arm, bump, keyframes
from ..rig import SIDES
from .base import Kind, register
from .steps import Step, drive_path, set_steps, walk_steps

PUSH_DIR = {"forward": (1.0, 0.0), "backward": (-1.0, 0.0), "left": (0.0, 1.0), "right": (0.0, -1.0)}


def _pulse(n: int, at: int, fps: float, peak_s: float) -> np.ndarray:
    """(n,) 0 before frame ``at``, then x e^(1-x) with x the time since ``at`` over peak_s: rises
    to 1 at peak_s and dies away (a jolt)."""
    x = np.clip((np.arange(n) - at) / (peak_s * fps), 0, None)
    return x * np.exp(1 - x)


def being_pushed(spec: Spec, tl: Timeline, t0: int, t1: int) -> None:
    """Standing, shoved towards ``direction``: the trunk jolts that way, the arms fly out, one
    foot then the other step after the body (and the first one closes in), balance regained."""
    n = t1 - t0
    r = tl.rng
    fps = tl.fps
    d = spec.direction or "backward"
    uf, ul = PUSH_DIR[d]
    side_push = ul != 0.0
    strength = r.uniform(0.0, 1.0)
    dist = (0.2 + 0.18 * strength) if side_push else (0.24 + 0.28 * strength)
    hit = round(r.uniform(0.1, 0.18) * n)
    tau = r.uniform(0.12, 0.16)
    t = (np.arange(n) - hit) / fps
    v = np.where(t > 0, t * np.exp(-t / tau), 0.0)
    disp = dist * np.cumsum(v) / v.sum()
    drive_path(tl, t0, uf * disp, ul * disp)
    # the feet: the first step lands past where the body will stop, the second beside it
    lead = ("l" if ul > 0 else "r") if side_push else ("l" if r.random() < 0.5 else "r")
    other = "r" if lead == "l" else "l"
    over = 0.06 + 0.1 * strength
    sw = round(r.uniform(0.24, 0.3) * fps)
    a = hit + round(r.uniform(0.04, 0.1) * fps)
    steps = [Step(lead, a, a + sw, uf * (dist + over), ul * (dist + over), 0.07)]
    b = a + sw + round(0.05 * fps)
    steps.append(Step(other, b, b + sw, uf * dist, ul * dist, 0.06))
    c = b + sw + round(0.12 * fps)
    steps.append(Step(lead, c, c + round(1.2 * sw), uf * dist, ul * dist, 0.05))
    set_steps(tl, t0, t1, steps)
    tl.arm_swing[t0:t1] = 0.0
    ch = tl.ch
    k = 0.75 + 0.5 * strength
    jolt = k * _pulse(n, hit, fps, r.uniform(0.15, 0.2))
    if d == "backward":  # shoved in the chest: the trunk goes back, the head lags forward
        ch.spine_bend[t0:t1] -= 0.35 * jolt
        ch.pelvis_pitch[t0:t1] -= 0.12 * jolt
        ch.neck_pitch[t0:t1] += 0.3 * jolt
    elif d == "forward":  # shoved in the back: the trunk pitches forward, the head lags back
        ch.spine_bend[t0:t1] += 0.45 * jolt
        ch.pelvis_pitch[t0:t1] += 0.15 * jolt
        ch.neck_pitch[t0:t1] -= 0.3 * jolt
    else:  # shoved at the shoulder: the upper body bends away from the push
        ch.spine_side[t0:t1] += ul * 0.35 * jolt
        ch.pelvis_roll[t0:t1] += ul * 0.08 * jolt
    u_hit = hit / n
    fly = (
        keyframes(
            n,
            [0.0, u_hit + 0.05 * fps / n, u_hit + 0.3 * fps / n, u_hit + 0.65 * fps / n, u_hit + 1.5 * fps / n, 1.0],
            [0, 0, 1, 0.8, 0, 0],
        )
        * k
    )
    for s in SIDES:
        if d == "backward":  # the arms fly forward
            _arm(tl, s, t0, t1, flex=0.65 * fly, abduct=0.35 * fly, elbow=0.4 * fly)
        elif d == "forward":  # back and out
            _arm(tl, s, t0, t1, flex=-0.45 * fly, abduct=0.8 * fly, elbow=0.5 * fly)
        else:  # out to the sides, the far one higher
            far = (s == "r") == (ul > 0)
            _arm(tl, s, t0, t1, abduct=(0.85 if far else 0.5) * fly, elbow=0.35 * fly, flex=0.2 * fly)
    ch.pelvis_y[t0:t1] -= 0.04 * fly


def stumble(spec: Spec, tl: Timeline, t0: int, t1: int) -> None:
    """Walking forward, one foot catches: its swing stops short, the trunk lurches forward, the
    arms fly out, the other foot takes a quick long step to catch the fall, and the walk goes on."""
    n = t1 - t0
    r = tl.rng
    fps = tl.fps
    v0 = r.uniform(0.9, 1.25)
    cad = 1.6 + 0.3 * v0
    env = bump(n, min(0.45, (0.7 * fps) / n))
    trip = round(r.uniform(0.4, 0.52) * n)
    # the trip checks the body: it slows at once and picks up again over a second or so
    u = (np.arange(n) - trip) / fps
    slow = np.where(u < 0, 0.0, np.clip(u / 0.25, 0, 1) * np.clip((1.6 - u) / 1.0, 0, 1))
    disp = np.cumsum(v0 * env * (1 - 0.4 * slow)) / fps
    drive_path(tl, t0, disp)
    first = "l" if r.random() < 0.5 else "r"
    sw = round(0.38 * (2 / cad) * fps)
    before, pos = walk_steps(disp, fps, cad, first, start=round(0.15 * fps), until=trip)
    a_side = ("r" if before[-1].side == "l" else "l") if before else first
    b_side = "r" if a_side == "l" else "l"
    a = before[-1].a + round(fps / cad) if before else trip  # the next beat: the trip is a step
    # the caught swing: low, stopped short, set down under the body
    cut = max(3, round(0.55 * sw))
    want = float(disp[min(n - 1, a + sw + round(0.6 * fps))])
    stop = pos[a_side] + 0.45 * (want - pos[a_side])
    steps = [*before, Step(a_side, a, a + cut, stop, 0.0, 0.035)]
    pos[a_side] = stop
    # the catching step: quick and long, past where the body will be
    cb = a + cut
    quick = max(4, round(0.7 * sw))
    reach = float(disp[min(n - 1, cb + quick)]) + r.uniform(0.1, 0.16)
    steps.append(Step(b_side, cb, cb + quick, reach, 0.0, 0.1))
    pos[b_side] = reach
    after, _ = walk_steps(disp, fps, cad, a_side, start=cb + quick + 1, plants=pos)
    steps += after
    set_steps(tl, t0, t1, steps)
    ch = tl.ch
    # walking posture, as locomote sets it
    ch.pelvis_pitch[t0:t1] += 0.05 * env
    ch.spine_bend[t0:t1] += 0.025 * env
    ch.pelvis_y[t0:t1] -= 0.02 * env
    for s in SIDES:
        ch.arms[s].elbow[t0:t1] += 0.05 * env
    catch = (a + 0.3 * cut) / n
    lurch = keyframes(
        n, [0.0, catch, catch + 0.25 * fps / n, catch + 0.4 * fps / n, catch + 1.3 * fps / n, 1.0], [0, 0, 1, 1, 0, 0]
    )
    k = r.uniform(0.85, 1.15)
    ch.spine_bend[t0:t1] += 0.5 * k * lurch
    ch.pelvis_pitch[t0:t1] += 0.22 * k * lurch
    ch.neck_pitch[t0:t1] -= 0.3 * k * lurch
    ch.pelvis_y[t0:t1] -= 0.02 * lurch
    fly = keyframes(
        n,
        [0.0, catch + 0.05 * fps / n, catch + 0.3 * fps / n, catch + 0.5 * fps / n, catch + 1.2 * fps / n, 1.0],
        [0, 0, 1, 1, 0, 0],
    )
    for s in SIDES:
        _arm(tl, s, t0, t1, flex=0.75 * k * fly, abduct=0.45 * k * fly, elbow=0.35 * fly)
    tl.arm_swing[t0:t1] = (0.35 + 0.45 * v0 * env) * (1 - fly)


def dodge(spec: Spec, tl: Timeline, t0: int, t1: int) -> None:
    """Fists up in a guard, then a quick slip of the head and trunk to one side (sometimes
    ducking too), held a moment, and back; the feet stay where they are."""
    n = t1 - t0
    r = tl.rng
    fps = tl.fps
    sg = 1.0 if spec.direction == "left" else -1.0
    guard = bump(n, 0.15, 0.15, 0.02, 0.98)
    for s in SIDES:
        _arm(tl, s, t0, t1, flex=0.6 * guard, abduct=-0.1 * guard, elbow=1.9 * guard)
    a = r.uniform(0.3, 0.42)
    out, hold, back = (r.uniform(0.18, 0.25) * fps / n, r.uniform(0.25, 0.5) * fps / n, r.uniform(0.35, 0.5) * fps / n)
    slip = keyframes(n, [0.0, a, a + out, a + out + hold, min(0.97, a + out + hold + back), 1.0], [0, 0, 1, 1, 0, 0])
    ch = tl.ch
    depth = r.uniform(0.8, 1.1)
    ch.spine_side[t0:t1] += sg * 0.42 * depth * slip
    ch.pelvis_roll[t0:t1] += sg * 0.1 * depth * slip
    tl.pelvis_offset[t0:t1, 0] += sg * 0.07 * slip
    if r.random() < 0.5:  # ducks as well
        ch.pelvis_y[t0:t1] -= r.uniform(0.08, 0.13) * slip
        ch.spine_bend[t0:t1] += 0.3 * slip
        ch.pelvis_pitch[t0:t1] += 0.12 * slip
    ch.pelvis_y[t0:t1] -= 0.04 * guard  # knees soft in the stance
    ch.spine_bend[t0:t1] += 0.08 * guard
    tl.arm_swing[t0:t1] = 0.0


DIRS4 = [{"direction": d} for d in ("backward", "forward", "left", "right")]

register(
    Kind(
        name="being_pushed",
        family="reactions",
        catalogue={"variants": DIRS4, "dur": (2.5, 4.0)},
        generate=being_pushed,
        captions=(
            "{who} is pushed {dir} and steps to regain balance",
            "{who} gets shoved and stumbles {dir}, then recovers",
            "{who} stands still, gets pushed and takes a step {dir}",
            "{who} is pushed and takes a few steps {dir} to catch their balance",
            "{who} gets a push and staggers {dir}",
            "standing, {who} is shoved {dir} and regains balance",
        ),
        looks=(
            "standing, a shove sends the chest off fast, the trunk jolts that way and the arms "
            "fly out; one foot steps past where the body stops, the other beside it, the first closes in"
        ),
    )
)
register(
    Kind(
        name="stumble",
        family="reactions",
        catalogue={"variants": [{"direction": "forward"}], "dur": (4.5, 7.0)},
        generate=stumble,
        captions=(
            "{who} stumbles while walking forward",
            "{who} walks forward, trips and catches themselves",
            "{who} trips over something while walking and keeps going",
            "{who} is walking, stumbles a little, then recovers",
            "walking forward, {who} trips, lurches and regains balance",
            "{who} walks and stumbles forward",
        ),
        looks=(
            "walking, one swing catches and is set down short, the trunk lurches forward with "
            "the arms thrown out, the other foot takes a quick long step, and the walk goes on"
        ),
    )
)
register(
    Kind(
        name="dodge",
        family="reactions",
        catalogue={"variants": [{"direction": d} for d in ("left", "right")], "dur": (2.0, 3.5)},
        generate=dodge,
        captions=(
            "{who} dodges to the {side}",
            "{who} ducks away to the {side}",
            "{who} in a boxing stance dodges a punch to the {side}",
            "{who} leans to the {side} to avoid a hit",
            "{who} dodges something, moving the head to the {side}",
            "{who} puts the fists up and slips to the {side}",
        ),
        looks=(
            "fists up in a guard, the head and trunk slip quickly to one side (sometimes ducking "
            "too), held a moment, and back; the feet stay"
        ),
    )
)
