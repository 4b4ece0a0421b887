"""Latent consistency distillation: the consistency function's boundary, the
student's start, the few-step sampler's determinism, and the ``train lcm`` command end to
end on a tiny corpus."""

from __future__ import annotations

import copy
import json
from pathlib import Path

import numpy as np
import pytest
import torch

import motion_core
from motion_core.body.skeleton import HUMANML3D
from motion_core.inference.base import InputError, UnknownMethod
from motion_core.inference.checkpoints import WEIGHTS, load_student, load_vae, read, read_float32
from motion_core.inference.registry import DIFFUSION_STEPS, GUIDANCE, register_arm, samplers, unregister_arm
from motion_core.inference.samplers import ConsistencySampler, GuidedDDIM
from motion_core.models.consistency import GuidedStudent
from motion_core.models.denoisers import TransformerConfig, transformer_denoiser
from motion_core.nn.consistency import (
    ConsistencyConfig,
    boundary_scalings,
    consistency_fn,
    consistency_sample,
    consistency_unroll,
    sample_timesteps,
)
from motion_core.nn.diffusion import Diffusion, DiffusionConfig
from motion_core.train.__main__ import main as train_main
from tests.test_denoiser_training import tiny  # noqa: F401  (the module-scoped corpus fixture)

CFG = ConsistencyConfig()


def _net() -> torch.nn.Module:
    torch.manual_seed(0)
    return transformer_denoiser(TransformerConfig(levels=1, ff=64, latent_dim=32, heads=2, dropout=0.0)).eval()


def test_the_consistency_function_is_the_identity_at_t_0_and_nearly_x0_high_up():
    c_skip, c_out = boundary_scalings(torch.tensor([0, 1, 901]), CFG)
    assert c_skip[0] == 1 and c_out[0] == 0
    assert c_skip[1] < 0.01 and c_out[1] > 0.99 and c_out[2] > 0.9999
    x = torch.randn(3, 2, 32)
    assert torch.equal(consistency_fn(lambda x, t: torch.zeros_like(x), x, torch.zeros(3, dtype=torch.long), CFG), x)


def test_an_untrained_student_is_its_teachers_conditional_branch():
    teacher = _net()
    student = GuidedStudent(copy.deepcopy(teacher)).eval()
    z, t = torch.randn(4, 2, 32), torch.tensor([1, 200, 500, 900])
    text, frames = torch.randn(4, 384), torch.tensor([40, 80, 120, 196])
    want = teacher(z, t, text, frames)
    for w in (1.0, 7.5, 15.0):
        assert torch.equal(student(z, t, text, frames, torch.full((4,), w)), want)


def test_sample_timesteps_descend_over_the_solver_grid():
    diff = Diffusion()
    assert sample_timesteps(diff, CFG, 1) == [901]
    assert sample_timesteps(diff, CFG, 2) == [901, 401]
    assert sample_timesteps(diff, CFG, 4) == [901, 701, 401, 201]
    with pytest.raises(ValueError, match="1 to 10 steps"):
        sample_timesteps(diff, CFG, 0)


@pytest.mark.parametrize("steps", [1, 2, 4])
def test_the_fast_sampler_is_deterministic_per_seed(steps):
    diff = Diffusion(DiffusionConfig(prediction="sample"))
    sampler = ConsistencySampler(GuidedStudent(_net()).eval(), diff, CFG)
    cond, empty, frames = torch.randn(3, 384), torch.randn(1, 384), torch.tensor([40, 80, 196])

    def run(seed: int) -> torch.Tensor:
        return sampler(cond, empty, frames, (3, 2, 32), torch.Generator().manual_seed(seed), steps)

    a, b, c = run(0), run(0), run(1)
    assert torch.equal(a, b) and not torch.allclose(a, c) and torch.isfinite(a).all()


def test_one_consistency_step_is_the_networks_x0_at_the_top_of_the_grid():
    # 1 step: f(x_T, T) = c_skip x_T + c_out x0 with c_skip ~ 1e-4 at T = 901
    net = GuidedStudent(_net()).eval()
    diff = Diffusion(DiffusionConfig(prediction="sample"))
    cond, frames = torch.randn(2, 384), torch.tensor([60, 60])
    g = torch.Generator().manual_seed(3)
    z = consistency_sample(
        lambda x, t: net(x, t, cond, frames, torch.full((2,), 7.5)), diff, CFG, (2, 2, 32), g, steps=1
    )
    x_T = torch.randn((2, 2, 32), generator=torch.Generator().manual_seed(3))
    with torch.no_grad():
        x0 = net(x_T, torch.full((2,), 901), cond, frames, torch.full((2,), 7.5))
    assert (z - x0).abs().max() < 1e-3 * (1 + x0.abs().max())


@pytest.fixture(scope="module")
def student_run(tiny, tmp_path_factory) -> Path:  # noqa: F811
    """``train lcm`` on the tiny corpus from the shipped baseline: 2 steps, then resumed to 3
    with a validation score; returns the run directory."""
    data, vae_dir = tiny
    out = tmp_path_factory.mktemp("lcm")
    common = ["lcm", "--teacher", str(WEIGHTS / "baseline.pt"), "--data", str(data), "--vae", str(vae_dir)]
    common += ["--batch", "4", "--save-every", "2", "--out", str(out), "--decay", "constant"]
    train_main([*common, "--steps", "2"])
    train_main([*common, "--steps", "3", "--val-every", "3", "--val-n", "4"])  # resumes at step 2
    return out


def test_a_run_resumed_only_to_ship_keeps_its_last_loss(student_run, tiny, tmp_path):  # noqa: F811
    # rerunning a finished run at its own --steps takes no step (how a run is shipped after
    # its time limit): its meta must keep the loss the last steps ended on, not null
    import shutil

    data, vae_dir = tiny
    run = tmp_path / "run"
    shutil.copytree(student_run, run)
    before = json.loads((run / "result.json").read_text())["final_loss_ema"]
    assert isinstance(before, float)
    args = ["lcm", "--teacher", str(WEIGHTS / "baseline.pt"), "--data", str(data), "--vae", str(vae_dir)]
    train_main([*args, "--batch", "4", "--decay", "constant", "--steps", "3", "--out", str(run)])
    assert json.loads((run / "result.json").read_text())["final_loss_ema"] == before


