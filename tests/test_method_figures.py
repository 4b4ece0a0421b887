"""The page's method figures come from the shipped results, and follow them when they change."""

from __future__ import annotations

import json
import shutil

from conftest import REPO

import motion_core
from app.method_figures import best_method, choice_label, default_rows, figures_note, load_figures, summaries

NAMES = [m["name"] for m in motion_core.methods()]


def test_shipped_results_pick_the_best_pooled_pass_rate_and_label_kmm_with_its_own():
    rows = default_rows(motion_core.methods())  # each method's default sampler's rows, as the page reads
    figures = load_figures(NAMES, rows=rows)
    proc = json.loads((REPO / "results/verifier.json").read_text())
    real = json.loads((REPO / "results/verifier_real.json").read_text())
    pooled = {m: proc[rows[m]]["pass_rate"] * proc["n"] + real[rows[m]]["pass_rate"] * real["n"] for m in NAMES}
    assert best_method(NAMES, figures) == max(NAMES, key=pooled.__getitem__)  # FTMoMamba since 2026-11-27
    kmm = figures["kmm"]
    expected = (proc["kmm"]["pass_rate"] * proc["n"] + real["kmm"]["pass_rate"] * real["n"]) / (proc["n"] + real["n"])
    assert kmm.prompts == proc["n"] + real["n"] and abs(kmm.pass_rate - expected) < 1e-12
    bench = json.loads((REPO / "results/bench.json").read_text())["generate"]["kmm"]["timeline_10s_median_ms"]
    assert abs(kmm.timeline_10s_s - bench / 1000) < 1e-12
    label = choice_label("KMM", kmm, 35)
    # the test prompts are all about the corpus's kinds of action: the label says so
    assert (
        label.startswith("KMM · follows ")
        and f"{100 * expected:.0f}% of prompts about the 35 actions it knows" in label
    )
    note = figures_note(kmm, 35)
    real_rate = real["kmm"]["pass_rate"]
    assert f"{100 * real_rate:.0f}% of {real['n']} captions of real motion-capture clips" in note, note


def test_a_method_whose_default_is_its_student_shows_the_students_figures():
    """Motion Mamba (2026-11-27) and FTMoMamba (2026-11-27) sample with their students by
    default: their labels and cards must say what a request gets, the ``NAME:fast`` rows, not
    their DDIM samplers'."""
    infos = motion_core.methods()
    rows = default_rows(infos)
    assert rows["motion_mamba"] == "motion_mamba:fast" and rows["kmm"] == "kmm" and rows["baseline"] == "baseline"
    assert rows["ftmomamba"] == "ftmomamba:fast"
    figures = load_figures(NAMES, rows=rows)
    proc = json.loads((REPO / "results/verifier.json").read_text())
    real = json.loads((REPO / "results/verifier_real.json").read_text())
    fast = "motion_mamba:fast"
    expected = (proc[fast]["pass_rate"] * proc["n"] + real[fast]["pass_rate"] * real["n"]) / (proc["n"] + real["n"])
    assert abs(figures["motion_mamba"].pass_rate - expected) < 1e-12
    bench = json.loads((REPO / "results/bench.json").read_text())["generate"]
    assert figures["motion_mamba"].timeline_10s_s == bench[fast]["timeline_10s_median_ms"] / 1000
    assert figures["motion_mamba"].timeline_10s_s < bench["motion_mamba"]["timeline_10s_median_ms"] / 1000
    summary = {s["name"]: s for s in summaries(infos)}["motion_mamba"]
    assert summary["default_sampler"] == "fast" and summary["text_following"] == figures["motion_mamba"].pass_rate


def test_the_default_follows_the_figures_when_they_change(tmp_path):
    for f in (REPO / "results").glob("*.json"):
        shutil.copy(f, tmp_path / f.name)
    doc = json.loads((tmp_path / "verifier.json").read_text())
    doc["baseline"]["pass_rate"] = 0.99
    doc["kmm"]["pass_rate"] = 0.10
    (tmp_path / "verifier.json").write_text(json.dumps(doc))
    (tmp_path / "verifier_real.json").unlink()
    figures = load_figures(NAMES, tmp_path)
    assert best_method(NAMES, figures) == "baseline"
    assert figures["baseline"].prompts == doc["n"]
    rows = {s["name"]: s for s in summaries(motion_core.methods(), tmp_path)}
    assert rows["baseline"]["default"] and not rows["kmm"]["default"]
    assert rows["baseline"]["text_following"] == 0.99
    # a broken or missing file is ignored: nothing measured, the registry's first is the default
    (tmp_path / "verifier.json").write_text("{not json")
    figures = load_figures(NAMES, tmp_path)
    assert all(f.pass_rate is None for f in figures.values())
    assert best_method(NAMES, figures) == NAMES[0]
    assert "not measured" in choice_label("X", figures[NAMES[0]])
