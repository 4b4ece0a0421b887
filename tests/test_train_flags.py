"""`python -m motion_core.train`'s flags are checked where they are read, before a cache is
built or a step is taken: a value that cannot be meant is refused with the flag's name, and a
setting that would be dropped without a word is refused rather than ignored."""

from __future__ import annotations

import argparse

import pytest

from motion_core.inference.checkpoints import WEIGHTS
from motion_core.train import consistency, denoiser, kmm, vae
from motion_core.train.__main__ import VAL_N
from motion_core.train.__main__ import main as train_main


@pytest.fixture
def captured(monkeypatch) -> dict[str, argparse.Namespace]:
    """The arguments the trainers would have been called with (none is run)."""
    seen: dict[str, argparse.Namespace] = {}
    monkeypatch.setattr(denoiser, "train_denoiser", lambda args: seen.setdefault("denoiser", args))
    monkeypatch.setattr(consistency, "train_consistency", lambda args: seen.setdefault("lcm", args))
    monkeypatch.setattr(vae, "train_vae", lambda args: seen.setdefault("vae", args))
    monkeypatch.setattr(kmm, "train_generator", lambda args: seen.setdefault("generator", args))
    monkeypatch.setattr(kmm, "train_rvq", lambda args: seen.setdefault("rvq", args))
    return seen


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        # --steps 0 once read as "the default": 20,000 steps
        (["baseline", "--data", "d", "--steps", "0"], "--steps: must be 1 or more, got 0"),
        (["vae", "--data", "d", "--steps", "-5"], "--steps: must be 1 or more, got -5"),
        # --save-every 0 divided by zero after the caches were built and a step taken
        (["motion_mamba", "--data", "d", "--save-every", "0"], "--save-every: must be 1 or more"),
        (["baseline", "--data", "d", "--batch", "0"], "--batch: must be 1 or more"),
        (["baseline", "--data", "d", "--lr=-1e-4"], "--lr: must be 0 or more"),
        (["baseline", "--data", "d", "--lr", "nan"], "--lr: must be 0 or more"),
        (["baseline", "--data", "d", "--ema", "1"], "--ema: must be 0 (no average) or more and below 1"),
        (["baseline", "--data", "d", "--warmup", "-1"], "--warmup: must be 0 or more"),
        (["baseline", "--data", "d", "--val-every", "-2"], "--val-every: must be 0 or more"),
        (["baseline", "--data", "d", "--time-limit", "0"], "--time-limit: must be above 0"),
        (["baseline", "--data", "d", "--steps", "many"], "--steps: invalid int value: 'many'"),
        (["kmm-generator", "--data", "d", "--out", "o", "--steps", "0"], "--steps: must be 1 or more"),
        (["kmm-rvq", "--data", "d", "--out", "o", "--save-every", "0"], "--save-every: must be 1 or more"),
        (["lcm", "--teacher", "t", "--out", "o", "--batch", "0"], "--batch: must be 1 or more"),
        # validation settings without --val-every were dropped
        (["baseline", "--data", "d", "--val-steps", "5"], "--val-steps set how validation scores"),
        (["ftmomamba", "--data", "d", "--val-n", "8", "--val-guidance", "3"], "--val-n, --val-guidance set how"),
        (["baseline", "--data", "d", "--val-source", "real"], "--val-source set how validation scores"),
        (["lcm", "--teacher", "t", "--out", "o", "--data", "d", "--val-n", "4"], "--val-n set how validation"),
        # a flag the chosen network does not read was dropped
        (["vae", "--data", "d", "--warmup", "0", "--ema", "0"], "--warmup, --ema: the denoisers' settings"),
        (["vae", "--data", "d", "--stage", "s.pt", "--time-limit", "60"], "--time-limit: the denoisers'"),
        (["vae", "--data", "d", "--val-every", "5"], "--val-every: the denoisers' settings"),
        (["baseline", "--data", "d", "--arch", "conv"], "--arch is the VAE's"),
        (["baseline", "--pack", "p.npz", "--limit", "8"], "--limit picks --data's first clips"),
        (["kmm-rvq", "--data", "d", "--out", "o", "--ship", "--stop-at", "3"], "--ship, --stop-at: the generator's"),
        (["kmm-rvq", "--data", "d", "--out", "o", "--mask", "random"], "--mask: the generator's settings"),
        (["kmm-generator", "--data", "d", "--out", "o", "--set", "position_weight=9"], "--set changes the tokeniser's"),
        (["kmm-generator", "--data", "d", "--out", "o", "--decoder-only"], "--decoder-only fine-tunes a tokeniser"),
        (["kmm-swap-decoder", "--out", "o", "--stage", "s.pt"], "--stage: training settings"),
        (["baseline", "--data", "nowhere", "--val-every", "5"], "--data nowhere: no such corpus directory"),
        (["vae", "--data", "d", "--val-n", "5"], "--val-n: the denoisers' settings"),
        (["kmm-generator", "--data", "d", "--out", "o", "--stop-at", "0"], "--stop-at: must be 1 or more"),
        (["kmm-generator", "--data", "d", "--out", "o", "--layers", "0"], "--layers: must be 1 or more"),
        (["kmm-generator", "--data", "d", "--out", "o", "--pair-prob", "1.5"], "--pair-prob: must be 0 to 1"),
        (["lcm", "--teacher", "t", "--out", "o", "--sample-steps", "0"], "--sample-steps: must be 1 or more"),
        (["guidance", "--teacher", "t", "--out", "o", "--pack", "p", "--limit", "3"], "--limit picks --data's"),
        # a student of no steps and no --init was an untrained one, which --ship shipped
        (["lcm", "--teacher", "t", "--out", "o", "--data", "d", "--steps", "0"], "--steps 0 rescores an --init"),
        (["guidance", "--teacher", "t", "--out", "o", "--data", "d", "--steps", "0"], "--steps 0 rescores"),
    ],
)
def test_a_flag_that_cannot_be_meant_is_refused_by_name(argv, message, captured, capsys):
    with pytest.raises(SystemExit) as stop:
        train_main(argv)
    assert stop.value.code == 2 and message in capsys.readouterr().err
    assert not captured  # refused before any trainer ran


