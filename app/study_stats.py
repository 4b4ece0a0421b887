"""Statistics of a user study's votes: win rates, Bradley-Terry ranking, votes per criterion.

Input: the vote rows of ``StudyStore.votes`` (each with method_a, method_b and the answer
A / B / tie / both_bad, plus per-criterion answers A / B / tie).

* Win rate of the pair's first method over the second, among decisive votes (A or B better),
  with a Wilson 95% interval; ties and both-bad are counted and shown, not folded in.
* Bradley-Terry strengths p_i with P(i beats j) = p_i / (p_i + p_j), fitted by Hunter's (2004)
  minorise-maximise iteration. As in FastChat's arena, a tie or a both-bad vote counts as half
  a win to each side. ``prior`` adds that many virtual ties to every pair, so a method that
  never won keeps a finite score; with ``prior=0`` and two methods, p1/p2 = w1/w2 exactly.
  Scores are reported on an Elo-like scale, 1000 + 400 log10(p_i / geometric mean of p).
* Bootstrap intervals: votes resampled with replacement, the fit repeated, 2.5/97.5 percentiles.
"""

from __future__ import annotations

import csv
import io
import json
import math
from collections.abc import Sequence
from typing import Any

import numpy as np

Z95 = 1.959963984540054


def wilson(k: float, n: float, z: float = Z95) -> tuple[float, float]:
    """Wilson score interval of a proportion k/n (n=0 gives (0, 1))."""
    if n <= 0:
        return 0.0, 1.0
    p = k / n
    den = 1 + z * z / n
    centre = (p + z * z / (2 * n)) / den
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / den
    return max(0.0, centre - half), min(1.0, centre + half)


def _pair_of(v: dict[str, Any]) -> tuple[str, str]:
    a, b = sorted((v["method_a"], v["method_b"]))
    return a, b


def _result_for_first(v: dict[str, Any], answer: str) -> str:
    """'first', 'second', 'tie' or 'both_bad' for the pair's first (sorted) method."""
    if answer in ("tie", "both_bad"):
        return answer
    winner = v["method_a"] if answer == "A" else v["method_b"]
    return "first" if winner == _pair_of(v)[0] else "second"


def pair_table(votes: Sequence[dict[str, Any]]) -> list[dict[str, Any]]:
    """Per method pair: counts, the first method's win rate among decisive votes, Wilson CI."""
    table: dict[tuple[str, str], dict[str, Any]] = {}
    for v in votes:
        pair = _pair_of(v)
        row = table.setdefault(
            pair, {"method_1": pair[0], "method_2": pair[1], "n": 0, "wins_1": 0, "wins_2": 0, "ties": 0, "both_bad": 0}
        )
        row["n"] += 1
        r = _result_for_first(v, v["answer"])
        row[{"first": "wins_1", "second": "wins_2", "tie": "ties", "both_bad": "both_bad"}[r]] += 1
    out = []
    for pair in sorted(table):
        row = table[pair]
        decisive = row["wins_1"] + row["wins_2"]
        lo, hi = wilson(row["wins_1"], decisive)
        row["win_rate_1"] = row["wins_1"] / decisive if decisive else None
        row["ci95_1"] = [lo, hi] if decisive else None
        out.append(row)
    return out


def _win_matrix(votes: Sequence[dict[str, Any]], index: dict[str, int]) -> np.ndarray:
    """W[i, j] = wins of i over j, ties and both-bad as half a win each."""
    W = np.zeros((len(index), len(index)))
    for v in votes:
        a, b = index[v["method_a"]], index[v["method_b"]]
        if v["answer"] == "A":
            W[a, b] += 1
        elif v["answer"] == "B":
            W[b, a] += 1
        else:
            W[a, b] += 0.5
            W[b, a] += 0.5
    return W


def bradley_terry_strengths(W: np.ndarray, prior: float = 1.0, iters: int = 10_000, tol: float = 1e-12) -> np.ndarray:
    """Strengths p (geometric mean 1) from a win matrix W (n, n) by MM iteration.

    Methods never compared with any other keep p = 1.
    """
    n = W.shape[0]
    W = W + (prior / 2.0) * (1 - np.eye(n))
    N = W + W.T  # comparisons per pair
    compared = N.sum(1) > 0
    wins = W.sum(1)
    p = np.ones(n)
    for _ in range(iters):
        denom = (N / (p[:, None] + p[None, :])).sum(1)
        new = np.where(compared & (denom > 0), wins / np.where(denom > 0, denom, 1.0), 1.0)
        new = np.maximum(new, 1e-300)
        new /= np.exp(np.mean(np.log(new)))
        if np.max(np.abs(np.log(new) - np.log(p))) < tol:
            p = new
            break
        p = new
    return p


