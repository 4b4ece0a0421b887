"""Exercises and balance: stand on one leg, touch the toes, bicep curls."""

from __future__ import annotations

import numpy as np

from ..actions import Spec, Timeline, _arm, _sides, bump, foot_steps, keyframes, leg_lift, pulses
from ..rig import OFF, SIDES, SIGN, Channels, J, pose
from .base import Kind, body_point, default_count, register
from .ik import body_axes, reach_world

NAME = {"l": "left", "r": "right"}


def stand_on_one_leg(spec: Spec, tl: Timeline, t0: int, t1: int) -> None:
    """Balance on the ``side`` leg with the other knee raised in front (or the foot held back)."""
    n = t1 - t0
    r = tl.rng
    s = _sides(spec.side)[0]  # the standing leg
    o = "r" if s == "l" else "l"
    knee_up = r.random() < 0.6
    h = r.uniform(0.32, 0.45) if knee_up else r.uniform(0.3, 0.4)
    fw = r.uniform(0.12, 0.22) if knee_up else r.uniform(-0.3, -0.2)
    a, b = r.uniform(0.1, 0.16), r.uniform(0.84, 0.9)
    leg_lift(tl, t0, t1, o, [(0.0, 0, 0, 0), (a, 0.0, h, fw), (b, 0.0, h, fw), (1.0, 0, 0, 0)], toe_pitch=0.5)
    e = bump(n, a + 0.05, 1 - b + 0.05, 0.0, 1.0)
    sway = np.sin(2 * np.pi * np.arange(n) / (tl.fps * r.uniform(1.6, 2.4))) * e
    tl.pelvis_offset[t0:t1, 0] += SIGN[s] * 0.05 * e  # weight over the standing foot
    tl.ch.pelvis_roll[t0:t1] += SIGN[s] * 0.05 * e + 0.02 * sway
    tl.ch.spine_side[t0:t1] -= 0.04 * sway
    for a_ in SIDES:  # arms out a little, for balance
        _arm(tl, a_, t0, t1, abduct=r.uniform(0.3, 0.6) * e + 0.05 * sway)


def touch_toes(spec: Spec, tl: Timeline, t0: int, t1: int) -> None:
    """Fold forward from the hips, legs straight, both hands down to the toes, and back up."""
    n = t1 - t0
    r = tl.rng
    d = keyframes(n, [0.0, 0.08, 0.42, 0.6, 0.92, 1.0], [0, 0, 1, 1, 0, 0])
    ch = tl.ch
    tilt = r.uniform(1.45, 1.6) * d
    ch.pelvis_pitch[t0:t1] += tilt
    ch.spine_bend[t0:t1] += r.uniform(1.0, 1.2) * d
    ch.neck_pitch[t0:t1] += 0.2 * d
    # Tilting the pelvis forward lifts the hip joints (they sit under and behind its joint):
    # lower the pelvis by as much, so the legs keep their standing length and stay straight.
    hip = OFF[J("left_hip")]
    ch.pelvis_y[t0:t1] -= -hip[1] * (1 - np.cos(tilt)) - hip[2] * np.sin(tilt)
    tl.pelvis_offset[t0:t1, 1] -= 0.1 * d  # hips back over the heels
    tl.arm_swing[t0:t1] = 0.0
    sl = slice(t0, t1)
    w = np.clip((d - 0.2) / 0.8, 0, 1)
    w = w * w * (3 - 2 * w)

    def finish(c: Channels) -> None:
        j = pose(c)
        fwd, left = body_axes(c)
        for s in SIDES:
            toe = j[sl, J(f"{NAME[s]}_foot")]
            reach_world(c, s, sl, body_point(c, sl, toe, 0.0, 0.09, -0.03), -fwd[sl] + SIGN[s] * 0.3 * left[sl], w, j)

    tl.finishers.append(finish)


def bicep_curls(spec: Spec, tl: Timeline, t0: int, t1: int) -> None:
    """Elbows by the sides, the forearms curl up to the shoulders and down, count times."""
    n = t1 - t0
    r = tl.rng
    count = default_count(spec, tl, n, 1.1, 2, 5)
    e = bump(n, 0.1, 0.1, 0.02, 0.98)
    reps = pulses(n, count, 0.12, 0.1)
    tl.arm_swing[t0:t1] = 0.0
    for s in _sides(spec.side):
        _arm(tl, s, t0, t1, flex=0.1 * e + 0.15 * reps, abduct=-0.04 * e, elbow=0.1 * e + r.uniform(1.85, 2.0) * reps)
    tl.ch.spine_bend[t0:t1] -= 0.04 * e


