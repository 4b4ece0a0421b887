"""FTMoMamba's cascaded depthwise convolution (CDWConv) as one compiled kernel (numba): the
CPU's sampling path.

CDWConv is three depthwise Conv1d of kernel 3, 'same' padding, dilations d = 1, 2, 4, one
after another on (B, L, C):

    y_t = b + w_0 x_{t-d} + w_1 x_t + w_2 x_{t+d}      (per channel; zero outside 0..L-1)

Eager, each convolution runs as its taps (``dilated_conv``) with a transpose on either side:
62 top-level torch ops a CDWConv and six CDWConvs a FTMoMamba sampling step, on arrays of a
few thousand elements, so dispatch rather than arithmetic. Here one call does the three in
the (B, L, C) layout the block holds, so no transpose either; the parameters' arrays are
kept between calls (converting six tensors a call cost 38 ops of its own).

Inference only (no autograd), float32, CPU, numba importable; ``CDWConv`` falls back to its
eager form otherwise. The two agree to float rounding (tests: 1e-5); the kernel's multiply-
adds may contract to fused ones, so the results are not bit-identical.
"""

from __future__ import annotations

import numpy as np
import torch

from . import numba_kernels
from .numba_kernels import prange
from .scan_compiled import _np

DILATIONS = (1, 2, 4)

if numba_kernels.available():

    def _cascade(x, w0, b0, w1, b1, w2, b2, out):  # pragma: no cover - compiled
        """x, out (B, L, C); w_i (C, 3) the i-th convolution's taps, b_i (C,) its bias, at
        dilation 1, 2, 4 for i = 0, 1, 2."""
        bsz, length, c = x.shape
        # the taps channel-last (3 convolutions, 3 taps, C), so the channel loops below read
        # them contiguously and vectorise
        taps = np.empty((3, 3, c), np.float32)
        for ch in range(c):
            for j in range(3):
                taps[0, j, ch] = w0[ch, j]
                taps[1, j, ch] = w1[ch, j]
                taps[2, j, ch] = w2[ch, j]
        for s in prange(bsz):
            cur = x[s].copy()
            nxt = np.empty_like(cur)
            for i in range(3):
                d = 1 << i
                b = b0 if i == 0 else (b1 if i == 1 else b2)
                for t in range(length):
                    row = nxt[t]
                    row[:] = b
                    for j in range(3):
                        tt = t + (j - 1) * d
                        if tt < 0 or tt >= length:
                            continue
                        src = cur[tt]
                        w = taps[i, j]
                        for ch in range(c):
                            row[ch] += w[ch] * src[ch]
                cur, nxt = nxt, cur
            out[s] = cur

    _KERNEL = numba_kernels.builds(_cascade)


def applies(convs, x: torch.Tensor) -> bool:
    """Whether a CDWConv's three convolutions (``convs``) can take the compiled path on x:
    numba imports, CPU float32 (B, L, C), nothing to differentiate, and the layout this
    kernel computes (depthwise, kernel 3, dilations 1, 2, 4 with 'same' zero padding)."""
    if not numba_kernels.available() or x.device.type != "cpu" or x.dtype != torch.float32 or x.dim() != 3:
        return False
    params = [p for conv in convs for p in conv.parameters()]
    if any(p.dtype != torch.float32 or p.device.type != "cpu" for p in params):
        return False  # the eager form says what is wrong with mixed dtypes or devices
    if torch.is_grad_enabled() and (x.requires_grad or any(p.requires_grad for p in params)):
        return False
    c = x.shape[-1]
    return len(convs) == 3 and all(
        conv.groups == conv.in_channels == conv.out_channels == c
        and conv.kernel_size == (3,)
        and conv.dilation == (d,)
        and conv.padding == (d,)
        and conv.stride == (1,)
        and conv.padding_mode == "zeros"
        and conv.bias is not None
        for conv, d in zip(convs, DILATIONS, strict=True)
    )


def _key(convs) -> tuple:
    return tuple(t.data_ptr() for conv in convs for t in (conv.weight, conv.bias))


def _views(convs) -> list[np.ndarray]:
    """The convolutions' weights (C, 3) and biases (C,) as arrays over their own memory,
    kept on ``convs`` and rebuilt only when a parameter is replaced by another tensor: an
    in-place change shows through, and converting six parameters on every call cost more
    dispatched ops than the kernel saves."""
    cached = getattr(convs, "_cdw_views", None)
    key = _key(convs)
    if cached is None or cached[0] != key:
        arrays = []
        for conv in convs:
            arrays += [_np(conv.weight.detach().reshape(conv.out_channels, 3)), _np(conv.bias.detach())]
        if not all(t.is_contiguous() for conv in convs for t in (conv.weight, conv.bias)):
            return arrays  # copies, not views: kept, they could go stale
        cached = (key, arrays)
        convs._cdw_views = cached  # a plain attribute: not a parameter, not in the state dict
    return cached[1]


def cdw_cascade(convs, x: torch.Tensor) -> torch.Tensor:
    """The three depthwise convolutions of ``convs`` applied in turn to x: (B, L, C) -> (B, L, C)."""
    xn = _np(x)
    out = np.empty_like(xn)
    numba_kernels.run(_KERNEL, xn, *_views(convs), out)
    return torch.from_numpy(out)
