"""A dilated 'same' Conv1d computed as the sum of its taps, for the CPU.

PyTorch's CPU convolution hands a dilated Conv1d to ``slow_conv_dilated2d``, which loops over
the batch and the kernel in dispatched ops (about 260 ``select``/``copy_`` a call): in the
shipped VAE decoder its four dilated convolutions (dilations 3 and 9) took as long as the
other eleven layers together, a third of a decode. Written as its taps,

    y[:, :, t] = b + sum_k W[:, :, k] x[:, :, t + k d - p]      (zero outside 0..T-1)

a full convolution (groups 1) is one matrix product of the weight (O, K*C) with the K
shifted copies of the input stacked on the channel axis (B, K*C, T), and a depthwise one
(groups = C = O) is K broadcast multiply-adds. Same parameters and state dict as
``nn.Conv1d``; values equal it to float rounding (tests: 1e-5, values and gradients).
A depthwise convolution takes the taps undilated too: PyTorch runs it through
``_slow_conv2d_forward`` as well (FTMoMamba's CDWConv: 0.36 ms a call at dilation 1).
Other strides, paddings and group counts, an undilated full convolution (PyTorch's own
path is fast there) and every CUDA tensor take ``nn.Conv1d``'s path.
"""

from __future__ import annotations

import torch
import torch.nn.functional as F
from torch import nn


class DilatedConv1d(nn.Conv1d):
    """``nn.Conv1d`` (same arguments) whose dilated or depthwise 'same' case runs as its
    taps. x: (B, C, T) -> (B, O, T)."""

    def _taps_apply(self, x: torch.Tensor) -> bool:
        (k,), (d,), (s,), pad = self.kernel_size, self.dilation, self.stride, self.padding
        depthwise = self.groups == self.in_channels == self.out_channels and self.groups > 1
        return (
            (d > 1 or depthwise)  # an undilated full convolution has a fast path of its own
            and s == 1
            and not isinstance(pad, str)
            and 2 * pad[0] == d * (k - 1)
            and self.padding_mode == "zeros"
            and x.device.type == "cpu"
            and x.dim() == 3
            and (self.groups == 1 or self.groups == self.in_channels == self.out_channels)
        )

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        if not self._taps_apply(x):
            return super().forward(x)
        (k,), (d,), (p,) = self.kernel_size, self.dilation, self.padding
        t = x.shape[-1]
        xp = F.pad(x, (p, p))
        taps = [xp[..., j * d : j * d + t] for j in range(k)]
        w = self.weight  # (O, C / groups, K)
        if self.groups == 1:
            # (O, K*C) @ (B, K*C, T): the weight's tap-major layout matches the stacked copies
            y = torch.matmul(w.permute(0, 2, 1).reshape(w.shape[0], -1), torch.cat(taps, dim=1))
        else:
            y = taps[0] * w[None, :, 0, 0:1]
            for j in range(1, k):
                y = y + taps[j] * w[None, :, 0, j : j + 1]
        return y if self.bias is None else y + self.bias[:, None]
