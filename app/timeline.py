"""The timeline composer's state, as plain functions (no Gradio): rows of (text, seconds).

The UI shows a fixed set of MAX_SEGMENTS rows and hides the unused ones; these functions
edit the list of segments and convert it to and from FlowMDM's composition JSON
(``{"text": [...], "lengths": [frames...]}``; we also accept ``"seconds"``, and a list of
``{"text": ..., "seconds": ...}`` segments).
"""

from __future__ import annotations

import html
import json
import re
from dataclasses import dataclass

from motion_core.inference.base import (
    FPS,
    MAX_SEGMENTS,
    MAX_TOTAL_SECONDS,
    MIN_SECONDS,
    InputError,
)
from motion_core.inference.generation import validate

Segment = tuple[str, float]

DEFAULT_SECONDS = 3.0
EXAMPLES: dict[str, list[Segment]] = {
    "Single prompt": [("a person walks forward", 4.0)],
    "Left / right": [("a person waves with the left hand", 3.0), ("a person waves with the right hand", 3.0)],
    "4-segment story": [
        ("a man walks forward", 3.0),
        ("the man jumps up twice", 2.5),
        ("a person claps the hands three times", 3.0),
        ("a person sits down", 3.0),
    ],
}
COLOURS = ["#4e79a7", "#f28e2b", "#59a14f", "#e15759", "#76b7b2", "#edc948", "#b07aa1", "#ff9da7", "#9c755f", "#bab0ac"]


def from_rows(n: int, texts: list[str | None], seconds: list[float | None]) -> list[Segment | tuple[str, None]]:
    """The first ``n`` rows as segments; a blank seconds box stays None (not a duration of
    0 s): ``generate`` then takes the length estimator's duration for that text."""
    return [((texts[i] or ""), float(seconds[i]) if seconds[i] is not None else None) for i in range(n)]


@dataclass(frozen=True)
class RowProblem:
    """What is wrong with a timeline, for one message: which row (1-based, None for the
    whole timeline) and which field ("text", "seconds" or "timeline")."""

    row: int | None
    field: str
    message: str

    @property
    def title(self) -> str:
        if self.row is None:
            return "Timeline too long" if "lasts" in self.message else "Timeline"
        return f"Segment {self.row}: {self.field}"


def check_rows(segments: list[tuple[str, float | None]], method: str) -> RowProblem | None:
    """The first problem of the timeline, naming its row and field, or None.

    Each row is put to the core's own ``validate`` on its own, first its text with a valid
    duration, then its duration with a valid text, so the limits live in one place (the core)
    and the message can still say which field to change."""
    for i, (text, seconds) in enumerate(segments, 1):
        try:
            validate([(text, MIN_SECONDS)], method)
        except InputError as e:
            return RowProblem(i, "text", _strip_segment(str(e)))
        if seconds is None:  # a blank box: the length estimator picks the seconds from the text
            continue
        try:
            validate([("a person walks", seconds)], method)
        except InputError as e:
            return RowProblem(i, "seconds", _strip_segment(str(e)))
    try:
        validate([(t, s) for t, s in segments], method)  # the whole: count and total length
    except InputError as e:
        return RowProblem(None, "timeline", str(e))
    return None


def _strip_segment(message: str) -> str:
    # the core says "segment 3: ..."; the title already names the row
    head, sep, rest = message.partition(": ")
    return rest if sep and head.startswith("segment ") else message


def edit(segments: list[Segment], op: str, index: int = -1) -> list[Segment]:
    """add (a row after the last), remove / up / down (the row at ``index``)."""
    segs = list(segments)
    if op == "add":
        if len(segs) >= MAX_SEGMENTS:
            raise InputError(f"a timeline has at most {MAX_SEGMENTS} segments")
        segs.append(("", DEFAULT_SECONDS))
    elif op == "remove":
        if len(segs) <= 1:
            raise InputError("a timeline needs at least one segment")
        segs.pop(index)
    elif op == "up" and index > 0:
        segs[index - 1], segs[index] = segs[index], segs[index - 1]
    elif op == "down" and index < len(segs) - 1:
        segs[index + 1], segs[index] = segs[index], segs[index + 1]
    return segs


