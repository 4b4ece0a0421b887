"""yardstick/relabel.py: the hand labels' unknown names mapped onto the grown corpus's kinds."""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path

from motion_core.corpus.kinds import all_kinds

YARD = Path(__file__).resolve().parents[1] / "yardstick"


def _relabel():
    spec = importlib.util.spec_from_file_location("relabel", YARD / "relabel.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def _rows() -> list[dict]:
    mod = _relabel()
    return [json.loads(line) for name in mod.SAMPLES for line in (YARD / name).read_text().splitlines() if line]


def test_every_rule_names_a_corpus_kind_and_fits_some_labelled_clause():
    mod = _relabel()
    rules = mod.read_map(YARD / "relabel_grown.txt")
    kinds = set(all_kinds())
    clauses = [c for r in _rows() for c in r["clauses"] if c["kind"] == "unknown"]
    for name, words, kind in rules:
        assert kind == "unknown" or kind in kinds, (name, kind)
        fits = [c for c in clauses if c["unknown"] == name and (words is None or words in c["words"].lower())]
        assert fits, f"no labelled clause fits {name!r} | {words!r}"


def test_relabelling_only_maps_unknown_clauses_and_status_follows():
    mod = _relabel()
    rules = mod.read_map(YARD / "relabel_grown.txt")
    for row in _rows():
        new = mod.relabel(row, rules)
        assert mod.relabel(new, rules) == new
        for old, c in zip(row["clauses"], new["clauses"], strict=True):
            assert c["words"] == old["words"] and c["with_previous"] == old["with_previous"]
            if old["kind"] != "unknown":
                assert c == old
            assert (c["kind"] == "unknown") == (c["unknown"] is not None)
        if row["status"] == "unusable":
            assert new == row
        else:
            unknown = [c["kind"] == "unknown" for c in new["clauses"]]
            assert new["status"] == ("out" if all(unknown) else "partial" if any(unknown) else "in")


def test_a_word_rule_comes_before_its_names_catch_all():
    """'swim | breast -> unknown' must be read before 'swim -> swim', or it never applies."""
    mod = _relabel()
    rules = mod.read_map(YARD / "relabel_grown.txt")
    clause = {"kind": "unknown", "unknown": "swim", "words": "swims in breaststroke style", "with_previous": False}
    assert mod.relabel_clause(clause, rules)["kind"] == "unknown"
    assert mod.relabel_clause({**clause, "words": "is swimming"}, rules)["kind"] == "swim"
