"""How well the prompt reader (``corpus.reader``) reads real captions, against hand labels.

    python -m motion_core.eval reader --labels yardstick/kitml_labels.jsonl [--out results/prompt_reader.json]

Labels: one JSON object a line, ``{"id", "text", "status": in|partial|out|unusable, "multi",
"clauses": [{"kind", "side", "direction", "count", "angle", "unknown", "words", "with_previous"}]}``
(``yardstick/PROTOCOL.md``). Unusable captions are left out of every figure but counted.

Figures:

* *asks for something unknown* (caption level; positive = status partial or out): the reader
  says so when any clause is unknown or no clause names an action. Precision and recall.
* *warning* (``check_prompt``: the reader's unknowns plus the phrasebook's unfamiliar-prompt
  check): the share of ``in`` captions warned and of partial/out captions warned.
* *clause kinds*: each labelled clause against the reader's clause at the same position
  (``in order``), and against an order-keeping alignment (longest common subsequence) of the
  two kind lists; unknown matches unknown. Side, direction and count where the label gives one,
  on the clauses aligned with the right kind; the unknown's name likewise.
* *planner*, on captions labelled multi: the sequential segments (a clause with its
  together-clauses) right in number, and right in number and in order (each segment's kinds,
  as a set, equal to the labelled segment's at the same place: ``segments_and_kinds_right``,
  the figure for "the number of segments and their order right"). The reader's segments are
  the planner's own (``Reading.groups()``, what ``plan()`` returns), not rebuilt from the
  clauses. Beside it, ``segments_in_place_right``: the rows right in number and in place
  (each labelled clause's words inside the reader's segment at its own segment's place),
  whatever kinds either side reads them as: the rows of their own words the user gets, which
  is what the models are given (a wrong kind only changes the warning). On the other
  captions (one action, or actions that only happen together) the share
  the planner keeps as one segment, so a planner that splits too much is seen too.
* *coverage* over every KIT-ML sentence (the non-mirrored keys): the share the reader calls
  fully known, next to the labels' share of ``in``, and the reader's agreement with the labels
  on in versus not.
"""

from __future__ import annotations

import argparse
import datetime as dt
import json
import os
import platform
import re
import subprocess
import time
from pathlib import Path

ANNOTATIONS = Path("../shared/captions/kitml-annotations.json")
POSITIVE = {"partial", "out"}


def load_labels(path: Path) -> list[dict]:
    return [json.loads(line) for line in Path(path).read_text().splitlines() if line.strip()]


def kitml_sentences(path: Path = ANNOTATIONS) -> list[str]:
    """Every annotation text of every non-mirrored key (6,082 for KIT-ML)."""
    data = json.loads(Path(path).read_text())
    return [a["text"].strip() for k in sorted(data) if not k.startswith("M") for a in data[k]["annotations"]]


def _kind(c: dict) -> str:
    return c["kind"]


def _lcs(a: list[str], b: list[str]) -> list[tuple[int, int]]:
    """Index pairs of a longest common subsequence of a and b."""
    n, m = len(a), len(b)
    t = [[0] * (m + 1) for _ in range(n + 1)]
    for i in range(n - 1, -1, -1):
        for j in range(m - 1, -1, -1):
            t[i][j] = t[i + 1][j + 1] + 1 if a[i] == b[j] else max(t[i + 1][j], t[i][j + 1])
    out, i, j = [], 0, 0
    while i < n and j < m:
        if a[i] == b[j]:
            out.append((i, j))
            i += 1
            j += 1
        elif t[i + 1][j] >= t[i][j + 1]:
            i += 1
        else:
            j += 1
    return out


def _segments(clauses: list[dict]) -> list[tuple[str, ...]]:
    segs: list[list[str]] = []
    for c in clauses:
        if c.get("with_previous") and segs:
            segs[-1].append(c["kind"])
        else:
            segs.append([c["kind"]])
    return [tuple(sorted(s)) for s in segs]


def _spans(text: str, clauses: list[dict]) -> list[tuple[int, int] | None]:
    """Where each labelled clause's words lie in the text (they are cut from it): the first
    whole-word occurrence that no earlier clause took, or None. Clauses are in the order the
    actions happen, which is not always the text's ("after X, Y"), so every search starts at
    the text's beginning."""
    taken: list[tuple[int, int]] = []
    out: list[tuple[int, int] | None] = []
    for c in clauses:
        words, found = (c.get("words") or "").strip(), None
        if words:
            for m in re.finditer(rf"(?<!\w){re.escape(words)}(?!\w)", text, re.I):
                if all(m.end() <= a or m.start() >= b for a, b in taken):
                    found = m.span()
                    break
        if found:
            taken.append(found)
        out.append(found)
    return out


