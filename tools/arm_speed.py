"""Time one guided denoiser call of Motion Mamba's architecture arms against the baseline's.

    python tools/arm_speed.py [--arm NAME=FIELD=VALUE,FIELD=VALUE ...] [--rounds 5 --repeats 20] [--out FILE]

Issue 30 asks for Motion Mamba at least as fast as the transformer baseline under the same
sampler, and where that cannot be had, for what stops it. A sampler is a number of denoiser
calls, so this compares one call: the guided pair (batch 2) on a 196-frame latent, under
``no_grad`` with one torch thread, as ``bench --blocks`` times it. The arms are the shipped
Motion Mamba config with fields changed the way ``train --set`` changes them (so an arm
that is fast enough can be trained by the same name); their weights are fresh, which does
not change what a call computes, only its values, and a "fresh" arm of the shipped config is
timed beside the shipped weights to show it. Arms and the baseline are timed in turn, round
after round, and each arm's time is read as its ratio to the baseline's in the same round.
MFLOP are torch's count of one call (matmuls; the scans' recurrences are not counted, as in
``bench``).
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
from pathlib import Path

import torch

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from motion_core.eval.bench import machine, timed
from motion_core.inference.checkpoints import WEIGHTS, read_float32
from motion_core.inference.registry import load_method
from motion_core.models.latent_denoisers import build_denoiser, config_from_dict
from motion_core.models.overrides import override_config

ARMS = {
    "fresh": [],
    "levels=2": ["levels=2"],
    "levels=1": ["levels=1"],
    "htm_order=flat": ["htm_order=flat"],
    "bsm=single": ["bsm=single"],
    "bsm=none": ["bsm=none"],
    "bsm_ssm.expand=1": ["bsm_ssm.expand=1"],
    "levels=2,bsm_ssm.expand=1": ["levels=2", "bsm_ssm.expand=1"],
}


def guided_args(den: torch.nn.Module, frames: int) -> tuple:
    """The guided pair of one sampling step: (z, t, text, frames) at batch 2."""
    fpt = den.frames_per_token
    tokens = min(den.n_z, -(-frames // fpt))
    g = torch.Generator().manual_seed(0)
    z = torch.randn(2, den.n_z, den.head.out_features, generator=g)
    z[:, tokens:] = 0
    return z, torch.full((2,), 500), torch.randn(2, 384, generator=g), torch.full((2,), tokens * fpt)


def call_mflop(den: torch.nn.Module, args: tuple) -> float:
    from torch.utils.flop_counter import FlopCounterMode

    fastpath = torch.backends.mha.get_fastpath_enabled()
    torch.backends.mha.set_fastpath_enabled(False)  # the fused layer hides its matmuls from the counter
    try:
        with torch.no_grad(), FlopCounterMode(display=False) as counter:
            den(*args)
    finally:
        torch.backends.mha.set_fastpath_enabled(fastpath)
    return counter.get_total_flops() / 1e6


def denoisers(arms: dict[str, list[str]]) -> dict[str, tuple[torch.nn.Module, dict]]:
    """name -> (denoiser in eval mode, its description); the baseline and the shipped Motion
    Mamba with their shipped weights, every arm fresh."""
    out = {}
    for kind in ("baseline", "motion_mamba"):
        den = load_method(kind).denoiser
        out[kind] = (den, {"weights": "shipped"})
    shipped = config_from_dict("motion_mamba", read_float32(WEIGHTS / "motion_mamba.pt")["meta"]["config"])
    for name, sets in arms.items():
        torch.manual_seed(0)
        cfg = override_config(shipped, sets)
        den = build_denoiser("motion_mamba", cfg).eval()
        out[f"motion_mamba[{name}]"] = (den, {"weights": "fresh", "set": sets})
    return out


def main(argv: list[str] | None = None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--arm", action="append", default=None, help="NAME=FIELD=VALUE[,FIELD=VALUE] (default: ARMS)")
    ap.add_argument("--frames", type=int, default=196)
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--repeats", type=int, default=20)
    ap.add_argument("--out", default=None)
    args = ap.parse_args(argv)
    torch.set_num_threads(1)
    arms = ARMS
    if args.arm:
        arms = {}
        for spec in args.arm:
            name, _, sets = spec.partition("=")
            arms[name] = [s for s in sets.split(",") if s]
    nets = denoisers(arms)
    calls = {name: (den, guided_args(den, args.frames)) for name, (den, _) in nets.items()}
    ms: dict[str, list[float]] = {name: [] for name in nets}
    ratio: dict[str, list[float]] = {name: [] for name in nets}
    t0 = time.time()
    with torch.no_grad():
        for _ in range(args.rounds):
            this = {}
            for name, (den, a) in calls.items():
                this[name] = 1e3 * statistics.median(timed(lambda den=den, a=a: den(*a), args.repeats))
                ms[name].append(this[name])
            for name in nets:
                ratio[name].append(this[name] / this["baseline"])
    rows = {}
    for name, (den, desc) in nets.items():
        rows[name] = {
            **desc,
            "params": sum(p.numel() for p in den.parameters()),
            "mflop": call_mflop(den, calls[name][1]),
            "ms_per_round": ms[name],
            "ms": statistics.median(ms[name]),
            "x_baseline_per_round": ratio[name],
            "x_baseline": statistics.median(ratio[name]),
        }
    result = {
        "what": "one guided denoiser call (batch 2) on a 196-frame latent, no_grad, one torch thread; "
        "medians of `repeats` calls per round, arms and the baseline in turn each round",
        "command": "python tools/arm_speed.py " + " ".join(argv if argv is not None else sys.argv[1:]),
        "frames": args.frames,
        "rounds": args.rounds,
        "repeats": args.repeats,
        "machine": machine(),
        "seconds": round(time.time() - t0, 1),
        "rows": rows,
    }
    text = json.dumps(result, indent=1)
    if args.out:
        Path(args.out).write_text(text + "\n")
    for name, r in rows.items():
        print(f"{name:42s} {r['ms']:7.2f} ms  x{r['x_baseline']:.2f}  {r['mflop']:6.0f} MFLOP  {r['params']:>8d}")
    return result


if __name__ == "__main__":
    main()
