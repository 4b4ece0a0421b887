"""The fully convolutional motion encoder / decoder and reconstruction loss shared by KMM's
tokeniser (``rvq.RVQVAE``) and the temporal-latent VAE (``conv_vae.ConvMotionVAE``).

Encoder: normalised features (B, 263, T) -> Conv1D -> ``levels`` stride-2 Conv1D, each
followed by dilated residual blocks -> Conv1D to ``out_dim`` channels: (B, out_dim, T / 2^levels).
Decoder: the mirror, nearest upsampling + Conv1D per level: (B, in_dim, n) -> (B, 263, 2^levels n).
Both are ``nn.Sequential`` so that one state dict's names (``encoder.3.conv1.weight``) fit both
models: a temporal VAE starts from the shipped tokeniser's convolutions.
"""

from __future__ import annotations

import torch
import torch.nn.functional as F
from torch import nn

from ..body.features import HML_LAYOUT
from ..body.skeleton import HUMANML3D
from ..nn.dilated_conv import DilatedConv1d


class ResBlock(nn.Module):
    """x + Conv1D(ReLU(Conv1D_dilated(ReLU(x)))); x: (B, C, T)."""

    def __init__(self, width: int, dilation: int) -> None:
        super().__init__()
        self.conv1 = DilatedConv1d(width, width, 3, padding=dilation, dilation=dilation)
        self.conv2 = nn.Conv1d(width, width, 1)

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        return x + self.conv2(F.relu(self.conv1(F.relu(x))))


def _res_stack(width: int, n: int) -> list[nn.Module]:
    return [ResBlock(width, 3**i) for i in range(n)]


def conv_encoder(feature_dim: int, width: int, out_dim: int, levels: int, res_blocks: int) -> nn.Sequential:
    enc: list[nn.Module] = [nn.Conv1d(feature_dim, width, 3, padding=1), nn.ReLU()]
    for _ in range(levels):
        enc += [nn.Conv1d(width, width, 4, stride=2, padding=1), *_res_stack(width, res_blocks)]
    enc += [nn.Conv1d(width, out_dim, 3, padding=1)]
    return nn.Sequential(*enc)


def conv_decoder(in_dim: int, width: int, feature_dim: int, levels: int, res_blocks: int) -> nn.Sequential:
    dec: list[nn.Module] = [nn.Conv1d(in_dim, width, 3, padding=1), nn.ReLU()]
    for _ in range(levels):
        dec += [
            *_res_stack(width, res_blocks),
            nn.Upsample(scale_factor=2, mode="nearest"),
            nn.Conv1d(width, width, 3, padding=1),
        ]
    dec += [nn.Conv1d(width, width, 3, padding=1), nn.ReLU(), nn.Conv1d(width, feature_dim, 3, padding=1)]
    return nn.Sequential(*dec)


# The joints whose small, fast movements the tokeniser and the VAE lost at the same position
# weight as the rest: a head turned to look around (its offset from the neck is a few cm), a
# strum, a sip, a golf swing's hands; and the feet that find a stair or a stumble's catch step.
UPPER_DETAIL_JOINTS = ("neck", "head", "left_elbow", "right_elbow", "left_wrist", "right_wrist")
FOOT_JOINTS = ("left_ankle", "right_ankle", "left_foot", "right_foot")


def feature_weights(
    feature_dim: int,
    root_weight: float,
    position_weight: float,
    device=None,
    upper_detail_weight: float = 1.0,
    foot_weight: float = 1.0,
) -> torch.Tensor:
    """Per-feature weights (F,) of the reconstruction and velocity losses, mean 1.
    ``upper_detail_weight`` and ``foot_weight`` multiply the position weight of
    ``UPPER_DETAIL_JOINTS`` and ``FOOT_JOINTS`` (1: all joints alike, as before)."""
    # the root's rotation and velocity are integrated over the clip, so a small error in
    # them becomes metres of drift; with all 263 features weighted alike the tokeniser
    # reproduced turns badly (global MPJPE ~1.2 m at 1,000 steps while root-relative
    # was 67 mm). Weighting the 4 root features up is our departure from MoMask's loss.
    w = torch.ones(feature_dim, device=device)
    w[:4] = root_weight
    # Joints are decoded from the root and the root-relative positions alone; the 6D
    # rotations and local velocities only help training. With every feature weighted alike
    # the tokeniser reproduced the arms' positions poorly: reconstructed reaches and
    # punches extended 0.1 m where the clip's hand went 0.5 m forward.
    w[HML_LAYOUT.ric] = position_weight
    for names, factor in ((UPPER_DETAIL_JOINTS, upper_detail_weight), (FOOT_JOINTS, foot_weight)):
        for name in names:
            j = HUMANML3D.index(name) - 1  # ric holds joints 1.. (the root is the first 4 features)
            start = HML_LAYOUT.ric.start + 3 * j
            w[start : start + 3] = position_weight * factor
    return w / w.mean()


def reconstruction_losses(
    rec: torch.Tensor, x: torch.Tensor, mask: torch.Tensor | None, w: torch.Tensor
) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    """MoMask's SmoothL1 on features and on their frame-to-frame differences, each weighted
    by ``w`` (F,), plus our trajectory term. rec, x: (B, T, F); mask (B, T) True on real
    frames. Returns (rec_loss, vel_loss, traj_loss)."""
    m = torch.ones(x.shape[:2], dtype=torch.bool, device=x.device) if mask is None else mask
    rec_loss = (F.smooth_l1_loss(rec[m], x[m], reduction="none") * w).mean()
    vm = m[:, 1:] & m[:, :-1]
    dv = F.smooth_l1_loss((rec[:, 1:] - rec[:, :-1])[vm], (x[:, 1:] - x[:, :-1])[vm], reduction="none")
    vel_loss = (dv * w).mean()
    # Weighting the root up did not fix it alone: a run "to the left" starts with a short burst of
    # root rotation that the tokeniser smoothed away (0.04 of 0.68 rad reconstructed),
    # and the rest of the clip then runs metres off course. The running sums of the
    # root's rotation and planar velocity (proportional to heading and path) are
    # matched as well, in units of 8 frames of one standard deviation.
    keep = m[..., None].float()
    traj_r = torch.cumsum(rec[..., :3] * keep, dim=1) / 8
    traj_x = torch.cumsum(x[..., :3] * keep, dim=1) / 8
    traj_loss = F.smooth_l1_loss(traj_r[m], traj_x[m])
    return rec_loss, vel_loss, traj_loss
