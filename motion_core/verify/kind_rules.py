"""Verifier rules of the kinds registered in ``motion_core.corpus.kinds``, one function each.

Each rule reads a motion's :class:`~.rules.Measures` (joint positions only, canonical: floor
at the lowest joint, facing +z at frame 0) and its labels, and returns (checks, measures).
``rules.verify`` uses them for these kinds. Heights are metres above the floor, "lateral"
is along the body's own left (+) axis of each frame, "forward" along its facing.
"""

from __future__ import annotations

from itertools import pairwise

import numpy as np

from .rules import ANKLE, EXTRA_RULES, HEAD, KNEE, OTHER, SHOULDER, TOE, WRIST, J, Measures, _count_ok, _sides, episodes

ELBOW = {"left": J("left_elbow"), "right": J("right_elbow")}
SG = {"left": 1.0, "right": -1.0}
RULES: dict = {}


def rule(name: str):
    def deco(fn):
        RULES[name] = fn
        EXTRA_RULES[name] = fn
        return fn

    return deco


def _y(m: Measures, idx: int) -> np.ndarray:
    return m.j[:, idx, 1]


def _start(x: np.ndarray) -> float:
    return float(x[: max(1, min(3, len(x)))].mean())


def _end(x: np.ndarray) -> float:
    return float(x[-max(1, min(3, len(x))) :].mean())


