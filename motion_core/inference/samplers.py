"""Latent samplers of the diffusion methods: one interface, two kinds.

* ``GuidedDDIM`` ("quality"): the trained denoiser, DDIM (eta 0) over ``steps`` steps with
  classifier-free guidance, the conditional and unconditional passes as one batch of 2B.
* ``ConsistencySampler`` ("fast"): a consistency student distilled from that sampler
  (``train lcm``), 1-4 calls of one batch of B, the guidance scale an input of the network.

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
