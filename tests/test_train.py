"""The training CLI end to end on a tiny corpus: VAE, resume, both denoisers."""

from __future__ import annotations

import json

import torch

from motion_core.corpus.__main__ import main as corpus_main
from motion_core.train import main as train_main


def test_train_cli_runs_resumes_and_writes_checkpoints(tmp_path):
    data = tmp_path / "corpus"
    args = ["build", str(data), "--train", "24", "--val", "4", "--test", "4"]
    args += ["--seq-train", "1", "--seq-val", "1", "--seq-test", "1", "--workers", "1"]
    assert corpus_main(args) == 0
    vae_dir = tmp_path / "vae"
    common = ["--data", str(data), "--batch", "8", "--save-every", "2"]
    train_main(["vae", *common, "--out", str(vae_dir), "--steps", "2"])
    assert torch.load(vae_dir / "state.pt", weights_only=False)["step"] == 2
    train_main(["vae", *common, "--out", str(vae_dir), "--steps", "3"])  # resumes at step 2
    ck = torch.load(vae_dir / "vae.pt", weights_only=False)
    assert ck["meta"]["steps"] == 3 and ck["meta"]["test"]["mpjpe_mm"] > 0
    for what in ("motion_mamba", "baseline"):
        out = tmp_path / what
        train_main([what, *common, "--vae", str(vae_dir), "--out", str(out), "--steps", "2"])
        meta = json.loads((out / "result.json").read_text())
        assert meta["steps"] == 2 and meta["vae_steps"] == 3
        assert meta["final_loss_ema"] == meta["final_loss_ema"]  # not NaN
