"""Sports moves, standing: a golf swing, a tennis forehand, a boxing combination, dribbling a
basketball, and swimming strokes in the air (the front crawl).

The golf swing's hands are solved together on the club's grip in the chest's frame, so the
trunk's turn carries them round; the forehand's racket hand follows keys in the body's frame
(back, through the ball in front, across to the other shoulder). Boxing and the crawl drive
the arm channels, as the built-in punch does.
"""

from __future__ import annotations

import numpy as np

from ..actions import Spec, Timeline, _arm, _sides, bump, foot_steps, keyframes
from ..rig import OFF, SIDES, SIGN, Channels, J, pose
from .base import Kind, body_point, default_count, register
from .channels import extra
from .gestures import UP, _gesture
from .ik import body_axes, reach_world, set_arm

NAME = {"l": "left", "r": "right"}
SH_CHEST = {s: OFF[J(f"{NAME[s]}_collar")] + OFF[J(f"{NAME[s]}_shoulder")] for s in SIDES}  # chest frame, from spine3


def _hold_feet(tl: Timeline, t0: int, t1: int, wide: float = 0.0) -> None:
    """Both feet stay planted through the window (the trunk and hips may turn over them);
    ``wide``: each foot first steps this far out, and back in at the end."""
    for k, s in enumerate(SIDES):  # one foot, then the other
        moves = [(0.02 + 0.06 * k, 0.07 + 0.06 * k, wide, 0.0), (0.88 + 0.06 * k, 0.93 + 0.06 * k, 0.0, 0.0)]
        foot_steps(tl, t0, t1, s, moves if wide else [], lift=0.05)


def golf_swing(spec: Spec, tl: Timeline, t0: int, t1: int) -> None:
    """Address the ball (hinged at the hips, knees soft, arms hanging, the head down), take the
    club back over the trail shoulder as the trunk turns, swing down fast through the ball and
    up to a high finish over the lead shoulder, hold it, and stand up. side: right = a
    right-handed golfer, whose backswing goes to the right."""
    n = t1 - t0
    r = tl.rng
    fps = tl.fps
    sg = 1.0 if (spec.side or "right") == "right" else -1.0
    sec = fps / n  # one second as a fraction of the window
    a = r.uniform(0.9, 1.3) * sec  # settled at the address
    top = a + r.uniform(0.85, 1.05) * sec  # the backswing
    down = top + 0.1 * sec  # a moment at the top
    fin = down + r.uniform(0.55, 0.65) * sec  # down through the ball and up to the finish
    hold = min(0.84, fin + r.uniform(0.5, 0.7) * sec)
    end = min(0.98, hold + r.uniform(0.7, 0.9) * sec)  # unwinds and lets the club down
    phi_top, phi_fin = r.uniform(2.1, 2.4), -r.uniform(2.3, 2.5)
    phi = keyframes(n, [0.0, a, top, down, fin, hold, end, 1.0], [0.0, 0.0, phi_top, phi_top, phi_fin, phi_fin, 0, 0])
    posture = keyframes(n, [0.0, 0.03, a - 0.2 * sec, hold, end, 1.0], [0, 0, 1, 1, 0, 0])
    ch = tl.ch
    ch.pelvis_pitch[t0:t1] += 0.3 * posture * (1 - 0.5 * (phi < 0) * np.clip(-phi / 2.4, 0, 1))
    ch.spine_bend[t0:t1] += 0.3 * posture * (1 - 0.6 * (phi < 0) * np.clip(-phi / 2.4, 0, 1))
    ch.pelvis_y[t0:t1] -= 0.05 * posture
    ch.neck_pitch[t0:t1] += 0.35 * posture * (1 - 0.8 * (phi < 0) * np.clip(-phi / 1.5, 0, 1))  # eyes on the ball
    ch.spine_twist[t0:t1] += -sg * 0.42 * phi
    _hold_feet(tl, t0, t1, wide=r.uniform(0.06, 0.1))
    tl.arm_swing[t0:t1] = 0.0
    w = np.clip(
        keyframes(n, [0.0, 0.03, a - 0.25 * sec, hold + 0.3 * (end - hold), end, 1.0], [0, 0, 1, 1, 0, 0]), 0, 1
    )
    L0 = r.uniform(0.43, 0.47)
    sl = slice(t0, t1)
    mid = 0.5 * (SH_CHEST["l"] + SH_CHEST["r"])
    d = np.stack([-sg * np.sin(phi), -np.cos(phi), np.full(n, 0.3)], -1)
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    # the grip no further from either shoulder than the arm reaches
    far = max(np.linalg.norm(SH_CHEST["l"] - mid), 0.2)
    L = np.minimum(L0, np.sqrt(0.5**2 - far**2 * (1 - (np.abs(d[:, 0])) ** 2)) - far * np.abs(d[:, 0]))
    grip = mid[None] + L[:, None] * d
    lead, trail = ("l", "r") if sg > 0 else ("r", "l")

    def finish(c: Channels) -> None:
        for s, k in ((lead, -0.04), (trail, 0.04)):  # the trail hand lower on the club
            tgt = grip + k * d - SH_CHEST[s][None]
            pole = np.broadcast_to(np.array([SIGN[s] * 0.5, -0.5, -1.0]), (n, 3))
            set_arm(c, s, sl, tgt, pole, w)

    tl.finishers.append(finish)


