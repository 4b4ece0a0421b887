"""Handling objects: pick up from the floor, put down on the floor, carry in front."""

from __future__ import annotations

import numpy as np

from ..actions import Spec, Timeline, _sides, keyframes, locomote, smoothstep, speed_of
from ..rig import SIDES, SIGN, Channels, J, pose
from .base import Kind, body_point, ease, register
from .ik import body_axes, reach_world


def _bend_down(tl: Timeline, t0: int, t1: int, down: np.ndarray, depth: float, hinge: float) -> None:
    """Squat-and-hinge towards the floor: knees bend (pelvis drops ``depth``), the trunk leans."""
    ch = tl.ch
    ch.pelvis_y[t0:t1] -= depth * down
    tl.pelvis_offset[t0:t1, 1] -= 0.1 * down
    ch.pelvis_pitch[t0:t1] += hinge * down
    ch.spine_bend[t0:t1] += 0.7 * down
    ch.neck_pitch[t0:t1] += 0.35 * down
    tl.arm_swing[t0:t1] = 0.0


def _object_transfer(spec: Spec, tl: Timeline, t0: int, t1: int, pick: bool) -> None:
    """Pick up (pick=True) or put down: the hands go between an object on the floor in front
    and a holding place in front of the waist; put down is pick up's timeline backwards."""
    n = t1 - t0
    r = tl.rng
    sides = _sides(spec.side or "both")
    both = len(sides) == 2
    down = keyframes(n, [0.0, 0.08, 0.4, 0.52, 0.85, 1.0], [0, 0, 1, 1, 0, 0])
    if not pick:
        down = down[::-1]
    _bend_down(tl, t0, t1, down, depth=r.uniform(0.34, 0.44), hinge=r.uniform(0.8, 1.0))
    fwd_obj = r.uniform(0.26, 0.36)
    lat_obj = r.uniform(0.1, 0.16) if both else r.uniform(0.12, 0.2)
    obj_h = r.uniform(0.08, 0.16)  # wrist height at the grasp (the grip above the floor)
    hold_fwd, hold_up = r.uniform(0.28, 0.36), r.uniform(0.1, 0.2)
    # Holding is a posture: after a pick up (before a put down) the hands stay held to the
    # clip's end (from its start).
    a, b = (t0, tl.ch.T) if pick else (0, t1)
    sl = slice(a, b)
    u = (np.arange(a, b) - t0 + 0.5) / n
    tt = u if pick else 1.0 - u  # pick up's time
    reach_in = smoothstep((tt - 0.1) / 0.3)  # joint-space blend: hanging arm -> the grasp
    to_hold = smoothstep((tt - 0.52) / 0.33)  # world-space path: floor -> held at the waist
    grasp = t0 + int((0.46 if pick else 0.54) * n)
    free = [s for s in SIDES if s not in sides]  # a one-hand pick up leans the free hand on its knee

    def finish(ch: Channels) -> None:
        j = pose(ch)
        fwd, left = body_axes(ch)
        root = np.array([ch.root_xz[grasp, 0], 0.0, ch.root_xz[grasp, 1]])
        for s in sides:
            lat = SIGN[s] * lat_obj
            floor_pt = root + left[grasp] * lat + fwd[grasp] * fwd_obj + np.array([0.0, obj_h, 0.0])
            hold = body_point(ch, sl, j[sl, 0], lat, hold_up, hold_fwd)
            target = floor_pt[None] + to_hold[:, None] * (hold - floor_pt[None])
            pole = -0.5 * fwd[sl] + SIGN[s] * 0.8 * left[sl] + np.array([0.0, -0.3, 0.0])
            reach_world(ch, s, sl, target, pole, np.where(tt >= 0.4, 1.0, reach_in), j)
        for s in free:
            knee = j[t0:t1, J(f"{'left' if s == 'l' else 'right'}_knee")]
            on_knee = body_point(ch, slice(t0, t1), knee, -SIGN[s] * 0.02, 0.08, 0.02)
            pole = SIGN[s] * left[t0:t1] - 0.3 * fwd[t0:t1]
            reach_world(ch, s, slice(t0, t1), on_knee, pole, np.clip(down / 0.9, 0, 1), j)

    tl.finishers.append(finish)


