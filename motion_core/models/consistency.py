"""A consistency student: a latent denoiser of its teacher's architecture that also reads the
guidance scale w (MotionLCM folds classifier-free guidance into the student, so one call
replaces the guided pair of the teacher).

w enters as a sinusoidal embedding of 100 w through a two-layer MLP added to the time
token (MotionLCM: an embedding projected into the U-Net's time conditioning). The MLP's
last layer starts at zero, so an untrained student is exactly its teacher's conditional
branch.
"""

from __future__ import annotations

import torch
from torch import nn

from .denoisers import LatentDenoiser, sinusoid_freqs, timestep_embedding


class GuidedStudent(nn.Module):
    """net(z, t, text, frames, w): (B, n_z, z_width) -> (B, n_z, z_width), the network's
    output in its teacher's prediction target; w: (B,) guidance scales."""

    def __init__(self, net: LatentDenoiser) -> None:
        super().__init__()
        self.net = net
        d = net.pos.shape[-1]
        self.register_buffer("w_freqs", sinusoid_freqs(d), persistent=False)
        self.w_embed = nn.Sequential(nn.Linear(d, d), nn.SiLU(), nn.Linear(d, d))
        nn.init.zeros_(self.w_embed[2].weight)
        nn.init.zeros_(self.w_embed[2].bias)

    def forward(
        self, z: torch.Tensor, t: torch.Tensor, text: torch.Tensor, frames: torch.Tensor, w: torch.Tensor
    ) -> torch.Tensor:
        shift = self.w_embed(timestep_embedding(100.0 * w, self.w_freqs))
        return self.net(z, t, text, frames, time_shift=shift)