def tennis_forehand(spec: Spec, tl: Timeline, t0: int, t1: int) -> None:
    """Ready, knees bent; the racket hand goes back as the shoulders turn away, then swings fast
    forward through the ball beside and in front of the body and across to the other shoulder;
    the free hand points out in front, then folds in. Back to ready."""
    n = t1 - t0
    r = tl.rng
    fps = tl.fps
    s = _sides(spec.side or "right")[0]
    o = "r" if s == "l" else "l"
    sec = fps / n
    a = r.uniform(0.25, 0.3)
    back = a + r.uniform(0.5, 0.65) * sec
    hit = back + r.uniform(0.16, 0.2) * sec
    thru = hit + r.uniform(0.18, 0.24) * sec
    rest = min(0.8, thru + r.uniform(0.4, 0.6) * sec)
    ks = [0.0, a - 0.08, a, back, hit, thru, rest, min(0.97, rest + 0.12), 1.0]
    sgn = SIGN[s]
    #   (lateral to its own side, up from the pelvis, forward): ready, back, through the ball, across
    lat = keyframes(n, ks, [0.2, 0.2, 0.15, 0.5, 0.42, -0.22, -0.22, 0.2, 0.2])
    up = keyframes(n, ks, [0.05, 0.05, 0.1, 0.2, 0.12, 0.3, 0.3, 0.05, 0.05])  # a finish at the chest
    fwd = keyframes(n, ks, [0.3, 0.3, 0.3, -0.2, 0.42, 0.25, 0.25, 0.3, 0.3])
    turn = keyframes(n, ks, [0, 0, 0.1, 1.0, 0.1, -0.8, -0.8, 0, 0])
    free = keyframes(n, ks, [0, 0, 0.3, 1.0, 0.6, 0.0, 0.0, 0, 0])
    ch = tl.ch
    ready = keyframes(n, [0.0, 0.05, a, rest, min(0.99, rest + 0.15), 1.0], [0, 0, 1, 1, 0, 0])
    ch.pelvis_y[t0:t1] -= 0.06 * ready
    ch.spine_bend[t0:t1] += 0.12 * ready
    ch.spine_twist[t0:t1] += sgn * 0.55 * turn  # the shoulders turn away from the ball, then through
    _hold_feet(tl, t0, t1, wide=r.uniform(0.05, 0.09))
    sl = slice(t0, t1)

    def where(c, j, side, sl_):
        pel = j[sl_, 0]
        if side == s:
            return body_point(c, sl_, pel, sgn * lat, up, fwd)
        return body_point(c, sl_, pel, SIGN[o] * (0.15 - 0.06 * free), 0.22 + 0.06 * free, 0.3 + 0.08 * free)

    def pole(f, left, side):
        return SIGN[side] * 0.8 * left - 0.5 * UP - 0.3 * f

    w = np.clip(keyframes(n, [0.0, 0.02, a - 0.02, rest, min(0.98, rest + 0.15), 1.0], [0, 0, 1, 1, 0, 0]), 0, 1)

    def finish(c: Channels) -> None:
        j = pose(c)
        f, left = body_axes(c)
        for side in (s, o):
            reach_world(c, side, sl, where(c, j, side, sl), pole(f[sl], left[sl], side), w, j)

    tl.arm_swing[t0:t1] = 0.0
    tl.finishers.append(finish)


