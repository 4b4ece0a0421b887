"""Guidance distillation of a trained denoiser (``nn/guidance_distillation.py``).

    python -m motion_core.train guidance --teacher motion_core/weights/baseline.pt --data DIR --vae RUN \\
        --out runs/baseline_guidance [--steps N] [--val-every N] [--ship]

The student starts as the teacher's network (or ``--student-from``'s) plus a guidance-scale
embedding whose last layer is zero (``GuidedStudent``: exactly the teacher's conditional
branch, for a copy of the teacher) and learns the
teacher's guided output for any w in [1, 15] in one pass. It shares the consistency
student's loop (``train/consistency.train_student``): data, resuming, validation, the
end-of-run comparison with the teacher's own sampler, and what ``--ship`` writes
(``weights/<kind>_fast.pt``).
"""

from __future__ import annotations

import argparse
import dataclasses

import torch

from ..inference.registry import DIFFUSION_STEPS
from ..inference.samplers import StudentDDIM
from ..models.consistency import GuidedStudent
from ..nn.diffusion import Diffusion
from ..nn.guidance_distillation import GuidanceDistillConfig
from .consistency import (
    StudentTraining,
    guidance_range,
    init_settings,
    say_ignored,
    teacher_scale,
    train_student,
)
from .device_steps import to_device
from .distributed import ALL_ROWS


def guidance_loss(
    student: GuidedStudent,
    teacher: torch.nn.Module,
    diffusion: Diffusion,
    cfg: GuidanceDistillConfig,
    z0: torch.Tensor,
    cond: torch.Tensor,
    empty: torch.Tensor,
    frames: torch.Tensor,
    generator: torch.Generator,
    rows: slice = ALL_ROWS,
) -> torch.Tensor:
    """One batch's loss. z0: (B, n_z, d) scaled clean latents, cond: (B, 384), empty: (384,),
    frames: (B,): the global batch, of which this process takes ``rows`` after every draw.
    Every draw on the CPU ``generator`` (one stream on every device and process)."""
    b = z0.shape[0]
    t = torch.randint(0, diffusion.cfg.train_steps, (b,), generator=generator)
    w = cfg.guidance_min + (cfg.guidance_max - cfg.guidance_min) * torch.rand(b, generator=generator)
    noise = torch.randn(z0.shape, generator=generator)
    z0, cond, frames, t, w, noise = (x[rows] for x in (z0, cond, frames, t, w, noise))
    b, dev = z0.shape[0], z0.device
    t, w, noise = (to_device(x, dev) for x in (t, w, noise))
    x_t = diffusion.add_noise(z0, noise, t)
    with torch.no_grad():
        o_c, o_u = teacher(
            torch.cat([x_t, x_t]),
            torch.cat([t, t]),
            torch.cat([cond, empty.expand(b, -1)]),
            torch.cat([frames, frames]),
        ).chunk(2)
        target = diffusion.guide(o_c, o_u, w)
    pred = student(x_t, t, cond, frames, w)
    # a temporal latent's padding is zero in both (the denoiser zeroes it): it adds nothing
    if cfg.loss_weight == "uniform":
        return torch.nn.functional.mse_loss(pred, target)
    if cfg.loss_weight == "inverse_w2":
        per_sample = (pred - target).pow(2).flatten(1).mean(1)
        return (per_sample / w.pow(2)).mean()
    raise ValueError(f"unknown loss_weight {cfg.loss_weight!r}: uniform or inverse_w2")


def guidance_training(args: argparse.Namespace) -> StudentTraining:
    sample_steps = getattr(args, "sample_steps", None)
    if getattr(args, "init", None) and getattr(args, "steps", None) == 0:
        # no step taken: a rescoring (and ship) of the init as it was distilled, its scales and
        # loss; only its default sampling steps may change (as ``consistency_training``)
        say_ignored(args, "guidance_range", "loss_weight")
        prior = GuidanceDistillConfig(**init_settings(args.init, "guidance_distillation"))
        cfg = dataclasses.replace(prior, sample_steps=sample_steps or prior.sample_steps)
    else:
        lo, hi = guidance_range(args, (1.0, 15.0))
        cfg = GuidanceDistillConfig(
            sample_steps=sample_steps or DIFFUSION_STEPS,
            loss_weight=getattr(args, "loss_weight", None) or "uniform",
            guidance_min=lo,
            guidance_max=hi,
            # the default scale: the teacher's method's, inside the range
            guidance=min(max(teacher_scale(args, GuidanceDistillConfig.guidance), lo), hi),
        )

    def loss(student, target, teacher, diffusion, z0, cond, empty, frames, g, rows=ALL_ROWS):
        return guidance_loss(student, teacher, diffusion, cfg, z0, cond, empty, frames, g, rows)

    return StudentTraining(
        "guidance_distillation",
        cfg,
        "guidance",
        loss,
        lambda net, diffusion: StudentDDIM(net, diffusion, cfg),
        cfg.sample_steps,
        None,
    )


def train_guidance(args: argparse.Namespace) -> None:
    train_student(args, guidance_training(args))
