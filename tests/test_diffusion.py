"""DDIM sampler and noise schedule."""

from __future__ import annotations

import torch

from motion_core.nn.diffusion import Diffusion, DiffusionConfig


def test_schedule_matches_the_papers_setting():
    d = Diffusion()
    assert len(d.alphas_cumprod) == 1000
    betas = 1 - d.alphas_cumprod[1:] / d.alphas_cumprod[:-1]
    assert abs(float(1 - d.alphas_cumprod[0]) - 8.5e-4) < 1e-6
    assert abs(float(betas[-1]) - 0.012) < 1e-5
    ts = d.timesteps(50)
    assert len(ts) == 50 and ts[0] == 981 and ts[-1] == 1 and ts == sorted(ts, reverse=True)


def test_ddim_with_an_oracle_denoiser_recovers_the_target():
    """If eps_fn returns the true noise for a fixed x0, DDIM must land on x0."""
    d = Diffusion(DiffusionConfig(guidance=1.0))
    x0 = torch.randn(3, 2, 8, generator=torch.Generator().manual_seed(1))
    ac = d.alphas_cumprod

    def eps_fn(x, t, guided):
        a = ac[t].view(-1, 1, 1)
        return (x - a.sqrt() * x0) / (1 - a).sqrt()

    out = d.sample(eps_fn, tuple(x0.shape), torch.Generator().manual_seed(0), steps=50)
    assert torch.allclose(out, x0, atol=1e-3)


def test_guidance_runs_conditional_and_unconditional_in_one_batch():
    d = Diffusion()
    seen = []

    def eps_fn(x, t, guided):
        seen.append((x.shape[0], guided))
        return torch.zeros_like(x)

    d.sample(eps_fn, (1, 2, 4), torch.Generator().manual_seed(0), steps=5, guidance=7.5)
    assert seen == [(2, True)] * 5
    seen.clear()
    d.sample(eps_fn, (1, 2, 4), torch.Generator().manual_seed(0), steps=5, guidance=1.0)
    assert seen == [(1, False)] * 5


def test_every_prediction_target_round_trips_and_an_oracle_recovers_x0():
    """For epsilon, x_0 ("sample") and v targets, ``split`` inverts ``target`` at every step,
    and DDIM driven by the true target of a fixed x_0 lands on x_0."""
    g = torch.Generator().manual_seed(3)
    x0 = torch.randn(4, 2, 8, generator=g)
    noise = torch.randn(4, 2, 8, generator=g)
    t = torch.tensor([1, 250, 700, 999])
    for pred in ("epsilon", "sample", "v"):
        d = Diffusion(DiffusionConfig(prediction=pred, guidance=1.0))
        xt = d.add_noise(x0, noise, t)
        eps, x0_hat = d.split(d.target(x0, noise, t), xt, t)
        assert torch.allclose(eps, noise, atol=1e-4) and torch.allclose(x0_hat, x0, atol=1e-3), pred

        def oracle(x, tt, guided, d=d):
            a = d.alphas_cumprod[tt].view(-1, 1, 1)
            return d.target(x0, (x - a.sqrt() * x0) / (1 - a).sqrt(), tt)

        out = d.sample(oracle, tuple(x0.shape), torch.Generator().manual_seed(0), steps=20)
        assert torch.allclose(out, x0, atol=1e-3), pred


def test_an_unknown_prediction_target_is_refused():
    import pytest

    with pytest.raises(ValueError, match="prediction must be one of"):
        DiffusionConfig(prediction="score")
