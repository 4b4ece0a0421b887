"""Per-clip jobs of the corpus commands, in an importable module: the process pool spawns
its workers, which must find the job by module name (a job defined in ``__main__`` is not
found when the command runs as ``python -m motion_core.corpus``)."""

from __future__ import annotations

import numpy as np

from ..body.features import features_to_joints
from ..verify.realism import realism
from ..verify.rules import verify


def realism_job(path: str):
    return realism(features_to_joints(np.load(path)))


def seq_job(args: tuple[str, list[int]]) -> tuple:
    path, bounds = args
    j = features_to_joints(np.load(path))
    r = realism(j)
    v = np.diff(j, axis=0) * 20.0  # (T-1, 22, 3) m/s
    acc = np.linalg.norm(np.diff(v, axis=0), axis=-1).max(-1) * 20.0  # (T-2,) peak joint acceleration
    step = np.linalg.norm(np.diff(j, axis=0), axis=-1).max(-1)  # per-frame displacement
    near = np.zeros(len(acc), bool)
    for b in bounds:
        near[max(0, b - 4) : b + 3] = True
    inside = acc[~near] if (~near).any() else acc
    return r, float(acc[near].max() if near.any() else 0.0), float(np.percentile(inside, 99)), float(step.max())


def verify_job(args: tuple[str, dict, dict]) -> tuple[bool, bool, str, list[str]]:
    path, labels, shuffled = args
    j = features_to_joints(np.load(path))
    v = verify(j, labels)
    return v.passed, verify(j, shuffled).passed, labels["kind"], [k for k, ok in v.checks.items() if not ok]
