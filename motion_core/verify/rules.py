"""Rule-based verifier: does a motion do what its structured labels say?

``verify(joints, labels)`` measures the motion (heading change, displacement direction
relative to the initial facing, which wrist rose, how many flights, ...) and checks each
label against it. It scores the corpus's own clips and, later, generated motions, so it
uses only what a motion shows (joint positions), never how it was made.

Conventions: the motion is canonicalised (floor at y = 0, facing +z at frame 0); +x is
the body's left, so a displacement angle atan2(dx, dz) > 0 and a heading increase are
both "to the left"; a clockwise circle seen from above is a continuous right turn.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..body.features import canonicalize, facing_angles
from ..body.skeleton import HUMANML3D
from ..body.terrain import surface

J = HUMANML3D.joint_names.index
WRIST = {"left": J("left_wrist"), "right": J("right_wrist")}
SHOULDER = {"left": J("left_shoulder"), "right": J("right_shoulder")}
ANKLE = {"left": J("left_ankle"), "right": J("right_ankle")}
TOE = {"left": J("left_foot"), "right": J("right_foot")}
KNEE = {"left": J("left_knee"), "right": J("right_knee")}
HEAD = J("head")
# "Raised" for a wrist, one definition for raise and wave: no lower than 10 cm under its
# shoulder. Real actors wave at chest-to-face height and raise a hand, in some styles, to
# shoulder height only (see the raise rule).
RAISED_VS_SHOULDER = -0.10
# A raise must lift the wrist this far (metres) above where it started: with the lower
# height above, this is what tells a raised arm from one that merely hangs high.
RAISE_LIFT = 0.30
DIRECTION_DEG = {"forward": 0, "left": 90, "right": -90, "forward-left": 45, "forward-right": -45, "backward": 180}
OTHER = {"left": "right", "right": "left"}


@dataclass
class Verdict:
    passed: bool
    checks: dict[str, bool] = field(default_factory=dict)
    measures: dict[str, float] = field(default_factory=dict)


def episodes(mask: np.ndarray, min_len: int = 2, min_gap: int = 2) -> list[tuple[int, int]]:
    """Runs of True at least min_len long; runs separated by fewer than min_gap False frames merge."""
    runs: list[list[int]] = []
    t = 0
    n = len(mask)
    while t < n:
        if mask[t]:
            s = t
            while t < n and mask[t]:
                t += 1
            if runs and s - runs[-1][1] < min_gap:
                runs[-1][1] = t
            else:
                runs.append([s, t])
        else:
            t += 1
    return [(a, b) for a, b in runs if b - a >= min_len]


class Measures:
    """Lazily computed measurements of one canonical motion (T, 22, 3), 20 fps."""

    def __init__(self, joints: np.ndarray, fps: float = 20.0) -> None:
        self.j = canonicalize(np.asarray(joints, dtype=np.float64))
        self.fps = fps
        self.T = len(self.j)
        self.heading = np.unwrap(facing_angles(self.j, smooth=False))
        h0 = self.heading[: max(1, min(5, self.T))].mean()
        self.h0 = h0
        self.fwd0 = np.array([np.sin(h0), np.cos(h0)])
        self.left0 = np.array([np.cos(h0), -np.sin(h0)])

    # --- whole-body path ---
    def turn_deg(self) -> float:
        k = max(1, min(5, self.T // 4))
        return float(np.degrees(self.heading[-k:].mean() - self.heading[:k].mean()))

    def displacement(self) -> np.ndarray:
        return self.j[-1, 0, [0, 2]] - self.j[0, 0, [0, 2]]

    def disp_angle_deg(self) -> float:
        d = self.displacement()
        return float(np.degrees(np.arctan2(d @ self.left0, d @ self.fwd0)))

    def mean_speed(self) -> float:
        a, b = self.T // 4, max(self.T // 4 + 2, 3 * self.T // 4)
        v = np.linalg.norm(np.diff(self.j[a:b, 0, [0, 2]], axis=0), axis=-1) * self.fps
        return float(v.mean()) if len(v) else 0.0

    # --- feet ---
    @property
    def ground(self) -> np.ndarray | None:
        """(T, 2) height of the ground under the left and right foot (``body.terrain``: a
        foot standing on a stair tread stands on the ground there), or None on flat ground."""
        if not hasattr(self, "_ground"):
            self._ground = surface(self.j)
        return self._ground

    def foot_lifted(self, side: str) -> np.ndarray:
        """(T,) the foot is off the ground: its toe over 4.5 cm and its ankle over 10 cm above
        the ground under it (y = 0, or the tread it stands on)."""
        toe, ankle = self.j[:, TOE[side], 1], self.j[:, ANKLE[side], 1]
        if self.ground is not None:
            under = self.ground[:, 0 if side == "left" else 1]
            toe, ankle = toe - under, ankle - under
        return (toe > 0.045) & (ankle > 0.1)

    def flights(self) -> list[tuple[int, int]]:
        return episodes(self.foot_lifted("left") & self.foot_lifted("right"), min_len=2, min_gap=3)

    # --- body-frame coordinates relative to the initial facing of each frame's chest ---
    def body_frame(self, idx: int) -> np.ndarray:
        """(T, 3) joint idx relative to the pelvis in each frame's own facing frame (x left, z front)."""
        rel = self.j[:, idx] - self.j[:, 0]
        h = self.heading
        x = rel[:, 0] * np.cos(h) - rel[:, 2] * np.sin(h)
        z = rel[:, 0] * np.sin(h) + rel[:, 2] * np.cos(h)
        return np.stack([x, rel[:, 1], z], -1)

    def reach_forward(self, side: str) -> np.ndarray:
        return self.body_frame(WRIST[side])[:, 2] - self.body_frame(SHOULDER[side])[:, 2]

    def wrist_above_head(self, side: str) -> np.ndarray:
        return self.j[:, WRIST[side], 1] - self.j[:, HEAD, 1]

    def wrist_above_shoulder(self, side: str) -> np.ndarray:
        return self.j[:, WRIST[side], 1] - self.j[:, SHOULDER[side], 1]

    def wrist_lift(self, side: str) -> float:
        """Highest wrist height above its starting height (median of the first 5 frames)."""
        y = self.j[:, WRIST[side], 1]
        return float(y.max() - np.median(y[: max(1, min(5, self.T))]))

    def wrist_speed(self, side: str) -> np.ndarray:
        return np.linalg.norm(np.diff(self.j[:, WRIST[side]], axis=0), axis=-1) * self.fps

    def furthest(self) -> float:
        """The pelvis's greatest horizontal distance from where it started (m)."""
        return float(np.linalg.norm(self.j[:, 0, [0, 2]] - self.j[0, 0, [0, 2]], axis=-1).max())


