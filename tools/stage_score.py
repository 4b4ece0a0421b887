"""A denoiser checkpoint (a stage, a run's) scored with its method's quality sampler on the
pooled validation prompts, over several seeds: how a stage is chosen against what ships;
or a consistency student of it, scored with its own sampler.

    python tools/stage_score.py --kind ftmomamba --checkpoint stages/ftmomamba.pt \\
        --data data/corpus_real [--seeds 0 1 2 3] [--out FILE]
    python tools/stage_score.py --kind ftmomamba --checkpoint motion_core/weights/ftmomamba.pt \\
        --student runs/lcm/ftmomamba_lcm.pt --data data/corpus_real [--steps 1]

The method's shipped VAE decodes. The sampler is the registry's quality sampler (guided DDIM
at its steps and guidance), or ``--steps`` / ``--guidance`` (the training curves' protocol
is 10 at 7.5 with ``--source procedural``). It samples ``--n`` procedural validation
prompts and the real validation clips the verifier covers, pooled
(``train.validation.validation_pass_rate``), one row per seed. ``--checkpoint
motion_core/weights/KIND.pt`` gives the shipped weights' own rows. ``--student S`` scores
the consistency student S of that checkpoint instead (the fast sampler: its own steps and
folded-in guidance unless ``--steps`` / ``--guidance`` name others); a student of other
weights, or of another kind (guidance-distilled), is refused. Validation prompts only: the
test split is for reporting.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import torch

# run as a script from the checkout: the package is not installed
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import motion_core
from motion_core.inference.checkpoints import distilled_from, load_denoiser, load_student, read_float32
from motion_core.inference.latent_diffusion import LatentDiffusionMethod
from motion_core.inference.registry import load_method
from motion_core.inference.samplers import GuidedDDIM, student_kind
from motion_core.nn.diffusion import Diffusion, DiffusionConfig
from motion_core.train.validation import VAL_SOURCES, load_validation, validation_pass_rate


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--kind", required=True, help="the method whose VAE and sampler settings score it")
    ap.add_argument("--checkpoint", required=True)
    ap.add_argument("--data", required=True, help="the corpus directory (its validation split)")
    ap.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2, 3])
    ap.add_argument("--n", type=int, default=200)
    ap.add_argument(
        "--steps", type=int, default=None, help="DDIM steps (default: the registry's); a student's consistency steps"
    )
    ap.add_argument(
        "--guidance", type=float, default=None, help="guidance scale (default: the registry's, or the student's)"
    )
    ap.add_argument(
        "--source", choices=("both", "procedural", "real"), default="both", help="which validation prompts (pooled)"
    )
    ap.add_argument("--student", default=None, help="score this consistency student of --checkpoint instead")
    ap.add_argument("--out", default=None)
    args = ap.parse_args()
    torch.set_num_threads(1)
    m = load_method(args.kind)
    if not isinstance(m, LatentDiffusionMethod):
        raise SystemExit(f"{args.kind} is not a latent diffusion method: it has no denoiser to score")
    ck = read_float32(args.checkpoint)
    meta = ck["meta"]
    if meta.get("kind") != args.kind:
        raise SystemExit(f"{args.checkpoint} is a {meta.get('kind')!r} checkpoint, not {args.kind!r}")
    if meta.get("vae_steps") != getattr(m.vae, "steps", None):
        raise SystemExit(f"{args.checkpoint} was trained on another VAE's latents than the shipped one")
    denoiser = load_denoiser(ck, args.kind).eval()
    # the schedule and prediction target it was trained with, as the method's loader takes them
    diffusion = Diffusion(DiffusionConfig(**meta.get("diffusion", {})))
    scale = float(meta["latent_scale"])
    quality = next(x for x in motion_core.methods() if x["name"] == args.kind)["sampler_options"]["quality"]
    steps = args.steps if args.steps is not None else int(quality["steps"])
    guidance = args.guidance if args.guidance is not None else float(quality["default_guidance"])
    sampler = GuidedDDIM(denoiser, diffusion)
    if args.student:
        sck = read_float32(args.student)
        if "consistency" not in sck["meta"]:
            raise SystemExit(f"{args.student} is not a consistency student (train lcm): this tool scores those")
        if not distilled_from(sck["meta"], ck["state_dict"]):
            raise SystemExit(f"{args.student} was not distilled from {args.checkpoint}")
        kind = student_kind(sck["meta"])  # the registry's own reading of a student: its sampler and defaults
        sampler = kind.sampler(load_student(sck).eval(), diffusion)
        own = kind.options()
        steps = args.steps if args.steps is not None else int(own["steps"])
        guidance = args.guidance if args.guidance is not None else float(own["default_guidance"])
    sets = load_validation(args.data, args.n, VAL_SOURCES if args.source == "both" else (args.source,))
    rows = []
    for seed in args.seeds:
        t0 = time.perf_counter()
        with torch.no_grad():
            r = validation_pass_rate(
                sampler,
                m.vae,
                m.normalizer,
                scale,
                sets,
                seed=seed,
                guidance=guidance,
                steps=steps,
            )
        rows.append({"seed": seed, **r, "seconds": time.perf_counter() - t0})
        print(json.dumps({k: v for k, v in rows[-1].items() if k != "sources"}), flush=True)
    mean = sum(r["pass_rate"] for r in rows) / len(rows)
    out = {
        "split": "val",
        "kind": args.kind,
        "checkpoint": args.checkpoint,
        "steps_trained": ck["meta"].get("steps"),
        **({"student": args.student, "student_steps_trained": sck["meta"].get("steps")} if args.student else {}),
        "sampler": {"consistency_steps" if args.student else "ddim_steps": steps, "guidance": guidance},
        "source": args.source,
        "rows": rows,
        "mean_pooled": mean,
        "command": "python tools/stage_score.py " + " ".join(sys.argv[1:]),
    }
    print(json.dumps({"mean_pooled": mean}))
    if args.out:
        Path(args.out).write_text(json.dumps(out, indent=1) + "\n")


if __name__ == "__main__":
    main()