def boxing(spec: Spec, tl: Timeline, t0: int, t1: int) -> None:
    """In a guard, bouncing lightly, punches straight out with the lead hand, then the rear,
    alternating (a jab-cross combination), the trunk turning into each punch."""
    n = t1 - t0
    r = tl.rng
    fps = tl.fps
    count = default_count(spec, tl, n, 0.45, 3, 6)
    lead = "l" if r.random() < 0.75 else "r"  # orthodox stance: the left hand leads
    rear = "r" if lead == "l" else "l"
    guard = bump(n, 0.12, 0.12, 0.02, 0.98)
    for s in SIDES:
        _arm(tl, s, t0, t1, flex=0.55 * guard, abduct=-0.1 * guard, elbow=1.9 * guard)
    lo, hi = 0.2, 0.15
    u = (np.arange(n) + 0.5) / n
    x = np.clip((u - lo) / (1 - lo - hi), 0, 1) * count
    k = np.floor(np.minimum(x, count - 1e-9)).astype(int)
    hit = np.where((u > lo) & (u < 1 - hi), np.sin(np.pi * (x % 1.0)) ** 2, 0.0)
    for i, s in enumerate((lead, rear)):
        mine = hit * ((k % 2) == i)
        _arm(tl, s, t0, t1, flex=1.0 * mine, abduct=-0.05 * mine, elbow=-1.95 * mine)
        tl.ch.spine_twist[t0:t1] += -SIGN[s] * 0.2 * mine
    tl.ch.pelvis_y[t0:t1] -= 0.03 * guard + 0.015 * guard * np.sin(2 * np.pi * 2.2 * np.arange(n) / fps) ** 2
    tl.ch.spine_bend[t0:t1] += 0.1 * guard
    tl.ch.neck_pitch[t0:t1] += 0.1 * guard  # chin down
    tl.arm_swing[t0:t1] = 0.0


def dribble(spec: Spec, tl: Timeline, t0: int, t1: int) -> None:
    """Knees bent, leaning a little, one hand bounces a ball beside the hip: it pushes down,
    the ball comes back up into it; the other forearm is held out in front."""
    n = t1 - t0
    r = tl.rng
    fps = tl.fps
    s = _sides(spec.side or "right")[0]
    o = "r" if s == "l" else "l"
    hz = r.uniform(1.6, 2.3)
    amp = r.uniform(0.07, 0.09)
    bounce = amp * np.cos(2 * np.pi * hz * np.arange(n) / fps)  # the hand at the top when it meets the ball
    lat, fwd, low = r.uniform(0.08, 0.12), r.uniform(0.16, 0.2), r.uniform(0.34, 0.37)

    def where(ch, j, side, sl):
        if side == s:  # beside and in front of the hip, from the shoulder (within reach)
            return body_point(ch, sl, j[sl, J(f"{NAME[s]}_shoulder")], SIGN[s] * lat, -low + bounce, fwd)
        return body_point(ch, sl, j[sl, 0], SIGN[o] * 0.12, 0.3, 0.32)  # the forearm across in front

    def pole(f, left, side):
        return SIGN[side] * left - 0.3 * f - (0.4 if side == s else 1.2) * UP

    w = _gesture(tl, t0, t1, (s, o), where, pole, 0.15, 0.03, 0.97)
    ch = tl.ch
    ch.pelvis_y[t0:t1] -= r.uniform(0.08, 0.12) * w
    ch.pelvis_pitch[t0:t1] += 0.15 * w
    ch.spine_bend[t0:t1] += 0.15 * w
    ch.neck_pitch[t0:t1] -= 0.1 * w  # head up


