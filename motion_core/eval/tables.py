"""The evaluation tables behind ``python -m motion_core.eval`` (options: ``eval/__main__.py``).

``--arm NAME=RUN`` makes a training run's denoiser (an ablation arm, ``train ... --set``) a
method of this run under NAME, so any table takes it; ``--ablation`` writes the arms' table:
held-out denoising loss, verifier pass rate and direction accuracy (ablation.json).

The metric suite (``suite``): the papers' text-to-motion table (Real, each method:
R-precision, FID, MM-Dist, Diversity, MModality, foot skating, verifier pass rate, left/right
accuracy) and the BABEL-style extended-motion table (subsequence metrics, Peak Jerk, AUJ),
written as Markdown and JSON to ``--out`` (metrics_<source>.md/.json).

``--verifier-only``: the corpus verifier's pass rate on ``n`` test prompts (each a test
clip's first caption, its labels and its duration), per method, next to the ground-truth
clips' and the VAE reconstructions' pass rates (verifier.json / verifier_real.json).
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np
import torch

from ..body.features import features_to_joints
from ..data.clips import Clip, load_clips, spread_clips
from ..verify.direction import direction_correct
from ..verify.rules import has_rule, verify
from .suite import label_direction


def test_prompts(data: str | Path, n: int = 200, source: str = "procedural") -> list[Clip]:
    """n test clips of one source ("procedural" or "real") spread evenly over the test split."""
    return spread_clips(data, "test", n, source)


@torch.no_grad()
def vae_reconstructions(prompts: list[Clip], vae_and_norm: tuple | None = None) -> list[np.ndarray]:
    """A VAE's reconstruction (posterior mean) of each clip, as joints (T, 22, 3): the ceiling
    of what the latent diffusion methods can reach. ``vae_and_norm``: (vae, its Normalizer),
    default the shipped VAE."""
    from ..data.clips import pad_batch
    from ..inference.latent_diffusion import shared_vae

    vae, norm = vae_and_norm or shared_vae()
    out = []
    for c in prompts:
        x, mask = pad_batch([norm.normalize(c.features)], vae.cfg.downsample)
        mu, _ = vae.encode(x, mask)
        rec = norm.denormalize(vae.decode(mu, c.frames)[0, : c.frames]).numpy().astype(np.float64)
        out.append(features_to_joints(rec))
    return out


@torch.no_grad()
def rvq_reconstructions(prompts: list[Clip]) -> list[np.ndarray]:
    """The shipped KMM tokeniser's reconstruction of each clip (all quantisers), as joints
    (T, 22, 3): the ceiling of what KMM's generator can reach by drawing the right codes."""
    from ..inference.registry import load_method

    m = load_method("kmm")
    out = []
    for c in prompts:
        codes, _ = m.rvq.encode(torch.from_numpy(m.normalizer.normalize(c.features)).float()[None])
        rec = m.normalizer.denormalize(m.rvq.decode(codes)[0, : c.frames]).numpy().astype(np.float64)
        out.append(features_to_joints(rec))
    return out


def verifier_table(
    methods: list[str], data: str | Path, n: int = 200, seed: int = 0, source: str = "procedural"
) -> dict:
    """Verifier pass rates of ground truth, VAE reconstructions and each method's motions
    for ``n`` test prompts of one source (the text is the clip's first caption)."""
    from ..inference.generation import generate, method_spec, row_name

    prompts = test_prompts(data, n, source)
    if source == "real":  # only the real clips whose labels the verifier covers
        prompts = [c for c in prompts if has_rule(c.labels)]
    out: dict = {"n": len(prompts), "source": source}
    gt = [verify(features_to_joints(c.features.astype(np.float64)), c.labels).passed for c in prompts]
    out["ground_truth"] = {"pass_rate": float(np.mean(gt))}
    truth = [features_to_joints(c.features.astype(np.float64)) for c in prompts]
    ceilings = [("vae_reconstruction", vae_reconstructions)]
    if "kmm" in methods:
        ceilings.append(("rvq_reconstruction", rvq_reconstructions))
    for key, reconstruct in ceilings:
        rec = reconstruct(prompts)
        errs = [np.linalg.norm(r - t, axis=-1).mean() for r, t in zip(rec, truth, strict=True)]
        out[key] = {
            "pass_rate": float(np.mean([verify(r, c.labels).passed for r, c in zip(rec, prompts, strict=True)])),
            "mpjpe_mm": float(1000 * np.mean(errs)),
        }
    for spec in methods:
        m, sampler = method_spec(spec)
        row = verifier_row(prompts, lambda segs, seed_, m=m, s=sampler: generate(segs, m, seed_, sampler=s), seed)
        out[row_name(m, sampler)] = {"sampler": sampler, **row}
    return out


