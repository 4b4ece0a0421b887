"""DDIM steps against text following for the shipped diffusion methods, on validation prompts.

    python tools/ddim_steps_sweep.py --data data/corpus_real [--methods motion_mamba,ftmomamba,baseline] \\
        [--steps 50 20 10 4] [--guidance 4 7.5 11] [--source real] [--out results/ddim_steps_val.json]

Each method's shipped denoiser and VAE sample the ``--n`` validation prompts (seed 0, its
default guidance or each of ``--guidance``) at each step count; rows give the verifier's
pass rate, direction accuracy and the seconds per prompt (sampling and decoding, batches of
100), all in one run. The denoisers trained on the x_0 target predict the clean latent at every step, so a
few DDIM steps may lose nothing; this is where the registry's default steps are chosen
(validation only; the test split is for reporting).
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

from motion_core.inference.registry import load_method
from motion_core.inference.samplers import GuidedDDIM
from motion_core.train.validation import validation_prompts, verifier_pass_rate


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--data", required=True)
    ap.add_argument("--methods", default="motion_mamba,ftmomamba,baseline")
    ap.add_argument("--steps", type=int, nargs="+", default=[50, 20, 10, 4])
    ap.add_argument(
        "--guidance", type=float, nargs="+", default=None, help="guidance scales to try (default: each method's own)"
    )
    ap.add_argument("--n", type=int, default=200)
    ap.add_argument("--source", default="procedural", choices=["procedural", "real"], help="which validation clips")
    ap.add_argument("--out", default=None)
    args = ap.parse_args()
    torch.set_num_threads(1)
    prompts = validation_prompts(args.data, args.n, args.source)
    rows = []
    for name in args.methods.split(","):
        m = load_method(name)
        sampler = GuidedDDIM(m.denoiser, m.diffusion)
        for steps in args.steps:
            for guidance in args.guidance or [m.info.default_guidance]:
                t0 = time.perf_counter()
                res = verifier_pass_rate(sampler, m.vae, m.normalizer, m.latent_scale, prompts, 0, guidance, steps)
                took = (time.perf_counter() - t0) / len(prompts)
                rows.append({"method": name, "steps": steps, "guidance": guidance, **res, "s_per_prompt": took})
                print(json.dumps(rows[-1]), flush=True)
    if args.out:
        cmd = "python tools/ddim_steps_sweep.py " + " ".join(
            f"--{k} {' '.join(map(str, v)) if isinstance(v, list) else v}"
            for k, v in vars(args).items()
            if k != "out" and v is not None
        )
        Path(args.out).write_text(
            json.dumps({"command": cmd, "split": "val", "source": args.source, "rows": rows}, indent=1) + "\n"
        )


if __name__ == "__main__":
    main()