register(
    Kind(
        name="stand_on_one_leg",
        family="exercise",
        catalogue={"variants": [{"side": s} for s in ("left", "right")], "dur": (3.0, 6.0)},
        generate=stand_on_one_leg,
        captions=(
            "{who} stands on {leg}",
            "{who} balances on {leg}",
            "{who} lifts one foot and stands on {leg}",
            "{who} stands on one leg, {leg}, keeping balance",
            "{who} balances on one foot, the {side} one",
        ),
        looks="the other knee comes up in front (or the foot back) and is held; arms out a little, swaying",
    )
)
register(
    Kind(
        name="touch_toes",
        family="exercise",
        catalogue={"variants": [{"side": "both"}], "dur": (3.0, 5.5)},
        generate=touch_toes,
        captions=(
            "{who} bends down and touches the toes",
            "{who} touches their toes",
            "{who} folds forward and reaches for the toes",
            "{who} does a toe touch, legs straight",
            "{who} bends over to touch the feet with both hands",
        ),
        looks="legs straight, folds at the hips, both hands reach the toes, rolls back up",
    )
)
register(
    Kind(
        name="bicep_curls",
        family="exercise",
        catalogue={
            "variants": [{"side": s} for s in ("both", "left", "right")],
            "dur": (3.0, 7.0),
            "count": (2, 5),
            "per_count": 1.1,
        },
        generate=bicep_curls,
        captions=(
            "{who} does bicep curls with {arm}{cnt}",
            "{who} curls {arm} up to the shoulder{cnt}",
            "{who} lifts dumbbells, curling {arm}{cnt}",
            "{who} does {num} arm curls with {arm}",
            "{who} bends {arm} at the elbow, lifting a weight{cnt}",
        ),
        looks="elbows stay by the sides, forearms curl up to the shoulders and down",
    )
)


def kneel_down(spec: Spec, tl: Timeline, t0: int, t1: int) -> None:
    """Down onto both knees and back up: a squat with the heels rising (toes tucked), the knees
    going forward onto the floor, kneeling upright, then the same way back."""
    n = t1 - t0
    r = tl.rng
    hold = r.uniform(0.22, 0.34)
    a = (1 - hold) / 2
    times = [0.0, 0.06, 0.06 + 0.45 * a, a, a + hold, 1 - 0.45 * a, 0.94, 1.0]
    ch = tl.ch
    drop = keyframes(n, times, [0, 0, 0.3, 0.435, 0.435, 0.3, 0, 0])
    fwd = keyframes(n, times, [0, 0, -0.04, 0.4, 0.4, -0.04, 0, 0])
    lean = keyframes(n, times, [0, 0, 0.35, 0.02, 0.02, 0.35, 0, 0])
    ch.pelvis_y[t0:t1] -= drop
    tl.pelvis_offset[t0:t1, 1] += fwd
    ch.pelvis_pitch[t0:t1] += lean
    ch.spine_bend[t0:t1] += 0.3 * lean
    tl.arm_swing[t0:t1] = 0.0
    heel = [(times[0], 0.0), (times[1], 0.0), (times[2], 0.7), (times[3], 1.25)]
    heel += [(times[4], 1.25), (times[5], 0.7), (times[6], 0.0), (times[7], 0.0)]
    for s in SIDES:
        foot_steps(tl, t0, t1, s, [], pitch_keys=heel)
        _arm(tl, s, t0, t1, flex=0.5 * lean + 0.15 * drop)


register(
    Kind(
        name="kneel_down",
        family="exercise",
        catalogue={"variants": [{"side": "both"}], "dur": (4.5, 7.5)},
        generate=kneel_down,
        captions=(
            "{who} kneels down on both knees and stands back up",
            "{who} gets down on both knees, then gets up again",
            "{who} kneels on the floor with both knees",
            "{who} drops to both knees and rises again",
            "{who} goes down onto the knees and stands up",
        ),
        looks="squats with the heels rising, the knees come forward onto the floor, kneels upright, and back up",
    )
)


def stand_up_from_kneeling(spec: Spec, tl: Timeline, t0: int, t1: int) -> None:
    """Starts kneeling upright on both knees (shins on the floor behind, toes tucked), then rises
    the way kneel_down came down: the hips go back over the heels into a squat and it stands up.
    Owns its clip (posture "kneeling"): kneels through the first part, stands through the last."""
    n = t1 - t0
    r = tl.rng
    fps = tl.fps
    k0 = r.uniform(0.2, 0.3)  # kneeling until here
    rise = min(0.6, r.uniform(1.8, 2.4) * fps / n)
    times = [0.0, k0, k0 + 0.55 * rise, k0 + rise, 1.0]
    ch = tl.ch
    drop = keyframes(n, times, [0.435, 0.435, 0.3, 0, 0])
    fwd = keyframes(n, times, [0.4, 0.4, -0.04, 0, 0])
    lean = keyframes(n, times, [0.02, 0.02, 0.35, 0, 0])
    ch.pelvis_y[t0:t1] -= drop
    tl.pelvis_offset[t0:t1, 1] += fwd
    ch.pelvis_pitch[t0:t1] += lean
    ch.spine_bend[t0:t1] += 0.3 * lean
    tl.arm_swing[t0:t1] = 0.0
    heel = [(times[0], 1.25), (times[1], 1.25), (times[2], 0.7), (times[3], 0.0), (times[4], 0.0)]
    for s in SIDES:
        foot_steps(tl, t0, t1, s, [], pitch_keys=heel)
        _arm(tl, s, t0, t1, flex=0.5 * lean + 0.15 * drop)


register(
    Kind(
        name="stand_up_from_kneeling",
        family="exercise",
        catalogue={"variants": [{}], "dur": (3.0, 5.0)},
        generate=stand_up_from_kneeling,
        captions=(
            "{who} stands up from a kneeling position",
            "a kneeling person gets up",
            "{who} rises from kneeling on both knees",
            "{who} kneels on the floor and then stands up",
            "{who} gets up off the knees",
            "from kneeling, {who} stands up",
        ),
        posture=("kneeling", "standing"),
        looks="kneeling upright on both knees, the hips go back over the heels into a squat and it stands up",
    )
)