def verifier_row(prompts: list[Clip], gen, seed: int = 0) -> dict:
    """One method's verifier figures on ``prompts``; ``gen(segments, seed)`` -> Motion."""
    passed, sided, direction, times, per_prompt = [], [], [], [], []
    for i, c in enumerate(prompts):
        motion = gen([(c.captions[0], c.frames / 20.0)], seed + i)
        times.append(motion.timings["total"])
        v = verify(motion.joints.astype(np.float64), c.labels)
        passed.append(v.passed)
        per_prompt.append({"id": c.id, "passed": bool(v.passed), "checks": {k: bool(x) for k, x in v.checks.items()}})
        if label_direction(c.labels):
            sided.append(v.passed)
            ok = direction_correct(v.checks, c.labels)
            if ok is not None:
                direction.append(ok)
    return {
        "per_prompt": per_prompt,
        "pass_rate": float(np.mean(passed)),
        "sided_prompts": len(sided),
        "sided_pass_rate": float(np.mean(sided)) if sided else None,
        "direction_prompts": len(direction),
        "direction_accuracy": float(np.mean(direction)) if direction else None,
        "median_generate_s": float(np.median(times)),
    }


def kmm_ablation(states: list[str], rvq_run: str | Path, data: str | Path, n: int = 100, seed: int = 0) -> dict:
    """KMM training variants compared at equal steps (paper Table 4's arms: key-frame vs
    random masking, alignment on/off): each ``states`` entry "name=path/to/state.pt" (a
    training state of ``train kmm-generator``, or a kmm.pt it shipped) is loaded with the tokeniser of ``rvq_run``
    and scored by the verifier (pass rate, direction accuracy) on ``n`` test prompts."""
    from ..inference.checkpoints import load_generator, load_rvq, vae_normalizer
    from ..inference.generation import validate
    from ..inference.masked import MaskedTokenMethod
    from ..inference.registry import REGISTRY

    prompts = test_prompts(data, n)
    rvq, meta = load_rvq(Path(rvq_run) / "rvq.pt")
    norm = vae_normalizer(meta)
    out: dict = {"n": len(prompts)}
    for item in states:
        name, path = item.split("=", 1)
        gen, steps = load_generator(path)  # at its own config; masking / alignment change training only
        method = MaskedTokenMethod(REGISTRY["kmm"], rvq, gen, norm, {}, 0.0)

        def run(segs, seed_, method=method):
            return method.sample(validate(segs, "kmm"), seed_, timings={})

        row = verifier_row(prompts, run, seed)
        row["steps"] = steps
        out[name] = {k: v for k, v in row.items() if k != "per_prompt"}
    return out


