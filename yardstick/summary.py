"""Summary of the hand labels (stdlib only): python yardstick/summary.py [labels.jsonl]

Prints the counts and shares of in / partial / out / unusable (of all captions, and of the
usable ones), the share and number of multi captions, the known kinds by frequency and the
unknown actions' names by frequency (clauses, and captions they occur in).
"""

from __future__ import annotations

import json
import sys
from collections import Counter
from pathlib import Path

path = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).resolve().parent / "kitml_labels.jsonl"
rows = [json.loads(l) for l in path.read_text().splitlines() if l.strip()]
n = len(rows)
usable = [r for r in rows if r["status"] != "unusable"]
st = Counter(r["status"] for r in rows)
print(f"captions: {n} ({len(usable)} usable)")
print(f"{'status':10} {'count':>5} {'of all':>7} {'of usable':>9}")
for s in ("in", "partial", "out", "unusable"):
    share_u = f"{st[s] / len(usable):.1%}" if s != "unusable" else ""
    print(f"{s:10} {st[s]:5d} {st[s] / n:7.1%} {share_u:>9}")
multi = sum(r["multi"] for r in usable)
print(f"multi: {multi} of {len(usable)} usable ({multi / len(usable):.1%})")
clauses = [c for r in usable for c in r["clauses"]]
print(f"clauses: {len(clauses)} ({len(clauses) / len(usable):.2f} per usable caption), "
      f"{sum(c['kind'] == 'unknown' for c in clauses)} unknown")
known = Counter(c["kind"] for c in clauses if c["kind"] != "unknown")
print("known kinds by clauses: " + ", ".join(f"{k} {v}" for k, v in known.most_common()))
unk = Counter(c["unknown"] for c in clauses if c["kind"] == "unknown")
unk_caps = Counter(u for r in usable for u in {c["unknown"] for c in r["clauses"] if c["kind"] == "unknown"})
print("unknown actions by frequency (clauses / captions):")
for name, k in sorted(unk.items(), key=lambda kv: (-kv[1], -unk_caps[kv[0]], kv[0])):
    print(f"  {name}: {k} / {unk_caps[name]}")
