"""FTMoMamba's CDWConv as one compiled call (``nn/cdw_compiled.py``) equals its eager form,
and is taken only where it computes the same thing."""

from __future__ import annotations

import pytest
import torch

from motion_core.models.ftmomamba import CDWConv
from motion_core.nn import cdw_compiled, numba_kernels

pytestmark = pytest.mark.skipif(not numba_kernels.available(), reason="numba is an optional dependency")


def _eager(m: CDWConv, x: torch.Tensor) -> torch.Tensor:
    y = x.transpose(1, 2)
    for conv in m.convs:
        y = torch.nn.functional.conv1d(
            y, conv.weight, conv.bias, padding=conv.padding, dilation=conv.dilation, groups=conv.groups
        )
    return y.transpose(1, 2)


@pytest.mark.parametrize(("b", "length", "c"), [(1, 49, 256), (2, 52, 64), (3, 7, 64), (2, 3, 16)])
def test_the_compiled_cascade_equals_the_eager_convolutions(b, length, c):
    torch.manual_seed(length + c)
    m = CDWConv(c).eval()
    x = torch.randn(b, length, c)
    with torch.no_grad():
        assert cdw_compiled.applies(m.convs, x)
        got = m(x)
        want = _eager(m, x)
    assert got.shape == x.shape and got.dtype == torch.float32
    torch.testing.assert_close(got, want, atol=1e-5, rtol=1e-5)


def test_the_module_falls_back_to_its_eager_form_where_the_kernel_does_not_apply(monkeypatch):
    m = CDWConv(32)
    x = torch.randn(2, 10, 32)
    # a gradient to take: the eager form, which autograd can follow
    assert not cdw_compiled.applies(m.convs, x)
    y = m(x)
    assert y.requires_grad
    y.sum().backward()
    assert m.convs[0].weight.grad is not None
    with torch.no_grad():
        assert cdw_compiled.applies(m.convs, x)
        assert not cdw_compiled.applies(m.convs, x.double())  # float32 only
        assert not cdw_compiled.applies(m.convs, x[0])  # (B, L, C) only
        assert not cdw_compiled.applies(m.convs[:2], x)  # the three convolutions
        odd = CDWConv(32)
        odd.convs[1].dilation = (3,)
        odd.convs[1].padding = (3,)
        assert not cdw_compiled.applies(odd.convs, x)  # a layout the kernel does not compute
        nobias = CDWConv(32)
        nobias.convs[0].bias = None
        assert not cdw_compiled.applies(nobias.convs, x)
        torch.testing.assert_close(nobias(x), _eager(nobias, x), atol=1e-5, rtol=1e-5)
        want = _eager(odd, x)
        torch.testing.assert_close(odd(x), want, atol=1e-5, rtol=1e-5)
    # the compiled path is what a sampling call takes: counted, not assumed
    calls = []
    real = cdw_compiled.cdw_cascade
    monkeypatch.setattr(cdw_compiled, "cdw_cascade", lambda convs, x: calls.append(x.shape) or real(convs, x))
    with torch.no_grad():
        torch.testing.assert_close(m(x), _eager(m, x), atol=1e-5, rtol=1e-5)
    assert calls == [x.shape]


def test_both_builds_agree_and_an_in_place_weight_change_shows_through():
    """The serial build (one torch thread) and the parallel one give the same values; the
    parameters' arrays are kept between calls, so a weight changed in place must be read
    anew, and a replaced one too."""
    torch.manual_seed(5)
    m = CDWConv(48).eval()
    x = torch.randn(3, 20, 48)
    from motion_core.nn.scan_compiled import _np

    with torch.no_grad():
        outs = []
        for parallel in (False, True):
            out = torch.empty_like(x).numpy()
            cdw_compiled._KERNEL[parallel](_np(x), *cdw_compiled._views(m.convs), out)
            outs.append(torch.from_numpy(out))
        torch.testing.assert_close(outs[0], outs[1], atol=1e-6, rtol=1e-6)
        torch.testing.assert_close(outs[0], _eager(m, x), atol=1e-5, rtol=1e-5)
        m(x)  # the arrays are cached now
        m.convs[1].weight.mul_(2.0)
        torch.testing.assert_close(m(x), _eager(m, x), atol=1e-5, rtol=1e-5)
        m.convs[2].bias = torch.nn.Parameter(torch.randn(48))
        torch.testing.assert_close(m(x), _eager(m, x), atol=1e-5, rtol=1e-5)
        # a non-contiguous input, and parameters of another dtype: the eager form's business
        xt = torch.randn(3, 48, 20).transpose(1, 2)
        torch.testing.assert_close(m(xt), _eager(m, xt), atol=1e-5, rtol=1e-5)
        assert not cdw_compiled.applies(m.double().convs, x)