@torch.no_grad()
def denoising_losses(method_name: str, data: str | Path, n: int = 256, seed: int = 0) -> np.ndarray:
    """Held-out MSE of a diffusion method's prediction against its training target (epsilon
    or x_0, the checkpoint's) on ``n`` validation clips, with the text: the same clips, timesteps (a fixed grid over
    1..1000) and noise for every method, so arms trained on the same VAE compare directly,
    clip by clip. Far more sensitive than the verifier while models pass only a few percent
    of prompts. Returns the per-clip losses (n,)."""
    from ..data.clips import pad_batch
    from ..inference.registry import load_method
    from ..nn.text import get_text_encoder

    m = load_method(method_name)
    clips = load_clips(data, "val", n)
    enc = get_text_encoder()
    g = torch.Generator().manual_seed(seed)
    losses = []
    for i in range(0, len(clips), 64):
        part = clips[i : i + 64]
        x, mask = pad_batch([m.normalizer.normalize(c.features) for c in part], m.vae.cfg.downsample)
        mu, _ = m.vae.encode(x, mask)
        z0 = mu / m.latent_scale
        t = torch.linspace(1, m.diffusion.cfg.train_steps - 1, len(clips)).long()[i : i + len(part)]
        noise = torch.randn(z0.shape, generator=g)
        zt = m.diffusion.add_noise(z0, noise, t)
        cond = enc.encode([c.captions[0] for c in part])
        frames = torch.tensor([c.frames for c in part])
        pred = m.denoiser(zt, t, cond, frames)
        # against the method's own target: an x_0 model compared with the noise scored as bad
        target = m.diffusion.target(z0, noise, t)
        losses.append(((pred - target) ** 2).mean(dim=tuple(range(1, pred.dim()))).numpy())
    return np.concatenate(losses)


def ablation_table(arms: list[str], data: str | Path, n: int = 100, seed: int = 0) -> dict:
    """The ablation arms (methods registered with ``--arm``, trained at equal steps): held-out
    denoising loss on 256 validation clips, and the verifier's pass rate and direction
    accuracy on ``n`` test prompts. The first arm is the reference: every other arm also gets
    its loss difference to it, clip by clip, with a 95% interval (paired, normal)."""
    from ..inference.checkpoints import read
    from ..inference.generation import generate
    from ..inference.registry import get_info

    prompts = test_prompts(data, n)
    out: dict = {"n": len(prompts), "reference": arms[0]}
    ref = None
    for name in arms:
        info = get_info(name)
        losses = denoising_losses(name, data, seed=seed)
        ref = losses if ref is None else ref
        diff = losses - ref
        ck = read(info.checkpoint)
        row = verifier_row(prompts, lambda segs, seed_, m=name: generate(segs, method=m, seed=seed_), seed)
        out[name] = {
            "checkpoint": info.checkpoint,
            "config": ck["meta"]["config"],
            "steps": ck["meta"]["steps"],
            "params": ck["meta"]["params"],
            "denoising_loss": float(losses.mean()),
            "denoising_loss_vs_reference": float(diff.mean()),
            "denoising_loss_vs_reference_ci95": float(1.96 * diff.std(ddof=1) / np.sqrt(len(diff))),
            **{k: v for k, v in row.items() if k != "per_prompt"},
        }
    return out


def test_timelines(data: str | Path, n: int = 50, min_segments: int = 3, max_segments: int = 5) -> list[dict]:
    """The first ``n`` multi-segment test sequences of the corpus (babel/test_labels.jsonl)
    with ``min_segments``-``max_segments`` segments, each segment with text and labels."""
    path = Path(data) / "babel" / "test_labels.jsonl"
    seqs = [json.loads(line) for line in path.read_text().splitlines() if line.strip()]
    seqs = [s for s in seqs if min_segments <= len(s["segments"]) <= max_segments]
    return seqs[:n]


