"""Evaluation commands.

    python -m motion_core.evaluate --methods motion_mamba,baseline --data DIR [--n 200] [--out results/]

For now: the corpus verifier's pass rate on ``n`` test prompts (each a test clip's first
caption, its labels and its duration), per method, next to the ground-truth clips' own
pass rate, and left/right direction accuracy on the prompts that name a side or a turn.
The metric suite of the papers (FID, R-precision, ...) joins this command with the
evaluation issue.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np
import torch

from .corpus.verify import verify
from .data.clips import Clip, load_clips
from .features import features_to_joints


def test_prompts(data: str | Path, n: int = 200, source: str = "procedural") -> list[Clip]:
    """n test clips of one source ("procedural" or "real") spread evenly over the test split."""
    clips = [c for c in load_clips(data, "test") if c.labels.get("source", "procedural") == source]
    if len(clips) <= n:
        return clips
    idx = np.linspace(0, len(clips) - 1, n).round().astype(int)
    return [clips[i] for i in idx]


def _direction(labels: dict) -> str | None:
    for key in ("side", "direction", "turn"):
        v = labels.get(key)
        if isinstance(v, str) and ("left" in v or "right" in v):
            return "left" if "left" in v else "right"
    return None


@torch.no_grad()
def vae_reconstructions(prompts: list[Clip]) -> list[np.ndarray]:
    """The shipped VAE's reconstruction (posterior mean) of each clip, as joints (T, 22, 3):
    the ceiling of what the latent diffusion methods can reach."""
    from .data.clips import pad_batch
    from .registry import shared_vae

    vae, norm = shared_vae()
    out = []
    for c in prompts:
        x, mask = pad_batch([norm.normalize(c.features)], vae.cfg.downsample)
        mu, _ = vae.encode(x, mask)
        rec = norm.denormalize(vae.decode(mu, c.frames)[0, : c.frames]).numpy().astype(np.float64)
        out.append(features_to_joints(rec))
    return out


def verifier_table(
    methods: list[str], data: str | Path, n: int = 200, seed: int = 0, source: str = "procedural"
) -> dict:
    """Verifier pass rates of ground truth, VAE reconstructions and each method's motions
    for ``n`` test prompts of one source (the text is the clip's first caption)."""
    from .generation import generate

    prompts = test_prompts(data, n, source)
    if source == "real":  # only the real clips whose labels the verifier covers
        prompts = [c for c in prompts if not str(c.labels.get("kind", "")).startswith("real:")]
    out: dict = {"n": len(prompts), "source": source}
    gt = [verify(features_to_joints(c.features.astype(np.float64)), c.labels).passed for c in prompts]
    out["ground_truth"] = {"pass_rate": float(np.mean(gt))}
    rec = vae_reconstructions(prompts)
    errs = [
        np.linalg.norm(r - features_to_joints(c.features.astype(np.float64)), axis=-1).mean()
        for r, c in zip(rec, prompts, strict=True)
    ]
    out["vae_reconstruction"] = {
        "pass_rate": float(np.mean([verify(r, c.labels).passed for r, c in zip(rec, prompts, strict=True)])),
        "mpjpe_mm": float(1000 * np.mean(errs)),
    }
    for m in methods:
        passed, sided, times = [], [], []
        for i, c in enumerate(prompts):
            motion = generate([(c.captions[0], c.frames / 20.0)], method=m, seed=seed + i)
            times.append(motion.timings["total"])
            v = verify(motion.joints.astype(np.float64), c.labels)
            passed.append(v.passed)
            if _direction(c.labels):
                sided.append(v.passed)
        out[m] = {
            "pass_rate": float(np.mean(passed)),
            "sided_prompts": len(sided),
            "sided_pass_rate": float(np.mean(sided)) if sided else None,
            "median_generate_s": float(np.median(times)),
        }
    return out


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(prog="python -m motion_core.evaluate", description=__doc__.splitlines()[0])
    ap.add_argument("--methods", default="motion_mamba,baseline")
    ap.add_argument("--data", required=True)
    ap.add_argument("--n", type=int, default=200)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--out", default=None)
    ap.add_argument(
        "--source", default="procedural", choices=["procedural", "real"], help="which test clips: ours or real mocap"
    )
    args = ap.parse_args(argv)
    t0 = time.time()
    res = verifier_table(args.methods.split(","), args.data, args.n, args.seed, args.source)
    res["seconds"] = time.time() - t0
    text = json.dumps(res, indent=1)
    print(text)
    if args.out:
        Path(args.out).mkdir(parents=True, exist_ok=True)
        name = "verifier.json" if args.source == "procedural" else f"verifier_{args.source}.json"
        (Path(args.out) / name).write_text(text)


if __name__ == "__main__":
    main()
