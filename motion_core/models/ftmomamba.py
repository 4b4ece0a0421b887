"""FTMoMamba's denoiser (Li et al. 2024): FreqMamba and TextMamba blocks in a U-Net-like stack.

It plugs into the same latent diffusion as Motion Mamba (``LatentDenoiser`` shell: the
[time+length, text] prefix tokens, the shared VAE, scheduler and sampler); only the body
differs. Per FTMamba block, on x: (B, L, d) (L = 2 prefix + n_z latent tokens):

    FreqMamba (Eq. 5-7)   f_lin = Linear(x);  f_freq = FS(sigmoid(CDWConv(f_lin)));
                          f_n = Linear(f_freq * sigmoid(f_lin))
    FreqSSM   (Eq. 8-11)  (f_low, f_high) = Conv(DWT(x));  A_n = A + alpha f_low + beta f_high;
                          output = C h + IDWT(f_low, f_high)
    TextMamba (Eq. 15-17) f_u = x + f_n;  same shape with TextSSM, C_s = f_text + C
    FTMamba   (Eq. 18)    z' = f_n + f_v

CDWConv: depthwise convolutions, kernel 3, dilations 1, 2, 4, one after another. FreqSSM
and TextSSM are bidirectional (forward + time-reversed scan, summed), as the paper's
experiments use. Stacked as the paper's "2 layers in the encoder, middle and decoder"
with MLD's concat + Linear skip fusion.

Departures, and why:
- A_n varies per step: the bands (length L/2) are repeated to length L so each step t
  gets A + alpha f_low[t//2] + beta f_high[t//2] (per channel, broadcast over the state
  size). The paper does not say how an (L/2, E) band enters the (E, N) matrix A; a per-step
  matrix keeps the bands' local trend, which is what the paper motivates them with.
- Stability: A_n is passed through ``ssm.stable_state_matrix`` (-(softplus(-(.)) + 1e-4)),
  so its real part is < 0 for any input; a raw sum can turn positive and blow the state up.
- The SSMs' own causal convolution is 1 tap wide (a per-channel scale): CDWConv in front
  of them is the block's temporal convolution, as in the paper's figure.
- Each block is wrapped as x + z' with a pre-LayerNorm: Eq. 18 has no outer residual, but
  a six-block stack without one trained poorly on our budget.
- Our latent is 2 tokens (+2 prefix tokens), the paper's 16: the DWT runs over 4 tokens.
- ``cond`` "broadcast" (the shipped setting since the temporal latent): each block adds a
  projection of its two prefix tokens (time+length, text) to every token of its normalised
  input. The paper builds f_m^mo "from the noisy feature z_t and the time step t" with the
  convolution of its reference [16], where the step embedding is added at every position;
  with the conditioning only in front, as MLD's prefix, it reached the first few of 50
  temporal tokens: at high noise the stage-2 checkpoint's x_0 error was 0.015 on the token
  next to the prefix and 0.17-0.43 from the fifth on (Motion Mamba's, whose attention mixer
  reaches every token: 0.04-0.06). The projection starts at zero, so a "prefix" checkpoint
  goes on from the same function. "prefix" keeps the earlier behaviour (and loads the
  checkpoints trained with it).

Ablation switches (paper Tables 2-4): ``freq`` "on" | "off" (off: plain bidirectional
Mamba in FreqMamba's place), ``text`` "on" | "off" (off: linear attention in TextMamba's
place), ``transform`` "dwt" | "fft", ``bands`` "both" | "low" | "high".
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import torch
import torch.nn.functional as F
from torch import nn

from ..nn import cdw_compiled
from ..nn.dilated_conv import DilatedConv1d
from ..nn.ssm import MambaBlock, SelectiveSSM, SSMConfig
from .denoisers import LatentDenoiser, shell

SQRT2 = math.sqrt(2.0)


def haar_dwt(x: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
    """One-level orthonormal Haar DWT over time: x (B, L, C), L even -> (low, high), each (B, L/2, C)."""
    if x.shape[1] % 2:
        raise ValueError(f"the Haar DWT needs an even length, got {x.shape[1]}")
    a, b = x[:, 0::2], x[:, 1::2]
    return (a + b) / SQRT2, (a - b) / SQRT2


def haar_idwt(low: torch.Tensor, high: torch.Tensor) -> torch.Tensor:
    """Inverse of ``haar_dwt``: (B, L/2, C) x 2 -> (B, L, C)."""
    a, b = (low + high) / SQRT2, (low - high) / SQRT2
    return torch.stack([a, b], dim=2).flatten(1, 2)


def fft_bands(x: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
    """FFT ablation: the lower and upper halves of the real spectrum, each back in time
    (B, L, C); low + high = x."""
    spec = torch.fft.rfft(x, dim=1)
    cut = spec.shape[1] // 2 + 1
    low = torch.fft.irfft(torch.cat([spec[:, :cut], torch.zeros_like(spec[:, cut:])], 1), n=x.shape[1], dim=1)
    return low, x - low


@dataclass
class FTMoMambaConfig:
    latent_tokens: int = 2
    latent_dim: int = 256
    z_width: int = 0  # see denoisers.LatentDenoiser
    frames_per_token: int = 0
    text_dim: int = 384
    layers_per_stage: int = 2  # encoder, middle and decoder stages each
    ssm: SSMConfig = None  # type: ignore[assignment]
    freq: str = "on"
    text: str = "on"
    transform: str = "dwt"
    bands: str = "both"
    cond: str = "prefix"  # "broadcast": every token also gets the prefix tokens (module docstring)

    def __post_init__(self) -> None:
        if self.ssm is None:
            self.ssm = SSMConfig(expand=1.0, d_state=8, d_conv=1)
        elif isinstance(self.ssm, dict):
            self.ssm = SSMConfig(**self.ssm)
        for name, allowed in (
            ("freq", ("on", "off")),
            ("text", ("on", "off")),
            ("transform", ("dwt", "fft")),
            ("bands", ("both", "low", "high")),
            ("cond", ("prefix", "broadcast")),
        ):
            if getattr(self, name) not in allowed:
                raise ValueError(f"{name} must be one of {allowed}, got {getattr(self, name)!r}")

    def to_dict(self) -> dict:
        return asdict(self)


class CDWConv(nn.Module):
    """Cascaded depthwise Conv1D, kernel 3, dilations 1, 2, 4 ('same' padding): (B, L, C) -> (B, L, C)."""

    def __init__(self, c: int) -> None:
        super().__init__()
        self.convs = nn.ModuleList(DilatedConv1d(c, c, 3, padding=d, dilation=d, groups=c) for d in (1, 2, 4))

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        if cdw_compiled.applies(self.convs, x):
            # the CPU's sampling path: the three convolutions in one compiled call
            return cdw_compiled.cdw_cascade(self.convs, x)
        y = x.transpose(1, 2)
        for conv in self.convs:
            y = conv(y)
        return y.transpose(1, 2)


class FreqSSM(nn.Module):
    """Bidirectional selective scan whose state matrix carries the input's frequency bands.

    x: (B, L, E) scan input, f: (B, L, d) the block input the bands are taken from
    (Eq. 8: DWT of f_m^mo) -> (B, L, E).
    """

    def __init__(self, d: int, e: int, cfg: SSMConfig, dt_rank: int, transform: str, bands: str) -> None:
        super().__init__()
        self.ssm = SelectiveSSM(e, (1, -1), cfg, dt_rank)
        self.transform, self.bands = transform, bands
        # Eq. 8's "Conv": maps each band from d to E channels and enhances it locally
        self.conv_low = nn.Conv1d(d, e, 3, padding=1)
        self.conv_high = nn.Conv1d(d, e, 3, padding=1)
        self.alpha = nn.Parameter(torch.full((e,), 0.1))
        self.beta = nn.Parameter(torch.full((e,), 0.1))

    def _bands(self, f: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor, int]:
        L = f.shape[1]
        if self.transform == "fft":
            low, high = fft_bands(f)
            return low, high, 1
        if L % 2:
            f = torch.cat([f, f[:, -1:]], dim=1)
        low, high = haar_dwt(f)
        return low, high, 2

    def forward(self, x: torch.Tensor, f: torch.Tensor) -> torch.Tensor:
        L = x.shape[1]
        low, high, rep = self._bands(f)
        low = self.conv_low(low.transpose(1, 2)).transpose(1, 2)
        high = self.conv_high(high.transpose(1, 2)).transpose(1, 2)
        if self.bands == "low":
            high = torch.zeros_like(high)
        elif self.bands == "high":
            low = torch.zeros_like(low)
        shift = self.alpha * low + self.beta * high  # (B, L/rep, E)
        shift = shift.repeat_interleave(rep, dim=1)[:, :L]
        y = self.ssm.mixed(x, a_shift=shift)  # forward + backward, summed
        back = haar_idwt(low, high) if self.transform == "dwt" else low + high
        return y + back[:, :L]


class TextSSM(nn.Module):
    """Bidirectional selective scan with C_s = f_text + C (Eq. 15-17).
    x: (B, L, E), text: (B, text_dim) -> (B, L, E)."""

    def __init__(self, e: int, text_dim: int, cfg: SSMConfig, dt_rank: int) -> None:
        super().__init__()
        self.ssm = SelectiveSSM(e, (1, -1), cfg, dt_rank)
        self.text = nn.Linear(text_dim, cfg.d_state)

    def forward(self, x: torch.Tensor, text: torch.Tensor) -> torch.Tensor:
        return self.ssm.mixed(x, c_shift=self.text(text))


class GatedBranch(nn.Module):
    """The shape FreqMamba and TextMamba share: Linear -> CDWConv -> sigmoid -> core,
    gated by sigmoid(Linear branch) -> Linear. (B, L, d) -> (B, L, d)."""

    def __init__(self, d: int, e: int) -> None:
        super().__init__()
        self.lin = nn.Linear(d, e)
        self.cdw = CDWConv(e)
        self.out = nn.Linear(e, d)

    def run(self, x: torch.Tensor, core) -> torch.Tensor:
        f_lin = self.lin(x)
        return self.out(core(torch.sigmoid(self.cdw(f_lin))) * torch.sigmoid(f_lin))


class LinearAttention(nn.Module):
    """TextMamba-off ablation: non-causal linear attention (phi = elu + 1) over the tokens,
    with the text as one more key/value. (B, L, d), (B, text_dim) -> (B, L, d)."""

    def __init__(self, d: int, text_dim: int) -> None:
        super().__init__()
        self.q, self.k, self.v = nn.Linear(d, d), nn.Linear(d, d), nn.Linear(d, d)
        self.text = nn.Linear(text_dim, d)
        self.out = nn.Linear(d, d)

    def forward(self, x: torch.Tensor, text: torch.Tensor) -> torch.Tensor:
        kv_in = torch.cat([x, self.text(text)[:, None]], dim=1)
        q = F.elu(self.q(x)) + 1
        k = F.elu(self.k(kv_in)) + 1
        v = self.v(kv_in)
        kv = torch.einsum("bld,ble->bde", k, v)
        norm = torch.einsum("bld,bd->bl", q, k.sum(1))[..., None]
        return self.out(torch.einsum("bld,bde->ble", q, kv) / norm)


class FTMambaBlock(nn.Module):
    """FreqMamba -> TextMamba -> z' = f_n + f_v, as x + z' (see the module docstring)."""

    def __init__(self, cfg: FTMoMambaConfig) -> None:
        super().__init__()
        d = cfg.latent_dim
        e = max(1, round(cfg.ssm.expand * d))
        dt_rank = cfg.ssm.dt_rank or math.ceil(d / 16)
        self.norm = nn.LayerNorm(d)
        self.cfg = cfg
        self.cond = None
        if cfg.cond == "broadcast":
            # zero at the start: a checkpoint trained without it computes the same function
            self.cond = nn.Linear(2 * d, d)
            nn.init.zeros_(self.cond.weight)
            nn.init.zeros_(self.cond.bias)
        if cfg.freq == "on":
            self.freq_branch = GatedBranch(d, e)
            self.freq_ssm = FreqSSM(d, e, cfg.ssm, dt_rank, cfg.transform, cfg.bands)
        else:
            self.bimamba = MambaBlock(d, (1, -1), cfg.ssm)
        if cfg.text == "on":
            self.text_branch = GatedBranch(d, e)
            self.text_ssm = TextSSM(e, cfg.text_dim, cfg.ssm, dt_rank)
        else:
            self.lin_attn = LinearAttention(d, cfg.text_dim)

    def forward(self, x: torch.Tensor, text: torch.Tensor) -> torch.Tensor:
        z = self.norm(x)
        if self.cond is not None:  # the prefix tokens (B, 2, d) reach every token
            z = z + self.cond(z[:, :2].flatten(1))[:, None]
        if self.cfg.freq == "on":
            f_n = self.freq_branch.run(z, lambda u: self.freq_ssm(u, z))
        else:
            f_n = self.bimamba(z)
        f_u = z + f_n
        if self.cfg.text == "on":
            f_v = self.text_branch.run(f_u, lambda u: self.text_ssm(u, text))
        else:
            f_v = self.lin_attn(f_u, text)
        return x + f_n + f_v


class FTMoMambaBody(nn.Module):
    """Encoder, middle and decoder stages of ``layers_per_stage`` blocks; each decoder block
    fuses the mirrored encoder block's output (concat, Linear 2d -> d, as MLD's skips).
    ``wants_text`` tells the ``LatentDenoiser`` shell to pass the sentence embedding
    (B, text_dim) along; it is an argument, never module state, so concurrent requests
    cannot see each other's text."""

    wants_text = True

    def __init__(self, cfg: FTMoMambaConfig) -> None:
        super().__init__()
        n = cfg.layers_per_stage
        self.enc = nn.ModuleList(FTMambaBlock(cfg) for _ in range(n))
        self.mid = nn.ModuleList(FTMambaBlock(cfg) for _ in range(n))
        self.dec = nn.ModuleList(FTMambaBlock(cfg) for _ in range(n))
        self.fuse = nn.ModuleList(nn.Linear(2 * cfg.latent_dim, cfg.latent_dim) for _ in range(n))

    def forward(self, x: torch.Tensor, text: torch.Tensor) -> torch.Tensor:
        skips = []
        for blk in self.enc:
            x = blk(x, text)
            skips.append(x)
        for blk in self.mid:
            x = blk(x, text)
        for blk, fuse in zip(self.dec, self.fuse, strict=True):
            x = blk(fuse(torch.cat([x, skips.pop()], dim=-1)), text)
        return x


def ftmomamba_denoiser(cfg: FTMoMambaConfig) -> LatentDenoiser:
    return shell(FTMoMambaBody(cfg), cfg)
