"""Several actions in one motion, in order: the verifier for a one-sentence chain.

A chain's labels are ``{"kind": "chain", "actions": [labels, labels, ...]}``, two or three
single-action labels in the order the sentence names them. A generated motion carries no
boundaries between its actions, so the chain passes when **some** cut points
``0 < c1 < c2 < T`` split it into stretches that each pass their own action's rule, in the
order given. The search is coarse (every ``STEP`` frames) and each stretch keeps at least
``MIN_SECONDS``; a chain's authored clip passes with its true boundaries too (the corpus
tests check both, and that the same clip fails the actions in reverse order).
"""

from __future__ import annotations

import numpy as np

from .rules import WHOLE_MOTION_RULES, Verdict, verify

CHAIN = "chain"
STEP = 4  # frames between candidate cut points (0.2 s at 20 fps)
MIN_SECONDS = 0.8  # the shortest stretch an action is looked for in


def _passes(joints: np.ndarray, labels: dict, a: int, b: int, fps: float, memo: dict) -> bool:
    key = (a, b, id(labels))
    if key not in memo:
        memo[key] = verify(joints[a:b], labels, fps).passed
    return memo[key]


def find_cuts(
    joints: np.ndarray, actions: list[dict], fps: float = 20.0, step: int = STEP, min_seconds: float = MIN_SECONDS
) -> list[int] | None:
    """Cut points [c1, ...] (len(actions) - 1 of them) at which every stretch of ``joints``
    (T, 22, 3) passes its action in order, the earliest such cuts; None when there are none."""
    T = len(joints)
    lo = max(2, round(min_seconds * fps))
    memo: dict = {}

    def search(start: int, i: int) -> list[int] | None:
        if i == len(actions) - 1:
            return [] if T - start >= lo and _passes(joints, actions[i], start, T, fps, memo) else None
        room = lo * (len(actions) - 1 - i)  # the later actions need their stretches too
        for cut in range(start + lo, T - room + 1, step):
            if _passes(joints, actions[i], start, cut, fps, memo):
                rest = search(cut, i + 1)
                if rest is not None:
                    return [cut, *rest]
        return None

    return search(0, 0)


def verify_chain(joints: np.ndarray, labels: dict, fps: float = 20.0) -> Verdict:
    """Check (T, 22, 3) joints against a chain's labels: every action, in order."""
    actions = labels["actions"]
    if not 2 <= len(actions) <= 3:
        raise ValueError(f"a chain names two or three actions, not {len(actions)}")
    cuts = find_cuts(joints, actions, fps)
    measures = {f"cut_{i + 1}_s": c / fps for i, c in enumerate(cuts or [])}
    return Verdict(passed=cuts is not None, checks={"every_action_in_order": cuts is not None}, measures=measures)


WHOLE_MOTION_RULES[CHAIN] = verify_chain
