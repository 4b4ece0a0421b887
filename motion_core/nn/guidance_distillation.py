"""Guidance distillation (Meng et al. 2023, "On Distillation of Guided Diffusion Models",
stage one): a student that reads the guidance scale w learns, in one pass, the teacher's
guided output o_u + w (o_c - o_u), which took the teacher two (the conditional and the
unconditional pass). Sampled with the teacher's own DDIM steps, it halves the network work
of a step without changing the sampler; Meng et al.'s stage two (progressive distillation
of the steps) or a consistency model (``nn/consistency.py``) can start from it.

Training (``train/guidance_distillation.py``): a training clip's latent z_0 and caption, a
step t ~ U{0..T-1}, w ~ U[guidance_min, guidance_max], x_t = add_noise(z_0, noise, t);
loss = || student(x_t, t, c, w) - guide(teacher(x_t, t, c), teacher(x_t, t, empty), w) ||^2
in the teacher's prediction target (x_0 for the shipped denoisers), optionally over w^2
(``loss_weight``).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass


@dataclass
class GuidanceDistillConfig:
    """``guidance_*``: the scales w is drawn from in training (the quality sampler's slider
    range, so the fast sampler keeps it); ``guidance`` and ``sample_steps``: its sampling
    defaults (the teacher's); ``max_steps``: the most DDIM steps it accepts."""

    guidance_min: float = 1.0
    guidance_max: float = 15.0
    # "uniform": plain MSE; "inverse_w2": each sample's MSE over w^2. The guided x_0 target
    # moves w times as far as the teacher's outputs differ, so plain MSE is mostly the largest
    # scales' error (the 600-step pilot's loss of 3.2 against the teacher's 0.03)
    loss_weight: str = "uniform"
    guidance: float = 7.5
    sample_steps: int = 10
    max_steps: int = 100

    def to_dict(self) -> dict:
        return asdict(self)
