"""Stairs and a platform: kinds whose ground changes height under the feet.

The rig has no floor of its own: a foot stands wherever its ankle target is. These kinds lay
out a stair (or a platform) in the body frame of the clip's start, put every plant flat on a
tread at the tread's height, and raise or lower the pelvis one step at a time, so that the
motion itself shows the steps (``motion_core.body.terrain`` finds them again from the joints).

A flight of stairs is N treads, each ``rise`` higher (or lower) than the last and ``tread``
deep. The feet go step over step: the leading foot lands on the first tread, the other on
the second, and so on; the last step brings the trailing foot onto the top (or the floor)
beside the other. Going up, the swinging foot first lifts almost straight up (the knee comes
up high), then forward over the nosing, and comes down flat; the trailing heel rises before
it leaves. Going down, the foot first travels forward over the edge, then the leg reaches
down, toes pointing down, and the foot lands flat. The pelvis rises (falls) by one rise per
step: going up mostly after the foot lands, as the leading leg straightens; going down while
the foot reaches down. Where a leg cannot reach, ``rig.make_reachable`` lowers the pelvis.

These kinds change the level the clip stands on, so they write that level outside their own
frames too: going up, the tail stands on the top; going down, the lead-in stands on it. So
they are a clip's only action, which is how ``sample_clip`` renders them.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.ndimage import gaussian_filter1d, maximum_filter1d

from ..actions import Spec, Timeline, _arm, smoothstep
from ..gait import FootOverride, Plant
from ..rig import FOOT, FOOT_PITCH_FLAT, SIDES, TOE_PLANT_Y, Channels
from .base import Kind, register

RISE = (0.15, 0.19)  # m: the height of one step (a typical stair rises about 17 cm)
TREAD = (0.26, 0.31)  # m: the depth of one tread (about 28 cm)
PLATFORM = (0.2, 0.38)  # m: the height of a platform stepped onto
HEEL = 0.05  # m: the heel, behind the ankle joint (the rig has no heel joint)


@dataclass
class Swing:
    side: str
    start: int  # frame (timeline) of the first frame in the air
    frames: int
    target: int  # index of the tread it lands on: 0 = where the feet start, 1 = the first, ...


@dataclass
class Layout:
    """A stair in the clip's body frame: ``along`` from the start position of the pelvis."""

    edges: np.ndarray  # (K,) along position where tread i (1..K) begins; tread K runs on
    levels: np.ndarray  # (K + 1,) height of the start (index 0) and of each tread
    inset: np.ndarray  # (K + 1,) how far past its tread's start edge the ankle lands (m)

    def height(self, x: np.ndarray) -> np.ndarray:
        """The ground height at along positions x."""
        return self.levels[np.searchsorted(self.edges, x, side="right")]

    def ankle_at(self, i: int) -> float:
        return float(self.edges[i - 1] + self.inset[i]) if i > 0 else 0.0


def _toe_len(pitch: np.ndarray | float, side: str) -> np.ndarray:
    return FOOT[SIDES.index(side)] * np.cos(pitch)


def _ankle_y(sole: np.ndarray, pitch: np.ndarray, side: str) -> np.ndarray:
    """Ankle height for the foot's lowest point (toe or heel) at ``sole`` above the floor."""
    return sole + TOE_PLANT_Y + FOOT[SIDES.index(side)] * np.maximum(np.sin(pitch), np.sin(FOOT_PITCH_FLAT))


