"""Format the hand-made decisions (yardstick/decisions.txt) into yardstick/kitml_labels.jsonl.

    python yardstick/format_labels.py                      # first sample
    python yardstick/format_labels.py --sample sample2.jsonl --decisions decisions2.txt \
        --out kitml_labels_2.jsonl                         # second sample
    python yardstick/format_labels.py --sample sample3.jsonl --decisions decisions3.txt \
        --out kitml_labels_3.jsonl --prefix                # third sample: the first N drawn
    python yardstick/format_labels.py --sample sample4.jsonl --decisions decisions4.txt \
        --out kitml_labels_4.jsonl --prefix                # fourth sample: the first N drawn
(paths relative to yardstick/)

--prefix: the sample is labelled only in part; the labelled captions must be exactly the first N
lines of the sample (the drawn order), with none missing before the last one labelled.

This script decides nothing: every status, kind, side, direction, count, angle, unknown name,
word span and with_previous flag is written by hand in decisions.txt; it only parses that
shorthand, checks it (known kind names, every caption of the sample labelled once, word spans
copied exactly from the caption) and writes JSON lines in the sample's order.

decisions.txt, one caption a line (blank lines and lines starting with '%' ignored):
    <id> <status> | <clause> || <clause> ...  ## optional note
    clause: [+]<kind> [side=..] [dir=..] [n=..] [angle=..] [u=<unknown name, '_' for spaces>] @<words>
'+' marks with_previous=true. status unusable takes no clauses. multi is true when there are
at least two clauses and at least one after the first has with_previous false.
"""

from __future__ import annotations

import argparse
import json
import re
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))


def kinds() -> set[str]:
    rows = [l for l in (HERE / "KINDS.md").read_text().splitlines() if l.startswith("| `")]
    ks = {re.match(r"\| `([^`]+)`", l).group(1) for l in rows}
    assert len(ks) == 35, len(ks)
    return ks | {"unknown"}


def parse_clause(s: str, text: str, known: set[str], cid: str) -> dict:
    head, _, words = s.partition("@")
    words = words.strip()
    assert words and words in text, f"{cid}: words {words!r} not in {text!r}"
    toks = head.split()
    wp = toks[0].startswith("+")
    kind = toks[0].lstrip("+")
    assert kind in known, f"{cid}: kind {kind!r}"
    c = {"kind": kind, "side": None, "direction": None, "count": None, "angle": None, "unknown": None}
    for t in toks[1:]:
        k, _, v = t.partition("=")
        key = {"side": "side", "dir": "direction", "n": "count", "angle": "angle", "u": "unknown"}[k]
        c[key] = int(v) if key in ("count", "angle") else v.replace("_", " ")
    assert (kind == "unknown") == (c["unknown"] is not None), f"{cid}: unknown name iff kind unknown"
    c["words"] = words
    c["with_previous"] = wp
    return c


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--sample", default="sample.jsonl")
    ap.add_argument("--decisions", default="decisions.txt")
    ap.add_argument("--out", default="kitml_labels.jsonl")
    ap.add_argument(
        "--prefix",
        action="store_true",
        help="only the first N captions of the sample are labelled; check that they are exactly those",
    )
    a = ap.parse_args()
    known = kinds()
    sample = [json.loads(l) for l in (HERE / a.sample).read_text().splitlines()]
    texts = {r["id"]: r["text"] for r in sample}
    dec: dict[str, dict] = {}
    for line in (HERE / a.decisions).read_text().splitlines():
        if not line.strip() or line.startswith("%"):
            continue
        line, _, note = line.partition("##")
        head, _, rest = line.partition("|")
        cid, status = head.split()
        assert cid in texts and cid not in dec, cid
        assert status in ("in", "partial", "out", "unusable"), (cid, status)
        clauses = [parse_clause(c, texts[cid], known, cid) for c in rest.split("||") if c.strip()]
        assert (status == "unusable") == (not clauses), cid
        ks = [c["kind"] for c in clauses]
        if status == "in":
            assert "unknown" not in ks, cid
        if status == "partial":
            assert "unknown" in ks and set(ks) != {"unknown"}, cid
        multi = len(clauses) >= 2 and any(not c["with_previous"] for c in clauses[1:])
        row = {"id": cid, "text": texts[cid], "status": status, "multi": multi, "clauses": clauses}
        if note.strip():
            row["note"] = note.strip()
        dec[cid] = row
    done = [dec[r["id"]] for r in sample if r["id"] in dec]
    if a.prefix:
        head = [r["id"] for r in sample[: len(dec)]]
        assert set(head) == set(dec), f"not a prefix: first unlabelled {next(i for i in head if i not in dec)}"
    (HERE / a.out).write_text("".join(json.dumps(r, ensure_ascii=False) + "\n" for r in done))
    missing = [r["id"] for r in sample if r["id"] not in dec]
    print(f"{len(done)} labelled, {len(missing)} still to label", file=sys.stderr)


if __name__ == "__main__":
    main()
