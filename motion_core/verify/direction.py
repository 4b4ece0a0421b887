"""Direction and side: whether a motion went the way, or used the limb, its prompt named.

Evaluation tables and training curves report it beside the verifier's pass rate.
"""

from __future__ import annotations

SIDE_CHECKS = ("direction", "turn_sign", "full_circle", "fast_arm")
SIDE_PREFIXES = ("this_", "other_", "left_", "right_")


def direction_correct(checks: dict[str, bool], labels: dict) -> bool | None:
    """Whether a motion got its prompt's direction or side right: every verifier check that
    is about a direction or a side passed (walk/run/sidestep direction, turn sign, circle
    sense, the labelled arm/leg/knee doing the action and the other one not; for a turn
    around, the signed 180 degrees). Other checks (counts, speed, amplitude) do not count.
    None when no such check applies."""
    kind = labels.get("kind") or labels.get("action")
    side = [
        v
        for k, v in checks.items()
        if k in SIDE_CHECKS or k.startswith(SIDE_PREFIXES) or (k == "turn_amount" and kind == "turn_around")
    ]
    return all(side) if side else None
