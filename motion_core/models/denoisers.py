"""Latent denoisers eps_theta(z_t, t, text, length) for the diffusion methods.

All take z_t: (B, n_z, d) noisy latent tokens, t: (B,) diffusion steps, text: (B, 384)
sentence embeddings (the empty text's embedding for the unconditional branch) and
frames: (B,) target lengths, and return epsilon (B, n_z, d).

Conditioning as MLD: a time-step token and a projected text token are put in front of
the latent tokens. Departure: the target length is embedded too and added to the time
token, so a 2 s and a 10 s "walk" get different latents (MLD tells only the VAE decoder
the length); the sequence seen by the blocks stays n_z + 2 tokens long.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field

import torch
from torch import nn

from ..nn.ssm import MambaBlock, SSMConfig


def sinusoid_freqs(dim: int, max_period: float = 10000.0) -> torch.Tensor:
    half = dim // 2
    return torch.exp(-math.log(max_period) * torch.arange(half, dtype=torch.float32) / half)


def timestep_embedding(t: torch.Tensor, freqs: torch.Tensor) -> torch.Tensor:
    """(B,) integer steps (or frame counts), (dim/2,) frequencies -> (B, dim) sinusoidal embedding."""
    args = t.float()[:, None] * freqs[None]
    return torch.cat([torch.cos(args), torch.sin(args)], dim=-1)


class Conditioning(nn.Module):
    """Builds the [time+length, text] prefix tokens: (B, 2, d)."""

    def __init__(self, d: int, text_dim: int) -> None:
        super().__init__()
        self.d = d
        self.time = nn.Sequential(nn.Linear(d, d), nn.SiLU(), nn.Linear(d, d))
        self.length = nn.Sequential(nn.Linear(d, d), nn.SiLU(), nn.Linear(d, d))
        self.text = nn.Linear(text_dim, d)
        # frequency tables built once (building them per call cost ~1 ms on the CPU)
        self.register_buffer("t_freqs", sinusoid_freqs(d), persistent=False)
        self.register_buffer("len_freqs", sinusoid_freqs(d, 1000.0), persistent=False)

    def forward(
        self, t: torch.Tensor, text: torch.Tensor, frames: torch.Tensor, shift: torch.Tensor | None = None
    ) -> torch.Tensor:
        """``shift`` (B, d), when given, is added to the time token: a consistency student's
        guidance-scale embedding enters there (``models/consistency.py``)."""
        tl = self.time(timestep_embedding(t, self.t_freqs)) + self.length(timestep_embedding(frames, self.len_freqs))
        if shift is not None:
            tl = tl + shift
        return torch.stack([tl, self.text(text)], dim=1)


@dataclass
class MotionMambaConfig:
    """Motion Mamba's denoiser. ``levels`` = N encoder (and N decoder) blocks; the HTM scan
    counts run 2N-1, 2N-3, ..., 1 from the outermost encoder block inwards (Eq. 6) and
    mirror in the decoder. ``htm_order`` "hierarchical" | "ascending" (S^1..S^N) |
    "descending" (S^N..S^1) | "flat" (1 scan everywhere) reproduces the paper's Table 4
    arms; ``bsm`` "bidirectional" | "single" | "none" likewise."""

    latent_tokens: int = 2
    latent_dim: int = 256
    z_width: int = 0  # the latent's channels when not latent_dim (a temporal VAE's 16); see LatentDenoiser
    frames_per_token: int = 0  # a temporal latent's frames per token (4); 0: a clip-level latent
    text_dim: int = 384
    levels: int = 5
    htm_order: str = "hierarchical"
    bsm: str = "bidirectional"
    htm_ssm: SSMConfig = field(default_factory=lambda: SSMConfig(expand=1.0))
    bsm_ssm: SSMConfig = field(default_factory=lambda: SSMConfig(expand=4.0, d_state=8))
    heads: int = 4
    ff: int = 1024
    dropout: float = 0.1  # in the attention mixer

    def __post_init__(self) -> None:
        for name, allowed in (
            ("htm_order", ("hierarchical", "ascending", "descending", "flat")),
            ("bsm", ("bidirectional", "single", "none")),
        ):
            if getattr(self, name) not in allowed:
                raise ValueError(f"{name} must be one of {allowed}, got {getattr(self, name)!r}")

    def scan_counts(self) -> list[int]:
        """Scans per encoder block E_1..E_N (the decoder mirrors: D_N gets E_1's)."""
        n = self.levels
        return {
            "hierarchical": [2 * (n - i) - 1 for i in range(n)],
            "ascending": list(range(1, n + 1)),
            "descending": list(range(n, 0, -1)),
            "flat": [1] * n,
        }[self.htm_order]

    def to_dict(self) -> dict:
        return asdict(self)


class HTM(nn.Module):
    """Hierarchical Temporal Mamba block (Algorithm 1): k isolated scans over the token
    axis, each with its own A, Conv1D and projections, aggregated then projected.
    Pre-norm residual. x: (B, L, C) -> (B, L, C)."""

    def __init__(self, d: int, k: int, cfg: SSMConfig) -> None:
        super().__init__()
        self.norm = nn.LayerNorm(d)
        self.mamba = MambaBlock(d, (1,) * k, cfg)

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        return x + self.mamba(self.norm(x))


class BSM(nn.Module):
    """Bidirectional Spatial Mamba block (Algorithm 2): rearrange (B, L, C) -> (B, C, L) so
    the scan runs over the C latent channels, normalise, scan forward and backward, gate
    and sum, rearrange back. Pre-norm residual. ``directions`` (1,) is the single-scan
    ablation. x: (B, L, C) -> (B, L, C)."""

    def __init__(self, tokens: int, cfg: SSMConfig, directions: tuple[int, ...] = (1, -1)) -> None:
        super().__init__()
        self.norm = nn.LayerNorm(tokens)
        self.mamba = MambaBlock(tokens, directions, cfg)

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        xt = x.transpose(1, 2)  # (B, C, L): channels are the sequence
        return x + self.mamba(self.norm(xt)).transpose(1, 2)


class MambaLevel(nn.Module):
    """One U-Net block: HTM followed by BSM (or HTM alone for the no-BSM ablation)."""

    def __init__(self, cfg: MotionMambaConfig, k: int) -> None:
        super().__init__()
        self.htm = HTM(cfg.latent_dim, k, cfg.htm_ssm)
        tokens = cfg.latent_tokens + 2
        self.bsm = None
        if cfg.bsm != "none":
            self.bsm = BSM(tokens, cfg.bsm_ssm, (1, -1) if cfg.bsm == "bidirectional" else (1,))

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        x = self.htm(x)
        return self.bsm(x) if self.bsm is not None else x


def _attention_layer(d: int, heads: int, ff: int, dropout: float = 0.1) -> nn.TransformerEncoderLayer:
    return nn.TransformerEncoderLayer(d, heads, ff, dropout, activation="gelu", batch_first=True, norm_first=True)


class _UNet(nn.Module):
    """E_1..E_N, mixer M, D_1..D_N with skips fused as MLD (concat, Linear 2d -> d)."""

    def __init__(self, enc: list[nn.Module], mid: nn.Module, dec: list[nn.Module], d: int) -> None:
        super().__init__()
        self.enc, self.mid, self.dec = nn.ModuleList(enc), mid, nn.ModuleList(dec)
        self.fuse = nn.ModuleList([nn.Linear(2 * d, d) for _ in dec])

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        skips = []
        for blk in self.enc:
            x = blk(x)
            skips.append(x)
        x = self.mid(x)
        for blk, fuse in zip(self.dec, self.fuse, strict=True):
            x = blk(fuse(torch.cat([x, skips.pop()], dim=-1)))
        return x


class LatentDenoiser(nn.Module):
    """Shared shell: conditioning prefix -> U-Net body -> the prediction on the latent tokens.

    z: (B, n_z, z_width) -> (B, n_z, z_width). A clip-level latent (MLD's, 2 x 256) enters
    the blocks as it is (z_width 0: the blocks' width d). A temporal latent (one
    ``z_width``-channel token per ``frames_per_token`` frames, zero-padded to n_z) is
    projected to d and back, and the prediction past a clip's last token is set to zero: the
    clean latent is zero there, so with the x_0 target (the one temporal latents train on)
    the padding is known rather than learned."""

    def __init__(
        self, body: nn.Module, latent_tokens: int, d: int, text_dim: int, z_width: int = 0, frames_per_token: int = 0
    ) -> None:
        super().__init__()
        self.cond = Conditioning(d, text_dim)
        self.pos = nn.Parameter(torch.randn(latent_tokens + 2, d) * 0.02)
        self.inp = nn.Linear(z_width, d) if z_width else nn.Identity()
        self.body = body
        self.norm = nn.LayerNorm(d)
        self.head = nn.Linear(d, z_width or d)
        self.n_z = latent_tokens
        self.frames_per_token = frames_per_token

    def forward(
        self,
        z: torch.Tensor,
        t: torch.Tensor,
        text: torch.Tensor,
        frames: torch.Tensor,
        time_shift: torch.Tensor | None = None,
    ) -> torch.Tensor:
        """``time_shift`` (B, d): added to the time token (see ``Conditioning``)."""
        x = torch.cat([self.cond(t, text, frames, time_shift), self.inp(z)], dim=1) + self.pos
        # FTMoMamba's TextSSM reads the sentence embedding inside every block
        x = self.body(x, text) if getattr(self.body, "wants_text", False) else self.body(x)
        out = self.head(self.norm(x[:, -self.n_z :]))
        if self.frames_per_token:
            tokens = (frames + self.frames_per_token - 1) // self.frames_per_token
            out = out * (torch.arange(self.n_z, device=z.device)[None] < tokens[:, None])[..., None]
        return out


def shell(body: nn.Module, cfg) -> LatentDenoiser:
    """The ``LatentDenoiser`` around ``body`` for a config with the shared latent fields."""
    return LatentDenoiser(body, cfg.latent_tokens, cfg.latent_dim, cfg.text_dim, cfg.z_width, cfg.frames_per_token)


def motion_mamba_denoiser(cfg: MotionMambaConfig) -> LatentDenoiser:
    counts = cfg.scan_counts()
    enc = [MambaLevel(cfg, k) for k in counts]
    dec = [MambaLevel(cfg, k) for k in reversed(counts)]  # D_1 (first after M) gets S^1
    mid = _attention_layer(cfg.latent_dim, cfg.heads, cfg.ff, cfg.dropout)
    return shell(_UNet(enc, mid, dec, cfg.latent_dim), cfg)


@dataclass
class TransformerConfig:
    """MLD's skip transformer: ``levels`` encoder layers, one middle layer, ``levels``
    decoder layers (MLD: 4 + 1 + 4 at d 256, ff 1024, 4 heads)."""

    latent_tokens: int = 2
    latent_dim: int = 256
    z_width: int = 0  # the latent's channels when not latent_dim (a temporal VAE's 16); see LatentDenoiser
    frames_per_token: int = 0  # a temporal latent's frames per token (4); 0: a clip-level latent
    text_dim: int = 384
    levels: int = 4
    heads: int = 4
    ff: int = 1024
    dropout: float = 0.1

    def to_dict(self) -> dict:
        return asdict(self)


def transformer_denoiser(cfg: TransformerConfig) -> LatentDenoiser:
    d = cfg.latent_dim
    enc = [_attention_layer(d, cfg.heads, cfg.ff, cfg.dropout) for _ in range(cfg.levels)]
    dec = [_attention_layer(d, cfg.heads, cfg.ff, cfg.dropout) for _ in range(cfg.levels)]
    mid = _attention_layer(d, cfg.heads, cfg.ff, cfg.dropout)
    return shell(_UNet(enc, mid, dec, d), cfg)
