"""Guidance distillation: a student that reads the guidance scale learns the
teacher's guided pair in one pass; its sampler is the teacher's DDIM with that one pass;
``train guidance`` end to end on a tiny corpus; the registry offers it as "fast"."""

from __future__ import annotations

import copy
from pathlib import Path

import numpy as np
import pytest
import torch

import motion_core
from motion_core.inference.base import InputError
from motion_core.inference.checkpoints import WEIGHTS, load_student, read_float32
from motion_core.inference.registry import register_arm, samplers, unregister_arm
from motion_core.inference.samplers import GuidedDDIM, StudentDDIM, student_kind
from motion_core.models.consistency import GuidedStudent
from motion_core.models.denoisers import TransformerConfig, transformer_denoiser
from motion_core.nn.diffusion import Diffusion, DiffusionConfig
from motion_core.nn.guidance_distillation import GuidanceDistillConfig
from motion_core.train.__main__ import main as train_main
from motion_core.train.guidance_distillation import guidance_loss
from tests.test_denoiser_training import tiny  # noqa: F401  (the module-scoped corpus fixture)


def _net() -> torch.nn.Module:
    torch.manual_seed(0)
    return transformer_denoiser(TransformerConfig(levels=1, ff=64, latent_dim=32, heads=2, dropout=0.0)).eval()


class _PerfectStudent(torch.nn.Module):
    """What guidance distillation aims at: the teacher's guided output, in one call."""

    def __init__(self, teacher: torch.nn.Module, empty: torch.Tensor, diffusion: Diffusion) -> None:
        super().__init__()
        self.teacher, self.empty, self.diffusion = teacher, empty, diffusion

    def forward(self, z, t, text, frames, w):
        b = z.shape[0]
        o = self.teacher(
            torch.cat([z, z]),
            torch.cat([t, t]),
            torch.cat([text, self.empty.expand(b, -1)]),
            torch.cat([frames, frames]),
        )
        o_c, o_u = o.chunk(2)
        return self.diffusion.guide(o_c, o_u, w)


@pytest.mark.parametrize("prediction", ["sample", "epsilon"])
def test_the_student_sampler_is_the_teachers_guided_ddim_when_the_student_is_perfect(prediction):
    teacher, diff = _net(), Diffusion(DiffusionConfig(prediction=prediction))
    cond, empty, frames = torch.randn(2, 384), torch.randn(1, 384), torch.tensor([60, 100])
    cfg = GuidanceDistillConfig(guidance=6.0, sample_steps=5)
    with torch.no_grad():
        fast = StudentDDIM(_PerfectStudent(teacher, empty, diff), diff, cfg)
        quality = GuidedDDIM(teacher, diff)
        a = fast(cond, empty, frames, (2, 2, 32), torch.Generator().manual_seed(4))
        b = quality(cond, empty, frames, (2, 2, 32), torch.Generator().manual_seed(4), steps=5, guidance=6.0)
        c = fast(cond, empty, frames, (2, 2, 32), torch.Generator().manual_seed(5))
    assert torch.allclose(a, b, atol=1e-5) and not torch.allclose(a, c)


@pytest.mark.long
def test_the_loss_starts_at_the_guidance_gap_and_training_closes_it():
    """An untrained student is the conditional branch: its loss is the guided correction
    ((w - 1)(o_c - o_u))^2; a few hundred steps on a fixed batch cut it by more than half."""
    teacher, diff = _net(), Diffusion(DiffusionConfig(prediction="sample"))
    for p in teacher.parameters():
        p.requires_grad_(False)
    student = GuidedStudent(copy.deepcopy(teacher)).train()
    for p in student.parameters():
        p.requires_grad_(True)
    cfg = GuidanceDistillConfig()
    z0, cond, empty = torch.randn(16, 2, 32), torch.randn(16, 384), torch.randn(384)
    frames = torch.full((16,), 80)

    def loss_at(seed: int) -> torch.Tensor:
        return guidance_loss(student, teacher, diff, cfg, z0, cond, empty, frames, torch.Generator().manual_seed(seed))

    start = float(loss_at(0).detach())
    assert start > 0
    opt = torch.optim.Adam(student.parameters(), lr=1e-3)
    for i in range(300):
        opt.zero_grad()
        loss_at(i % 4).backward()
        opt.step()
    assert float(loss_at(0).detach()) < 0.5 * start


@pytest.fixture(scope="module")
def guidance_run(tiny, tmp_path_factory) -> Path:  # noqa: F811
    data, vae_dir = tiny
    out = tmp_path_factory.mktemp("guidance")
    common = ["guidance", "--teacher", str(WEIGHTS / "baseline.pt"), "--data", str(data), "--vae", str(vae_dir)]
    common += ["--batch", "4", "--save-every", "2", "--out", str(out), "--decay", "constant", "--sample-steps", "3"]
    train_main([*common, "--steps", "2"])
    train_main([*common, "--steps", "3", "--val-every", "3", "--val-n", "4"])  # resumes at step 2
    return out