def timeline_table(methods: list[str], data: str | Path, n: int = 50, seed: int = 0, window: int = 60) -> dict:
    """Per-segment verifier pass rate and transition smoothness on ``n`` multi-segment
    timelines, each method against the corpus's ground-truth sequences.

    Each test sequence becomes a timeline of (segment text, segment seconds, clipped to
    1-10 s); the whole timeline is generated in one call and every segment's frames are
    checked against that segment's labels. Transitions as FlowMDM: jerk curves in windows
    of ``window`` frames centred on the boundaries, Peak Jerk = the curve's maximum, AUJ =
    sum |curve - ground truth's mean jerk| (``metrics``), averaged over timelines.
    """
    from ..inference.generation import generate, method_spec, row_name
    from . import metrics

    seqs = test_timelines(data, n)

    def score(joints: np.ndarray, segments: list[tuple[int, int]], labels: list[dict]) -> tuple[list[bool], object]:
        passed = [verify(joints[a:b], lab).passed for (a, b), lab in zip(segments, labels, strict=True)]
        try:
            curve = metrics.transition_jerk(joints, [a for a, _ in segments[1:]], window)
        except ValueError:
            curve = None
        return passed, curve

    def summarise(passed: list[bool], curves: list, reference: float, times: list[float] | None = None) -> dict:
        curves = [c for c in curves if c is not None]
        row = {
            "segments": len(passed),
            "segment_pass_rate": float(np.mean(passed)),
            "peak_jerk": float(np.mean([c.max() for c in curves])) if curves else None,
            "auj": float(np.mean([metrics.area_under_jerk(c, reference) for c in curves])) if curves else None,
            "timelines_with_curves": len(curves),
        }
        if times:
            row["median_generate_s"] = float(np.median(times))
        return row

    gt_pass, gt_curves = [], []
    for s in seqs:
        feats = np.load(Path(data) / "babel" / "motions" / f"{s['id']}.npy").astype(np.float64)
        joints = features_to_joints(feats)
        p, c = score(
            joints, [(g["start_frame"], g["end_frame"]) for g in s["segments"]], [g["labels"] for g in s["segments"]]
        )
        gt_pass += p
        gt_curves.append(c)
    reference = float(np.mean([c.mean() for c in gt_curves if c is not None]))
    out: dict = {"timelines": len(seqs), "window": window, "gt_mean_jerk": reference}
    out["ground_truth"] = summarise(gt_pass, gt_curves, reference)
    for spec in methods:
        m, sampler = method_spec(spec)
        passed, curves, times = [], [], []
        for i, s in enumerate(seqs):
            plan = [
                (g["text"], float(np.clip((g["end_frame"] - g["start_frame"]) / 20.0, 1.0, 10.0)))
                for g in s["segments"]
            ]
            motion = generate(plan, method=m, seed=seed + i, sampler=sampler)
            times.append(motion.timings["total"])
            p, c = score(motion.joints, [(a, b) for a, b, _ in motion.segments], [g["labels"] for g in s["segments"]])
            passed += p
            curves.append(c)
        out[row_name(m, sampler)] = {"sampler": sampler, **summarise(passed, curves, reference, times)}
    return out


def _report(res: dict, out: str | None, name: str, t0: float) -> None:
    """Print a table's JSON (with the seconds since ``t0``) and write it to ``out/name``."""
    res["seconds"] = time.time() - t0
    text = json.dumps(res, indent=1)
    print(text)
    if out:
        Path(out).mkdir(parents=True, exist_ok=True)
        (Path(out) / name).write_text(text)


def run_suite(args: argparse.Namespace) -> dict:
    from .evaluator import CHECKPOINT, load_evaluator
    from .suite import SuiteConfig, extended_motion_table, markdown, text_to_motion_table

    t0 = time.time()
    cfg = (SuiteConfig.quick if args.quick else SuiteConfig)(
        n=args.n if not args.quick else 32, source=args.source, seed=args.seed
    )
    ev = load_evaluator(args.evaluator or CHECKPOINT)
    methods = [m for m in args.methods.split(",") if m]
    t2m = text_to_motion_table(methods, args.data, cfg, ev)
    has_babel = (Path(args.data) / "babel" / "test.json").is_file()
    ext = extended_motion_table(methods, args.data, cfg, ev) if has_babel and not args.no_extended else None
    res = {"config": cfg.__dict__, "text_to_motion": t2m, "extended": ext, "seconds": time.time() - t0}
    table = markdown(t2m, ext)
    print(table)
    if args.out:
        out = Path(args.out)
        out.mkdir(parents=True, exist_ok=True)
        stem = f"metrics_{args.source}" + ("_quick" if args.quick else "")
        (out / f"{stem}.json").write_text(json.dumps(res, indent=1) + "\n")
        cmd = f"python -m motion_core.eval --methods {args.methods} --data DIR --source {args.source}"
        (out / f"{stem}.md").write_text(
            f"`{cmd}{' --quick' if args.quick else ''}` ({res['seconds']:.0f} s)\n\n{table}"
        )
    return res
