"""Scoring a latent denoiser that is still in training: the verifier's pass rate on
validation prompts, sampled in batches straight from the in-memory networks.

Training curves and every setting chosen during training (prediction target, guidance,
DDIM steps, when to stop) use these validation prompts; the test split is only for the
figures reported afterwards (``evaluate``).

The prompts come from a corpus directory (their captions encoded here) or from a training
pack that holds them with their embeddings (``train pack``; ``latent_pack.read_validation``),
which is how a lent GPU machine without the text encoder scores the same prompts.
"""

from __future__ import annotations

import argparse
import copy
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import torch

from ..body.features import Normalizer, features_to_joints
from ..body.ik import rigidify
from ..data.clips import Clip, spread_clips
from ..inference.base import on_floor
from ..inference.checkpoints import AnyVAE
from ..inference.samplers import LatentSampler
from ..nn.text import get_text_encoder
from ..verify.rules import verify


def validation_prompts(data: str | Path, n: int = 200, source: str = "procedural") -> list[Clip]:
    """n validation clips of one source, spread evenly over the split (the text is each
    clip's first caption, its length the clip's); of the real ones, those whose labels the
    verifier covers, as the test table keeps them."""
    clips = spread_clips(data, "val", n, source)
    if source == "real":
        from ..verify.rules import has_rule

        clips = [c for c in clips if has_rule(c.labels)]
    return clips


@dataclass
class Prompt:
    """A validation prompt as scoring reads it: a corpus ``Clip`` has these and more, a
    pack holds only these."""

    captions: list[str]
    frames: int
    labels: dict


def is_pack(data: str | Path | None) -> bool:
    return data is not None and str(data).endswith(".npz")


def packed_prompts(pack: str | Path, n: int, source: str) -> tuple[list[Prompt], torch.Tensor, torch.Tensor] | None:
    """The pack's validation prompts of ``source`` with their caption embeddings (P, 384)
    and the empty text's (1, 384); None when it holds none of that source."""
    from .latent_pack import read_validation

    v = read_validation(pack, source)
    if v is None:
        return None
    if v["n"] != n:
        raise ValueError(f"{pack} holds the validation prompts of --val-n {v['n']}, not {n}: pack again with that")
    prompts = [Prompt([c], f, lab) for c, f, lab in zip(v["captions"], v["frames"], v["labels"], strict=True)]
    return prompts, torch.from_numpy(v["embeddings"]), torch.from_numpy(v["empty"])[None]


def eval_copy(net: torch.nn.Module) -> torch.nn.Module:
    """A network in training as validation samples it: an eval-mode copy where it is (a GPU
    samples the validation prompts in seconds; they are decoded and verified on the CPU)."""
    return copy.deepcopy(net).eval()


@torch.no_grad()
def sample_joints(
    sampler: LatentSampler,
    vae: AnyVAE,
    norm: Normalizer,
    scale: float,
    texts: list[str],
    frames: list[int],
    seed: int = 0,
    guidance: float | None = None,
    steps: int | None = None,
    batch: int = 100,
    embeddings: torch.Tensor | None = None,
    empty: torch.Tensor | None = None,
    device: torch.device | None = None,
) -> list[np.ndarray]:
    """One motion per (text, frames), as rigid joints (T_i, 22, 3) standing on the floor (``on_floor``),
    sampled ``batch`` rows at a time by ``sampler`` (guided DDIM or a consistency student)
    as ``generate`` does. ``embeddings`` (P, 384) and ``empty`` (1, 384): the texts'
    embeddings where they are known (a pack's), else the text encoder makes them.
    ``device``: where the sampler's network is (decoding stays on the CPU)."""
    if embeddings is None or empty is None:
        emb = get_text_encoder().encode([*texts, ""])
        cond, empty = emb[:-1], emb[-1:]
    else:
        cond = embeddings
    dev = torch.device(device or "cpu")
    g = torch.Generator().manual_seed(seed)
    n_z, d = vae.latent_shape
    out: list[np.ndarray] = []
    for s in range(0, len(texts), batch):
        c = cond[s : s + batch]
        fr = torch.tensor(frames[s : s + batch])
        z = sampler(c.to(dev), empty.to(dev), fr.to(dev), (len(c), n_z, d), g, steps, guidance, dev).cpu()
        feats = norm.denormalize(vae.decode(z * scale, fr))
        joints = features_to_joints(feats).numpy()
        for j, n in zip(joints, fr.tolist(), strict=True):
            out.append(on_floor(rigidify(j[:n])))
    return out


def verifier_pass_rate(
    sampler: LatentSampler,
    vae: AnyVAE,
    norm: Normalizer,
    scale: float,
    prompts: list[Clip] | list[Prompt],
    seed: int = 0,
    guidance: float | None = None,
    steps: int | None = None,
    embeddings: torch.Tensor | None = None,
    empty: torch.Tensor | None = None,
    device: torch.device | None = None,
) -> dict:
    """Verifier pass rate and direction accuracy of the sampler's motions for ``prompts``
    (``embeddings``, ``empty``, ``device``: as ``sample_joints``)."""
    from ..verify.direction import direction_correct

    joints = sample_joints(
        sampler,
        vae,
        norm,
        scale,
        [c.captions[0] for c in prompts],
        [c.frames for c in prompts],
        seed,
        guidance,
        steps,
        embeddings=embeddings,
        empty=empty,
        device=device,
    )
    passed, direction = [], []
    for j, c in zip(joints, prompts, strict=True):
        v = verify(j.astype(np.float64), c.labels)
        passed.append(v.passed)
        ok = direction_correct(v.checks, c.labels)
        if ok is not None:
            direction.append(ok)
    return {
        "n": len(prompts),
        "pass_rate": float(np.mean(passed)),
        "direction_accuracy": float(np.mean(direction)) if direction else None,
        "direction_prompts": len(direction),
    }