def _count_ok(n: int, want: int | None, slack: int = 0) -> bool:
    return want is None or abs(n - want) <= slack


def _sides(side: str | None) -> list[str]:
    return ["left", "right"] if side == "both" else [side] if side in ("left", "right") else []


def has_rule(labels: dict) -> bool:
    """Whether the verifier can check these labels: the corpus labels a real clip whose
    content it has no rule for (bow, punch, dance, ...) "real:CONTENT"."""
    return not str(labels.get("kind", "")).startswith("real:")


# Rules of kinds registered outside this file (motion_core/verify/kind_rules.py): kind ->
# rule(measures, labels) -> (checks, measures). verify() uses them for kinds it has no
# branch for.
EXTRA_RULES: dict = {}

# Rules that read the whole motion rather than its Measures (verify/chain.py: several actions
# in order): kind -> rule(joints, labels, fps) -> Verdict.
WHOLE_MOTION_RULES: dict = {}


def verify(joints: np.ndarray, labels: dict, fps: float = 20.0) -> Verdict:
    """Check a motion against labels {action, side, direction, count, speed, amplitude, angle}."""
    kind = labels.get("kind") or labels.get("action")
    if kind in WHOLE_MOTION_RULES:
        return WHOLE_MOTION_RULES[kind](joints, labels, fps)
    m = Measures(joints, fps)
    side = labels.get("side")
    direction = labels.get("direction")
    count = labels.get("count")
    c: dict[str, bool] = {}
    ms: dict[str, float] = {}
    turn = m.turn_deg()
    disp = float(np.linalg.norm(m.displacement()))
    ang = m.disp_angle_deg()
    ms.update(turn_deg=turn, displacement=disp, disp_angle_deg=ang)

    def angle_close(target: float, tol: float) -> bool:
        return abs((ang - target + 180) % 360 - 180) <= tol

    if kind in ("walk", "jog", "run"):
        spd = m.mean_speed()
        nflight = sum(b - a for a, b in m.flights())
        ms.update(speed=spd, flight_frames=nflight)
        c["moves"] = disp > 1.0
        c["direction"] = angle_close(DIRECTION_DEG[direction or "forward"], 35)
        if kind == "walk":
            c["gait"] = nflight <= 1 and spd < 2.0
            if labels.get("speed") == "slow":
                c["speed"] = spd < 0.95
            elif labels.get("speed") == "fast":
                c["speed"] = spd > 1.3
        else:
            c["gait"] = nflight >= 2 and (spd > 2.6 if kind == "run" else 1.4 < spd < 3.3)
    elif kind == "walk_backward":
        c["moves"] = disp > 0.8
        c["direction"] = angle_close(180, 35)
        c["facing_kept"] = abs(turn) < 45
    elif kind == "sidestep":
        c["moves"] = disp > 0.5
        c["direction"] = angle_close(DIRECTION_DEG[direction], 35)
        c["facing_kept"] = abs(turn) < 30
        # Steps, not a jump to the side: no flight longer than 0.15 s (a staged jump_sideways
        # flies for 0.35-0.4 s).
        c["steps"] = max((b - a for a, b in m.flights()), default=0) <= 3
    elif kind == "turn":
        want = (labels.get("angle") or 90) * (1 if direction == "left" else -1)
        c["turn_sign"] = np.sign(turn) == np.sign(want)
        c["turn_amount"] = abs(turn - want) <= max(40, 0.3 * abs(want))
        c["moves"] = disp > 0.5
    elif kind == "circle":
        want = 1 if direction == "ccw" else -1
        c["full_circle"] = turn * want > 270
        # Walked round: the pelvis goes at least half a metre from where it started (a turn on
        # the spot, as the staged spin or a jump with a full turn, does not).
        c["walks_round"] = m.furthest() > 0.5
    elif kind == "turn_around":
        want = 180 * (1 if direction == "left" else -1)
        c["turn_amount"] = abs(turn - want) <= 50
        c["in_place"] = disp < 0.6
    elif kind == "step_over":
        lift = max(m.j[:, ANKLE["left"], 1].max(), m.j[:, ANKLE["right"], 1].max())
        ms["ankle_max"] = float(lift)
        c["high_steps"] = lift > 0.3
        c["moves_forward"] = disp > 0.4 and angle_close(0, 45)
    elif kind == "raise_arm":
        # Raised: the wrist lifted at least 30 cm from where it started, to no lower than
        # 10 cm under its shoulder. Why, from the Bandai Namco motion capture: "5 cm above
        # the head" refused the actors who stop just under the head;
        # "10 cm above the shoulder" then refused every Bandai Namco raise in the feminine
        # style (the wrist lifted 0.43-0.5 m, to shoulder height) and a fifth of the elderly
        # ones. The lift requirement keeps an arm that only hangs high from counting.
        for s in _sides(side):
            top = float(m.wrist_above_shoulder(s).max())
            lift = m.wrist_lift(s)
            ms.update({f"{s}_above_shoulder": top, f"{s}_lift": lift})
            c[f"{s}_up"] = top > RAISED_VS_SHOULDER and lift > RAISE_LIFT
        if side in ("left", "right"):
            c["other_down"] = m.wrist_above_shoulder(OTHER[side]).max() < 0.0
        elif side == "both":
            # both arms up, not the two hands together on one grip (a golf swing): at their
            # highest the wrists are more than 25 cm apart (every real raise: 35 cm or more)
            t = int((m.j[:, WRIST["left"], 1] + m.j[:, WRIST["right"], 1]).argmax())
            c["hands_apart"] = float(np.linalg.norm(m.j[t, WRIST["left"]] - m.j[t, WRIST["right"]])) > 0.25
    elif kind == "wave":
        for s in _sides(side):
            # Raised: the wrist no lower than 10 cm under its shoulder (real actors wave at
            # chest-to-face height; "5 cm above the shoulder" refused 15% of real waves).
            up = m.wrist_above_shoulder(s) > RAISED_VS_SHOULDER
            c[f"{s}_raised"] = up.mean() > 0.3
            # oscillation of the wrist across the body while raised
            x = m.body_frame(WRIST[s])[:, 0] * (1 if s == "left" else -1)
            xr = x[up]
            if len(xr) > 9:
                xr = xr - np.convolve(xr, np.ones(9) / 9, mode="same")
                peaks = episodes(xr > 0.02, min_len=1, min_gap=2)
                ms[f"{s}_waves"] = len(peaks)
                c[f"{s}_waves"] = len(peaks) >= 1 and _count_ok(len(peaks), count, 1)
            else:
                c[f"{s}_waves"] = False
        if side in ("left", "right"):
            c["other_down"] = m.wrist_above_shoulder(OTHER[side]).max() < 0.0
    elif kind in ("punch", "reach"):
        s = side
        ext = m.reach_forward(s)
        other = m.reach_forward(OTHER[s])
        ms.update(extension=float(ext.max()), other_extension=float(other.max()))
        c["extends"] = ext.max() > 0.42
        c["this_side"] = ext.max() > other.max() + 0.1
        if kind == "punch":
            hits = episodes(ext > 0.45, min_len=1, min_gap=3)
            ms["punches"] = len(hits)
            c["count"] = _count_ok(len(hits), count)
        else:
            c["slow_extension"] = m.wrist_speed(s).max() < 3.0
    elif kind == "clap":
        d = np.linalg.norm(m.j[:, WRIST["left"]] - m.j[:, WRIST["right"]], axis=-1)
        claps = episodes(d < 0.14, min_len=1, min_gap=2)
        ms["claps"] = len(claps)
        c["hands_meet"] = len(claps) >= 1
        c["count"] = _count_ok(len(claps), count)
        c["in_front"] = (
            bool(np.all([m.body_frame(WRIST[s])[d < 0.14, 2].mean() > 0.15 for s in ("left", "right")]))
            if len(claps)
            else False
        )
        # Claps: the hands open wide before each meeting (35 cm) and part again soon (within
        # 0.6 s), and both come in to it (not one hand coming to the other held still):
        # crossing the arms, clasping or stirring a bowl bring the hands together otherwise.
        sp = {s: np.r_[0.0, m.wrist_speed(s)] for s in ("left", "right")}
        opened, brief, both_in, prev = [], [], [], 0
        for a, b in claps:
            opened.append(a > prev and float(d[prev:a].max()) > 0.35)
            brief.append((b - a) / fps <= 0.6)
            both_in.append(min(sp[s][max(0, a - 3) : a + 1].max() for s in ("left", "right")) > 0.25)
            prev = b
        c["hands_open_between"] = bool(claps) and all(opened)
        c["brief"] = bool(claps) and all(brief)
        c["both_hands_in"] = bool(claps) and all(both_in)
    elif kind == "throw":
        sp, so = m.wrist_speed(side).max(), m.wrist_speed(OTHER[side]).max()
        ms.update(wrist_speed=float(sp), other_speed=float(so))
        c["fast_arm"] = sp > 3.0 and sp > 1.8 * so
        c["overhead"] = m.wrist_above_shoulder(side).max() > 0.05
        # Thrown, not held up: the free hand stays below its shoulder (both arms overhead in
        # turn is a swimming stroke) and the hand does not rest at the head (a salute).
        at_head = episodes(np.linalg.norm(m.j[:, WRIST[side]] - m.j[:, HEAD], axis=-1) < 0.2, min_len=1, min_gap=2)
        c["free_hand_low"] = m.wrist_above_shoulder(OTHER[side]).max() < -0.05
        c["not_held_at_head"] = max((b - a for a, b in at_head), default=0) / fps <= 0.5
    elif kind == "kick":
        a_s = m.j[:, ANKLE[side], 1]
        a_o = m.j[:, ANKLE[OTHER[side]], 1]
        ms.update(ankle_max=float(a_s.max()), other_ankle_max=float(a_o.max()))
        c["this_leg"] = a_s.max() > a_o.max() + 0.15
        kicks = episodes(a_s > 0.3, min_len=1, min_gap=3)
        c["count"] = len(kicks) >= 1 and _count_ok(len(kicks), count)
        c["amplitude"] = (a_s.max() > 0.7) if labels.get("amplitude") == "high" else (a_s.max() < 0.7)
        c["forward"] = m.body_frame(ANKLE[side])[:, 2].max() > 0.3
    elif kind == "lunge":
        drop = m.j[:5, 0, 1].mean() - m.j[:, 0, 1].min()
        f_s = m.body_frame(ANKLE[side])[:, 2] - m.body_frame(ANKLE[OTHER[side]])[:, 2]
        ms.update(pelvis_drop=float(drop), stride=float(f_s.max()))
        c["drops"] = drop > 0.15
        c["this_leg_forward"] = f_s.max() > 0.45
    elif kind == "squat":
        base = m.j[:5, 0, 1].mean()
        dips = episodes(m.j[:, 0, 1] < base - 0.2, min_len=2, min_gap=3)
        ms["squats"] = len(dips)
        c["squats"] = len(dips) >= 1 and _count_ok(len(dips), count)
        c["feet_stay"] = not m.foot_lifted("left").any() and not m.foot_lifted("right").any()
        # From standing, on the feet: the knees stay off the floor (not kneeling down) and so
        # do the hands (a squat, not a pick-up or a push-up).
        c["from_standing"] = base > 0.75
        c["knees_off_floor"] = min(m.j[:, KNEE[s], 1].min() for s in ("left", "right")) > 0.15
        c["hands_off_floor"] = min(m.j[:, WRIST[s], 1].min() for s in ("left", "right")) > 0.3
    elif kind == "hop":
        up_other = m.foot_lifted(OTHER[side])
        hops = episodes(m.foot_lifted(side), min_len=1, min_gap=2)
        ms["hops"] = len(hops)
        c["other_leg_up"] = up_other[m.T // 4 : 3 * m.T // 4].mean() > 0.8
        c["hops"] = len(hops) >= 1 and _count_ok(len(hops), count)
    elif kind == "kneel":
        k_s, k_o = m.j[:, KNEE[side], 1].min(), m.j[:, KNEE[OTHER[side]], 1].min()
        ms.update(knee_min=float(k_s), other_knee_min=float(k_o))
        c["goes_down"] = m.j[:, 0, 1].min() < 0.65
        c["this_knee"] = k_s < 0.2 and k_s < k_o - 0.1
        c["stands_again"] = m.j[-3:, 0, 1].mean() > 0.8
    elif kind in ("jump_up", "jump_forward"):
        fl = m.flights()
        rise = float(m.j[:, 0, 1].max() - np.median(m.j[: max(3, m.T // 10), 0, 1]))
        ms.update(jumps=len(fl), rise=rise)
        c["jumps"] = len(fl) >= 1 and _count_ok(len(fl), count)
        if kind == "jump_up":
            c["in_place"] = disp < 0.4
            c["facing_kept"] = abs(turn) < 45  # straight up (a jump that turns in the air is another action)
            c["amplitude"] = rise > 0.3 if labels.get("amplitude") == "high" else rise < 0.3
        else:
            c["forward"] = disp > 0.35 and angle_close(0, 35)
    elif kind == "jumping_jacks":
        fl = m.flights()
        width = np.abs(m.j[:, ANKLE["left"], 0] - m.j[:, ANKLE["right"], 0])
        arms = episodes((m.wrist_above_head("left") > 0) & (m.wrist_above_head("right") > 0), min_len=1, min_gap=3)
        ms.update(hops=len(fl), arm_raises=len(arms), max_width=float(width.max()))
        c["hops"] = len(fl) >= 2 and _count_ok(len(fl), 2 * count if count else None, 1)
        c["arms"] = len(arms) >= 1 and _count_ok(len(arms), count)
        c["feet_apart"] = width.max() > 0.4
    elif kind in ("sit_down", "stand_up"):
        p0, p1 = m.j[:3, 0, 1].mean(), m.j[-3:, 0, 1].mean()
        hi, lo = (p0, p1) if kind == "sit_down" else (p1, p0)
        c["standing_end"] = hi > 0.8
        # Seated: the pelvis at seat height with the knees up in front, not on the floor
        # (kneeling puts the pelvis at seat height too).
        seat = slice(-3, None) if kind == "sit_down" else slice(0, 3)
        knees = min(m.j[seat, KNEE[s], 1].mean() for s in ("left", "right"))
        c["seated_end"] = 0.3 < lo < 0.65 and knees > 0.25
    elif kind in ("lie_down", "get_up"):
        a, b = (slice(0, 3), slice(-3, None)) if kind == "lie_down" else (slice(-3, None), slice(0, 3))
        c["standing_end"] = m.j[a, 0, 1].mean() > 0.8
        c["lying_end"] = m.j[b, 0, 1].mean() < 0.3 and m.j[b, HEAD, 1].mean() < 0.4
    elif kind == "bow":
        head = m.j[:, HEAD, 1]
        drop = head[:3].mean() - head.min()
        ms["head_drop"] = float(drop)
        c["bends"] = drop > 0.2
        c["stays_up"] = m.j[:, 0, 1].min() > 0.75 and abs(head[-3:].mean() - head[:3].mean()) < 0.1
        c["forward"] = m.body_frame(HEAD)[:, 2].max() > 0.25
        # Only the bow: in place (not a stumble), the hands hanging between the knees and the
        # shoulders (not touching the toes, not a guard or a golf swing).
        c["in_place"] = m.furthest() < 0.4
        c["hands_hang"] = all(
            (m.j[:, WRIST[s], 1] > m.j[:, KNEE[s], 1]).all() and m.wrist_above_shoulder(s).max() < 0.0
            for s in ("left", "right")
        )
    elif kind == "stretch":
        both_up = (m.wrist_above_head("left") > 0) & (m.wrist_above_head("right") > 0)
        lean = m.body_frame(HEAD)[:, 0]
        ms.update(lean_left=float(lean.max()), lean_right=float(lean.min()))
        # up apart (a golf swing's hands go over the head together)
        apart = np.linalg.norm(m.j[:, WRIST["left"]] - m.j[:, WRIST["right"]], axis=-1) > 0.25
        c["arms_up"] = len(episodes(both_up & apart, min_len=3)) >= 1
        c["leans_both_ways"] = lean.max() > 0.08 and lean.min() < -0.08
    elif kind in EXTRA_RULES:
        extra_c, extra_ms = EXTRA_RULES[kind](m, labels)
        c.update(extra_c)
        ms.update(extra_ms)
    else:
        raise ValueError(f"the verifier has no rule for action {kind!r}")
    return Verdict(passed=bool(all(c.values())) and bool(c), checks={k: bool(v) for k, v in c.items()}, measures=ms)
