"""A link that reproduces a result: the timeline, method, seed and sampling options in the
page's query string. Generation is deterministic for these inputs, so opening the link
regenerates the same motion, bit for bit."""

from __future__ import annotations

import json
from dataclasses import dataclass
from urllib.parse import urlencode

from motion_core import InputError

from .timeline import Segment


@dataclass(frozen=True)
class Shared:
    segments: list[Segment]
    method: str
    seed: int
    guidance: float | None
    steps: int | None
    sampler: str = "quality"  # "quality" or "fast" (a distilled student; see registry.samplers)


def to_query(s: Shared) -> str:
    """?timeline=[["a person walks", 3.0], ...]&method=kmm&seed=0&guidance=1&steps=4
    &sampler=quality ("fast": a distilled student's motion)"""
    q = {
        "timeline": json.dumps([[t, sec] for t, sec in s.segments], separators=(",", ":")),
        "method": s.method,
        "seed": str(int(s.seed)),
    }
    if s.guidance is not None:
        q["guidance"] = f"{float(s.guidance):g}"
    if s.steps is not None:
        q["steps"] = str(int(s.steps))
    # always named: a method whose default is its fast sampler would otherwise reopen a
    # quality motion with the fast one
    q["sampler"] = str(s.sampler)
    return urlencode(q)


def from_query(params: dict[str, str]) -> Shared | None:
    """The shared result in a page's query parameters; None when the page has none. Raises
    InputError when the link is damaged (the timeline itself is checked by the generation)."""
    if "timeline" not in params:
        return None
    try:
        rows = json.loads(params["timeline"])
        segments = [(str(t), float(sec)) for t, sec in rows]
        seed = int(params.get("seed", "0"))
        guidance = float(params["guidance"]) if params.get("guidance") else None
        steps = int(params["steps"]) if params.get("steps") else None
    except (ValueError, TypeError):
        raise InputError("this link's timeline or options cannot be read: it may have been cut short") from None
    # links made before samplers existed name none: they were all "quality"
    return Shared(segments, params.get("method", ""), seed, guidance, steps, params.get("sampler") or "quality")