def test_a_run_killed_between_validations_is_scored_when_resumed_to_ship(student_run, tiny, tmp_path):  # noqa: F811
    # killed after a save but before its last validation, a run resumed to ship must score
    # the network it ships, or the meta records no validation and the registry cannot weigh it
    import shutil

    data, vae_dir = tiny
    run = tmp_path / "run"
    shutil.copytree(student_run, run)
    (run / "curve.json").write_text(json.dumps(json.loads((run / "curve.json").read_text())[:-1]))
    args = ["lcm", "--teacher", str(WEIGHTS / "baseline.pt"), "--data", str(data), "--vae", str(vae_dir)]
    args += ["--batch", "4", "--decay", "constant", "--steps", "3", "--val-every", "3", "--val-n", "4"]
    train_main([*args, "--out", str(run)])
    assert json.loads((run / "curve.json").read_text())[-1]["step"] == 3
    assert json.loads((run / "result.json").read_text())["validation"]["fast"]["pass_rate"] is not None


def test_train_lcm_distils_resumes_and_writes_a_student(student_run, tiny, tmp_path):  # noqa: F811
    teacher = WEIGHTS / "baseline.pt"
    ck = read_float32(student_run / "baseline_lcm.pt")
    # 2 steps then resumed to 3 equals 3 steps in one go, bit for bit (a held rate: a cosine's
    # depends on --steps, which the two legs of the resumed run set differently)
    data, vae_dir = tiny
    whole = ["lcm", "--teacher", str(teacher), "--data", str(data), "--vae", str(vae_dir), "--batch", "4"]
    whole += ["--decay", "constant"]
    train_main([*whole, "--save-every", "3", "--steps", "3", "--out", str(tmp_path / "whole")])
    once = read_float32(tmp_path / "whole" / "baseline_lcm.pt")["state_dict"]
    assert all(torch.equal(once[k], v) for k, v in ck["state_dict"].items())
    meta = ck["meta"]
    assert meta["steps"] == 3 and meta["kind"] == "baseline" and meta["teacher"]["from"] == "baseline.pt"
    assert meta["consistency"]["solver_steps"] == 10 and meta["latent_scale"] > 0
    student = load_student(ck).eval()
    # the student's network is the teacher's architecture, and it moved away from the teacher
    tck = read_float32(teacher)
    moved = [k for k, v in tck["state_dict"].items() if not torch.equal(ck["state_dict"][f"net.{k}"], v)]
    assert moved
    curve = (student_run / "curve.json").read_text()
    assert '"step": 3' in curve and '"pass_rate"' in curve
    # both samplers scored on the same validation prompts: the registry's default rule reads this
    val = meta["validation"]
    assert val["prompts"] == 4 and val["fast"]["steps"] == 2 and val["quality"]["steps"] == DIFFUSION_STEPS
    # the teacher is scored, and the student learns by default, at the teacher's method's scale
    assert val["quality"]["guidance"] == val["fast"]["guidance"] == GUIDANCE["baseline"]
    assert meta["consistency"]["guidance"] == GUIDANCE["baseline"]
    assert all(0.0 <= val[s]["pass_rate"] <= 1.0 for s in ("fast", "quality"))
    assert val["fast"]["pass_rate"] == json.loads(curve)[-1]["pass_rate"]
    diff = Diffusion(DiffusionConfig(**meta["diffusion"]))
    fast = ConsistencySampler(student, diff, ConsistencyConfig(**meta["consistency"]))
    quality = GuidedDDIM(load_student(ck).net.eval(), diff)
    cond, empty, frames = torch.randn(2, 384), torch.randn(1, 384), torch.tensor([60, 100])
    shape = (2, *load_vae(WEIGHTS / "vae.pt")[0].latent_shape)  # the shipped VAE's latent
    for sampler in (fast, quality):
        z = sampler(cond, empty, frames, shape, torch.Generator().manual_seed(0), steps=2)
        assert z.shape == shape and torch.isfinite(z).all()


def test_a_resume_under_another_recipe_is_refused(student_run, tiny, tmp_path):  # noqa: F811
    """Rerunning with the same --out resumes: a new --lr or distillation setting there would
    train the rest on another recipe while the meta claimed one for the whole run."""
    import shutil

    data, vae_dir = tiny
    run = tmp_path / "run"
    shutil.copytree(student_run, run)
    args = ["lcm", "--teacher", str(WEIGHTS / "baseline.pt"), "--data", str(data), "--vae", str(vae_dir)]
    args += ["--batch", "4", "--decay", "constant", "--out", str(run), "--steps", "4"]
    with pytest.raises(SystemExit, match=r"another recipe \(--lr was 0\.0002, now 0\.001\)"):
        train_main([*args, "--lr", "1e-3"])
    with pytest.raises(SystemExit, match="distillation settings was"):
        train_main([*args, "--guidance-range", "2", "2"])
    with pytest.raises(SystemExit, match="--batch was 4, now 8"):
        train_main([*args, "--batch", "8"])
    # the recorded recipe, a longer --steps and another sampling step count (how the student
    # samples and is scored, not how it learns): it resumes
    train_main([*args, "--sample-steps", "1"])
    assert json.loads((run / "result.json").read_text())["steps"] == 4
    # a state written before --student-from was recorded started as a copy of the teacher: a
    # resume that names a start of the same shape (the teacher's own file) is another run
    st = torch.load(run / "state.pt", weights_only=False)
    del st["recipe"]["student network"]
    torch.save(st, run / "state.pt")
    with pytest.raises(SystemExit, match=r"another recipe \(student network was None, now '[0-9a-f]{64}'\)"):
        train_main([*args, "--steps", "5", "--student-from", str(WEIGHTS / "baseline.pt")])
    train_main([*args, "--steps", "5"])  # without it: the recorded start, and it resumes
    assert json.loads((run / "result.json").read_text())["steps"] == 5


