"""Standing gestures: hands on the body (hands on hips, arms crossed, scratching the head,
saluting, checking a watch, ...), and the head and shoulders (looking around, a shrug). A hand
goes to the body along an eased path that comes up close in front of it, and, once there, the
arm IK holds it on the body part as the body moves."""

from __future__ import annotations

import numpy as np

from ..actions import Spec, Timeline, _arm, _sides, bump, keyframes
from ..rig import SIDES, SIGN, Channels, J, pose
from .base import Kind, body_point, register
from .channels import extra
from .ik import body_axes, reach_world

UP = np.array([0.0, 1.0, 0.0])
NAME = {"l": "left", "r": "right"}


def _gesture(tl: Timeline, t0: int, t1: int, sides, where, pole_fn, rise: float, start: float, end: float):
    """Hands of ``sides`` go to where(ch, joints, side, sl) -> (n, 3) world targets, with the
    elbow towards pole_fn(fwd, left, side) -> (n, 3); in over ``rise`` of the window from
    ``start``, back out by ``end``. On the way the wrist follows a path from where it hung to
    the target, bowed forward a little (by a fifth of its length): the elbow bends as the hand
    comes up close in front of the body, rather than the arm swinging out straight first."""
    n = t1 - t0
    w = bump(n, rise, rise, start, end)
    w = np.clip(w / 0.98, 0, 1)  # exactly on the target over the hold
    sl = slice(t0, t1)
    tl.arm_swing[t0:t1] = 0.0

    def finish(ch: Channels) -> None:
        j = pose(ch)
        fwd, left = body_axes(ch)
        for s in sides:
            target = where(ch, j, s, sl)
            hung = j[sl, J(f"{NAME[s]}_wrist")]
            bow = 0.2 * np.linalg.norm(target - hung, axis=-1) * np.sin(np.pi * w)
            path = hung + w[:, None] * (target - hung) + bow[:, None] * fwd[sl]
            reach_world(ch, s, sl, path, pole_fn(fwd[sl], left[sl], s), np.clip(w / 0.15, 0, 1), j)

    tl.finishers.append(finish)
    return w


def hands_on_hips(spec: Spec, tl: Timeline, t0: int, t1: int) -> None:
    r = tl.rng
    out, up, back = r.uniform(0.1, 0.13), r.uniform(0.06, 0.11), r.uniform(0.0, 0.04)
    w = _gesture(
        tl,
        t0,
        t1,
        SIDES,
        lambda ch, j, s, sl: body_point(ch, sl, j[sl, J(f"{NAME[s]}_hip")], SIGN[s] * out, up, -back),
        lambda f, left, s: SIGN[s] * left - 0.35 * f,
        0.18,
        0.03,
        0.97,
    )
    tl.ch.spine_bend[t0:t1] -= 0.06 * w  # chest up


def cross_arms(spec: Spec, tl: Timeline, t0: int, t1: int) -> None:
    r = tl.rng
    top = "l" if r.random() < 0.5 else "r"  # which forearm lies on top
    depth = r.uniform(0.16, 0.2)
    across = r.uniform(0.1, 0.15)
    low = r.uniform(0.12, 0.18)

    def where(ch, j, s, sl):
        # each wrist by the other arm's elbow, in front of the chest
        chest = j[sl, J("spine3")]
        on_top = s == top
        return body_point(
            ch, sl, chest, -SIGN[s] * across, -low + (0.04 if on_top else 0.0), depth + (0.04 if on_top else 0.0)
        )

    _gesture(tl, t0, t1, SIDES, where, lambda f, left, s: SIGN[s] * 0.5 * left - UP, 0.2, 0.03, 0.97)


def scratch_head(spec: Spec, tl: Timeline, t0: int, t1: int) -> None:
    r = tl.rng
    s = _sides(spec.side)[0]
    n = t1 - t0
    hz = r.uniform(2.5, 4.0)
    rub = 0.025 * np.sin(2 * np.pi * hz * np.arange(n) / tl.fps)
    side_off, up = r.uniform(0.05, 0.09), r.uniform(0.09, 0.13)

    def where(ch, j, side, sl):
        return body_point(ch, sl, j[sl, J("head")], SIGN[side] * side_off, up, -0.02 + rub)

    _gesture(tl, t0, t1, (s,), where, lambda f, left, side: SIGN[side] * left + 0.3 * f + 0.2 * UP, 0.22, 0.05, 0.95)
    tl.ch.neck_pitch[t0:t1] += 0.12 * bump(n, 0.25, 0.25, 0.05, 0.95)  # head tilts into the hand


