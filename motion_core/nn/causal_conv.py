"""Depthwise causal Conv1D over the time axis of channels-last input, compiled (numba).

    out[b, t, c] = bias[c] + sum_j w[j, c] * x[b, t - (K - 1) + j, c]    (x before t = 0 is 0)

Every ``SelectiveSSM`` runs one before its scans. Written as K shifted multiply-adds in torch
(``causal_conv_reference``), the forward is 2K element-wise ops over the whole (B, L, C)
tensor and the backward more: each shifted slice's gradient is materialised as a zero-padded
copy and summed. At Motion Mamba's training batch of 256 a BSM block's input is 100+ MiB,
so those passes were a fifth of the block's forward and backward (348 of 1,549 ms, one
thread). Here the forward and the backward are each one pass, vectorised over the channels.
``oneDNN``'s grouped ``conv1d`` wants (B, C, L) and was several times slower on these short
sequences (the reason for the channels-last shifted form in the first place).

Float32 and float64; where numba does not import, ``causal_conv`` is the reference.
"""

from __future__ import annotations

import torch

from . import numba_kernels
from .numba_kernels import prange


def causal_conv_reference(x: torch.Tensor, weight: torch.Tensor, bias: torch.Tensor) -> torch.Tensor:
    """The definition in torch ops: x (B, L, C), weight (K, C) (tap K - 1 multiplies the
    current step), bias (C,) -> (B, L, C)."""
    K, L = weight.shape[0], x.shape[1]
    xp = torch.nn.functional.pad(x, (0, 0, K - 1, 0))
    out = bias + xp[:, :L] * weight[0]
    for j in range(1, K):
        out = out + xp[:, j : j + L] * weight[j]
    return out


if numba_kernels.available():

    def _conv_forward(x, w, bias, out):  # pragma: no cover - compiled
        b_n, l_n, c_n = x.shape
        k_n = w.shape[0]
        for b in prange(b_n):
            for t in range(l_n):
                o = out[b, t]
                for c in range(c_n):
                    o[c] = bias[c]
                for j in range(max(0, k_n - 1 - t), k_n):
                    src, wj = x[b, t - (k_n - 1) + j], w[j]
                    for c in range(c_n):
                        o[c] += wj[c] * src[c]

    def _conv_backward(x, w, g, gx, gw):  # pragma: no cover - compiled
        """gx (B, L, C) written; gw (B, K, C): per-sample sums, added to (zeroed by the caller)."""
        b_n, l_n, c_n = x.shape
        k_n = w.shape[0]
        for b in prange(b_n):
            for t in range(l_n):
                gt, gxt = g[b, t], gx[b, t]
                for c in range(c_n):
                    gxt[c] = 0.0
                # out[t'] reads x[t] through tap j where t' = t + (K - 1) - j
                for j in range(k_n):
                    tt = t + (k_n - 1) - j
                    if tt < l_n:
                        gsrc, wj = g[b, tt], w[j]
                        for c in range(c_n):
                            gxt[c] += wj[c] * gsrc[c]
                # tap j of out[t] read x[t - (K - 1) + j]
                for j in range(max(0, k_n - 1 - t), k_n):
                    src, gwj = x[b, t - (k_n - 1) + j], gw[b, j]
                    for c in range(c_n):
                        gwj[c] += gt[c] * src[c]

    _KERNELS = (numba_kernels.builds(_conv_forward), numba_kernels.builds(_conv_backward))


class _CausalConv(torch.autograd.Function):
    @staticmethod
    def forward(ctx, x, weight, bias):  # type: ignore[override]
        xc, wc = x.detach().contiguous(), weight.detach().contiguous()
        out = torch.empty_like(xc)
        numba_kernels.run(_KERNELS[0], xc.numpy(), wc.numpy(), bias.detach().contiguous().numpy(), out.numpy())
        ctx.save_for_backward(xc, wc)
        return out

    @staticmethod
    def backward(ctx, g):  # type: ignore[override]
        x, w = ctx.saved_tensors
        g = g.contiguous()
        gx = torch.empty_like(x)
        gw = torch.zeros((x.shape[0], *w.shape), dtype=x.dtype)
        numba_kernels.run(_KERNELS[1], x.numpy(), w.numpy(), g.numpy(), gx.numpy(), gw.numpy())
        gb = g.sum((0, 1), dtype=torch.float64).to(g.dtype) if ctx.needs_input_grad[2] else None
        return gx, gw.sum(0, dtype=torch.float64).to(w.dtype), gb


def causal_conv(x: torch.Tensor, weight: torch.Tensor, bias: torch.Tensor) -> torch.Tensor:
    """Depthwise causal Conv1D, channels last: x (B, L, C), weight (K, C), bias (C,) ->
    (B, L, C). The compiled kernels on CPU tensors where numba imports, else the reference."""
    if not numba_kernels.available() or x.device.type != "cpu" or x.dtype not in (torch.float32, torch.float64):
        return causal_conv_reference(x, weight, bias)
    dtype = x.dtype
    return _CausalConv.apply(x, weight.to(dtype), bias.to(dtype))
