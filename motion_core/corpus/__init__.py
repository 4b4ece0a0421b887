"""The built-in motion-language corpus: procedural, labelled, verifiable.

* ``sample_clip`` / ``sample_sequence``: render actions on the HumanML3D skeleton.
* ``build``: write the data set (HumanML3D directory format + BABEL-style sequences).
* ``prompt_guide``: which prompts the corpus covers (the demo's prompt hints and warning).

Its motions are checked by ``motion_core.verify`` (rules and realism), a layer below.

Command line: ``python -m motion_core.corpus build OUT_DIR`` and ``... check DIR``.
"""

from . import kinds  # noqa: F401  (registers the kinds of motion_core/corpus/kinds with the dispatch)
from .actions import CATALOGUE, Spec, distinct_actions
from .compose import Composed, compose, sample_clip, sample_sequence
from .text import captions_for

__all__ = [
    "CATALOGUE",
    "Composed",
    "Spec",
    "captions_for",
    "compose",
    "distinct_actions",
    "sample_clip",
    "sample_sequence",
]
