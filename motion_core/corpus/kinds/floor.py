"""Floor work: push-ups (prone plank), crawling on hands and knees, sit-ups (on the back).

They own their whole clip (posture "plank", "all_fours", "supine": they start and end in it) and are
built on the final channels (a Timeline finisher): the body's line, then the feet and knees
by the rig's leg IK, then the hands onto the floor by the arm IK. Hands, knees and toes that
bear weight stay where they were put.
"""

from __future__ import annotations

import numpy as np

from ..actions import Spec, Timeline, bump, pulses, smoothstep
from ..rig import (
    FOOT,
    FOOT_PITCH_FLAT,
    OFF,
    SHIN,
    SIDES,
    SIGN,
    THIGH,
    Channels,
    J,
    _mv,
    _pelvis_frame,
    ankle_height_flat,
    pose,
)
from .base import Kind, default_count, register
from .ik import body_axes, chest_frame, reach_world

UP = np.array([0.0, 1.0, 0.0])
TOE_Y = 0.02  # toe joint on the floor (rig.TOE_PLANT_Y)
WRIST_Y = 0.045  # wrist joint above the floor with the palm flat on it
KNEE_Y = 0.06  # knee joint above the floor when kneeling on it
HIP_MID = 0.5 * (OFF[J("left_hip")] + OFF[J("right_hip")])


def _mid(j: np.ndarray, a: str, b: str) -> np.ndarray:
    return 0.5 * (j[:, J(a)] + j[:, J(b)])


def _place_pelvis(ch: Channels, sl: slice, hip_mid: np.ndarray) -> None:
    """Put the pelvis where its hip midpoint lands on ``hip_mid`` (n, 3) (pitch, roll, heading set)."""
    Rp = _pelvis_frame(ch)[sl]
    pel = hip_mid - _mv(Rp, HIP_MID)
    ch.root_xz[sl] = pel[:, [0, 2]]
    ch.pelvis_y[sl] = pel[:, 1]


def _trunk_pitch_for(
    ch: Channels, sl: slice, hip_mid_fn, pivot: np.ndarray, shoulder_y: np.ndarray, pitch0: np.ndarray
) -> None:
    """Set pelvis_pitch over ``sl`` so that the shoulders sit at height shoulder_y (n,), with
    the hips placed by hip_mid_fn(pitch) -> (n, 3) and the body turning about ``pivot`` (n, 3)
    (the toes for a plank, the hips on all fours); Newton steps on the shoulder height."""
    pitch = pitch0.copy()
    for _ in range(6):
        ch.pelvis_pitch[sl] = pitch
        _place_pelvis(ch, sl, hip_mid_fn(pitch))
        sh = _mid(pose(ch)[sl], "left_shoulder", "right_shoulder")
        d = sh - pivot
        horiz = np.linalg.norm(d[:, [0, 2]], axis=-1)
        # more pitch lowers the shoulders by about their horizontal distance from the pivot per radian
        pitch = pitch + np.clip((sh[:, 1] - shoulder_y) / horiz.clip(0.2), -0.3, 0.3)


# ----------------------------------------------------------------------------------------
# Push-ups
# ----------------------------------------------------------------------------------------