def test_a_student_goes_on_from_a_student_checkpoint_of_its_teacher(student_run, tiny, tmp_path):  # noqa: F811
    """--init starts from a student file (what ships, where state.pt is not kept): its first
    step starts from those weights, the meta counts both runs' steps, and a student of
    other teacher weights or of the other kind is refused."""
    data, vae_dir = tiny
    first = student_run / "baseline_lcm.pt"
    common = ["lcm", "--teacher", str(WEIGHTS / "baseline.pt"), "--data", str(data), "--vae", str(vae_dir)]
    common += ["--batch", "4", "--decay", "constant", "--lr", "0"]
    train_main([*common, "--steps", "1", "--init", str(first), "--out", str(tmp_path / "on")])
    ck = read_float32(tmp_path / "on" / "baseline_lcm.pt")
    was = read_float32(first)["state_dict"]
    # at a rate of 0 the EMA target stays where the student started: at the checkpoint
    assert all(torch.equal(ck["state_dict"][k], v) for k, v in was.items())
    assert ck["meta"]["steps"] == 4 and ck["meta"]["init"] == {"from": "baseline_lcm.pt", "steps": 3}
    other = tmp_path / "other.pt"
    bad = read_float32(first)
    bad["meta"]["teacher"]["fingerprint"] = "0" * 64
    torch.save(bad, other)
    with pytest.raises(SystemExit, match="other teacher weights"):
        train_main([*common, "--steps", "1", "--init", str(other), "--out", str(tmp_path / "x")])
    with pytest.raises(SystemExit, match="not a guidance_distillation student"):
        train_main(["guidance", *common[1:], "--steps", "1", "--init", str(first), "--out", str(tmp_path / "y")])
    # no step (--steps 0: how a student's default sampling steps are changed and rescored):
    # its weights, its distillation settings (grid, scales) and the record of how it was
    # trained stay the init's, whatever this command's own defaults; only --sample-steps moves
    rescore = ["lcm", "--teacher", str(WEIGHTS / "baseline.pt"), "--data", str(data), "--vae", str(vae_dir)]
    rescore += ["--lr", "0.5", "--batch", "2", "--steps", "0", "--init", str(first), "--sample-steps", "1"]
    train_main(
        [
            *rescore,
            "--solver-steps",
            "20",
            "--guidance-range",
            "1",
            "2",
            "--huber-c",
            "0.1",
            "--out",
            str(tmp_path / "z"),
        ]
    )
    z = read_float32(tmp_path / "z" / "baseline_lcm.pt")
    prior = read_float32(first)["meta"]
    assert all(torch.equal(z["state_dict"][k], v) for k, v in was.items())
    assert z["meta"]["consistency"] == {**prior["consistency"], "sample_steps": 1}
    assert z["meta"]["steps"] == prior["steps"] == 3
    assert (z["meta"]["batch"], z["meta"]["lr"]) == (prior["batch"], prior["lr"])
    assert "init" not in z["meta"]  # the init was a fresh student: it has no init of its own
    # without --sample-steps the init's own steps stay too
    train_main([*rescore[:-2], "--out", str(tmp_path / "z2")])
    assert read_float32(tmp_path / "z2" / "baseline_lcm.pt")["meta"]["consistency"] == prior["consistency"]


def _smaller_baseline(path: Path, ff: int = 256, **meta_changes) -> Path:
    """A baseline denoiser of the shipped one's latent with a narrower feed-forward (fresh
    weights), saved as a run's checkpoint: a network smaller than its teacher."""
    from motion_core.inference.checkpoints import save_run
    from motion_core.models.latent_denoisers import build_denoiser, config_from_dict

    meta = copy.deepcopy(read_float32(WEIGHTS / "baseline.pt")["meta"])
    meta["config"]["ff"] = ff
    meta.update(meta_changes, steps=7)
    torch.manual_seed(3)
    save_run(path, build_denoiser("baseline", config_from_dict("baseline", meta["config"])), meta)
    return path


