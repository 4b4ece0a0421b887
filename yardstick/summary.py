"""Summary of the hand labels (stdlib only): python yardstick/summary.py [labels.jsonl ...]

With no argument it summarises the first sample (kitml_labels.jsonl), the second sample
(kitml_labels_2.jsonl), the first two pooled (the figures quoted before the third sample), the
third sample (kitml_labels_3.jsonl, the labelled first 507 of its 600 drawn), all three
pooled, the fourth sample (kitml_labels_4.jsonl, the labelled first 491 of its 600 drawn), all
four pooled, the fifth sample (kitml_labels_5.jsonl, the labelled first 478 of its 600 drawn),
all five pooled, the sixth sample (kitml_labels_6.jsonl, the labelled first 428 of its 600 drawn),
all six pooled, the seventh and the eighth samples (kitml_labels_7.jsonl, kitml_labels_8.jsonl,
each the first 520 of its 600 drawn, an extent fixed before labelling), all seven pooled, all
eight pooled, the ninth sample (kitml_labels_9.jsonl, the whole draw of 259) and all nine pooled;
with one or more files, each file and (for two or more) all of them pooled.
For each set it prints the counts and shares of in / partial / out / unusable (of all
captions, and of the usable ones), the share and number of multi captions, the known kinds by
frequency and the unknown actions' names by frequency (clauses, and captions they occur in).
"""

from __future__ import annotations

import json
import sys
from collections import Counter
from pathlib import Path

HERE = Path(__file__).resolve().parent


def load(path: Path) -> list[dict]:
    return [json.loads(l) for l in path.read_text().splitlines() if l.strip()]


def summarise(title: str, rows: list[dict]) -> None:
    print(f"== {title}")
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
    print(
        f"clauses: {len(clauses)} ({len(clauses) / len(usable):.2f} per usable caption), "
        f"{sum(c['kind'] == 'unknown' for c in clauses)} unknown"
    )
    known = Counter(c["kind"] for c in clauses if c["kind"] != "unknown")
    print("known kinds by clauses: " + ", ".join(f"{k} {v}" for k, v in known.most_common()))
    unk = Counter(c["unknown"] for c in clauses if c["kind"] == "unknown")
    unk_caps = Counter(u for r in usable for u in {c["unknown"] for c in r["clauses"] if c["kind"] == "unknown"})
    print("unknown actions by frequency (clauses / captions):")
    for name, k in sorted(unk.items(), key=lambda kv: (-kv[1], -unk_caps[kv[0]], kv[0])):
        print(f"  {name}: {k} / {unk_caps[name]}")


def main() -> None:
    if len(sys.argv) > 1:
        sets = [(a, load(Path(a))) for a in sys.argv[1:]]
        for i, (title, rows) in enumerate(sets):
            if i:
                print()
            summarise(title, rows)
        if len(sets) > 1:
            print()
            summarise("both samples pooled" if len(sets) == 2 else "all pooled", pool(sets))
        return
    s1 = ("sample 1 (kitml_labels.jsonl)", load(HERE / "kitml_labels.jsonl"))
    s2 = ("sample 2 (kitml_labels_2.jsonl)", load(HERE / "kitml_labels_2.jsonl"))
    s3 = ("sample 3 (kitml_labels_3.jsonl)", load(HERE / "kitml_labels_3.jsonl"))
    s4 = ("sample 4 (kitml_labels_4.jsonl)", load(HERE / "kitml_labels_4.jsonl"))
    s5 = ("sample 5 (kitml_labels_5.jsonl)", load(HERE / "kitml_labels_5.jsonl"))
    s6 = ("sample 6 (kitml_labels_6.jsonl)", load(HERE / "kitml_labels_6.jsonl"))
    s7 = ("sample 7 (kitml_labels_7.jsonl)", load(HERE / "kitml_labels_7.jsonl"))
    s8 = ("sample 8 (kitml_labels_8.jsonl)", load(HERE / "kitml_labels_8.jsonl"))
    s9 = ("sample 9 (kitml_labels_9.jsonl)", load(HERE / "kitml_labels_9.jsonl"))
    check_prefix(s3[1], HERE / "sample3.jsonl")
    check_prefix(s4[1], HERE / "sample4.jsonl", "sample 4")
    check_prefix(s5[1], HERE / "sample5.jsonl", "sample 5")
    check_prefix(s6[1], HERE / "sample6.jsonl", "sample 6")
    check_prefix(s7[1], HERE / "sample7.jsonl", "sample 7", fixed=520)
    check_prefix(s8[1], HERE / "sample8.jsonl", "sample 8", fixed=520)
    check_prefix(s9[1], HERE / "sample9.jsonl", "sample 9", fixed=259)
    summarise(*s1)
    print()
    summarise(*s2)
    print()
    summarise("samples 1 and 2 pooled", pool([s1, s2]))
    print()
    summarise(*s3)
    print()
    summarise("all three samples pooled", pool([s1, s2, s3]))
    print()
    summarise(*s4)
    print()
    summarise("all four samples pooled", pool([s1, s2, s3, s4]))
    print()
    summarise(*s5)
    print()
    summarise("all five samples pooled", pool([s1, s2, s3, s4, s5]))
    print()
    summarise(*s6)
    print()
    summarise("all six samples pooled", pool([s1, s2, s3, s4, s5, s6]))
    print()
    summarise(*s7)
    print()
    summarise("all seven samples pooled", pool([s1, s2, s3, s4, s5, s6, s7]))
    print()
    summarise(*s8)
    print()
    summarise("all eight samples pooled", pool([s1, s2, s3, s4, s5, s6, s7, s8]))
    print()
    summarise(*s9)
    print()
    summarise("all nine samples pooled", pool([s1, s2, s3, s4, s5, s6, s7, s8, s9]))


def pool(sets: list[tuple[str, list[dict]]]) -> list[dict]:
    pooled = [r for _, rows in sets for r in rows]
    ids = [r["id"] for r in pooled]
    assert len(ids) == len(set(ids)), "the samples overlap"
    return pooled


def check_prefix(rows: list[dict], sample: Path, name: str = "sample 3", fixed: int | None = None) -> None:
    """A prefix sample's labels are the first N of its draw: for the third to the sixth, N the first
    point with 300 captions and 100 multi; for a sample whose extent was fixed before labelling
    (the seventh, the eighth and the ninth), N that extent."""
    drawn = [json.loads(l)["id"] for l in sample.read_text().splitlines()]
    assert [r["id"] for r in rows] == drawn[: len(rows)], f"{name}'s labels are not the start of its draw"
    if fixed is not None:
        assert len(rows) == fixed, f"{name} holds {len(rows)} labels, not the {fixed} fixed before labelling"
        return
    multi = 0
    for i, r in enumerate(rows, 1):
        multi += r["multi"]
        if i >= 300 and multi >= 100:
            break
    assert i == len(rows) and multi >= 100, f"{name} does not stop at the first point with 300 and 100 multi"


if __name__ == "__main__":
    main()
