"""The latent denoisers' training data and its use of the text (the fault these guard against:
the diffusion methods produced nearly the same motion whatever the text said).

These are the checks that would have caught a caption paired with the wrong clip, a cache
reused across a corpus or VAE change, or a training recipe that teaches a denoiser to
ignore its text."""

from __future__ import annotations

import argparse
import json
import shutil
import sys
from pathlib import Path

import numpy as np
import pytest
import torch

from motion_core.corpus.__main__ import main as corpus_main
from motion_core.data.clips import load_clips, pad_batch
from motion_core.inference.checkpoints import WEIGHTS, load_vae
from motion_core.train.__main__ import main as train_main
from motion_core.train.caches import StaleCache
from motion_core.train.denoiser import encode_corpus
from tests.conftest import REPO


@pytest.fixture(scope="module")
def tiny(tmp_path_factory) -> tuple[Path, Path]:
    """A 32-clip corpus and a run directory holding a copy of the shipped VAE."""
    root = tmp_path_factory.mktemp("denoiser")
    data = root / "corpus"
    args = ["build", str(data), "--train", "32", "--val", "8", "--test", "4"]
    args += ["--seq-train", "1", "--seq-val", "1", "--seq-test", "1", "--workers", "1"]
    assert corpus_main(args) == 0
    vae_dir = root / "vae"
    vae_dir.mkdir()
    shutil.copy(WEIGHTS / "vae.pt", vae_dir / "vae.pt")
    return data, vae_dir


def _args(data: Path, vae_dir: Path) -> argparse.Namespace:
    return argparse.Namespace(data=str(data), vae=str(vae_dir), limit=None)


def test_each_cached_caption_and_latent_belongs_to_its_clip(tiny, text_encoder):
    """The caches a training batch is drawn from: latent j is the VAE's posterior of clip j,
    and caption i's embedding is that of a caption of clip text_clip[i]."""
    data, vae_dir = tiny
    cache = encode_corpus(_args(data, vae_dir))
    clips = load_clips(data, "train")
    vae, meta = load_vae(vae_dir / "vae.pt")
    from motion_core.body.features import Normalizer

    norm = Normalizer(np.asarray(meta["mean"]), np.asarray(meta["std"]))
    assert cache["mu"].shape[0] == len(clips) and cache["frames"].tolist() == [c.frames for c in clips]
    for j in (0, 7, len(clips) - 1):
        x, mask = pad_batch([norm.normalize(clips[j].features)], vae.cfg.downsample)
        with torch.no_grad():
            mu, _ = vae.encode(x, mask)
        assert np.allclose(cache["mu"][j], mu[0].numpy(), atol=1e-4)
    for i in np.linspace(0, len(cache["text"]) - 1, 9).round().astype(int):
        own = text_encoder.encode(clips[cache["text_clip"][i]].captions).numpy()
        assert np.abs(own - cache["text"][i]).max(axis=1).min() < 1e-5, f"caption {i} is not its clip's"


def test_a_cache_built_for_another_corpus_or_vae_is_refused(tiny, tmp_path):
    data, vae_dir = tiny
    encode_corpus(_args(data, vae_dir))  # builds (or reuses) both caches
    other = tmp_path / "corpus"
    shutil.copytree(data, other)
    first = (other / "train.txt").read_text().split()[0]
    cap = other / "texts" / f"{first}.txt"
    cap.write_text(cap.read_text().replace("person", "figure", 1) + "a person stands still#a/DET#0.0#0.0\n")
    with pytest.raises(StaleCache, match="another corpus or VAE"):
        encode_corpus(_args(other, vae_dir))
    # the same corpus with another VAE: the latents are stale, the captions are not
    other_vae = tmp_path / "vae"
    other_vae.mkdir()
    shutil.copy(vae_dir / "texts.npz", other_vae / "texts.npz")
    shutil.copy(vae_dir / "latents.npz", other_vae / "latents.npz")
    ck = torch.load(vae_dir / "vae.pt", weights_only=False)
    ck["meta"]["steps"] = -1
    torch.save(ck, other_vae / "vae.pt")
    with pytest.raises(StaleCache, match=r"latents\.npz"):
        encode_corpus(_args(data, other_vae))