def salute(spec: Spec, tl: Timeline, t0: int, t1: int) -> None:
    r = tl.rng
    s = _sides(spec.side or "right")[0]
    out, fwd_off = r.uniform(0.11, 0.14), r.uniform(0.05, 0.08)

    def where(ch, j, side, sl):
        return body_point(ch, sl, j[sl, J("head")], SIGN[side] * out, 0.0, fwd_off)

    _gesture(tl, t0, t1, (s,), where, lambda f, left, side: SIGN[side] * left + 0.25 * f, 0.12, 0.1, 0.9)
    tl.ch.spine_bend[t0:t1] -= 0.05 * bump(t1 - t0, 0.12, 0.12, 0.1, 0.9)  # standing to attention


def check_watch(spec: Spec, tl: Timeline, t0: int, t1: int) -> None:
    r = tl.rng
    s = _sides(spec.side or "left")[0]
    low, depth = r.uniform(0.14, 0.22), r.uniform(0.3, 0.36)

    def where(ch, j, side, sl):
        return body_point(ch, sl, j[sl, J("spine3")], SIGN[side] * 0.03, -low, depth)

    w = _gesture(tl, t0, t1, (s,), where, lambda f, left, side: SIGN[side] * 0.7 * left - UP, 0.22, 0.08, 0.92)
    tl.ch.neck_pitch[t0:t1] += 0.5 * w  # looks down at the wrist
    tl.ch.spine_bend[t0:t1] += 0.05 * w


def touch_face(spec: Spec, tl: Timeline, t0: int, t1: int) -> None:
    """One hand to the cheek or chin, elbow down, held a moment (thinking, feeling the face)."""
    r = tl.rng
    s = _sides(spec.side)[0]
    chin = r.random() < 0.5
    out = r.uniform(0.0, 0.03) if chin else r.uniform(0.05, 0.08)
    down, fwd_off = (
        (r.uniform(0.12, 0.15), r.uniform(0.08, 0.11)) if chin else (r.uniform(0.07, 0.1), r.uniform(0.06, 0.09))
    )

    def where(ch, j, side, sl):
        return body_point(ch, sl, j[sl, J("head")], SIGN[side] * out, -down, fwd_off)

    w = _gesture(
        tl, t0, t1, (s,), where, lambda f, left, side: SIGN[side] * 0.4 * left - UP + 0.3 * f, 0.22, 0.05, 0.95
    )
    tl.ch.neck_pitch[t0:t1] += 0.1 * w


def clasp_hands(spec: Spec, tl: Timeline, t0: int, t1: int) -> None:
    """Both palms together in front of the chest (praying, pleading), elbows down and out, the
    head bowed a little."""
    r = tl.rng
    low, depth = r.uniform(0.05, 0.12), r.uniform(0.2, 0.26)
    gap = r.uniform(0.02, 0.035)  # wrist to wrist; the palms meet beyond the stick figure's wrists

    def where(ch, j, side, sl):
        return body_point(ch, sl, j[sl, J("spine3")], SIGN[side] * gap, -low, depth)

    w = _gesture(tl, t0, t1, SIDES, where, lambda f, left, side: SIGN[side] * 0.8 * left - UP, 0.2, 0.04, 0.96)
    tl.ch.neck_pitch[t0:t1] += r.uniform(0.15, 0.35) * w  # head bowed


def phone_call(spec: Spec, tl: Timeline, t0: int, t1: int) -> None:
    """One hand held at the ear as if on the phone, elbow down in front, the head tipped a little."""
    r = tl.rng
    s = _sides(spec.side)[0]
    out, up, fwd_off = r.uniform(0.09, 0.12), r.uniform(-0.06, -0.03), r.uniform(-0.03, 0.0)

    def where(ch, j, side, sl):
        return body_point(ch, sl, j[sl, J("head")], SIGN[side] * out, up, fwd_off)

    w = _gesture(
        tl, t0, t1, (s,), where, lambda f, left, side: SIGN[side] * 0.1 * left - UP + 0.2 * f, 0.15, 0.04, 0.96
    )
    tl.ch.neck_pitch[t0:t1] += 0.1 * w


