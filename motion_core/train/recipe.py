"""A run's recipe, kept in its training state so that a resume cannot change it unseen.

Rerunning a command with the same ``--out`` resumes from OUT/state.pt. A resume that took a
new ``--lr``, ``--batch``, schedule, moving average or target from its command line would
train the rest of the run on another recipe while its checkpoint's meta claimed one recipe
for the whole. ``--steps`` stays free (it is how a stopped run is extended or shipped), and
so do the settings that only say when to save, score or stop.
"""

from __future__ import annotations

import argparse
from pathlib import Path


def recipe(args: argparse.Namespace, fields: tuple[str, ...], **extra) -> dict:
    """The named flags' values (their attribute names), plus ``extra`` settings a trainer
    derives from them (a student's distillation settings), as plain data."""
    return {**{name: getattr(args, name, None) for name in fields}, **extra}


def check_resume(state: dict, now: dict, state_path: Path) -> None:
    """Refuse to resume ``state`` under a recipe that differs from the one it recorded.
    A state written before recipes were recorded has none to compare, and resumes."""
    then = state.get("recipe")
    if then is None:
        return
    changed = [name for name in now if name in then and then[name] != now[name]]
    if changed:
        said = "; ".join(f"{_flag(n)} was {then[n]!r}, now {now[n]!r}" for n in changed)
        raise SystemExit(
            f"{state_path} was trained with another recipe ({said}): rerun with the recorded values to "
            "resume, or start a new --out with --init from its weights to change them"
        )


def _flag(name: str) -> str:
    """A flag's attribute as the flag; an ``extra`` setting's label as it is."""
    return name if " " in name else "--" + name.replace("_", "-")
