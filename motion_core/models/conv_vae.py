"""Temporal-latent motion VAE: a motion <-> one small latent vector per 4 frames.

Encoder and decoder are KMM's tokeniser's convolutions (``conv1d``); the quantiser is
replaced by a Gaussian posterior: Linear heads map the encoder's (B, T/4, code_dim) output
to mu and log-variance (B, T/4, z_width), and a Linear maps z back to code_dim for the
decoder. A run can start from the shipped tokeniser's convolutions (``init_from_tokeniser``).

Departure from Motion Mamba / MLD, whose VAE compresses a whole clip into 2 x 256: the
2-token VAE trained on this 2-core CPU reconstructed only half of the verifier's validation
prompts (and 1 to 8 tokens x 256 all reached ~20% at 1,000 steps), where the tokeniser's
convolutions pass 94% (``docs/training-log.md``). The denoisers see the latent as
``max_frames / 4`` tokens (56): a clip's tokens, then zeros; HTM's temporal scans
then run over a real sequence.

Padding: every layer's output is zeroed past the clip's end at that layer's frame rate, so
a clip's latent and its decoding do not depend on the batch it is in.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import torch
from torch import nn

from ..body.features import HML_LAYOUT, Normalizer
from .conv1d import conv_decoder, conv_encoder, feature_weights, reconstruction_losses

_PAD_LOGVAR = -30.0  # padded tokens' log-variance: sampling them gives their mean, zero


@dataclass
class ConvVAEConfig:
    feature_dim: int = HML_LAYOUT.dim
    width: int = 128  # the tokeniser's convolution channels
    code_dim: int = 512  # the encoder's output channels (the tokeniser's code width)
    z_width: int = 16  # the latent's channels per token
    res_blocks: int = 3
    downsample: int = 4  # two stride-2 levels
    # the longest latent the denoisers see, max_frames / 4 tokens: a 10 s segment (200 frames)
    # plus the frames a timeline's segment is generated longer to blend into the next (10),
    # rounded up so that the denoisers' 2 + 56 tokens are even (FTMoMamba's Haar DWT halves them)
    max_frames: int = 224
    root_weight: float = 5.0
    position_weight: float = 4.0
    # multipliers of the position weight of the neck, head, elbows and wrists, and of the feet
    # (``conv1d.UPPER_DETAIL_JOINTS``, ``FOOT_JOINTS``); 1: all joints alike, as shipped
    upper_detail_weight: float = 1.0
    foot_weight: float = 1.0
    velocity_weight: float = 0.5
    trajectory_weight: float = 1.0
    kl_weight: float = 1e-4

    @property
    def levels(self) -> int:
        return {1: 0, 2: 1, 4: 2, 8: 3}[self.downsample]

    def to_dict(self) -> dict:
        return asdict(self)


def _lengths_mask(lengths: torch.Tensor, n: int) -> torch.Tensor:
    """(B,) lengths -> (B, 1, n) float mask, 1 on the first lengths[b] positions."""
    return (torch.arange(n, device=lengths.device)[None] < lengths[:, None]).float()[:, None]


def _run_masked(layers: nn.Sequential, h: torch.Tensor, lengths: torch.Tensor) -> torch.Tensor:
    """Apply ``layers`` to h (B, C, n), zeroing positions past ``lengths`` (in h's frame rate)
    after every layer; a stride-2 conv halves the lengths (rounding up), an upsampling doubles them."""
    for layer in layers:
        h = layer(h)
        if isinstance(layer, nn.Conv1d) and layer.stride[0] == 2:
            lengths = (lengths + 1) // 2
        elif isinstance(layer, nn.Upsample):
            lengths = lengths * 2
        h = h * _lengths_mask(lengths, h.shape[-1])
    return h


class ConvMotionVAE(nn.Module):
    def __init__(self, cfg: ConvVAEConfig | None = None) -> None:
        super().__init__()
        self.cfg = cfg = cfg or ConvVAEConfig()
        self.encoder = conv_encoder(cfg.feature_dim, cfg.width, cfg.code_dim, cfg.levels, cfg.res_blocks)
        self.decoder = conv_decoder(cfg.code_dim, cfg.width, cfg.feature_dim, cfg.levels, cfg.res_blocks)
        self.z_mu = nn.Linear(cfg.code_dim, cfg.z_width)
        self.z_logvar = nn.Linear(cfg.code_dim, cfg.z_width)
        self.z_in = nn.Linear(cfg.z_width, cfg.code_dim)
        nn.init.zeros_(self.z_logvar.weight)
        nn.init.constant_(self.z_logvar.bias, -4.0)  # start nearly deterministic, as the tokeniser was

    @property
    def latent_shape(self) -> tuple[int, int]:
        """(tokens, width) of one motion's latent as the denoisers see it: the longest clip's tokens."""
        return self.tokens(self.cfg.max_frames), self.cfg.z_width

    @property
    def longest(self) -> int:
        """The most frames one latent decodes to: its tokens' frames."""
        return self.latent_shape[0] * self.cfg.downsample

    @property
    def frames_per_token(self) -> int:
        return self.cfg.downsample

    def tokens(self, frames: int) -> int:
        return -(-frames // self.cfg.downsample)

    def init_from_tokeniser(self, rvq_state: dict) -> int:
        """Copy the encoder's and decoder's convolutions from a tokeniser state dict; the
        encoder's last and the decoder's first layer map to code_dim, as the tokeniser's do.
        Returns the number of tensors copied."""
        own = self.state_dict()
        taken = {k: v for k, v in rvq_state.items() if k.startswith(("encoder.", "decoder.")) and k in own}
        for k, v in taken.items():
            if own[k].shape != v.shape:
                raise ValueError(f"{k}: tokeniser {tuple(v.shape)} vs VAE {tuple(own[k].shape)}")
        self.load_state_dict({**own, **taken})
        return len(taken)

    def encode(self, x: torch.Tensor, mask: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        """x: (B, T, 263) normalised, T a multiple of 4; mask (B, T) True on real frames.
        Returns mu, logvar: (B, max_frames / 4, z_width); tokens past a clip's end have mu 0
        and a log-variance of -30."""
        lengths = mask.sum(1)
        h = _run_masked(self.encoder, x.transpose(1, 2) * mask[:, None], lengths).transpose(1, 2)
        mu, logvar = self.z_mu(h), self.z_logvar(h).clamp(-10, 10)
        n_max = self.latent_shape[0]
        if h.shape[1] > n_max:
            raise ValueError(f"clips of up to {self.cfg.max_frames} frames, got {x.shape[1]}")
        valid = _lengths_mask((lengths + self.cfg.downsample - 1) // self.cfg.downsample, n_max)[:, 0, :, None]
        pad = n_max - h.shape[1]
        mu = nn.functional.pad(mu, (0, 0, 0, pad)) * valid
        logvar = nn.functional.pad(logvar, (0, 0, 0, pad)) * valid + _PAD_LOGVAR * (1 - valid)
        return mu, logvar

    def decode(self, z: torch.Tensor, frames: int | torch.Tensor, t_pad: int | None = None) -> torch.Tensor:
        """z: (B, n >= tokens(T), z_width); frames: int or (B,) lengths. Returns (B, T, 263)
        normalised features with T = t_pad or max(frames) rounded up to a multiple of 4."""
        bsz = z.shape[0]
        lengths = torch.as_tensor(frames, device=z.device).expand(bsz) if not torch.is_tensor(frames) else frames
        t_max = t_pad or int(lengths.max())
        n = self.tokens(t_max)
        tok_len = (lengths + self.cfg.downsample - 1) // self.cfg.downsample
        h = self.z_in(z[:, :n]).transpose(1, 2) * _lengths_mask(tok_len, n)
        y = _run_masked(self.decoder, h, tok_len).transpose(1, 2)
        return y[:, : n * self.cfg.downsample]

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
        """The tokeniser's reconstruction loss (``conv1d.reconstruction_losses``) + kl_weight x KL
        over the clips' tokens; ``norm`` is unused (the loss is on normalised features)."""
        rec, mu, logvar = out
        cfg = self.cfg
        w = feature_weights(
            cfg.feature_dim,
            cfg.root_weight,
            cfg.position_weight,
            x.device,
            cfg.upper_detail_weight,
            cfg.foot_weight,
        )
        rec_loss, vel_loss, traj_loss = reconstruction_losses(rec[:, : x.shape[1]], x, mask, w)
        tok = logvar > _PAD_LOGVAR / 2  # the clips' own tokens
        kl = 0.5 * (mu.pow(2) + logvar.exp() - 1 - logvar)[tok].mean()
        loss = rec_loss + cfg.velocity_weight * vel_loss + cfg.trajectory_weight * traj_loss + cfg.kl_weight * kl
        parts = {
            k: float(v.detach()) for k, v in (("feat", rec_loss), ("vel", vel_loss), ("traj", traj_loss), ("kl", kl))
        }
        return loss, parts
