"""Verifier pass rates per action kind, on a grown corpus's test clips: how far each network
reaches on the kinds it is being retrained on.

    python -m motion_core.eval per-kind --data data/corpus_grown [--vae VAE.pt] [--rvq RVQ.pt]
        [--kinds staged|all] [--per-kind 20] [--out results/per_kind_reconstructions.json]
        [--method kmm --method mm=stages/grown/motion_mamba.pt --seeds 0 1 2 [--guidance G] [--steps N]]

Rows: the ground-truth clips (through the 263-dim features, as stored), the VAE's
reconstructions (posterior mean; the shipped ``vae.pt`` unless ``--vae``) and KMM's tokeniser's
(all quantisers; the shipped ``kmm.pt`` unless ``--rvq``, a tokeniser run's ``rvq.pt`` or a
stage). The reconstructions are the ceiling of what a latent denoiser on that VAE, or KMM's
generator on those codes, can reach. Each kind is ``--per-kind`` test clips spread over the
split; the chains (two or three actions under one sentence) are one more row, ``chain``.

``--method`` adds a row of generated motions, one per clip from its first caption and its
length, at each of ``--seeds`` (the rate is over all of them): a method's name
("NAME[:SAMPLER]"), or "NAME=CHECKPOINT" for a network in training (a denoiser stage, on the
``--vae`` VAE it was trained on, or a KMM ``kmm.pt`` stage with its own tokeniser).
``--guidance`` and ``--steps`` override every ``--method`` row's defaults (a stage in training
may want other decoding settings than the shipped network they were chosen for).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
import torch

from ..body.features import features_to_joints
from ..data.clips import Clip, load_clips
from ..verify.rules import has_rule, verify
from .provenance import provenance

Reconstruct = Callable[[list[Clip]], list[np.ndarray]]


def kind_prompts(data: str | Path, kinds: list[str], per_kind: int, split: str = "test") -> dict[str, list[Clip]]:
    """kind -> up to ``per_kind`` clips of that kind spread evenly over ``split`` (and
    "chain" -> the chains'), procedural clips only."""
    by_kind: dict[str, list[Clip]] = {}
    for c in load_clips(data, split):
        k = c.labels.get("kind")
        if c.labels.get("source", "procedural") == "procedural" and has_rule(c.labels) and (k in kinds or k == "chain"):
            by_kind.setdefault(k, []).append(c)
    out = {}
    for k, clips in by_kind.items():
        idx = np.linspace(0, len(clips) - 1, min(per_kind, len(clips))).round().astype(int)
        out[k] = [clips[i] for i in idx]
    return out


def vae_rows(path: str | Path) -> Reconstruct:
    """The VAE checkpoint at ``path``'s reconstructions (posterior mean), as joints (T, 22, 3)."""
    from ..inference.checkpoints import load_vae, vae_normalizer
    from .tables import vae_reconstructions

    vae, meta = load_vae(path)
    norm = vae_normalizer(meta)
    return lambda prompts: vae_reconstructions(prompts, (vae, norm))


def rvq_rows(path: str | Path) -> Reconstruct:
    """KMM's tokeniser at ``path`` (a kmm.pt, an rvq.pt or a stage): reconstructions with all
    quantisers, as joints (T, 22, 3)."""
    from ..inference.checkpoints import load_kmm, load_rvq, read, vae_normalizer

    if "rvq" in read(path):  # a kmm.pt: tokeniser and generator
        model, _, norm, _ = load_kmm(path)
    else:
        model, meta = load_rvq(path)
        norm = vae_normalizer(meta)

    @torch.no_grad()
    def run(prompts: list[Clip]) -> list[np.ndarray]:
        out = []
        for c in prompts:
            codes, _ = model.encode(torch.from_numpy(norm.normalize(c.features)).float()[None])
            rec = norm.denormalize(model.decode(codes)[0, : c.frames]).numpy().astype(np.float64)
            out.append(features_to_joints(rec))
        return out

    return run


def method_rows(
    specs: list[str],
    vae: str | Path,
    seeds: list[int],
    guidance: float | None = None,
    steps: int | None = None,
) -> dict[str, Reconstruct]:
    """``--method`` rows: each clip generated from its first caption at its length, at every
    seed in turn (the clips repeated once per seed); ``guidance`` / ``steps`` None keep each
    method's defaults."""
    from ..inference.generation import generate, method_spec, row_name
    from ..inference.registry import register_arm

    rows: dict[str, Reconstruct] = {}
    for spec in specs:
        name, arm, path = spec.partition("=")
        if arm:
            register_arm(name, path, vae=None if "rvq" in _read(path) else vae)
        m, sampler = method_spec(name)

        def run(prompts: list[Clip], m: str = m, sampler: str = sampler) -> list[np.ndarray]:
            return [
                generate(
                    [(c.captions[0], c.frames / 20.0)],
                    m,
                    seed * 1000 + i,
                    steps=steps,
                    guidance=guidance,
                    sampler=sampler,
                ).joints
                for seed in seeds
                for i, c in enumerate(prompts)
            ]

        rows[row_name(m, sampler)] = run
    return rows


def _pct(x: float | None) -> str:
    return "-" if x is None else f"{100 * x:.1f}%"


def _read(path: str | Path) -> dict:
    from ..inference.checkpoints import read

    return read(path)


def per_kind_table(prompts: dict[str, list[Clip]], rows: dict[str, Reconstruct]) -> dict:
    """row -> {"kinds": {kind: pass rate}, "mean", "below_80"}; "ground_truth" is always a row."""
    table: dict = {}
    every = {"ground_truth": lambda ps: [features_to_joints(c.features.astype(np.float64)) for c in ps], **rows}
    for name, fn in every.items():
        rates = {}
        for k, ps in prompts.items():
            joints = fn(ps)
            # a generated row holds each clip once per seed, in turn
            labels = [c.labels for c in ps] * (len(joints) // len(ps))
            rates[k] = float(
                np.mean([verify(np.asarray(j, np.float64), lab).passed for j, lab in zip(joints, labels, strict=True)])
            )
        single = [v for k, v in rates.items() if k != "chain"]
        table[name] = {
            "kinds": rates,
            "mean_over_kinds": float(np.mean(single)) if single else None,
            "kinds_below_80": sorted(k for k, v in rates.items() if v < 0.8 and k != "chain"),
        }
    return table


def main(argv: list[str] | None = None) -> None:
    from ..corpus.kinds import all_kinds, staged_kinds
    from ..inference.checkpoints import WEIGHTS

    ap = argparse.ArgumentParser(prog="python -m motion_core.eval per-kind", description=__doc__)
    ap.add_argument("--data", required=True, help="a corpus built with --with-staged (and chains)")
    ap.add_argument("--vae", default=str(WEIGHTS / "vae.pt"))
    ap.add_argument("--rvq", default=str(WEIGHTS / "kmm.pt"))
    ap.add_argument("--kinds", choices=["staged", "all"], default="staged")
    ap.add_argument("--per-kind", type=int, default=20)
    ap.add_argument("--split", default="test", choices=["val", "test"])
    ap.add_argument("--out", default=None, help="write the table as JSON here")
    ap.add_argument(
        "--method",
        action="append",
        default=[],
        metavar="NAME[:SAMPLER] | NAME=CHECKPOINT",
        help="a row of generated motions: a method, or a network in training (a denoiser on --vae, a kmm.pt)",
    )
    ap.add_argument("--seeds", type=int, nargs="+", default=[0], help="--method rows: the seeds generated at")
    ap.add_argument(
        "--guidance", type=float, default=None, help="--method rows: guidance scale (default: each method's)"
    )
    ap.add_argument(
        "--steps", type=int, default=None, help="--method rows: sampling steps or passes (default: each method's)"
    )
    ap.add_argument("--no-reconstructions", action="store_true", help="only ground truth and the --method rows")
    a = ap.parse_args(argv)
    t0 = time.time()
    kinds = staged_kinds() if a.kinds == "staged" else all_kinds()
    prompts = kind_prompts(a.data, kinds, a.per_kind, a.split)
    if not prompts:
        raise SystemExit(f"{a.data}: no {a.split} clips of these kinds (build it with --with-staged)")
    rows: dict[str, Reconstruct] = {}
    if not a.no_reconstructions:
        rows = {"vae_reconstruction": vae_rows(a.vae), "rvq_reconstruction": rvq_rows(a.rvq)}
    table = per_kind_table(prompts, {**rows, **method_rows(a.method, a.vae, a.seeds, a.guidance, a.steps)})
    staged = set(staged_kinds())
    for row in table.values():
        for name, keep in (("staged", lambda k: k in staged), ("built_in", lambda k: k not in staged)):
            vals = [v for k, v in row["kinds"].items() if k != "chain" and keep(k)]
            row[f"mean_over_{name}"] = float(np.mean(vals)) if vals else None
    result = {
        **provenance("python -m motion_core.eval per-kind " + " ".join(argv if argv is not None else sys.argv[2:])),
        "data": str(a.data),
        "split": a.split,
        "per_kind": a.per_kind,
        "vae": str(a.vae),
        "rvq": str(a.rvq),
        "methods": a.method,
        "seeds": a.seeds,
        "guidance": a.guidance,
        "steps": a.steps,
        "clips": {k: len(v) for k, v in prompts.items()},
        "rows": table,
        "seconds": round(time.time() - t0, 1),
    }
    text = json.dumps(result, indent=1)
    if a.out:
        Path(a.out).parent.mkdir(parents=True, exist_ok=True)
        Path(a.out).write_text(text + "\n")
    for name, row in table.items():
        print(
            f"{name}: mean over kinds {row['mean_over_kinds']:.3f} (staged {_pct(row['mean_over_staged'])}, "
            f"built-in {_pct(row['mean_over_built_in'])}), chain {row['kinds'].get('chain')}, "
            f"{len(row['kinds_below_80'])} kinds below 80%"
        )
