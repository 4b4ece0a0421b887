"""Per-session rate limits for a hosted space (token buckets, in memory, thread-safe).

A key is a Gradio session hash (each browser tab, each ``gradio_client.Client``), or for the
study's wrong admin tokens a client address and "all" (a session is free to make, so those
are counted across sessions). A bucket holds ``burst`` tokens and refills at
``rate_per_minute``; a request that finds it empty is refused with a message saying when to
retry. Buckets idle for ten minutes are dropped. Per-replica only: a multi-replica space
would need a shared store (not built).
"""

from __future__ import annotations

import os
import threading
import time
from dataclasses import dataclass


class RateLimited(RuntimeError):
    pass


@dataclass
class _Bucket:
    tokens: float
    stamp: float


class RateLimiter:
    def __init__(self, rate_per_minute: float, burst: int, clock=time.monotonic) -> None:
        self.rate = rate_per_minute / 60.0
        self.burst = float(burst)
        self.clock = clock
        self._buckets: dict[str, _Bucket] = {}
        self._lock = threading.Lock()

    def _bucket(self, key: str, now: float) -> _Bucket:
        """The key's bucket, refilled up to ``now`` (under the lock)."""
        if len(self._buckets) > 10_000:
            self._buckets = {k: b for k, b in self._buckets.items() if now - b.stamp < 600}
        b = self._buckets.get(key)
        if b is None:
            b = self._buckets[key] = _Bucket(self.burst, now)
        b.tokens = min(self.burst, b.tokens + (now - b.stamp) * self.rate)
        b.stamp = now
        return b

    def wait(self, key: str | None) -> float:
        """Seconds until ``key`` has a token again (0: it has one now); takes nothing, and
        makes no bucket for a key not seen (a client inventing addresses fills no memory)."""
        if self.rate <= 0:
            return 0.0
        with self._lock:
            if (key or "anonymous") not in self._buckets:
                return 0.0
            b = self._bucket(key or "anonymous", self.clock())
            return 0.0 if b.tokens >= 1.0 else (1.0 - b.tokens) / self.rate

    def take(self, key: str | None) -> None:
        """Spend one of ``key``'s tokens, if it has one (never refuses: ``wait`` says when)."""
        if self.rate <= 0:
            return
        with self._lock:
            b = self._bucket(key or "anonymous", self.clock())
            b.tokens = max(0.0, b.tokens - 1.0)

    def check(self, key: str | None, what: str = "requests") -> None:
        """Take one token for ``key`` or raise RateLimited."""
        if self.rate <= 0:
            return
        with self._lock:
            b = self._bucket(key or "anonymous", self.clock())
            if b.tokens < 1.0:
                wait = (1.0 - b.tokens) / self.rate
                raise RateLimited(f"too many {what} from this session: try again in {wait:.0f} s")
            b.tokens -= 1.0


def from_env(name: str, rate_per_minute: float, burst: int) -> RateLimiter:
    """``$MMS_RATE_<NAME>`` = "rate_per_minute/burst" overrides the defaults ("0/0" turns it off)."""
    spec = os.environ.get(f"MMS_RATE_{name.upper()}")
    if spec:
        r, _, b = spec.partition("/")
        rate_per_minute, burst = float(r), int(b or burst)
    return RateLimiter(rate_per_minute, burst)
