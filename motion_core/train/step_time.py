"""Seconds per training step of the latent denoisers (``python -m motion_core.train step-time``).

One step as ``train.denoiser`` takes it: the shipped config of each kind, a batch of random
latents of the given shape, forward, MSE, backward, gradient clipping, AdamW. The kinds are
timed in turns (round robin), so that a machine whose load changes during the run slows
all of them alike: compare the figures of one run, as ratios.

On a GPU (``device="cuda"``) each step ends with a synchronise, and ``profile`` prints
where one step's time goes (torch.profiler: the ops by their own CPU and GPU time): a lent
GPU's minutes are few, so this is what says how to spend the next ones.
"""

from __future__ import annotations

import contextlib
import dataclasses
import statistics
import time

import torch

from ..models.latent_denoisers import build_denoiser, default_config
from ..nn.ssm import eager_scans, forced_scan

# "compiled": the dispatcher's choice (the compiled scan on a CPU, the chunked one on a GPU);
# "eager": the dispatcher without the compiled scan; "chunked" / "sequential": that scan forced
SCAN_ARMS = ("compiled", "eager", "chunked", "sequential")


def _scans(arm: str):
    if arm == "eager":
        return eager_scans()
    if arm in ("chunked", "sequential"):
        return forced_scan(arm)
    return contextlib.nullcontext()


def _step_fn(kind: str, batch: int, tokens: int, z_width: int, frames_per_token: int, device: str = "cpu"):
    torch.manual_seed(0)
    cfg = default_config(kind)
    cfg = dataclasses.replace(
        cfg,
        latent_tokens=tokens,
        z_width=z_width if z_width != cfg.latent_dim else 0,
        frames_per_token=frames_per_token,
    )
    model = build_denoiser(kind, cfg).to(device)
    opt = torch.optim.AdamW(model.parameters(), lr=1e-4)
    z = torch.randn(batch, tokens, z_width, device=device)
    t = torch.randint(0, 1000, (batch,), device=device)
    text = torch.randn(batch, 384, device=device)
    frames = torch.randint(40, 200, (batch,), device=device)

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
    device: str = "cpu",
    profile: bool = False,
) -> list[dict]:
    """Median seconds per step for each (kind, batch, scan): one warm-up step, then
    ``repeats`` rounds in which every arm takes one step. ``scans``: any of ``SCAN_ARMS``.
    With ``profile``, each arm's last step is also profiled and its tables printed."""
    arms = {
        (k, b, s): _step_fn(k, b, tokens, z_width, frames_per_token, device)
        for k in kinds
        for b in batches
        for s in scans
    }
    sync = torch.cuda.synchronize if device.startswith("cuda") else (lambda: None)

    def run(arm, fn) -> float:
        sync()
        t0 = time.perf_counter()
        with _scans(arm[2]):
            fn()
        sync()
        return time.perf_counter() - t0

    for arm, fn in arms.items():
        run(arm, fn)
    times: dict[tuple[str, int, str], list[float]] = {a: [] for a in arms}
    for _ in range(repeats):
        for arm, fn in arms.items():
            times[arm].append(run(arm, fn))
    if profile:
        for arm, fn in arms.items():
            _profile(arm, fn, device)
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


def _profile(arm: tuple, fn, device: str) -> None:
    from torch.profiler import ProfilerActivity
    from torch.profiler import profile as torch_profile

    acts = [ProfilerActivity.CPU] + ([ProfilerActivity.CUDA] if device.startswith("cuda") else [])
    with torch_profile(activities=acts) as prof, _scans(arm[2]):
        fn()
        if device.startswith("cuda"):
            torch.cuda.synchronize()
    ka = prof.key_averages()
    print(f"== {arm}: by own CPU time")
    print(ka.table(sort_by="self_cpu_time_total", row_limit=12, max_name_column_width=48))
    if device.startswith("cuda"):
        print(f"== {arm}: by own GPU time")
        print(ka.table(sort_by="self_cuda_time_total", row_limit=12, max_name_column_width=48))