def pick_up(spec: Spec, tl: Timeline, t0: int, t1: int) -> None:
    _object_transfer(spec, tl, t0, t1, pick=True)


def put_down(spec: Spec, tl: Timeline, t0: int, t1: int) -> None:
    _object_transfer(spec, tl, t0, t1, pick=False)


def carry(spec: Spec, tl: Timeline, t0: int, t1: int) -> None:
    """Walk forward holding something in front with both hands (a box at the waist)."""
    n = t1 - t0
    r = tl.rng
    # a load slows the walk; above about 1.2 m/s the gait's fast start can leave a foot behind
    locomote(tl, t0, t1, "walk", min(speed_of(tl, "walk", spec.speed) * 0.8, 1.2))
    tl.arm_swing[t0:t1] = 0.0
    tl.ch.pelvis_pitch[t0:t1] -= 0.06 * ease(n, 0.0, 0.15)  # leaning back a little under the load
    width = r.uniform(0.24, 0.34)
    hold_fwd, hold_up = r.uniform(0.3, 0.38), r.uniform(0.06, 0.16)
    sl = slice(0, tl.ch.T)  # holding is a posture: the hands are held through the whole clip
    w = None

    def finish(ch: Channels) -> None:
        j = pose(ch)
        fwd, left = body_axes(ch)
        for s in SIDES:
            hold = body_point(ch, sl, j[sl, 0], SIGN[s] * width / 2, hold_up, hold_fwd)
            pole = -0.4 * fwd[sl] + SIGN[s] * 0.5 * left[sl] + np.array([0.0, -1.0, 0.0])
            reach_world(ch, s, sl, hold, pole, w, j)

    tl.finishers.append(finish)


register(
    Kind(
        name="pick_up",
        family="objects",
        catalogue={"variants": [{"side": s} for s in ("both", "left", "right")], "dur": (3.0, 5.0)},
        generate=pick_up,
        captions=(
            "{who} picks something up off the ground with {arm}",
            "{who} bends down and grabs an object with {arm}",
            "{who} lifts a box from the floor with {arm}",
            "{who} crouches and picks up something from the floor with {arm}",
            "{who} reaches down to the ground and picks an object up with {arm}",
        ),
        posture=("standing", "holding"),
        looks="squats and leans, the hands go to a spot on the floor in front, then come up to the waist",
    )
)
register(
    Kind(
        name="put_down",
        family="objects",
        catalogue={"variants": [{"side": s} for s in ("both", "left", "right")], "dur": (3.0, 5.0)},
        generate=put_down,
        captions=(
            "{who} puts something down on the ground with {arm}",
            "{who} bends down and sets an object on the floor with {arm}",
            "{who} places a box on the floor with {arm}",
            "{who} crouches to put down what they are holding with {arm}",
            "{who} lowers an object to the ground with {arm} and stands up",
        ),
        posture=("holding", "standing"),
        looks="starts holding at the waist, squats, the hands set down on the floor in front, stands with empty hands",
    )
)
register(
    Kind(
        name="carry",
        family="objects",
        catalogue={"variants": [{"side": "both", "direction": "forward"}], "dur": (3.5, 8.0), "speed": True},
        generate=carry,
        captions=(
            "{who} carries a box forward with both hands{spd}",
            "{who} walks{spd} holding something in front with both hands",
            "{who} walks forward carrying an object{spd}",
            "{who} carries something heavy in both arms while walking{spd}",
            "{who} is walking with a box held in front{spd}",
        ),
        posture=("holding", "holding"),
        looks="walks forward, no arm swing, both hands held together in front of the waist",
    )
)
