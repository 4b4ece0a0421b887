"""The fused inference kernel of a selective SSM (``nn/ssm_fused.py``) equals the eager
forward it replaces, and is taken only where nothing needs a gradient."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from motion_core.models.denoisers import MotionMambaConfig, motion_mamba_denoiser
from motion_core.models.ftmomamba import FTMoMambaConfig, ftmomamba_denoiser
from motion_core.nn import kernel_math as km
from motion_core.nn import numba_kernels
from motion_core.nn import ssm_fused as sf
from motion_core.nn.ssm import MambaBlock, SelectiveSSM, SSMConfig, forced_scan

pytestmark = pytest.mark.skipif(not numba_kernels.available(), reason="the fused kernel needs numba")


def _perturbed(module: torch.nn.Module, seed: int = 0) -> torch.nn.Module:
    """Trained-looking weights: the initial ones have D = 1 and zero biases everywhere."""
    g = torch.Generator().manual_seed(seed)
    with torch.no_grad():
        for p in module.parameters():
            p.add_(0.1 * torch.randn(p.shape, generator=g))
    return module


def _close(got: torch.Tensor, want: torch.Tensor, tol: float = 1e-5) -> None:
    scale = want.abs().max().item()
    assert (got - want).abs().max().item() <= tol * max(scale, 1.0), (got - want).abs().max().item()


@pytest.mark.parametrize(
    "directions,e,n,L,shift,text",
    [
        ((1, 1, 1, 1, 1), 128, 8, 52, False, False),  # an HTM block of 5 scans
        ((1, -1), 104, 4, 256, False, False),  # a BSM block: the channels are the sequence
        ((1, -1), 48, 8, 40, True, True),  # FTMoMamba's FreqSSM and TextSSM hooks
        ((-1,), 16, 4, 3, True, False),  # shorter than the conv: its taps reach before t = 0
    ],
)
def test_fused_ssm_equals_the_eager_forward_mixed_and_gated(directions, e, n, L, shift, text):
    torch.manual_seed(0)
    ssm = _perturbed(SelectiveSSM(e, directions, SSMConfig(d_state=n), 8))
    x = torch.randn(3, L, e)
    z = torch.randn(3, L, e)
    a = torch.randn(3, L, e) if shift else None
    c = torch.randn(3, n) if text else None
    mix = torch.rand(len(directions), e)
    with torch.no_grad():
        with forced_scan("sequential"):  # the reference: the scan as its definition
            want = (ssm(x, a_shift=a, c_shift=c) * mix).sum(2)
        _close(sf.fused_ssm(ssm, x, mix=mix, a_shift=a, c_shift=c), want)
        xz = torch.cat([x, z], dim=-1)  # a MambaBlock's in-projection: x, then the gate
        gated = sf.fused_ssm(ssm, xz, (0, e), mix, gate_from=e, a_shift=a, c_shift=c)
        _close(gated, want * torch.nn.functional.silu(z))


def test_the_kernels_exp_is_within_4e_7_of_float64_and_clamps():
    """exp over [-86, 88] (a million points and the ends): relative error under 4e-7 (3.0e-7
    at worst, near 88, with the degree-7 polynomial as with the degree-11 one before it:
    float32's rounding of the argument, not the polynomial); beyond, the clamp's values."""
    v = np.concatenate([np.linspace(-86, 88, 1_000_001), [-86.0, 0.0, 88.0]]).astype(np.float32)
    c = km.CONSTANTS[np.dtype(np.float32)]
    got, k32 = v.copy(), np.empty(v.size, np.int32)
    km._exp_inplace(got, k32, c)
    want = np.exp(v.astype(np.float64))
    assert np.max(np.abs(got - want) / want) < 4e-7
    ends = np.array([-1e30, -np.inf, 1e30, np.inf], np.float32)
    km._exp_inplace(ends, np.empty(4, np.int32), c)
    assert np.allclose(ends, np.exp(np.array([-86, -86, 88, 88.0])), rtol=4e-7, atol=0)


def test_the_kernels_silu_softplus_and_sigmoid_match_float64_over_the_whole_range():
    v = np.concatenate([np.linspace(-120, 120, 20001), [-1e30, -88.0, -45.0, 0.0, 45.0, 1e30]]).astype(np.float32)
    x = v.astype(np.float64)
    c = km.CONSTANTS[np.dtype(np.float32)]
    tmp, k32 = np.empty_like(v), np.empty(v.size, np.int32)
    got = v.copy()
    km._softplus_inplace(got, tmp, k32, c)
    want = np.logaddexp(0.0, x)
    assert np.all(np.abs(got - want) <= 4e-7 * np.maximum(want, 1e-30) + 1e-37)
    got = v.copy()
    km._silu_inplace(got, tmp, k32, c)
    want = x / (1.0 + np.exp(np.clip(-x, -700, 700)))
    # below -88 the clamped exp makes SiLU(x) = x exp(-88) instead of x exp(x): ~0 down to
    # x = -1e30 (6e-9 there)
    assert np.all(np.abs(got - want) <= 4e-7 * np.abs(want) + 1e-35 * np.maximum(1.0, np.abs(x)))
    got = v.copy()
    km._sigmoid_inplace(got, tmp, k32, c)
    want = 1.0 / (1.0 + np.exp(np.clip(-x, -700, 700)))
    assert np.all(np.abs(got - want) <= 4e-7 * want + 1e-37)


@pytest.mark.parametrize("directions", [(1, 1, 1), (1, -1)])
def test_a_mamba_block_takes_the_fused_path_only_without_gradients(directions, monkeypatch):
    torch.manual_seed(1)
    block = _perturbed(MambaBlock(32, directions, SSMConfig(expand=2.0, d_state=4)))
    x = torch.randn(2, 20, 32)
    calls = []
    real = sf.fused_ssm
    monkeypatch.setattr("motion_core.nn.ssm.fused_ssm", lambda *a, **k: calls.append(1) or real(*a, **k))
    with torch.no_grad():
        fused = block(x)
        assert calls, "no_grad inference should take the fused kernel"
        with forced_scan("compiled"):  # a forced scan is an explicit choice: the eager path
            eager = block(x)
    assert len(calls) == 1
    _close(fused, eager)
    y = block(x)  # with gradients: the eager path, and they reach every parameter
    assert len(calls) == 1
    y.square().sum().backward()
    assert all(p.grad is not None for p in block.parameters())
    _close(y.detach(), eager)


@pytest.mark.parametrize("name", ["A_log", "conv_weight", "D"])
def test_the_fused_path_reads_the_weights_as_they_are_now(name):
    """In-place writes of every kind (``.data``, an optimiser step, a loaded state dict)
    reach the kernel, A_log and the conv taps included (laid out afresh each call)."""
    torch.manual_seed(2)
    ssm = _perturbed(SelectiveSSM(16, (1, -1), SSMConfig(d_state=4), 2))
    x = torch.randn(1, 9, 16)
    with torch.no_grad():
        before = ssm.mixed(x)
    getattr(ssm, name).data.mul_(0.5)  # .data: no version bump
    with torch.no_grad():
        after = ssm.mixed(x)
        with forced_scan("sequential"):
            want = ssm.mixed(x)
    assert (after - before).abs().max() > 1e-3
    _close(after, want)


def test_a_model_built_in_inference_mode_samples_fused():
    with torch.inference_mode():
        torch.manual_seed(4)
        block = _perturbed(MambaBlock(16, (1, -1), SSMConfig(expand=2.0, d_state=4)))
        x = torch.randn(2, 7, 16)
        fused = block(x)
        with forced_scan("sequential"):
            _close(fused, block(x))


def test_fused_ssm_refuses_inputs_it_would_read_past():
    ssm = SelectiveSSM(8, (1, -1), SSMConfig(d_state=4), 2)
    x = torch.randn(2, 5, 8)
    with torch.no_grad():
        with pytest.raises(ValueError, match="a_shift must be"):
            sf.fused_ssm(ssm, x, a_shift=torch.randn(2, 4, 8))
        with pytest.raises(ValueError, match="c_shift must be"):
            sf.fused_ssm(ssm, x, c_shift=torch.randn(2, 3))
        with pytest.raises(ValueError, match=r"input \(and gate\) channels"):
            sf.fused_ssm(ssm, x, (0, 8), gate_from=4)


@pytest.mark.parametrize("kind", ["motion_mamba", "ftmomamba"])
def test_a_whole_denoiser_call_fused_equals_eager(kind):
    torch.manual_seed(3)
    if kind == "motion_mamba":
        cfg = MotionMambaConfig(
            latent_tokens=12, latent_dim=64, z_width=8, frames_per_token=4, levels=2,
            htm_ssm=SSMConfig(expand=0.5, d_state=8), bsm_ssm=SSMConfig(expand=2.0, d_state=4), ff=128,
        )  # fmt: skip
        den = motion_mamba_denoiser(cfg)
    else:
        cfg = FTMoMambaConfig(latent_tokens=12, latent_dim=64, z_width=8, frames_per_token=4)
        den = ftmomamba_denoiser(cfg)
    den = _perturbed(den).eval()
    z, t = torch.randn(2, 12, 8), torch.tensor([900, 10])
    text, frames = torch.randn(2, 384), torch.tensor([48, 30])
    with torch.no_grad():
        fused = den(z, t, text, frames)
        with forced_scan("compiled"):
            eager = den(z, t, text, frames)
    _close(fused, eager)


def test_scipys_blas_runs_on_the_kernels_threads():
    """In a fresh process with OpenBLAS's default thread count (no OMP_NUM_THREADS, which
    would make the test pass without the setting), one torch thread puts scipy's BLAS on one
    thread and leaves numpy's alone."""
    pytest.importorskip("threadpoolctl")
    import os
    import subprocess
    import sys

    code = (
        "import os, scipy, torch, threadpoolctl\n"
        "from motion_core.nn.ssm import SelectiveSSM, SSMConfig\n"
        "libs = os.path.realpath(os.path.dirname(scipy.__file__) + '.libs')\n"
        "info = lambda: [(os.path.realpath(i['filepath']).startswith(libs), i['num_threads'])"
        " for i in threadpoolctl.threadpool_info() if i['user_api'] == 'blas']\n"
        "torch.set_num_threads(1)\n"
        "before = info()\n"
        "with torch.no_grad():\n"
        "    SelectiveSSM(8, (1,), SSMConfig(d_state=2), 1).mixed(torch.randn(1, 5, 8))\n"
        "print(before, info())\n"
    )
    env = {k: v for k, v in os.environ.items() if not k.endswith("_NUM_THREADS")}
    env["OPENBLAS_NUM_THREADS"] = "2"  # what a 2-core machine starts with; any count above 1
    res = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=300)
    assert res.returncode == 0, res.stderr[-2000:]
    before, after = eval(res.stdout.strip().splitlines()[-1].replace("] [", "], ["))
    assert any(s and n == 2 for s, n in before), before  # scipy's BLAS started on two threads
    assert all(n == 1 for s, n in after if s) and any(s for s, _ in after), after
    assert all(n == 2 for s, n in after if not s), after  # numpy's untouched