def test_a_smaller_student_learns_a_larger_teacher_and_its_method_samples_it(tiny, tmp_path):  # noqa: F811
    """--student-from: the student's network is another checkpoint's (here a baseline of half
    the feed-forward width), not a copy of the teacher. Its file records its own config, so the
    method loads it as its "fast" sampler; --init goes on from it with its own network."""
    data, vae_dir = tiny
    small = _smaller_baseline(tmp_path / "small.pt")
    common = ["lcm", "--teacher", str(WEIGHTS / "baseline.pt"), "--data", str(data), "--vae", str(vae_dir)]
    common += ["--batch", "4", "--decay", "constant"]
    train_main([*common, "--steps", "1", "--lr", "0", "--student-from", str(small), "--out", str(tmp_path / "s")])
    ck = read_float32(tmp_path / "s" / "baseline_lcm.pt")
    meta = ck["meta"]
    assert meta["config"]["ff"] == 256 and meta["student_from"]["from"] == "small.pt"
    assert meta["student_from"]["steps"] == 7
    teacher = read_float32(WEIGHTS / "baseline.pt")
    assert meta["params"] < sum(v.numel() for v in teacher["state_dict"].values())
    # at a rate of 0 the student is the smaller network as it came
    was = read_float32(small)["state_dict"]
    assert all(torch.equal(ck["state_dict"][f"net.{k}"], v) for k, v in was.items())
    assert sum(p.numel() for p in load_student(ck).parameters()) == meta["params"]  # built by its own config
    # going on from it rebuilds its own network, and keeps the record of where it came from
    train_main(
        [*common, "--steps", "1", "--init", str(tmp_path / "s" / "baseline_lcm.pt"), "--out", str(tmp_path / "on")]
    )
    on = read_float32(tmp_path / "on" / "baseline_lcm.pt")["meta"]
    assert on["config"]["ff"] == 256 and on["student_from"] == meta["student_from"] and on["steps"] == 2
    # the method takes it as its fast sampler: its teacher is the method's weights
    register_arm("lcm_small", WEIGHTS / "baseline.pt", student=tmp_path / "on" / "baseline_lcm.pt")
    try:
        assert samplers(motion_core.inference.registry.REGISTRY["lcm_small"]) == ("quality", "fast")
        method = motion_core.inference.registry.load_method("lcm_small")
        assert method.denoiser_params("fast") == on["params"] < method.denoiser_params("quality")  # the bench's
        m = motion_core.generate([("a person waves", 2.0)], method="lcm_small", sampler="fast", seed=1)
        assert m.joints.shape == (40, 22, 3) and np.isfinite(m.joints).all()
    finally:
        unregister_arm("lcm_small")
    # rescored without a step (how its default steps change and it ships): its own network,
    # its origin and the record of how it was trained (here: as if by two processes) stay
    init = read_float32(tmp_path / "on" / "baseline_lcm.pt")
    init["meta"]["processes"] = 2
    torch.save(init, tmp_path / "two.pt")
    train_main([*common, "--steps", "0", "--init", str(tmp_path / "two.pt"), "--out", str(tmp_path / "r")])
    r = read_float32(tmp_path / "r" / "baseline_lcm.pt")
    assert r["meta"]["config"]["ff"] == 256 and r["meta"]["student_from"] == meta["student_from"]
    assert r["meta"]["processes"] == 2 and r["meta"]["steps"] == 2
    assert all(torch.equal(r["state_dict"][k], v) for k, v in init["state_dict"].items())
    # a student (of any teacher) as the start: its guidance embedding comes with it
    first = tmp_path / "s" / "baseline_lcm.pt"
    train_main([*common, "--steps", "1", "--lr", "0", "--student-from", str(first), "--out", str(tmp_path / "w")])
    w = read_float32(tmp_path / "w" / "baseline_lcm.pt")
    assert w["meta"]["student_from"]["from"] == "baseline_lcm.pt" and w["meta"]["config"]["ff"] == 256
    assert all(torch.equal(w["state_dict"][k], v) for k, v in read_float32(first)["state_dict"].items())
    # refused: with --init, of another latent, and a resume under another network
    with pytest.raises(SystemExit, match="--student-from starts a new one"):
        train_main(
            [
                *common,
                "--steps",
                "1",
                "--init",
                str(tmp_path / "s" / "baseline_lcm.pt"),
                "--student-from",
                str(small),
                "--out",
                str(tmp_path / "x"),
            ]
        )
    other = _smaller_baseline(tmp_path / "other.pt", latent_scale=2.0)
    with pytest.raises(SystemExit, match="latent_scale differ"):
        train_main([*common, "--steps", "1", "--student-from", str(other), "--out", str(tmp_path / "y")])
    wide = _smaller_baseline(tmp_path / "wide.pt")
    ck_wide = read_float32(wide)
    ck_wide["meta"]["config"]["latent_dim"] = 128
    torch.save(ck_wide, wide)
    with pytest.raises(SystemExit, match=r"config\.latent_dim differ"):
        train_main([*common, "--steps", "1", "--student-from", str(wide), "--out", str(tmp_path / "y2")])
    with pytest.raises(SystemExit, match=r"another recipe \(student network was '[0-9a-f]{64}', now None\)"):
        train_main([*common, "--steps", "2", "--lr", "0", "--out", str(tmp_path / "s")])  # resumed without it


def test_huber_c_is_the_students_loss_and_recorded(tiny, tmp_path):  # noqa: F811
    """--huber-c sets the pseudo-Huber loss's c (recorded with the distillation settings, so a
    resume under another c is refused); 0 or less is refused as it is parsed."""
    data, vae_dir = tiny
    args = ["lcm", "--teacher", str(WEIGHTS / "baseline.pt"), "--data", str(data), "--vae", str(vae_dir)]
    args += ["--batch", "2", "--steps", "1", "--out", str(tmp_path / "c")]
    train_main([*args, "--huber-c", "0.05"])
    assert read_float32(tmp_path / "c" / "baseline_lcm.pt")["meta"]["consistency"]["huber_c"] == 0.05
    with pytest.raises(SystemExit, match=r"another recipe.*huber_c"):
        train_main([*args[:-4], "--steps", "2", "--out", str(tmp_path / "c")])  # the default 0.5
    for bad in ("0", "-1", "inf"):
        with pytest.raises(SystemExit) as refused:
            train_main([*args[:-1], str(tmp_path / f"bad{bad}"), "--huber-c", bad])
        assert refused.value.code == 2  # argparse's: refused as parsed, before any state is read


def test_val_seeds_pool_both_samplers_over_the_seeds_the_default_is_decided_on(student_run, tiny, tmp_path):  # noqa: F811
    """``--val-seeds`` (a rescoring, ``--steps 0``): the meta's two figures, which pick the
    method's default sampler, are each sampler's mean over those seeds on the same prompts,
    scored here seed by seed; the seeds are recorded. Bad seeds, a seed given twice, or
    seeds without --val-every are refused before anything runs."""
    import argparse

    from motion_core.inference.checkpoints import load_denoiser
    from motion_core.inference.registry import sampling_scale
    from motion_core.inference.samplers import student_kind
    from motion_core.train.validation import score_run

    data, vae_dir = tiny
    first = student_run / "baseline_lcm.pt"
    args = ["lcm", "--teacher", str(WEIGHTS / "baseline.pt"), "--data", str(data), "--vae", str(vae_dir)]
    args += ["--batch", "4", "--steps", "0", "--init", str(first), "--val-every", "1", "--val-n", "4"]
    train_main([*args, "--val-seeds", "0", "1", "3", "--out", str(tmp_path / "r")])
    val = read_float32(tmp_path / "r" / "baseline_lcm.pt")["meta"]["validation"]
    assert val["seeds"] == [0, 1, 3]

    ns = argparse.Namespace(data=str(data), pack=None, vae=str(vae_dir), val_n=4, val_source="both")
    student_ck = read_float32(first)
    student = load_student(student_ck).eval()
    teacher_ck = read_float32(WEIGHTS / "baseline.pt")
    teacher = load_denoiser(teacher_ck, "baseline").eval()
    diffusion = Diffusion(DiffusionConfig(**teacher_ck["meta"]["diffusion"]))
    scale = float(teacher_ck["meta"]["latent_scale"])
    w = sampling_scale("baseline", 0.0)
    kind = student_kind(student_ck["meta"])
    fast = [score_run(ns, lambda n: kind.sampler(n, diffusion), student, scale, seed=s) for s in (0, 1, 3)]
    quality = [
        score_run(ns, lambda n: GuidedDDIM(n, diffusion), teacher, scale, steps=DIFFUSION_STEPS, guidance=w, seed=s)
        for s in (0, 1, 3)
    ]
    for name, runs in (("fast", fast), ("quality", quality)):
        assert val[name]["pass_rate"] == pytest.approx(sum(r["pass_rate"] for r in runs) / 3, abs=1e-12)
    # the teacher passes 4 of 4 at seeds 0 and 3 and 3 of 4 at seed 1: seed 0 alone reads otherwise
    assert val["quality"]["pass_rate"] != quality[0]["pass_rate"]
    for bad in (["0", "0"], ["-1"], [str(2**63)]):
        with pytest.raises(SystemExit):
            train_main([*args, "--val-seeds", *bad, "--out", str(tmp_path / "bad")])
    with pytest.raises(SystemExit):
        train_main([*args[:-4], "--val-seeds", "0", "1", "--out", str(tmp_path / "unscored")])
    assert not (tmp_path / "bad").exists() and not (tmp_path / "unscored").exists()


