"""Motion Mamba Studio core: skeleton, features, data sets, text encoder, models, exports.

This package never imports Gradio; the app asks it, never the other way round.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from .features import Normalizer, features_to_joints, joints_to_features
from .skeleton import HUMANML3D, KIT, get_skeleton

if TYPE_CHECKING:
    from .generation import Motion


def generate(segments: list[tuple[str, float]], method: str = "motion_mamba", seed: int = 0, **options) -> Motion:
    """A timeline of (text, seconds) -> one continuous Motion; see ``motion_core.generate``."""
    from .generation import generate as _generate

    return _generate(segments, method=method, seed=seed, **options)


def generate_batch(
    texts: list[str], seconds: float, method: str = "motion_mamba", seed: int = 0, **options
) -> list[Motion]:
    """One single-segment Motion per text, sampled as one batch; see ``generation.generate_batch``."""
    from .generation import generate_batch as _generate_batch

    return _generate_batch(texts, seconds, method=method, seed=seed, **options)


def methods() -> list[dict]:
    """The available methods with display names and descriptions (the method registry)."""
    from .registry import methods as _methods

    return _methods()


__all__ = [
    "HUMANML3D",
    "KIT",
    "Normalizer",
    "features_to_joints",
    "generate",
    "generate_batch",
    "get_skeleton",
    "joints_to_features",
    "methods",
]
__version__ = "0.1.0"
