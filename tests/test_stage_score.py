"""tools/stage_score.py, the tool stages and students are chosen with: ``--student`` scores
the consistency student of the checkpoint with the student's own steps and scale, and
refuses a student of other weights (its scores would not be that checkpoint's)."""

from __future__ import annotations

import importlib.util
import json
import sys
from pathlib import Path

import pytest
import torch

from motion_core.inference.checkpoints import WEIGHTS, read_float32
from motion_core.inference.samplers import ConsistencySampler, GuidedDDIM

TOOL = Path(__file__).resolve().parents[1] / "tools" / "stage_score.py"


@pytest.fixture
def tool(monkeypatch):
    """The tool's module, with its validation swapped for a recorder: what is under test is
    which sampler, steps and scale it scores, not the verifier."""
    spec = importlib.util.spec_from_file_location("stage_score_tool", TOOL)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    calls: list[dict] = []

    def record(sampler, vae, norm, scale, sets, seed, guidance, steps):
        calls.append({"sampler": sampler, "seed": seed, "guidance": guidance, "steps": steps})
        return {"n": 1, "pass_rate": 0.5, "direction_accuracy": None, "direction_prompts": 0, "sources": {}}

    monkeypatch.setattr(mod, "validation_pass_rate", record)
    monkeypatch.setattr(mod, "load_validation", lambda *a, **k: {})
    mod.calls = calls
    return mod


def _run(tool, monkeypatch, tmp_path, *extra: str) -> dict:
    out = tmp_path / "score.json"
    argv = ["stage_score.py", "--kind", "ftmomamba", "--checkpoint", str(WEIGHTS / "ftmomamba.pt")]
    monkeypatch.setattr(sys, "argv", [*argv, "--data", str(tmp_path), "--seeds", "0", "1", *extra, "--out", str(out)])
    tool.main()
    return json.loads(out.read_text())


def test_a_student_is_scored_with_its_own_steps_and_scale(tool, monkeypatch, tmp_path):
    cons = read_float32(WEIGHTS / "ftmomamba_fast.pt")["meta"]["consistency"]
    doc = _run(tool, monkeypatch, tmp_path, "--student", str(WEIGHTS / "ftmomamba_fast.pt"))
    assert [c["seed"] for c in tool.calls] == [0, 1]
    assert all(isinstance(c["sampler"], ConsistencySampler) for c in tool.calls)
    assert {(c["steps"], c["guidance"]) for c in tool.calls} == {(cons["sample_steps"], cons["guidance"])}
    assert doc["sampler"] == {"consistency_steps": cons["sample_steps"], "guidance": cons["guidance"]}
    assert doc["student"].endswith("ftmomamba_fast.pt")
    tool.calls.clear()
    doc = _run(tool, monkeypatch, tmp_path, "--student", str(WEIGHTS / "ftmomamba_fast.pt"), "--steps", "4")
    assert {c["steps"] for c in tool.calls} == {4}
    # without --student: the teacher's guided DDIM at the registry's steps
    tool.calls.clear()
    doc = _run(tool, monkeypatch, tmp_path)
    assert all(isinstance(c["sampler"], GuidedDDIM) for c in tool.calls)
    assert "student" not in doc and "ddim_steps" in doc["sampler"]


def test_a_student_of_other_weights_or_another_kind_is_refused(tool, monkeypatch, tmp_path):
    with pytest.raises(SystemExit, match="was not distilled from"):
        _run(tool, monkeypatch, tmp_path, "--student", str(WEIGHTS / "motion_mamba_fast.pt"))
    # a guidance-distilled student has no consistency sampler: named, not a KeyError
    ck = read_float32(WEIGHTS / "ftmomamba_fast.pt")
    del ck["meta"]["consistency"]
    torch.save(ck, tmp_path / "guided.pt")
    with pytest.raises(SystemExit, match="is not a consistency student"):
        _run(tool, monkeypatch, tmp_path, "--student", str(tmp_path / "guided.pt"))
    assert tool.calls == []
