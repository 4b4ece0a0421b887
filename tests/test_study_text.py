"""The study page's wording: counts read right, a returning participant is told what resumes."""

from __future__ import annotations

import motion_core
from app.study_config import SAMPLE_CONFIG, load_config
from app.study_ui import results_markdown, welcome_back


def test_counts_read_right():
    base = {"answers": {}, "watched_both": 0, "median_decision_seconds": None, "pairs": [], "ranking": [],
            "criteria": []}  # fmt: skip
    assert "**1 vote** from 1 participant;" in results_markdown({**base, "votes": 1, "participants": 1})
    assert "**3 votes** from 2 participants;" in results_markdown({**base, "votes": 3, "participants": 2})


def test_a_returning_participant_is_told_the_open_trial_resumes():
    assert welcome_back(None, 6) == ""
    note = welcome_back({"study": "s", "votes": 2, "open": "tok"}, 6)
    assert "answered 2 of 6" in note and "open trial (trial 3) resumes" in note
    assert "all 6 trials" in welcome_back({"study": "s", "votes": 6, "open": None}, 6)


def test_the_sample_study_compares_every_method_kmm_included():
    cfg = load_config(SAMPLE_CONFIG)
    assert "kmm" in cfg.methods and set(cfg.methods) == {m["name"] for m in motion_core.methods()}
