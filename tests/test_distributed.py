"""Data-parallel training under torchrun: two CPU processes (gloo) take the same steps as
one process with the same global batch."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest
import torch

from motion_core.train.__main__ import main as train_main
from tests.test_denoiser_training import tiny  # noqa: F401  (the module-scoped corpus fixture)


@pytest.mark.long
def test_two_processes_equal_one_with_the_same_global_batch(tiny, tmp_path):  # noqa: F811
    data, vae_dir = tiny
    common = ["motion_mamba", "--data", str(data), "--vae", str(vae_dir), "--batch", "8", "--steps", "3"]
    common += ["--lr", "1e-3", "--prediction", "sample", "--set", "dropout=0.0", "--save-every", "3"]
    train_main([*common, "--out", str(tmp_path / "one")])
    env = {**os.environ, "OMP_NUM_THREADS": "1"}
    cmd = [sys.executable, "-m", "torch.distributed.run", "--standalone", "--nproc_per_node", "2"]
    cmd += ["-m", "motion_core.train", *common, "--out", str(tmp_path / "two")]
    run = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stderr[-3000:]
    one = torch.load(tmp_path / "one" / "motion_mamba.pt", weights_only=False)
    two = torch.load(tmp_path / "two" / "motion_mamba.pt", weights_only=False)
    assert (one["meta"]["processes"], two["meta"]["processes"]) == (1, 2)
    assert one["state_dict"].keys() == two["state_dict"].keys()
    worst = max(float((one["state_dict"][k] - two["state_dict"][k]).abs().max()) for k in one["state_dict"])
    assert worst < 1e-4, worst
    # the logged loss is the global batch's, not one process's half
    l1 = json.loads((tmp_path / "one" / "result.json").read_text())["final_loss_ema"]
    l2 = json.loads((tmp_path / "two" / "result.json").read_text())["final_loss_ema"]
    assert abs(l1 - l2) < 1e-4 * abs(l1), (l1, l2)
