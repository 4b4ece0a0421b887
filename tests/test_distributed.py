"""Data-parallel training under torchrun: two CPU processes (gloo) take the same steps as
one process with the same global batch, a denoiser's and a student's."""

from __future__ import annotations

import copy
import json
import os
import subprocess
import sys

import pytest
import torch

from motion_core.inference.checkpoints import WEIGHTS
from motion_core.models.consistency import GuidedStudent
from motion_core.models.denoisers import TransformerConfig, transformer_denoiser
from motion_core.nn.consistency import ConsistencyConfig
from motion_core.nn.diffusion import Diffusion, DiffusionConfig
from motion_core.nn.guidance_distillation import GuidanceDistillConfig
from motion_core.train.__main__ import main as train_main
from motion_core.train.consistency import distillation_loss
from motion_core.train.distributed import ALL_ROWS, World
from motion_core.train.guidance_distillation import guidance_loss
from tests.test_denoiser_training import tiny  # noqa: F401  (the module-scoped corpus fixture)


def _gap(a: dict, b: dict) -> float:
    """The mean absolute difference over all elements of two state dicts' common tensors.
    At the full rate a weight whose gradient is near 0 may take Adam's step either way with
    the order of the float sums, so one element can differ by a whole step: the mean, not
    the largest, tells equal training from different training."""
    keys = sorted(a.keys() & b.keys())
    diff = torch.cat([(a[k].float() - b[k].float()).abs().flatten() for k in keys])
    return float(diff.mean())


def _run_two(common: list[str], out) -> None:
    env = {**os.environ, "OMP_NUM_THREADS": "1"}
    cmd = [sys.executable, "-m", "torch.distributed.run", "--standalone", "--nproc_per_node", "2"]
    cmd += ["-m", "motion_core.train", *common, "--out", str(out)]
    run = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stderr[-3000:]


@pytest.mark.long
def test_two_processes_equal_one_with_the_same_global_batch(tiny, tmp_path):  # noqa: F811
    """A denoiser's steps under torchrun, from known weights (--init) at the full rate from
    the first step, so the check weighs the difference against how far the weights moved:
    at the default warm-up three steps moved them less than any fixed tolerance."""
    data, vae_dir = tiny
    base = ["motion_mamba", "--data", str(data), "--vae", str(vae_dir), "--batch", "8", "--prediction", "sample"]
    base += ["--set", "dropout=0.0"]
    train_main([*base, "--steps", "1", "--save-every", "1", "--out", str(tmp_path / "start")])
    start_file = tmp_path / "start" / "motion_mamba.pt"
    common = [*base, "--steps", "3", "--lr", "1e-3", "--warmup", "0", "--decay", "constant", "--save-every", "3"]
    common += ["--init", str(start_file)]
    train_main([*common, "--out", str(tmp_path / "one")])
    _run_two(common, tmp_path / "two")
    one = torch.load(tmp_path / "one" / "motion_mamba.pt", weights_only=False)
    two = torch.load(tmp_path / "two" / "motion_mamba.pt", weights_only=False)
    assert (one["meta"]["processes"], two["meta"]["processes"]) == (1, 2)
    assert one["state_dict"].keys() == two["state_dict"].keys()
    start = torch.load(start_file, weights_only=False)["state_dict"]
    raw = [torch.load(tmp_path / r / "state.pt", weights_only=False)["model"] for r in ("one", "two")]
    for a, b in (raw, (one["state_dict"], two["state_dict"])):  # as trained, and its moving average
        assert _gap(a, b) < 0.02 * _gap(b, start), (_gap(a, b), _gap(b, start))
    # the logged loss is the global batch's, not one process's half
    l1 = json.loads((tmp_path / "one" / "result.json").read_text())["final_loss_ema"]
    l2 = json.loads((tmp_path / "two" / "result.json").read_text())["final_loss_ema"]
    assert abs(l1 - l2) < 1e-4 * abs(l1), (l1, l2)


