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

from dataclasses import dataclass
from typing import Protocol

import torch

from ..models.consistency import GuidedStudent
from ..models.denoisers import LatentDenoiser
from ..nn.consistency import ConsistencyConfig, consistency_sample
from ..nn.diffusion import Diffusion
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
        generator: torch.Generator,
        steps: int | None = None,
        guidance: float | None = None,
        device: torch.device | str | None = None,
    ) -> torch.Tensor:
        """cond: (B, 384) sentence embeddings, empty: (1, 384) the empty text's, frames: (B,)
        target lengths; returns z_0 of ``shape`` (B, n_z, d)."""
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
        generator: torch.Generator,
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
        generator: torch.Generator,
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
        generator: torch.Generator,
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


def _check_guidance(lo: float, hi: float, guidance: float | None) -> None:
    if guidance is not None and not lo <= guidance <= hi:
        raise InputError(f"the fast sampler was distilled for guidance {lo:g}-{hi:g}, not {guidance:g}")


@dataclass
class ConsistencyStudent:
    cfg: ConsistencyConfig
    meta_key: str = "consistency"

    def sampler(self, student: GuidedStudent, diffusion: Diffusion) -> LatentSampler:
        return ConsistencySampler(student, diffusion, self.cfg)

    def check(self, steps: int | None, guidance: float | None) -> None:
        if steps is not None and not 1 <= steps <= self.cfg.solver_steps:
            raise InputError(f"the fast sampler takes 1 to {self.cfg.solver_steps} steps, not {steps}")
        _check_guidance(self.cfg.guidance_min, self.cfg.guidance_max, guidance)

    def options(self) -> dict:
        c = self.cfg
        return {
            "steps": c.sample_steps,
            "max_steps": c.solver_steps,
            "guidance": [c.guidance_min, c.guidance_max],
            "default_guidance": c.guidance,
            "label": f"fast: {c.sample_steps} consistency steps (distilled student)",
            "steps_label": "consistency steps (distilled student)",
        }


@dataclass
class GuidanceStudent:
    cfg: GuidanceDistillConfig
    meta_key: str = "guidance_distillation"

    def sampler(self, student: GuidedStudent, diffusion: Diffusion) -> LatentSampler:
        return StudentDDIM(student, diffusion, self.cfg)

    def check(self, steps: int | None, guidance: float | None) -> None:
        if steps is not None and not 1 <= steps <= self.cfg.max_steps:
            raise InputError(f"the fast sampler takes 1 to {self.cfg.max_steps} steps, not {steps}")
        _check_guidance(self.cfg.guidance_min, self.cfg.guidance_max, guidance)

    def options(self) -> dict:
        c = self.cfg
        return {
            "steps": c.sample_steps,
            "max_steps": c.max_steps,
            "guidance": [c.guidance_min, c.guidance_max],
            "default_guidance": c.guidance,
            "label": f"fast: {c.sample_steps} DDIM steps, one pass each (guidance-distilled student)",
            "steps_label": "sampling steps (DDIM, guidance-distilled student)",
        }


def student_kind(meta: dict) -> StudentKind:
    """The kind of a student checkpoint's meta ("consistency" or "guidance_distillation")."""
    if "consistency" in meta:
        return ConsistencyStudent(ConsistencyConfig(**meta["consistency"]))
    if "guidance_distillation" in meta:
        return GuidanceStudent(GuidanceDistillConfig(**meta["guidance_distillation"]))
    raise ValueError("not a student checkpoint: its meta has neither 'consistency' nor 'guidance_distillation'")