def strip_html(segments: list[Segment]) -> str:
    """A bar with one block per segment, its width proportional to the duration."""
    total = sum(max(s or 0.0, 0.0) for _, s in segments)
    if total <= 0:
        return "<div class='mms-strip mms-strip-empty'>empty timeline</div>"
    blocks = []
    for i, (text, sec) in enumerate(segments):
        sec = sec or 0.0
        w = 100.0 * max(sec, 0.0) / total
        label = html.escape(text.strip() or "(no text)")
        blocks.append(
            f"<div class='mms-block' style='width:{w:.3f}%;background:{COLOURS[i % len(COLOURS)]}' "
            f"title='{i + 1}: {label} ({sec:g} s)'><span>{i + 1}. {label}</span><b>{sec:g} s</b></div>"
        )
    bar = f"<div class='mms-strip' data-total='{total:g}'>{''.join(blocks)}</div>"
    over = total > MAX_TOTAL_SECONDS
    note = f" (at most {MAX_TOTAL_SECONDS:g} s: shorten a segment)" if over else f" of at most {MAX_TOTAL_SECONDS:g} s"
    return bar + f"<div class='mms-total{' mms-over' if over else ''}'>total {total:g} s{note}</div>"


def download_stem(first_text: str, method: str, seed: int) -> str:
    """A file name stem for a motion's downloads: its first prompt, the method and the seed,
    e.g. "a-person-walks-forward_kmm_seed0" (ASCII letters and digits only, at most 48 of the
    prompt's characters)."""
    words = re.findall(r"[a-z0-9]+", first_text.lower())
    slug = "-".join(words)[:48].rstrip("-") or "motion"
    return f"{slug}_{re.sub(r'[^a-z0-9]+', '-', method.lower())}_seed{int(seed)}"


def to_json(segments: list[Segment]) -> str:
    """FlowMDM's composition format (lengths in frames at 20 fps), plus seconds for readers."""
    texts = [t for t, _ in segments]
    seconds = [s for _, s in segments]
    return json.dumps({"text": texts, "lengths": [round(s * FPS) for s in seconds], "seconds": seconds})


def from_json(text: str | list | dict) -> list[tuple[str, float | None]]:
    """Parse a timeline; raises InputError with what is wrong. Two shapes, as JSON text or
    already parsed: a list of segments ``[{"text": "a person walks", "seconds": 3}, ...]``,
    or FlowMDM's composition ``{"text": [...], "lengths": [frames at 20 fps]}`` (or
    ``"seconds": [...]`` instead of lengths). A null duration stays None: the length
    estimator picks that segment's seconds from its text, as a blank box does."""
    if isinstance(text, str):
        try:
            doc = json.loads(text)
        except json.JSONDecodeError as e:
            raise InputError(f"the timeline JSON does not parse: {e.msg} (line {e.lineno}, column {e.colno})") from None
    else:
        doc = text
    if isinstance(doc, list):
        return _from_segment_list(doc)
    if not isinstance(doc, dict) or not isinstance(doc.get("text"), list):
        raise InputError(
            'the timeline JSON needs a list of {"text": ..., "seconds": ...} segments, or a "text" list with a '
            '"lengths" (frames) or "seconds" list'
        )
    texts = doc["text"]
    if isinstance(doc.get("seconds"), list):
        secs = doc["seconds"]
    elif isinstance(doc.get("lengths"), list):
        secs = [n / FPS if isinstance(n, int | float) and not isinstance(n, bool) else n for n in doc["lengths"]]
    else:
        raise InputError('the timeline JSON needs a "lengths" (frames at 20 fps) or "seconds" list')
    if len(secs) != len(texts):
        raise InputError(f"the timeline JSON has {len(texts)} texts but {len(secs)} durations")
    return [_segment(i, t, s) for i, (t, s) in enumerate(zip(texts, secs, strict=True), 1)]


def _from_segment_list(doc: list) -> list[tuple[str, float | None]]:
    """[{"text": ..., "seconds": ...}, ...]: "seconds" may be null or left out (estimated)."""
    if not doc:
        raise InputError('the timeline JSON needs at least one segment: [{"text": ..., "seconds": ...}, ...]')
    out = []
    for i, seg in enumerate(doc, 1):
        if not isinstance(seg, dict) or "text" not in seg:
            raise InputError(f'segment {i} of the timeline JSON needs to be an object {{"text": ..., "seconds": ...}}')
        if unknown := sorted(set(seg) - {"text", "seconds"}):
            keys = ", ".join(repr(k) for k in unknown)
            raise InputError(f'segment {i} of the timeline JSON has unknown keys {keys}: give "text" and "seconds"')
        out.append(_segment(i, seg["text"], seg.get("seconds")))
    return out


def _segment(i: int, t: object, s: object) -> tuple[str, float | None]:
    number = isinstance(s, int | float) and not isinstance(s, bool)
    if not isinstance(t, str) or not (number or s is None):
        raise InputError(f"segment {i} of the timeline JSON needs a text and a number (or null: estimated)")
    return t, float(s) if s is not None else None  # type: ignore[arg-type]
