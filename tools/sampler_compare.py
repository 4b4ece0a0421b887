"""A teacher's guided DDIM against its consistency student, on the validation prompts.

    python tools/sampler_compare.py --teacher motion_core/weights/baseline.pt \\
        --student runs/lcm_baseline/baseline_lcm.pt --vae runs/vae2 --data data/corpus_real \\
        [--out results/sampler_compare_baseline.json]

Rows: the teacher at its shipped DDIM steps (the registry's, 10) and at 1, 2 and 4 DDIM
steps (what cutting its steps alone gives), the student at 1, 2 and 4 consistency steps;
each with the verifier's pass rate and direction accuracy on the validation clips of
``--source`` (both by default: ``--n`` procedural prompts and the real clips the verifier
covers, pooled, each source's own figures beside; seed 0, guidance 7.5) and the
milliseconds per prompt with decoding, all in this one run. Validation prompts only:
settings are chosen on them; the test split is for reporting.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

# run as a script from the checkout: the package is not installed
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from motion_core.inference.checkpoints import load_denoiser, load_student, load_vae, read_float32, vae_normalizer
from motion_core.inference.registry import DIFFUSION_STEPS
from motion_core.inference.samplers import ConsistencySampler, GuidedDDIM
from motion_core.nn.consistency import ConsistencyConfig
from motion_core.nn.diffusion import Diffusion, DiffusionConfig
from motion_core.train.validation import VAL_SOURCES, load_validation, validation_pass_rate


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--teacher", required=True)
    ap.add_argument("--student", required=True)
    ap.add_argument("--vae", required=True, help="run directory holding the teachers' vae.pt")
    ap.add_argument("--data", required=True)
    ap.add_argument("--n", type=int, default=200)
    ap.add_argument("--guidance", type=float, default=7.5)
    ap.add_argument("--source", choices=("both", *VAL_SOURCES), default="both", help="which validation clips")
    ap.add_argument("--out", default=None)
    args = ap.parse_args()
    tck, sck = read_float32(args.teacher), read_float32(args.student)
    teacher = load_denoiser(tck, tck["meta"]["kind"]).eval()
    student = load_student(sck).eval()
    diffusion = Diffusion(DiffusionConfig(**tck["meta"]["diffusion"]))
    vae, vmeta = load_vae(Path(args.vae) / "vae.pt")
    norm, scale = vae_normalizer(vmeta), float(tck["meta"]["latent_scale"])
    sources = VAL_SOURCES if args.source == "both" else (args.source,)
    sets = load_validation(args.data, args.n, sources)  # once, outside the timed arms
    arms = [("teacher DDIM", GuidedDDIM(teacher, diffusion), s) for s in (DIFFUSION_STEPS, 4, 2, 1)]
    fast = ConsistencySampler(student, diffusion, ConsistencyConfig(**sck["meta"]["consistency"]))
    arms += [("student consistency", fast, s) for s in (4, 2, 1)]
    rows = []
    for name, sampler, steps in arms:
        t0 = time.perf_counter()
        res = validation_pass_rate(sampler, vae, norm, scale, sets, args.n, seed=0, guidance=args.guidance, steps=steps)
        took = time.perf_counter() - t0
        rows.append({"sampler": name, "steps": steps, **res, "ms_per_prompt_with_decode": 1e3 * took / res["n"]})
        print(json.dumps(rows[-1]))
    doc = {
        "command": "python tools/sampler_compare.py "
        + " ".join(f"--{k} {v}" for k, v in vars(args).items() if v is not None and k != "out"),
        "teacher": {"file": Path(args.teacher).name, "steps": tck["meta"].get("steps")},
        "student": {"file": Path(args.student).name, "steps": sck["meta"].get("steps")},
        "rows": rows,
    }
    if args.out:
        Path(args.out).write_text(json.dumps(doc, indent=1) + "\n")


if __name__ == "__main__":
    main()
