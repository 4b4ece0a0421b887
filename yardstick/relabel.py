"""The hand labels relabelled against a later kind list, by a mapping of their unknown names
(PROTOCOL.md, "Relabelling against a future kind list"); the status follows from the clauses as
it does in the labels (``in``: no clause unknown, ``out``: every clause unknown).

    python yardstick/relabel.py [--map yardstick/relabel_grown.txt] [--out-dir DIR]
    PYTHONPATH=. python yardstick/relabel.py --reader

Prints the status shares of each sample and of all nine pooled, before and after, and the
unknown names that remain. ``--out-dir`` writes the relabelled samples there under their own
file names. The decisions files and ``kitml_labels*.jsonl`` stay the labels against the shipped
models' 35 kinds, which the prompt reader is measured on; the relabelled files are what it is
measured on once the grown kinds ship.

``--reader`` also asks how ready the prompt reader is for them: its unknown clauses mapped by
the same rules (its unknown names are the labels' normalised ones), against the relabelled
labels of the first five samples (the sixth is held out for the reader and is not read here):
the share of captions it would still call unknown, among those labelled partial or out and
among those labelled in, and its clause kinds by position.
"""

from __future__ import annotations

import argparse
import copy
import json
from collections import Counter
from pathlib import Path

HERE = Path(__file__).resolve().parent
SAMPLES = ["kitml_labels.jsonl", *(f"kitml_labels_{i}.jsonl" for i in range(2, 10))]


def read_map(path: Path) -> list[tuple[str, str | None, str]]:
    """[(unknown name, words substring or None, kind or "unknown")], in file order."""
    rules = []
    for n, line in enumerate(path.read_text().splitlines(), 1):
        line = line.split("#", 1)[0].strip()
        if not line:
            continue
        if "->" not in line:
            raise SystemExit(f"{path}:{n}: expected 'name [| words] -> kind'")
        left, kind = (s.strip() for s in line.split("->", 1))
        name, _, words = (s.strip() for s in left.partition("|"))
        rules.append((name, words.lower() or None, kind))
    return rules


def relabel_clause(clause: dict, rules: list[tuple[str, str | None, str]]) -> dict:
    """The clause with its unknown name mapped to a kind by the first rule that fits."""
    if clause["kind"] != "unknown":
        return clause
    for name, words, kind in rules:
        if name == clause["unknown"] and (words is None or words in clause["words"].lower()):
            if kind == "unknown":
                return clause
            return {**clause, "kind": kind, "unknown": None}
    return clause


def relabel(row: dict, rules: list[tuple[str, str | None, str]]) -> dict:
    if row["status"] == "unusable":
        return row
    out = copy.deepcopy(row)
    out["clauses"] = [relabel_clause(c, rules) for c in row["clauses"]]
    unknown = [c["kind"] == "unknown" for c in out["clauses"]]
    out["status"] = "out" if all(unknown) else "partial" if any(unknown) else "in"
    return out


def shares(rows: list[dict]) -> dict[str, float]:
    usable = [r for r in rows if r["status"] != "unusable"]
    st = Counter(r["status"] for r in usable)
    return {s: st[s] / len(usable) for s in ("in", "partial", "out")} | {"usable": len(usable)}


def reader_readiness(rules: list[tuple[str, str | None, str]], samples: list[str]) -> dict[str, float]:
    """The prompt reader's unknown clauses mapped by ``rules``, against the relabelled labels."""
    from motion_core.corpus.reader import read_prompt

    flagged = {True: [0, 0], False: [0, 0]}  # labelled partial/out?: [called unknown, captions]
    kinds = [0, 0]
    for name in samples:
        for line in (HERE / name).read_text().splitlines():
            row = json.loads(line)
            if row["status"] == "unusable":
                continue
            want = relabel(row, rules)
            got = [
                relabel_clause({"kind": c.kind, "unknown": c.unknown, "words": c.words}, rules)
                for c in read_prompt(row["text"]).clauses
            ]
            truth = want["status"] != "in"
            flagged[truth][0] += any(c["kind"] == "unknown" for c in got)
            flagged[truth][1] += 1
            kinds[0] += sum(a["kind"] == b["kind"] for a, b in zip(want["clauses"], got, strict=False))
            kinds[1] += len(want["clauses"])
    return {
        "captions_partial_or_out": flagged[True][1],
        "called_unknown_of_partial_or_out": flagged[True][0] / flagged[True][1],
        "captions_in": flagged[False][1],
        "called_unknown_of_in": flagged[False][0] / flagged[False][1],
        "clause_kinds_by_position": kinds[0] / kinds[1],
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--map", default=str(HERE / "relabel_grown.txt"))
    ap.add_argument("--out-dir", default=None)
    ap.add_argument("--reader", action="store_true", help="also the prompt reader's readiness (needs motion_core)")
    a = ap.parse_args()
    rules = read_map(Path(a.map))
    before_all, after_all = [], []
    print(f"{'sample':12} {'usable':>6}  {'in before':>9} {'in after':>8}  {'partial':>7} {'out':>5}  (after)")
    for i, name in enumerate(SAMPLES, 1):
        rows = [json.loads(line) for line in (HERE / name).read_text().splitlines() if line.strip()]
        new = [relabel(r, rules) for r in rows]
        before_all += rows
        after_all += new
        b, f = shares(rows), shares(new)
        print(f"{i:<12} {b['usable']:6d}  {b['in']:9.1%} {f['in']:8.1%}  {f['partial']:7.1%} {f['out']:5.1%}")
        if a.out_dir:
            Path(a.out_dir).mkdir(parents=True, exist_ok=True)
            (Path(a.out_dir) / name).write_text("".join(json.dumps(r) + "\n" for r in new))
    b, f = shares(before_all), shares(after_all)
    print(f"{'all pooled':12} {b['usable']:6d}  {b['in']:9.1%} {f['in']:8.1%}  {f['partial']:7.1%} {f['out']:5.1%}")
    kinds = Counter(c["kind"] for r in after_all for c in r["clauses"])
    clauses = [c for r in after_all if r["status"] != "unusable" for c in r["clauses"]]
    unk = Counter(c["unknown"] for c in clauses if c["kind"] == "unknown")
    mapped = sum(1 for r in before_all for c in r["clauses"] if c["kind"] == "unknown") - sum(unk.values())
    print(f"clauses relabelled: {mapped}; unknown clauses left: {sum(unk.values())} of {len(clauses)}")
    print("kinds now named, by clauses: " + ", ".join(f"{k} {v}" for k, v in kinds.most_common() if k != "unknown"))
    print("unknown actions left, by clauses (those with 3 or more):")
    for name, k in unk.most_common():
        if k >= 3:
            print(f"  {name}: {k}")
    if a.reader:
        r = reader_readiness(rules, SAMPLES[:5])
        print(
            f"the reader, its unknown names mapped the same way, samples 1-5: calls unknown "
            f"{r['called_unknown_of_partial_or_out']:.1%} of {r['captions_partial_or_out']} partial/out captions "
            f"and {r['called_unknown_of_in']:.1%} of {r['captions_in']} in; clause kinds by position "
            f"{r['clause_kinds_by_position']:.1%}"
        )


if __name__ == "__main__":
    main()
