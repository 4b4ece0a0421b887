"""`python -m motion_core.eval pair-speed` (eval/pair_speed.py): two methods' generate() timed in
alternating pairs, the ratio taken within each pair."""

from __future__ import annotations

import json
import random
import time

import pytest
import torch


def test_a_pair_series_reads_the_ratio_of_the_two_calls_within_each_pair():
    from motion_core.eval import pair_speed

    calls = []

    def sleeper(name, seconds):
        def run(request):
            calls.append((name, request))
            time.sleep(seconds)

        return run

    s = pair_speed.pair_series(sleeper("a", 0.01), sleeper("b", 0.03), "req", 6, random.Random(0), warmup=1)
    assert len(calls) == 2 * (1 + 6) and {r for _, r in calls} == {"req"}
    # a sleep overshoots by a few ms on a loaded machine: bounds, not the exact third
    assert s["a_faster_share"] >= 5 / 6
    lo, mid, hi = s["ratio_quartiles"]
    assert lo <= mid <= hi and 0.2 < mid < 0.6
    # a random order per pair: B ran first in some pairs and second in others
    firsts = [calls[i][0] for i in range(2, len(calls), 2)]
    assert set(firsts) == {"a", "b"}


def test_the_cli_times_two_shipped_methods_and_writes_its_json(tmp_path):
    from motion_core.eval import pair_speed

    threads = torch.get_num_threads()
    out = tmp_path / "pairs.json"
    pair_speed.main(["--a", "kmm", "--b", "baseline:quality", "--pairs", "2", "--steps", "2", "--out", str(out)])
    got = json.loads(out.read_text())
    assert got["a"] == "kmm" and got["b"] == "baseline" and got["pairs"] == 2 and got["steps"] == 2
    for series in ("frames_196", "timeline_10s"):
        assert all(x > 0 for x in got[series]["ratio_quartiles"])
        assert 0.0 <= got[series]["a_faster_share"] <= 1.0
    assert torch.get_num_threads() == threads
    with pytest.raises(SystemExit, match="at least 2"):
        pair_speed.main(["--a", "kmm", "--b", "baseline", "--pairs", "1"])
    with pytest.raises(SystemExit, match="at least 1"):
        pair_speed.main(["--a", "kmm", "--b", "baseline", "--steps", "0"])