@pytest.mark.long
@pytest.mark.parametrize("what", ["lcm", "guidance"])
def test_a_students_two_processes_equal_one_with_the_same_global_batch(what, tiny, tmp_path):  # noqa: F811
    """Distillation under torchrun: each process draws the whole batch (captions, steps,
    scales, noise) and takes its rows, so two processes take one process's steps. The
    teacher has no dropout, the one draw a process makes for its rows alone. The first
    process validates at the last step while the other waits."""
    data, vae_dir = tiny
    teach = ["baseline", "--data", str(data), "--vae", str(vae_dir), "--batch", "4", "--steps", "2"]
    teach += ["--prediction", "sample"]
    train_main([*teach, "--set", "dropout=0.0", "--save-every", "2", "--out", str(tmp_path / "teacher")])
    teacher = tmp_path / "teacher" / "baseline.pt"
    common = [what, "--teacher", str(teacher), "--data", str(data), "--vae", str(vae_dir), "--batch", "8"]
    common += ["--steps", "3", "--lr", "1e-3", "--warmup", "0", "--decay", "constant", "--save-every", "3"]
    common += ["--val-every", "3", "--val-n", "4"]
    train_main([*common, "--out", str(tmp_path / "one")])
    _run_two(common, tmp_path / "two")
    one = torch.load(tmp_path / "one" / f"baseline_{what}.pt", weights_only=False)
    two = torch.load(tmp_path / "two" / f"baseline_{what}.pt", weights_only=False)
    assert (one["meta"]["processes"], two["meta"]["processes"]) == (1, 2)
    assert one["state_dict"].keys() == two["state_dict"].keys()
    # the student as trained (lcm ships its slow-moving EMA target), against how far it moved
    # at the full rate from the first step
    start = {f"net.{k}": v for k, v in torch.load(teacher, weights_only=False)["state_dict"].items()}
    raw = [torch.load(tmp_path / r / "state.pt", weights_only=False)["model"] for r in ("one", "two")]
    for a, b in (raw, (one["state_dict"], two["state_dict"])):
        assert _gap(a, b) < 0.02 * _gap(b, start), (_gap(a, b), _gap(b, start))
    l1, l2 = one["meta"]["final_loss_ema"], two["meta"]["final_loss_ema"]
    assert abs(l1 - l2) < 1e-4 * abs(l1), (l1, l2)
    # validated by the first process, scored once
    assert [c["step"] for c in json.loads((tmp_path / "two" / "curve.json").read_text())] == [3]
    assert two["meta"]["validation"]["prompts"] == one["meta"]["validation"]["prompts"] == 4


def test_torchrun_refuses_the_trajectory_objective(tiny, tmp_path, monkeypatch):  # noqa: F811
    """The trajectory objective unrolls the student before one backward, which DDP cannot
    reduce: refused with a message, before any step."""
    data, vae_dir = tiny
    monkeypatch.setattr("motion_core.train.consistency.init_world", lambda: World(rank=0, size=2))
    args = ["lcm", "--teacher", str(WEIGHTS / "baseline.pt"), "--data", str(data), "--vae", str(vae_dir)]
    args += ["--objective", "trajectory", "--guidance-range", "3", "3", "--out", str(tmp_path / "t")]
    with pytest.raises(SystemExit, match="trajectory runs in one process"):
        train_main(args)


@pytest.mark.parametrize("what", ["lcm", "guidance"])
def test_a_students_loss_on_each_processs_rows_averages_to_the_whole_batchs(what):
    """What makes the two-process run above faster as well as equal: each process's loss is
    its own rows' (half the network calls), drawn from the whole batch's draws, so the two
    halves' mean (what DDP's gradient average makes of them) is the one-process loss."""
    torch.manual_seed(0)
    teacher = transformer_denoiser(TransformerConfig(levels=1, ff=64, latent_dim=32, heads=2, dropout=0.0)).eval()
    student = GuidedStudent(copy.deepcopy(teacher))
    diffusion = Diffusion(DiffusionConfig())
    z0, cond, empty = torch.randn(8, 2, 32), torch.randn(8, 384), torch.randn(384)
    frames = torch.tensor([40, 60, 80, 100, 120, 140, 160, 196])
    calls = []
    student.register_forward_hook(lambda m, i, o: calls.append(len(i[0])))

    def loss(rows: slice) -> float:
        g = torch.Generator().manual_seed(3)
        if what == "lcm":
            cfg = ConsistencyConfig(solver_steps=5, guidance_min=2.0, guidance_max=4.0)
            return float(
                distillation_loss(student, student, teacher, diffusion, cfg, z0, cond, empty, frames, g, rows).detach()
            )
        cfg = GuidanceDistillConfig(guidance_min=2.0, guidance_max=4.0)
        return float(guidance_loss(student, teacher, diffusion, cfg, z0, cond, empty, frames, g, rows).detach())

    whole, halves = loss(ALL_ROWS), [loss(World(rank=r, size=2).shard(8)) for r in (0, 1)]
    assert abs(sum(halves) / 2 - whole) < 1e-6 * abs(whole)
    assert abs(halves[0] - whole) > 1e-3 * abs(whole)
    assert set(calls[len(calls) // 2 :]) == {4}  # the halves' calls: 4 rows each, not 8
