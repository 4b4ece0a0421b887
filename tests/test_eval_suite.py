"""Our evaluator and the metric tables, end to end on a small corpus built by the real CLI."""

from __future__ import annotations

import json
import time

import numpy as np
import pytest

from motion_core.data.clips import load_clips
from motion_core.eval.__main__ import main as evaluate_main
from motion_core.eval.evaluator import CHECKPOINT, load_evaluator
from motion_core.eval.metrics import r_precision


@pytest.fixture(scope="module")
def evaluator():
    assert CHECKPOINT.is_file(), "the evaluator checkpoint ships in the repository"
    assert CHECKPOINT.stat().st_size < 20 * 2**20
    t0 = time.perf_counter()
    ev = load_evaluator()
    assert time.perf_counter() - t0 < 2.0
    return ev


def test_evaluator_matches_real_pairs_far_above_chance(evaluator, built):
    clips = load_clips(built, "test")[:128]
    zm = evaluator.embed_motions([c.features for c in clips])
    zt = evaluator.embed_texts([c.captions[0] for c in clips])
    assert zm.shape == (128, 512) and zt.shape == (128, 512)
    assert np.allclose(np.linalg.norm(zm, axis=1), 1, atol=1e-4)
    top, mm = r_precision(zt, zm, rng=np.random.default_rng(0))
    shuffled, mm_shuffled = r_precision(zt, zm[np.random.default_rng(1).permutation(128)], rng=np.random.default_rng(0))
    assert top[2] > 0.5 > shuffled[2]  # chance for top-3 in batches of 32: 0.09
    assert mm < mm_shuffled


@pytest.mark.long
def test_quick_evaluation_writes_both_tables(built, tmp_path, evaluator):
    t0 = time.time()
    evaluate_main(["--methods", "baseline", "--data", str(built), "--quick", "--out", str(tmp_path)])
    seconds = time.time() - t0
    res = json.loads((tmp_path / "metrics_procedural_quick.json").read_text())
    md = (tmp_path / "metrics_procedural_quick.md").read_text()
    rows = res["text_to_motion"]["rows"]
    assert set(rows) == {"Real", "baseline"}
    for row in rows.values():
        for key in ("top1", "top2", "top3", "mm_dist", "diversity"):
            mean, half = row[key]
            assert np.isfinite(mean) and half >= 0
        assert row["fid"] >= 0
    assert rows["Real"]["top3"][0] > 0.5
    assert rows["Real"]["verifier"] > 0.9  # the corpus's own clips pass its verifier
    # the real clips' FID against the reference set is sampling noise only; the baseline's
    # came within 0.001 of it on this quick sample once it followed its prompts, so the two
    # are not ordered here (the full tables order them)
    # the bound: the 2-token baseline that ignored its text scored 0.33 on the full table
    assert rows["Real"]["fid"] < 0.5 and rows["baseline"]["fid"] < 1.0
    ext = res["extended"]["rows"]
    assert set(ext) == {"Real", "baseline"} and ext["baseline"]["peak_jerk"] > 0
    assert "| Real |" in md and "| baseline |" in md and "Peak Jerk" in md
    assert seconds < 120, f"--quick took {seconds:.0f} s"


def test_verifier_and_timeline_tables_are_written_by_the_cli(built, tmp_path):
    """--verifier-only and --timelines print their JSON and write it to --out."""
    evaluate_main(["--methods", "kmm", "--data", str(built), "--verifier-only", "--n", "3", "--out", str(tmp_path)])
    ver = json.loads((tmp_path / "verifier.json").read_text())
    assert ver["n"] == 3 and ver["ground_truth"]["pass_rate"] >= 0 and "median_generate_s" in ver["kmm"]
    assert ver["seconds"] > 0
    # the tokeniser's reconstruction, KMM's ceiling, is scored next to the VAE's
    assert 0 < ver["rvq_reconstruction"]["mpjpe_mm"] < 300 and 0 <= ver["rvq_reconstruction"]["pass_rate"] <= 1
    evaluate_main(["--methods", "kmm", "--data", str(built), "--timelines", "--n", "2", "--out", str(tmp_path)])
    tl = json.loads((tmp_path / "timelines.json").read_text())
    assert tl["timelines"] <= 2 and tl["ground_truth"]["segments"] == tl["kmm"]["segments"] > 0
