"""Latent consistency models (Song et al. 2023; Luo et al.'s LCM; MotionLCM's distillation).

A consistency function maps any point x_t of the probability-flow ODE straight to its
origin x_0. It is parametrised so that it is the identity at t = 0:

    f(x_t, t) = c_skip(t) x_t + c_out(t) x0_theta(x_t, t)
    c_skip(t) = s^2 / ((k t)^2 + s^2),   c_out(t) = k t / sqrt((k t)^2 + s^2)

with s = sigma_data (0.5) and k the timestep scaling (10), as LCM. ``x0_theta`` is the
denoiser's x_0 (whatever its prediction target, through ``Diffusion.split``).

Distillation (``train/consistency.py``) pairs each t_{n+1} of a coarse DDIM grid with the
point one teacher DDIM step below it, t_n (guided teacher, guidance scale w drawn per
sample and given to the student), and pulls f_student(x_{t_{n+1}}) towards
f_target(x_{t_n}), the target being an EMA of the student; the distance is the
pseudo-Huber loss sqrt(d^2 + c^2) - c. Sampling takes 1-4 steps: x_0 = f(x_t, t), then
noise x_0 back to the next, lower t of the schedule and repeat.

A departure, ``objective="trajectory"``: a consistency student fine-tuned so that its whole
few-step sample (``consistency_unroll``, trained through) lands where the teacher's whole
guided DDIM sample lands from the same start noise, as in Luhman & Luhman's distillation of
a deterministic sampler. LCD's one-grid-step targets leave the student's 2-step samples a
few verifier points behind its 5-step teacher; this regresses on the endpoint the user sees.
The sampler and the meta's kind stay those of a consistency student; ``renoise="ddim"``
makes the sampler deterministic too (``ConsistencyConfig``). Tried on the three shipped
students (2026-11-27), it lowered the loss but did not raise their validation pass rates
beyond the prompts' noise (docs/training-log.md), so none ships trained that way.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import asdict, dataclass

import torch

from .diffusion import Diffusion, Generators, randn_rows


@dataclass
class ConsistencyConfig:
    """MotionLCM's distillation settings (``../shared/docs/paper-notes.md``) where they carry
    over; ``sample_steps`` and ``guidance`` are the student's sampling defaults."""

    sigma_data: float = 0.5
    timestep_scaling: float = 10.0
    solver_steps: int = 10  # the teacher's DDIM grid: one solver step skips train_steps / solver_steps
    guidance_min: float = 5.0  # w is drawn per sample from [guidance_min, guidance_max]
    guidance_max: float = 15.0
    huber_c: float = 0.5
    ema: float = 0.95  # the target network's EMA decay
    sample_steps: int = 2
    guidance: float = 7.5
    # "consistency": MotionLCM's loss (above); "trajectory": the student's whole few-step
    # sample regressed on the teacher's whole guided sample from the same start noise
    # (train/consistency.trajectory_loss), a fine-tune of a consistency student
    objective: str = "consistency"
    # how a multi-step sample goes from one step's x_0 to the next, lower t: "random" (LCM:
    # fresh noise) or "ddim" (the noise the step's own x_t and x_0 imply, as a DDIM step:
    # the sample is a deterministic function of its start noise, as the teacher's is)
    renoise: str = "random"

    def to_dict(self) -> dict:
        return asdict(self)


def boundary_scalings(t: torch.Tensor, cfg: ConsistencyConfig) -> tuple[torch.Tensor, torch.Tensor]:
    """(c_skip, c_out) for integer steps ``t`` (B,): c_skip(0) = 1 and c_out(0) = 0."""
    kt = t.float() * cfg.timestep_scaling
    s2 = cfg.sigma_data**2
    return s2 / (kt**2 + s2), kt / (kt**2 + s2).sqrt()


def solver_grid(diffusion: Diffusion, cfg: ConsistencyConfig) -> list[int]:
    """The teacher's DDIM steps, ascending (``Diffusion.timesteps`` of ``solver_steps``)."""
    return sorted(diffusion.timesteps(cfg.solver_steps))


