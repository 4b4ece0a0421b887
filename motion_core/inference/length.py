"""The duration a segment gets when its seconds are left blank: the shipped length estimator
(``models.length``), loaded once per process."""

from __future__ import annotations

import threading

from ..models.length import LengthEstimator
from ..nn.text import get_text_encoder
from . import checkpoints

_lock = threading.Lock()
_loaded: LengthEstimator | None = None


def length_estimator() -> LengthEstimator:
    global _loaded
    with _lock:
        if _loaded is None:
            _loaded = checkpoints.load_length(checkpoints.WEIGHTS / "length.pt")
        return _loaded


def estimate_seconds(texts: list[str]) -> list[float]:
    """Seconds for each text: 1-10 s in 0.1 s steps."""
    return length_estimator().seconds(get_text_encoder().encode(list(texts))).tolist()