def _mid(m: Measures) -> slice:
    return slice(m.T // 4, max(m.T // 4 + 1, 3 * m.T // 4))


def _lateral(m: Measures, idx: int, side: str) -> np.ndarray:
    """Distance out to the body's ``side`` of the pelvis (negative: across the midline)."""
    return SG[side] * m.body_frame(idx)[:, 0]


def _flexion(m: Measures, side: str) -> np.ndarray:
    """(T,) knee flexion in degrees (0 = straight leg)."""
    hip, knee, ankle = (m.j[:, J(f"{side}_{n}")] for n in ("hip", "knee", "ankle"))
    u, v = hip - knee, ankle - knee
    cos = (u * v).sum(-1) / (np.linalg.norm(u, axis=-1) * np.linalg.norm(v, axis=-1)).clip(1e-9)
    return 180.0 - np.degrees(np.arccos(np.clip(cos, -1, 1)))


def _disp_angle_ok(m: Measures, target: float, tol: float) -> bool:
    return abs((m.disp_angle_deg() - target + 180) % 360 - 180) <= tol


def _transfer(m: Measures, labels: dict, pick: bool) -> tuple[dict, dict]:
    """Pick up / put down: crouch, the labelled hands to the floor in front, stand again;
    the hands end (pick up) or start (put down) held in front, higher than they hang."""
    c, ms = {}, {}
    sides = _sides(labels.get("side") or "both")
    pel = _y(m, 0)
    p0 = _start(pel)
    drop = p0 - float(pel.min())
    ms["pelvis_drop"] = drop
    c["crouches"] = drop > 0.16
    c["stands_again"] = _end(pel) > p0 - 0.1
    for s in sides:
        w = _y(m, WRIST[s])
        low = int(w.argmin())
        ms[f"{s}_wrist_min"] = float(w.min())
        c[f"{s}_to_floor"] = w.min() < 0.25 and m.body_frame(WRIST[s])[low, 2] > 0.15  # in front
        held, hanging = (_end, _start) if pick else (_start, _end)
        fwd = m.reach_forward(s)
        c[f"{s}_held"] = held(w) > hanging(w) + 0.06 and held(fwd) > 0.15
    if len(sides) == 1:
        s, o = sides[0], OTHER[sides[0]]
        c["other_hand_stays_up"] = _y(m, WRIST[o]).min() > _y(m, WRIST[s]).min() + 0.15
    return c, ms


@rule("pick_up")
def pick_up(m: Measures, labels: dict):
    return _transfer(m, labels, pick=True)


@rule("put_down")
def put_down(m: Measures, labels: dict):
    return _transfer(m, labels, pick=False)


@rule("carry")
def carry(m: Measures, labels: dict):
    c, ms = {}, {}
    mid = _mid(m)
    disp = float(np.linalg.norm(m.displacement()))
    ms["displacement"] = disp
    c["moves_forward"] = disp > 1.0 and _disp_angle_ok(m, 0, 35)
    lw, rw = m.j[mid, WRIST["left"]], m.j[mid, WRIST["right"]]
    front = np.minimum(m.reach_forward("left")[mid], m.reach_forward("right")[mid])
    ms["front_min_median"] = float(np.median(front))
    c["hands_in_front"] = (front > 0.15).mean() > 0.9
    c["hands_together"] = float(np.median(np.linalg.norm(lw - rw, axis=-1))) < 0.5
    pel, sh = m.j[mid, 0, 1], m.j[mid, SHOULDER["left"], 1]
    y = np.minimum(lw[:, 1], rw[:, 1])
    c["held_height"] = ((y > pel - 0.15) & (np.maximum(lw[:, 1], rw[:, 1]) < sh)).mean() > 0.9
    return c, ms


@rule("crawl")
def crawl(m: Measures, labels: dict):
    c, ms = {}, {}
    mid = _mid(m)
    disp = float(np.linalg.norm(m.displacement()))
    head_fwd = float(np.median(m.body_frame(HEAD)[mid, 2]))
    ms.update(displacement=disp, head_forward=head_fwd, pelvis_max=float(m.j[mid, 0, 1].max()))
    c["low"] = m.j[mid, 0, 1].max() < 0.65 and m.j[mid, HEAD, 1].max() < 0.85
    c["trunk_level"] = head_fwd > 0.4
    c["hands_down"] = all(_y(m, WRIST[s])[mid].min() < 0.12 for s in ("left", "right"))
    c["knees_down"] = all(_y(m, KNEE[s])[mid].min() < 0.12 for s in ("left", "right"))
    c["moves_forward"] = disp > 0.4 and _disp_angle_ok(m, 0, 40)
    return c, ms


@rule("push_up")
def push_up(m: Measures, labels: dict):
    c, ms = {}, {}
    mid = _mid(m)
    sh = 0.5 * (_y(m, SHOULDER["left"]) + _y(m, SHOULDER["right"]))
    top, bot = np.percentile(sh, 95), np.percentile(sh, 5)
    reps = episodes(sh < 0.5 * (top + bot), min_len=2, min_gap=3) if top - bot > 0.15 else []
    head_fwd = float(np.median(m.body_frame(HEAD)[mid, 2]))
    ankle_back = float(np.median(np.minimum(m.body_frame(ANKLE["left"])[:, 2], m.body_frame(ANKLE["right"])[:, 2])))
    ms.update(push_ups=len(reps), range=float(top - bot), head_forward=head_fwd, ankle_back=ankle_back)
    knee_flex = max(float(_flexion(m, s)[mid].max()) for s in ("left", "right"))
    ms["knee_flex_deg"] = knee_flex
    c["plank"] = m.j[:, 0, 1].max() < 0.6 and head_fwd > 0.4 and ankle_back < -0.7
    c["legs_straight"] = knee_flex < 35
    c["hands_down"] = all(_y(m, WRIST[s]).min() < 0.12 for s in ("left", "right"))
    c["in_place"] = float(np.linalg.norm(m.displacement())) < 0.3
    c["count"] = len(reps) >= 1 and _count_ok(len(reps), labels.get("count"))
    return c, ms


@rule("hands_on_hips")
def hands_on_hips(m: Measures, labels: dict):
    c, ms = {}, {}
    pel = _y(m, 0)
    on = np.ones(m.T, dtype=bool)
    for s in ("left", "right"):
        w_lat, e_lat = _lateral(m, WRIST[s], s), _lateral(m, ELBOW[s], s)
        w_z = m.body_frame(WRIST[s])[:, 2]
        on &= (np.abs(_y(m, WRIST[s]) - pel) < 0.12) & (w_lat > 0.1) & (w_lat < 0.24) & (np.abs(w_z) < 0.12)
        on &= e_lat > w_lat + 0.1  # elbows out
    ms["on_hips"] = float(on.mean())
    c["hands_on_hips"] = on.mean() > 0.35
    c["in_place"] = float(np.linalg.norm(m.displacement())) < 0.3
    return c, ms


@rule("cross_arms")
def cross_arms(m: Measures, labels: dict):
    c, ms = {}, {}
    pel, sh = _y(m, 0), _y(m, SHOULDER["left"])
    on = np.ones(m.T, dtype=bool)
    for s in ("left", "right"):
        y = _y(m, WRIST[s])
        on &= (_lateral(m, WRIST[s], s) < -0.03) & (y > pel + 0.15) & (y < sh) & (m.body_frame(WRIST[s])[:, 2] > 0.08)
    ms["crossed"] = float(on.mean())
    c["arms_crossed"] = on.mean() > 0.35
    c["in_place"] = float(np.linalg.norm(m.displacement())) < 0.3
    return c, ms


def _hand_at_head(m: Measures, s: str) -> tuple[np.ndarray, np.ndarray]:
    d = m.j[:, WRIST[s]] - m.j[:, HEAD]
    return np.linalg.norm(d, axis=-1), d[:, 1]


def _rub(m: Measures, idx: int, mask: np.ndarray) -> float:
    """Std (m) of the wrist's fast back-and-forth where mask, after a 7-frame moving average."""
    x = m.body_frame(idx)
    if mask.sum() < 8:
        return 0.0
    k = np.ones(7) / 7
    hp = np.stack([x[:, i] - np.convolve(x[:, i], k, mode="same") for i in range(3)], -1)
    return float(np.linalg.norm(hp[mask], axis=-1).std() + np.abs(hp[mask]).mean())


@rule("scratch_head")
def scratch_head(m: Measures, labels: dict):
    c, ms = {}, {}
    s = labels.get("side") or "right"
    dist, dy = _hand_at_head(m, s)
    on = (dist < 0.2) & (dy > 0.05)
    inner = on.copy()
    inner[:4] = inner[-4:] = False
    rub = _rub(m, WRIST[s], inner)
    ms.update(on_head=float(on.mean()), rub=rub)
    c["hand_on_head"] = on.mean() > 0.2
    c["rubs"] = rub > 0.01
    c["other_down"] = m.wrist_above_shoulder(OTHER[s]).max() < 0.0
    return c, ms


@rule("salute")
def salute(m: Measures, labels: dict):
    c, ms = {}, {}
    s = labels.get("side") or "right"
    dist, dy = _hand_at_head(m, s)
    ahead = m.body_frame(WRIST[s])[:, 2] - m.body_frame(HEAD)[:, 2]
    elbow_out = _lateral(m, ELBOW[s], s) - _lateral(m, SHOULDER[s], s)
    elbow_up = _y(m, ELBOW[s]) - _y(m, SHOULDER[s])
    on = (dist < 0.22) & (np.abs(dy) < 0.06) & (ahead > 0.0) & (elbow_out > 0.12) & (elbow_up > -0.12)
    ms.update(at_brow=float(on.mean()))
    c["hand_at_brow"] = on.mean() > 0.2
    c["other_down"] = m.wrist_above_shoulder(OTHER[s]).max() < 0.0
    return c, ms


@rule("check_watch")
def check_watch(m: Measures, labels: dict):
    c, ms = {}, {}
    s = labels.get("side") or "left"
    w = WRIST[s]
    y, sh = _y(m, w), _y(m, SHOULDER[s])
    on = (
        (m.reach_forward(s) > 0.18)
        & (y > sh - 0.45)
        & (y < sh - 0.05)
        & (np.abs(m.body_frame(w)[:, 0]) < 0.15)
        & (np.abs(_y(m, ELBOW[s]) - y) < 0.12)  # forearm about level
    )
    ms["looking"] = float(on.mean())
    c["wrist_up_in_front"] = on.mean() > 0.25
    c["other_hangs"] = m.wrist_above_shoulder(OTHER[s]).max() < -0.3
    c["in_place"] = float(np.linalg.norm(m.displacement())) < 0.3
    c["stays_up"] = float(_y(m, 0).min()) > _start(_y(m, 0)) - 0.1  # no crouch (a put down holds a hand there too)
    return c, ms


@rule("stand_on_one_leg")
def stand_on_one_leg(m: Measures, labels: dict):
    c, ms = {}, {}
    s = labels.get("side") or "left"  # the standing leg
    o = OTHER[s]
    up = m.foot_lifted(o) & (_y(m, ANKLE[o]) > 0.2)
    ms["other_foot_up"] = float(up.mean())
    c["other_foot_up"] = up.mean() > 0.45
    speed = np.linalg.norm(np.diff(m.j[:, ANKLE[o]], axis=0), axis=-1) * m.fps
    held = float(np.median(speed[up[1:]])) if up[1:].any() else 99.0
    ms["raised_foot_speed"] = held
    c["foot_held_up"] = held < 0.4  # held there, not kicking or stepping
    c["standing_foot_down"] = not m.foot_lifted(s).any()
    c["in_place"] = float(np.linalg.norm(m.displacement())) < 0.3
    return c, ms


@rule("touch_toes")
def touch_toes(m: Measures, labels: dict):
    c, ms = {}, {}
    head = _y(m, HEAD)
    # knees bend no further than standing (the corpus stands with soft knees, about 35 degrees)
    knee_bend = max(float(_flexion(m, s).max() - _start(_flexion(m, s))) for s in ("left", "right"))
    ms["knee_bend_deg"] = knee_bend
    c["legs_straight"] = knee_bend < 15  # a fold from the hips, not a squat
    for s in ("left", "right"):
        w = m.j[:, WRIST[s]]
        low = int(w[:, 1].argmin())
        gap = float(np.linalg.norm(w[low, [0, 2]] - m.j[low, TOE[s], [0, 2]]))
        ms[f"{s}_toe_gap"] = gap
        c[f"{s}_hand_to_toes"] = w[low, 1] < 0.3 and gap < 0.3
    c["folds"] = head.min() < 0.8
    c["stands_again"] = _end(head) > _start(head) - 0.1
    return c, ms


@rule("bicep_curls")
def bicep_curls(m: Measures, labels: dict):
    c, ms = {}, {}
    sides = _sides(labels.get("side") or "both")
    for s in sides:
        curl = _y(m, WRIST[s]) - _y(m, ELBOW[s])
        reps = episodes(curl > 0.1, min_len=2, min_gap=3)
        ms[f"{s}_curls"] = len(reps)
        c[f"{s}_curls"] = len(reps) >= 2 and _count_ok(len(reps), labels.get("count"))  # curls come in sets
        c[f"{s}_elbow_low"] = (_y(m, ELBOW[s]) - _y(m, SHOULDER[s])).max() < -0.15
        elbow_fwd = m.body_frame(ELBOW[s])[:, 2] - m.body_frame(SHOULDER[s])[:, 2]
        c[f"{s}_elbow_by_side"] = elbow_fwd.max() < 0.18  # the upper arm stays down (not a punch or a reach)
    if len(sides) == 1:
        o = OTHER[sides[0]]
        c["other_still"] = (_y(m, WRIST[o]) - _y(m, ELBOW[o])).max() < 0.0
    c["in_place"] = float(np.linalg.norm(m.displacement())) < 0.3  # a jog's arms curl too
    return c, ms


@rule("march_in_place")
def march_in_place(m: Measures, labels: dict):
    c, ms = {}, {}
    lifts = {}
    for s in ("left", "right"):
        up = m.foot_lifted(s) & (_y(m, ANKLE[s]) > 0.15)
        lifts[s] = len(episodes(up, min_len=2, min_gap=2))
    ms.update(left_lifts=lifts["left"], right_lifts=lifts["right"], flights=len(m.flights()))
    c["both_knees_up"] = min(lifts.values()) >= 2
    c["count"] = _count_ok(sum(lifts.values()), labels.get("count"), 1)
    c["no_flight"] = len(m.flights()) == 0
    c["in_place"] = float(np.linalg.norm(m.j[:, 0, [0, 2]] - m.j[0, 0, [0, 2]], axis=-1).max()) < 0.3
    return c, ms


@rule("spin")
def spin(m: Measures, labels: dict):
    c, ms = {}, {}
    turn = m.turn_deg()
    want = 1 if labels.get("direction") == "left" else -1
    out = float(np.linalg.norm(m.j[:, 0, [0, 2]] - m.j[0, 0, [0, 2]], axis=-1).max())
    ms.update(turn=turn, furthest=out)
    c["full_turn"] = 300 < turn * want < 420
    c["on_the_spot"] = out < 0.45
    c["stepping"] = not m.flights()  # not a jump with a turn
    return c, ms


@rule("jump_sideways")
def jump_sideways(m: Measures, labels: dict):
    c, ms = {}, {}
    fl = m.flights()
    disp = float(np.linalg.norm(m.displacement()))
    ms.update(jumps=len(fl), displacement=disp)
    c["jumps"] = len(fl) >= 1 and _count_ok(len(fl), labels.get("count"))
    c["sideways"] = disp > 0.3 and _disp_angle_ok(m, 90 if labels.get("direction") == "left" else -90, 35)
    c["facing_kept"] = abs(m.turn_deg()) < 30
    return c, ms


@rule("arm_circles")
def arm_circles(m: Measures, labels: dict):
    """Both arms out to the side while each wrist goes round (the angle of its path about its
    mean in the body's sagittal plane keeps growing, in the labelled sense)."""
    c, ms = {}, {}
    want = 1 if labels.get("direction", "forward") == "forward" else -1
    for s in ("left", "right"):
        out = _lateral(m, WRIST[s], s) - _lateral(m, SHOULDER[s], s)
        on = out > 0.3
        ms[f"{s}_out"] = float(on.mean())
        w = m.body_frame(WRIST[s]) - m.body_frame(SHOULDER[s])
        if on.sum() < 10:
            c[f"{s}_circles"] = False
            continue
        z, y = w[on, 2] - w[on, 2].mean(), w[on, 1] - w[on, 1].mean()
        # forward circles: the hand comes over the top moving forward (+z at the top): y then z
        ang = np.unwrap(np.arctan2(z, y))
        turns = float((ang[-1] - ang[0]) / (2 * np.pi))
        radius = float(np.median(np.hypot(z, y)))
        ms.update({f"{s}_turns": turns, f"{s}_radius": radius})
        c[f"{s}_out"] = on.mean() > 0.5
        c[f"{s}_circles"] = turns * want > 1.5 and radius > 0.05
        if labels.get("count"):
            c[f"{s}_count"] = abs(abs(turns) - labels["count"]) <= 1.5  # ramps in and out: part turns
    return c, ms


@rule("sit_up")
def sit_up(m: Measures, labels: dict):
    c, ms = {}, {}
    head, pel = _y(m, HEAD), _y(m, 0)
    base = min(_start(head), _end(head))
    ups = episodes(head > base + 0.25, min_len=2, min_gap=3)
    ms.update(sit_ups=len(ups), head_top=float(head.max() - base))
    c["lying"] = pel.max() < 0.3 and _start(head) < 0.35 and _end(head) < 0.35
    c["knees_up"] = all(float(np.median(_y(m, KNEE[s]))) > 0.3 for s in ("left", "right"))
    c["feet_down"] = not m.foot_lifted("left").any() and not m.foot_lifted("right").any()
    c["count"] = len(ups) >= 1 and _count_ok(len(ups), labels.get("count"))
    return c, ms


@rule("touch_face")
def touch_face(m: Measures, labels: dict):
    """The wrist at the face: under the head joint (cheek, chin), in front of it, the elbow down."""
    c, ms = {}, {}
    s = labels.get("side") or "right"
    dist, dy = _hand_at_head(m, s)
    ahead = m.body_frame(WRIST[s])[:, 2] - m.body_frame(HEAD)[:, 2]
    elbow_down = _y(m, ELBOW[s]) < _y(m, SHOULDER[s]) - 0.05
    near = (dist < 0.2) & (dy < -0.04) & (dy > -0.2) & (ahead > 0.02)
    on = near & elbow_down
    ms["at_face"] = float(on.mean())
    c["hand_at_face"] = on.mean() > 0.2
    c["elbow_stays_down"] = not (near & ~elbow_down).any()  # not a cup tipped up to the mouth
    c["other_down"] = m.wrist_above_shoulder(OTHER[s]).max() < 0.0
    return c, ms


@rule("kneel_down")
def kneel_down(m: Measures, labels: dict):
    """Both knees on the floor at once with the trunk upright over them, standing before and after."""
    c, ms = {}, {}
    both = (_y(m, KNEE["left"]) < 0.12) & (_y(m, KNEE["right"]) < 0.12)
    pel, head = _y(m, 0), _y(m, HEAD)
    upright = both & (pel > 0.35) & (pel < 0.75) & (head > 0.9)
    ms.update(both_knees_down=float(both.mean()), kneeling_upright=float(upright.mean()))
    c["both_knees_down"] = upright.mean() > 0.15
    c["standing_ends"] = _start(pel) > 0.8 and _end(pel) > 0.8
    return c, ms


@rule("clasp_hands")
def clasp_hands(m: Measures, labels: dict):
    """Both wrists together in front of the chest, near the midline, the elbows below the shoulders."""
    c, ms = {}, {}
    pel, sh = _y(m, 0), _y(m, SHOULDER["left"])
    lw, rw = m.j[:, WRIST["left"]], m.j[:, WRIST["right"]]
    together = np.linalg.norm(lw - rw, axis=-1) < 0.1
    on = together.copy()
    for s in ("left", "right"):
        y = _y(m, WRIST[s])
        on &= (y > pel + 0.15) & (y < sh) & (m.body_frame(WRIST[s])[:, 2] > 0.12)
        on &= np.abs(m.body_frame(WRIST[s])[:, 0]) < 0.08
        on &= _y(m, ELBOW[s]) < _y(m, SHOULDER[s]) - 0.1
    ms["clasped"] = float(on.mean())
    c["hands_clasped"] = on.mean() > 0.35
    c["in_place"] = float(np.linalg.norm(m.displacement())) < 0.3
    return c, ms


@rule("phone_call")
def phone_call(m: Measures, labels: dict):
    """The wrist beside the head at ear height (not in front of the face, not on top), the elbow down."""
    c, ms = {}, {}
    s = labels.get("side") or "right"
    dist, dy = _hand_at_head(m, s)
    out = _lateral(m, WRIST[s], s) - _lateral(m, HEAD, s)
    ahead = m.body_frame(WRIST[s])[:, 2] - m.body_frame(HEAD)[:, 2]
    elbow_down = _y(m, ELBOW[s]) < _y(m, SHOULDER[s]) - 0.02
    on = (dist < 0.17) & (dy < 0.0) & (dy > -0.1) & (out > 0.05) & (np.abs(ahead) < 0.06) & elbow_down
    ms["at_ear"] = float(on.mean())
    c["hand_at_ear"] = on.mean() > 0.35
    c["other_down"] = m.wrist_above_shoulder(OTHER[s]).max() < 0.0
    c["in_place"] = float(np.linalg.norm(m.displacement())) < 0.3
    return c, ms


# ----------------------------------------------------------------------------------------
# Reactions: being pushed, stumbling, dodging
# ----------------------------------------------------------------------------------------

PUSH_DIR = {"forward": (1.0, 0.0), "backward": (-1.0, 0.0), "left": (0.0, 1.0), "right": (0.0, -1.0)}


def _velocity(m: Measures, idx: int) -> np.ndarray:
    """(T - 1, 2) horizontal velocity (left, forward) of joint idx in the first frame's facing."""
    return np.diff(m.j[:, idx][:, [0, 2]], axis=0) * m.fps


def _trunk_pitch(m: Measures) -> np.ndarray:
    """(T,) forward lean of the trunk (pelvis to neck) from upright, degrees, in each frame's facing."""
    rel = m.body_frame(J("neck"))
    return np.degrees(np.arctan2(rel[:, 2], rel[:, 1]))


@rule("being_pushed")
def being_pushed(m: Measures, labels: dict):
    """Still, then a jolt: the chest speeds off in the labelled direction within a fraction of a
    second, the trunk tilts that way, one to a few steps follow it, and the body stops again
    less than a stride away, facing the same way."""
    c, ms = {}, {}
    uf, ul = PUSH_DIR.get(labels.get("direction") or "backward", (-1.0, 0.0))
    v = _velocity(m, J("spine3"))
    along = v[:, 0] * ul + v[:, 1] * uf
    speed = np.linalg.norm(v, axis=-1)
    k = max(2, round(0.25 * m.fps))
    peak = int(along.argmax())
    quiet = np.nonzero(along[:peak] < 0.2)[0]
    rise = (peak - quiet[-1]) / m.fps if len(quiet) else 99.0
    disp = float(np.linalg.norm(m.displacement()))
    rel = m.body_frame(J("neck"))
    tilt = rel[:, 0] * ul + rel[:, 2] * uf
    lifts = sum(len(episodes(m.foot_lifted(s), min_len=1, min_gap=2)) for s in ("left", "right"))
    ms.update(peak_speed=float(along.max()), rise_s=rise, displacement=disp, tilt=float(tilt.max() - _start(tilt)))
    ms["foot_lifts"] = lifts
    c["still_first"] = speed[:k].max() < 0.3 and speed[-k:].max() < 0.3
    c["jolt"] = along.max() > 0.8 and rise < 0.45
    c["trunk_tilts_away"] = tilt.max() - _start(tilt) > 0.05
    c["pushed_that_way"] = 0.15 < disp < 0.8 and _disp_angle_ok(m, np.degrees(np.arctan2(ul, uf)), 40)
    c["steps"] = 1 <= lifts <= 5 and not m.flights()
    c["facing_kept"] = abs(m.turn_deg()) < 25
    return c, ms


@rule("stumble")
def stumble(m: Measures, labels: dict):
    """A walk forward with one short lurch: the trunk pitches well forward of its walking lean
    for under a second and a half in the middle of the clip, walking on both sides of it."""
    c, ms = {}, {}
    disp = float(np.linalg.norm(m.displacement()))
    pitch = _trunk_pitch(m)
    base = float(np.median(pitch))
    lurch = episodes(pitch > base + 12, min_len=2, min_gap=3)
    ms.update(displacement=disp, lurch_deg=float(pitch.max() - base), lurches=len(lurch))
    c["walks_forward"] = disp > 1.0 and _disp_angle_ok(m, 0, 30) and not m.flights()
    ok = False
    if len(lurch) == 1:
        a, b = lurch[0]
        v = _velocity(m, 0)[:, 1]
        w = round(0.6 * m.fps)
        pre, post = v[max(0, a - w) : a], v[b : b + w]
        ms.update(
            speed_before=float(pre.mean()) if len(pre) else 0.0, speed_after=float(post.mean()) if len(post) else 0.0
        )
        ok = (b - a) / m.fps < 1.5 and a > 0.15 * m.T and b < 0.9 * m.T and len(pre) and len(post)
        ok = bool(ok and pre.mean() > 0.4 and post.mean() > 0.3)
    c["one_lurch_mid_walk"] = ok
    return c, ms


@rule("dodge")
def dodge(m: Measures, labels: dict):
    """Guard up, the head slips quickly to the labelled side of the feet and comes back; the feet stay."""
    c, ms = {}, {}
    s = "left" if labels.get("direction") == "left" else "right"
    mid = 0.5 * (m.j[:, ANKLE["left"]] + m.j[:, ANKLE["right"]])
    x = SG[s] * (m.j[:, HEAD, 0] - mid[:, 0])
    shift = float(x.max() - _start(x))
    vx = np.diff(x) * m.fps
    ms.update(head_shift=shift, head_speed=float(vx.max()))
    guard = np.ones(m.T, dtype=bool)
    for side in ("left", "right"):
        y = _y(m, WRIST[side])
        guard &= (y > _y(m, SHOULDER[side]) - 0.3) & (y < _y(m, HEAD) + 0.05) & (m.reach_forward(side) > 0.05)
    ms["guard"] = float(guard.mean())
    c["guard_up"] = guard.mean() > 0.5
    c["slips_that_way"] = shift > 0.15 and vx.max() > 0.6
    c["comes_back"] = abs(_end(x) - _start(x)) < 0.1
    c["feet_stay"] = not m.foot_lifted("left").any() and not m.foot_lifted("right").any()
    return c, ms


# ----------------------------------------------------------------------------------------
# Hands at work (wipe, stir, drink) and instruments (guitar, violin)
# ----------------------------------------------------------------------------------------


def _hp(x: np.ndarray, k: int = 7) -> np.ndarray:
    """x minus its k-frame moving average (edge-padded): the quick part of a movement."""
    pad = np.pad(x, (k // 2, k // 2), mode="edge")
    return x - np.convolve(pad, np.ones(k) / k, mode="valid")


def _spread(x: np.ndarray) -> float:
    return float(np.percentile(x, 95) - np.percentile(x, 5)) if len(x) else 0.0


def _still(m: Measures, idx: int, mask: np.ndarray) -> float:
    """Median speed (m/s) of joint idx relative to the pelvis over mask."""
    rel = m.j[:, idx] - m.j[:, 0]
    v = np.linalg.norm(np.diff(rel, axis=0), axis=-1) * m.fps
    mk = mask[1:] & mask[:-1]
    return float(np.median(v[mk])) if mk.any() else 99.0


def _in_place(m: Measures, r: float = 0.3) -> bool:
    return float(np.linalg.norm(m.displacement())) < r


@rule("wipe")
def wipe(m: Measures, labels: dict):
    """One wrist moves over a flat surface in front at about hip height: big horizontal strokes
    or circles at a nearly constant height; the other hand hangs."""
    c, ms = {}, {}
    s = labels.get("side") or "right"
    w = m.j[:, WRIST[s]]
    pel = _y(m, 0)
    on = (m.reach_forward(s) > 0.12) & (w[:, 1] > pel - 0.2) & (w[:, 1] < pel + 0.2)
    if on.sum() < 10:
        c["wipes"] = False
        return c, ms
    on &= np.abs(w[:, 1] - np.median(w[on, 1])) < 0.025  # on the surface: at its height
    ms["on_surface"] = float(on.mean())
    if on.sum() < 10:
        c["wipes"] = False
    else:
        bf = m.body_frame(WRIST[s])[on]
        path = float(np.linalg.norm(np.diff(w[:, [0, 2]], axis=0), axis=-1)[on[1:] & on[:-1]].sum())
        ext = max(_spread(bf[:, 0]), _spread(bf[:, 2]))
        ms.update(path=path, extent=ext)
        c["wipes"] = on.mean() > 0.3 and path > 0.6 and ext > 0.16
    c["other_hangs"] = m.wrist_above_shoulder(OTHER[s]).max() < -0.3
    c["in_place"] = _in_place(m)
    return c, ms


@rule("stir")
def stir(m: Measures, labels: dict):
    """One wrist goes round in small circles in front of the belly, the other held still in
    front of it (holding the bowl)."""
    c, ms = {}, {}
    s = labels.get("side") or "right"
    o = OTHER[s]
    pel = _y(m, 0)

    def front(side):
        y = _y(m, WRIST[side])
        return (m.reach_forward(side) > 0.12) & (y > pel + 0.02) & (y < pel + 0.42)

    on = front(s) & front(o)
    ms["at_bowl"] = float(on.mean())
    if on.sum() < 12:
        c["stirs"] = False
    else:
        bf = m.body_frame(WRIST[s])[on]
        x, z = _hp(bf[:, 0], 15)[7:-7], _hp(bf[:, 2], 15)[7:-7]  # about the hand's running centre
        turns = abs(float(np.unwrap(np.arctan2(z, x))[-1] - np.arctan2(z[0], x[0])) / (2 * np.pi)) if len(x) > 4 else 0
        ext = max(_spread(x), _spread(z))
        ms.update(turns=turns, extent=ext)
        c["stirs"] = on.mean() > 0.35 and turns > 1.5 and 0.04 < ext < 0.15
    c["other_holds"] = _still(m, WRIST[o], on) < 0.15
    c["in_place"] = _in_place(m)
    return c, ms


@rule("drink")
def drink(m: Measures, labels: dict):
    """The wrist in front of and below the face, with the elbow raised to the shoulder and the
    head tipped back (drinking), for a while; the other hand down."""
    c, ms = {}, {}
    s = labels.get("side") or "right"
    dist, dy = _hand_at_head(m, s)
    ahead = m.body_frame(WRIST[s])[:, 2] - m.body_frame(HEAD)[:, 2]
    nod = m.body_frame(HEAD)[:, 2] - m.body_frame(J("neck"))[:, 2]
    back = nod < _start(nod) - 0.02
    elbow_up = _y(m, ELBOW[s]) > _y(m, SHOULDER[s]) - 0.08
    at_mouth = (dist < 0.24) & (dy < -0.06) & (dy > -0.22) & (ahead > 0.05)
    sip = at_mouth & back & elbow_up
    ms.update(at_mouth=float(at_mouth.mean()), sipping=float(sip.mean()))
    c["cup_at_mouth"] = at_mouth.mean() > 0.3
    c["drinks"] = sip.sum() >= round(0.4 * m.fps)
    c["other_down"] = m.wrist_above_shoulder(OTHER[s]).max() < -0.2
    c["in_place"] = _in_place(m)
    return c, ms


@rule("play_guitar")
def play_guitar(m: Measures, labels: dict):
    """The strumming wrist at the belly, near the midline, going quickly up and down; the other
    held out to its side at chest height, nearly still."""
    c, ms = {}, {}
    s = labels.get("side") or "right"
    o = OTHER[s]
    pel = _y(m, 0)
    ys, yo = _y(m, WRIST[s]), _y(m, WRIST[o])
    strum = (
        (m.reach_forward(s) > 0.08)
        & (ys > pel - 0.05)
        & (ys < pel + 0.32)
        & (np.abs(m.body_frame(WRIST[s])[:, 0]) < 0.14)
    )
    fret = (_lateral(m, WRIST[o], o) > 0.2) & (yo > pel + 0.12) & (yo < _y(m, SHOULDER[o]) - 0.05)
    fret &= m.body_frame(WRIST[o])[:, 2] > 0.1
    on = strum & fret
    hp = _hp(ys, 5)[on]
    strokes = len(episodes(hp > 0.015, min_len=1, min_gap=1)) if on.any() else 0
    ms.update(playing=float(on.mean()), strum=float(hp.std()) if on.any() else 0.0, strokes=strokes)
    c["holds_guitar"] = on.mean() > 0.35
    c["strums"] = strokes >= 4
    c["fretting_hand_still"] = _still(m, WRIST[o], on) < 0.3
    c["in_place"] = _in_place(m)
    return c, ms


@rule("play_violin")
def play_violin(m: Measures, labels: dict):
    """The holding wrist out in front at shoulder height and still; the bowing wrist sweeps
    side to side in front of the chest in long strokes."""
    c, ms = {}, {}
    s = labels.get("side") or "right"
    o = OTHER[s]
    yo, ys = _y(m, WRIST[o]), _y(m, WRIST[s])
    fwd_o = m.body_frame(WRIST[o])[:, 2] - m.body_frame(SHOULDER[o])[:, 2]
    hold = (np.abs(yo - _y(m, SHOULDER[o])) < 0.12) & (fwd_o > 0.22)
    hold &= _lateral(m, WRIST[o], o) - _lateral(m, SHOULDER[o], o) > 0.03
    bowing = (ys > _y(m, SHOULDER[s]) - 0.42) & (ys < _y(m, SHOULDER[s]) + 0.05) & (m.reach_forward(s) > 0.1)
    on = hold & bowing
    x = m.body_frame(WRIST[s])[:, 0]
    turns = len(episodes(np.diff(x)[on[1:]] > 0.004, min_len=2, min_gap=2)) if on.any() else 0
    ms.update(playing=float(on.mean()), bow_extent=_spread(x[on]), strokes=turns)
    c["holds_violin"] = on.mean() > 0.35 and _still(m, WRIST[o], on) < 0.25
    c["bows"] = _spread(x[on]) > 0.25 and turns >= 1
    c["in_place"] = _in_place(m)
    return c, ms


# ----------------------------------------------------------------------------------------
# Sports: golf swing, tennis forehand, boxing, dribbling, swimming strokes
# ----------------------------------------------------------------------------------------


def _feet_stay(m: Measures) -> bool:
    return not m.foot_lifted("left").any() and not m.foot_lifted("right").any()


@rule("golf_swing")
def golf_swing(m: Measures, labels: dict):
    """The hands together all through: up high on the backswing side, fast down past the hips,
    up high on the other side; in that order, the feet where they stand."""
    c, ms = {}, {}
    sg = 1.0 if (labels.get("side") or "right") == "right" else -1.0  # backswing to the golfer's right
    lw, rw = m.j[:, WRIST["left"]], m.j[:, WRIST["right"]]
    hands = 0.5 * (lw + rw)
    apart = np.linalg.norm(lw - rw, axis=-1)
    sh = 0.5 * (_y(m, SHOULDER["left"]) + _y(m, SHOULDER["right"]))
    # the canonical x is the body's left at the start; the feet stay, so it stays the body's left
    side = -sg * (hands[:, 0] - m.j[:, 0, 0])  # > 0: on the backswing side
    grip = episodes(apart < 0.15, min_len=2, min_gap=2)
    a, b = max(grip, key=lambda e: e[1] - e[0]) if grip else (0, 0)
    held = np.zeros(m.T, dtype=bool)
    held[a:b] = True
    high = held & (hands[:, 1] > sh - 0.1)
    back = np.nonzero(high & (side > 0.12))[0]
    thru = np.nonzero(high & (side < -0.12))[0]
    speed = np.linalg.norm(np.diff(hands, axis=0), axis=-1) * m.fps
    fast = float(speed[a : max(a, b - 1)].max()) if b - a > 2 else 0.0
    ms.update(grip_s=(b - a) / m.fps, hand_speed=fast, low=float(hands[held, 1].min()) if held.any() else 9.0)
    c["hands_together"] = (b - a) / m.fps > 1.5
    c["backswing_then_finish"] = len(back) > 0 and len(thru) > 0 and back[0] < thru[-1]
    c["fast_through_the_ball"] = fast > 4.0 and (hands[held, 1] < _y(m, 0)[held]).any()
    c["feet_stay"] = float(np.abs(m.j[:, ANKLE["left"], [0, 2]] - m.j[0, ANKLE["left"], [0, 2]]).max()) < 0.2
    c["in_place"] = _in_place(m)
    return c, ms


@rule("tennis_forehand")
def tennis_forehand(m: Measures, labels: dict):
    """One hand swings fast from back on its own side across to the other side, between hip and
    shoulder height (never overhead), much faster than the other hand."""
    c, ms = {}, {}
    s = labels.get("side") or "right"
    w = m.j[:, WRIST[s]]
    x = SG[s] * (w[:, 0] - m.j[:, 0, 0])  # out to its own side (canonical frame; the feet stay)
    z = w[:, 2] - m.j[:, 0, 2]
    sp, so = m.wrist_speed(s), m.wrist_speed(OTHER[s])
    k = int(sp.argmax())
    before, after = x[max(0, k - round(0.5 * m.fps)) : k + 1], x[k : k + round(0.5 * m.fps)]
    ms.update(
        wrist_speed=float(sp.max()), other_speed=float(so.max()), out=float(before.max()), across=float(after.min())
    )
    c["fast_swing"] = sp.max() > 3.5 and sp.max() > 1.6 * so.max()
    c["back_to_across"] = (
        before.max() > 0.3 and after.min() < 0.0 and z[max(0, k - round(0.6 * m.fps)) : k].min() < 0.05
    )
    c["not_overhead"] = m.wrist_above_shoulder(s).max() < 0.02
    c["at_hip_to_chest"] = _y(m, 0)[k] - 0.1 < w[k, 1] < _y(m, SHOULDER[s])[k]
    c["in_place"] = _in_place(m)
    return c, ms


@rule("boxing")
def boxing(m: Measures, labels: dict):
    """Both hands punch straight out in turn (each at least once, switching hands), coming back
    to a guard at the chin between punches."""
    c, ms = {}, {}
    punches = []
    for s in ("left", "right"):
        level = np.abs(_y(m, WRIST[s]) - _y(m, SHOULDER[s])) < 0.2  # straight out, not up
        alone = m.reach_forward(OTHER[s]) < 0.3  # the other hand back at the guard meanwhile
        punches += [(a, s) for a, _ in episodes((m.reach_forward(s) > 0.4) & level & alone, min_len=1, min_gap=3)]
    punches.sort()
    order = [s for _, s in punches]
    switches = sum(a != b for a, b in pairwise(order))
    guard = np.ones(m.T, dtype=bool)
    for s in ("left", "right"):
        y = _y(m, WRIST[s])
        guard &= (y > _y(m, SHOULDER[s]) - 0.25) & (y < _y(m, HEAD)) & (m.reach_forward(s) > 0.05)
    ms.update(punches=len(punches), switches=switches, guard=float(guard.mean()))
    c["both_hands_punch"] = set(order) == {"left", "right"} and switches >= 1
    c["count"] = len(punches) >= 2 and _count_ok(len(punches), labels.get("count"), 1)
    c["guard"] = guard.mean() > 0.25
    c["in_place"] = _in_place(m, 0.4)
    return c, ms


@rule("dribble")
def dribble(m: Measures, labels: dict):
    """Knees bent, one hand beside and in front of the hip, below it, pumping up and down
    (bouncing a ball) a few times."""
    c, ms = {}, {}
    s = labels.get("side") or "right"
    pel = _y(m, 0)
    y = _y(m, WRIST[s])
    at = (y < pel + 0.2) & (y > pel - 0.3) & (_lateral(m, WRIST[s], s) > 0.15) & (m.reach_forward(s) > 0.05)
    hp = _hp(y, 9)
    bounces = len(episodes((hp < -0.03) & at, min_len=1, min_gap=2))
    ms.update(
        at_ball=float(at.mean()),
        bounces=bounces,
        pelvis_drop=float(_start(pel) - np.median(pel[at])) if at.any() else 0.0,
    )
    c["hand_at_the_ball"] = at.mean() > 0.35
    c["bounces"] = bounces >= 3
    c["knees_bent"] = at.any() and _start(pel) - float(np.median(pel[at])) > 0.04
    c["in_place"] = _in_place(m)
    return c, ms


@rule("swim")
def swim(m: Measures, labels: dict):
    """The arms go over the head in turn, each reaching up several times, out of step with the
    other (front crawl in the air), while standing in place."""
    c, ms = {}, {}
    ups = {}
    for s in ("left", "right"):
        ups[s] = len(episodes(m.wrist_above_head(s) > 0.02, min_len=2, min_gap=3))
    yl, yr = _hp(_y(m, WRIST["left"]), 15), _hp(_y(m, WRIST["right"]), 15)
    corr = float(np.corrcoef(yl, yr)[0, 1]) if yl.std() > 1e-6 and yr.std() > 1e-6 else 1.0
    ms.update(left_strokes=ups["left"], right_strokes=ups["right"], corr=corr)
    c["strokes"] = min(ups.values()) >= 2
    c["alternating"] = corr < -0.3
    c["in_front_and_behind"] = all(
        m.reach_forward(s).max() > 0.3 and m.reach_forward(s).min() < -0.1 for s in ("left", "right")
    )
    c["in_place"] = _in_place(m)
    return c, ms


# ----------------------------------------------------------------------------------------
# Jumps with a turn or backwards, stomping, heel to toe on a line; looking around, shrugging;
# standing up from kneeling
# ----------------------------------------------------------------------------------------


@rule("spin_jump")
def spin_jump(m: Measures, labels: dict):
    """One flight, in place, the heading turned by the labelled angle that way, most of the turn
    while off the floor."""
    c, ms = {}, {}
    fl = m.flights()
    turn = m.turn_deg()
    want = (labels.get("angle") or 180) * (1 if labels.get("direction") == "left" else -1)
    in_air = sum(float(m.heading[b - 1] - m.heading[max(0, a - 1)]) for a, b in fl)
    ms.update(jumps=len(fl), turn=turn, turn_in_air=float(np.degrees(in_air)))
    c["jumps"] = len(fl) == 1
    c["turn"] = abs(turn - want) <= max(30, 0.25 * abs(want))
    c["turns_in_the_air"] = np.degrees(in_air) * np.sign(want) > 0.5 * abs(want)
    c["in_place"] = _in_place(m, 0.45)
    return c, ms


@rule("jump_backward")
def jump_backward(m: Measures, labels: dict):
    c, ms = {}, {}
    fl = m.flights()
    disp = float(np.linalg.norm(m.displacement()))
    ms.update(jumps=len(fl), displacement=disp)
    c["jumps"] = len(fl) == 1
    c["backward"] = disp > 0.4 and _disp_angle_ok(m, 180, 30)
    c["facing_kept"] = abs(m.turn_deg()) < 25
    return c, ms


@rule("stomp")
def stomp(m: Measures, labels: dict):
    """The labelled foot comes up and is driven down fast onto the same spot, count times; the
    other foot stays down; no kick forward."""
    c, ms = {}, {}
    s = labels.get("side") or "left"
    a = m.j[:, ANKLE[s]]
    lifted = (a[:, 1] - _start(a[:, 1]) > 0.12) & m.foot_lifted(s)
    n_up = len(episodes(lifted, min_len=2, min_gap=3))
    vy = np.diff(a[:, 1]) * m.fps
    ms.update(stomps=n_up, down_speed=float(-vy.min()), forward=float(m.body_frame(ANKLE[s])[:, 2].max()))
    c["stomps"] = n_up >= 1 and _count_ok(n_up, labels.get("count"))
    c["driven_down"] = -vy.min() > 1.4
    c["same_spot"] = (
        float(np.linalg.norm(a[-1, [0, 2]] - a[0, [0, 2]])) < 0.12 and m.body_frame(ANKLE[s])[:, 2].max() < 0.25
    )
    c["other_foot_down"] = not m.foot_lifted(OTHER[s]).any()
    return c, ms


@rule("walk_a_line")
def walk_a_line(m: Measures, labels: dict):
    """Slowly forward with the feet on one line (one in front of the other, not side by side)
    and both arms out to the sides."""
    c, ms = {}, {}
    mid = _mid(m)
    disp = float(np.linalg.norm(m.displacement()))
    gap = np.abs(m.body_frame(ANKLE["left"])[mid, 0] - m.body_frame(ANKLE["right"])[mid, 0])
    out = np.ones(m.T, dtype=bool)
    for s in ("left", "right"):
        out &= _lateral(m, WRIST[s], s) - _lateral(m, SHOULDER[s], s) > 0.25
    ms.update(displacement=disp, feet_apart=float(np.median(gap)), arms_out=float(out[mid].mean()))
    c["walks_forward"] = disp > 0.5 and _disp_angle_ok(m, 0, 25) and m.mean_speed() < 0.5 and not m.flights()
    c["feet_on_a_line"] = float(np.median(gap)) < 0.06
    c["arms_out"] = out[mid].mean() > 0.6
    return c, ms


def _yaw(v: np.ndarray) -> np.ndarray:
    """(T,) heading (radians, + = to the left) of horizontal vectors v (T, 3) with x left, z forward."""
    return np.arctan2(v[:, 0], v[:, 2])


@rule("look_around")
def look_around(m: Measures, labels: dict):
    """Standing still, the head and shoulders turn well to one side and to the other (the hips
    and feet stay), the arms down."""
    c, ms = {}, {}
    hips = m.j[:, J("left_hip")] - m.j[:, J("right_hip")]
    shl = m.j[:, SHOULDER["left"]] - m.j[:, SHOULDER["right"]]
    face = m.j[:, HEAD] - m.j[:, J("neck")]
    hip_yaw = np.unwrap(np.arctan2(-hips[:, 2], hips[:, 0]))  # the hips' line turned to forward
    sh = np.degrees(np.unwrap(np.arctan2(-shl[:, 2], shl[:, 0])) - hip_yaw)
    head = np.degrees(np.unwrap(_yaw(face)) - hip_yaw)
    sh, head = sh - _start(sh), head - _start(head)
    ms.update(
        shoulders_left=float(sh.max()),
        shoulders_right=float(sh.min()),
        head_left=float(head.max()),
        head_right=float(head.min()),
    )
    c["head_turns_both_ways"] = head.max() > 25 and head.min() < -25
    c["shoulders_follow"] = sh.max() > 10 and sh.min() < -10
    c["feet_stay"] = _feet_stay(m) and _in_place(m, 0.2)
    c["arms_down"] = max(m.wrist_above_shoulder(s).max() for s in ("left", "right")) < -0.25
    return c, ms


@rule("shrug")
def shrug(m: Measures, labels: dict):
    """Both shoulders rise towards the head (along the trunk, from the top of the spine) and drop
    again, count times, standing in place."""
    c, ms = {}, {}
    up = m.j[:, J("neck")] - m.j[:, J("spine3")]
    up /= np.linalg.norm(up, axis=-1, keepdims=True)
    rise = np.minimum(*(((m.j[:, SHOULDER[s]] - m.j[:, J("spine3")]) * up).sum(-1) for s in ("left", "right")))
    rise = rise - _start(rise)
    n_up = len(episodes(rise > 0.03, min_len=2, min_gap=3))
    ms.update(shrugs=n_up, rise=float(rise.max()))
    c["shoulders_up"] = n_up >= 1 and _count_ok(n_up, labels.get("count"))
    c["drop_again"] = _end(rise) < 0.015
    c["in_place"] = _in_place(m, 0.2) and _feet_stay(m)
    return c, ms


@rule("stand_up_from_kneeling")
def stand_up_from_kneeling(m: Measures, labels: dict):
    """Kneeling upright on both knees at the start, standing at the end."""
    c, ms = {}, {}
    k = max(2, round(0.3 * m.fps))
    knees = np.maximum(_y(m, KNEE["left"]), _y(m, KNEE["right"]))
    pel, head = _y(m, 0), _y(m, HEAD)
    ms.update(knees_start=float(knees[:k].max()), pelvis_start=float(pel[:k].mean()), pelvis_end=_end(pel))
    c["kneeling_first"] = knees[:k].max() < 0.12 and 0.35 < pel[:k].mean() < 0.75 and head[:k].min() > 0.9
    c["standing_end"] = _end(pel) > 0.8
    return c, ms