def consistency_fn(
    x0_fn: Callable[[torch.Tensor, torch.Tensor], torch.Tensor],
    x: torch.Tensor,
    t: torch.Tensor,
    cfg: ConsistencyConfig,
) -> torch.Tensor:
    """f(x_t, t) from ``x0_fn(x, t)``, the network's x_0 estimate; x: (B, ...), t: (B,)."""
    c_skip, c_out = boundary_scalings(t, cfg)
    shape = (-1, *([1] * (x.dim() - 1)))
    return c_skip.view(shape) * x + c_out.view(shape) * x0_fn(x, t)


def pseudo_huber(a: torch.Tensor, b: torch.Tensor, c: float) -> torch.Tensor:
    """mean of sqrt((a - b)^2 + c^2) - c: quadratic near 0, linear far out."""
    return (torch.sqrt((a - b) ** 2 + c * c) - c).mean()


def sample_timesteps(diffusion: Diffusion, cfg: ConsistencyConfig, steps: int) -> list[int]:
    """``steps`` points of the solver grid, descending from its top, evenly spaced
    (1 step: the top alone; 2 of a 10-point grid: 901, 401)."""
    grid = solver_grid(diffusion, cfg)[::-1]
    if not 1 <= steps <= len(grid):
        raise ValueError(f"a consistency sampler takes 1 to {len(grid)} steps, not {steps}")
    return [grid[i * len(grid) // steps] for i in range(steps)]


@torch.no_grad()
def consistency_sample(
    x0_fn: Callable[[torch.Tensor, torch.Tensor], torch.Tensor],
    diffusion: Diffusion,
    cfg: ConsistencyConfig,
    shape: tuple[int, ...],
    generator: Generators,
    steps: int | None = None,
    device: torch.device | str | None = None,
) -> torch.Tensor:
    """Multi-step consistency sampling; returns x_0 of ``shape``. Every draw (the start and
    each re-noising) comes from the CPU ``generator``, so a seed gives one result; with one
    generator per row (``randn_rows``) each row draws its own, in the same order."""
    n = len(sample_timesteps(diffusion, cfg, steps or cfg.sample_steps))
    # drawn in the order the steps use them: the start, then one re-noising per later step
    draws = [randn_rows(shape, generator).to(device or "cpu") for _ in range(n)]
    return consistency_unroll(x0_fn, diffusion, cfg, draws[0], draws[1:])


def consistency_unroll(
    x0_fn: Callable[[torch.Tensor, torch.Tensor], torch.Tensor],
    diffusion: Diffusion,
    cfg: ConsistencyConfig,
    x: torch.Tensor,
    renoise: list[torch.Tensor],
) -> torch.Tensor:
    """The few-step sampler from the start noise ``x`` (B, ...) with the re-noising draws
    ``renoise`` (one per step after the first, each like x); 1 + len(renoise) steps.
    Differentiable: the trajectory objective trains through it."""
    ts = sample_timesteps(diffusion, cfg, 1 + len(renoise))
    x0 = x
    for i, t in enumerate(ts):
        tt = torch.full((x.shape[0],), t, dtype=torch.long, device=x.device)
        x0 = consistency_fn(x0_fn, x, tt, cfg)
        if i + 1 < len(ts):
            t_next = torch.full_like(tt, ts[i + 1])
            if cfg.renoise == "ddim":
                a, a_next = diffusion.alpha_before(tt, x), diffusion.alpha_before(t_next, x)
                eps = (x - a.sqrt() * x0) / (1 - a).sqrt()
                x = a_next.sqrt() * x0 + (1 - a_next).sqrt() * eps
            elif cfg.renoise == "random":
                x = diffusion.add_noise(x0, renoise[i], t_next)
            else:
                raise ValueError(f"unknown renoise {cfg.renoise!r}: random or ddim")
    return x0