ARMS_LR = [{"side": s} for s in ("left", "right")]

register(
    Kind(
        name="hands_on_hips",
        family="gestures",
        catalogue={"variants": [{"side": "both"}], "dur": (2.5, 5.0)},
        generate=hands_on_hips,
        captions=(
            "{who} puts both hands on the hips",
            "{who} stands with the hands on the hips",
            "{who} places the hands on the waist, elbows out",
            "{who} rests the hands on the hips",
            "{who} stands akimbo",
        ),
        looks="both hands to the sides of the pelvis, elbows out, chest up; held, then back down",
    )
)
register(
    Kind(
        name="cross_arms",
        family="gestures",
        catalogue={"variants": [{"side": "both"}], "dur": (2.5, 5.0)},
        generate=cross_arms,
        captions=(
            "{who} crosses the arms",
            "{who} folds the arms across the chest",
            "{who} stands with the arms crossed",
            "{who} crosses both arms in front of the chest",
            "{who} folds the arms and waits",
        ),
        looks="forearms folded across in front of the chest, each hand by the other elbow",
    )
)
register(
    Kind(
        name="scratch_head",
        family="gestures",
        catalogue={"variants": ARMS_LR, "dur": (2.5, 4.5)},
        generate=scratch_head,
        captions=(
            "{who} scratches the head with {arm}",
            "{who} scratches their head with {arm}",
            "{who} raises {arm} and scratches the top of the head",
            "{who} looks puzzled and scratches the head with {arm}",
            "with {arm}, {who} rubs the top of the head",
        ),
        looks="one hand up on top of the head, rubbing back and forth, head tilting into it",
    )
)
register(
    Kind(
        name="salute",
        family="gestures",
        catalogue={"variants": [{"side": "right"}, {"side": "left"}], "dur": (2.0, 4.0)},
        generate=salute,
        captions=(
            "{who} salutes with {arm}",
            "{who} gives a military salute with {arm}",
            "{who} raises {arm} to the forehead in a salute",
            "{who} stands to attention and salutes with {arm}",
            "{who} salutes",
        ),
        looks="the hand goes up briskly to the brow, elbow out to the side, held, then down",
    )
)
register(
    Kind(
        name="check_watch",
        family="gestures",
        catalogue={"variants": [{"side": "left"}, {"side": "right"}], "dur": (2.5, 4.5)},
        generate=check_watch,
        captions=(
            "{who} checks the watch on {arm}",
            "{who} looks at the wristwatch on {arm}",
            "{who} raises {arm} and checks the time",
            "{who} glances at a watch on {arm}",
            "{who} lifts the wrist to check the time, {arm}",
        ),
        looks="the forearm comes up level in front of the chest and the head tips down to look at it",
    )
)
register(
    Kind(
        name="touch_face",
        family="gestures",
        catalogue={"variants": ARMS_LR, "dur": (2.5, 4.5)},
        generate=touch_face,
        captions=(
            "{who} touches the face with {arm}",
            "{who} puts {arm} to the cheek",
            "{who} raises {arm} and rubs the chin",
            "{who} strokes the chin with {arm}, thinking",
            "{who} brings {arm} up to the face",
        ),
        looks="one hand comes up to the cheek or chin, elbow down in front of the chest, held, then down",
    )
)
register(
    Kind(
        name="clasp_hands",
        family="gestures",
        catalogue={"variants": [{"side": "both"}], "dur": (2.5, 5.0)},
        generate=clasp_hands,
        captions=(
            "{who} puts the hands together in prayer",
            "{who} prays with the palms pressed together",
            "{who} clasps both hands in front of the chest",
            "{who} holds the palms together in front of the chest and bows the head",
            "{who} presses the hands together as if praying",
            "{who} brings both hands together at the chest",
        ),
        looks="both palms together in front of the chest, elbows down and out, the head bowed a little",
    )
)
register(
    Kind(
        name="phone_call",
        family="gestures",
        catalogue={"variants": ARMS_LR, "dur": (3.0, 6.0)},
        generate=phone_call,
        captions=(
            "{who} talks on the phone",
            "{who} holds a phone to the ear with {arm}",
            "{who} answers a phone call, {arm} at the ear",
            "{who} makes a phone call",
            "{who} raises {arm} to the ear and talks on a phone",
            "{who} stands and talks on a mobile phone",
        ),
        looks="one hand held at the ear, elbow down in front of the chest, the head tipped a little",
    )
)


