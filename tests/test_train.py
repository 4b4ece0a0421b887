"""The training CLI end to end on a tiny corpus: VAE, resume, both denoisers."""

from __future__ import annotations

import json
import math

import pytest
import torch

from motion_core.corpus.__main__ import main as corpus_main
from motion_core.train.__main__ import main as train_main


def test_train_cli_runs_resumes_and_writes_checkpoints(tmp_path):
    data = tmp_path / "corpus"
    args = ["build", str(data), "--train", "24", "--val", "4", "--test", "4"]
    args += ["--seq-train", "1", "--seq-val", "1", "--seq-test", "1", "--workers", "1"]
    assert corpus_main(args) == 0
    vae_dir = tmp_path / "vae"
    common = ["--data", str(data), "--batch", "8", "--save-every", "2"]
    train_main(["vae", *common, "--out", str(vae_dir), "--steps", "2"])
    assert torch.load(vae_dir / "state.pt", weights_only=False)["step"] == 2
    with pytest.raises(SystemExit, match=r"another recipe \(--lr was 0\.0004, now 0\.001\)"):
        train_main(["vae", *common, "--out", str(vae_dir), "--steps", "3", "--lr", "1e-3"])
    staged = tmp_path / "vae_stage.pt"
    # resumes at step 2; --stage also writes the float16 checkpoint a later stage goes on from
    train_main(["vae", *common, "--out", str(vae_dir), "--steps", "3", "--stage", str(staged)])
    ck = torch.load(vae_dir / "vae.pt", weights_only=False)
    assert ck["meta"]["steps"] == 3 and ck["meta"]["test"]["mpjpe_mm"] > 0
    st = torch.load(staged, weights_only=False)
    assert st["meta"] == ck["meta"] and {v.dtype for v in st["state_dict"].values() if v.is_floating_point()} == {
        torch.float16
    }
    # a later stage goes on from the committed (float16) checkpoint: same weights at its start,
    # a fresh optimiser, and the lineage's steps in its meta
    stage2 = tmp_path / "vae2"
    train_main(["vae", *common, "--out", str(stage2), "--steps", "1", "--init", str(staged)])
    ck2 = torch.load(stage2 / "vae.pt", weights_only=False)
    assert ck2["meta"]["steps"] == 4 and ck2["meta"]["init"] == {"from": "vae_stage.pt", "steps": 3}
    for what in ("motion_mamba", "baseline"):
        out = tmp_path / what
        train_main([what, *common, "--vae", str(vae_dir), "--out", str(out), "--steps", "2"])
        meta = json.loads((out / "result.json").read_text())
        assert meta["steps"] == 2 and meta["vae_steps"] == 3
        assert meta["final_loss_ema"] == meta["final_loss_ema"]  # not NaN


def test_ablation_arm_trains_with_overrides_and_joins_the_tables(tmp_path):
    """`train motion_mamba --set ...` trains an arm with the changed config; `evaluate --arm
    NAME=RUN --ablation` scores it like a shipped method (on the shipped VAE) and forgets it."""
    import shutil

    import pytest

    from motion_core.eval.__main__ import main as evaluate_main
    from motion_core.inference.checkpoints import WEIGHTS
    from motion_core.inference.registry import REGISTRY, methods, unregister_arm

    data = tmp_path / "corpus"
    args = ["build", str(data), "--train", "16", "--val", "4", "--test", "6"]
    args += ["--seq-train", "1", "--seq-val", "1", "--seq-test", "1", "--workers", "1"]
    assert corpus_main(args) == 0
    vae_dir = tmp_path / "vae"
    vae_dir.mkdir()
    shutil.copy(WEIGHTS / "vae.pt", vae_dir / "vae.pt")  # arms must share the shipped VAE
    arm = tmp_path / "mm_flat"
    # x_0, the target the shipped denoisers train on (a temporal VAE refuses epsilon)
    common = ["--data", str(data), "--batch", "4", "--vae", str(vae_dir), "--steps", "2", "--prediction", "sample"]
    train_main(["motion_mamba", *common, "--out", str(arm), "--set", "htm_order=flat", "--set", "bsm=single"])
    cfg = json.loads((arm / "result.json").read_text())["config"]
    assert cfg["htm_order"] == "flat" and cfg["bsm"] == "single"
    with pytest.raises(ValueError, match="bsm must be one of"):
        train_main(["motion_mamba", *common, "--out", str(tmp_path / "bad"), "--set", "bsm=sideways"])

    out = tmp_path / "res"
    try:
        evaluate_main(["--data", str(data), "--arm", f"flat={arm}", "--ablation", "--n", "2", "--out", str(out)])
        assert "flat" in [m["name"] for m in methods()]
    finally:
        unregister_arm("flat")
    assert "flat" not in REGISTRY
    res = json.loads((out / "ablation.json").read_text())
    row = res["flat"]
    assert res["n"] == 2 and row["steps"] == 2 and row["config"]["htm_order"] == "flat"
    assert 0 < row["denoising_loss"] < 10 and 0 <= row["pass_rate"] <= 1
    assert res["reference"] == "flat" and row["denoising_loss_vs_reference"] == 0.0


def test_learning_rate_schedules():
    from motion_core.train.schedule import learning_rate

    # cosine: the shipped runs' schedule, warm-up then down to a tenth at the end
    assert learning_rate(1.0, 0, 1000, warmup=500) == pytest.approx(1 / 500)
    assert learning_rate(1.0, 499, 1000, warmup=500) == pytest.approx(0.1 + 0.45 * (1 + math.cos(math.pi * 0.499)))
    assert learning_rate(1.0, 1000, 1000, warmup=0) == pytest.approx(0.1)
    # constant: a stage before the last holds the rate; a stage that goes on needs no warm-up
    assert learning_rate(3e-4, 50, 1000, warmup=100, decay="constant") == pytest.approx(3e-4 * 51 / 100)
    assert [learning_rate(3e-4, s, 1000, warmup=0, decay="constant") for s in (0, 999, 5000)] == [3e-4] * 3
    with pytest.raises(ValueError, match="unknown decay"):
        learning_rate(1.0, 0, 10, decay="linear")
