"""Self-agreement: the blind second reading (blind_recheck.txt) against kitml_labels.jsonl.

    python yardstick/compare_recheck.py          # prints the agreement and every disagreement
    python yardstick/compare_recheck.py --show   # the 40 texts only, as shown for the second reading

The 40 captions are random.Random(40).sample(sample rows, 40). Stdlib only.
"""

from __future__ import annotations

import json
import random
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sample = [json.loads(l) for l in (HERE / "sample.jsonl").read_text().splitlines()]
if "--show" in sys.argv:
    for r in random.Random(40).sample(sample, 40):
        print(r["id"], "|", r["text"])
    sys.exit()
labels = {r["id"]: r for r in map(json.loads, (HERE / "kitml_labels.jsonl").read_text().splitlines())}
n = same_status = same_kinds = 0
for line in (HERE / "blind_recheck.txt").read_text().splitlines():
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
