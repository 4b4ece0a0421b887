"""Learning-rate schedules shared by the training loops.

A run is linear warm-up then either a cosine from the base rate down to a tenth of it
(``"cosine"``, every shipped checkpoint's schedule) or the base rate held (``"constant"``).
The constant shape is for training split into stages across days: a stage that goes
on from committed weights (``--init``) with a fresh optimiser and a short warm-up keeps the
rate where the last stage left it, instead of warming up again and decaying within each
stage; the last stage then decays with ``"cosine"`` (warm-up, stable, decay).
"""

from __future__ import annotations

import math

DECAYS = ("cosine", "constant")


def learning_rate(base: float, step: int, total: int, warmup: int = 500, decay: str = "cosine") -> float:
    """The rate for 0-based ``step`` of a ``total``-step run."""
    if decay not in DECAYS:
        raise ValueError(f"unknown decay {decay!r}; choose from {DECAYS}")
    ramp = min(1.0, (step + 1) / warmup) if warmup > 0 else 1.0
    if decay == "constant":
        return base * ramp
    return base * ramp * (0.1 + 0.9 * 0.5 * (1 + math.cos(math.pi * step / total)))
