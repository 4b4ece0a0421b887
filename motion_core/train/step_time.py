"""Seconds per training step of the latent denoisers (``python -m motion_core.train step-time``).

One step as ``train.denoiser`` takes it: the shipped config of each kind, a batch of random
latents of the given shape, forward, MSE, backward, gradient clipping, AdamW. The kinds are
timed in turns (round robin), so that a machine whose load changes during the run slows
all of them alike: compare the figures of one run, as ratios.
"""

from __future__ import annotations

import contextlib
import dataclasses
import statistics
import time

import torch

from ..models.latent_denoisers import build_denoiser, default_config
from ..nn.ssm import eager_scans


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
    kinds: list[str],
    batches: list[int],
    tokens: int,
    z_width: int,
    frames_per_token: int = 0,
    repeats: int = 5,
    scans: tuple[str, ...] = ("compiled",),
) -> list[dict]:
    """Median seconds per step for each (kind, batch, scan): one warm-up step, then
    ``repeats`` rounds in which every arm takes one step. ``scans``: "compiled" (the
    dispatcher's default on the CPU) and / or "eager" (``ssm.eager_scans``, as before it)."""
    arms = {(k, b, s): _step_fn(k, b, tokens, z_width, frames_per_token) for k in kinds for b in batches for s in scans}

    def run(arm, fn) -> float:
        t0 = time.perf_counter()
        with eager_scans() if arm[2] == "eager" else contextlib.nullcontext():
            fn()
        return time.perf_counter() - t0

    for arm, fn in arms.items():
        run(arm, fn)
    times: dict[tuple[str, int, str], list[float]] = {a: [] for a in arms}
    for _ in range(repeats):
        for arm, fn in arms.items():
            times[arm].append(run(arm, fn))
    return [
        {
            "kind": k,
            "batch": b,
            "scan": s,
            "tokens": tokens,
            "z_width": z_width,
            "s_per_step": statistics.median(times[(k, b, s)]),
        }
        for (k, b, s) in arms
    ]
