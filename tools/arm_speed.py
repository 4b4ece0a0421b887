"""Time one guided denoiser call of Motion Mamba's architecture arms against the baseline's.

    python tools/arm_speed.py [--arm NAME=FIELD=VALUE,FIELD=VALUE ...] [--rounds 5 --repeats 20] [--out FILE]

The speed target asks for Motion Mamba at least as fast as the transformer baseline under the same
sampler, and where that cannot be had, for what stops it. A sampler is a number of denoiser
calls, so this compares one call: the guided pair (batch 2) on a 196-frame latent, under
``no_grad`` with one torch thread, as ``bench --blocks`` times it. The arms are the shipped
Motion Mamba config with fields changed the way ``train --set`` changes them (so an arm
that is fast enough can be trained by the same name); their weights are fresh, which does
not change what a call computes, only its values, and a "fresh" arm of the shipped config is
timed beside the shipped weights to show it. Each net is timed right after the baseline, in
an order shuffled every round, and read as its ratio to that baseline timing. MFLOP are
torch's count of one call with the scans run as the plain loop (matmuls and convolutions;
the recurrences are not counted, as in ``bench``).
"""

from __future__ import annotations

import argparse
import json
import random
import statistics
import sys
import time
from pathlib import Path

import torch

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from motion_core.eval.bench import guided_call_args, machine, timed
from motion_core.inference.checkpoints import WEIGHTS, read_float32
from motion_core.inference.registry import load_method
from motion_core.models.latent_denoisers import build_denoiser, config_from_dict
from motion_core.models.overrides import override_config

ARMS = {
    "fresh": [],
    "htm_order=flat": ["htm_order=flat"],
    "htm_ssm.d_state=4": ["htm_ssm.d_state=4"],
    "bsm_ssm.d_state=2": ["bsm_ssm.d_state=2"],
    "bsm_ssm.expand=1": ["bsm_ssm.expand=1"],
    "bsm=single": ["bsm=single"],
    "bsm=none": ["bsm=none"],
    "levels=2": ["levels=2"],
    "levels=1": ["levels=1"],
    # the lightest arm that keeps both of the paper's blocks and a hierarchy of scans
    "levels=2,bsm_ssm.expand=1,bsm_ssm.d_state=2": ["levels=2", "bsm_ssm.expand=1", "bsm_ssm.d_state=2"],
}


def call_mflop(den: torch.nn.Module, args: tuple) -> float:
    from torch.utils.flop_counter import FlopCounterMode

    from motion_core.nn.ssm import forced_scan

    fastpath = torch.backends.mha.get_fastpath_enabled()
    torch.backends.mha.set_fastpath_enabled(False)  # the fused layer hides its matmuls from the counter
    try:
        # the fused SSM kernel does its x and dt projections where the counter cannot see them
        with forced_scan("sequential"), torch.no_grad(), FlopCounterMode(display=False) as counter:
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
        arms = {"fresh": []}  # the control: the shipped config with fresh weights
        for spec in args.arm:
            name, _, sets = spec.partition("=")
            if name in arms:
                ap.error(f"arm {name!r} named twice")
            arms[name] = [s for s in sets.split(",") if s]
    nets = denoisers(arms)
    calls = {name: (den, guided_call_args(den, args.frames)) for name, (den, _) in nets.items()}
    ms: dict[str, list[float]] = {name: [] for name in nets}
    ratio: dict[str, list[float]] = {name: [] for name in nets}
    t0 = time.time()
    # each net is timed right after a timing of the baseline, in an order shuffled every round,
    # so the machine's drift lands on both sides of a ratio rather than on the last arms
    order = [name for name in nets if name != "baseline"]
    rng = random.Random(0)
    with torch.no_grad():
        for _ in range(args.rounds):
            rng.shuffle(order)
            for name in order:
                for who in ("baseline", name):
                    den, a = calls[who]
                    ms[who].append(1e3 * statistics.median(timed(lambda den=den, a=a: den(*a), args.repeats)))
                ratio[name].append(ms[name][-1] / ms["baseline"][-1])
    ratio["baseline"] = [1.0]
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
        "what": f"one guided denoiser call (batch 2) on a {args.frames}-frame latent, no_grad, one torch thread; "
        "medians of `repeats` calls, each net timed right after the baseline, in a shuffled order every round",
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
