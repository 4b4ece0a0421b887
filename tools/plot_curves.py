"""Plot training curves: the verifier pass rate on validation prompts against training step.

    python tools/plot_curves.py results/curves/temporal_*.json --out docs/training-curve-temporal.png

Each file is a ``curve.json`` written by ``python -m motion_core.train METHOD --val-every N``
(a list of {"step", "pass_rate", "direction_accuracy", ...}); its name without ``.json``
labels the line. A horizontal reference line may be given with ``--ceiling LABEL=RATE``.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("curves", nargs="+", type=Path)
    ap.add_argument("--out", type=Path, required=True)
    ap.add_argument("--title", default="Verifier pass rate on 200 validation prompts")
    ap.add_argument("--ceiling", action="append", default=[], metavar="LABEL=RATE")
    ap.add_argument("--xlabel", default="training step (batch 64)", help="what a step is (its batch)")
    ap.add_argument("--logx", action="store_true", help="a log step axis (curves of very different lengths)")
    args = ap.parse_args(argv)
    fig, ax = plt.subplots(figsize=(7, 4), dpi=120)
    for path in args.curves:
        pts = json.loads(path.read_text())
        ax.plot([p["step"] for p in pts], [100 * p["pass_rate"] for p in pts], marker="o", label=path.stem)
    if args.logx:  # before the ceilings' labels, which sit at the axis's left end
        ax.set_xscale("log")
    for item in args.ceiling:
        label, _, rate = item.partition("=")
        ax.axhline(100 * float(rate), ls="--", color="grey", lw=1)
        y = 100 * float(rate)
        ax.text(ax.get_xlim()[0], y - 4 if y > 90 else y + 1, label, color="grey", fontsize=8)
    ax.set_xlabel(args.xlabel)
    ax.set_ylabel("verifier pass rate (%)")
    ax.set_ylim(0, 100)
    ax.set_title(args.title)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    args.out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(args.out)


if __name__ == "__main__":
    main()