def push_up(spec: Spec, tl: Timeline, t0: int, t1: int) -> None:
    n = t1 - t0
    r = tl.rng
    count = default_count(spec, tl, n, 1.4, 1, 5)
    down = pulses(n, count, r.uniform(0.1, 0.16), r.uniform(0.1, 0.16))
    top_h = r.uniform(0.47, 0.52)  # shoulder height, arms almost straight
    bot_h = r.uniform(0.17, 0.23)  # chest near the floor
    hand_w = r.uniform(0.2, 0.27)
    feet_w = r.uniform(0.05, 0.11)
    leg = 0.993 * (THIGH[0] + SHIN[0])  # legs straight, knees just off locked
    tl.arm_swing[t0:t1] = 0.0
    sl = slice(t0, t1)

    def finish(ch: Channels) -> None:
        ch.neck_pitch[sl] = ch.neck_pitch[sl] - 0.15  # looking at the floor a little ahead
        fwd, left = body_axes(ch)
        f = fwd[sl]
        toe0 = np.array([ch.root_xz[t0, 0], TOE_Y, ch.root_xz[t0, 1]]) - 0.85 * fwd[t0]
        shoulder_y = top_h + (bot_h - top_h) * down

        def feet_for(pitch: np.ndarray):
            alpha = np.pi / 2 - pitch  # the body line's rise from the floor
            p = 1.35 - alpha  # toes tucked, the foot about square to the shin
            toe_dir = np.cos(p)[:, None] * f - np.sin(p)[:, None] * UP
            ankle_mid = toe0[None] - FOOT[0] * toe_dir
            line = np.cos(alpha)[:, None] * f + np.sin(alpha)[:, None] * UP
            return ankle_mid, p, ankle_mid + leg * line

        _trunk_pitch_for(ch, sl, lambda pitch: feet_for(pitch)[2], toe0[None], shoulder_y, np.full(n, 1.3))
        ankle_mid, p, _ = feet_for(ch.pelvis_pitch[sl])
        for s in SIDES:
            ft = ch.feet[s]
            ft.ankle[sl] = ankle_mid + SIGN[s] * feet_w * left[sl]
            ft.yaw[sl] = ch.heading[sl]
            ft.pitch[sl] = p
        j = pose(ch)
        # hands under the shoulders at the top of the push-up, fixed on the floor
        top = sl.start + int(np.argmin(down[: max(1, n // 8)]))
        sh_top = _mid(j, "left_shoulder", "right_shoulder")[top]
        for s in SIDES:
            w = sh_top + SIGN[s] * hand_w * left[top] + 0.02 * fwd[top]
            w = np.array([w[0], WRIST_Y, w[2]])
            pole = -0.7 * f + SIGN[s] * 0.6 * left[sl] + 0.2 * UP
            reach_world(ch, s, sl, np.repeat(w[None], n, 0), pole, None, j)

    tl.finishers.append(finish)


# ----------------------------------------------------------------------------------------
# Crawling on hands and knees
# ----------------------------------------------------------------------------------------


def _limb_track(n: int, neutral: np.ndarray, phase: float, period: int, duty: float, lift: float, active: np.ndarray):
    """A limb's contact point (n, 3) on the floor: planted, then an eased swing of (1 - duty)
    of a period that lands where the limb's neutral place will be at mid-stance. Steps start
    at ``phase`` of each period while ``active``; a step shorter than 2 cm is not taken."""
    out = np.zeros((n, 3))
    plant = neutral[0].copy()
    swing_n = max(3, round((1 - duty) * period))
    t = 0
    starts = {round((phase + k) * period) for k in range(-1, n // period + 2)}
    while t < n:
        if t in starts and active[t] and t + swing_n < n:
            land = t + swing_n
            target = neutral[min(n - 1, land + int(0.5 * duty * period))].copy()
            if np.linalg.norm(target[[0, 2]] - plant[[0, 2]]) > 0.02:
                u = (np.arange(1, swing_n + 1)) / swing_n
                s = smoothstep((u - 0.2) / 0.6)  # travel only once lifted clear of the floor
                seg = plant[None] + s[:, None] * (target - plant)[None]
                seg[:, 1] += lift * np.sin(np.pi * u) ** 0.6
                out[t + 1 : land + 1] = seg
                out[t] = plant
                plant = target
                t = land + 1
                continue
        out[t] = plant
        t += 1
    return out


def crawl(spec: Spec, tl: Timeline, t0: int, t1: int) -> None:
    n = t1 - t0
    r = tl.rng
    fps = tl.fps
    speed = r.uniform(0.18, 0.3)
    period = round(r.uniform(1.1, 1.4) * fps)  # one full cycle of the four limbs
    hand_w, knee_w = r.uniform(0.17, 0.22), r.uniform(0.09, 0.13)
    hip_h = KNEE_Y + float(np.sqrt(THIGH[0] ** 2 - 0.04**2)) - r.uniform(0.0, 0.02)
    sh_h = WRIST_Y + 0.95 * 0.52 - r.uniform(0.0, 0.03)
    lift = r.uniform(0.04, 0.06)
    move = bump(n, 0.15, 0.15, 0.1, 0.9)
    tl.vel[t0:t1, 1] += speed * move
    tl.arm_swing[t0:t1] = 0.0
    sl = slice(t0, t1)
    lag = r.uniform(0.0, 0.08)  # the knee follows its diagonal hand a little later
    sway = np.sin(2 * np.pi * (np.arange(n) / period)) * move

    def finish(ch: Channels) -> None:
        ch.neck_pitch[sl] = ch.neck_pitch[sl] - 0.45  # head up, looking ahead
        ch.pelvis_roll[sl] += 0.05 * sway
        ch.spine_side[sl] += 0.06 * sway
        fwd, left = body_axes(ch)
        path = np.stack([ch.root_xz[sl, 0], np.zeros(n), ch.root_xz[sl, 1]], -1)
        hip_mid = path + hip_h * UP
        _trunk_pitch_for(ch, sl, lambda pitch: hip_mid, hip_mid, np.full(n, sh_h), np.full(n, 1.35))
        j = pose(ch)
        active = move > 0.05
        phases = {("hand", "l"): 0.0, ("knee", "r"): lag, ("hand", "r"): 0.5, ("knee", "l"): 0.5 + lag}
        for s in SIDES:
            hip = j[sl, J(f"{'left' if s == 'l' else 'right'}_hip")]
            knee_neutral = hip + SIGN[s] * (knee_w - 0.06) * left[sl]
            knee_neutral[:, 1] = KNEE_Y
            knee = _limb_track(n, knee_neutral, phases[("knee", s)], period, 0.7, lift, active)
            # the shin runs back from the knee to the tucked toes on the floor
            dy = TOE_Y + FOOT[0] - KNEE_Y
            back = np.sqrt(SHIN[0] ** 2 - dy**2) * 0.995
            ft = ch.feet[s]
            ft.ankle[sl] = knee - back * fwd[sl] + dy * UP
            ft.yaw[sl] = ch.heading[sl]
            ft.pitch[sl] = np.pi / 2 - 0.05
        j = pose(ch)
        for s in SIDES:
            sh = j[sl, J(f"{'left' if s == 'l' else 'right'}_shoulder")]
            hand_neutral = sh + SIGN[s] * (hand_w - 0.2) * left[sl] + 0.02 * fwd[sl]
            hand_neutral[:, 1] = WRIST_Y
            hand = _limb_track(n, hand_neutral, phases[("hand", s)], period, 0.7, lift, active)
            pole = -1.0 * fwd[sl] + SIGN[s] * 0.3 * left[sl]
            reach_world(ch, s, sl, hand, pole, None, j)

    tl.finishers.append(finish)


# ----------------------------------------------------------------------------------------
# Sit-ups
# ----------------------------------------------------------------------------------------


def sit_up(spec: Spec, tl: Timeline, t0: int, t1: int) -> None:
    """On the back, knees bent and feet flat: the trunk curls up towards the knees and back down."""
    n = t1 - t0
    r = tl.rng
    count = default_count(spec, tl, n, 1.8, 1, 5)
    up = pulses(n, count, r.uniform(0.08, 0.14), r.uniform(0.08, 0.14))
    height = r.uniform(0.75, 0.95)  # how far up (1: trunk about 60 degrees off the floor)
    hands_behind_head = r.random() < 0.6
    feet_fwd = r.uniform(0.38, 0.46)
    tl.arm_swing[t0:t1] = 0.0
    sl = slice(t0, t1)

    def finish(ch: Channels) -> None:
        curl = height * up
        ch.pelvis_y[sl] = 0.115 + 0.01 * curl
        ch.pelvis_pitch[sl] = -1.48 + 0.4 * curl
        ch.spine_bend[sl] = ch.spine_bend[sl] + 0.75 * curl
        ch.neck_pitch[sl] = ch.neck_pitch[sl] + 0.25 + 0.2 * curl  # chin towards the chest
        fwd, left = body_axes(ch)
        pel = np.stack([ch.root_xz[sl, 0], ch.pelvis_y[sl], ch.root_xz[sl, 1]], -1)
        for s in SIDES:  # feet flat on the floor in front of the hips, knees up
            base = pel[0] + SIGN[s] * 0.11 * left[t0] + feet_fwd * fwd[t0]
            ft = ch.feet[s]
            ft.ankle[sl] = np.array([base[0], ankle_height_flat(s), base[2]])
            ft.yaw[sl] = ch.heading[sl]
            ft.pitch[sl] = FOOT_PITCH_FLAT
        j = pose(ch)
        R = chest_frame(ch)[sl]
        for s in SIDES:
            if hands_behind_head:  # fingers laced behind the head, elbows out
                target = j[sl, J("head")] + _mv(R, np.array([SIGN[s] * 0.07, 0.0, -0.09]))
                pole = _mv(R, np.array([SIGN[s] * 1.0, 0.4, 0.2]))
            else:  # arms crossed on the chest
                target = j[sl, J("spine3")] + _mv(R, np.array([-SIGN[s] * 0.1, -0.06, 0.13]))
                pole = _mv(R, np.array([SIGN[s] * 0.5, -1.0, 0.3]))
            reach_world(ch, s, sl, target, pole, None, j)

    tl.finishers.append(finish)


register(
    Kind(
        name="push_up",
        family="floor",
        catalogue={"variants": [{}], "dur": (2.5, 4.5), "count": (1, 5), "per_count": 1.4},
        generate=push_up,
        captions=(
            "{who} does push-ups{cnt}",
            "{who} does {num} push-ups",
            "{who} is doing push ups on the floor{cnt}",
            "{who} lowers the chest to the floor and pushes back up{cnt}",
            "{who} performs press-ups{cnt}",
            "in a plank, {who} bends the arms and pushes up{cnt}",
        ),
        posture=("plank", "plank"),
        looks="prone plank on the toes and hands, body straight; the arms bend and straighten",
    )
)
register(
    Kind(
        name="crawl",
        family="floor",
        catalogue={"variants": [{"direction": "forward"}], "dur": (4.0, 9.0)},
        generate=crawl,
        captions=(
            "{who} crawls forward on hands and knees",
            "{who} is crawling on all fours",
            "{who} crawls along the floor",
            "on hands and knees, {who} crawls ahead",
            "{who} gets on all fours and crawls forward",
        ),
        posture=("all_fours", "all_fours"),
        looks="on hands and knees, diagonal limbs step together, moving forward slowly",
    )
)
register(
    Kind(
        name="sit_up",
        family="floor",
        catalogue={"variants": [{}], "dur": (3.0, 5.0), "count": (1, 5), "per_count": 1.8},
        generate=sit_up,
        captions=(
            "{who} does sit-ups{cnt}",
            "{who} does {num} sit ups",
            "lying on the back, {who} curls up towards the knees and lies back down{cnt}",
            "{who} is doing crunches on the floor{cnt}",
            "{who} performs sit-ups with the knees bent{cnt}",
        ),
        posture=("supine", "supine"),
        looks="on the back, knees up, feet flat; the trunk curls up and lowers, hands behind the head or on the chest",
    )
)
