"""Motion VAE in the MLD style: a variable-length motion <-> a few latent tokens x 256.

Encoder: normalised features (B, T, 263) -> Linear -> two stride-2 Conv1D (T/4 tokens)
-> transformer over [2*n_z learned query tokens | motion tokens] -> the query tokens'
outputs are mu and log-variance, each (B, n_z, 256).
Decoder: z (B, n_z, 256) and T -> transformer over [z | T/4 positional queries] ->
two stride-2 transposed Conv1D back to T frames -> Linear -> features (B, T, 263).

Departure from MLD: MLD's VAE runs its transformer on every frame (9 layers, skip
connections); ours runs it on T/4 tokens after a strided convolution, 4x less attention
work, which is what makes training on a 2-core CPU possible. The latent interface (a few
tokens x 256, KL-regularised, decoder told the length) is MLD's.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import torch
from torch import nn

from ..body.features import HML_LAYOUT, Normalizer, features_to_joints


@dataclass
class VAEConfig:
    feature_dim: int = HML_LAYOUT.dim
    latent_tokens: int = 2
    latent_dim: int = 256  # the transformers' width, and the latent's unless z_width is set
    # the latent's width when it differs from the transformers' (MotionLCM-V2's 16 x 32):
    # 0 keeps MLD's interface, the latent tokens being the transformer outputs themselves
    z_width: int = 0
    layers: int = 2  # transformer layers in the encoder and in the decoder
    heads: int = 4
    ff: int = 512
    dropout: float = 0.1
    downsample: int = 4  # two stride-2 convolutions
    max_frames: int = 200
    # loss weights (recorded with the checkpoint; the defaults are the first shipped VAE's)
    root_weight: float = 20.0  # extra weight of the 4 root features
    position_weight: float = 1.0  # extra weight of the 63 root-relative joint positions
    joint_weight: float = 2.0  # global joint positions (the root's path integrated), metres
    relative_joint_weight: float = 0.0  # root-relative joint positions, metres
    velocity_weight: float = 0.0  # frame-to-frame feature differences, weighted like the features
    kl_weight: float = 1e-4

    def to_dict(self) -> dict:
        return asdict(self)


def sinusoid(n: int, d: int, device=None) -> torch.Tensor:
    """(n, d) sinusoidal position table."""
    pos = torch.arange(n, device=device, dtype=torch.float32)[:, None]
    div = torch.exp(torch.arange(0, d, 2, device=device, dtype=torch.float32) * (-math.log(10000.0) / d))
    pe = torch.zeros(n, d, device=device)
    pe[:, 0::2] = torch.sin(pos * div)
    pe[:, 1::2] = torch.cos(pos * div)
    return pe


def _transformer(cfg: VAEConfig) -> nn.TransformerEncoder:
    layer = nn.TransformerEncoderLayer(
        cfg.latent_dim, cfg.heads, cfg.ff, cfg.dropout, activation="gelu", batch_first=True, norm_first=True
    )
    # nested tensors are a fast path for inference only and warn under norm_first
    return nn.TransformerEncoder(layer, cfg.layers, norm=nn.LayerNorm(cfg.latent_dim), enable_nested_tensor=False)


class MotionVAE(nn.Module):
    def __init__(self, cfg: VAEConfig | None = None) -> None:
        super().__init__()
        self.cfg = cfg = cfg or VAEConfig()
        d = cfg.latent_dim
        self.inp = nn.Linear(cfg.feature_dim, d)
        self.down = nn.Sequential(
            nn.Conv1d(d, d, 4, stride=2, padding=1), nn.GELU(), nn.Conv1d(d, d, 4, stride=2, padding=1), nn.GELU()
        )
        self.dist_tokens = nn.Parameter(torch.randn(2 * cfg.latent_tokens, d) * 0.02)
        if cfg.z_width:
            self.z_mu = nn.Linear(d, cfg.z_width)
            self.z_logvar = nn.Linear(d, cfg.z_width)
            self.z_in = nn.Linear(cfg.z_width, d)
        self.encoder = _transformer(cfg)
        self.decoder = _transformer(cfg)
        self.up = nn.Sequential(
            nn.ConvTranspose1d(d, d, 4, stride=2, padding=1),
            nn.GELU(),
            nn.ConvTranspose1d(d, d, 4, stride=2, padding=1),
            nn.GELU(),
        )
        self.out = nn.Linear(d, cfg.feature_dim)
        self.register_buffer("pe", sinusoid(cfg.max_frames // cfg.downsample + 8, d), persistent=False)

    @property
    def latent_shape(self) -> tuple[int, int]:
        """(n_z, width) of one motion's latent."""
        return self.cfg.latent_tokens, self.cfg.z_width or self.cfg.latent_dim

    @property
    def longest(self) -> int:
        """The most frames one latent decodes to (its position table's length)."""
        return self.pe.shape[0] * self.cfg.downsample

    @property
    def frames_per_token(self) -> int:
        """0: the latent describes the whole clip (a temporal VAE's is its frames per token)."""
        return 0

    def tokens(self, frames: int) -> int:
        return -(-frames // self.cfg.downsample)

    def encode(self, x: torch.Tensor, mask: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        """x: (B, T, 263) normalised, T a multiple of 4; mask: (B, T) True on real frames.
        Returns mu, logvar: (B, n_z, width), width 256 unless ``z_width`` is set."""
        # padded frames are zeroed after the input projection and after the first strided
        # convolution (their biases would make them nonzero): the convolutions reach a few
        # frames past a clip's end, so otherwise a clip's posterior depended on how much
        # padding its batch had
        h = (self.inp(x) * mask[..., None]).transpose(1, 2)
        conv1, act1, conv2, act2 = self.down
        h = act1(conv1(h)) * mask[:, None, ::2]
        h = act2(conv2(h)).transpose(1, 2)  # (B, T/4, d)
        n = h.shape[1]
        h = h + self.pe[:n]
        tok_mask = mask[:, :: self.cfg.downsample][:, :n]
        q = self.dist_tokens.expand(x.shape[0], -1, -1)
        pad = torch.cat([torch.zeros_like(q[..., 0], dtype=torch.bool), ~tok_mask], dim=1)
        out = self.encoder(torch.cat([q, h], dim=1), src_key_padding_mask=pad)
        k = self.cfg.latent_tokens
        mu, logvar = out[:, :k], out[:, k : 2 * k]
        if self.cfg.z_width:
            mu, logvar = self.z_mu(mu), self.z_logvar(logvar)
        return mu, logvar.clamp(-10, 10)

    def decode(self, z: torch.Tensor, frames: int | torch.Tensor, t_pad: int | None = None) -> torch.Tensor:
        """z: (B, n_z, width); frames: int or (B,) lengths. Returns (B, T, 263) normalised
        features with T = t_pad or max(frames) rounded up to a multiple of 4."""
        bsz = z.shape[0]
        if self.cfg.z_width:
            z = self.z_in(z)
        lengths = torch.as_tensor(frames, device=z.device).expand(bsz) if not torch.is_tensor(frames) else frames
        t_max = t_pad or int(lengths.max())
        n = self.tokens(t_max)
        q = self.pe[:n].expand(bsz, -1, -1)
        tok_valid = torch.arange(n, device=z.device)[None] < (lengths[:, None] + self.cfg.downsample - 1) // (
            self.cfg.downsample
        )
        pad = torch.cat([torch.zeros(bsz, z.shape[1], dtype=torch.bool, device=z.device), ~tok_valid], dim=1)
        out = self.decoder(torch.cat([z, q], dim=1), src_key_padding_mask=pad)[:, z.shape[1] :]
        # the same for the padded tokens, which the transposed convolutions blend into a
        # clip's last frames: a clip decodes the same alone and in a batch of longer ones
        out = out * tok_valid[..., None]
        y = self.up(out.transpose(1, 2)).transpose(1, 2)
        return self.out(y)[:, : n * self.cfg.downsample]

    def forward(self, x: torch.Tensor, mask: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
        mu, logvar = self.encode(x, mask)
        z = mu + torch.randn_like(mu) * torch.exp(0.5 * logvar) if self.training else mu
        return self.decode(z, mask.sum(1), t_pad=x.shape[1]), mu, logvar

    def loss(
        self,
        out: tuple[torch.Tensor, torch.Tensor, torch.Tensor],
        x: torch.Tensor,
        mask: torch.Tensor,
        norm: Normalizer,
    ) -> tuple[torch.Tensor, dict[str, float]]:
        """``vae_loss`` with this VAE's weights."""
        return vae_loss(out, x, mask, norm, self.cfg)


def vae_loss(
    vae_out: tuple[torch.Tensor, torch.Tensor, torch.Tensor],
    x: torch.Tensor,
    mask: torch.Tensor,
    norm: Normalizer,
    cfg: VAEConfig | None = None,
) -> tuple[torch.Tensor, dict[str, float]]:
    """MLD's VAE loss: SmoothL1 on features + SmoothL1 on joint positions (metres) + KL,
    with the weights of ``cfg``. Departures, all weights: the root features and (from the
    second VAE on) the root-relative positions weighted up, a root-relative joint term and
    a velocity term; the reasons are those of KMM's tokeniser (``RVQVAE.feature_weights``)."""
    cfg = cfg or VAEConfig()
    rec, mu, logvar = vae_out
    m = mask[..., None].float()
    n = m.sum()
    # the 4 root features (yaw velocity, planar velocity, height) carry the whole trajectory
    # but are 4 of 263 dimensions: weighted up so that direction and turning survive
    w = torch.ones(x.shape[-1], device=x.device)
    w[:4] = cfg.root_weight
    w[HML_LAYOUT.ric] = cfg.position_weight
    l_feat = (nn.functional.smooth_l1_loss(rec, x, reduction="none") * m * w).sum() / (n * w.sum())
    jr = features_to_joints(norm.denormalize(rec))
    jx = features_to_joints(norm.denormalize(x))
    l_joint = (nn.functional.smooth_l1_loss(jr, jx, reduction="none", beta=0.05) * m[..., None]).sum() / (n * 66)
    parts = {"feat": float(l_feat.detach()), "joint": float(l_joint.detach())}
    loss = l_feat + cfg.joint_weight * l_joint
    if cfg.relative_joint_weight:
        rel = nn.functional.smooth_l1_loss(jr - jr[:, :, :1], jx - jx[:, :, :1], reduction="none", beta=0.05)
        l_rel = (rel * m[..., None]).sum() / (n * 66)
        loss = loss + cfg.relative_joint_weight * l_rel
        parts["rel_joint"] = float(l_rel.detach())
    if cfg.velocity_weight:
        mv = (mask[:, 1:] & mask[:, :-1])[..., None].float()
        dv = nn.functional.smooth_l1_loss(rec[:, 1:] - rec[:, :-1], x[:, 1:] - x[:, :-1], reduction="none")
        l_vel = (dv * mv * w).sum() / (mv.sum() * w.sum())
        loss = loss + cfg.velocity_weight * l_vel
        parts["vel"] = float(l_vel.detach())
    kl = 0.5 * (mu.pow(2) + logvar.exp() - 1 - logvar).mean()
    parts["kl"] = float(kl.detach())
    return loss + cfg.kl_weight * kl, parts


def mpjpe_mm(pred: torch.Tensor, gt: torch.Tensor, mask: torch.Tensor) -> float:
    """Mean per-joint position error in millimetres over real frames; (B, T, J, 3) each."""
    err = (pred - gt).norm(dim=-1).mean(-1)  # (B, T)
    return float(1000.0 * (err * mask).sum() / mask.sum())
