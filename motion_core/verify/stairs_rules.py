"""Verifier rules of the stairs kinds (``motion_core/corpus/kinds/stairs.py``).

They read the ground the feet stand on (``motion_core.body.terrain``): the raised plants, a
foot standing flat and bearing weight on a level a step above (or below) the other foot.
A level is a height at least ``TerrainConfig.rise`` (10 cm) above the floor that a raised
plant stands on; levels closer than ``level_tol`` (4 cm) are one.

* walk_upstairs: at least two levels (the count, where labelled, is the number of levels);
  each foot's plants go only up; both feet start on the floor and end on the top level; the
  pelvis rises by about the top's height; the body moves forward (within 35 degrees of its
  facing); no flight.
* walk_downstairs: the same, down: both feet start on the top level and end on the floor.
* step_up_onto: exactly one level, at least 15 cm high; both feet start on the floor and end
  on it, the labelled foot first; the pelvis rises by about its height; one step: the body
  travels less than 0.9 m; no flight.
"""

from __future__ import annotations

import numpy as np

from ..body.terrain import TerrainConfig, _raised, foot_plants
from .kind_rules import _disp_angle_ok, _end, _start, rule
from .rules import Measures

CFG = TerrainConfig()


def _ground(m: Measures) -> tuple[list, list[float]]:
    """The motion's firm plants (flat, bearing weight; by start frame), each with the height of
    the level it stands on (0 for the floor), and the levels' heights, low to high."""
    plants = foot_plants(m.j, cfg=CFG)
    raised = {(p.foot, p.start) for p in _raised(plants, CFG)}
    firm = sorted((p for p in plants if p.flat and p.bears_weight), key=lambda p: p.start)
    levels: list[float] = []
    for h in sorted(p.height for p in firm if (p.foot, p.start) in raised):
        if not levels or h - levels[-1] > CFG.level_tol:
            levels.append(h)
    on = [(p, p.height if (p.foot, p.start) in raised else 0.0) for p in firm]
    return on, levels


def _feet_at(on: list, first: bool) -> dict[int, float]:
    """Each foot's level at its first (or last) firm plant."""
    out: dict[int, float] = {}
    for p, h in on if first else reversed(on):
        out.setdefault(p.foot, h)
    return out


def _monotone(on: list, up: bool) -> bool:
    """Each foot's plants never go the wrong way by more than a level's tolerance."""
    for f in (0, 1):
        hs = np.array([h for p, h in on if p.foot == f])
        d = np.diff(hs) * (1 if up else -1)
        if len(d) and d.min() < -CFG.level_tol:
            return False
    return True


def _close(h: float, level: float) -> bool:
    return abs(h - level) <= CFG.level_tol


def _climb_measures(m: Measures, levels: list, top: float) -> tuple[float, dict]:
    """The pelvis's rise over the clip, and the measures both stairs rules report."""
    rise = _end(m.j[:, 0, 1]) - _start(m.j[:, 0, 1])
    return rise, {
        "levels": len(levels),
        "top_m": float(top),
        "pelvis_rise_m": float(rise),
        "displacement_m": float(np.linalg.norm(m.displacement())),
        "flights": len(m.flights()),
    }


def _stairs(m: Measures, labels: dict, up: bool):
    on, levels = _ground(m)
    count = labels.get("count")
    top = levels[-1] if levels else 0.0
    start, end = _feet_at(on, True), _feet_at(on, False)
    lo, hi = (start, end) if up else (end, start)
    rise, ms = _climb_measures(m, levels, top)
    c = {
        "on_steps": len(levels) >= 2 and (count is None or len(levels) == count),
        "one_way": _monotone(on, up),
        "floor_end": len(lo) == 2 and all(h == 0.0 for h in lo.values()),
        "top_end": len(hi) == 2 and all(_close(h, top) for h in hi.values()) and top > 0,
        "pelvis_follows": abs(rise * (1 if up else -1) - top) < 0.15 and top > 0,
        "forward": ms["displacement_m"] > 0.4 and _disp_angle_ok(m, 0.0, 35.0),
        "no_flight": ms["flights"] == 0,
    }
    return c, ms


@rule("walk_upstairs")
def walk_upstairs(m: Measures, labels: dict):
    return _stairs(m, labels, up=True)


@rule("walk_downstairs")
def walk_downstairs(m: Measures, labels: dict):
    return _stairs(m, labels, up=False)


@rule("step_up_onto")
def step_up_onto(m: Measures, labels: dict):
    on, levels = _ground(m)
    top = levels[-1] if levels else 0.0
    start, end = _feet_at(on, True), _feet_at(on, False)
    first_up = next((p.foot for p, h in on if h > 0), None)
    rise, ms = _climb_measures(m, levels, top)
    want = {"left": 0, "right": 1}.get(labels.get("side"))
    c = {
        "one_level": len(levels) == 1 and top >= 0.15,
        "floor_start": len(start) == 2 and all(h == 0.0 for h in start.values()),
        "up_end": len(end) == 2 and all(_close(h, top) for h in end.values()) and top > 0,
        "this_foot_first": first_up is not None and (want is None or first_up == want),
        "pelvis_follows": abs(rise - top) < 0.12 and top > 0,
        "one_step": ms["displacement_m"] < 0.9,
        "no_flight": ms["flights"] == 0,
    }
    return c, ms