def test_the_students_pooled_figure_takes_seed_0_from_the_curve_and_scores_the_others(monkeypatch, tmp_path):
    """``_compare_with_teacher`` with ``--val-seeds``: the teacher is scored at every seed, the
    student at every seed but 0 (the curve's last score holds it), each pooled over its
    samples; the tiny corpus's student passes alike at every seed, so this is checked with
    a scorer that reads seed and network back."""
    import argparse

    from motion_core.train import consistency

    calls: list[tuple[str, int]] = []

    def fake_score(args, make_sampler, net, scale, steps=None, guidance=None, seed=0):
        who = "teacher" if steps == DIFFUSION_STEPS else "student"
        calls.append((who, seed))
        rate = {"teacher": 0.9, "student": 0.5}[who] + seed / 100
        return {
            "n": 10,
            "pass_rate": rate,
            "direction_accuracy": rate,
            "direction_prompts": 4,
            "sources": {"procedural": {}},
        }

    monkeypatch.setattr(consistency, "score_run", fake_score)
    curve = [{"step": 7, "n": 10, "pass_rate": 0.2, "direction_accuracy": 0.2, "direction_prompts": 4, "sources": {}}]
    (tmp_path / "curve.json").write_text(json.dumps(curve))
    net = torch.nn.Linear(1, 1)
    kind = argparse.Namespace(sampler=lambda n, d: None, sample_steps=1, settings=argparse.Namespace(guidance=2.0))
    args = argparse.Namespace(out=str(tmp_path), val_every=1, val_seeds=[0, 2, 5], teacher=None)
    diffusion = argparse.Namespace(cfg=argparse.Namespace(guidance=3.0))
    out = consistency._compare_with_teacher(args, net, net, diffusion, 1.0, kind, 7)
    assert sorted(calls) == [("student", 2), ("student", 5), ("teacher", 0), ("teacher", 2), ("teacher", 5)]
    assert out["seeds"] == [0, 2, 5]
    assert out["fast"]["pass_rate"] == pytest.approx((0.2 + 0.52 + 0.55) / 3)
    assert out["quality"]["pass_rate"] == pytest.approx((0.9 + 0.92 + 0.95) / 3)
    calls.clear()
    args.val_seeds = None  # the default: seed 0, the student's figure the curve's as it is
    out = consistency._compare_with_teacher(args, net, net, diffusion, 1.0, kind, 7)
    assert calls == [("teacher", 0)] and out["fast"]["pass_rate"] == 0.2 and "seeds" not in out


def test_train_lcm_trajectory_fine_tunes_a_student_and_says_so(student_run, tiny, tmp_path):  # noqa: F811
    """``--objective trajectory`` from a consistency student: the weights move, the meta
    records the objective and the one scale, and the sampler reads the file back as the
    consistency student it still is."""
    from motion_core.inference.samplers import student_kind

    data, vae_dir = tiny
    first = student_run / "baseline_lcm.pt"
    args = ["lcm", "--teacher", str(WEIGHTS / "baseline.pt"), "--data", str(data), "--vae", str(vae_dir)]
    args += ["--batch", "4", "--decay", "constant", "--lr", "1e-3", "--warmup", "0", "--steps", "2"]
    args += ["--objective", "trajectory", "--solver-steps", "5", "--guidance-range", "3", "3"]
    train_main([*args, "--init", str(first), "--out", str(tmp_path / "traj")])
    ck = read_float32(tmp_path / "traj" / "baseline_lcm.pt")
    was = read_float32(first)["state_dict"]
    assert any(not torch.equal(ck["state_dict"][k], v) for k, v in was.items())
    cfg = ck["meta"]["consistency"]
    assert (cfg["objective"], cfg["guidance_min"], cfg["guidance_max"], cfg["guidance"]) == ("trajectory", 3, 3, 3)
    assert student_kind(ck["meta"]).meta_key == "consistency"


def test_a_student_is_not_a_teacher(tiny, tmp_path):  # noqa: F811
    data, vae_dir = tiny
    ck = read_float32(WEIGHTS / "baseline.pt")
    ck["meta"]["consistency"] = CFG.to_dict()
    bad = tmp_path / "student.pt"
    torch.save(ck, bad)
    with pytest.raises(SystemExit, match="consistency student"):
        train_main(["lcm", "--teacher", str(bad), "--data", str(data), "--vae", str(vae_dir), "--out", str(tmp_path)])