# ----------------------------------------------------------------------------------------
# The head and the shoulders: looking around, shrugging (channels.py drives the neck's turn
# and the collars, which the rig's channels do not have)
# ----------------------------------------------------------------------------------------


def look_around(spec: Spec, tl: Timeline, t0: int, t1: int) -> None:
    """Standing, the head turns well to one side with the shoulders following a little, pauses
    to look, then to the other side, pauses, and back to the front; the eyes go up and down a bit."""
    n = t1 - t0
    r = tl.rng
    sg = 1.0 if r.random() < 0.5 else -1.0
    looks = [sg, -sg] + ([sg * 0.6] if r.random() < 0.4 else [])
    span = 0.9 / len(looks)
    times, vals = [0.0, 0.05], [0.0, 0.0]
    for k, side in enumerate(looks):
        a = 0.05 + k * span
        times += [a + 0.35 * span, a + 0.8 * span]
        vals += [side * r.uniform(0.8, 1.05), side * r.uniform(0.75, 1.0)]
    times += [0.97, 1.0]
    vals += [0.0, 0.0]
    turn = keyframes(n, times, vals)
    extra(tl).neck_yaw[t0:t1] += turn
    tl.ch.spine_twist[t0:t1] += r.uniform(0.45, 0.6) * turn  # the shoulders follow the head
    tl.ch.neck_pitch[t0:t1] += 0.12 * np.sin(np.linspace(0, r.uniform(2, 4) * np.pi, n)) * bump(n, 0.1)


def shrug(spec: Spec, tl: Timeline, t0: int, t1: int) -> None:
    """Both shoulders go up towards the ears, held a moment, and drop; the forearms come out a
    little with the palms up, the head tips: "I don't know". Once or twice."""
    n = t1 - t0
    r = tl.rng
    fps = tl.fps
    count = spec.count or 1
    per = 0.8 / count
    times, vals = [0.0, 0.1], [0.0, 0.0]
    for k in range(count):
        a = 0.1 + k * per
        up, hold = min(0.3 * per, 0.25 * fps / n), min(0.3 * per, r.uniform(0.25, 0.45) * fps / n)
        times += [a + up, a + up + hold, a + up + hold + min(0.3 * per, 0.3 * fps / n)]
        vals += [1.0, 1.0, 0.0]
    times.append(1.0)
    vals.append(0.0)
    lift = keyframes(n, times, vals)
    ex = extra(tl)
    k = r.uniform(0.4, 0.55)
    for s in SIDES:
        ex.collar_lift[s][t0:t1] += k * lift
    arms = bump(n, 0.12, 0.15, 0.05, 0.97)
    for s in SIDES:
        _arm(tl, s, t0, t1, flex=0.3 * arms, abduct=0.1 * arms + 0.1 * lift, elbow=1.25 * arms, twist=-0.4 * arms)
    tl.ch.neck_pitch[t0:t1] += 0.08 * lift
    tl.ch.spine_bend[t0:t1] -= 0.03 * lift
    tl.arm_swing[t0:t1] = 0.0


register(
    Kind(
        name="look_around",
        family="gestures",
        catalogue={"variants": [{}], "dur": (3.5, 6.5)},
        generate=look_around,
        captions=(
            "{who} looks around",
            "{who} stands and looks around with the head and upper body",
            "{who} looks to the left and to the right",
            "{who} turns the head to look around",
            "{who} looks around, turning to one side and then the other",
            "standing still, {who} looks around curiously",
        ),
        looks=(
            "standing, the head turns well to one side with the shoulders following, pauses, then "
            "to the other side, and back"
        ),
    )
)
register(
    Kind(
        name="shrug",
        family="gestures",
        catalogue={"variants": [{}], "dur": (2.0, 3.5), "count": (1, 2), "per_count": 1.2},
        generate=shrug,
        captions=(
            "{who} shrugs{cnt}",
            "{who} shrugs the shoulders{cnt}",
            "{who} raises the shoulders as if to say I don't know",
            "{who} shrugs with the palms up{cnt}",
            "{who} lifts both shoulders and lets them drop{cnt}",
        ),
        looks="both shoulders go up towards the ears and drop, once or twice, the forearms out with the palms up",
    )
)