def swim(spec: Spec, tl: Timeline, t0: int, t1: int) -> None:
    """Standing, leaning a little forward, the arms windmill in turn as in the front crawl: each
    reaches forward over the head, pulls down through the front to the hip and comes back up
    behind; the trunk rolls with the strokes and the head turns to the side to breathe."""
    n = t1 - t0
    r = tl.rng
    count = default_count(spec, tl, n, 1.3, 2, 5)  # strokes per arm
    e = bump(n, 0.15, 0.15, 0.02, 0.98)
    u = np.clip(((np.arange(n) + 0.5) / n - 0.1) / 0.8, 0, 1)
    ramp = np.sin(np.pi * np.clip(u / 0.12, 0, 1) / 2) * np.sin(np.pi * np.clip((1 - u) / 0.12, 0, 1) / 2)
    ph = 2 * np.pi * count * u
    tl.arm_swing[t0:t1] = 0.0
    for s, off in (("r", 0.0), ("l", np.pi)):
        # flex runs down from the hanging arm, through behind and overhead (-pi), to in front;
        # the left arm is half a turn ahead once both are going
        flex = -ph - off * ramp
        _arm(tl, s, t0, t1, flex=flex, abduct=0.15 * e, elbow=e * (0.25 + 0.2 * (0.5 + 0.5 * np.sin(ph + off))))
    roll = np.sin(ph) * ramp
    ch = tl.ch
    ch.spine_twist[t0:t1] += 0.15 * roll
    ch.spine_bend[t0:t1] += r.uniform(0.18, 0.3) * e
    ch.pelvis_pitch[t0:t1] += 0.1 * e
    breathe = (np.sin(ph / 2) > 0.7) * 1.0
    breathe = np.convolve(breathe, np.ones(5) / 5, mode="same")
    breath_side = 1.0 if r.random() < 0.5 else -1.0
    extra(tl).neck_yaw[t0:t1] += (
        breath_side * 0.7 * breathe * ramp
    )  # turning to one side to breathe every second stroke


register(
    Kind(
        name="golf_swing",
        family="sports",
        catalogue={"variants": [{"side": "right"}, {"side": "left"}], "dur": (4.0, 5.5)},
        generate=golf_swing,
        captions=(
            "{who} swings a golf club",
            "{who} plays golf, taking a full swing",
            "{who} performs a golf swing",
            "{who} hits a golf ball with a big swing",
            "{who} addresses the ball and swings like a golfer",
            "{who} takes a swing as if playing golf",
        ),
        looks=(
            "addresses the ball, swings back over the trail shoulder as the trunk turns, fast "
            "down through the ball to a high finish, unwinds"
        ),
    )
)
register(
    Kind(
        name="tennis_forehand",
        family="sports",
        catalogue={"variants": [{"side": "right"}, {"side": "left"}], "dur": (3.0, 4.5)},
        generate=tennis_forehand,
        captions=(
            "{who} hits a tennis forehand with {arm}",
            "{who} swings a tennis racket with {arm}",
            "{who} plays tennis, hitting the ball with {arm}",
            "{who} makes a forehand stroke with {arm}",
            "{who} swings {arm} like hitting a ball with a racket",
            "{who} does a tennis swing",
        ),
        looks=(
            "ready, knees bent; the racket hand goes back with the shoulders and swings fast through "
            "the ball beside the hip and across"
        ),
    )
)
register(
    Kind(
        name="boxing",
        family="sports",
        catalogue={"variants": [{"side": "both"}], "dur": (2.5, 4.5), "count": (3, 6), "per_count": 0.45},
        generate=boxing,
        captions=(
            "{who} boxes, punching with both hands in turn{cnt}",
            "{who} throws a combination of punches",
            "{who} boxes, alternating left and right punches",
            "{who} does a jab and a cross{cnt}",
            "{who} shadow boxes, throwing {num} punches",
            "in a boxing stance, {who} punches with the left and the right hand",
        ),
        looks=(
            "guard at the chin, straight punches at shoulder height with one hand and the other "
            "in turn, the trunk turning into each"
        ),
    )
)
register(
    Kind(
        name="dribble",
        family="sports",
        catalogue={"variants": [{"side": "right"}, {"side": "left"}], "dur": (3.0, 6.0)},
        generate=dribble,
        captions=(
            "{who} dribbles a basketball with {arm}",
            "{who} bounces a ball with {arm}",
            "{who} dribbles a ball on the spot",
            "{who} plays basketball, dribbling with {arm}",
            "{who} bends the knees and dribbles a ball with {arm}",
            "{who} is dribbling a basketball",
        ),
        looks="knees bent, one hand pumps up and down beside the hip bouncing a ball, the other forearm out in front",
    )
)
register(
    Kind(
        name="swim",
        family="sports",
        catalogue={"variants": [{"side": "both"}], "dur": (4.0, 7.0), "count": (2, 5), "per_count": 1.3},
        generate=swim,
        captions=(
            "{who} makes swimming movements with the arms",
            "{who} swims the crawl in the air",
            "{who} pretends to swim, stroking with both arms{cnt}",
            "{who} stands and does front crawl strokes",
            "{who} imitates swimming, the arms circling in turn",
            "{who} mimes swimming freestyle",
        ),
        looks=(
            "leaning forward a little, the arms windmill in turn as in the crawl, the trunk rolling, "
            "the head turning to breathe"
        ),
    )
)