def test_generate_takes_the_fast_sampler_where_a_student_exists(student_run):
    info = register_arm("lcm_arm", WEIGHTS / "baseline.pt", student=student_run / "baseline_lcm.pt")
    try:
        assert samplers(info) == ("quality", "fast")
        listed = {m["name"]: m for m in motion_core.methods()}
        assert listed["lcm_arm"]["samplers"] == ["quality", "fast"]
        assert ("fast" in listed["baseline"]["samplers"]) == (WEIGHTS / "baseline_fast.pt").is_file()
        segs = [("a person walks forward", 2.5), ("a person waves with the right hand", 2.0)]
        a = motion_core.generate(segs, method="lcm_arm", seed=3, sampler="fast", steps=2)
        b = motion_core.generate(segs, method="lcm_arm", seed=3, sampler="fast", steps=2)
        c = motion_core.generate(segs, method="lcm_arm", seed=4, sampler="fast", steps=2)
        q = motion_core.generate(segs, method="lcm_arm", seed=3, sampler="quality", steps=2)
        assert a.joints.shape == (90, 22, 3) and np.array_equal(a.joints, b.joints)
        assert (a.sampler, q.sampler) == ("fast", "quality")
        assert not np.array_equal(a.joints, c.joints) and not np.array_equal(a.joints, q.joints)
        # on the skeleton, and continuous where the two segments were joined
        bones = np.linalg.norm(a.joints[:, 1:] - a.joints[:, HUMANML3D.parents[1:]], axis=-1)
        assert np.abs(bones - HUMANML3D.bone_lengths[1:]).max() < 1e-4
        step = np.linalg.norm(np.diff(a.joints[:, 0], axis=0), axis=-1)
        assert step[45:55].max() < 3 * np.median(step) + 0.02
        batch = motion_core.generate_batch(["a person jumps"], 2.0, method="lcm_arm", seed=3, sampler="fast", steps=2)
        one = motion_core.generate([("a person jumps", 2.0)], method="lcm_arm", seed=3, sampler="fast", steps=2)
        assert np.array_equal(batch[0].joints, one.joints)
        # what the student was not distilled for is a clear error, not an extrapolation
        with pytest.raises(InputError, match="1 to 10 steps, not 50"):
            motion_core.generate(segs, method="lcm_arm", sampler="fast", steps=50)
        # MotionLCM's 5-15, widened to the teacher's own scale (the baseline samples at 3)
        with pytest.raises(InputError, match=f"guidance {GUIDANCE['baseline']:g}-15, not 1"):
            motion_core.generate(segs, method="lcm_arm", sampler="fast", guidance=1.0)
    finally:
        unregister_arm("lcm_arm")


@pytest.mark.parametrize(
    ("fast", "quality", "want"),
    # 0.12 against 0.14 is exactly 2 points (0.020000000000000018 in floats)
    [
        (0.40, 0.41, "fast"),
        (0.42, 0.41, "fast"),
        (0.12, 0.14, "fast"),
        (0.385, 0.41, "quality"),
        (None, None, "quality"),
    ],
)
def test_fast_is_the_default_sampler_only_within_2_points_of_its_teacher(student_run, tmp_path, fast, quality, want):
    ck = read(student_run / "baseline_lcm.pt")
    if fast is None:
        ck["meta"].pop("validation")
    else:
        ck["meta"]["validation"]["fast"]["pass_rate"] = fast
        ck["meta"]["validation"]["quality"]["pass_rate"] = quality
    path = tmp_path / "baseline_lcm.pt"
    torch.save(ck, path)
    register_arm("lcm_rule", WEIGHTS / "baseline.pt", student=path)
    try:
        listed = {m["name"]: m for m in motion_core.methods()}["lcm_rule"]
        assert listed["default_sampler"] == want
        opts = listed["sampler_options"]
        assert (opts["fast"]["steps"], opts["fast"]["max_steps"], opts["fast"]["guidance"]) == (
            2,
            10,
            [GUIDANCE["baseline"], 15.0],
        )
        assert opts["quality"]["steps"] == DIFFUSION_STEPS and "DDIM" in opts["quality"]["label"]
        assert motion_core.generate([("a person jumps", 2.0)], method="lcm_rule", steps=2).sampler == want
    finally:
        unregister_arm("lcm_rule")


def test_a_student_shipped_after_its_method_loaded_is_not_offered_until_a_restart(student_run, tmp_path):
    late = tmp_path / "baseline_lcm.pt"
    info = register_arm("lcm_late", WEIGHTS / "baseline.pt", student=late)  # loads it, with no student yet
    try:
        late.write_bytes((student_run / "baseline_lcm.pt").read_bytes())
        # offering it would make "fast" the default of a method that cannot run it
        assert samplers(info) == ("quality",)
        listed = {m["name"]: m for m in motion_core.methods()}["lcm_late"]
        assert listed["samplers"] == ["quality"] and listed["default_sampler"] == "quality"
        assert motion_core.generate([("a person jumps", 2.0)], method="lcm_late", steps=2).sampler == "quality"
    finally:
        unregister_arm("lcm_late")


def test_a_student_of_other_weights_is_left_out_and_the_teacher_still_samples(student_run):
    with pytest.warns(UserWarning, match="distilled from other weights"):
        register_arm("lcm_other", WEIGHTS / "ftmomamba.pt", student=student_run / "baseline_lcm.pt")
    try:
        # not offered at all: the listing, the default and a request for it agree
        listed = {m["name"]: m for m in motion_core.methods()}["lcm_other"]
        assert listed["samplers"] == ["quality"] and listed["default_sampler"] == "quality"
        with pytest.raises(InputError, match="no 'fast' sampler; choose 'quality'"):
            motion_core.generate([("a person walks", 2.0)], method="lcm_other", sampler="fast")
        m = motion_core.generate([("a person walks", 2.0)], method="lcm_other", steps=2)
        assert m.joints.shape == (40, 22, 3)
    finally:
        unregister_arm("lcm_other")


