"""The built-in motion-language corpus: procedural, labelled, verifiable.

* ``sample_clip`` / ``sample_sequence``: render actions on the HumanML3D skeleton.
* ``build``: write the data set (HumanML3D directory format + BABEL-style sequences).
* ``verify(joints, labels)``: rule-based check that a motion does what its labels say.
* ``realism(joints)``: bone length, foot slide, penetration, speed and joint-limit figures.

Command line: ``python -m motion_core.corpus build OUT_DIR`` and ``... check DIR``.
"""

from .actions import CATALOGUE, Spec, distinct_actions
from .check import BOUNDS, Realism, realism, summarize
from .compose import Composed, compose, sample_clip, sample_sequence
from .text import captions_for
from .verify import Verdict, verify

__all__ = [
    "BOUNDS",
    "CATALOGUE",
    "Composed",
    "Realism",
    "Spec",
    "Verdict",
    "captions_for",
    "compose",
    "distinct_actions",
    "realism",
    "sample_clip",
    "sample_sequence",
    "summarize",
    "verify",
]
