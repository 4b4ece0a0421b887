"""Self-agreement: a blind second reading against the first labels.

    python yardstick/compare_recheck.py          # prints the agreement and every disagreement
    python yardstick/compare_recheck.py --show   # the 40 texts only, as shown for the second reading
    python yardstick/compare_recheck.py --sample sample3.jsonl --labels kitml_labels_3.jsonl \
        --recheck blind_recheck3.txt [--show]    # the third sample
    python yardstick/compare_recheck.py --sample sample4.jsonl --labels kitml_labels_4.jsonl \
        --recheck blind_recheck4.txt [--show]    # the fourth sample
(paths relative to yardstick/; the defaults are the first sample's files)

The 40 captions are random.Random(40).sample(rows, 40), where rows are the first N lines of the
sample and N is the number of labelled captions (all of them for the first sample, the labelled
prefix of the drawn order for the third and fourth). Stdlib only.
"""

from __future__ import annotations

import argparse
import json
import random
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
ap = argparse.ArgumentParser()
ap.add_argument("--sample", default="sample.jsonl")
ap.add_argument("--labels", default="kitml_labels.jsonl")
ap.add_argument("--recheck", default="blind_recheck.txt")
ap.add_argument("--show", action="store_true")
a = ap.parse_args()
sample = [json.loads(l) for l in (HERE / a.sample).read_text().splitlines()]
n_labelled = len((HERE / a.labels).read_text().splitlines())
rows = sample[:n_labelled]
if a.show:
    for r in random.Random(40).sample(rows, 40):
        print(r["id"], "|", r["text"])
    sys.exit()
labels = {r["id"]: r for r in map(json.loads, (HERE / a.labels).read_text().splitlines())}
assert set(labels) == {r["id"] for r in rows}, "the labels must be the first N lines of the sample"
n = same_status = same_kinds = 0
for line in (HERE / a.recheck).read_text().splitlines():
    if not line.strip() or line.startswith("%"):
        continue
    head, _, kinds = line.partition("|")
    cid, status = head.split()
    first = labels[cid]
    first_kinds = [
        c["kind"] if c["kind"] != "unknown" else "u:" + c["unknown"].replace(" ", "_") for c in first["clauses"]
    ]
    n += 1
    same_status += status == first["status"]
    same_kinds += kinds.split() == first_kinds
    if status != first["status"] or kinds.split() != first_kinds:
        print(f"{cid}: second {status} {kinds.split()} / first {first['status']} {first_kinds}  {first['text']!r}")
print(f"status agreement {same_status}/{n}; same clause kinds in the same order {same_kinds}/{n}")
