"""The compiled depthwise causal convolution equals its definition (``nn/causal_conv.py``)."""

from __future__ import annotations

import pytest
import torch

from motion_core.nn import causal_conv as cc
from motion_core.nn.ssm import SelectiveSSM, SSMConfig


def _args(bsz, L, C, K, dtype, seed=0):
    gen = torch.Generator().manual_seed(seed)
    x = torch.randn(bsz, L, C, generator=gen, dtype=dtype)
    w = torch.randn(K, C, generator=gen, dtype=dtype)
    b = torch.randn(C, generator=gen, dtype=dtype)
    return [t.requires_grad_() for t in (x, w, b)]


def _run(fn, args, seed=1):
    y = fn(*args)
    g = torch.randn(y.shape, generator=torch.Generator().manual_seed(seed), dtype=y.dtype)
    return y.detach(), torch.autograd.grad(y, args, g)


@pytest.mark.skipif(not cc.numba_kernels.available(), reason="the compiled kernels need numba")
@pytest.mark.parametrize("L", [1, 2, 3, 4, 9, 64])
@pytest.mark.parametrize("K", [1, 2, 4])
def test_compiled_equals_the_shifted_multiply_adds_float64(L, K):
    args = _args(3, L, 10, K, torch.float64)
    y_ref, g_ref = _run(cc.causal_conv_reference, args)
    y, g = _run(cc.causal_conv, args)
    assert (y - y_ref).abs().max() < 1e-12
    for a, b in zip(g, g_ref, strict=True):
        assert (a - b).abs().max() < 1e-12


@pytest.mark.skipif(not cc.numba_kernels.available(), reason="the compiled kernels need numba")
def test_compiled_float32_is_close_deterministic_and_causal():
    args = _args(4, 50, 416, 4, torch.float32, seed=2)
    y_ref, g_ref = _run(cc.causal_conv_reference, args)
    runs = [_run(cc.causal_conv, args) for _ in range(2)]
    assert torch.equal(runs[0][0], runs[1][0]) and all(
        torch.equal(a, b) for a, b in zip(runs[0][1], runs[1][1], strict=True)
    )
    y, g = runs[0]
    assert (y - y_ref).abs().max() < 1e-5 * (1 + y_ref.abs().max())
    for a, b in zip(g, g_ref, strict=True):
        assert (a - b).abs().max() < 1e-5 * (1 + b.abs().max())
    # a change at step 20 moves nothing before it
    x2 = args[0].detach().clone()
    x2[:, 20] += 1.0
    y2 = cc.causal_conv(x2, args[1].detach(), args[2].detach())
    assert torch.equal(y2[:, :20], y[:, :20]) and not torch.equal(y2[:, 20], y[:, 20])


@pytest.mark.skipif(not cc.numba_kernels.available(), reason="the compiled kernels need numba")
def test_selective_ssm_convolves_as_before(monkeypatch):
    # the layer's output and gradients with the compiled convolution and with the reference
    torch.manual_seed(3)
    m = SelectiveSSM(6, (1, -1), SSMConfig(d_state=4), dt_rank=2).double()
    x = torch.randn(2, 11, 6, dtype=torch.float64, requires_grad=True)
    y, (gx,) = _run(m, [x])
    monkeypatch.setattr("motion_core.nn.ssm.causal_conv", cc.causal_conv_reference)
    y_ref, (gx_ref,) = _run(m, [x])
    assert (y - y_ref).abs().max() < 1e-10 and (gx - gx_ref).abs().max() < 1e-10
