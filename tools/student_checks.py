"""Where one checkpoint loses to another: the verifier's results per kind of action, and
the checks the second fails on prompts the first passes, on one source's validation clips.
The second is a distilled student of the first (either kind), or another denoiser (a
stage against the shipped one).

    python tools/student_checks.py --teacher motion_core/weights/baseline.pt \\
        --student stages/baseline_fast.pt --vae runs/tvae --data data/corpus_real --source real \\
        [--out results/student_checks_baseline_fast.json]

Each samples as it ships (a denoiser: guided DDIM at the registry's steps; a student: its
own sampler, steps and guidance), seed 0, as the training validation does. Validation
prompts only.
"""

from __future__ import annotations

import argparse
import collections
import json
import sys
from pathlib import Path

# run as a script from the checkout: the package is not installed
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import numpy as np

from motion_core.inference.checkpoints import load_denoiser, load_student, load_vae, read_float32, vae_normalizer
from motion_core.inference.registry import DIFFUSION_STEPS, sampling_scale
from motion_core.inference.samplers import GuidedDDIM, LatentSampler, student_kind
from motion_core.nn.diffusion import Diffusion, DiffusionConfig
from motion_core.train.validation import VAL_SOURCES, sample_joints, validation_prompts
from motion_core.verify.rules import verify


def _sampler(ck: dict, diffusion: Diffusion) -> tuple[LatentSampler, int | None, float | None]:
    """A student's own sampler at its default steps and guidance (either kind:
    ``samplers.student_kind``), or a denoiser's guided DDIM at the registry's steps and its
    method's scale (before 2026-11-27 the teacher sampled at the diffusion config's 7.5,
    above the scales its method samples at since 2026-11-26)."""
    meta = ck["meta"]
    if "consistency" in meta or "guidance_distillation" in meta:
        return student_kind(meta).sampler(load_student(ck).eval(), diffusion), None, None
    denoiser = load_denoiser(ck, meta["kind"]).eval()
    return GuidedDDIM(denoiser, diffusion), DIFFUSION_STEPS, sampling_scale(meta["kind"], diffusion.cfg.guidance)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--teacher", required=True)
    ap.add_argument(
        "--student",
        required=True,
        help="a distilled student (train lcm or guidance), or another denoiser",
    )
    ap.add_argument("--vae", required=True, help="run directory holding the teacher's vae.pt")
    ap.add_argument("--data", required=True)
    ap.add_argument("--source", choices=VAL_SOURCES, default="real")
    ap.add_argument("--n", type=int, default=200)
    ap.add_argument("--out", default=None)
    args = ap.parse_args()
    tck, sck = read_float32(args.teacher), read_float32(args.student)
    diffusion = Diffusion(DiffusionConfig(**tck["meta"]["diffusion"]))
    samplers = {"teacher": _sampler(tck, diffusion), "student": _sampler(sck, diffusion)}
    vae, vmeta = load_vae(Path(args.vae) / "vae.pt")
    norm, scale = vae_normalizer(vmeta), float(tck["meta"]["latent_scale"])
    prompts = validation_prompts(args.data, args.n, args.source)
    texts, frames = [c.captions[0] for c in prompts], [c.frames for c in prompts]
    results = {}
    for name, (sampler, steps, guidance) in samplers.items():
        joints = sample_joints(sampler, vae, norm, scale, texts, frames, 0, guidance, steps)
        results[name] = [verify(j.astype(np.float64), c.labels) for j, c in zip(joints, prompts, strict=True)]
    per_kind: dict[str, dict[str, int]] = collections.defaultdict(lambda: {"n": 0, "teacher": 0, "student": 0})
    lost: collections.Counter[str] = collections.Counter()
    for c, t, s in zip(prompts, results["teacher"], results["student"], strict=True):
        row = per_kind[str(c.labels.get("kind", "other"))]
        row["n"] += 1
        row["teacher"] += int(t.passed)
        row["student"] += int(s.passed)
        if t.passed and not s.passed:
            lost.update(k for k, ok in s.checks.items() if not ok)
    doc = {
        "command": "python tools/student_checks.py "
        + " ".join(f"--{k} {v}" for k, v in vars(args).items() if v is not None and k != "out"),
        "split": "val",
        "prompts": len(prompts),
        "passed": {name: int(sum(v.passed for v in r)) for name, r in results.items()},
        "per_kind": dict(sorted(per_kind.items(), key=lambda kv: -kv[1]["n"])),
        "checks_the_student_fails_where_the_teacher_passes": dict(lost.most_common()),
    }
    print(json.dumps(doc, indent=1))
    if args.out:
        Path(args.out).write_text(json.dumps(doc, indent=1) + "\n")


if __name__ == "__main__":
    main()
