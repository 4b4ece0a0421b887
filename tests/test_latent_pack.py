"""The pack of a denoiser's training caches (train/latent_pack.py): what a lent GPU trains on."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import torch

from motion_core.train.latent_pack import has_validation, read_pack, read_validation, write_pack
from tests.test_denoiser_training import tiny  # noqa: F401  (the module-scoped corpus fixture)


def _caches(rng: np.random.Generator) -> dict[str, np.ndarray]:
    """Caches shaped as encode_corpus's: 5 clips of up to 6 tokens (4 frames each), padded
    as the encoder leaves them (mu 0, log-variance -30), 12 captions of which 4 repeat."""
    frames = np.array([24, 3, 13, 20, 9])
    tokens = (frames + 3) // 4
    mu = rng.normal(size=(5, 6, 3)).astype(np.float32)
    lv = rng.uniform(-12, -4, size=(5, 6, 3)).astype(np.float32)
    pad = np.arange(6)[None] >= tokens[:, None]
    mu[pad], lv[pad] = 0.0, -30.0
    distinct = rng.normal(size=(8, 384)).astype(np.float32)
    return {
        "mu": mu,
        "logvar": lv,
        "frames": frames,
        "text": distinct[[0, 1, 2, 3, 4, 5, 6, 7, 0, 1, 2, 3]],
        "text_clip": np.array([0, 0, 1, 1, 2, 2, 3, 3, 4, 4, 4, 4]),
        "empty": rng.normal(size=384).astype(np.float32),
    }


def test_a_pack_gives_back_the_caches_within_its_rounding(tmp_path):
    data = _caches(np.random.default_rng(0))
    path = write_pack(data, "corpus" + "vaehash", 4, tmp_path / "p.npz")
    back = read_pack(path, "vaehash")
    for k in ("mu", "logvar", "text"):
        assert back[k].shape == data[k].shape and back[k].dtype == np.float32
    # padding exactly as the cache has it: a step's noise there stays exp(-15), not 1
    pad = np.arange(6)[None] >= ((data["frames"] + 3) // 4)[:, None]
    assert (back["mu"][pad] == 0).all() and (back["logvar"][pad] == -30).all()
    assert np.abs(back["mu"] - data["mu"]).max() <= 1e-3 * np.abs(data["mu"]).max()
    assert np.abs(back["logvar"] - data["logvar"]).max() <= 0.0625 + 1e-6  # half a 1/8 step
    np.testing.assert_allclose(back["text"], data["text"], atol=2e-3)
    np.testing.assert_array_equal(back["text_clip"], data["text_clip"])
    np.testing.assert_array_equal(back["frames"], data["frames"])
    np.testing.assert_array_equal(back["empty"], data["empty"])
    # the repeated captions are stored once
    assert len(np.load(path)["text"]) == 8


def test_a_pack_goes_into_a_folder_that_does_not_exist_yet(tmp_path):
    # the GPU script's `--out .pack/temporal.npz` on a fresh clone, where .pack/ is not there
    path = write_pack(_caches(np.random.default_rng(2)), "corpus" + "vaehash", 4, tmp_path / "new" / "p.npz")
    assert path.is_file() and len(read_pack(path, "vaehash")["frames"]) == 5


def test_a_pack_of_another_vaes_latents_is_refused(tmp_path):
    path = write_pack(_caches(np.random.default_rng(1)), "corpus" + "vae-a", 4, tmp_path / "p.npz")
    with pytest.raises(SystemExit, match="another VAE"):
        read_pack(path, "vae-b")


def test_without_data_a_denoiser_needs_a_pack_and_no_validation(capsys):
    from motion_core.train.__main__ import main

    with pytest.raises(SystemExit):
        main(["motion_mamba", "--vae", "runs/none"])
    assert "--data is required" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        main(["motion_mamba", "--pack", "p.npz", "--val-every", "100"])
    assert "--data is required" in capsys.readouterr().err


def test_a_denoiser_and_a_student_train_on_a_pack_and_stop_at_their_time_limit(tiny, tmp_path):  # noqa: F811
    """What a lent GPU runs, on the CPU: `train pack` from a corpus, then a denoiser and a
    guidance student trained on the pack alone (no --data), each stopped by --time-limit
    long before --steps, each writing its checkpoint as a finished run would."""
    from motion_core.inference.checkpoints import WEIGHTS, read_float32
    from motion_core.train.__main__ import main as train_main

    data, vae_dir = tiny
    pack = tmp_path / "p.npz"
    train_main(["pack", "--data", str(data), "--vae", str(vae_dir), "--out", str(pack)])
    den = tmp_path / "den"
    common = ["--pack", str(pack), "--vae", str(vae_dir), "--batch", "4", "--steps", "100000", "--time-limit", "2"]
    train_main(["baseline", *common, "--prediction", "sample", "--out", str(den), "--stage", str(tmp_path / "s.pt")])
    meta = read_float32(tmp_path / "s.pt")["meta"]
    assert 0 < meta["stage_steps"] < 100000 and meta["data"] == "pack p.npz"
    # the last step's state was saved with it (--save-every is far off): a rerun resumes there
    assert torch.load(den / "state.pt", map_location="cpu", weights_only=False)["step"] == meta["stage_steps"]
    stu = tmp_path / "stu"
    train_main(["guidance", "--teacher", str(WEIGHTS / "baseline.pt"), *common, "--out", str(stu)])
    res = read_float32(stu / "baseline_guidance.pt")["meta"]
    assert 0 < res["steps"] < 100000 and "validation" not in res  # nothing validated, nothing claimed
    assert torch.load(stu / "state.pt", map_location="cpu", weights_only=False)["step"] == res["steps"]


def test_log_variances_outside_the_packs_range_are_refused(tmp_path):
    data = _caches(np.random.default_rng(2))
    data["logvar"][0, 0, 0] = 3.0  # above 1.875: clipping it would change the posterior silently
    with pytest.raises(ValueError, match="log-variances outside"):
        write_pack(data, "x", 4, tmp_path / "p.npz")


def test_a_pack_holds_the_validation_prompts_and_a_run_on_it_scores_them_as_the_corpus_does(tiny, tmp_path):  # noqa: F811
    """`train pack --val-n N` keeps the validation prompts with their embeddings, so a run on
    the pack alone (a lent GPU: no corpus, no text encoder) scores --val-every on the same
    prompts, and --stage-best keeps the best-scored weights as its stage."""
    import json

    from motion_core.inference.checkpoints import load_denoiser, load_vae, read_float32, vae_normalizer
    from motion_core.inference.samplers import GuidedDDIM
    from motion_core.nn.diffusion import Diffusion, DiffusionConfig
    from motion_core.nn.text import get_text_encoder
    from motion_core.train.__main__ import main as train_main
    from motion_core.train.validation import validation_pass_rate, validation_prompts

    data, vae_dir = tiny
    pack = tmp_path / "p.npz"
    train_main(["pack", "--data", str(data), "--vae", str(vae_dir), "--out", str(pack), "--val-n", "6"])
    assert has_validation(pack)
    clips = validation_prompts(data, 6, "procedural")
    held = read_validation(pack, "procedural")
    assert held["n"] == 6 and held["captions"] == [c.captions[0] for c in clips]
    assert held["frames"] == [c.frames for c in clips] and held["labels"] == [c.labels for c in clips]
    enc = get_text_encoder()
    np.testing.assert_allclose(held["embeddings"], enc.encode(held["captions"]).numpy(), atol=1e-6)
    np.testing.assert_allclose(held["empty"], enc.encode([""]).numpy()[0], atol=1e-6)
    assert read_validation(pack, "real") is None  # this corpus has no motion capture

    run, stage = tmp_path / "run", tmp_path / "stage.pt"
    args = ["baseline", "--pack", str(pack), "--vae", str(vae_dir), "--batch", "4", "--steps", "4"]
    args += ["--prediction", "sample", "--val-every", "2", "--val-n", "6", "--val-steps", "2"]
    train_main([*args, "--out", str(run), "--stage", str(stage), "--stage-best"])
    curve = json.loads((run / "curve.json").read_text())
    assert [c["step"] for c in curve] == [2, 4] and all(set(c["sources"]) == {"procedural"} for c in curve)
    ck = read_float32(stage)
    best = max(c["pass_rate"] for c in curve)
    assert ck["meta"]["validation"]["pass_rate"] == best
    assert ck["meta"]["stage_steps"] == max(c["step"] for c in curve if c["pass_rate"] == best)
    # the staged weights score the same from the corpus (captions encoded here) as from the pack
    vae, vmeta = load_vae(vae_dir / "vae.pt")
    sampler = GuidedDDIM(load_denoiser(ck, "baseline").eval(), Diffusion(DiffusionConfig(**ck["meta"]["diffusion"])))
    scale = float(ck["meta"]["latent_scale"])
    from_corpus = validation_pass_rate(sampler, vae, vae_normalizer(vmeta), scale, data, 6, steps=2)
    from_pack = validation_pass_rate(sampler, vae, vae_normalizer(vmeta), scale, pack, 6, steps=2)
    assert from_corpus == from_pack
    with pytest.raises(ValueError, match="--val-n 6, not 8"):
        validation_pass_rate(sampler, vae, vae_normalizer(vmeta), scale, pack, 8, steps=2)


@pytest.mark.long
def test_stage_best_keeps_the_best_scored_step_across_a_failed_score_and_a_resume(tiny, tmp_path, monkeypatch):  # noqa: F811
    """--stage-best with scripted scores: the stage is the best-scored step's weights, a
    score that fails does not stop the run, and a resumed run keeps the best it had."""
    import json

    from motion_core.inference.checkpoints import read_float32
    from motion_core.train import denoiser
    from motion_core.train.__main__ import main as train_main

    data, vae_dir = tiny
    pack = tmp_path / "p.npz"
    train_main(["pack", "--data", str(data), "--vae", str(vae_dir), "--out", str(pack), "--val-n", "6"])
    scores = {2: 0.5, 4: 0.25, 6: RuntimeError("out of memory"), 8: 0.375}

    def scripted(args, model, diff, scale, step, loss):
        score = scores[step]
        if isinstance(score, Exception):
            raise score
        path = Path(args.out) / "curve.json"
        curve = json.loads(path.read_text()) if path.is_file() else []
        curve.append({"step": step, "n": 6, "pass_rate": score, "sources": {}, "loss_ema": loss})
        path.write_text(json.dumps(curve))
        return curve

    monkeypatch.setattr(denoiser, "_validate", scripted)
    run, stage = tmp_path / "run", tmp_path / "stage.pt"
    args = ["baseline", "--pack", str(pack), "--vae", str(vae_dir), "--batch", "4", "--val-every", "2"]
    args += ["--val-n", "6", "--prediction", "sample", "--save-every", "2", "--out", str(run), "--stage", str(stage)]
    train_main([*args, "--stage-best", "--steps", "6"])  # the score at 6 fails; the run still ends
    assert read_float32(stage)["meta"]["stage_steps"] == 2
    assert json.loads((run / "result.json").read_text())["stage_steps"] == 6
    train_main([*args, "--stage-best", "--steps", "8"])  # resumed at 6: 0.375 is below the 0.5 it had
    assert read_float32(stage)["meta"]["stage_steps"] == 2
    assert read_float32(stage)["meta"]["validation"]["pass_rate"] == 0.5
    # --ship with --stage-best ships the best-scored weights, not the last
    monkeypatch.setattr(denoiser, "WEIGHTS", tmp_path / "weights")
    train_main([*args, "--stage-best", "--steps", "8", "--ship"])
    assert read_float32(tmp_path / "weights" / "baseline.pt")["meta"]["stage_steps"] == 2
    with pytest.raises(SystemExit, match="--val-n 6, not 5"):
        train_main([*args[:-6], "--val-n", "5", "--out", str(tmp_path / "other"), "--steps", "2"])


@pytest.mark.long
def test_the_gpu_script_trains_every_kind_from_scratch_or_from_the_shipped_weights(tiny, tmp_path):  # noqa: F811
    """`scripts/train_on_gpu.sh`, run here on a tiny corpus's pack as a lent GPU would run it
    (a bug found there costs minutes of a budget of fifteen): FROM_SCRATCH=1 STEPS=N trains
    each named kind from fresh weights for N steps with the same recipe (the
    one-recipe comparison); INIT_DIR=DIR goes on from DIR/KIND.pt (its committed stages);
    without either each goes on from its staged or shipped weights; a job the time limit
    stops short of STEPS fails the script; WARMUP applies to a kind going on too; STUDENT
    distils the shipped teacher or TEACHER_DIR's, and refuses the two teacher-start settings,
    the settings of a teacher's training (TRAIN_FLAGS, VAL_EVERY, VAL_STEPS, WARMUP) and an
    unknown kind; VAL_STEPS without VAL_EVERY, and TEACHER_DIR without STUDENT, are refused."""
    import os
    import subprocess
    import sys

    from motion_core.inference.checkpoints import read_float32
    from motion_core.train.__main__ import main as train_main
    from tests.conftest import REPO

    data, vae_dir = tiny
    pack = tmp_path / "p.npz"
    train_main(["pack", "--data", str(data), "--vae", str(vae_dir), "--out", str(pack)])
    # the script reads its settings from the environment: none may leak in from the caller's
    settings = {"KINDS", "STEPS", "INIT_DIR", "FROM_SCRATCH", "STUDENT", "STUDENT_FLAGS", "TRAIN_FLAGS", "TEACHER_DIR"}
    settings |= {"VAL_EVERY", "VAL_STEPS", "WARMUP", "VAE"}
    env = {k: v for k, v in os.environ.items() if k not in settings} | {
        "PY": sys.executable,
        "RUNS": str(tmp_path / "runs"),
    }

    def run(out: str, kinds: list[str], secs: str = "600", **extra: str) -> subprocess.CompletedProcess:
        cmd = ["bash", "scripts/train_on_gpu.sh", str(pack), secs, str(tmp_path / out), "4"]
        return subprocess.run(
            cmd, cwd=REPO, env={**env, "KINDS": " ".join(kinds), **extra}, capture_output=True, text=True
        )

    def metas(out: str, kinds: list[str], done: subprocess.CompletedProcess) -> dict[str, dict]:
        logs = "".join(
            (tmp_path / out / f"{k}.log").read_text() for k in kinds if (tmp_path / out / f"{k}.log").is_file()
        )
        assert done.returncode == 0, done.stdout + done.stderr + logs
        return {k: read_float32(tmp_path / out / f"{k}.pt")["meta"] for k in kinds}

    two = ["baseline", "motion_mamba"]
    fresh = metas("fresh", two, run("fresh", two, FROM_SCRATCH="1", STEPS="3", WARMUP="2"))
    for meta in fresh.values():
        assert (meta["steps"], meta["stage_steps"], meta["schedule"]["warmup"]) == (3, 3, 2)
        assert meta["init"] is None and meta["batch"] == 4 and meta["lr"] == 3e-4
    assert fresh["baseline"]["config"]["latent_tokens"] == fresh["motion_mamba"]["config"]["latent_tokens"]
    # FROM_SCRATCH=0 is off, and FTMoMamba goes on from its stage in stages/ where one is
    on = ["baseline", "ftmomamba"]
    going_on = metas("on", on, run("on", on, FROM_SCRATCH="0", STEPS="2"))
    for kind, meta in going_on.items():
        staged = REPO / "stages" / f"{kind}.pt"
        start = staged if staged.is_file() else REPO / "motion_core" / "weights" / f"{kind}.pt"
        start_meta = read_float32(start)["meta"]
        before = start_meta["steps"]
        # the start's own lineage travels in the record (train --init keeps it)
        lineage = {k: start_meta[k] for k in ("teacher", "pruned", "init") if start_meta.get(k)}
        assert meta["init"] == {"from": start.name, "steps": before, **lineage} and meta["steps"] == before + 2
        assert meta["schedule"]["warmup"] == 0
    # INIT_DIR: every kind goes on from its file there (the one-recipe stages), rate held
    cont = metas("cont", two, run("cont", two, INIT_DIR=str(tmp_path / "fresh"), STEPS="2"))
    for meta in cont.values():
        assert meta["init"] == {"from": f"{meta['kind']}.pt", "steps": 3} and meta["steps"] == 5
        assert meta["schedule"]["warmup"] == 0
    # a warm-up asked of a kind going on is given, not dropped
    one = ["baseline"]
    warm = metas("warm", one, run("warm", one, INIT_DIR=str(tmp_path / "fresh"), STEPS="2", WARMUP="1"))
    assert warm["baseline"]["schedule"]["warmup"] == 1
    # TEACHER_DIR: a student of a stage, not of the shipped teacher
    staged = run("staged", ["baseline"], STUDENT="lcm", STEPS="2", TEACHER_DIR=str(tmp_path / "fresh"))
    assert staged.returncode == 0, staged.stdout + staged.stderr
    student_meta = read_float32(tmp_path / "staged" / "baseline_lcm.pt")["meta"]
    assert student_meta["teacher"]["from"] == "baseline.pt" and student_meta["teacher"]["steps"] == 3
    for extra, message in [
        ({"VAL_STEPS": "2"}, "it needs VAL_EVERY"),
        ({"TEACHER_DIR": str(tmp_path / "fresh")}, "TEACHER_DIR names the teachers a STUDENT"),
    ]:
        refused = run("refused", two, STEPS="2", **extra)
        assert refused.returncode == 2 and message in refused.stderr, (extra, refused.stderr)
        assert not (tmp_path / "refused").exists()  # refused before anything is written
    both = run("both", two, INIT_DIR=str(tmp_path / "fresh"), FROM_SCRATCH="1", STEPS="2")
    assert both.returncode == 2 and "contradict" in both.stderr and not (tmp_path / "both").exists()
    missing = run("missing", ["ftmomamba"], INIT_DIR=str(tmp_path / "fresh"), STEPS="2")
    assert missing.returncode == 2 and "holds no ftmomamba.pt" in missing.stderr
    assert not (tmp_path / "missing").exists()  # refused before anything is written
    # a student is distilled from the shipped teacher: a teacher's start, or a setting of a
    # teacher's training, is refused rather than ignored, and so is a student of no known kind
    refusals = [
        ({"INIT_DIR": str(tmp_path / "fresh")}, "do not apply"),
        ({"FROM_SCRATCH": "1"}, "do not apply"),
        ({"VAL_EVERY": "5"}, "VAL_EVERY sets a teacher's training"),
        ({"TRAIN_FLAGS": "--tf32"}, "TRAIN_FLAGS sets a teacher's training"),
        ({"WARMUP": "3"}, "WARMUP sets a teacher's training"),
        ({"VAL_STEPS": "5"}, "VAL_STEPS sets a teacher's training"),
        ({"TEACHER_DIR": str(tmp_path / "cont" / "x")}, "holds no baseline.pt"),
        ({"STUDENT": "lcmm"}, "STUDENT must be lcm or guidance"),
    ]
    for extra, message in refusals:
        student = run("student", ["baseline"], **{"STUDENT": "lcm", "STEPS": "2", **extra})
        assert student.returncode == 2 and message in student.stderr, (extra, student.stderr)
        assert not (tmp_path / "student").exists()  # refused before anything is written
    short = run("short", ["baseline"], secs="1", FROM_SCRATCH="1", STEPS="100000")
    assert short.returncode != 0 and "not 100000" in short.stderr


def test_gpu_slim_links_out_what_a_call_does_not_read_and_restore_brings_it_back(tmp_path):
    """`scripts/gpu_slim.sh` in a clone of this checkout (it rewrites the working tree): by
    default the one-recipe stages and KMM's tokeniser stage go with KMM, the evaluator and the
    students; ONE_RECIPE=1
    keeps them and links out the teachers instead; `restore` leaves the clone as committed,
    and a file with uncommitted changes, or one git does not track, is never linked."""
    import os
    import shutil
    import subprocess

    from tests.conftest import REPO

    clone = tmp_path / "clone"
    subprocess.run(["git", "clone", "-q", str(REPO), str(clone)], check=True)

    def git(*args: str) -> None:
        subprocess.run(["git", "-c", "user.name=t", "-c", "user.email=t@t", *args], cwd=clone, check=True)

    shutil.copy(REPO / "scripts" / "gpu_slim.sh", clone / "scripts" / "gpu_slim.sh")  # the working tree's
    stage_dir = clone / "stages" / "one_recipe"
    stage_dir.mkdir(parents=True, exist_ok=True)
    for kind in ("motion_mamba", "ftmomamba", "baseline"):
        if not (stage_dir / f"{kind}.pt").exists():
            (stage_dir / f"{kind}.pt").write_bytes(b"stage")
    tokeniser_stage = clone / "stages" / "grown" / "rvq.pt"
    generator_stage = clone / "stages" / "grown" / "kmm.pt"
    baseline_stage = clone / "stages" / "grown" / "baseline.pt"
    for stage in (tokeniser_stage, generator_stage, baseline_stage):
        if not stage.exists():
            stage.parent.mkdir(parents=True, exist_ok=True)
            stage.write_bytes(b"stage")
    git("add", "scripts", "stages")
    git("commit", "-q", "--allow-empty", "-m", "the script and stages under test")
    weights = clone / "motion_core" / "weights"

    def slim(**env: str) -> subprocess.CompletedProcess:
        return subprocess.run(
            ["bash", "scripts/gpu_slim.sh"], cwd=clone, env={**os.environ, **env}, capture_output=True, text=True
        )

    def restore() -> None:
        subprocess.run(["bash", "scripts/gpu_slim.sh", "restore"], cwd=clone, check=True, capture_output=True)
        assert subprocess.run(["git", "status", "--porcelain"], cwd=clone, capture_output=True, text=True).stdout == ""

    done = slim()
    assert done.returncode == 0, done.stderr
    assert (weights / "kmm.pt").is_symlink() and (stage_dir / "ftmomamba.pt").is_symlink()
    assert tokeniser_stage.is_symlink() and generator_stage.is_symlink()  # KMM's stages go with KMM
    assert baseline_stage.is_symlink()
    assert not (weights / "ftmomamba.pt").is_symlink() and not (weights / "vae.pt").is_symlink()
    restore()
    done = slim(ONE_RECIPE="1")
    assert done.returncode == 0, done.stderr
    assert (weights / "ftmomamba.pt").is_symlink() and (weights / "kmm.pt").is_symlink()
    assert not (stage_dir / "ftmomamba.pt").is_symlink() and not (weights / "vae.pt").is_symlink()
    # the other mode on top of an unrestored slim: what it would send is a link, refused
    restore()
    assert slim().returncode == 0
    mixed = slim(ONE_RECIPE="1")
    assert mixed.returncode == 1 and "restore first" in mixed.stderr
    restore()
    (weights / "kmm.pt").write_bytes(b"changed")
    refused = slim()
    assert refused.returncode == 1 and "uncommitted changes" in refused.stderr
    assert (weights / "kmm.pt").read_bytes() == b"changed" and not (weights / "ftmomamba_fast.pt").is_symlink()
    git("checkout", "--", "motion_core/weights/kmm.pt")
    git("rm", "-q", "--cached", "stages/one_recipe/baseline.pt")  # a file git could not bring back
    kept = (stage_dir / "baseline.pt").read_bytes()
    refused = slim()
    assert refused.returncode == 1 and "untracked" in refused.stderr
    assert (stage_dir / "baseline.pt").read_bytes() == kept
