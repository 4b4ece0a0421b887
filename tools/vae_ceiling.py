"""The verifier's pass rate and MPJPE of a VAE's reconstructions on the test prompts (the
diffusion methods' ceiling), for a VAE checkpoint that is not (yet) the shipped one.

    python tools/vae_ceiling.py runs/cvae/z16b/vae.pt --data data/corpus_real --out results/vae_temporal.json

The same computation as the metric suite's ``vae_reconstruction`` rows (``eval/tables.py``),
on the 200 procedural test prompts and on the real test clips whose labels the verifier covers.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from motion_core.body.features import features_to_joints
from motion_core.eval.tables import test_prompts, vae_reconstructions
from motion_core.inference import checkpoints, latent_diffusion
from motion_core.verify.rules import has_rule, verify


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("vae")
    ap.add_argument("--data", required=True)
    ap.add_argument("--out", required=True)
    args = ap.parse_args()
    vae, meta = checkpoints.load_vae(args.vae)
    latent_diffusion._VAE["vae"] = (vae, checkpoints.vae_normalizer(meta))
    out: dict = {
        "command": "python " + " ".join(sys.argv),
        "vae": args.vae,
        "vae_steps": meta.get("steps"),
        "arch": meta.get("arch", "transformer"),
        "config": meta["config"],
        "test_500_mpjpe": meta.get("test"),
    }
    for source in ("procedural", "real"):
        prompts = test_prompts(args.data, 200, source)
        if source == "real":
            prompts = [c for c in prompts if has_rule(c.labels)]
        rec = vae_reconstructions(prompts)
        truth = [features_to_joints(c.features.astype(np.float64)) for c in prompts]
        out[source] = {
            "n": len(prompts),
            "pass_rate": float(np.mean([verify(r, c.labels).passed for r, c in zip(rec, prompts, strict=True)])),
            "mpjpe_mm": float(
                1000 * np.mean([np.linalg.norm(r - t, axis=-1).mean() for r, t in zip(rec, truth, strict=True)])
            ),
        }
        print(source, json.dumps(out[source]))
    Path(args.out).write_text(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