def elo_scale(p: np.ndarray) -> np.ndarray:
    return 1000.0 + 400.0 * np.log10(p / np.exp(np.mean(np.log(p))))


def bradley_terry(
    votes: Sequence[dict[str, Any]],
    methods: Sequence[str],
    prior: float = 1.0,
    rounds: int = 1000,
    seed: int = 0,
) -> list[dict[str, Any]]:
    """Ranking with bootstrap 95% intervals: [{method, score, ci95, strength, rank}], best first."""
    methods = list(methods)
    index = {m: i for i, m in enumerate(methods)}
    votes = [v for v in votes if v["method_a"] in index and v["method_b"] in index]
    p = bradley_terry_strengths(_win_matrix(votes, index), prior)
    score = elo_scale(p)
    boot = np.empty((rounds, len(methods)))
    rng = np.random.default_rng(seed)
    for r in range(rounds):
        sample = [votes[i] for i in rng.integers(0, len(votes), len(votes))] if votes else []
        boot[r] = elo_scale(bradley_terry_strengths(_win_matrix(sample, index), prior))
    lo, hi = (np.percentile(boot, q, axis=0) for q in (2.5, 97.5)) if rounds else (score, score)
    order = np.argsort(-score)
    return [
        {
            "rank": r + 1,
            "method": methods[i],
            "score": float(score[i]),
            "ci95": [float(lo[i]), float(hi[i])],
            "strength": float(p[i]),
            "votes": sum(methods[i] in (v["method_a"], v["method_b"]) for v in votes),
        }
        for r, i in enumerate(order)
    ]


def criteria_table(votes: Sequence[dict[str, Any]], criteria: Sequence[str]) -> list[dict[str, Any]]:
    """Per criterion and method pair: wins of each method and ties (votes that answered it)."""
    out = []
    for c in criteria:
        rows: dict[tuple[str, str], dict[str, Any]] = {}
        for v in votes:
            ans = (v.get("criteria") or {}).get(c)
            if ans is None:
                continue
            pair = _pair_of(v)
            row = rows.setdefault(
                pair,
                {"criterion": c, "method_1": pair[0], "method_2": pair[1], "n": 0, "wins_1": 0, "wins_2": 0, "ties": 0},
            )
            row["n"] += 1
            row[{"first": "wins_1", "second": "wins_2", "tie": "ties"}[_result_for_first(v, ans)]] += 1
        out += [rows[k] for k in sorted(rows)]
    return out


def summarise(
    votes: Sequence[dict[str, Any]],
    methods: Sequence[str],
    criteria: Sequence[str],
    rounds: int = 1000,
    seed: int = 0,
) -> dict[str, Any]:
    """Everything the results view shows, JSON-ready."""
    return {
        "votes": len(votes),
        "participants": len({v["participant"] for v in votes}),
        "answers": {a: sum(v["answer"] == a for v in votes) for a in ("A", "B", "tie", "both_bad")},
        "pairs": pair_table(votes),
        "ranking": bradley_terry(votes, methods, rounds=rounds, seed=seed),
        "criteria": criteria_table(votes, criteria),
        "watched_both": sum(bool(v.get("watched_a")) and bool(v.get("watched_b")) for v in votes),
        "median_decision_seconds": float(np.median([v["decision_seconds"] for v in votes])) if votes else None,
    }


CSV_FIELDS = (
    "vote_id",
    "participant",
    "trial",
    "position",
    "prompt",
    "custom_prompt",
    "seconds",
    "seed",
    "method_a",
    "method_b",
    "swapped",
    "answer",
    "winner",
    "criteria",
    "decision_seconds",
    "watched_a",
    "watched_b",
    "gen_seconds_a",
    "gen_seconds_b",
    "sampler_a",
    "sampler_b",
    "trial_created_at",
    "voted_at",
)


def votes_csv(votes: Sequence[dict[str, Any]]) -> str:
    buf = io.StringIO()
    w = csv.DictWriter(buf, fieldnames=CSV_FIELDS, extrasaction="ignore")
    w.writeheader()
    for v in votes:
        w.writerow({**v, "criteria": json.dumps(v.get("criteria") or {}, sort_keys=True)})
    return buf.getvalue()
