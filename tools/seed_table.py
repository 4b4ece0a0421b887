"""Several seeds' verifier tables as one: each method's pass rate and direction accuracy per
seed, their mean and spread, in float32 as shipped (the three-seed table).

    python tools/seed_table.py results/verifier.json /tmp/r/seed1/verifier.json /tmp/r/seed2/verifier.json \\
        --seeds 0 1 2 --methods kmm,motion_mamba,ftmomamba,baseline --out results/verifier_seeds.json

Each input is a table ``python -m motion_core.eval --verifier-only --seed S`` wrote (the
same prompts, ``--n`` and ``--source``, another sampling seed); the rows named in
``--methods`` are read from each. Several sources (procedural, real) go in as separate
runs of this tool, or one ``--out`` each.
"""

from __future__ import annotations

import argparse
import json
import statistics
from pathlib import Path


def seed_rows(tables: list[dict], seeds: list[int], methods: list[str]) -> dict:
    out: dict = {}
    for m in methods:
        per = []
        for seed, t in zip(seeds, tables, strict=True):
            row = t[m]
            per.append(
                {"seed": seed, "pass_rate": row["pass_rate"], "direction_accuracy": row.get("direction_accuracy")}
            )
        rates = [p["pass_rate"] for p in per]
        dirs = [p["direction_accuracy"] for p in per if p["direction_accuracy"] is not None]
        out[m] = {
            "seeds": per,
            "pass_rate_mean": statistics.mean(rates),
            "pass_rate_sd": statistics.stdev(rates) if len(rates) > 1 else 0.0,
            "direction_mean": statistics.mean(dirs) if dirs else None,
        }
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("tables", nargs="+", type=Path)
    ap.add_argument("--seeds", nargs="+", type=int, required=True)
    ap.add_argument("--methods", required=True)
    ap.add_argument("--out", type=Path, required=True)
    ap.add_argument("--note", default="")
    args = ap.parse_args()
    if len(args.seeds) != len(args.tables):
        raise SystemExit("one --seeds entry per table")
    tables = [json.loads(p.read_text()) for p in args.tables]
    sources = {t.get("source") for t in tables}
    ns = {t.get("n") for t in tables}
    if len(sources) != 1 or len(ns) != 1:
        raise SystemExit(f"the tables differ in source or n: {sources}, {ns}")
    doc = {
        "source": sources.pop(),
        "n": ns.pop(),
        "seeds": args.seeds,
        "rows": seed_rows(tables, args.seeds, args.methods.split(",")),
        "inputs": [str(p) for p in args.tables],
        "note": args.note,
    }
    args.out.write_text(json.dumps(doc, indent=1) + "\n")
    for m, r in doc["rows"].items():
        d = r["direction_mean"]
        print(
            f"{m}: {100 * r['pass_rate_mean']:.1f}% ± {100 * r['pass_rate_sd']:.1f}"
            + (f", direction {100 * d:.1f}%" if d is not None else "")
        )


if __name__ == "__main__":
    main()
