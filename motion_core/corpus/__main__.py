"""python -m motion_core.corpus {build,check,verify} ...

build OUT_DIR      write the corpus (defaults: 20,000 train / 1,000 val / 2,000 test clips,
                   1,000 / 50 / 100 multi-segment sequences)
check DIR          realism figures over the whole set; exit 1 if any is out of bounds
verify DIR         the rule-based verifier on a split: pass rate on true and shuffled labels
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

from ..verify.realism import BOUNDS, summarize
from ..verify.rules import has_rule
from .build import BuildConfig, build, default_workers, process_pool
from .jobs import realism_job, seq_job, verify_job


def _load_labels(d: Path) -> list[dict]:
    with open(d / "labels.jsonl", encoding="utf-8") as f:
        return [json.loads(ln) for ln in f if ln.strip()]


def cmd_check(d: Path, workers: int, limit: int | None) -> int:
    t0 = time.time()
    rows = _load_labels(d)[:limit] if limit else _load_labels(d)
    paths = [str(d / "new_joint_vecs" / f"{r['id']}.npy") for r in rows]
    with process_pool(workers) as ex:
        figs = list(ex.map(realism_job, paths, chunksize=64))
    summary = {"clips": summarize(figs)}
    bad = [(r["id"], f.violations()) for r, f in zip(rows, figs, strict=True) if f.violations()]
    seq_rows = []
    for split in ("train", "val", "test"):
        p = d / "babel" / f"{split}_labels.jsonl"
        if p.is_file():
            seq_rows += [json.loads(ln) for ln in p.read_text().splitlines() if ln.strip()]
    seq_rows = seq_rows[:limit] if limit else seq_rows
    if seq_rows:
        jobs = [
            (str(d / "babel" / "motions" / f"{s['id']}.npy"), [g["start_frame"] for g in s["segments"][1:]])
            for s in seq_rows
        ]
        with process_pool(workers) as ex:
            res = list(ex.map(seq_job, jobs, chunksize=4))
        sfigs = [r[0] for r in res]
        summary["sequences"] = summarize(sfigs)
        summary["sequences"]["transitions"] = {
            "boundary_peak_accel_ms2_max": max(r[1] for r in res),
            "in_segment_p99_accel_ms2_median": float(np.median([r[2] for r in res])),
            "boundary_over_inside_p99_ratio_median": float(np.median([r[1] / max(r[2], 1e-6) for r in res])),
            "max_frame_step_m": max(r[3] for r in res),
        }
        bad += [(s["id"], f.violations()) for s, f in zip(seq_rows, sfigs, strict=True) if f.violations()]
    summary["bounds"] = BOUNDS
    summary["violations"] = len(bad)
    summary["check_seconds"] = round(time.time() - t0, 1)
    print(json.dumps(summary, indent=1))
    for cid, why in bad[:20]:
        print(f"OUT OF BOUNDS {cid}: {'; '.join(why)}", file=sys.stderr)
    return 1 if bad else 0


def cmd_verify(d: Path, split: str, workers: int, limit: int | None, seed: int = 0) -> int:
    rows = [r for r in _load_labels(d) if r["split"] == split]
    uncovered = sum(not has_rule(r["labels"]) for r in rows)  # counted, not verified
    rows = [r for r in rows if has_rule(r["labels"])]
    rows = rows[:limit] if limit else rows
    perm = np.random.default_rng(seed).permutation(len(rows))
    jobs = [
        (str(d / "new_joint_vecs" / f"{r['id']}.npy"), r["labels"], rows[p]["labels"])
        for r, p in zip(rows, perm, strict=True)
    ]
    with process_pool(workers) as ex:
        res = list(ex.map(verify_job, jobs, chunksize=32))
    ok = np.mean([r[0] for r in res])
    sh = np.mean([r[1] for r in res])
    fails: dict[str, int] = {}
    for r in res:
        if not r[0]:
            fails[r[2]] = fails.get(r[2], 0) + 1
    print(
        json.dumps(
            {
                "split": split,
                "clips": len(res),
                "real_clips_without_a_rule": uncovered,
                "by_source": {
                    src: float(
                        np.mean([x[0] for x, r in zip(res, rows, strict=True) if r.get("source", "procedural") == src])
                    )
                    for src in sorted({r.get("source", "procedural") for r in rows})
                },
                "pass_rate": float(ok),
                "shuffled_pass_rate": float(sh),
                "failures_by_action": fails,
            },
            indent=1,
        )
    )
    return 0


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(
        prog="python -m motion_core.corpus", description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    sub = ap.add_subparsers(dest="cmd", required=True)
    b = sub.add_parser("build", help="write the corpus")
    b.add_argument("out", type=Path)
    b.add_argument("--train", type=int, default=20000)
    b.add_argument("--val", type=int, default=1000)
    b.add_argument("--test", type=int, default=2000)
    b.add_argument(
        "--with-staged", action="store_true", help="draw from the staged kinds too (the corpus to retrain on)"
    )
    b.add_argument("--chain-train", type=int, default=0, help="clips of 2-3 actions under one sentence")
    b.add_argument("--chain-val", type=int, default=0)
    b.add_argument("--chain-test", type=int, default=0)
    b.add_argument("--seq-train", type=int, default=1000)
    b.add_argument("--seq-val", type=int, default=50)
    b.add_argument("--seq-test", type=int, default=100)
    b.add_argument("--seed", type=int, default=0)
    b.add_argument("--workers", type=int, default=default_workers())
    b.add_argument(
        "--real",
        type=Path,
        default=None,
        metavar="ARCHIVE",
        help="also import the real Bandai Namco BVH clips from this .tar.xz (CC BY-NC 4.0)",
    )
    b.add_argument("--real-cache", type=Path, default=Path(".cache/bandai-namco"), help="where to unpack it")
    b.add_argument("--real-limit", type=int, default=None, help="import only about this many real clips")
    c = sub.add_parser("check", help="realism figures; exit 1 if out of bounds")
    c.add_argument("dir", type=Path)
    c.add_argument("--workers", type=int, default=default_workers())
    c.add_argument("--limit", type=int, default=None)
    v = sub.add_parser("verify", help="verifier pass rate on a split")
    v.add_argument("dir", type=Path)
    v.add_argument("--split", default="test")
    v.add_argument("--workers", type=int, default=default_workers())
    v.add_argument("--limit", type=int, default=None)
    a = ap.parse_args(argv)
    if a.cmd == "build":
        summary = build(
            BuildConfig(
                a.out,
                a.train,
                a.val,
                a.test,
                a.seq_train,
                a.seq_val,
                a.seq_test,
                a.seed,
                a.workers,
                real_archive=a.real,
                real_cache=a.real_cache,
                real_limit=a.real_limit,
                staged=a.with_staged,
                chain_train=a.chain_train,
                chain_val=a.chain_val,
                chain_test=a.chain_test,
            )
        )
        print(json.dumps(summary, indent=1))
        return 0
    if a.cmd == "check":
        if not (a.dir / "labels.jsonl").is_file():
            print(f"{a.dir} is not a built corpus (no labels.jsonl)", file=sys.stderr)
            return 2
        return cmd_check(a.dir, a.workers, a.limit)
    return cmd_verify(a.dir, a.split, a.workers, a.limit)


if __name__ == "__main__":
    raise SystemExit(main())
