"""The reader's figures (``motion_core.eval.reader``): where labelled words lie, and the rows
figure beside the strict segments-and-kinds one."""

from __future__ import annotations

import motion_core
from motion_core.eval.reader import _rows_in_place, _spans, evaluate


def _clause(kind: str, words: str, with_previous: bool = False) -> dict:
    return {"kind": kind, "words": words, "with_previous": with_previous}


def test_labelled_words_are_found_as_whole_words_in_any_order():
    # "turns" is not the inside of "returns"; clauses in the order of the actions, not the text's
    assert _spans("he returns and turns", [_clause("turn", "turns"), _clause("walk", "returns")]) == [(15, 20), (3, 10)]
    # the same words twice: each clause its own occurrence
    assert _spans("walks, walks", [_clause("walk", "walks"), _clause("walk", "walks")]) == [(0, 5), (7, 12)]
    assert _spans("a person waves", [_clause("wave", "claps")]) == [None]


def test_the_rows_figure_asks_for_the_words_in_their_own_row():
    text = "a person walks forward, then sits down and waves"
    groups = motion_core.read_prompt(text).groups()
    right = [_clause("walk", "walks forward"), _clause("sit_down", "sits down"), _clause("wave", "waves")]
    assert _rows_in_place(text, right, groups)
    # the same three kinds with the words of two clauses swapped between rows: not in place
    swapped = [_clause("walk", "walks forward"), _clause("sit_down", "waves"), _clause("wave", "sits down")]
    assert not _rows_in_place(text, swapped, groups)
    # two labelled segments where the reader has three
    merged = [_clause("walk", "walks forward"), _clause("sit_down", "sits down"), _clause("wave", "waves", True)]
    assert not _rows_in_place(text, merged, groups)


def test_evaluate_reports_the_rows_beside_the_kinds():
    text = "a person walks forward, then sits down and waves"
    good = {"id": "a", "text": text, "status": "in", "multi": True}
    good["clauses"] = [_clause("walk", "walks forward"), _clause("sit_down", "sits down"), _clause("wave", "waves")]
    # the rows right, one kind labelled otherwise: counted in the rows figure, not the strict one
    other = {**good, "id": "b", "clauses": [*good["clauses"][:2], _clause("unknown", "waves")], "status": "partial"}
    out = evaluate([good, other])["planner_on_multi"]
    assert out["captions"] == 2 and out["segments_in_place_right"] == 1.0 and out["segments_and_kinds_right"] == 0.5
