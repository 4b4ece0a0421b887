"""A row's sentence as a timeline: what the prompt reader understood of it, in one line, and
the rows that splitting it makes (plain functions, no Gradio).

A row whose text reads as several actions in sequence (``Reading.plan()`` has more than one
segment) is offered a split: the row is replaced, in place, by one row per planned segment,
each the user's own words for its clauses and the length estimator's seconds. The page offers
it only for text the user typed (the row's input event), never for rows an example, an import
or a shared link filled in, and never splits anything by itself.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass
from functools import cache

from motion_core import InputError
from motion_core.corpus.reader import Clause, Reading
from motion_core.inference.base import MAX_SEGMENTS, MAX_TOTAL_SECONDS

from .timeline import Segment

log = logging.getLogger("motion_mamba_studio")

# how a clause's direction words read for people ("cw" is the reader's short form)
_DIRECTIONS = {"cw": "clockwise", "ccw": "counter-clockwise"}


@dataclass(frozen=True)
class SplitOffer:
    """What the page shows under a row: the one-line reading and, when the split fits the
    timeline, a button "Split into N segments"."""

    line: str  # "" when the row reads as one action (or none): nothing is shown
    segments: tuple[Segment, ...]  # the rows a split makes, in order
    fits: bool  # the split fits the timeline's MAX_SEGMENTS rows

    @property
    def n(self) -> int:
        return len(self.segments)

    @property
    def shown(self) -> bool:
        return bool(self.line)

    @property
    def button(self) -> str:
        return f"Split into {self.n} segments"


NONE = SplitOffer("", (), False)


@cache
def _titles() -> dict[str, str]:
    """Each corpus kind's title for people ("jump_up" -> "jump up"), from the prompt guide."""
    from .guide import kinds

    try:
        return {k.kind: k.title for k in kinds()}
    except Exception:
        log.exception("the kinds of action cannot be read")
        return {}


def kind_title(kind: str) -> str:
    return _titles().get(kind) or kind.removeprefix("mocap:").replace("_", " ").replace("-", " ")


def clause_words(clause: Clause, unknown_words: str | None = None) -> str:
    """One clause as the reader understood it: "wave (right, 3 times)", "unknown 'picks up a box'"."""
    if not clause.known:
        return f"unknown '{unknown_words or clause.unknown or clause.words}'"
    title = kind_title(clause.kind)
    details = []
    direction = _DIRECTIONS.get(clause.direction or "", clause.direction)
    if direction and direction not in title.split():  # not "walk backward (backward)"
        details.append(direction)
    if clause.side:
        details.append(clause.side)
    if clause.angle and "around" not in title:  # a turn around is 180°
        details.append(f"{clause.angle}°")
    if clause.count and clause.count > 1:
        details.append("twice" if clause.count == 2 else f"{clause.count} times")
    return title + (f" ({', '.join(details)})" if details else "")


def reading_line(reading: Reading) -> str:
    """The reading in one line: "Read as: walk → sit down → unknown 'picks up a box'". Clauses
    that run together share a step ("walk + wave")."""
    unknown = iter(reading.unknown_parts)  # one per unknown clause, in the clauses' order
    words = {id(c): (next(unknown).words if not c.known else None) for c in reading.clauses}
    steps = [" + ".join(clause_words(c, words[id(c)]) for c in group) for group in reading.groups()]
    return "Read as: " + " → ".join(steps)


def offer(segments: list[tuple[str, float | None]], index: int) -> SplitOffer:
    """The offer for row ``index`` of the timeline ``segments``: NONE unless its text reads
    as more than one action in sequence."""
    if not 0 <= index < len(segments):
        return NONE
    text = segments[index][0]
    if not (text or "").strip():
        return NONE
    import motion_core

    reading = motion_core.read_prompt(text)
    plan = reading.plan()
    if len(plan) < 2:
        return NONE
    split = tuple((s.text, float(s.seconds)) for s in plan)
    line = f"{reading_line(reading)}."
    rows = len(segments) - 1 + len(split)
    fits = rows <= MAX_SEGMENTS
    if not fits:
        line += (
            f" Splitting it would make {rows} rows, more than the {MAX_SEGMENTS} a timeline holds: "
            "remove a row or shorten the sentence to split it here."
        )
    else:
        others = sum(s or 0.0 for i, (_, s) in enumerate(segments) if i != index)
        total = others + sum(s for _, s in split)
        if total > MAX_TOTAL_SECONDS:
            line += (
                f" Split, the timeline would last {total:g} s, over the {MAX_TOTAL_SECONDS:g} s a timeline holds: "
                "shorten some of the rows after splitting."
            )
    return SplitOffer(line, split, fits)


def split_row(segments: list[tuple[str, float | None]], index: int) -> list[tuple[str, float | None]]:
    """The timeline with row ``index`` replaced by its planned segments, in order. Raises
    InputError when the row does not read as several actions or the split would not fit."""
    if not 0 <= index < len(segments):
        raise InputError(f"there is no row {index + 1} to split")
    if not (segments[index][0] or "").strip():
        raise InputError(f"row {index + 1} is empty: there is nothing to split")
    got = offer(segments, index)
    if got.n < 2:
        raise InputError(f"row {index + 1} reads as one action: there is nothing to split")
    if not got.fits:
        raise InputError(
            f"splitting row {index + 1} into {got.n} segments would make {len(segments) - 1 + got.n} rows, "
            f"more than the {MAX_SEGMENTS} a timeline holds"
        )
    return [*segments[:index], *got.segments, *segments[index + 1 :]]