@pytest.mark.long
def test_train_guidance_resumes_and_writes_a_student_the_registry_offers(guidance_run, tiny, tmp_path):  # noqa: F811
    data, vae_dir = tiny
    ck = read_float32(guidance_run / "baseline_guidance.pt")
    whole = ["guidance", "--teacher", str(WEIGHTS / "baseline.pt"), "--data", str(data), "--vae", str(vae_dir)]
    whole += ["--batch", "4", "--decay", "constant", "--sample-steps", "3", "--save-every", "3", "--steps", "3"]
    train_main([*whole, "--out", str(tmp_path / "whole")])
    once = read_float32(tmp_path / "whole" / "baseline_guidance.pt")["state_dict"]
    assert all(torch.equal(once[k], v) for k, v in ck["state_dict"].items())  # resumed = in one go
    meta = ck["meta"]
    assert meta["guidance_distillation"]["sample_steps"] == 3 and "consistency" not in meta
    assert meta["validation"]["fast"]["steps"] == 3 and meta["teacher"]["from"] == "baseline.pt"
    assert isinstance(student_kind(meta).sampler(load_student(ck), Diffusion(DiffusionConfig())), StudentDDIM)

    info = register_arm("gd_arm", WEIGHTS / "baseline.pt", student=guidance_run / "baseline_guidance.pt")
    try:
        assert samplers(info) == ("quality", "fast")
        opts = {m["name"]: m for m in motion_core.methods()}["gd_arm"]["sampler_options"]["fast"]
        assert (opts["steps"], opts["max_steps"], opts["guidance"]) == (3, 100, [1.0, 15.0])
        assert "guidance-distilled" in opts["label"] and "guidance-distilled" in opts["steps_label"]
        segs = [("a person walks forward", 2.5), ("a person waves with the right hand", 2.0)]
        a = motion_core.generate(segs, method="gd_arm", seed=3, sampler="fast")
        b = motion_core.generate(segs, method="gd_arm", seed=3, sampler="fast")
        q = motion_core.generate(segs, method="gd_arm", seed=3, sampler="quality", steps=3)
        assert a.sampler == "fast" and np.array_equal(a.joints, b.joints)
        assert not np.array_equal(a.joints, q.joints)
        # continuous where the two segments were joined
        step = np.linalg.norm(np.diff(a.joints[:, 0], axis=0), axis=-1)
        assert step[45:55].max() < 3 * np.median(step) + 0.02
        with pytest.raises(InputError, match="1 to 100 steps, not 101"):
            motion_core.generate(segs, method="gd_arm", sampler="fast", steps=101)
        with pytest.raises(InputError, match="guidance 1-15, not 20"):
            motion_core.generate(segs, method="gd_arm", sampler="fast", guidance=20.0)
    finally:
        unregister_arm("gd_arm")


def test_the_inverse_w2_loss_weighs_each_sample_by_its_scale():
    """loss_weight="inverse_w2" is each sample's MSE over its own w^2, from the same draws
    (t, w, noise, in that order) as the plain loss."""
    teacher, diff = _net(), Diffusion(DiffusionConfig(prediction="sample"))
    student = GuidedStudent(copy.deepcopy(teacher))
    with torch.no_grad():  # a student that differs from the teacher's conditional branch
        for p in student.parameters():
            p.add_(0.05 * torch.randn_like(p))
    z0, cond, empty = torch.randn(6, 2, 32), torch.randn(6, 384), torch.randn(384)
    frames = torch.full((6,), 80)
    cfg = GuidanceDistillConfig(loss_weight="inverse_w2")
    with torch.no_grad():
        got = guidance_loss(student, teacher, diff, cfg, z0, cond, empty, frames, torch.Generator().manual_seed(3))
        g = torch.Generator().manual_seed(3)
        t = torch.randint(0, diff.cfg.train_steps, (6,), generator=g)
        w = cfg.guidance_min + (cfg.guidance_max - cfg.guidance_min) * torch.rand(6, generator=g)
        x_t = diff.add_noise(z0, torch.randn(z0.shape, generator=g), t)
        target = diff.guide(teacher(x_t, t, cond, frames), teacher(x_t, t, empty.expand(6, -1), frames), w)
        per_sample = (student(x_t, t, cond, frames, w) - target).pow(2).flatten(1).mean(1)
    assert float(got) > 0
    assert float(got) == pytest.approx(float((per_sample / w**2).mean()), rel=1e-5)
    with pytest.raises(ValueError, match="loss_weight"):
        guidance_loss(
            student, teacher, diff, GuidanceDistillConfig(loss_weight="x"), z0, cond, empty, frames, torch.Generator()
        )