def test_the_teachers_step_to_t0_is_its_guided_x0():
    from motion_core.train.consistency import teacher_step

    teacher = _net()
    diff = Diffusion(DiffusionConfig(prediction="sample"))
    x, t = torch.randn(3, 2, 32), torch.tensor([1, 101, 901])
    cond, uncond, frames, w = (
        torch.randn(3, 384),
        torch.randn(3, 384),
        torch.tensor([40, 80, 196]),
        torch.tensor([5.0, 7.5, 15.0]),
    )
    with torch.no_grad():
        o_c, o_u = teacher(x, t, cond, frames), teacher(x, t, uncond, frames)
    guided = o_u + w.view(-1, 1, 1) * (o_c - o_u)
    at_zero = teacher_step(teacher, diff, x, t, torch.zeros_like(t), cond, uncond, frames, w)
    # float32 rounding, relative: the batched pass rounds apart from the two single ones
    # (by 1.05e-5 on values up to 3 on one AMD CPU), and w = 15 multiplies that
    assert (at_zero - guided).abs().max() < 1e-5 * (1 + guided.abs().max())
    # one step down the grid is DDIM's update with the guided output, as the sampler takes it
    down = teacher_step(teacher, diff, x, t, (t - 100).clamp(min=0), cond, uncond, frames, w)
    a = diff.alphas_cumprod[(t - 100).clamp(min=0)].view(-1, 1, 1)
    eps = (x - diff.alphas_cumprod[t].sqrt().view(-1, 1, 1) * guided) / (1 - diff.alphas_cumprod[t]).sqrt().view(
        -1, 1, 1
    )
    want = torch.where((t > 100).view(-1, 1, 1), a.sqrt() * guided + (1 - a).sqrt() * eps, guided)
    assert (down - want).abs().max() < 1e-4


def test_a_sampler_a_method_lacks_is_a_clear_error():
    with pytest.raises(InputError, match="no 'fast' sampler; choose 'quality'"):
        motion_core.generate([("a person walks", 2.0)], method="kmm", sampler="fast")


def test_evaluations_name_the_sampler_they_measured(student_run, tiny):  # noqa: F811
    """The tables and the bench take "NAME:SAMPLER" and record the sampler of every row, so a
    student becoming a method's default cannot slip into figures measured under its name."""
    from motion_core.eval.bench import bench_ops
    from motion_core.eval.tables import verifier_table
    from motion_core.inference.generation import method_spec, row_name

    data, _ = tiny
    from motion_core.inference.registry import default_sampler

    info = register_arm("lcm_eval", WEIGHTS / "baseline.pt", student=student_run / "baseline_lcm.pt")
    try:
        assert method_spec("lcm_eval") == ("lcm_eval", default_sampler(info))  # the default as it is now
        assert method_spec("lcm_eval:quality") == ("lcm_eval", "quality")
        assert method_spec("lcm_eval:fast") == ("lcm_eval", "fast")
        with pytest.raises(InputError, match="no 'turbo' sampler"):
            method_spec("lcm_eval:turbo")
        with pytest.raises(UnknownMethod, match="unknown method 'no_such_method'"):
            method_spec("no_such_method")
        # rows are named by what ran: the bare name for "quality", NAME:fast for the student, so a
        # bare name in the command writes the row of the method's default as it is now
        table = verifier_table(["lcm_eval:quality", "lcm_eval:fast"], data, n=2)
        assert (table["lcm_eval"]["sampler"], table["lcm_eval:fast"]["sampler"]) == ("quality", "fast")
        assert row_name("lcm_eval", default_sampler(info)) in verifier_table(["lcm_eval"], data, n=1)
        ops = bench_ops(["lcm_eval:fast"], frames=40, steps=(1, 2), repeats=1)
        assert ops["lcm_eval:fast"]["sampler"] == "fast" and ops["lcm_eval:fast"]["ops_per_step"] > 0
    finally:
        unregister_arm("lcm_eval")


def test_lcm_takes_a_guidance_range_and_refuses_a_bad_one():
    """Without --guidance-range the student learns MotionLCM's 5-15 (no teacher file here, so
    the default scale 7.5 lies inside it); with 4 4 it is a student of one scale, the
    sampler's default sits there, and a range with MIN above MAX or a scale of 0 is refused."""
    import argparse

    from motion_core.train.consistency import consistency_training

    def kind(rng):
        return consistency_training(argparse.Namespace(solver_steps=5, sample_steps=2, guidance_range=rng))

    c = kind(None).settings
    assert (c.guidance_min, c.guidance_max, c.guidance) == (5.0, 15.0, 7.5)
    c = kind([4.0, 4.0]).settings
    assert (c.guidance_min, c.guidance_max, c.guidance, c.solver_steps) == (4.0, 4.0, 4.0, 5)
    for bad in ([9.0, 7.5], [0.0, 7.5]):
        with pytest.raises(SystemExit, match="guidance-range"):
            kind(bad)


def test_the_unrolled_sampler_is_the_fast_sampler_and_carries_gradients():
    """``consistency_unroll`` from the sampler's own draws gives the sampler's motion (the
    trajectory objective trains through the path users sample), and its output has a
    gradient with respect to the student's weights."""
    diff = Diffusion(DiffusionConfig(prediction="sample"))
    student = GuidedStudent(_net()).eval()
    cond, empty, frames = torch.randn(2, 384), torch.randn(1, 384), torch.tensor([40, 196])
    w = torch.full((2,), 4.0)
    cfg = ConsistencyConfig(solver_steps=5, guidance=4.0, guidance_min=4.0, guidance_max=4.0)
    want = ConsistencySampler(student, diff, cfg)(cond, empty, frames, (2, 2, 32), torch.Generator().manual_seed(5))
    g = torch.Generator().manual_seed(5)
    draws = [torch.randn((2, 2, 32), generator=g) for _ in range(2)]

    def x0_fn(x, t):
        return diff.split(student(x, t, cond, frames, w), x, t)[1]

    got = consistency_unroll(x0_fn, diff, cfg, draws[0], draws[1:])
    # not bit for bit: without a gradient torch's transformer layers take their fused path
    assert (got - want).abs().max() < 1e-5
    got.square().sum().backward()
    grads = [p.grad for p in student.parameters() if p.grad is not None]
    assert grads and any(gr.abs().sum() > 0 for gr in grads)


