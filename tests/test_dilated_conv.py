"""The dilated / depthwise Conv1d computed as its taps equals nn.Conv1d: values and gradients."""

from __future__ import annotations

import pytest
import torch
from torch import nn

from motion_core.nn.dilated_conv import DilatedConv1d


@pytest.mark.parametrize(
    ("c", "o", "d", "groups", "t", "b"),
    [
        (128, 128, 3, 1, 50, 1),  # the VAE decoder's residual blocks
        (128, 128, 9, 1, 200, 2),
        (16, 32, 3, 1, 5, 1),  # shorter than the padding
        (64, 64, 1, 64, 52, 3),  # FTMoMamba's CDWConv, dilations 1, 2, 4
        (64, 64, 2, 64, 52, 2),
        (64, 64, 4, 64, 7, 2),
    ],
)
def test_taps_equal_conv1d_values_and_gradients(c, o, d, groups, t, b):
    torch.manual_seed(d * 100 + groups)
    ref = nn.Conv1d(c, o, 3, padding=d, dilation=d, groups=groups)
    taps = DilatedConv1d(c, o, 3, padding=d, dilation=d, groups=groups)
    taps.load_state_dict(ref.state_dict())  # the same parameters and state dict keys
    x = torch.randn(b, c, t, requires_grad=True)
    x2 = x.detach().clone().requires_grad_(True)
    assert taps._taps_apply(x2)
    want, got = ref(x), taps(x2)
    torch.testing.assert_close(got, want, atol=1e-5, rtol=1e-5)
    g = torch.randn_like(want)
    want.backward(g)
    got.backward(g)
    torch.testing.assert_close(x2.grad, x.grad, atol=1e-5, rtol=1e-5)
    torch.testing.assert_close(taps.weight.grad, ref.weight.grad, atol=1e-4, rtol=1e-5)
    torch.testing.assert_close(taps.bias.grad, ref.bias.grad, atol=1e-4, rtol=1e-5)


@pytest.mark.parametrize(
    "kw",
    [
        dict(padding=1),  # an undilated full convolution: PyTorch's own fast path
        dict(padding=2, dilation=2, stride=2),
        dict(padding=0, dilation=2),  # not 'same'
        dict(padding=2, dilation=2, groups=4),  # neither full nor depthwise
    ],
)
def test_other_convolutions_take_conv1ds_own_path(kw):
    torch.manual_seed(0)
    ref = nn.Conv1d(8, 8, 3, **kw)
    conv = DilatedConv1d(8, 8, 3, **kw)
    conv.load_state_dict(ref.state_dict())
    x = torch.randn(2, 8, 20)
    assert not conv._taps_apply(x)
    assert torch.equal(conv(x), ref(x))
