"""Latent samplers of the diffusion methods: one interface, three kinds.

* ``GuidedDDIM`` ("quality"): the trained denoiser, DDIM (eta 0) over ``steps`` steps with
  classifier-free guidance, the conditional and unconditional passes as one batch of 2B.
* ``ConsistencySampler`` ("fast"): a consistency student distilled from that sampler
  (``train lcm``), 1-4 calls of one batch of B, the guidance scale an input of the network.
* ``StudentDDIM`` ("fast"): a guidance-distilled student (``train guidance``), the same DDIM
  steps as the teacher but one pass of B per step, the guidance scale an input.

A method's "fast" student is one of two kinds (``StudentKind``), told apart by its
checkpoint's meta; each kind builds its sampler, checks a request's steps and guidance, and
describes itself for the registry's listing.

Both map (text embeddings, frames, shape, generator) to clean latents z_0 (B, n_z, d) in
the denoiser's scaled units, drawing every random number from the CPU ``generator``, so
a seed gives one result on every device.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Protocol

import torch

from ..models.consistency import GuidedStudent
from ..models.denoisers import LatentDenoiser
from ..nn.consistency import ConsistencyConfig, consistency_sample
from ..nn.diffusion import Diffusion, Generators
from ..nn.guidance_distillation import GuidanceDistillConfig
from .base import InputError

SAMPLERS = ("quality", "fast")


class LatentSampler(Protocol):
    name: str

    def __call__(
        self,
        cond: torch.Tensor,
        empty: torch.Tensor,
        frames: torch.Tensor,
        shape: tuple[int, ...],
        generator: Generators,
        steps: int | None = None,
        guidance: float | None = None,
        device: torch.device | str | None = None,
    ) -> torch.Tensor:
        """cond: (B, 384) sentence embeddings, empty: (1, 384) the empty text's, frames: (B,)
        target lengths; ``generator``: one for the batch, or one per row (row b's noise is
        then what it would be sampled alone); returns z_0 of ``shape`` (B, n_z, d)."""
        ...


@dataclass
class GuidedDDIM:
    denoiser: LatentDenoiser
    diffusion: Diffusion
    name: str = "quality"

    def __call__(
        self,
        cond: torch.Tensor,
        empty: torch.Tensor,
        frames: torch.Tensor,
        shape: tuple[int, ...],
        generator: Generators,
        steps: int | None = None,
        guidance: float | None = None,
        device: torch.device | str | None = None,
    ) -> torch.Tensor:
        b = cond.shape[0]

        def eps_fn(x, t, guided):
            if guided:
                return self.denoiser(x, t, torch.cat([cond, empty.expand(b, -1)]), torch.cat([frames, frames]))
            return self.denoiser(x, t, cond, frames)

        return self.diffusion.sample(eps_fn, shape, generator, steps, guidance, device=device)


@dataclass
class ConsistencySampler:
    student: GuidedStudent
    diffusion: Diffusion  # the teacher's: its schedule and prediction target
    cfg: ConsistencyConfig
    name: str = "fast"

    def __call__(
        self,
        cond: torch.Tensor,
        empty: torch.Tensor,
        frames: torch.Tensor,
        shape: tuple[int, ...],
        generator: Generators,
        steps: int | None = None,
        guidance: float | None = None,
        device: torch.device | str | None = None,
    ) -> torch.Tensor:
        w = torch.full((cond.shape[0],), self.cfg.guidance if guidance is None else guidance, device=cond.device)

        def x0_fn(x, t):
            return self.diffusion.split(self.student(x, t, cond, frames, w), x, t)[1]

        return consistency_sample(x0_fn, self.diffusion, self.cfg, shape, generator, steps, device)


@dataclass
class StudentDDIM:
    """A guidance-distilled student sampled as its teacher is (DDIM, the same steps), one
    network pass per step instead of the guided pair: w is the network's input."""

    student: GuidedStudent
    diffusion: Diffusion  # the teacher's: its schedule and prediction target
    cfg: GuidanceDistillConfig
    name: str = "fast"

    def __call__(
        self,
        cond: torch.Tensor,
        empty: torch.Tensor,
        frames: torch.Tensor,
        shape: tuple[int, ...],
        generator: Generators,
        steps: int | None = None,
        guidance: float | None = None,
        device: torch.device | str | None = None,
    ) -> torch.Tensor:
        w = torch.full((cond.shape[0],), self.cfg.guidance if guidance is None else guidance, device=cond.device)

        def out_fn(x, t, guided):
            return self.student(x, t, cond, frames, w)

        # guidance 1 to the scheduler: the one (already guided) pass per step
        return self.diffusion.sample(out_fn, shape, generator, steps or self.cfg.sample_steps, 1.0, device=device)


