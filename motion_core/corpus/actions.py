"""The corpus's actions: how each one drives the rig's channels, and its labels.

An action instance is a :class:`Spec` (kind + side/direction/count/speed/amplitude/angle).
``apply(spec, ctx, t0, t1)`` writes the action into frames [t0, t1) of a timeline: pose
channels get smooth deltas that start and end at zero (ease in/out), locomotion writes
body-frame velocity and yaw rate (integrated later into the pelvis path), and actions that
move the feet themselves register foot overrides with the gait. Every action starts and
ends in its posture's rest state with zero velocity, which is what makes segment joins
continuous in position and velocity.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import asdict, dataclass, field

import numpy as np

from .gait import FootOverride, GaitParams, Plant, ideal_plant, swing
from .rig import FOOT, FOOT_PITCH_FLAT, SIDES, SIGN, Channels, ankle_height_flat

G = 9.81


@dataclass(frozen=True)
class Spec:
    kind: str
    side: str | None = None  # "left" | "right" | "both"
    direction: str | None = None  # forward, backward, left, right, forward-left, forward-right, cw, ccw
    count: int | None = None
    speed: str = "normal"  # slow | normal | fast
    amplitude: str = "normal"  # normal | high
    angle: int | None = None  # degrees, for turns

    def labels(self) -> dict:
        return {k: v for k, v in asdict(self).items() if v is not None}


@dataclass
class Timeline:
    """What actions write into: pose channels, locomotion drives and foot overrides."""

    ch: Channels
    fps: float
    rng: np.random.Generator
    vel: np.ndarray  # (T, 2) body-frame velocity (lateral +left, forward)
    yaw_rate: np.ndarray  # (T,) rad/s, + = turning left
    pelvis_offset: np.ndarray  # (T, 2) body-frame (lateral, forward) pelvis offset from the path
    gait: GaitParams
    arm_swing: np.ndarray  # (T,) gain of gait-coupled arm swing
    overrides: list[FootOverride] = field(default_factory=list)
    # Run by compose on the final channels (after the path, the feet and make_reachable,
    # just before forward kinematics): what must hit a place in the world, such as a hand
    # on the floor or on the head, is solved there. Only registered kinds use it.
    finishers: list[Callable[[Channels], None]] = field(default_factory=list)
    # Run by compose on the joints (T, 22, 3) after forward kinematics, in place: the joints
    # that the rig's channels cannot place (the head turned on the neck, the shoulders raised
    # by the collars; kinds/channels.py). Only registered kinds use it.
    posers: list[Callable[[Channels, np.ndarray], None]] = field(default_factory=list)

    @classmethod
    def empty(cls, T: int, fps: float, rng: np.random.Generator) -> Timeline:
        width = float(rng.uniform(0.085, 0.11))
        return cls(
            ch=Channels.neutral(T),
            fps=fps,
            rng=rng,
            vel=np.zeros((T, 2)),
            yaw_rate=np.zeros(T),
            pelvis_offset=np.zeros((T, 2)),
            gait=GaitParams.idle(T, width),
            arm_swing=np.full(T, 0.35),
        )


# ------------------------------------------------------------------------------------
# Envelopes
# ------------------------------------------------------------------------------------


def smoothstep(x: np.ndarray) -> np.ndarray:
    x = np.clip(x, 0.0, 1.0)
    return x * x * (3 - 2 * x)


def bump(n: int, rise: float, fall: float | None = None, start: float = 0.0, end: float = 1.0) -> np.ndarray:
    """(n,) envelope: 0 until ``start``, eases to 1 over ``rise``, holds, eases back to 0 over
    ``fall`` ending at ``end`` (all as fractions of the window)."""
    fall = rise if fall is None else fall
    u = (np.arange(n) + 0.5) / n
    return smoothstep((u - start) / rise) * smoothstep((end - u) / fall)


def keyframes(n: int, times: list[float], values: list[float]) -> np.ndarray:
    """(n,) curve through (time fraction, value) keys with eased segments (zero slope at keys)."""
    u = (np.arange(n) + 0.5) / n
    out = np.full(n, values[0], dtype=float)
    for (ta, va), (tb, vb) in zip(
        zip(times, values, strict=True), zip(times[1:], values[1:], strict=True), strict=False
    ):
        m = (u >= ta) & (u <= tb)
        out[m] = va + (vb - va) * smoothstep((u[m] - ta) / max(tb - ta, 1e-6))
    out[u > times[-1]] = values[-1]
    return out


def pulses(n: int, count: int, lead: float = 0.15, tail: float = 0.15) -> np.ndarray:
    """(n,) ``count`` smooth 0->1->0 pulses between fractions lead and 1-tail."""
    u = (np.arange(n) + 0.5) / n
    x = np.clip((u - lead) / (1 - lead - tail), 0, 1) * count
    return np.where((u > lead) & (u < 1 - tail), np.sin(np.pi * (x % 1.0)) ** 2, 0.0)


def _sides(side: str | None) -> tuple[str, ...]:
    return {"left": ("l",), "right": ("r",), "both": ("l", "r")}.get(side or "", ())


# ------------------------------------------------------------------------------------
# Locomotion
# ------------------------------------------------------------------------------------

GAITS = {
    # speed (m/s) per speed word, cadence (steps/s) at normal speed, duty, lift, lean, elbow
    "walk": ({"slow": (0.5, 0.75), "normal": (1.0, 1.3), "fast": (1.5, 1.8)}, 1.9, 0.62, 0.09, 0.05, 0.25),
    "jog": ({"slow": (1.7, 2.0), "normal": (2.0, 2.5), "fast": (2.5, 2.9)}, 2.6, 0.38, 0.16, 0.12, 1.3),
    "run": ({"slow": (2.8, 3.1), "normal": (3.1, 3.6), "fast": (3.6, 4.0)}, 2.9, 0.34, 0.2, 0.2, 1.5),
}
DIRECTION_DEG = {"forward": 0, "left": 90, "right": -90, "forward-left": 45, "forward-right": -45, "backward": 180}


def _ramp(n: int, fps: float, secs: float = 0.5) -> np.ndarray:
    r = min(0.45, secs * fps / n)
    return bump(n, r)


def locomote(
    tl: Timeline,
    t0: int,
    t1: int,
    gait: str,
    speed: float,
    lateral: float = 0.0,
    backward: bool = False,
    turn: float = 0.0,
    turn_at_start: bool = False,
    lift: float | None = None,
) -> None:
    """Drive the path over [t0, t1): body-frame speed with eased start and stop, and a total
    heading change ``turn`` (rad), either spread over the walk or done in its first second."""
    n = t1 - t0
    speeds, cad, duty, lift0, lean, elbow = GAITS[gait]
    env = _ramp(n, tl.fps, 0.5 + 0.2 * speed)  # faster gaits take longer to reach speed
    fwd = -speed if backward else speed
    if lateral:
        tl.vel[t0:t1, 0] += lateral * env
    else:
        tl.vel[t0:t1, 1] += fwd * env
    if turn:
        if turn_at_start:
            w = bump(n, 0.5, 0.5, 0.0, min(1.0, 1.4 * tl.fps / n))
        else:
            w = bump(n, 0.2)
        tl.yaw_rate[t0:t1] += turn * w / (w.sum() / tl.fps)
    mean_speed = abs(lateral) if lateral else speed
    tl.gait.cadence[t0:t1] = cad * (0.75 + 0.25 * mean_speed / np.mean(speeds["normal"])) if gait == "walk" else cad
    tl.gait.duty[t0:t1] = duty
    tl.gait.lift[t0:t1] = lift if lift is not None else lift0 * tl.rng.uniform(0.85, 1.15)
    if gait != "walk":
        tl.gait.width[t0:t1] *= 0.6
    tl.ch.pelvis_pitch[t0:t1] += lean * env
    tl.ch.spine_bend[t0:t1] += 0.5 * lean * env
    tl.arm_swing[t0:t1] = 0.35 + (0.9 if gait != "walk" else 0.45 * mean_speed) * env * (0.0 if lateral else 1.0)
    for s in SIDES:
        tl.ch.arms[s].elbow[t0:t1] += (elbow - 0.2) * env
    # Walking bobs the pelvis twice per cycle; running is lower on average.
    tl.ch.pelvis_y[t0:t1] -= (0.02 if gait == "walk" else 0.05) * env


def speed_of(tl: Timeline, gait: str, word: str) -> float:
    lo, hi = GAITS[gait][0][word]
    return float(tl.rng.uniform(lo, hi))


# ------------------------------------------------------------------------------------
# Foot-moving primitives
# ------------------------------------------------------------------------------------


def _body_xz(heading: float, lateral: float, forward: float) -> np.ndarray:
    return np.array(
        [lateral * np.cos(heading) + forward * np.sin(heading), -lateral * np.sin(heading) + forward * np.cos(heading)]
    )


def _hold(p: Plant, n: int, side: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    a = np.tile([p.xz[0], ankle_height_flat(side), p.xz[1]], (n, 1))
    return a, np.full(n, p.yaw), np.full(n, FOOT_PITCH_FLAT)


def _concat(*parts: tuple[np.ndarray, np.ndarray, np.ndarray]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    return tuple(np.concatenate([p[i] for p in parts]) for i in range(3))  # type: ignore[return-value]


def hop_sequence(
    tl: Timeline, t0: int, t1: int, hops: list[dict], sides: tuple[str, ...], tuck: float = 0.08, arm_lift: bool = True
) -> None:
    """Jumps/hops: crouch, ballistic flight, landing, for every hop in ``hops`` (each a dict of
    height h, forward/lateral displacement, per-side landing width, relative duration).
    The feet in ``sides`` take off and land together; the pelvis follows a ballistic arc."""
    n = t1 - t0
    fps = tl.fps
    weights = np.array([hp.get("dur", 1.0) for hp in hops])
    bounds = np.concatenate([[0], np.cumsum(weights) / weights.sum() * n]).round().astype(int)
    dy = np.zeros(n)
    lean = np.zeros(n)
    arms_up = np.zeros(n)
    fwd = np.zeros(n)
    flights: list[tuple[int, int]] = []
    for k, hp in enumerate(hops):
        a, b = bounds[k], bounds[k + 1]
        m = b - a
        t_flight = 2 * np.sqrt(2 * hp["h"] / G)
        nf = max(3, round(t_flight * fps))
        crouch = max(2, round((m - nf) * 0.5))
        f0, f1 = a + crouch, min(b - 2, a + crouch + nf)
        flights.append((f0, f1))
        depth = hp.get("crouch", 0.12)
        dy[a:f0] -= depth * np.sin(np.linspace(0, np.pi / 2, f0 - a)) ** 2
        # Push-off: rise back to standing height in the last quarter of the crouch.
        push = max(1, (f0 - a) // 3)
        dy[f0 - push : f0] = -depth * (1 - smoothstep(np.linspace(0, 1, push)))
        tt = (np.arange(f1 - f0) + 0.5) / fps
        vz = G * t_flight / 2
        dy[f0:f1] = vz * tt - 0.5 * G * tt**2
        land = b - f1
        dy[f1:b] -= depth * 0.8 * np.sin(np.linspace(0, np.pi, land))
        lean[a:b] = 0.35 * np.sin(np.linspace(0, np.pi, m)) * (1.0 if hp.get("fwd", 0.0) > 0.2 else 0.4)
        if arm_lift:
            arms_up[a:b] = keyframes(m, [0.0, 0.35, 0.55, 1.0], [0.0, -0.6, 1.0, 0.0])
        # Horizontal travel between crouch bottom and landing, eased.
        u = np.clip((np.arange(a, b) - (f0 - push)) / max(1, f1 + 2 - (f0 - push)), 0, 1)
        fwd[a:b] = smoothstep(u) * hp.get("fwd", 0.0)
    ch = tl.ch
    ch.pelvis_y[t0:t1] += dy
    ch.spine_bend[t0:t1] += lean
    ch.pelvis_pitch[t0:t1] += 0.3 * lean
    if arm_lift:
        for s in SIDES:
            ch.arms[s].flex[t0:t1] += arms_up
    # Path travel: differentiate the cumulative displacement into body-frame velocity.
    cum = np.zeros(n)
    for k in range(len(hops)):
        a, b = bounds[k], bounds[k + 1]
        cum[a:b] = fwd[a:b] + sum(h.get("fwd", 0.0) for h in hops[:k])
        cum[b:] = sum(h.get("fwd", 0.0) for h in hops[: k + 1])
    tl.vel[t0:t1, 1] += np.gradient(cum) * fps

    def fn(start: int, end: int, plants: dict[str, Plant], chn: Channels):
        out = {}
        for s in sides:
            cur = plants[s]
            parts = []
            for k, hp in enumerate(hops):
                a, b = bounds[k], bounds[k + 1]
                f0, f1 = flights[k]
                h_end = chn.heading[min(t0 + b - 1, chn.T - 1)]
                width = hp.get("width", {}).get(s)
                base = chn.root_xz[min(t0 + b - 1, chn.T - 1)]
                if width is not None:
                    target = Plant(base + _body_xz(h_end, SIGN[s] * width, 0.0), float(h_end))
                else:
                    rel = cur.xz - chn.root_xz[min(t0 + a, chn.T - 1)]
                    target = Plant(base + rel, cur.yaw + float(h_end - chn.heading[min(t0 + a, chn.T - 1)]))
                pre = _hold(cur, f0 - a, s)
                nfl = f1 - f0
                # In the air the ankle rises with the pelvis, plus a little knee tuck.
                rise = np.clip(dy[f0:f1], 0, None) + tuck * np.sin(np.linspace(0, np.pi, nfl))
                sw = swing(cur, target, nfl, 0.0, s, height=rise)
                post = _hold(target, b - f1, s)
                parts += [pre, sw, post]
                cur = target
            out[s] = _concat(*parts)
        return out

    tl.overrides.append(FootOverride(t0, t1, sides, fn))


def foot_steps(
    tl: Timeline,
    t0: int,
    t1: int,
    side: str,
    moves: list[tuple[float, float, float, float]],
    lift: float = 0.08,
    pitch_keys: list[tuple[float, float]] | None = None,
) -> None:
    """One foot steps to body-frame offsets relative to its start plant: moves are
    (start frac, end frac, lateral, forward); the foot holds between moves. Optional
    pitch keys (frac, extra pitch) raise the heel with the toe fixed."""
    n = t1 - t0

    def fn(start: int, end: int, plants: dict[str, Plant], chn: Channels):
        p0 = plants[side]
        h = p0.yaw
        cur = p0
        a, yw, pt = _hold(p0, n, side)
        for fa, fb, lat, fw in moves:
            ia, ib = round(fa * n), max(round(fa * n) + 2, round(fb * n))
            tgt = Plant(p0.xz + _body_xz(h, SIGN[side] * lat, fw), h)
            sa, sy, sp = swing(cur, tgt, ib - ia, lift, side)
            a[ia:ib], yw[ia:ib], pt[ia:ib] = sa, sy, sp
            a[ib:], yw[ib:] = (tgt.xz[0], ankle_height_flat(side), tgt.xz[1]), tgt.yaw
            cur = tgt
        if pitch_keys:
            extra = keyframes(n, [k[0] for k in pitch_keys], [k[1] for k in pitch_keys])
            toe = a + _toe_vec(yw, pt, side)
            pt = pt + extra
            a = toe - _toe_vec(yw, pt, side)
        return {side: (a[: end - start], yw[: end - start], pt[: end - start])}

    tl.overrides.append(FootOverride(t0, t1, (side,), fn))


def _toe_vec(yaw: np.ndarray, pitch: np.ndarray, side: str) -> np.ndarray:
    L = FOOT[SIDES.index(side)]
    return L * np.stack([np.cos(pitch) * np.sin(yaw), -np.sin(pitch), np.cos(pitch) * np.cos(yaw)], -1)


def leg_lift(
    tl: Timeline, t0: int, t1: int, side: str, keys: list[tuple[float, float, float, float]], toe_pitch: float = 0.3
) -> None:
    """The foot leaves its plant, follows hip-relative body-frame ankle keys
    (frac, lateral, height above floor, forward of the plant), and comes back."""
    n = t1 - t0

    def fn(start: int, end: int, plants: dict[str, Plant], chn: Channels):
        p0 = plants[side]
        fr = [k[0] for k in keys]
        lat = keyframes(n, fr, [k[1] for k in keys])
        hy = keyframes(n, fr, [k[2] for k in keys])
        fw = keyframes(n, fr, [k[3] for k in keys])
        hd = chn.heading[start:end]
        pitch = FOOT_PITCH_FLAT + toe_pitch * keyframes(n, fr, [1.0 if k[2] > 0.06 else 0.0 for k in keys])
        # The foot travels only while its toe is off the floor (toe-down pitch lowers the toe).
        toe_rise = hy - FOOT[SIDES.index(side)] * (np.sin(pitch) - np.sin(FOOT_PITCH_FLAT))
        gate = smoothstep((toe_rise - 0.025) / 0.04)
        g = 0.5 * (gate[1:] + gate[:-1])  # gate the increments: no travel on the floor, none lost in the air
        lat = lat[0] + np.concatenate([[0.0], np.cumsum(np.diff(lat) * g)])
        fw = fw[0] + np.concatenate([[0.0], np.cumsum(np.diff(fw) * g)])
        xz = p0.xz[None] + np.stack([lat * np.cos(hd) + fw * np.sin(hd), -lat * np.sin(hd) + fw * np.cos(hd)], -1)
        a = np.stack([xz[:, 0], ankle_height_flat(side) + hy, xz[:, 1]], -1)
        return {side: (a, np.full(n, p0.yaw), pitch)}

    tl.overrides.append(FootOverride(t0, t1, (side,), fn))


# ------------------------------------------------------------------------------------
# The actions
# ------------------------------------------------------------------------------------


def _arm(tl: Timeline, s: str, t0: int, t1: int, flex=None, abduct=None, elbow=None, twist=None) -> None:
    a = tl.ch.arms[s]
    for name, val in (("flex", flex), ("abduct", abduct), ("elbow", elbow), ("twist", twist)):
        if val is not None:
            getattr(a, name)[t0:t1] += val


def apply(spec: Spec, tl: Timeline, t0: int, t1: int) -> None:
    """Write one action into frames [t0, t1) of the timeline."""
    if spec.kind in REGISTERED:  # a kind registered in motion_core.corpus.kinds
        REGISTERED[spec.kind].generate(spec, tl, t0, t1)
        return
    n = t1 - t0
    r = tl.rng
    k = spec.kind
    ch = tl.ch
    if k in ("walk", "jog", "run"):
        turn = np.radians(DIRECTION_DEG[spec.direction or "forward"])
        locomote(tl, t0, t1, k, speed_of(tl, k, spec.speed), turn=turn, turn_at_start=True)
    elif k == "walk_backward":
        locomote(tl, t0, t1, "walk", speed_of(tl, "walk", spec.speed) * 0.65, backward=True)
        ch.pelvis_pitch[t0:t1] -= 0.08 * _ramp(n, tl.fps)
    elif k == "sidestep":
        v = speed_of(tl, "walk", spec.speed) * 0.45 * (1 if spec.direction == "left" else -1)
        locomote(tl, t0, t1, "walk", abs(v), lateral=v)
    elif k == "turn":
        ang = np.radians(spec.angle or 90) * (1 if spec.direction == "left" else -1)
        locomote(tl, t0, t1, "walk", speed_of(tl, "walk", spec.speed) * 0.85, turn=ang)
    elif k == "circle":
        ang = 2 * np.pi * (1 if spec.direction == "ccw" else -1)  # counter-clockwise from above = turning left
        locomote(tl, t0, t1, "walk", speed_of(tl, "walk", spec.speed) * 0.8, turn=ang)
    elif k == "turn_around":
        ang = np.pi * (1 if spec.direction == "left" else -1)
        w = bump(n, 0.3, 0.3, 0.1, 0.9)
        tl.yaw_rate[t0:t1] += ang * w / (w.sum() / tl.fps)
        ch.spine_twist[t0:t1] += 0.15 * np.sign(ang) * bump(n, 0.25, 0.25, 0.05, 0.8)
    elif k == "step_over":
        locomote(tl, t0, t1, "walk", r.uniform(0.55, 0.75), lift=r.uniform(0.3, 0.4))
        for s in SIDES:
            _arm(tl, s, t0, t1, abduct=0.35 * bump(n, 0.2))
    elif k == "raise_arm":
        e = bump(n, 0.3, 0.3, 0.05, 0.95)
        # Up through the front or through the side (one plane: mixing both stops short of overhead).
        through_front = r.random() < 0.5
        lift = r.uniform(2.7, 2.95)
        for s in _sides(spec.side):
            if through_front:
                _arm(tl, s, t0, t1, flex=lift * e, elbow=-0.15 * e)
            else:
                _arm(tl, s, t0, t1, abduct=lift * e, elbow=-0.15 * e)
    elif k == "wave":
        count = spec.count or int(r.integers(2, 5))
        e = bump(n, 0.2, 0.2, 0.03, 0.97)
        osc = np.sin(2 * np.pi * count * np.clip(((np.arange(n) + 0.5) / n - 0.2) / 0.6, 0, 1))
        for s in _sides(spec.side):
            _arm(tl, s, t0, t1, flex=0.35 * e, abduct=1.9 * e, elbow=1.2 * e, twist=(-1.2 + 0.55 * osc) * e)
    elif k == "punch":
        count = spec.count or 1
        guard = bump(n, 0.15, 0.15, 0.02, 0.98)
        hits = pulses(n, count, 0.2, 0.12)
        for s in SIDES:  # boxing guard: fists up in front of the chin
            _arm(tl, s, t0, t1, flex=0.55 * guard, abduct=-0.1 * guard, elbow=1.9 * guard)
        for s in _sides(spec.side):
            _arm(tl, s, t0, t1, flex=1.0 * hits, abduct=-0.15 * hits, elbow=-2.0 * hits)
            ch.spine_twist[t0:t1] += -SIGN[s] * 0.3 * hits
    elif k == "reach":
        e = bump(n, 0.35, 0.3, 0.05, 0.95)
        for s in _sides(spec.side):
            _arm(tl, s, t0, t1, flex=r.uniform(1.4, 1.8) * e, abduct=r.uniform(-0.1, 0.4) * e, elbow=-0.18 * e)
            ch.spine_twist[t0:t1] += -SIGN[s] * 0.15 * e
        ch.spine_bend[t0:t1] += 0.25 * e
    elif k == "clap":
        count = spec.count or int(r.integers(2, 6))
        e = bump(n, 0.15, 0.15, 0.02, 0.98)
        together = pulses(n, count, 0.15, 0.12)
        for s in SIDES:
            _arm(tl, s, t0, t1, flex=1.15 * e, abduct=(0.35 * e - 1.05 * together), elbow=0.75 * e)
    elif k == "throw":
        s = _sides(spec.side)[0]
        wind = keyframes(n, [0.0, 0.15, 0.5, 0.62, 0.8, 1.0], [0, 1, 1, -0.4, 0, 0])
        _arm(
            tl,
            s,
            t0,
            t1,
            flex=keyframes(n, [0, 0.15, 0.5, 0.62, 0.8, 1], [0, 0.3, 0.5, 1.6, 0.4, 0]),
            abduct=1.6 * np.clip(wind, 0, None),
            elbow=keyframes(n, [0, 0.15, 0.5, 0.62, 0.8, 1], [0, 1.2, 1.6, 0.1, 0.3, 0]),
        )
        ch.spine_twist[t0:t1] += SIGN[s] * 0.45 * wind
        o = "r" if s == "l" else "l"
        _arm(tl, o, t0, t1, flex=0.8 * bump(n, 0.2, 0.3, 0.1, 0.85))
    elif k == "kick":
        s = _sides(spec.side)[0]
        count = spec.count or 1
        apex = r.uniform(0.8, 0.95) if spec.amplitude == "high" else r.uniform(0.35, 0.5)
        keys = [(0.0, 0.0, 0.0, 0.0)]
        per = 0.9 / count
        for c in range(count):
            base = 0.05 + c * per
            keys += [
                (base + 0.12 * per, 0.0, 0.12, -0.25),
                (base + 0.45 * per, 0.0, apex, 0.55 + 0.2 * apex),
                (base + 0.85 * per, 0.0, 0.05, 0.0),
            ]
        keys.append((1.0, 0.0, 0.0, 0.0))
        leg_lift(tl, t0, t1, s, keys)
        ch.pelvis_pitch[t0:t1] -= 0.12 * (apex / 0.5) * pulses(n, count, 0.05, 0.05)
        for a in SIDES:
            _arm(tl, a, t0, t1, abduct=0.5 * bump(n, 0.15))
    elif k == "lunge":
        s = _sides(spec.side)[0]
        o = "r" if s == "l" else "l"
        depth = r.uniform(0.25, 0.33)
        foot_steps(tl, t0, t1, s, [(0.05, 0.3, 0.0, 0.7), (0.7, 0.95, 0.0, 0.0)], lift=0.1)
        foot_steps(
            tl, t0, t1, o, [], pitch_keys=[(0.0, 0.0), (0.3, 0.0), (0.5, 0.9), (0.65, 0.9), (0.85, 0.0), (1.0, 0.0)]
        )
        down = keyframes(n, [0.0, 0.3, 0.5, 0.65, 0.85, 1.0], [0, 0.35, 1, 1, 0.0, 0])
        tl.pelvis_offset[t0:t1, 1] += 0.35 * keyframes(n, [0, 0.1, 0.3, 0.7, 0.95, 1], [0, 0, 1, 1, 0, 0])
        ch.pelvis_y[t0:t1] -= depth * down
    elif k == "squat":
        count = spec.count or 1
        d = pulses(n, count, 0.08, 0.08)
        depth = r.uniform(0.33, 0.42)
        ch.pelvis_y[t0:t1] -= depth * d
        tl.pelvis_offset[t0:t1, 1] -= 0.12 * d
        ch.pelvis_pitch[t0:t1] += 0.35 * d
        ch.spine_bend[t0:t1] += 0.2 * d
        for s in SIDES:
            _arm(tl, s, t0, t1, flex=1.4 * d)
    elif k == "hop":
        s = _sides(spec.side)[0]  # the supporting leg
        o = "r" if s == "l" else "l"
        count = spec.count or int(r.integers(2, 5))
        hops = [{"h": r.uniform(0.09, 0.13), "fwd": r.uniform(0.0, 0.2), "crouch": 0.07} for _ in range(count)]
        lead = round(0.2 * n)
        hop_sequence(tl, t0 + lead, t1 - lead, hops, (s,), tuck=0.03, arm_lift=False)
        leg_lift(
            tl,
            t0,
            t1,
            o,
            [
                (0.0, 0, 0, 0),
                (0.12, 0.0, 0.22, -0.2),
                (0.88, 0.0, 0.22, -0.2 + sum(h["fwd"] for h in hops)),
                (1.0, 0, 0, sum(h["fwd"] for h in hops)),
            ],
            toe_pitch=0.6,
        )
        ch.pelvis_roll[t0:t1] += SIGN[s] * 0.06 * bump(n, 0.15)
        for a in SIDES:
            _arm(tl, a, t0, t1, abduct=0.45 * bump(n, 0.15))
    elif k == "kneel":
        s = _sides(spec.side)[0]  # the knee that goes down
        down = keyframes(n, [0, 0.25, 0.45, 0.7, 0.9, 1], [0, 0, 1, 1, 0, 0])
        foot_steps(
            tl,
            t0,
            t1,
            s,
            [(0.03, 0.25, 0.0, -0.42), (0.9, 1.0, 0.0, 0.0)],
            lift=0.06,
            pitch_keys=[(0, 0), (0.25, 0), (0.45, 1.0), (0.7, 1.0), (0.9, 0), (1, 0)],
        )
        ch.pelvis_y[t0:t1] -= 0.44 * down
        tl.pelvis_offset[t0:t1, 1] -= 0.12 * down
        ch.spine_bend[t0:t1] += 0.1 * down
        for a in SIDES:
            _arm(tl, a, t0, t1, flex=0.3 * down)
    elif k in ("jump_up", "jump_forward"):
        count = spec.count or 1
        h = r.uniform(0.32, 0.42) if spec.amplitude == "high" else r.uniform(0.15, 0.24)
        fwd = r.uniform(0.5, 0.9) if k == "jump_forward" else 0.0
        lead = round(0.08 * n)
        hop_sequence(tl, t0 + lead, t1 - lead, [{"h": h, "fwd": fwd, "crouch": 0.17} for _ in range(count)], ("l", "r"))
    elif k == "jumping_jacks":
        count = spec.count or int(r.integers(2, 5))
        wide, narrow = r.uniform(0.25, 0.32), 0.1
        hops = []
        for _ in range(count):
            hops += [
                {"h": 0.1, "crouch": 0.06, "width": {"l": wide, "r": wide}},
                {"h": 0.1, "crouch": 0.06, "width": {"l": narrow, "r": narrow}},
            ]
        lead = round(0.08 * n)
        hop_sequence(tl, t0 + lead, t1 - lead, hops, ("l", "r"), tuck=0.02, arm_lift=False)
        nn = t1 - t0 - 2 * lead
        arms = np.zeros(n)
        arms[lead : lead + nn] = pulses(nn, count, 0.0, 0.0)
        for a in SIDES:
            _arm(tl, a, t0, t1, abduct=2.6 * arms, elbow=-0.1 * arms)
    elif k in ("sit_down", "stand_up"):
        fwd = k == "sit_down"
        e = keyframes(n, [0, 0.1, 0.8, 1], [0, 0, 1, 1])
        lean = np.sin(np.pi * np.clip(((np.arange(n) + 0.5) / n - 0.1) / 0.7, 0, 1))
        if not fwd:
            e, lean = e[::-1], lean[::-1]
        _posture_sit(tl, t0, t1, e, lean)
    elif k in ("lie_down", "get_up"):
        _lie(tl, t0, t1, reverse=(k == "get_up"))
    elif k == "bow":
        e = bump(n, 0.3, 0.3, 0.05, 0.95)
        depth = r.uniform(0.8, 1.1)
        ch.spine_bend[t0:t1] += depth * e
        ch.pelvis_pitch[t0:t1] += 0.3 * depth * e
        ch.neck_pitch[t0:t1] += 0.3 * e
        tl.pelvis_offset[t0:t1, 1] -= 0.06 * e
    elif k == "stretch":
        up = bump(n, 0.2, 0.2, 0.03, 0.97)
        side = np.sin(2 * np.pi * np.clip(((np.arange(n) + 0.5) / n - 0.25) / 0.5, 0, 1))
        for a in SIDES:
            _arm(tl, a, t0, t1, flex=2.2 * up, abduct=0.55 * up, elbow=-0.1 * up)
        ch.spine_side[t0:t1] += 0.45 * side * up
        ch.spine_bend[t0:t1] -= 0.1 * up
    else:
        raise ValueError(f"unknown action kind {k!r}")


def _posture_sit(tl: Timeline, t0: int, t1: int, e: np.ndarray, lean: np.ndarray) -> None:
    ch = tl.ch
    ch.pelvis_y[t0:t1] -= 0.44 * e
    tl.pelvis_offset[t0:t1, 1] -= 0.3 * e
    ch.pelvis_pitch[t0:t1] += 0.45 * lean
    ch.spine_bend[t0:t1] += 0.35 * lean - 0.05 * e
    for a in SIDES:
        _arm(tl, a, t0, t1, flex=0.5 * lean + 0.35 * e, elbow=0.9 * e)


def _lie(tl: Timeline, t0: int, t1: int, reverse: bool) -> None:
    """Standing -> squat -> sit on the floor (legs forward) -> lie on the back; reversed for get_up."""
    n = t1 - t0
    ch = tl.ch
    times = [0, 0.1, 0.35, 0.6, 0.9, 1]
    y = keyframes(n, times, [0, 0, 0.5, 0.81, 0.8, 0.8])
    back = keyframes(n, times, [0, 0, 0.25, 0.45, 0.45, 0.45])
    pitch = keyframes(n, times, [0, 0, 0.5, -0.25, -1.45, -1.45])
    bend = keyframes(n, times, [0, 0, 0.45, 0.35, 0.0, 0.0])
    flex = keyframes(n, times, [0, 0, 0.9, 0.3, 0.05, 0.05])
    neck = keyframes(n, times, [0, 0, 0.2, 0.1, 0.35, 0.35])
    if reverse:
        y, back, pitch, bend, flex, neck = (a[::-1] for a in (y, back, pitch, bend, flex, neck))
    ch.pelvis_y[t0:t1] -= y
    tl.pelvis_offset[t0:t1, 1] -= back
    ch.pelvis_pitch[t0:t1] += pitch
    ch.spine_bend[t0:t1] += bend
    ch.neck_pitch[t0:t1] -= neck
    for a in SIDES:
        _arm(tl, a, t0, t1, flex=flex)
    for i, s in enumerate(SIDES):
        a0, a1 = (0.36 + 0.1 * i, 0.5 + 0.1 * i) if not reverse else (0.4 - 0.1 * i, 0.54 - 0.1 * i)
        tl.overrides.append(FootOverride(t0, t1, (s,), _lie_feet(s, a0, a1, reverse)))


def _lie_feet(side: str, fa: float, fb: float, reverse: bool):
    def fn(start: int, end: int, plants: dict[str, Plant], chn: Channels):
        n = end - start
        h = chn.heading[end - 1]
        stand = plants[side]
        if reverse:  # the plant at the start is the lying one; standing is where the path ends
            lying = stand
            stand = ideal_plant(chn, end - 1, side, 0.1)
        else:
            lying = Plant(stand.xz + _body_xz(h, 0.0, 0.32), stand.yaw)
        a0, b0 = (stand, lying) if not reverse else (lying, stand)
        ia, ib = round(fa * n), round(fb * n)
        a, yw, pt = _hold(a0, n, side)
        sw = swing(a0, b0, ib - ia, 0.06, side)
        a[ia:ib], yw[ia:ib], pt[ia:ib] = sw
        a[ib:] = (b0.xz[0], ankle_height_flat(side), b0.xz[1])
        # Legs stretched out on the floor rest on the heels with the toes up.
        toes_up = (
            keyframes(n, [0, 0.55, 0.75, 1], [0, 0, 1, 1])
            if not reverse
            else keyframes(n, [0, 0.25, 0.45, 1], [1, 1, 0, 0])
        )
        pt = pt - 1.2 * toes_up
        a[:, 1] -= 0.02 * toes_up
        return {side: (a, yw, pt)}

    return fn


def hold_posture(tl: Timeline, t: int, until: int) -> None:
    """Keep the pose of frame t over frames (t, until): a seated or lying action's end state,
    held until the next action (which starts from that posture) takes over."""
    ch = tl.ch
    for arr in (ch.pelvis_y, ch.pelvis_pitch, ch.spine_bend, ch.neck_pitch):
        arr[t + 1 : until] = arr[t]
    tl.pelvis_offset[t + 1 : until] = tl.pelvis_offset[t]
    for s in SIDES:
        for name in ("flex", "abduct", "elbow", "twist"):
            arr = getattr(ch.arms[s], name)
            arr[t + 1 : until] = arr[t]


# ------------------------------------------------------------------------------------
# The catalogue: which variants exist, how long they take, what posture they need
# ------------------------------------------------------------------------------------

POSTURE = {
    "sit_down": ("standing", "sitting"),
    "stand_up": ("sitting", "standing"),
    "lie_down": ("standing", "lying"),
    "get_up": ("lying", "standing"),
}

CATALOGUE: dict[str, dict] = {
    "walk": {
        "variants": [{"direction": d} for d in ("forward", "left", "right", "forward-left", "forward-right")],
        "dur": (3.0, 8.0),
        "speed": True,
    },
    "jog": {"variants": [{"direction": d} for d in ("forward", "left", "right")], "dur": (4.0, 8.0), "speed": True},
    "run": {"variants": [{"direction": d} for d in ("forward", "left", "right")], "dur": (4.5, 8.0), "speed": True},
    "walk_backward": {"variants": [{"direction": "backward"}], "dur": (3.0, 7.0), "speed": True},
    "sidestep": {"variants": [{"direction": d} for d in ("left", "right")], "dur": (3.0, 6.0)},
    "turn": {
        "variants": [{"direction": d, "angle": a} for d in ("left", "right") for a in (90, 180)],
        "dur": (4.0, 8.0),
    },
    "circle": {"variants": [{"direction": d} for d in ("cw", "ccw")], "dur": (7.0, 10.0)},
    "turn_around": {"variants": [{"direction": d} for d in ("left", "right")], "dur": (2.0, 3.5)},
    "step_over": {"variants": [{}], "dur": (2.5, 4.0)},
    "raise_arm": {"variants": [{"side": s} for s in ("left", "right", "both")], "dur": (2.0, 4.5), "speed": True},
    "wave": {"variants": [{"side": s} for s in ("left", "right", "both")], "dur": (2.5, 5.0), "count": (2, 4)},
    "punch": {"variants": [{"side": s} for s in ("left", "right")], "dur": (2.0, 4.0), "count": (1, 3)},
    "reach": {"variants": [{"side": s} for s in ("left", "right")], "dur": (2.0, 4.0)},
    "clap": {"variants": [{"side": "both"}], "dur": (2.0, 4.5), "count": (2, 5)},
    "throw": {"variants": [{"side": s} for s in ("left", "right")], "dur": (2.0, 3.5)},
    "kick": {"variants": [{"side": s} for s in ("left", "right")], "dur": (2.0, 4.5), "count": (1, 2), "amp": True},
    "lunge": {"variants": [{"side": s} for s in ("left", "right")], "dur": (3.0, 5.0)},
    "squat": {"variants": [{}], "dur": (2.5, 6.0), "count": (1, 3)},
    "hop": {"variants": [{"side": s} for s in ("left", "right")], "dur": (3.0, 6.0), "count": (2, 4)},
    "kneel": {"variants": [{"side": s} for s in ("left", "right")], "dur": (4.0, 7.0)},
    "jump_up": {"variants": [{}], "dur": (2.0, 5.0), "count": (1, 3), "amp": True},
    "jump_forward": {"variants": [{"direction": "forward"}], "dur": (2.0, 4.5), "count": (1, 2)},
    "jumping_jacks": {"variants": [{}], "dur": (3.0, 7.0), "count": (2, 4)},
    "sit_down": {"variants": [{}], "dur": (2.5, 4.0)},
    "stand_up": {"variants": [{}], "dur": (2.5, 4.0)},
    "lie_down": {"variants": [{}], "dur": (5.0, 8.0)},
    "get_up": {"variants": [{}], "dur": (5.0, 8.0)},
    "bow": {"variants": [{}], "dur": (2.5, 4.0)},
    "stretch": {"variants": [{}], "dur": (4.0, 7.0)},
}

# Kinds registered one entry each in motion_core.corpus.kinds (name -> its Kind), filled
# when that package is imported. They are not in CATALOGUE: sample_spec(rng) without a kind,
# distinct_actions() and the corpus build draw only from CATALOGUE, so a registered kind that
# the models were not trained on (a staged kind) changes nothing they read. Asked for by name
# (sample_spec(rng, kind), apply, duration_of, captions), a registered kind works like any other.
REGISTERED: dict = {}


def catalogue_entry(kind: str) -> dict:
    """The catalogue entry (variants, dur, count, ...) of a built-in or registered kind."""
    return CATALOGUE[kind] if kind in CATALOGUE else REGISTERED[kind].catalogue


# Seconds per repetition, so that counted actions get room for every repetition.
PER_COUNT = {
    "wave": 0.55,
    "punch": 0.8,
    "clap": 0.5,
    "kick": 1.6,
    "squat": 1.8,
    "hop": 0.7,
    "jump_up": 1.4,
    "jump_forward": 1.8,
    "jumping_jacks": 1.4,
}


def distinct_actions() -> list[str]:
    """Every (kind, side/direction) variant, the unit the corpus counts as one action."""
    out = []
    for kind, c in CATALOGUE.items():
        for v in c["variants"]:
            tag = "-".join(str(x) for x in v.values())
            out.append(f"{kind}:{tag}" if tag else kind)
    return out


def sample_spec(rng: np.random.Generator, kind: str | None = None, kinds: list[str] | None = None) -> Spec:
    """One action's labels: of ``kind``, else of a kind drawn from ``kinds`` (default CATALOGUE)."""
    kinds = list(CATALOGUE) if kinds is None else kinds
    kind = kind or kinds[int(rng.integers(len(kinds)))]
    c = catalogue_entry(kind)
    v = dict(c["variants"][int(rng.integers(len(c["variants"])))])
    if c.get("count") and rng.random() < 0.7:
        v["count"] = int(rng.integers(c["count"][0], c["count"][1] + 1))
    if c.get("speed"):
        v["speed"] = str(rng.choice(["slow", "normal", "normal", "fast"]))
    if c.get("amp") and rng.random() < 0.35:
        v["amplitude"] = "high"
    return Spec(kind=kind, **v)


def duration_of(spec: Spec, rng: np.random.Generator) -> float:
    c = catalogue_entry(spec.kind)
    lo, hi = c["dur"]
    d = float(rng.uniform(lo, hi))
    per = PER_COUNT.get(spec.kind, c.get("per_count"))
    if spec.count and per:
        d = max(d, 1.0 + per * spec.count)
    if spec.speed == "slow" and spec.kind in ("raise_arm",):
        d *= 1.3
    return float(min(d, 10.0))
