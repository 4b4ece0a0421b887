"""Time ``generate`` of two methods in alternating pairs in one process: is A at least as
fast as B?

    python -m motion_core.eval pair-speed --a motion_mamba:quality --b baseline:quality \\
        [--pairs 40] [--steps N] [--out FILE]

``bench`` times one method after another, so a machine that slows down between them moves
the ratio (this VM's runs drift by 10-30% within minutes), and for two methods near the same
speed that drift decides the answer. Here each pair runs A and B back to back in a
random order, on the same request (``bench``'s 196-frame prompt, then its 10 s two-segment
timeline, each as its own series), after warm-up calls of both; the ratio is taken within
each pair, and the result is the median of the pairs' ratios with its quartiles and the
share of pairs in which A was the faster. One torch thread (set here, restored after), as
``bench``'s recorded runs had.
``MMS_WEIGHTS_DIR`` chooses the weights as it does for the app.
"""

from __future__ import annotations

import argparse
import functools
import json
import random
import statistics
import sys
import time
from pathlib import Path

import torch

from ..inference.generation import generate, method_spec, row_name
from ..inference.registry import load_method
from .bench import BENCH_TEXT, TIMELINE_10S, machine

PROMPT = [(BENCH_TEXT, 196 / 20.0)]


def quartiles(xs: list[float]) -> list[float]:
    q = statistics.quantiles(xs, n=4, method="inclusive")
    return [q[0], statistics.median(xs), q[2]]


def pair_series(run_a, run_b, request, pairs: int, rng: random.Random, warmup: int = 3) -> dict:
    """``pairs`` back-to-back timings of A and B on ``request``, in a random order per pair."""
    for _ in range(warmup):
        run_a(request)
        run_b(request)
    a_ms, b_ms = [], []
    for _ in range(pairs):
        order = [("a", run_a), ("b", run_b)]
        rng.shuffle(order)
        got = {}
        for name, run in order:
            t0 = time.perf_counter()
            run(request)
            got[name] = 1e3 * (time.perf_counter() - t0)
        a_ms.append(got["a"])
        b_ms.append(got["b"])
    ratios = [a / b for a, b in zip(a_ms, b_ms, strict=True)]
    return {
        "a_ms_quartiles": quartiles(a_ms),
        "b_ms_quartiles": quartiles(b_ms),
        "ratio_quartiles": quartiles(ratios),
        "a_faster_share": sum(r < 1.0 for r in ratios) / len(ratios),
    }


def main(argv: list[str] | None = None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--a", required=True, help="METHOD[:SAMPLER], e.g. motion_mamba:quality")
    ap.add_argument("--b", required=True, help="METHOD[:SAMPLER], e.g. baseline:quality")
    ap.add_argument("--pairs", type=int, default=40)
    ap.add_argument("--steps", type=int, default=None, help="sampling steps of both (default: each sampler's own)")
    ap.add_argument("--seed", type=int, default=0, help="of the pairs' order (the motions use seed 0)")
    ap.add_argument("--out", default=None)
    args = ap.parse_args(argv)
    if args.pairs < 2:
        raise SystemExit("--pairs must be at least 2")
    if args.steps is not None and args.steps < 1:
        raise SystemExit("--steps must be at least 1")
    threads = torch.get_num_threads()
    torch.set_num_threads(1)
    try:
        runs = {}
        for key in ("a", "b"):
            name, sampler = method_spec(getattr(args, key))
            load_method(name)  # loading is not part of the timing
            runs[key] = (
                row_name(name, sampler),
                functools.partial(generate, method=name, seed=0, sampler=sampler, steps=args.steps),
            )
        rng = random.Random(args.seed)
        t0 = time.perf_counter()
        result = {
            "what": "generate() of A and B timed back to back in alternating pairs (random order per pair), "
            "ratio A/B taken within each pair; one torch thread",
            "command": "python -m motion_core.eval pair-speed " + " ".join(argv if argv is not None else sys.argv[1:]),
            "a": runs["a"][0],
            "b": runs["b"][0],
            "pairs": args.pairs,
            "steps": args.steps or "each sampler's default",
            "machine": machine(),
            "frames_196": pair_series(runs["a"][1], runs["b"][1], PROMPT, args.pairs, rng),
            "timeline_10s": pair_series(runs["a"][1], runs["b"][1], TIMELINE_10S, args.pairs, rng),
        }
        result["seconds"] = round(time.perf_counter() - t0, 1)
    finally:
        torch.set_num_threads(threads)
    for series in ("frames_196", "timeline_10s"):
        s = result[series]
        lo, mid, hi = s["ratio_quartiles"]
        print(
            f"{series:13s} {result['a']} / {result['b']}: {mid:.3f}x (quartiles {lo:.3f}-{hi:.3f}), "
            f"A faster in {s['a_faster_share']:.0%} of {args.pairs} pairs; "
            f"A {s['a_ms_quartiles'][1]:.1f} ms, B {s['b_ms_quartiles'][1]:.1f} ms"
        )
    if args.out:
        Path(args.out).write_text(json.dumps(result, indent=1) + "\n")
    return result


if __name__ == "__main__":
    main()