class StudentKind(Protocol):
    """What the core needs of a kind of "fast" student (its meta key names the kind)."""

    meta_key: str

    def sampler(self, student: GuidedStudent, diffusion: Diffusion) -> LatentSampler: ...

    def check(self, steps: int | None, guidance: float | None) -> None:
        """InputError where the student was not distilled for these steps or guidance."""
        ...

    def options(self) -> dict:
        """steps, max_steps, guidance [lo, hi], default_guidance, label and steps_label (the
        registry's listing; the demo's picker and steps slider show the labels)."""
        ...


@dataclass
class _Student:
    """A kind of student: its settings (guidance range, default steps and guidance), the most
    steps it accepts, its labels and how it samples. Both kinds are this with other values."""

    cfg: ConsistencyConfig | GuidanceDistillConfig
    meta_key: str
    max_steps: int
    label: str
    steps_label: str
    make: Callable[[GuidedStudent, Diffusion], LatentSampler]

    def sampler(self, student: GuidedStudent, diffusion: Diffusion) -> LatentSampler:
        return self.make(student, diffusion)

    def check(self, steps: int | None, guidance: float | None) -> None:
        c = self.cfg
        if steps is not None and not 1 <= steps <= self.max_steps:
            # a method whose default is "fast" gets here from a bare steps=10 meant for DDIM
            raise InputError(
                f"the fast sampler takes 1 to {self.max_steps} steps, not {steps}; "
                "sampler='quality' takes up to 100 DDIM steps"
            )
        if guidance is not None and not c.guidance_min <= guidance <= c.guidance_max:
            raise InputError(
                f"the fast sampler was distilled for guidance {c.guidance_min:g}-{c.guidance_max:g}, not {guidance:g}; "
                "sampler='quality' takes 1-15"
            )

    def options(self) -> dict:
        c = self.cfg
        return {
            "steps": c.sample_steps,
            "max_steps": self.max_steps,
            "guidance": [c.guidance_min, c.guidance_max],
            "default_guidance": c.guidance,
            "label": self.label,
            "steps_label": self.steps_label,
        }


def consistency_student(cfg: ConsistencyConfig) -> StudentKind:
    return _Student(
        cfg,
        "consistency",
        cfg.solver_steps,
        f"fast: {cfg.sample_steps} consistency step{'s' if cfg.sample_steps != 1 else ''} (distilled student)",
        "consistency steps (distilled student)",
        lambda student, diffusion: ConsistencySampler(student, diffusion, cfg),
    )


def guidance_student(cfg: GuidanceDistillConfig) -> StudentKind:
    return _Student(
        cfg,
        "guidance_distillation",
        cfg.max_steps,
        f"fast: {cfg.sample_steps} DDIM step{'s' if cfg.sample_steps != 1 else ''}, one pass each "
        "(guidance-distilled student)",
        "sampling steps (DDIM, guidance-distilled student)",
        lambda student, diffusion: StudentDDIM(student, diffusion, cfg),
    )


def student_kind(meta: dict) -> StudentKind:
    """The kind of a student checkpoint's meta ("consistency" or "guidance_distillation")."""
    if "consistency" in meta:
        return consistency_student(ConsistencyConfig(**meta["consistency"]))
    if "guidance_distillation" in meta:
        return guidance_student(GuidanceDistillConfig(**meta["guidance_distillation"]))
    raise ValueError("not a student checkpoint: its meta has neither 'consistency' nor 'guidance_distillation'")
