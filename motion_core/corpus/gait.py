"""Foot placement from a pelvis path: planted stance feet and eased swings.

A foot stays exactly where it was planted (no skating by construction) until the pelvis
path has moved its ideal placement by more than ``STEP_NEED`` (or turned it by more than
``TURN_NEED``); steps start on the beats of a cadence clock, alternating feet, and land
where the pelvis will be at mid-stance. Walking in place, turning on the spot, walking,
jogging and running all come out of the same rule; a per-frame duty factor below 0.5 gives
running's flight phase.

Actions that move feet themselves (jumps, kicks, lunges...) register :class:`FootOverride`
windows: the gait hands the foot over at the window's start with its current plant and
takes back the override's final plant at its end.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from .rig import FOOT, FOOT_PITCH_FLAT, SIDES, SIGN, Channels, FootTrack, ankle_height_flat

STEP_NEED = 0.03  # m
TURN_NEED = np.radians(10.0)
URGENT = 0.3  # m: a planted foot this far from its ideal plant steps without waiting for a beat
MAX_STEP_WALK, MAX_STEP_RUN = 1.8, 2.6  # m travelled by one foot in one swing (a stride)
SWING_PEAK_WALK, SWING_PEAK_RUN = 8.5, 12.0  # m/s peak horizontal foot speed in a swing


@dataclass
class Plant:
    xz: np.ndarray  # (2,) ankle ground position
    yaw: float


@dataclass
class GaitParams:
    """Per-frame gait settings, each (T,)."""

    cadence: np.ndarray  # steps per second
    duty: np.ndarray  # stance fraction of a gait cycle
    lift: np.ndarray  # swing height of the ankle (m)
    width: np.ndarray  # lateral ankle offset from the path (m)

    @classmethod
    def idle(cls, T: int, width: float = 0.095) -> GaitParams:
        return cls(np.full(T, 1.9), np.full(T, 0.6), np.full(T, 0.07), np.full(T, width))


# An override gets (start frame, end frame, plants at start, channels) and returns, per side
# it controls, (ankle (n, 3), yaw (n,), pitch (n,)) for frames [start, end).
OverrideFn = Callable[[int, int, dict[str, Plant], Channels], dict[str, tuple[np.ndarray, np.ndarray, np.ndarray]]]


@dataclass
class FootOverride:
    start: int
    end: int
    sides: tuple[str, ...]
    fn: OverrideFn = field(repr=False)


def ideal_plant(ch: Channels, t: int, side: str, width: float) -> Plant:
    t = min(max(t, 0), ch.T - 1)
    h = ch.heading[t]
    lateral = np.array([np.cos(h), -np.sin(h)])  # body's +x (left) in world xz
    return Plant(ch.root_xz[t] + SIGN[side] * width * lateral, float(h))


def _wrap(a: float) -> float:
    return float((a + np.pi) % (2 * np.pi) - np.pi)


CLEARANCE = 0.045  # m the toe must be off the floor before the foot may travel horizontally
TOE_DOWN = 0.15  # extra toe-down pitch at mid-swing (rad)


def swing(
    a: Plant, b: Plant, n: int, lift: float, side: str, height: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """An eased step from plant a to plant b over n frames (the last frame lands on b).

    ``height`` (n,) overrides the default ankle lift profile ``lift * sin(pi u)^0.8``.
    Horizontal travel happens only while the toe is at least CLEARANCE off the floor, so a
    foot is never dragged along it: it lifts, travels, then sets down.
    """
    u = np.arange(1, n + 1) / n
    rise = lift * np.sin(np.pi * u) ** 0.8 if height is None else np.asarray(height, dtype=float)
    toe_drop = FOOT[SIDES.index(side)] * (
        np.sin(FOOT_PITCH_FLAT + TOE_DOWN * np.sin(np.pi * u)) - np.sin(FOOT_PITCH_FLAT)
    )
    gap = CLEARANCE + 0.01 - (rise - toe_drop).max()
    if gap > 0 and np.linalg.norm(b.xz - a.xz) > 0.005:
        # Too low to clear the floor (a short hop, a shuffle): lift the foot that must travel.
        rise = rise + gap * np.sin(np.pi * u) ** 0.6
    clear = np.nonzero(rise - toe_drop >= CLEARANCE)[0]
    if len(clear) >= 2:
        i0, i1 = clear[0], clear[-1]
    else:  # too low a step to clear the floor: travel over the middle third
        i0, i1 = n // 3, max(n // 3 + 1, 2 * n // 3)
    s = np.clip((np.arange(n) - i0 + 0.5) / max(i1 - i0, 1), 0.0, 1.0)
    s = s * s * (3 - 2 * s)
    s[-1] = 1.0
    xz = a.xz[None] + (b.xz - a.xz)[None] * s[:, None]
    y = ankle_height_flat(side) + rise
    yaw = a.yaw + _wrap(b.yaw - a.yaw) * s
    pitch = FOOT_PITCH_FLAT + TOE_DOWN * np.sin(np.pi * u)
    return np.stack([xz[:, 0], y, xz[:, 1]], -1), yaw, pitch


def plan_feet(
    ch: Channels, gp: GaitParams, fps: float, overrides: list[FootOverride] | None = None
) -> dict[str, FootTrack]:
    """Fill ch.feet from the pelvis path (ch.root_xz, ch.heading) and the overrides."""
    T = ch.T
    overrides = sorted(overrides or [], key=lambda o: o.start)
    ankle = {s: np.zeros((T, 3)) for s in SIDES}
    yaw = {s: np.zeros(T) for s in SIDES}
    pitch = {s: np.full(T, FOOT_PITCH_FLAT) for s in SIDES}
    plant = {s: ideal_plant(ch, 0, s, gp.width[0]) for s in SIDES}
    busy_until = {s: 0 for s in SIDES}  # frame until which the foot's track is already written
    phase = 0.0
    turn = 0  # 0: left's beat, 1: right's
    next_override = 0

    def write_plant(s: str, t0: int, t1: int) -> None:
        p = plant[s]
        ankle[s][t0:t1] = (p.xz[0], ankle_height_flat(s), p.xz[1])
        yaw[s][t0:t1] = p.yaw
        pitch[s][t0:t1] = FOOT_PITCH_FLAT

    t = 0
    while t < T:
        # Hand feet to an override that starts now.
        while next_override < len(overrides) and overrides[next_override].start <= t:
            ov = overrides[next_override]
            next_override += 1
            start, end = max(ov.start, t), min(ov.end, T)
            if end <= start:
                continue
            tracks = ov.fn(start, end, {s: plant[s] for s in SIDES}, ch)
            for s in ov.sides:
                a, yw, pt = tracks[s]
                # A swing still in flight when the override starts is cut where the override begins.
                ankle[s][start:end], yaw[s][start:end], pitch[s][start:end] = a, yw, pt
                plant[s] = Plant(a[-1, [0, 2]].copy(), float(yw[-1]))
                busy_until[s] = end
        for s in SIDES:
            if busy_until[s] <= t:
                write_plant(s, t, t + 1)
                busy_until[s] = t + 1
        beat_prev = int(np.floor(phase))
        phase += gp.cadence[t] / fps
        urgent = any(
            busy_until[s] <= t + 1 and np.linalg.norm(ideal_plant(ch, t, s, gp.width[t]).xz - plant[s].xz) > URGENT
            for s in SIDES
        )
        if urgent:
            phase = float(np.floor(phase)) + 1.0  # restart the clock on this step
        if int(np.floor(phase)) > beat_prev:
            cycle = 2.0 / gp.cadence[t]
            n_swing = max(3, round((1.0 - gp.duty[t]) * cycle * fps))
            stance = gp.duty[t] * cycle
            land = t + n_swing
            t_target = round(land + 0.5 * stance * fps)
            order = (SIDES[turn], SIDES[1 - turn])
            walking = gp.duty[t] >= 0.5
            for s in order:
                other = "r" if s == "l" else "l"
                if busy_until[s] > t + 1:
                    continue
                # Walking keeps one foot on the ground; running (duty < 0.5) may not.
                if walking and busy_until[other] > t + 1:
                    continue
                target = ideal_plant(ch, t_target, s, gp.width[t])
                delta = target.xz - plant[s].xz
                err = float(np.linalg.norm(delta))
                if err < STEP_NEED and abs(_wrap(target.yaw - plant[s].yaw)) < TURN_NEED:
                    continue
                # A single step covers at most a stride; a foot that lags further catches up in
                # several steps rather than teleporting.
                max_step = MAX_STEP_WALK if walking else MAX_STEP_RUN
                if err > max_step:
                    target = Plant(plant[s].xz + delta * (max_step / err), target.yaw)
                    err = max_step
                # The swing lasts long enough for its distance (bounded peak foot speed).
                v_peak = SWING_PEAK_WALK if walking else SWING_PEAK_RUN
                n = max(n_swing, int(np.ceil(fps * 1.5 * err / (0.65 * v_peak))))
                # A step must land before an override of this foot begins: shorten it to fit.
                nxt = [o.start for o in overrides[next_override:] if s in o.sides and o.end > t]
                if nxt:
                    n = min(n, nxt[0] - t - 2)
                if n < 3 or t + n > T:
                    continue
                land = t + n
                a, yw, pt = swing(plant[s], target, n, float(gp.lift[t]), s)
                ankle[s][t + 1 : land + 1], yaw[s][t + 1 : land + 1], pitch[s][t + 1 : land + 1] = (
                    a[: T - t - 1],
                    yw[: T - t - 1],
                    pt[: T - t - 1],
                )
                plant[s] = target
                busy_until[s] = land + 1
                turn = 1 - SIDES.index(s)
                break
        t += 1
    ch.feet = {s: FootTrack(ankle[s], yaw[s], pitch[s]) for s in SIDES}
    return ch.feet