def _swing_path(
    lay: Layout, a0: float, a1: float, h0: float, h1: float, p0: float, n: int, up: bool, side: str, rng
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Along position, sole height and pitch of an ankle swinging over the stair (n frames; the
    last lands). a0, a1: ankle along at lift-off and landing; h0, h1: tread heights; p0: the
    pitch at lift-off (heel raised)."""
    u = np.arange(1, n + 1) / n
    if up:
        s = smoothstep((u - 0.05) / 0.8)  # up and forward: the knee comes forward and up
        base = h0 + (h1 - h0) * smoothstep(u / 0.55)
        prof = FOOT_PITCH_FLAT - 0.18 * np.sin(np.pi * u)  # toes up to clear the nosing
        clear = rng.uniform(0.06, 0.09)
    else:
        s = smoothstep((u - 0.03) / 0.78)  # forward over the edge, then down
        base = h0 + (h1 - h0) * smoothstep((u - 0.3) / 0.62)
        prof = FOOT_PITCH_FLAT + 0.4 * smoothstep((u - 0.2) / 0.35) * (1 - smoothstep((u - 0.62) / 0.28))
        clear = rng.uniform(0.03, 0.05)
    pitch = p0 + (prof - p0) * smoothstep(u / 0.3)
    x = a0 + (a1 - a0) * s
    # the whole foot (heel to toe) stays above the ground under it by ``clear``, except where it
    # lifts off and lands
    span = np.linspace(-HEEL, 1.0, 12)
    toe = _toe_len(pitch, side)
    pts = x[:, None] + np.where(span < 0, span, span * toe[:, None])
    under = lay.height(pts).max(1)
    w = np.minimum(1.0, np.minimum(u / 0.25, (1 - u) / 0.2))
    env = under + clear * np.clip(w, 0.0, 1.0)
    sole = np.maximum(base + 0.02 * np.sin(np.pi * u), env)
    sole = gaussian_filter1d(maximum_filter1d(sole, 3), 1.0, mode="nearest")
    sole = np.maximum(sole, env)
    sole[-1] = h1
    pitch[-1] = FOOT_PITCH_FLAT
    return x, sole, pitch


def _foot_track(
    lay: Layout, swings: list[Swing], side: str, w0: int, w1: int, up: bool, heel: float, rng
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Along position, sole height and pitch of one foot over frames [w0, w1)."""
    n = w1 - w0
    x, sole, pitch = np.zeros(n), np.full(n, lay.levels[0]), np.full(n, FOOT_PITCH_FLAT)
    cur = 0
    last_land = 0
    for sw in (s for s in swings if s.side == side):
        a, b = sw.start - w0, sw.start - w0 + sw.frames
        # the heel rises before lift-off, the toe staying where it is
        k = max(2, min(round(0.55 * sw.frames), a - last_land - 2))
        rise = heel * smoothstep(np.arange(1, k + 1) / k)
        pitch[a - k : a] = FOOT_PITCH_FLAT + rise
        toe0 = lay.ankle_at(cur) + _toe_len(FOOT_PITCH_FLAT, side)
        x[a - k : a] = toe0 - _toe_len(pitch[a - k : a], side)
        sx, ss, sp = _swing_path(
            lay, float(x[a - 1]), lay.ankle_at(sw.target), lay.levels[cur], lay.levels[sw.target],
            float(pitch[a - 1]), sw.frames, up, side, rng,
        )  # fmt: skip
        x[a:b], sole[a:b], pitch[a:b] = sx, ss, sp
        x[b:], sole[b:], pitch[b:] = lay.ankle_at(sw.target), lay.levels[sw.target], FOOT_PITCH_FLAT
        cur, last_land = sw.target, b
    return x, sole, pitch


def _climb(
    tl: Timeline,
    t0: int,
    t1: int,
    lay: Layout,
    swings: list[Swing],
    up: bool,
    heel: float,
    travel: tuple[float, float] | None = None,
) -> None:
    """Write the feet (an override over the frames the feet are on the stair) and the path.
    The pelvis travels over the feet (the mean of their along positions, smoothed), or, with
    ``travel`` (from frame, to frame), from the start to over the final feet in that time."""
    T = tl.ch.T
    w0, w1 = (t0, T) if up else (0, t1)
    rng = tl.rng
    tracks = {s: _foot_track(lay, swings, s, w0, w1, up, heel, rng) for s in SIDES}
    mean_x = 0.5 * (tracks["l"][0] + tracks["r"][0])
    if travel is None:
        period = np.mean(np.diff([s.start for s in swings])) if len(swings) > 1 else 10.0
        centre = gaussian_filter1d(mean_x, 0.3 * period, mode="nearest")
    else:
        t = np.arange(w0, w1) + 0.5
        centre = mean_x[-1] * smoothstep((t - travel[0]) / max(travel[1] - travel[0], 1.0))
    centre -= centre[0]
    tl.vel[w0:w1, 1] += np.gradient(centre) * tl.fps

    def fn(start: int, end: int, plants: dict[str, Plant], ch: Channels):
        h = ch.heading[start]
        fwd, left = np.array([np.sin(h), np.cos(h)]), np.array([np.cos(h), -np.sin(h)])
        root = ch.root_xz[start]
        out = {}
        for s in SIDES:
            x, sole, pitch = (v[start - w0 : end - w0] for v in tracks[s])
            lat = float((plants[s].xz - root) @ left)
            xz = root[None] + fwd[None] * x[:, None] + left[None] * lat
            a = np.stack([xz[:, 0], _ankle_y(sole, pitch, s), xz[:, 1]], -1)
            out[s] = (a, np.full(end - start, plants[s].yaw), pitch)
        return out

    tl.overrides.append(FootOverride(w0, w1, SIDES, fn))


def _level_track(T: int, changes: list[tuple[float, float, float]], start: float) -> np.ndarray:
    """(T,) the body's level: ``start``, then each (from frame, to frame, step) eased in."""
    t = np.arange(T) + 0.5
    out = np.full(T, start)
    for a, b, d in changes:
        out += d * smoothstep((t - a) / max(b - a, 1.0))
    return out


def _stairs(spec: Spec, tl: Timeline, t0: int, t1: int, up: bool) -> None:
    n = t1 - t0
    r = tl.rng
    fps = tl.fps
    rise, tread = r.uniform(*RISE), r.uniform(*TREAD)
    secs = r.uniform(0.62, 0.8) if up else r.uniform(0.55, 0.72)  # per step
    N = spec.count or int(np.clip(round((n / fps - 0.5) / secs - 0.7), 3, 8))
    # frames per step: a labelled count gets the window (slower steps, to a second each)
    P = min((1.0 if spec.count else 1.15 * secs) * fps, (n - 14) / (N + 0.7))
    sw_n = max(7, round(0.68 * P))
    spare = n - (N * P + sw_n) - 12
    first = t0 + 6 + 0.35 * max(spare, 0.0)  # room for the first heel to rise
    lead = "l" if r.random() < 0.5 else "r"
    other = "r" if lead == "l" else "l"
    swings = []
    for k in range(N + 1):
        side = lead if k % 2 == 0 else other
        swings.append(Swing(side, round(first + k * P), sw_n, min(k + 1, N)))
    toe0 = _toe_len(FOOT_PITCH_FLAT, "l")
    edge0 = toe0 + r.uniform(0.06, 0.14) if up else toe0 + r.uniform(0.02, 0.08)
    edges = edge0 + tread * np.arange(N)
    levels = rise * (np.arange(N + 1) if up else np.arange(N, -1, -1))
    inset = np.concatenate([[0.0], r.uniform(0.05, 0.08, N)])
    if not up:
        inset[-1] += r.uniform(0.03, 0.1)  # the floor: no tread edge to keep to
    lay = Layout(edges, levels, inset)
    _climb(tl, t0, t1, lay, swings, up, heel=r.uniform(0.35, 0.5) if up else r.uniform(0.3, 0.45))
    T = tl.ch.T
    if up:  # the body rises as the leading leg straightens, after the foot lands
        ch = [(s.start + s.frames - 0.3 * P, s.start + s.frames + 0.6 * P, rise) for s in swings[:N]]
    else:  # ... and goes down while the leg reaches down
        ch = [(s.start + 0.15 * s.frames, s.start + s.frames + 0.25 * P, -rise) for s in swings[:N]]
    tl.ch.pelvis_y += _level_track(T, ch, 0.0 if up else N * rise)
    t = np.arange(T) + 0.5
    land = swings[-1].start + sw_n
    env = smoothstep((t - first + 0.5 * P) / P) * (1 - smoothstep((t - land) / P))
    if up:  # leaning into the climb, eyes on the next steps
        tl.ch.pelvis_pitch += 0.12 * env
        tl.ch.spine_bend += 0.1 * env
        tl.ch.neck_pitch += 0.15 * env
    else:  # upright, looking down at the steps
        tl.ch.neck_pitch += 0.3 * env
        tl.ch.spine_bend += 0.04 * env
    tl.arm_swing[t0:t1] = 0.25
    for s in SIDES:
        _arm(tl, s, 0, T, elbow=0.25 * env, abduct=0.05 * env)


def walk_upstairs(spec: Spec, tl: Timeline, t0: int, t1: int) -> None:
    """Up a flight of stairs, step over step, ending on the top."""
    _stairs(spec, tl, t0, t1, up=True)


def walk_downstairs(spec: Spec, tl: Timeline, t0: int, t1: int) -> None:
    """Down a flight of stairs, step over step, from the top to the floor."""
    _stairs(spec, tl, t0, t1, up=False)


def step_up_onto(spec: Spec, tl: Timeline, t0: int, t1: int) -> None:
    """One big step up onto a platform with the leading leg, the other foot joining it; stays up."""
    n = t1 - t0
    r = tl.rng
    fps = tl.fps
    hp = r.uniform(*PLATFORM)
    lead = "l" if spec.side == "left" else "r"
    other = "r" if lead == "l" else "l"
    sw1, sw2 = round(r.uniform(0.55, 0.7) * fps), round(r.uniform(0.5, 0.6) * fps)
    pause = round(r.uniform(0.25, 0.5) * fps)  # the leading leg pushes the body up meanwhile
    spare = n - (sw1 + pause + sw2) - 12
    a = t0 + 6 + round(0.35 * max(spare, 0))
    b = a + sw1 + pause
    swings = [Swing(lead, a, sw1, 1), Swing(other, b, sw2, 1)]
    toe0 = _toe_len(FOOT_PITCH_FLAT, "l")
    lay = Layout(np.array([toe0 + r.uniform(0.08, 0.18)]), np.array([0.0, hp]), np.array([0.0, r.uniform(0.1, 0.18)]))
    # the body goes forward over the leading foot as it rises onto it
    rise = (a + 0.8 * sw1, b + 0.8 * sw2)
    _climb(tl, t0, t1, lay, swings, True, heel=r.uniform(0.3, 0.45), travel=(a + 0.9 * sw1, rise[1]))
    T = tl.ch.T
    tl.ch.pelvis_y += _level_track(T, [(*rise, hp)], 0.0)
    push = np.zeros(T)
    t = np.arange(T) + 0.5
    push += smoothstep((t - a) / sw1) * (1 - smoothstep((t - b - sw2) / sw2))
    tl.ch.pelvis_pitch += 0.2 * (hp / 0.3) * push  # leaning over the leading leg to push up
    tl.ch.spine_bend += 0.12 * push
    tl.ch.neck_pitch += 0.2 * push
    tl.arm_swing[t0:t1] = 0.2
    for s in SIDES:
        _arm(tl, s, 0, T, elbow=0.3 * push, flex=0.15 * push)


STAIRS = {"variants": [{}], "dur": (3.0, 7.0), "count": (3, 8), "per_count": 0.75}

register(
    Kind(
        name="walk_upstairs",
        family="stairs",
        catalogue=STAIRS,
        generate=walk_upstairs,
        captions=(
            "{who} walks up the stairs",
            "{who} walks upstairs",
            "{who} climbs {num} stairs",
            "{who} is climbing some stairs",
            "{who} goes up the stairs",
            "{who} walks up {num} steps",
        ),
        looks=(
            "up a flight of 3-8 steps (rise 15-19 cm, tread 26-31 cm), step over step: the knee comes up high, "
            "the foot lifts over the nosing and lands flat on the tread, the trailing heel rises before it "
            "leaves, the pelvis rises a step at a time, leaning forward a little; ends standing on the top"
        ),
    )
)
register(
    Kind(
        name="walk_downstairs",
        family="stairs",
        catalogue=STAIRS,
        generate=walk_downstairs,
        captions=(
            "{who} walks down the stairs",
            "{who} walks downstairs",
            "{who} goes down {num} steps",
            "{who} walks down some steps",
            "{who} goes downstairs",
            "{who} descends the stairs",
        ),
        looks=(
            "down a flight of 3-8 steps, step over step: the foot goes forward over the edge, the leg reaches "
            "down with the toes pointing down and lands flat, the pelvis lowers a step at a time, upright, "
            "looking down; starts on the top, ends on the floor"
        ),
    )
)
register(
    Kind(
        name="step_up_onto",
        family="stairs",
        catalogue={"variants": [{"side": s} for s in ("left", "right")], "dur": (2.5, 4.5)},
        generate=step_up_onto,
        captions=(
            "{who} steps up onto a platform",
            "{who} steps on a low platform with {leg}",
            "{who} steps up onto a box, leading with {leg}",
            "{who} steps onto higher ground",
            "{who} steps on a platform with one large step",
            "{who} steps up on a step with {leg} first",
        ),
        looks=(
            "one big step with the leading leg onto a platform 20-38 cm high, a lean over that knee as it "
            "pushes the body up, the other foot comes up beside it, and it stays standing on the platform"
        ),
    )
)
