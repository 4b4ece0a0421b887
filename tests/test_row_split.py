"""A row's sentence as a timeline (app/split.py), without a server: the one-line reading, the
rows a split makes, and the timeline's limits."""

from __future__ import annotations

import pytest

import motion_core
from app.split import NONE, offer, reading_line, split_row
from motion_core import InputError
from motion_core.inference.base import MAX_SEGMENTS

SENTENCE = "a person walks forward, then sits down and picks up a box"


def test_a_sentence_of_several_actions_is_offered_the_readers_plan():
    plan = motion_core.read_prompt(SENTENCE).plan()
    got = offer([("a person claps twice", 2.0), (SENTENCE, 3.0)], 1)
    assert got.n == len(plan) == 3 and got.fits
    assert got.button == "Split into 3 segments"
    # the plan's own segments: the user's words cut to the clause, the estimator's seconds
    assert got.segments == tuple((s.text, s.seconds) for s in plan)
    assert [t for t, _ in got.segments] == ["a person walks forward", "a person sits down", "a person picks up a box"]
    assert got.line == "Read as: walk (forward) → sit down → unknown 'picks up a box'."


def test_one_action_or_no_text_is_offered_nothing():
    for text in ("a person walks forward", "a person waves with the right hand", "", "   "):
        assert offer([(text, 3.0)], 0) == NONE and not NONE.shown
    assert offer([("a person walks", 3.0)], 4) == NONE  # no such row


def test_the_reading_line_names_counts_sides_and_together_clauses():
    line = reading_line(motion_core.read_prompt("a man walks forward then jumps twice then claps three times"))
    assert line == "Read as: walk (forward) → jump up (twice) → clap (3 times)"
    # clauses that run together share a step; a detail the title says already is not repeated
    line = reading_line(motion_core.read_prompt("a person walks backwards while waving, then turns around"))
    assert "walk backward + wave" in line or "wave + walk backward" in line, line
    assert "(backward)" not in line and "180°" not in line, line


def test_a_split_replaces_the_row_in_place():
    segs = [("a person claps twice", 2.0), (SENTENCE, 3.0), ("a person bows", 4.0)]
    new = split_row(segs, 1)
    assert new[0] == segs[0] and new[-1] == segs[-1] and len(new) == 5
    assert [t for t, _ in new[1:4]] == ["a person walks forward", "a person sits down", "a person picks up a box"]
    with pytest.raises(InputError, match="reads as one action"):
        split_row(segs, 0)
    with pytest.raises(InputError, match="row 1 is empty"):
        split_row([("  ", 3.0)], 0)


def test_a_split_over_the_timelines_rows_is_refused_and_says_so():
    others = [("a person claps twice", 1.0)] * (MAX_SEGMENTS - 2)  # 8 rows + the sentence's 3 = 11
    segs = [*others, (SENTENCE, 3.0)]
    got = offer(segs, len(segs) - 1)
    assert got.n == 3 and not got.fits
    assert f"would make {MAX_SEGMENTS + 1} rows, more than the {MAX_SEGMENTS} a timeline holds" in got.line
    with pytest.raises(InputError, match=f"more than the {MAX_SEGMENTS}"):
        split_row(segs, len(segs) - 1)
    # one row fewer and it fits
    assert offer(segs[1:], len(segs) - 2).fits


def test_a_split_over_the_timelines_seconds_says_so():
    segs = [(SENTENCE, 3.0), *[("a person claps twice", 9.0)] * 6]  # 54 s + the split's 12.6 s
    got = offer(segs, 0)
    assert got.fits and "over the 60 s a timeline holds" in got.line, got.line
    assert "over the" not in offer([(SENTENCE, 3.0)], 0).line
