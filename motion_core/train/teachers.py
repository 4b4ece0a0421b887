"""A trained denoiser as a teacher: frozen, in eval mode, read from any of its checkpoints.

Both kinds of distillation read it here: the few-step students (``consistency``,
``guidance_distillation``) and a denoiser trained on another network's predictions
(``denoiser --teacher``, e.g. a smaller Motion Mamba taught by the shipped one).
"""

from __future__ import annotations

from pathlib import Path

import torch

from ..inference import checkpoints

# the meta keys that mark a checkpoint as a distilled student, one per kind of student
STUDENT_KEYS = ("consistency", "guidance_distillation")


def load_teacher(path: str | Path) -> tuple[torch.nn.Module, dict]:
    """A denoiser checkpoint's network (frozen, eval mode) and meta."""
    ck = checkpoints.read_float32(path)
    meta = ck["meta"]
    for student in STUDENT_KEYS:
        if student in meta:
            raise SystemExit(f"{path} is a {student.replace('_', ' ')} student, not a denoiser to distil")
    net = checkpoints.load_denoiser(ck, meta["kind"]).eval()
    for p in net.parameters():
        p.requires_grad_(False)
    return net, meta