def _rows_in_place(text: str, labelled: list[dict], groups: list[list]) -> bool:
    """The planner's rows are the labelled segments: as many, and each labelled clause's words
    lie (by most characters) in the reader's segment at its own segment's place, whatever
    kinds either side reads them as. This is what the user gets as rows of their own words."""
    seg_of, n = [], -1
    for c in labelled:
        n += not (c.get("with_previous") and n >= 0)
        seg_of.append(n)
    if n + 1 != len(groups):
        return False
    for span, want in zip(_spans(text, labelled), seg_of, strict=True):
        if span is None:
            return False
        overlap = [sum(max(0, min(span[1], c.end) - max(span[0], c.start)) for c in g) for g in groups]
        if max(overlap) == 0 or overlap.index(max(overlap)) != want:
            return False
    return True


def _rate(k: int, n: int) -> float | None:
    return round(k / n, 4) if n else None


def _git(*args: str) -> str:
    try:
        return subprocess.run(["git", *args], capture_output=True, text=True, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return ""


def evaluate(labels: list[dict], sentences: list[str] | None = None) -> dict:
    from ..corpus.reader import check_prompt, read_prompt

    t0 = time.time()
    usable = [r for r in labels if r["status"] != "unusable"]
    tp = fp = fn = tn = 0
    warn = {"in": [0, 0], "partial_or_out": [0, 0]}
    pos_kind = [0, 0]
    lcs_kind = [0, 0]
    fields = {f: [0, 0] for f in ("side", "direction", "count", "angle", "unknown")}
    multi = {"captions": 0, "segment_count": 0, "segments": 0, "rows": 0}
    single = {"captions": 0, "one_segment": 0, "right": 0}
    agree = 0
    wrong: dict[str, list] = {"missed_unknown": [], "false_unknown": [], "kinds": [], "plan": [], "plan_split": []}
    for r in usable:
        reading = read_prompt(r["text"])
        got = [c.to_dict() for c in reading.clauses]
        said_unknown = not reading.fully_known
        truth = r["status"] in POSITIVE
        tp += said_unknown and truth
        fp += said_unknown and not truth
        fn += (not said_unknown) and truth
        tn += (not said_unknown) and not truth
        agree += said_unknown == truth
        if truth and not said_unknown:
            wrong["missed_unknown"].append(r["text"])
        if said_unknown and not truth:
            wrong["false_unknown"].append(r["text"])
        w = check_prompt(r["text"]).warn
        key = "partial_or_out" if truth else "in"
        warn[key][0] += w
        warn[key][1] += 1
        lab = r["clauses"]
        lk, gk = [_kind(c) for c in lab], [_kind(c) for c in got]
        pos_kind[0] += sum(a == b for a, b in zip(lk, gk, strict=False))
        pos_kind[1] += len(lk)
        pairs = _lcs(lk, gk)
        lcs_kind[0] += len(pairs)
        lcs_kind[1] += len(lk)
        if lk != gk:
            wrong["kinds"].append({"text": r["text"], "labels": lk, "reader": gk})
        for i, j in pairs:
            for f in fields:
                want = lab[i].get(f)
                if want is None:
                    continue
                fields[f][1] += 1
                fields[f][0] += got[j].get(f) == want
        ls = _segments(lab)
        gs = [tuple(sorted(c.kind for c in g)) for g in reading.groups()]  # the planner's own segments
        if r.get("multi"):
            multi["captions"] += 1
            multi["segment_count"] += len(ls) == len(gs)
            multi["segments"] += ls == gs
            multi["rows"] += _rows_in_place(r["text"], lab, reading.groups())
            if ls != gs:
                wrong["plan"].append({"text": r["text"], "labels": ls, "reader": gs})
        elif lab:
            single["captions"] += 1
            single["one_segment"] += len(gs) == 1
            single["right"] += ls == gs
            if len(gs) != 1:
                wrong["plan_split"].append({"text": r["text"], "labels": ls, "reader": gs})
    out: dict = {
        "captions": len(labels),
        "usable": len(usable),
        "unusable": len(labels) - len(usable),
        "asks_for_unknown": {
            "positive": "status partial or out",
            "said": "a clause unknown, or no clause names an action",
            "precision": _rate(tp, tp + fp),
            "recall": _rate(tp, tp + fn),
            "tp": tp,
            "fp": fp,
            "fn": fn,
            "tn": tn,
        },
        "warning": {
            "what": "check_prompt(text).warn: the reader's unknowns, no action, or the phrasebook's unfamiliar check",
            "in_warned": _rate(*warn["in"]),
            "in": warn["in"][1],
            "partial_or_out_warned": _rate(*warn["partial_or_out"]),
            "partial_or_out": warn["partial_or_out"][1],
            "targets": "partial/out warned >= 0.85, in warned <= 0.10",
        },
        "clause_kinds": {
            "labelled_clauses": pos_kind[1],
            "in_order_accuracy": _rate(*pos_kind),
            "aligned_accuracy": _rate(*lcs_kind),
            "note": "in order: the labelled clause and the reader's clause at the same position have the same kind "
            "(unknown = unknown); aligned: matched along a longest common subsequence of the two kind lists",
        },
        "clause_fields_on_aligned": {
            f: {"right": v[0], "labelled": v[1], "accuracy": _rate(*v)} for f, v in fields.items()
        },
        "planner_on_multi": {
            "captions": multi["captions"],
            "segment_count_right": _rate(multi["segment_count"], multi["captions"]),
            "segments_and_kinds_right": _rate(multi["segments"], multi["captions"]),
            "segments_in_place_right": _rate(multi["rows"], multi["captions"]),
            "note": "segments: each sequential clause with its together-clauses (the planner's Reading.groups()); "
            "segments_and_kinds_right is the number of segments and their order right: each segment's kinds, as a "
            "set, equal to the labelled segment's at the same place (unknown = unknown); segments_in_place_right "
            "asks only that the rows be the labelled segments, in number and place (each labelled clause's words in "
            "the reader's segment at its own segment's place), whatever kinds they are read as",
        },
        "planner_on_single": {
            "captions": single["captions"],
            "kept_one_segment": _rate(single["one_segment"], single["captions"]),
            "one_segment_kinds_right": _rate(single["right"], single["captions"]),
            "note": "captions not labelled multi (one action, or actions only together): the share the planner keeps "
            "as one segment (so over-splitting is seen), and as one segment with the labelled kinds",
        },
        "in_vs_not_agreement": _rate(agree, len(usable)),
        "labels_in_share": _rate(sum(r["status"] == "in" for r in usable), len(usable)),
    }
    if sentences is not None:
        known = sum(read_prompt(t).fully_known for t in sentences)
        out["coverage"] = {
            "sentences": len(sentences),
            "fully_known": known,
            "share": _rate(known, len(sentences)),
            "note": "the reader's share of KIT-ML sentences it calls fully known; compare labels_in_share (the hand "
            "labels' share of in on the sample) and in_vs_not_agreement (how often the reader's call matches them)",
        }
    out["seconds"] = round(time.time() - t0, 1)
    out["mistakes"] = {k: v[:40] for k, v in wrong.items()}
    return out


def main(argv: list[str] | None = None) -> dict:
    ap = argparse.ArgumentParser(prog="python -m motion_core.eval reader", description=__doc__.split("\n\n")[0])
    ap.add_argument("--labels", type=Path, default=Path("yardstick/kitml_labels.jsonl"))
    ap.add_argument("--annotations", type=Path, default=ANNOTATIONS, help="KIT-ML annotations (for coverage)")
    ap.add_argument("--out", type=Path, default=Path("results/prompt_reader.json"))
    ap.add_argument("--note", default="", help="recorded with the figures (e.g. which run this is)")
    args = ap.parse_args(argv)
    sentences = kitml_sentences(args.annotations) if args.annotations.exists() else None
    result = evaluate(load_labels(args.labels), sentences)
    commit = _git("rev-parse", "HEAD")
    dirty = bool(_git("status", "--porcelain", "--", "motion_core"))
    result = {
        "command": "python -m motion_core.eval reader " + " ".join(argv if argv is not None else []),
        "date": dt.datetime.now(dt.UTC).strftime("%Y-%m-%dT%H:%M:%SZ"),
        "machine": f"{platform.node()} {platform.machine()} {os.cpu_count()} cores, Python {platform.python_version()}",
        "commit": commit + (" (motion_core modified)" if dirty else ""),
        "labels": str(args.labels),
        "note": args.note,
        **result,
    }
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(result, indent=1) + "\n")
    summary = {
        k: result[k] for k in ("asks_for_unknown", "warning", "clause_kinds", "planner_on_multi", "planner_on_single")
    }
    summary["coverage"] = result.get("coverage")
    print(json.dumps(summary, indent=1))
    return result