def test_a_student_of_one_scale_is_configured_for_it_alone_and_a_bad_range_is_refused():
    """--guidance-range 7.5 7.5: the scales drawn in training span 7.5 alone and the default sits there; a
    range with MIN above MAX (or a scale of 0) is refused before any training."""
    import argparse

    from motion_core.train.guidance_distillation import guidance_training

    kind = guidance_training(argparse.Namespace(sample_steps=10, loss_weight="uniform", guidance_range=[7.5, 7.5]))
    assert (kind.settings.guidance_min, kind.settings.guidance_max, kind.settings.guidance) == (7.5, 7.5, 7.5)
    for bad in ([9.0, 7.5], [0.0, 7.5]):
        with pytest.raises(SystemExit, match="guidance-range"):
            guidance_training(argparse.Namespace(sample_steps=10, loss_weight="uniform", guidance_range=bad))


def test_a_rescoring_with_no_step_keeps_the_init_students_settings(tmp_path):
    """``train guidance --init S --steps 0`` rescores (and may ship) S as it was distilled:
    its scales and loss weighting from S's meta, only its default sampling steps changeable;
    the command's own defaults would otherwise have been recorded over them."""
    import argparse

    from motion_core.inference.registry import DIFFUSION_STEPS
    from motion_core.train.guidance_distillation import guidance_training

    distilled = GuidanceDistillConfig(guidance_min=2.0, guidance_max=4.0, loss_weight="inverse_w2", guidance=3.0)
    distilled.sample_steps = 7
    init = tmp_path / "baseline_guidance.pt"
    torch.save({"state_dict": {}, "meta": {"guidance_distillation": distilled.to_dict()}}, init)
    teacher = str(WEIGHTS / "baseline.pt")

    def settings(**kw) -> GuidanceDistillConfig:
        args = {"teacher": teacher, "init": None, "steps": 0, "sample_steps": None, "loss_weight": None}
        args.update(guidance_range=None, **kw)
        return guidance_training(argparse.Namespace(**args)).settings

    assert settings(init=str(init)) == distilled
    assert settings(init=str(init), sample_steps=2) == GuidanceDistillConfig(
        **{**distilled.to_dict(), "sample_steps": 2}
    )
    # steps taken, or no init: a fresh student's settings, from the command's flags
    fresh = settings(init=str(init), steps=5)
    assert (fresh.guidance_min, fresh.guidance_max, fresh.loss_weight) == (1.0, 15.0, "uniform")
    assert fresh.sample_steps == DIFFUSION_STEPS
    assert settings(steps=5, loss_weight="inverse_w2", sample_steps=3).loss_weight == "inverse_w2"


def test_a_no_step_rescoring_of_a_trajectory_student_or_another_kind(tmp_path, capsys):
    """``train lcm --init S --steps 0`` of a student fine-tuned on the trajectory objective
    keeps its settings (it raised UnboundLocalError); an --init of the other kind of student
    is refused by name; flags the rescoring ignores are named."""
    import argparse

    from motion_core.nn.consistency import ConsistencyConfig
    from motion_core.train.consistency import consistency_training
    from motion_core.train.guidance_distillation import guidance_training

    tuned = ConsistencyConfig(guidance=2.0, guidance_min=2.0, guidance_max=2.0, objective="trajectory")
    init = tmp_path / "ftmomamba_lcm.pt"
    torch.save({"state_dict": {}, "meta": {"consistency": tuned.to_dict()}}, init)
    base = {"teacher": str(WEIGHTS / "ftmomamba.pt"), "init": str(init), "steps": 0, "sample_steps": None}
    args = argparse.Namespace(**base, guidance_range=[1.0, 9.0], loss_weight=None)
    assert consistency_training(args).settings == tuned
    assert "--guidance-range ignored" in capsys.readouterr().out
    # lcm's own flags too: they had non-None defaults, so a given one went unmentioned
    own = argparse.Namespace(**base, solver_steps=7, objective="consistency", renoise="ddim", huber_c=0.1)
    assert consistency_training(own).settings == tuned
    assert "--solver-steps, --objective, --renoise, --huber-c ignored" in capsys.readouterr().out
    # what the command line gives when none of them is named: nothing to call ignored
    from motion_core.train.__main__ import lcm_parser

    parsed = lcm_parser().parse_args(["--teacher", base["teacher"], "--out", "x", "--init", str(init), "--steps", "0"])
    assert (parsed.solver_steps, parsed.objective, parsed.renoise, parsed.huber_c) == (None, None, None, None)
    consistency_training(parsed)
    assert "ignored" not in capsys.readouterr().out
    # a fresh student takes MotionLCM's defaults for them; a grid of no steps is refused
    fresh = lcm_parser().parse_args(["--teacher", base["teacher"], "--out", "x"])
    made = consistency_training(fresh).settings
    assert (made.solver_steps, made.objective, made.renoise) == (10, "consistency", "random")
    fresh.solver_steps = 0
    with pytest.raises(SystemExit, match="--solver-steps wants a positive"):
        consistency_training(fresh)
    with pytest.raises(SystemExit, match="is not a guidance_distillation student"):
        guidance_training(args)
