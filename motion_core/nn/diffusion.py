"""Latent diffusion shared by Motion Mamba, FTMoMamba and the transformer baseline.

DDPM training over ``train_steps`` = 1000 steps, betas linear
from 8.5e-4 to 0.012 (the papers' MLD setting; MLD's code squares a linear ramp of their
square roots, "scaled_linear", available as an option), DDIM sampling (eta = 0) with 50
steps by default and classifier-free guidance:

    eps = eps_uncond + w * (eps_cond - eps_uncond)

The conditional and unconditional passes run as one batch of 2B.

``prediction`` names what the network is trained to output: "epsilon" (MLD, the papers'
setting), "sample" (x_0 itself, as MDM) or "v" (sqrt(a) eps - sqrt(1 - a) x_0, Salimans &
Ho). The sampler turns any of them into (eps, x_0) for the DDIM update, and guidance
mixes the raw outputs, which is the same as mixing eps since the conversions are affine in
the output. Why the choice matters here: the epsilon loss weighs an error in x_0 by
a / (1 - a), about 0.005 at the noisiest steps, where a motion's content (and so its text)
is decided; our denoisers trained on it learned to ignore the text (docs/training-log.md).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass

import torch

PREDICTIONS = ("epsilon", "sample", "v")


Generators = torch.Generator | Sequence[torch.Generator]


def randn_rows(shape: tuple[int, ...], generator: Generators) -> torch.Tensor:
    """Standard normal noise of ``shape`` (B, ...) on the CPU. One generator draws the whole
    tensor; a sequence of B generators draws row b from generator b alone, so a row gets the
    same numbers batched as it would sampled by itself with its generator (a timeline's
    segments are sampled as one batch, each with its own seed's stream)."""
    if isinstance(generator, torch.Generator):
        return torch.randn(shape, generator=generator)
    if len(generator) != shape[0]:
        raise ValueError(f"{len(generator)} generators for a batch of {shape[0]}")
    return torch.cat([torch.randn((1, *shape[1:]), generator=g) for g in generator])


@dataclass
class DiffusionConfig:
    train_steps: int = 1000
    beta_start: float = 8.5e-4
    beta_end: float = 0.012
    schedule: str = "linear"  # or "scaled_linear" (MLD's code)
    sample_steps: int = 50
    guidance: float = 7.5
    cond_drop: float = 0.1  # probability of training on the empty text (classifier-free guidance)
    prediction: str = "epsilon"  # "epsilon" | "sample" | "v": the network's training target

    def __post_init__(self) -> None:
        if self.prediction not in PREDICTIONS:
            raise ValueError(f"prediction must be one of {PREDICTIONS}, got {self.prediction!r}")

    def to_dict(self) -> dict:
        return asdict(self)


class Diffusion:
    def __init__(self, cfg: DiffusionConfig | None = None) -> None:
        self.cfg = cfg = cfg or DiffusionConfig()
        if cfg.schedule == "linear":
            betas = torch.linspace(cfg.beta_start, cfg.beta_end, cfg.train_steps, dtype=torch.float64)
        elif cfg.schedule == "scaled_linear":
            betas = torch.linspace(cfg.beta_start**0.5, cfg.beta_end**0.5, cfg.train_steps, dtype=torch.float64) ** 2
        else:
            raise ValueError(f"unknown beta schedule {cfg.schedule!r}")
        self.alphas_cumprod = torch.cumprod(1.0 - betas, dim=0).float()

    def add_noise(self, x0: torch.Tensor, noise: torch.Tensor, t: torch.Tensor) -> torch.Tensor:
        """q(x_t | x_0); x0, noise: (B, ...), t: (B,) integer steps."""
        a = self.alphas_cumprod.to(x0.device)[t].view(-1, *([1] * (x0.dim() - 1)))
        return a.sqrt() * x0 + (1 - a).sqrt() * noise

    def _alpha(self, t: torch.Tensor, like: torch.Tensor) -> torch.Tensor:
        return self.alphas_cumprod.to(like.device)[t].view(-1, *([1] * (like.dim() - 1)))

    def target(self, x0: torch.Tensor, noise: torch.Tensor, t: torch.Tensor) -> torch.Tensor:
        """The training target of ``cfg.prediction`` for x_t = add_noise(x0, noise, t)."""
        if self.cfg.prediction == "epsilon":
            return noise
        if self.cfg.prediction == "sample":
            return x0
        a = self._alpha(t, x0)
        return a.sqrt() * noise - (1 - a).sqrt() * x0

    def split(self, out: torch.Tensor, x: torch.Tensor, t: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        """(eps, x_0) from a network output ``out`` at x_t = ``x``, steps ``t`` (B,)."""
        a = self._alpha(t, x)
        if self.cfg.prediction == "epsilon":
            return out, (x - (1 - a).sqrt() * out) / a.sqrt()
        if self.cfg.prediction == "sample":
            return (x - a.sqrt() * out) / (1 - a).sqrt(), out
        x0 = a.sqrt() * x - (1 - a).sqrt() * out
        return a.sqrt() * out + (1 - a).sqrt() * x, x0

    def alpha_before(self, t_prev: torch.Tensor, like: torch.Tensor) -> torch.Tensor:
        """alpha-bar of the step a DDIM update lands on, shaped to broadcast over ``like``;
        t_prev <= 0 is the clean data (alpha 1), where the last step of a sampler lands."""
        ac = self.alphas_cumprod.to(t_prev.device)[t_prev.clamp(min=0)]
        a = torch.where(t_prev > 0, ac, torch.ones_like(ac))
        return a.to(like.device).view(-1, *([1] * (like.dim() - 1)))

    @staticmethod
    def guide(out_cond: torch.Tensor, out_uncond: torch.Tensor, w: float | torch.Tensor) -> torch.Tensor:
        """Classifier-free guidance on raw outputs; ``w`` a scale or (B,) scales."""
        if isinstance(w, torch.Tensor):
            w = w.view(-1, *([1] * (out_cond.dim() - 1)))
        return out_uncond + w * (out_cond - out_uncond)

    def ddim_step(self, out: torch.Tensor, x: torch.Tensor, t: torch.Tensor, t_prev: torch.Tensor) -> torch.Tensor:
        """One DDIM (eta 0) update from x_t to x_{t_prev} with the network output ``out``;
        t, t_prev: (B,) steps (t_prev <= 0: to the clean data, i.e. the x_0 estimate)."""
        eps, x0 = self.split(out, x, t)
        a_prev = self.alpha_before(t_prev, x)
        return a_prev.sqrt() * x0 + (1 - a_prev).sqrt() * eps

    def timesteps(self, steps: int) -> list[int]:
        """DDIM's evenly spaced steps, 'leading' spacing with offset 1 (as MLD), descending."""
        stride = self.cfg.train_steps // steps
        return [i * stride + 1 for i in range(steps)][::-1]

    @torch.no_grad()
    def sample(
        self,
        eps_fn: Callable[[torch.Tensor, torch.Tensor, bool], torch.Tensor],
        shape: tuple[int, ...],
        generator: Generators,
        steps: int | None = None,
        guidance: float | None = None,
        x_init: torch.Tensor | None = None,
        device: torch.device | str | None = None,
    ) -> torch.Tensor:
        """DDIM (eta 0) with classifier-free guidance.

        eps_fn(x (B, ...), t (B,), guided) returns the network's output (epsilon, x_0 or v
        as ``cfg.prediction`` says); when ``guided`` it receives the batch twice ([cond;
        uncond]) and returns both halves stacked. Returns x_0 (shape).
        The noise is drawn on the CPU ``generator`` (or one generator per row, see
        ``randn_rows``) and moved to ``device`` (default: the CPU, or x_init's device), so a
        seed gives the same start on every device.
        """
        steps = steps or self.cfg.sample_steps
        w = self.cfg.guidance if guidance is None else guidance
        x = randn_rows(shape, generator).to(device or "cpu") if x_init is None else x_init
        ts = self.timesteps(steps)
        for i, t in enumerate(ts):
            tt = torch.full((shape[0],), t, dtype=torch.long, device=x.device)
            if w != 1.0:
                o_c, o_u = eps_fn(torch.cat([x, x]), torch.cat([tt, tt]), True).chunk(2)
                out = self.guide(o_c, o_u, w)
            else:
                out = eps_fn(x, tt, False)
            # the last step goes to alpha = 1, i.e. returns the x_0 prediction itself
            x = self.ddim_step(out, x, tt, torch.full_like(tt, ts[i + 1] if i + 1 < len(ts) else 0))
        return x
