"""Motion Mamba Studio core: text -> 3D human motion.

    import motion_core
    motion_core.methods()                       # the available methods
    m = motion_core.generate([("a person walks forward", 4.0)], method="kmm", seed=0)
    motion_core.export_all(m, "out/")           # .glb, .bvh, features and joints
    r = motion_core.read_prompt("a person walks forward, then sits down")
    motion_core.generate([(s.text, s.seconds) for s in r.plan()])   # the sentence as a timeline
    motion_core.check_prompt("someone does push-ups").messages       # what the models do not know

The package is layered, each layer importing only the ones before it (docs/architecture.md):
``body``, ``nn`` -> ``models``, ``verify`` -> ``inference`` -> ``formats``, ``data`` ->
``corpus``, ``eval`` -> ``train``. It never imports Gradio; the app asks it, never the
other way round.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from .body.features import Normalizer, features_to_joints, joints_to_features
from .body.skeleton import HUMANML3D, KIT, get_skeleton
from .inference.base import InputError, Motion, UnknownMethod

if TYPE_CHECKING:
    from collections.abc import Iterator
    from pathlib import Path

    from .corpus.reader import PromptCheck, Reading


def generate(segments: list[tuple[str, float]], method: str = "motion_mamba", seed: int = 0, **options) -> Motion:
    """A timeline of (text, seconds) -> one continuous Motion; see ``inference.generation.generate``."""
    from .inference.generation import generate as _generate

    return _generate(segments, method=method, seed=seed, **options)


def generate_batch(
    texts: list[str], seconds: float, method: str = "motion_mamba", seed: int = 0, **options
) -> list[Motion]:
    """One single-segment Motion per text, sampled as one batch; see ``inference.generation.generate_batch``."""
    from .inference.generation import generate_batch as _generate_batch

    return _generate_batch(texts, seconds, method=method, seed=seed, **options)


def methods() -> list[dict]:
    """The available methods with display names and descriptions (the method registry)."""
    from .inference.registry import methods as _methods

    return _methods()


def export_all(motion: Motion, out_dir: str | Path, stem: str = "motion", rig: str = "humanml3d") -> dict[str, Path]:
    """Write a Motion's .glb, .bvh, features and joints; ``rig="humanoid"`` names the bones as
    humanoid rigs do (T-pose rest). See ``formats.export.export_all``."""
    from .formats.export import export_all as _export_all

    return _export_all(motion, out_dir, stem, rig)


def export_files(
    motion: Motion, out_dir: str | Path, stem: str = "motion", rig: str = "humanml3d"
) -> Iterator[tuple[str, Path]]:
    """``export_all`` a file at a time, the GLB first, yielding (kind, path) as each is
    written. See ``formats.export.export_files``."""
    from .formats.export import export_files as _export_files

    return _export_files(motion, out_dir, stem, rig)


def read_prompt(text: str) -> Reading:
    """A prompt's clauses in the order they happen (a known kind with side/direction/count, or
    an unknown action by name), its ``unknown_parts`` and a timeline ``plan()`` in the user's
    own words. See ``corpus.reader``."""
    from .corpus.reader import read_prompt as _read_prompt

    return _read_prompt(text)


def check_prompt(text: str) -> PromptCheck:
    """The warning to show before generating: ``warn``, and ``messages`` naming each part of
    the prompt the models do not know with the nearest known action. See ``corpus.reader``."""
    from .corpus.reader import check_prompt as _check_prompt

    return _check_prompt(text)


def rigs() -> tuple[str, ...]:
    """The bone-naming rigs ``export_all`` accepts, the default first."""
    from .formats.export import RIGS

    return tuple(RIGS)


__all__ = [
    "HUMANML3D",
    "KIT",
    "InputError",
    "Motion",
    "Normalizer",
    "UnknownMethod",
    "check_prompt",
    "export_all",
    "export_files",
    "features_to_joints",
    "generate",
    "generate_batch",
    "get_skeleton",
    "joints_to_features",
    "methods",
    "read_prompt",
    "rigs",
]
__version__ = "0.1.0"