@pytest.mark.long
def test_a_short_training_run_learns_to_tell_two_texts_apart(tiny, text_encoder):
    """After 450 steps on the tiny corpus, the denoiser's clean-latent estimate at a very
    noisy step differs between a sitting and a walking prompt by more than a quarter of
    the latents' own spread. The shipped recipe before this test (epsilon target) moved
    it by a few percent of it after its full training, which is what a user saw as the
    same motion for every text. On a temporal VAE both are taken over the clip's own latent
    tokens (past them the latent is zero padding); it needs more steps than the 2-token
    latent (on the temporal one: 0.04 / 0.27 / 0.43 of the spread after 150 / 300 / 600)."""
    data, vae_dir = tiny
    out = vae_dir.parent / "baseline"
    common = ["--data", str(data), "--vae", str(vae_dir), "--out", str(out), "--batch", "16", "--steps", "450"]
    train_main(["baseline", *common, "--lr", "1e-3", "--prediction", "sample", "--save-every", "450"])
    ck = torch.load(out / "baseline.pt", weights_only=False)
    assert ck["meta"]["prediction"] == "sample"
    from motion_core.models.latent_denoisers import build_denoiser, config_from_dict
    from motion_core.nn.diffusion import Diffusion, DiffusionConfig

    den = build_denoiser("baseline", config_from_dict("baseline", ck["meta"]["config"])).eval()
    den.load_state_dict(ck["state_dict"])
    diff = Diffusion(DiffusionConfig(**ck["meta"]["diffusion"]))
    cache = encode_corpus(_args(data, vae_dir))
    mu = torch.from_numpy(cache["mu"]) / ck["meta"]["latent_scale"]
    fpt = ck["meta"]["config"].get("frames_per_token", 0)
    if fpt:  # a temporal latent: the clips' own tokens, and the 80-frame prompt's 20
        frames = torch.from_numpy(cache["frames"])
        spread = float(mu[torch.arange(mu.shape[1])[None] < ((frames + fpt - 1) // fpt)[:, None]].std())
        own = (80 + fpt - 1) // fpt
    else:
        spread, own = float(mu.std(0).mean()), mu.shape[1]
    texts = text_encoder.encode(["a person sits down on a chair", "a person walks forward"])
    z = torch.randn(1, *mu.shape[1:], generator=torch.Generator().manual_seed(0)).expand(2, -1, -1)
    t = torch.full((2,), 900)
    with torch.no_grad():
        _, x0 = diff.split(den(z, t, texts, torch.tensor([80, 80])), z, t)
    moved = float((x0[0, :own] - x0[1, :own]).abs().mean())
    assert moved > 0.25 * spread, (moved, spread)


@pytest.mark.long
def test_a_stage_goes_on_from_committed_weights(tiny):
    """--init: a new stage starts from a denoiser checkpoint's weights and config, and its
    meta counts the whole lineage's steps."""
    data, vae_dir = tiny
    first = vae_dir.parent / "stage1"
    common = ["--data", str(data), "--vae", str(vae_dir), "--batch", "8", "--prediction", "sample"]
    val = ["--val-every", "3", "--val-n", "4", "--val-steps", "2"]
    train_main(["baseline", *common, "--out", str(first), "--steps", "3", "--save-every", "3", *val])
    # the curve says how many DDIM steps each score sampled (--val-steps: cheaper scores)
    point = json.loads((first / "curve.json").read_text())[-1]
    assert point["step"] == 3 and point["ddim_steps"] == 2 and point["n"] == 4
    second = vae_dir.parent / "stage2"
    train_main(
        [
            "baseline",
            *common,
            "--out",
            str(second),
            "--steps",
            "2",
            "--save-every",
            "2",
            "--init",
            str(first / "baseline.pt"),
        ]
    )
    meta = torch.load(second / "baseline.pt", weights_only=False)["meta"]
    assert meta["steps"] == 5 and meta["stage_steps"] == 2 and meta["init"] == {"from": "baseline.pt", "steps": 3}
    assert meta["schedule"] == {"warmup": 500, "decay": "cosine"}
    # a stopped stage rerun at its saved step writes its float16 stage file, holding the rate
    third = vae_dir.parent / "stage3"
    stage = vae_dir.parent / "stages" / "baseline_s3.pt"
    hold = ["--init", str(second / "baseline.pt"), "--warmup", "0", "--decay", "constant", "--save-every", "2"]
    train_main(["baseline", *common, "--out", str(third), "--steps", "2", *hold])
    train_main(["baseline", *common, "--out", str(third), "--steps", "2", *hold, "--stage", str(stage)])
    staged = torch.load(stage, weights_only=False)
    assert staged["meta"]["steps"] == 7 and staged["meta"]["schedule"] == {"warmup": 0, "decay": "constant"}
    assert all(v.dtype == torch.float16 for v in staged["state_dict"].values() if v.is_floating_point())
    with pytest.raises(SystemExit, match="holds a baseline denoiser"):
        train_main(
            [
                "motion_mamba",
                *common,
                "--out",
                str(vae_dir.parent / "x"),
                "--steps",
                "1",
                "--init",
                str(first / "baseline.pt"),
            ]
        )


def test_denoisers_train_on_a_temporal_vae_from_the_tokeniser(tiny):
    """The temporal VAE from KMM's tokeniser, then a denoiser on its latents: the latent's
    width and frames per token reach the denoiser's config; epsilon is refused."""
    data, _ = tiny
    root = data.parent / "temporal"
    vae_out = root / "vae"
    init = ["--arch", "conv", "--init", str(WEIGHTS / "kmm.pt"), "--set", "z_width=8"]
    train_main(
        ["vae", *init, "--data", str(data), "--out", str(vae_out), "--steps", "2", "--batch", "8", "--save-every", "2"]
    )
    vae, meta = load_vae(vae_out / "vae.pt")
    assert meta["arch"] == "conv" and meta["tokeniser_init"]["steps"] > 0 and vae.latent_shape == (56, 8)
    common = ["--data", str(data), "--vae", str(vae_out), "--batch", "4", "--steps", "1", "--save-every", "1"]
    with pytest.raises(SystemExit, match="--prediction sample"):
        train_main(["baseline", *common, "--out", str(root / "eps")])
    train_main(["baseline", *common, "--out", str(root / "x0"), "--prediction", "sample"])
    cfg = torch.load(root / "x0" / "baseline.pt", weights_only=False)["meta"]["config"]
    assert (cfg["latent_tokens"], cfg["z_width"], cfg["frames_per_token"]) == (56, 8, 4)
    # a stage may switch on a layer that starts at zero (FTMoMamba's broadcast conditioning):
    # it goes on from the prefix checkpoint, whose weights all load
    train_main(["ftmomamba", *common, "--out", str(root / "ftm"), "--prediction", "sample", "--set", "cond=prefix"])
    go_on = ["--init", str(root / "ftm" / "ftmomamba.pt"), "--set", "cond=broadcast", "--prediction", "sample"]
    train_main(["ftmomamba", *common, "--out", str(root / "ftm2"), *go_on])
    meta = torch.load(root / "ftm2" / "ftmomamba.pt", weights_only=False)["meta"]
    assert meta["config"]["cond"] == "broadcast" and meta["steps"] == 2
    # the other way round a checkpoint's weights would be left out: refused
    back = ["--init", str(root / "ftm2" / "ftmomamba.pt"), "--set", "cond=prefix", "--prediction", "sample"]
    with pytest.raises(SystemExit, match="does not fit"):
        train_main(["ftmomamba", *common, "--out", str(root / "ftm3"), *back])


def test_validation_of_a_source_the_data_does_not_hold_is_refused_before_training(tiny, tmp_path, capsys):
    """The tiny corpus has no real clips: scoring them would fail at every score (a student:
    after its last step, without writing its checkpoint), so the command is refused first."""
    data, vae_dir = tiny
    common = ["--data", str(data), "--vae", str(vae_dir), "--val-every", "1", "--val-source", "real"]
    common += ["--steps", "1", "--batch", "2"]  # were it not refused, a short run
    for argv in (
        ["baseline", *common, "--prediction", "sample", "--out", str(tmp_path / "d")],
        ["lcm", "--teacher", str(WEIGHTS / "baseline.pt"), *common, "--out", str(tmp_path / "s")],
    ):
        with pytest.raises(SystemExit):
            train_main(argv)
        err = capsys.readouterr().err
        assert "--val-source real: " in err and "holds no real validation prompts" in err
        assert not (tmp_path / "d").exists() and not (tmp_path / "s").exists()


def test_a_resume_under_another_recipe_is_refused(tiny):
    """Rerunning with the same --out resumes from its state: a new rate, average or target
    there would train the rest on another recipe while the meta claimed one for the whole."""
    data, vae_dir = tiny
    out = vae_dir.parent / "recipe"
    common = ["baseline", "--data", str(data), "--vae", str(vae_dir), "--batch", "2", "--prediction", "sample"]
    common += ["--save-every", "1", "--out", str(out)]
    train_main([*common, "--steps", "1"])
    with pytest.raises(SystemExit, match=r"another recipe \(--lr was 0\.0003, now 0\.001\)"):
        train_main([*common, "--steps", "2", "--lr", "1e-3"])
    with pytest.raises(SystemExit, match=r"--warmup was 500, now 0; --ema was 0\.999, now 0\.0"):
        train_main([*common, "--steps", "2", "--ema", "0", "--warmup", "0"])
    with pytest.raises(SystemExit, match="network config was"):
        train_main([*common, "--steps", "2", "--set", "dropout=0.3"])
    # the recorded recipe and the same network however --set spells it, a longer --steps: it resumes
    train_main([*common, "--steps", "2", "--set", "dropout=0.10"])
    assert json.loads((out / "result.json").read_text())["stage_steps"] == 2


@pytest.mark.long
def test_the_staged_weights_are_a_moving_average_that_resumes_exactly(tiny):
    """--ema: the checkpoint holds the moving average of the weights (what is scored and
    shipped), not the last step's; a run stopped and resumed gives the same average."""
    data, vae_dir = tiny
    root = vae_dir.parent / "ema"
    common = ["baseline", "--data", str(data), "--vae", str(vae_dir), "--batch", "4", "--prediction", "sample"]
    common += ["--decay", "constant", "--warmup", "0", "--save-every", "3"]
    train_main([*common, "--out", str(root / "whole"), "--steps", "6"])
    train_main([*common, "--out", str(root / "split"), "--steps", "3"])
    train_main([*common, "--out", str(root / "split"), "--steps", "6"])  # resumes at step 3
    whole = torch.load(root / "whole" / "baseline.pt", weights_only=False)
    split = torch.load(root / "split" / "baseline.pt", weights_only=False)
    assert all(torch.equal(v, split["state_dict"][k]) for k, v in whole["state_dict"].items())
    assert whole["meta"]["weights_ema"] == 0.999
    raw = torch.load(root / "whole" / "state.pt", weights_only=False)["model"]
    # the average trails the raw weights: after 6 updates it weighs the early steps in
    moved = [k for k, v in raw.items() if v.is_floating_point() and not torch.equal(v, whole["state_dict"][k])]
    assert moved
    train_main([*common, "--out", str(root / "raw"), "--steps", "6", "--ema", "0"])
    plain = torch.load(root / "raw" / "baseline.pt", weights_only=False)
    assert plain["meta"]["weights_ema"] is None
    assert all(torch.equal(v, plain["state_dict"][k]) for k, v in raw.items())  # --ema 0: the raw weights


def test_a_teacher_s_predictions_become_the_target(tiny, capsys):
    """--teacher: the denoiser regresses the teacher's prediction on the same noisy latents,
    captions and steps (knowledge distillation, how the equal-speed design's smaller Motion Mamba learns
    from the shipped one). A network taught by its own weights, held still (--lr 0) and
    without dropout, has nothing to learn: its loss is zero where the data's is not, and at
    a share s of the teacher's it is (1 - s)^2 times the data's. The teacher is recorded
    (and carried by a stage that goes on from a taught one), a resume cannot gain, drop or
    swap it, and a teacher of another kind is refused before the data is read."""
    from motion_core.train.teachers import load_teacher

    data, vae_dir = tiny
    root = vae_dir.parent / "taught"
    common = ["--data", str(data), "--vae", str(vae_dir), "--batch", "4", "--prediction", "sample"]
    common += ["--save-every", "2", "--set", "dropout=0"]
    train_main(["baseline", *common, "--out", str(root / "teacher"), "--steps", "1"])
    teacher = root / "teacher" / "baseline.pt"
    assert not load_teacher(teacher)[0].training  # its dropout off, whatever its config says
    still = ["--init", str(teacher), "--lr", "0", "--warmup", "0", "--steps", "2"]
    train_main(["baseline", *common, *still, "--out", str(root / "data")])
    train_main(["baseline", *common, *still, "--out", str(root / "self"), "--teacher", str(teacher)])
    alone = json.loads((root / "data" / "result.json").read_text())
    taught = json.loads((root / "self" / "result.json").read_text())
    assert alone["final_loss_ema"] > 1e-4 and "teacher" not in alone
    assert taught["final_loss_ema"] < 1e-9
    assert taught["teacher"]["from"] == "baseline.pt" and taught["teacher"]["share"] == 1.0
    quarter = ["--teacher", str(teacher), "--teacher-share", "0.25"]
    train_main(["baseline", *common, *still, "--out", str(root / "quarter"), *quarter])
    part = json.loads((root / "quarter" / "result.json").read_text())["final_loss_ema"]
    assert part == pytest.approx(0.75**2 * alone["final_loss_ema"], rel=1e-4)
    # a stage that goes on from a taught one says so in its lineage
    go_on = ["--init", str(root / "self" / "baseline.pt"), "--steps", "1"]
    train_main(["baseline", *common, *go_on, "--out", str(root / "on")])
    on = json.loads((root / "on" / "result.json").read_text())
    assert on["init"]["teacher"]["fingerprint"] == taught["teacher"]["fingerprint"] and "teacher" not in on
    # cut by tools/prune_ff.py and trained on: the record keeps the cut and the hand-over
    # before it, teacher included, not only the last hand-over
    sys.path.insert(0, str(REPO / "tools"))
    import prune_ff

    ff = json.loads((root / "on" / "result.json").read_text())["config"]["ff"]
    prune_ff.main(
        ["--checkpoint", str(root / "on" / "baseline.pt"), "--ff", str(ff // 2), "--out", str(root / "cut.pt")]
    )
    train_main(["baseline", *common, "--init", str(root / "cut.pt"), "--steps", "1", "--out", str(root / "after_cut")])
    after = json.loads((root / "after_cut" / "result.json").read_text())
    assert after["config"]["ff"] == ff // 2 and after["init"]["pruned"]["ff"] == ff // 2
    assert after["init"]["init"]["teacher"]["fingerprint"] == taught["teacher"]["fingerprint"]
    # resumes: dropping, gaining or swapping the teacher is refused
    longer = [*still[:-1], "4"]
    with pytest.raises(SystemExit, match="teacher was"):
        train_main(["baseline", *common, *longer, "--out", str(root / "self")])
    with pytest.raises(SystemExit, match="teacher was None"):
        train_main(["baseline", *common, *longer, "--out", str(root / "data"), "--teacher", str(teacher)])
    # a state written before teachers were recorded was trained without one, too
    state = torch.load(root / "data" / "state.pt", weights_only=False)
    del state["recipe"]["teacher"]
    torch.save(state, root / "data" / "state.pt")
    with pytest.raises(SystemExit, match="teacher was None"):
        train_main(["baseline", *common, *longer, "--out", str(root / "data"), "--teacher", str(teacher)])
    other = root / "other.pt"
    ck = torch.load(teacher, weights_only=False)
    ck["state_dict"] = {k: v + 1 if v.is_floating_point() else v for k, v in ck["state_dict"].items()}
    torch.save(ck, other)
    with pytest.raises(SystemExit, match="teacher was"):
        train_main(["baseline", *common, *longer, "--out", str(root / "self"), "--teacher", str(other)])
    with pytest.raises(SystemExit, match="does not teach this run: kind 'baseline', this run 'motion_mamba'"):
        train_main(["motion_mamba", *common, "--steps", "1", "--out", str(root / "mm"), "--teacher", str(teacher)])
    # and before the data is read: a wrong teacher costs no minutes of caching
    nowhere = ["--data", str(root / "no corpus"), "--vae", str(vae_dir), "--prediction", "sample", "--steps", "1"]
    with pytest.raises(SystemExit, match="does not teach this run: kind"):
        train_main(["motion_mamba", *nowhere, "--out", str(root / "mm"), "--teacher", str(teacher)])
    for argv, said in (
        (["baseline", *common, "--steps", "1", "--out", str(root / "x"), "--teacher-share", "0.5"], "give --teacher"),
        (["baseline", *common, "--steps", "1", "--teacher", str(teacher), "--teacher-share", "0"], "above 0"),
        (["vae", "--data", str(data), "--steps", "1", "--teacher", str(teacher)], "--teacher: the denoisers'"),
    ):
        with pytest.raises(SystemExit):
            train_main(argv)
        assert said in capsys.readouterr().err
