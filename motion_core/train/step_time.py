"""Seconds per training step of the latent denoisers (``python -m motion_core.train step-time``).

One step as ``train.denoiser`` takes it: the shipped config of each kind, a batch of random
latents of the given shape, forward, MSE, backward, gradient clipping, AdamW. The kinds are
timed in turns (round robin), so that a machine whose load changes during the run slows
all of them alike: compare the figures of one run, as ratios.
"""

from __future__ import annotations

import dataclasses
import statistics
import time

import torch

from ..models.latent_denoisers import build_denoiser, default_config


def _step_fn(kind: str, batch: int, tokens: int, z_width: int, frames_per_token: int):
    torch.manual_seed(0)
    cfg = default_config(kind)
    cfg = dataclasses.replace(
        cfg,
        latent_tokens=tokens,
        z_width=z_width if z_width != cfg.latent_dim else 0,
        frames_per_token=frames_per_token,
    )
    model = build_denoiser(kind, cfg)
    opt = torch.optim.AdamW(model.parameters(), lr=1e-4)
    z = torch.randn(batch, tokens, z_width)
    t = torch.randint(0, 1000, (batch,))
    text = torch.randn(batch, 384)
    frames = torch.randint(40, 200, (batch,))

    def step() -> None:
        loss = torch.nn.functional.mse_loss(model(z, t, text, frames), z)
        opt.zero_grad(set_to_none=True)
        loss.backward()
        torch.nn.utils.clip_grad_norm_(model.parameters(), 1.0)
        opt.step()

    return step


def step_seconds(
    kinds: list[str], batches: list[int], tokens: int, z_width: int, frames_per_token: int = 0, repeats: int = 5
) -> list[dict]:
    """Median seconds per step for each (kind, batch): one warm-up step, then ``repeats``
    rounds in which every arm takes one step."""
    arms = {(k, b): _step_fn(k, b, tokens, z_width, frames_per_token) for k in kinds for b in batches}
    for fn in arms.values():
        fn()
    times: dict[tuple[str, int], list[float]] = {a: [] for a in arms}
    for _ in range(repeats):
        for a, fn in arms.items():
            t0 = time.perf_counter()
            fn()
            times[a].append(time.perf_counter() - t0)
    return [
        {"kind": k, "batch": b, "tokens": tokens, "z_width": z_width, "s_per_step": statistics.median(times[(k, b)])}
        for (k, b) in arms
    ]