VAL_SOURCES = ("procedural", "real")


def val_sources(args: argparse.Namespace) -> tuple[str, ...]:
    """A training command's --val-source: "both" (the default: procedural and real,
    pooled), or one of them."""
    src = getattr(args, "val_source", "both") or "both"
    return VAL_SOURCES if src == "both" else (src,)


ValidationSets = dict[str, tuple[list, torch.Tensor | None, torch.Tensor | None]]


def load_validation(data: str | Path, n: int, sources: tuple[str, ...] = VAL_SOURCES) -> ValidationSets:
    """Each source's validation prompts, with their caption embeddings and the empty text's
    where a pack holds them (else None: encoded when scored). Loaded once, scored often
    (``validation_pass_rate`` takes the result as its ``data``)."""
    sets: ValidationSets = {}
    for src in sources:
        if is_pack(data):
            got = packed_prompts(data, n, src)
            sets[src] = got if got is not None else ([], None, None)
        else:
            sets[src] = (validation_prompts(data, n, src), None, None)
    return sets


def validation_pass_rate(
    sampler: LatentSampler,
    vae: AnyVAE,
    norm: Normalizer,
    scale: float,
    data: str | Path | ValidationSets,
    n: int = 200,
    sources: tuple[str, ...] = VAL_SOURCES,
    seed: int = 0,
    guidance: float | None = None,
    steps: int | None = None,
    device: torch.device | None = None,
) -> dict:
    """``verifier_pass_rate`` on the validation clips of each source (``n`` spread over
    each; the real ones cut to what the verifier covers), pooled over their prompts, with
    each source's own figures under "sources". ``data``: a corpus directory, a pack that
    holds its validation prompts, or ``load_validation``'s result. A source without clips
    (a corpus built without --real) is left out. Both, pooled, are what stages and students
    are chosen on: twice on 2026-11-26 the procedural prompts alone picked a checkpoint that lost 5-17
    points on the real ones (docs/training-log.md)."""
    per: dict[str, dict] = {}
    sets = data if isinstance(data, dict) else load_validation(data, n, sources)
    for src, (prompts, emb, empty) in sets.items():
        if prompts:
            per[src] = verifier_pass_rate(
                sampler, vae, norm, scale, prompts, seed, guidance, steps, embeddings=emb, empty=empty, device=device
            )
    if not per:
        raise ValueError(f"no validation clips of {sources} in {data}")
    return {**pooled_rates(list(per.values())), "sources": per}


def pooled_rates(runs: list[dict]) -> dict:
    """Verifier scores pooled over their samples (sources of one score, or one sampler's
    scores at several seeds): n, pass_rate, direction_accuracy and direction_prompts."""
    total = sum(r["n"] for r in runs)
    dir_n = sum(r["direction_prompts"] for r in runs)
    return {
        "n": total,
        "pass_rate": sum(r["pass_rate"] * r["n"] for r in runs) / total,
        "direction_accuracy": (
            sum((r["direction_accuracy"] or 0.0) * r["direction_prompts"] for r in runs) / dir_n if dir_n else None
        ),
        "direction_prompts": dir_n,
    }


@torch.no_grad()
def reconstruction_pass_rate(vae: AnyVAE, norm: Normalizer, prompts: list[Clip], batch: int = 64) -> dict:
    """Verifier pass rate of the VAE's reconstructions (posterior mean) of ``prompts``: the
    ceiling a latent denoiser on this VAE can reach, scored as ``evaluate`` scores it."""
    from ..data.clips import pad_batch

    was_training = vae.training
    vae.eval()
    passed = []
    for s in range(0, len(prompts), batch):
        part = prompts[s : s + batch]
        x, mask = pad_batch([norm.normalize(c.features) for c in part], vae.cfg.downsample)
        mu, _ = vae.encode(x, mask)
        rec = norm.denormalize(vae.decode(mu, mask.sum(1), t_pad=x.shape[1]))
        for r, c in zip(rec, part, strict=True):
            joints = features_to_joints(r[: c.frames].double()).numpy()
            passed.append(verify(joints, c.labels).passed)
    vae.train(was_training)
    return {"n": len(prompts), "pass_rate": float(np.mean(passed))}


def score_run(
    args: argparse.Namespace,
    make_sampler: Callable[[torch.nn.Module], LatentSampler],
    net: torch.nn.Module,
    scale: float,
    steps: int | None = None,
    guidance: float | None = None,
    seed: int = 0,
) -> dict:
    """``validation_pass_rate`` of a network in training, as a training command asks: its
    VAE (``--vae``), prompts (``--data``, else the ``--pack`` that holds them), ``--val-n`` and
    ``--val-source``; sampled by ``make_sampler(an eval copy of net)`` where the network is,
    from sampling seed ``seed``."""
    from ..inference.checkpoints import load_vae, vae_normalizer

    vae, vmeta = load_vae(Path(args.vae) / "vae.pt")
    return validation_pass_rate(
        make_sampler(eval_copy(net)),
        vae,
        vae_normalizer(vmeta),
        scale,
        args.data or args.pack,
        args.val_n,
        val_sources(args),
        seed=seed,
        guidance=guidance,
        steps=steps,
        device=next(net.parameters()).device,
    )
