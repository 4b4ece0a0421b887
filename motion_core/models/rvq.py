"""Residual VQ-VAE: a motion <-> a sequence of discrete tokens, one per 4 frames (KMM's tokeniser).

Encoder: normalised features (B, T, 263) -> Conv1D -> two stride-2 Conv1D levels with
dilated residual blocks -> (B, T/4, code_dim). Quantiser: ``quantizers`` residual
codebooks of ``codebook_size`` x ``code_dim`` (KMM / MoMask: 6 x 512 x 512); layer q
quantises what layers 0..q-1 left over, the token's vector is the sum. Decoder: the mirror
(nearest upsampling + Conv1D) -> features (B, T, 263). Fully convolutional, so a 60 s
timeline decodes in one pass.

Codebooks are updated by exponential moving averages of their assigned vectors (decay
0.99), not by gradients; a code that has gone unused (EMA count below ``dead_threshold``)
is reset to a random encoder output of the current batch. Quantiser dropout (0.2, as
MoMask): in training a batch uses only its first q ~ U{1..Q} layers, so that the first
layers alone already decode to a plausible motion.

Losses: SmoothL1 on the features and 0.5 x SmoothL1 on their frame-to-frame differences
("velocity"), as MoMask, plus two departures of ours (see ``forward``): the 4 root features
weighted x5, and SmoothL1 on the running sums of the root's rotation and planar velocity;
0.02 x commitment.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import torch
import torch.nn.functional as F
from torch import nn

from ..body.features import HML_LAYOUT
from .conv1d import conv_decoder, conv_encoder, feature_weights, reconstruction_losses


@dataclass
class RVQConfig:
    feature_dim: int = HML_LAYOUT.dim
    width: int = 128  # convolution channels (MoMask: 512); narrower so that it trains on 2 CPU cores
    code_dim: int = 512
    codebook_size: int = 512
    quantizers: int = 6
    res_blocks: int = 3  # dilated residual blocks per level (dilations 1, 3, 9, ...)
    downsample: int = 4  # two stride-2 levels
    ema_decay: float = 0.99
    commitment: float = 0.02
    velocity_weight: float = 0.5
    quantizer_dropout: float = 0.2
    dead_threshold: float = 1.0
    root_weight: float = 5.0  # extra weight of the 4 root features (see RVQVAE.forward)
    trajectory_weight: float = 1.0  # integrated root rotation / velocity (see RVQVAE.forward)
    position_weight: float = 4.0  # extra weight of the 63 root-relative joint positions (see RVQVAE.forward)
    # multipliers of the position weight of the neck, head, elbows and wrists, and of the feet
    # (``conv1d.UPPER_DETAIL_JOINTS``, ``FOOT_JOINTS``); 1: all joints alike, as shipped
    upper_detail_weight: float = 1.0
    foot_weight: float = 1.0

    def to_dict(self) -> dict:
        return asdict(self)

    @property
    def levels(self) -> int:
        return {1: 0, 2: 1, 4: 2, 8: 3}[self.downsample]


class EMACodebook(nn.Module):
    """One codebook (K, D) updated by EMA; buffers only, no gradient parameters."""

    def __init__(self, size: int, dim: int, decay: float, dead_threshold: float) -> None:
        super().__init__()
        self.decay, self.dead_threshold = decay, dead_threshold
        self.register_buffer("embed", torch.randn(size, dim) * 0.01)
        self.register_buffer("cluster_size", torch.zeros(size))
        self.register_buffer("embed_sum", torch.zeros(size, dim))
        self.register_buffer("initialised", torch.tensor(False))

    def assign(self, x: torch.Tensor) -> torch.Tensor:
        """x: (N, D) -> nearest code indices (N,)."""
        d = x.pow(2).sum(1, keepdim=True) - 2 * x @ self.embed.t() + self.embed.pow(2).sum(1)[None]
        return d.argmin(1)

    @torch.no_grad()
    def update(self, x: torch.Tensor, idx: torch.Tensor) -> None:
        """EMA of counts and sums of the vectors x (N, D) assigned to each code, then dead-code reset."""
        if not bool(self.initialised):
            self.embed.copy_(x[torch.randint(0, len(x), (len(self.embed),))])
            self.cluster_size.fill_(1.0)
            self.embed_sum.copy_(self.embed)
            self.initialised.fill_(True)
            return
        counts = torch.bincount(idx, minlength=len(self.embed)).type_as(x)
        sums = torch.zeros_like(self.embed_sum).index_add_(0, idx, x)
        self.cluster_size.mul_(self.decay).add_(counts, alpha=1 - self.decay)
        self.embed_sum.mul_(self.decay).add_(sums, alpha=1 - self.decay)
        n = self.cluster_size.sum()
        # Laplace smoothing keeps rarely used codes from dividing by ~0
        size = (self.cluster_size + 1e-5) / (n + len(self.embed) * 1e-5) * n
        self.embed.copy_(self.embed_sum / size[:, None])
        dead = self.cluster_size < self.dead_threshold
        if bool(dead.any()):
            pick = x[torch.randint(0, len(x), (int(dead.sum()),))]
            self.embed[dead] = pick
            self.embed_sum[dead] = pick
            self.cluster_size[dead] = 1.0


class ResidualQuantizer(nn.Module):
    def __init__(self, cfg: RVQConfig) -> None:
        super().__init__()
        self.cfg = cfg
        self.books = nn.ModuleList(
            EMACodebook(cfg.codebook_size, cfg.code_dim, cfg.ema_decay, cfg.dead_threshold)
            for _ in range(cfg.quantizers)
        )

    def forward(self, z: torch.Tensor, mask: torch.Tensor | None = None, layers: int | None = None):
        """z: (B, n, D) encoder output, mask (B, n) True on real tokens.
        Returns (z_q straight-through (B, n, D), codes (B, n, Q) with -1 on unused layers,
        commitment loss)."""
        b, n, dim = z.shape
        layers = layers or len(self.books)
        flat = z.reshape(-1, dim)
        keep = mask.reshape(-1) if mask is not None else torch.ones(len(flat), dtype=torch.bool, device=z.device)
        residual = flat
        total = torch.zeros_like(flat)
        codes = torch.full((len(flat), len(self.books)), -1, dtype=torch.long, device=z.device)
        commit = z.new_zeros(())
        for q, book in enumerate(self.books[:layers]):
            idx = book.assign(residual.detach())
            if self.training:
                # EMA step from this batch's assignment; the batch itself is quantised with
                # the codebook it was assigned against (one distance computation per layer)
                vec = book.embed[idx]
                book.update(residual.detach()[keep], idx[keep])
            else:
                vec = book.embed[idx]
            commit = commit + F.mse_loss(residual[keep], vec[keep].detach())
            codes[:, q] = idx
            total = total + vec
            residual = residual - vec.detach()
        zq = flat + (total - flat).detach()
        return zq.view(b, n, dim), codes.view(b, n, -1), commit

    def lookup(self, codes: torch.Tensor) -> torch.Tensor:
        """codes (B, n, q<=Q) -> summed code vectors (B, n, D); a code of -1 adds nothing."""
        out = 0
        for q in range(codes.shape[-1]):
            c = codes[..., q]
            out = out + self.books[q].embed[c.clamp(min=0)] * (c >= 0).unsqueeze(-1)
        return out


class RVQVAE(nn.Module):
    def __init__(self, cfg: RVQConfig | None = None) -> None:
        super().__init__()
        self.cfg = cfg = cfg or RVQConfig()
        self.encoder = conv_encoder(cfg.feature_dim, cfg.width, cfg.code_dim, cfg.levels, cfg.res_blocks)
        self.decoder = conv_decoder(cfg.code_dim, cfg.width, cfg.feature_dim, cfg.levels, cfg.res_blocks)
        self.quantizer = ResidualQuantizer(cfg)

    def _pad(self, x: torch.Tensor) -> torch.Tensor:
        """Repeat the last frame up to a multiple of ``downsample``: (B, T, F) -> (B, T', F)."""
        r = (-x.shape[1]) % self.cfg.downsample
        return torch.cat([x, x[:, -1:].expand(-1, r, -1)], dim=1) if r else x

    def encode_latent(self, x: torch.Tensor) -> torch.Tensor:
        """Normalised features (B, T, F) -> continuous latents (B, ceil(T/4), code_dim)."""
        return self.encoder(self._pad(x).transpose(1, 2)).transpose(1, 2)

    def encode(self, x: torch.Tensor, mask: torch.Tensor | None = None) -> tuple[torch.Tensor, torch.Tensor]:
        """(B, T, F) -> (codes (B, n, Q), continuous latents (B, n, code_dim))."""
        z = self.encode_latent(x)
        tok_mask = None if mask is None else mask[:, :: self.cfg.downsample][:, : z.shape[1]]
        _, codes, _ = self.quantizer(z, tok_mask)
        return codes, z

    def decode_latent(self, zq: torch.Tensor) -> torch.Tensor:
        """(B, n, code_dim) -> features (B, 4n, F)."""
        return self.decoder(zq.transpose(1, 2)).transpose(1, 2)

    def decode(self, codes: torch.Tensor) -> torch.Tensor:
        """Codes (B, n, q) -> normalised features (B, 4n, F)."""
        return self.decode_latent(self.quantizer.lookup(codes))

    def feature_weights(self, device: torch.device | None = None) -> torch.Tensor:
        """Per-feature weights (F,) of the reconstruction and velocity losses, mean 1
        (``conv1d.feature_weights``: the root and the joint positions weighted up)."""
        return feature_weights(
            self.cfg.feature_dim,
            self.cfg.root_weight,
            self.cfg.position_weight,
            device,
            self.cfg.upper_detail_weight,
            self.cfg.foot_weight,
        )

    def forward(self, x: torch.Tensor, mask: torch.Tensor | None = None) -> dict[str, torch.Tensor]:
        """Training pass on (B, T, F) with T a multiple of 4: reconstruction, losses, codes."""
        z = self.encode_latent(x)
        layers = None
        if self.training and self.cfg.quantizer_dropout > 0 and torch.rand(()) < self.cfg.quantizer_dropout:
            layers = int(torch.randint(1, self.cfg.quantizers + 1, ()))
        tok_mask = None if mask is None else mask[:, :: self.cfg.downsample]
        zq, codes, commit = self.quantizer(z, tok_mask, layers)
        rec = self.decode_latent(zq)[:, : x.shape[1]]
        rec_loss, vel_loss, traj_loss = reconstruction_losses(rec, x, mask, self.feature_weights(x.device))
        loss = (
            rec_loss
            + self.cfg.velocity_weight * vel_loss
            + self.cfg.trajectory_weight * traj_loss
            + self.cfg.commitment * commit
        )
        return {
            "rec": rec,
            "codes": codes,
            "loss": loss,
            "rec_loss": rec_loss,
            "vel_loss": vel_loss,
            "traj_loss": traj_loss,
            "commit": commit,
        }