def test_the_trajectory_objective_pulls_the_students_sample_onto_the_teachers():
    """A student that starts as its teacher, whose 2 unguided consistency steps land far from
    the teacher's guided 5-step sample: 30 Adam steps on the trajectory loss for one fixed
    batch bring its sample at least 3x closer to the teacher's from the same noise."""
    from motion_core.train.consistency import trajectory_loss

    diff = Diffusion(DiffusionConfig(prediction="sample"))
    teacher = _net()
    for p in teacher.parameters():
        p.requires_grad_(False)
    student = GuidedStudent(_net().train())
    cfg = ConsistencyConfig(solver_steps=5, guidance=4.0, guidance_min=4.0, guidance_max=4.0, objective="trajectory")
    z0, cond, empty = torch.zeros(4, 2, 32), torch.randn(4, 384), torch.randn(384)
    frames = torch.tensor([40, 80, 120, 196])

    def loss() -> torch.Tensor:
        return trajectory_loss(student, teacher, diff, cfg, z0, cond, empty, frames, torch.Generator().manual_seed(0))

    opt = torch.optim.Adam(student.parameters(), lr=3e-3)
    first = loss().item()
    for _ in range(30):
        opt.zero_grad()
        loss().backward()
        opt.step()
    assert loss().item() < first / 3


def test_the_trajectory_target_at_guidance_1_is_the_conditional_sample():
    """At w = 1 the teacher's sampler makes one (conditional) pass per step: the target is
    that sample, not a shape error."""
    from motion_core.train.consistency import trajectory_loss

    diff = Diffusion(DiffusionConfig(prediction="sample"))
    teacher = _net()
    cfg = ConsistencyConfig(solver_steps=5, guidance=1.0, guidance_min=1.0, guidance_max=1.0, objective="trajectory")
    z0, cond, empty, frames = torch.zeros(2, 2, 32), torch.randn(2, 384), torch.randn(384), torch.tensor([40, 196])
    student = GuidedStudent(_net())
    loss = trajectory_loss(student, teacher, diff, cfg, z0, cond, empty, frames, torch.Generator().manual_seed(0))
    assert torch.isfinite(loss) and loss > 0


def test_lcm_trajectory_trains_one_guidance_scale():
    import argparse

    from motion_core.train.consistency import consistency_training

    args = argparse.Namespace(solver_steps=5, sample_steps=2, objective="trajectory")
    with pytest.raises(SystemExit, match="one guidance scale"):
        consistency_training(argparse.Namespace(**vars(args), guidance_range=[3.0, 5.0]))
    c = consistency_training(argparse.Namespace(**vars(args), guidance_range=[4.0, 4.0])).settings
    assert c.objective == "trajectory" and c.guidance == 4.0


def test_ddim_renoising_keeps_the_start_noises_direction_and_needs_no_fresh_draw():
    """renoise="ddim": the second step starts at sqrt(a') x0 + sqrt(1 - a') eps, with eps the
    noise the first step's x_t and x_0 imply, so the sample is a function of the start noise
    alone (the re-noising draws are ignored); "random" uses them."""
    diff = Diffusion(DiffusionConfig(prediction="sample"))
    seen = []

    def x0_fn(x, t):
        seen.append(x.clone())
        return 0.5 * x.flip(-1)

    x = torch.randn(2, 2, 32, generator=torch.Generator().manual_seed(0))
    other = [torch.randn(2, 2, 32), torch.randn(2, 2, 32)]
    cfg = ConsistencyConfig(solver_steps=5, renoise="ddim")
    a_run = consistency_unroll(x0_fn, diff, cfg, x, other[:1])
    second = seen[1]
    ts = sample_timesteps(diff, cfg, 2)
    a, a2 = diff.alphas_cumprod[ts[0]], diff.alphas_cumprod[ts[1]]
    x0 = consistency_fn(lambda x, t: 0.5 * x.flip(-1), x, torch.full((2,), ts[0]), cfg)
    eps = (x - a.sqrt() * x0) / (1 - a).sqrt()
    assert (second - (a2.sqrt() * x0 + (1 - a2).sqrt() * eps)).abs().max() < 1e-5
    assert torch.equal(consistency_unroll(x0_fn, diff, cfg, x, other[1:]), a_run)
    rnd = ConsistencyConfig(solver_steps=5)
    assert not torch.allclose(
        consistency_unroll(x0_fn, diff, rnd, x, other[:1]), consistency_unroll(x0_fn, diff, rnd, x, other[1:])
    )
    with pytest.raises(ValueError, match="renoise"):
        consistency_unroll(x0_fn, diff, ConsistencyConfig(solver_steps=5, renoise="other"), x, other[:1])


def test_each_shipped_student_samples_at_its_teachers_scale():
    """A method's scale and its student's move together (Motion Mamba's 4 became 3 on 2026-11-29
    with a student distilled at 3): a student of another scale than its teacher's sampler would be
    compared, by the 2-point rule, with a sampler it never learned."""
    offered = [m for m in motion_core.methods() if "fast" in m["sampler_options"]]
    assert {m["name"] for m in offered} >= {"motion_mamba", "ftmomamba", "baseline"}
    for m in offered:
        fast, quality = m["sampler_options"]["fast"], m["sampler_options"]["quality"]
        assert fast["default_guidance"] == quality["default_guidance"] == m["default_guidance"], m["name"]
        assert fast["guidance"][0] <= m["default_guidance"] <= fast["guidance"][1], m["name"]


@pytest.mark.parametrize("flag", ["--teacher", "--init", "--student-from"])
def test_a_missing_checkpoint_is_a_usage_error_not_a_traceback(flag, tmp_path, capsys):
    args = ["lcm", "--teacher", str(WEIGHTS / "baseline.pt"), "--data", str(tmp_path), "--out", str(tmp_path / "o")]
    if flag == "--teacher":
        args[2] = str(tmp_path / "none.pt")
    else:
        args += [flag, str(tmp_path / "none.pt")]
    with pytest.raises(SystemExit) as refused:
        train_main(args)
    assert (
        refused.value.code == 2 and f"{flag} {tmp_path / 'none.pt'}: no such checkpoint file" in capsys.readouterr().err
    )
