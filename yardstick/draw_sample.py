"""Draw the yardstick's random sample of KIT-ML sentences (stdlib only, reproducible).

    python yardstick/draw_sample.py [--n 330] [--seed 20261201] > yardstick/sample.jsonl
    python yardstick/draw_sample.py --n 250 --seed 20261202 --exclude yardstick/sample.jsonl \
        > yardstick/sample2.jsonl
    python yardstick/draw_sample.py --n 600 --seed 20261203 \
        --exclude yardstick/sample.jsonl yardstick/sample2.jsonl > yardstick/sample3.jsonl
    python yardstick/draw_sample.py --n 600 --seed 20261204 --exclude yardstick/sample.jsonl \
        yardstick/sample2.jsonl yardstick/sample3.jsonl > yardstick/sample4.jsonl

Pool: every annotation "text" of every key of ../shared/captions/kitml-annotations.json except
the mirrored "M" keys (their text swaps left and right), in sorted key order then annotation
order; whitespace stripped. Identical texts (compared case-insensitively, whitespace collapsed,
a final period dropped) are kept once, at their first occurrence. Then
random.Random(seed).sample(pool, n), in the order drawn. Each line: {"id": "<key>-<annotation
index>", "text": ...}.

Second sample: --exclude drops from the pool every id in the given JSONL file(s) (the first
sample) before the draw, so the second sample is a plain random draw from the rest of the same
pool, disjoint from the first.

Third sample: --exclude with both earlier samples' files, so it is disjoint from both. It draws
600 in a fixed order; only a prefix of that order is labelled (PROTOCOL.md says how long).

Fourth sample: --exclude with all three earlier samples' files; 600 drawn, a prefix labelled by
the same rule.

The CMU sample (another caption set, worded unlike KIT-ML): --cmu draws from the "Motion
Description" column of ../shared/captions/cmu-trial-index.csv instead, in file order, identical
texts kept once as above; ids "cmu-<subject>_<trial>":

    python yardstick/draw_sample.py --cmu --n 300 --seed 20261209 > yardstick/sample_cmu.jsonl
"""

from __future__ import annotations

import argparse
import csv
import json
import random
from collections.abc import Iterable
from pathlib import Path

DEFAULT = Path(__file__).resolve().parents[2] / "shared" / "captions" / "kitml-annotations.json"
CMU = DEFAULT.with_name("cmu-trial-index.csv")


def norm(text: str) -> str:
    return " ".join(text.lower().split()).rstrip(".").strip()


def first_of_each(rows: Iterable[tuple[str, str]]) -> list[dict]:
    """(id, text) pairs in order, with empty texts dropped and identical texts (``norm``) kept once,
    at their first occurrence."""
    seen: set[str] = set()
    out = []
    for rid, text in rows:
        text = text.strip()
        if not text or norm(text) in seen:
            continue
        seen.add(norm(text))
        out.append({"id": rid, "text": text})
    return out


def pool(path: Path) -> list[dict]:
    data = json.loads(path.read_text())
    return first_of_each(
        (f"{key}-{i}", ann["text"])
        for key in sorted(data)
        if not key.startswith("M")
        for i, ann in enumerate(data[key]["annotations"])
    )


def cmu_pool(path: Path) -> list[dict]:
    with path.open(newline="") as f:
        rows = list(csv.DictReader(f))
    return first_of_each((f"cmu-{r['Subject'].strip()}_{r['Trial #'].strip()}", r["Motion Description"]) for r in rows)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--annotations", type=Path, default=DEFAULT)
    ap.add_argument("--n", type=int, default=330)
    ap.add_argument("--seed", type=int, default=20261201)
    ap.add_argument(
        "--exclude",
        type=Path,
        action="extend",
        nargs="+",
        default=[],
        help="JSONL file(s) of rows whose ids are left out of the pool (several files "
        "after one --exclude, or --exclude repeated)",
    )
    ap.add_argument("--cmu", action="store_true", help="draw from the CMU trial descriptions instead")
    a = ap.parse_args()
    p = cmu_pool(CMU) if a.cmu else pool(a.annotations)
    drop = {json.loads(l)["id"] for f in a.exclude for l in f.read_text().splitlines() if l.strip()}
    assert drop <= {r["id"] for r in p}, "excluded ids must come from the same pool"
    p = [r for r in p if r["id"] not in drop]
    for row in random.Random(a.seed).sample(p, a.n):
        print(json.dumps(row, ensure_ascii=False))


if __name__ == "__main__":
    main()
