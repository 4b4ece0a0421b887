"""The length estimator: a segment left without seconds gets a duration from its
text, in the demo's 1-10 s range, longer for what takes longer."""

from __future__ import annotations

import json
from pathlib import Path

from motion_core.inference.length import estimate_seconds
from motion_core.models.length import MAX_SECONDS, MIN_SECONDS

RESULTS = Path(__file__).resolve().parents[1] / "results" / "length_estimator.json"


def test_the_shipped_estimator_gives_plausible_durations() -> None:
    texts = ["a person claps once", "a person walks forward, turns around and walks back slowly", "a person waves"]
    s = estimate_seconds(texts)
    assert all(MIN_SECONDS <= x <= MAX_SECONDS for x in s)
    assert s == estimate_seconds(texts)  # deterministic
    assert s[1] > s[0] + 1.0, s  # a walk there and back takes longer than one clap


def test_the_reported_error_beats_a_constant_guess() -> None:
    r = json.loads(RESULTS.read_text())
    assert r["test"]["mae_s"] < 0.6 * r["test_constant_median"]["mae_s"]
    assert r["captions"]["test"] > 1000
