"""One kind = one :class:`Kind` entry: its catalogue entry, generator, captions and rule."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ...verify import kind_rules
from ..actions import CATALOGUE, REGISTERED, Spec, Timeline, smoothstep
from ..rig import Channels
from .ik import body_axes

Generator = Callable[[Spec, Timeline, int, int], None]


@dataclass(frozen=True)
class Kind:
    """A corpus action kind, self-contained.

    catalogue: as in actions.CATALOGUE (variants, dur, and optionally count, per_count,
    speed, amp). generate(spec, timeline, t0, t1) writes the action into frames [t0, t1).
    captions: templates with the fields text.captions_for fills ({who}, {arm}, {leg},
    {side}, {cnt}, {num}, {spd}). The verifier rule is kind_rules.RULES[name].
    posture: (start, end): "standing"; "holding" (hands held in front, through the clip's
    lead-in or tail); "plank" or "all_fours" (off its feet: the kind writes its whole clip).
    trained: False while the shipped models have not been trained on it (staged): it is
    then in no training corpus, phrasebook or model card, only in all_kinds().
    source: "procedural" (or, later, real motion capture).
    looks: what a person sees, and what is still missing (docs/new-kinds.md).
    """

    name: str
    family: str
    catalogue: dict
    generate: Generator
    captions: tuple[str, ...]
    posture: tuple[str, str] = ("standing", "standing")
    trained: bool = False
    source: str = "procedural"
    looks: str = ""

    @property
    def owns_clip(self) -> bool:
        """Starts off its feet (plank, all fours): its generator writes the whole clip."""
        return self.posture[0] not in ("standing", "holding")

    @property
    def rule(self):
        return kind_rules.RULES[self.name]


REGISTRY: dict[str, Kind] = {}


def register(kind: Kind) -> Kind:
    if kind.name in CATALOGUE or kind.name in REGISTRY:
        raise ValueError(f"kind {kind.name!r} is already defined")
    if kind.name not in kind_rules.RULES:
        raise ValueError(f"kind {kind.name!r} has no verifier rule in motion_core/verify/kind_rules.py")
    if kind.trained:
        raise ValueError("a registered kind enters training by moving into CATALOGUE with the retrained models")
    REGISTRY[kind.name] = kind
    REGISTERED[kind.name] = kind
    return kind


# ----------------------------------------------------------------------------------------
# Helpers the generators share
# ----------------------------------------------------------------------------------------


def ease(n: int, a: float, b: float) -> np.ndarray:
    """(n,) 0 before fraction a, eased to 1 at fraction b."""
    u = (np.arange(n) + 0.5) / n
    return smoothstep((u - a) / max(b - a, 1e-6))


def body_point(ch: Channels, sl: slice, origin: np.ndarray, lateral, up, forward) -> np.ndarray:
    """World points (n, 3) at body-frame offsets (left, up, forward) from origin (n, 3) under the path heading."""
    fwd, left = body_axes(ch)
    up_v = np.array([0.0, 1.0, 0.0])
    lat, u, f = (np.broadcast_to(np.asarray(x, dtype=float), (sl.stop - sl.start,)) for x in (lateral, up, forward))
    return origin + left[sl] * lat[:, None] + up_v * u[:, None] + fwd[sl] * f[:, None]


def default_count(spec: Spec, tl: Timeline, n: int, per: float, lo: int, hi: int) -> int:
    """The labelled count, or as many repetitions of ``per`` seconds as fit the n frames."""
    return spec.count or int(np.clip(round(n / tl.fps / per), lo, hi))
