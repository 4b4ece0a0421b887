"""Would the nearest hand-labelled clause's kind correct the reader? Leave-one-sample-out over
the tuning samples 1-4 (the fifth is held out and not read here).

    PYTHONPATH=. python yardstick/neighbour_kinds.py

For each sample, the labelled clauses of the other three (their words and kinds) are the
memory; each of the reader's clauses is embedded with the frozen text encoder, and where its
nearest k labelled clauses agree on a kind other than the reader's, with cosine similarity at
least tau, the kind is replaced (under one of four policies). Printed: the clause kinds in
order, the planner's segments-and-kinds figure on the multi captions and the warning's shares,
before -> after, pooled over the four folds. The rules were written from these four samples'
mistakes, so a fold favours the rules over the neighbour: a gain here would be worth a held-out
check, a loss is not conclusive either way.
"""

from __future__ import annotations

import collections
from pathlib import Path

import numpy as np

from motion_core.corpus.reader import read_prompt
from motion_core.eval.reader import _segments, load_labels
from motion_core.nn.text import get_text_encoder

SAMPLES = [Path(f"yardstick/kitml_labels{s}.jsonl") for s in ("", "_2", "_3", "_4")]
POLICIES = {
    "any": lambda rule, near: True,
    "rule unknown -> known": lambda rule, near: rule == "unknown",
    "known -> unknown": lambda rule, near: near == "unknown",
    "known -> other known": lambda rule, near: "unknown" not in (rule, near),
}


def _embed(texts: list[str]) -> np.ndarray:
    return get_text_encoder().encode(list(texts)).numpy().astype(np.float32)


def _groups(clauses: list[tuple[str, bool]]) -> list[tuple[str, ...]]:
    out: list[list[str]] = []
    for kind, with_previous in clauses:
        if with_previous and out:
            out[-1].append(kind)
        else:
            out.append([kind])
    return [tuple(sorted(g)) for g in out]


def _pair(t: collections.Counter, what: str, n: str) -> str:
    return f"{t['before ' + what] / t[n]:.3f} -> {t['after ' + what] / t[n]:.3f}"


def main() -> None:
    samples = [[r for r in load_labels(p) if r["status"] != "unusable"] for p in SAMPLES]
    memory = []
    for s in samples:
        clauses = [c for r in s for c in r["clauses"] if c.get("words")]
        memory.append((_embed([c["words"] for c in clauses]), np.array([c["kind"] for c in clauses])))
    readings = []
    for s in samples:
        rs = [[(c.kind, c.with_previous, c.words) for c in read_prompt(r["text"]).clauses] for r in s]
        readings.append((rs, _embed([w for cl in rs for _, _, w in cl])))
    print("tau   k  policy                  replaced  kinds          planner        in warned      partial/out warned")
    for tau in (0.95, 0.85, 0.75, 0.7):
        for k in (1, 3):
            for name, allowed in POLICIES.items():
                t: collections.Counter = collections.Counter()
                for i, s in enumerate(samples):
                    emb = np.concatenate([memory[j][0] for j in range(len(samples)) if j != i])
                    kinds = np.concatenate([memory[j][1] for j in range(len(samples)) if j != i])
                    rs, e = readings[i]
                    at = 0
                    for r, cl in zip(s, rs, strict=True):
                        new = []
                        for kind, with_previous, _ in cl:
                            sims = emb @ e[at]
                            at += 1
                            top = np.argsort(-sims)[:k]
                            near, votes = collections.Counter(kinds[top]).most_common(1)[0]
                            swap = sims[top[0]] >= tau and votes == k and near != kind and allowed(kind, near)
                            t["replaced"] += swap
                            new.append((str(near) if swap else kind, with_previous))
                        want = [c["kind"] for c in r["clauses"]]
                        truth = r["status"] in ("partial", "out")
                        for arm, got in (("before", [(kd, wp) for kd, wp, _ in cl]), ("after", new)):
                            t[arm + " kinds"] += sum(a == b for a, (b, _) in zip(want, got, strict=False))
                            t[arm + " plan"] += bool(r.get("multi")) and _segments(r["clauses"]) == _groups(got)
                            said = not got or any(kd == "unknown" for kd, _ in got)
                            t[arm + " in"] += said and not truth
                            t[arm + " po"] += said and truth
                        t["clauses"] += len(want)
                        t["multi"] += bool(r.get("multi"))
                        t["in"] += r["status"] == "in"
                        t["po"] += truth

                print(
                    f"{tau:<5} {k}  {name:22s}  {t['replaced']:8d}  {_pair(t, 'kinds', 'clauses')}"
                    f"  {_pair(t, 'plan', 'multi')}  {_pair(t, 'in', 'in')}  {_pair(t, 'po', 'po')}"
                )


if __name__ == "__main__":
    main()
