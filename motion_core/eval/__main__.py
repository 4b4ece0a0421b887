"""Evaluation command line.

    python -m motion_core.eval --methods motion_mamba,baseline --data DIR [--source real] [--out results/]
    python -m motion_core.eval ... --quick               # small sample, few repeats (tests)
    python -m motion_core.eval ... --verifier-only       # the verifier table alone
    python -m motion_core.eval ... --timelines           # 50 multi-segment timelines
    python -m motion_core.eval --kmm-ablation key=runs/kmm/state_1000.pt random=... --rvq runs/kmm_rvq --data DIR
    python -m motion_core.eval --arm flat=runs/mm_flat --arm full=runs/mm_full --methods full,flat --ablation ...
    python -m motion_core.eval bench [--scans | --batch 1,32]    # speed (eval/bench.py)
    python -m motion_core.eval evaluator-check --data DIR        # the evaluator's own R-precision
    python -m motion_core.eval pair-speed --a A --b B            # two methods timed in alternating pairs
    python -m motion_core.eval kernel-budget                     # the SSM kernels' element-wise work
    python -m motion_core.eval reader --labels yardstick/kitml_labels.jsonl   # the prompt reader (eval/reader.py)
    python -m motion_core.eval per-kind --data DIR [--vae V] [--rvq R]  # pass rates per kind (eval/per_kind.py)

What each table holds: ``tables`` (verifier, ablations, timelines) and ``suite`` (the papers'
metrics).
"""

from __future__ import annotations

import argparse
import sys
import time

from .evaluator import CHECKPOINT, check
from .tables import _report, ablation_table, kmm_ablation, run_suite, timeline_table, verifier_table


def tables(argv: list[str]) -> None:
    ap = argparse.ArgumentParser(prog="python -m motion_core.eval", description="Evaluation tables.")
    ap.add_argument("--methods", default="motion_mamba,baseline")
    ap.add_argument("--data", required=True)
    ap.add_argument("--n", type=int, default=200)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--out", default=None)
    ap.add_argument(
        "--source", default="procedural", choices=["procedural", "real"], help="which test clips: ours or real mocap"
    )
    ap.add_argument("--quick", action="store_true", help="small sample and few repeats (about a minute per method)")
    ap.add_argument("--verifier-only", action="store_true")
    ap.add_argument(
        "--kmm-ablation",
        nargs="+",
        metavar="NAME=STATE",
        help="compare KMM training states (train kmm-generator runs) by the verifier; needs --rvq",
    )
    ap.add_argument("--rvq", default=None, help="KMM tokeniser run directory (for --kmm-ablation)")
    ap.add_argument(
        "--timelines", action="store_true", help="per-segment verifier and transition jerk on multi-segment timelines"
    )
    ap.add_argument(
        "--arm",
        action="append",
        default=[],
        metavar="NAME=RUN",
        help="register a training run's denoiser (an ablation arm) as method NAME for this run",
    )
    ap.add_argument("--ablation", action="store_true", help="the --arm methods' ablation table (ablation.json)")
    ap.add_argument("--evaluator", default=None, help="evaluator checkpoint (default: the shipped one)")
    ap.add_argument("--no-extended", action="store_true", help="skip the BABEL-style extended-motion table")
    args = ap.parse_args(argv)
    t0 = time.time()
    if args.arm:
        from ..inference.registry import register_arm

        for item in args.arm:
            name, sep, path = item.partition("=")
            if not sep:
                ap.error(f"--arm wants NAME=RUN, got {item!r}")
            register_arm(name, path)
    if args.ablation:
        if not args.arm:
            ap.error("--ablation needs --arm NAME=RUN (at least one)")
        _report(
            ablation_table([a.partition("=")[0] for a in args.arm], args.data, args.n, args.seed),
            args.out,
            "ablation.json",
            t0,
        )
        return
    if args.kmm_ablation:
        _report(
            kmm_ablation(args.kmm_ablation, args.rvq, args.data, args.n, args.seed),
            args.out,
            "kmm_ablation.json",
            t0,
        )
        return
    if args.timelines:
        _report(
            timeline_table(args.methods.split(","), args.data, min(args.n, 50), args.seed),
            args.out,
            "timelines.json",
            t0,
        )
        return
    if not args.verifier_only:
        run_suite(args)
        return
    name = "verifier.json" if args.source == "procedural" else f"verifier_{args.source}.json"
    _report(verifier_table(args.methods.split(","), args.data, args.n, args.seed, args.source), args.out, name, t0)


def evaluator_check(argv: list[str]) -> None:
    """R-precision of real (motion, caption) pairs under the evaluator, on the test split."""
    ap = argparse.ArgumentParser(prog="python -m motion_core.eval evaluator-check", description=evaluator_check.__doc__)
    ap.add_argument("--data", required=True)
    ap.add_argument("--checkpoint", default=str(CHECKPOINT))
    ap.add_argument("--limit", type=int, default=None)
    ap.add_argument("--out", default=None)
    check(ap.parse_args(argv))


def main(argv: list[str] | None = None) -> None:
    argv = list(sys.argv[1:] if argv is None else argv)
    if argv[:1] == ["bench"]:
        from .bench import main as bench

        bench(argv[1:])
    elif argv[:1] == ["evaluator-check"]:
        evaluator_check(argv[1:])
    elif argv[:1] == ["pair-speed"]:
        from .pair_speed import main as pair_speed

        pair_speed(argv[1:])
    elif argv[:1] == ["kernel-budget"]:
        from .kernel_budget import main as kernel_budget

        kernel_budget(argv[1:])
    elif argv[:1] == ["per-kind"]:
        from .per_kind import main as per_kind

        per_kind(argv[1:])
    elif argv[:1] == ["reader"]:
        from .reader import main as reader

        reader(argv[1:])
    else:
        tables(argv)


if __name__ == "__main__":
    main()