def test_unset_flags_take_the_subcommands_defaults_and_given_ones_are_kept(captured, monkeypatch, tmp_path):
    from motion_core.train import validation

    # --val-every looks for the validation prompts first: here every source has some
    monkeypatch.setattr(validation, "validation_prompts", lambda data, n, source: ["a prompt"])
    train_main(["baseline", "--data", "d"])
    args = captured.pop("denoiser")
    assert (args.steps, args.batch, args.lr, args.val_n, args.val_source) == (20000, 256, 3e-4, VAL_N, "both")
    assert (args.prediction, args.warmup, args.decay, args.ema, args.val_every) == ("epsilon", 500, "cosine", 0.999, 0)
    train_main(["vae", "--data", "d"])
    args = captured.pop("vae")
    assert (args.steps, args.batch, args.lr, args.arch, args.val_every) == (6000, 64, 4e-4, "transformer", 0)
    train_main(["baseline", "--data", "d", "--warmup", "0", "--ema", "0", "--prediction", "sample"])
    args = captured.pop("denoiser")
    assert (args.warmup, args.ema, args.prediction) == (0, 0.0, "sample")
    argv = ["motion_mamba", "--data", str(tmp_path), "--steps", "7", "--val-every", "5", "--val-n", "9"]
    train_main([*argv, "--val-steps", "3"])
    args = captured.pop("denoiser")
    assert (args.steps, args.val_every, args.val_n, args.val_steps, args.val_source) == (7, 5, 9, 3, "both")
    train_main(["kmm-generator", "--data", "d", "--out", "o"])
    args = captured.pop("generator")
    assert (args.steps, args.mask, args.pair_prob, args.no_align) == (4000, "keyframe", 0.5, False)
    train_main(["kmm-rvq", "--data", "d", "--out", "o", "--decoder-only", "--init", "r.pt"])
    assert captured.pop("rvq").decoder_only
    # the checkpoints must exist (a missing one is a usage error): the shipped ones stand in
    teacher, student = str(WEIGHTS / "baseline.pt"), str(WEIGHTS / "baseline_fast.pt")
    train_main(["lcm", "--teacher", teacher, "--out", "o", "--data", "d", "--steps", "0", "--init", student])
    args = captured.pop("lcm")
    assert (args.steps, args.init, args.val_n) == (0, student, VAL_N)


@pytest.mark.parametrize(
    ("argv", "said"),
    [
        (["kmm-extract-rvq", "--out", "o", "--steps", "5", "--seed", "1"], "--steps, --seed: training settings"),
        (["kmm-swap-decoder", "--out", "o", "--data", "d", "--init", "x"], "--data, --init: training settings"),
        (["kmm-swap-decoder", "--out", "o", "--layers", "2"], "--layers: training settings"),
        (["kmm-extract-rvq", "--out", "o", "--rvq", "r"], "kmm-extract-rvq writes one to --out"),
        (["kmm-rvq", "--data", "d", "--out", "o", "--rvq", "r"], "kmm-rvq writes one to --out"),
        (["kmm-generator", "--data", "d", "--out", "o", "--from", "k.pt"], "kmm-generator starts from --init"),
    ],
)
def test_kmm_s_file_commands_refuse_training_flags_and_the_trainers_refuse_from(
    argv, said, capsys, monkeypatch, tmp_path
):
    """kmm-extract-rvq and kmm-swap-decoder copy weights between files: a training flag given
    to them was dropped without a word, as --from was by the trainers and --rvq by the
    commands that write a tokeniser rather than read one."""
    # without the refusal kmm-extract-rvq reads the shipped KMM and writes o/rvq.pt: keep
    # that out of the checkout
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SystemExit):
        train_main(argv)
    assert said in capsys.readouterr().err
