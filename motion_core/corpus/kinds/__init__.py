"""Registered action kinds: one self-contained entry per kind, grouped by family.

Adding a kind is one :class:`~.base.Kind` entry in a family module (objects, floor,
gestures, exercise) plus its verifier rule in ``motion_core/verify/kind_rules.py``; the
corpus's dispatch (``actions.apply``, ``duration_of``, ``captions_for``, ``verify``) finds it
through the registry. The 29 built-in kinds of ``actions.CATALOGUE`` are not (yet) here.

Kinds registered with ``trained=False`` are staged: the shipped models were not trained on
them, so they stay out of ``CATALOGUE``, ``sample_spec(rng)``, ``distinct_actions()``, the
corpus build, the phrasebook and what the app says the models know. ``all_kinds()`` lists
them with the built-in ones, for the verifier checks and the contact sheet.
"""

from __future__ import annotations

from ..actions import CATALOGUE
from . import exercise, floor, gestures, handwork, moves, music, objects, reactions, sports  # noqa: F401  (each registers its kinds)
from . import stairs as _stairs  # noqa: F401  (the stairs kinds: the ground changes height under the feet)
from .base import REGISTRY, Kind, register


def all_kinds(staged: bool = True) -> list[str]:
    """Every kind the corpus can render: the built-in ones, then the registered ones
    (the staged ones too unless staged=False)."""
    return list(CATALOGUE) + [k for k, v in REGISTRY.items() if staged or v.trained]


def staged_kinds() -> list[str]:
    """Registered kinds the models are not trained on yet."""
    return [k for k, v in REGISTRY.items() if not v.trained]


__all__ = ["REGISTRY", "Kind", "all_kinds", "register", "staged_kinds"]
