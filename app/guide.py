"""Prompt guidance on the page: the "what the models know" list, the nearest known phrasings
of what the user types and the unfamiliar-prompt warning, worded from motion_core.corpus.prompt_guide."""

from __future__ import annotations

import html
import logging

from motion_core.corpus.prompt_guide import ActionKind, Guidance, action_kinds, get_phrasebook

log = logging.getLogger("motion_mamba_studio")


def kinds() -> list[ActionKind]:
    return action_kinds()


def guidance(text: str) -> Guidance | None:
    """None when the phrasebook cannot be used (guidance must never stop the page)."""
    try:
        return get_phrasebook().guide(text)
    except Exception:
        log.exception("prompt guidance failed")
        return None


def unfamiliar_note(row: int, g: Guidance) -> str:
    return (
        f"⚠️ **Segment {row}: the models were not trained on anything like “{html.escape(g.text)}”** "
        f"(closest known phrasing {g.best:.2f} similar; below {g.threshold:.2f} counts as unfamiliar): the "
        "motion will most likely not follow it. Describe a body movement, e.g. one from *What the models know*."
    )


def check(text: str):
    """check_prompt's reading, or None when it cannot be made (it must never stop the page)."""
    try:
        from motion_core.corpus.reader import check_prompt

        return check_prompt(text)
    except Exception:
        log.exception("prompt check failed")
        return None


def check_note(row: int, text: str) -> str:
    """The warning for segment ``row``: which parts the models do not know and the nearest known
    action ("" when the prompt is known)."""
    c = check(text)
    if c is None or not c.warn:
        return ""
    msgs = "; ".join(html.escape(m) for m in c.messages)
    known = [cl for cl in c.reading.clauses if cl.known]
    tail = " The known part still generates." if known and c.unknown_parts else ""
    return f"⚠️ **Segment {row}: {msgs}.**{tail}"


def guide_markdown(row: int, text: str) -> str:
    """Under the timeline while the user types in segment ``row`` (1-based)."""
    if not (text or "").strip():
        return ""
    g = guidance(text)
    if g is None:
        return ""
    near = "; ".join(f"“{html.escape(m.caption)}” ({m.similarity:.2f})" for m in g.nearest)
    note = check_note(row, text)
    lines = [note] if note else []
    lines.append(f"Segment {row}, nearest known phrasings: {near}")
    return "\n\n".join(lines)


def generation_notes(texts: list[str]) -> str:
    """After a generation: a warning per unfamiliar segment ("" when every text is familiar)."""
    notes = []
    for i, t in enumerate(texts, 1):
        note = check_note(i, t)
        if note:
            notes.append(note)
    return "\n\n".join(notes)
