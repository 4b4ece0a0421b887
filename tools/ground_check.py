"""How the floor rule changes the verifier's reading, per method, on validation prompts.

    python tools/ground_check.py --data data/corpus_real [--methods motion_mamba,kmm,ftmomamba,baseline] \\
        [--out results/ground_choice.json]

Each method generates every validation prompt of both sources once (``generate``, seed 0,
its default sampler, no foot lock) with the whole-clip floor (the clip's lowest foot point
on y = 0, the rule before ``body.ground``); then each candidate ``GroundConfig`` stands the
same motions on the floor frame by frame and the verifier reads them again. Ground truth
(the clips' own joints, rigid; ``--gt-n`` clips a source) goes through the same rules: a
floor rule must not change its verdicts. Pass rates per source, pooled over both, and per kind of action. This is where
``GroundConfig``'s defaults were chosen (validation only; the test split is for reporting).
"""

from __future__ import annotations

import argparse
import collections
import functools
import json
import sys
import time
from pathlib import Path
from unittest import mock

import numpy as np
import torch

# run as a script from the checkout: the package is not installed
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from motion_core.body.features import features_to_joints
from motion_core.body.ground import GroundConfig, ground
from motion_core.body.ik import rigidify
from motion_core.inference.generation import generate
from motion_core.train.validation import VAL_SOURCES, validation_prompts
from motion_core.verify.rules import verify

CANDIDATES = {
    f"height_{h}_speed_{v}": GroundConfig(height=h, speed=v) for h in (0.05, 0.06, 0.07, 0.08) for v in (0.3, 0.45, 0.6)
}
# the rule before body.ground: one shift for the whole clip
CLIP_FLOOR = GroundConfig(max_shift=0.0)


def clip_floor(joints: np.ndarray) -> np.ndarray:
    return ground(joints, cfg=CLIP_FLOOR)


def motions(method: str, prompts: list) -> list[np.ndarray]:
    """Each prompt's motion as ``generate`` makes it, but on the whole-clip floor."""
    if method == "ground_truth":
        return [clip_floor(rigidify(features_to_joints(c.features.astype(np.float64)))) for c in prompts]
    # generate's modules took on_floor by name: patch each one
    with (
        mock.patch("motion_core.inference.base.on_floor", clip_floor),
        mock.patch("motion_core.inference.latent_diffusion.on_floor", clip_floor),
        mock.patch("motion_core.inference.masked.on_floor", clip_floor),
    ):
        return [
            generate([(c.captions[0], c.frames / 20.0)], method=method, seed=0, foot_lock=False).joints for c in prompts
        ]


def score(joints: list[np.ndarray], prompts: list, rule) -> dict:
    verdicts = [verify(rule(j).astype(np.float64), c.labels) for j, c in zip(joints, prompts, strict=True)]
    kinds: dict[str, list[int]] = collections.defaultdict(lambda: [0, 0])
    for v, c in zip(verdicts, prompts, strict=True):
        row = kinds[str(c.labels.get("kind", "other"))]
        row[0] += int(v.passed)
        row[1] += 1
    return {
        "n": len(verdicts),
        "passed": sum(v.passed for v in verdicts),
        "pass_rate": float(np.mean([v.passed for v in verdicts])),
        "kinds": {k: f"{a}/{b}" for k, (a, b) in sorted(kinds.items())},
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--data", required=True)
    ap.add_argument("--methods", default="motion_mamba,kmm,ftmomamba,baseline")
    ap.add_argument("--n", type=int, default=200, help="validation prompts per source for the methods")
    ap.add_argument("--gt-n", type=int, default=1000, help="validation clips per source for ground truth")
    ap.add_argument("--out", default=None)
    args = ap.parse_args()
    torch.set_num_threads(1)
    t0 = time.time()
    prompts = {s: validation_prompts(args.data, args.n, s) for s in VAL_SOURCES}
    gt_prompts = {s: validation_prompts(args.data, args.gt_n, s) for s in VAL_SOURCES}
    rules = {"clip_floor": clip_floor} | {k: functools.partial(ground, cfg=c) for k, c in CANDIDATES.items()}
    doc: dict = {
        "command": "python tools/ground_check.py " + " ".join(sys.argv[1:]),
        "candidates": {k: vars(c) for k, c in CANDIDATES.items()},
        "rows": {},
    }
    for method in ["ground_truth", *args.methods.split(",")]:
        which = gt_prompts if method == "ground_truth" else prompts
        joints = {s: motions(method, p) for s, p in which.items()}
        row = {}
        for name, rule in rules.items():
            per = {s: score(joints[s], which[s], rule) for s in which}
            n = sum(r["n"] for r in per.values())
            row[name] = {**per, "pooled": sum(r["passed"] for r in per.values()) / n}
            print(method, name, " ".join(f"{s} {r['pass_rate']:.3f}" for s, r in per.items()), flush=True)
        doc["rows"][method] = row
    doc["seconds"] = time.time() - t0
    text = json.dumps(doc, indent=1)
    if args.out:
        Path(args.out).write_text(text + "\n")
    else:
        print(text)


if __name__ == "__main__":
    main()
