"""Latent denoisers on a temporal latent (one token per 4 frames, zero-padded)."""

from __future__ import annotations

import dataclasses

import pytest
import torch

from motion_core.models.latent_denoisers import build_denoiser, default_config


@pytest.mark.parametrize("kind", ["motion_mamba", "ftmomamba", "baseline"])
def test_a_temporal_latent_denoiser_predicts_zero_past_the_clip(kind: str) -> None:
    torch.manual_seed(0)
    cfg = dataclasses.replace(default_config(kind), latent_tokens=56, z_width=8, frames_per_token=4)
    den = build_denoiser(kind, cfg).eval()
    z = torch.randn(2, 56, 8)
    frames = torch.tensor([90, 200])  # 23 and 50 tokens
    with torch.no_grad():
        out = den(z, torch.tensor([10, 500]), torch.randn(2, 384), frames)
    assert out.shape == (2, 56, 8)
    assert out[0, 23:].abs().max() == 0 and out[1, 50:].abs().max() == 0
    assert out[0, :23].abs().min() > 0 and out[1, :50].abs().mean() > 0


def test_step_time_times_every_arm() -> None:
    from motion_core.train.step_time import step_seconds

    rows = step_seconds(
        ["motion_mamba"], [2], tokens=8, z_width=4, frames_per_token=4, repeats=1, scans=("compiled", "eager")
    )
    assert [(r["scan"], r["batch"]) for r in rows] == [("compiled", 2), ("eager", 2)]
    assert all(r["s_per_step"] > 0 for r in rows)


def test_a_timeline_on_a_temporal_latent_joins_a_10_s_segment_without_overlap_frames() -> None:
    """A temporal VAE's latent decodes to at most its tokens' frames (200 at max_frames 200):
    a 10 s segment followed by another gets no overlap frames and is joined without a blend,
    the timeline keeps its length and stays finite."""
    import numpy as np

    from motion_core.body.features import Normalizer
    from motion_core.inference.base import MethodInfo
    from motion_core.inference.latent_diffusion import LatentDiffusionMethod
    from motion_core.models.conv_vae import ConvMotionVAE, ConvVAEConfig
    from motion_core.nn.diffusion import Diffusion, DiffusionConfig

    torch.manual_seed(0)
    vae = ConvMotionVAE(ConvVAEConfig(z_width=8, max_frames=200)).eval()
    assert vae.longest == 200
    cfg = dataclasses.replace(default_config("baseline"), latent_tokens=50, z_width=8, frames_per_token=4)
    info = MethodInfo("t", "t", "t", "x.pt", LatentDiffusionMethod)
    norm = Normalizer(np.zeros(263, np.float32), np.ones(263, np.float32))
    method = LatentDiffusionMethod(
        info,
        vae,
        build_denoiser("baseline", cfg).eval(),
        Diffusion(DiffusionConfig(prediction="sample")),
        norm,
        1.0,
        0.0,
    )
    timings: dict[str, float] = {}
    motion = method.sample(
        [("a person walks", 200), ("a person sits", 40)],
        0,
        steps=2,
        guidance=2.0,
        timings=timings,
        device=torch.device("cpu"),
    )
    assert motion.joints.shape == (240, 22, 3) and np.isfinite(motion.joints).all()
