"""A selective SSM's whole inference forward as one compiled kernel (numba): the CPU's
sampling path for Motion Mamba, FTMoMamba and KMM.

``SelectiveSSM.forward`` followed by the mix of its k outputs (and, in a ``MambaBlock``, the
SiLU gate) is some twenty dispatched torch ops per block: spread and flip the input, causal
Conv1D, SiLU, the x- and delta-projections (einsums and their copies), softplus, exp of A,
the scan, flip back, mix, gate. A Motion Mamba denoiser call has twelve such blocks and made
1,031 top-level torch ops in all, against the transformer baseline's 43, for about the same
matrix-multiply FLOPs (``results/ops_per_call.json``). Here one call does all of it:

    per scan i (reversed scans read the input back to front):
      xc = SiLU(causal_conv_i(x))                            (B, L, E)
      [dt | B | C] = xc W_x,i;  delta = softplus(dt W_dt,i + b_i)
      h_t = exp(delta_t A_i) h_{t-1} + delta_t B_t xc_t;  O_i,t = <C_t, h_t> + D_i xc_t
    y = sum_i mix_i O_i  (times SiLU(z) in a MambaBlock)

Both projections are BLAS matrix products over all B*L rows (numba's ``np.dot``, scipy's
BLAS); SiLU, softplus and the decays are ``kernel_math``'s vectorised float32 functions
(numba's ``math`` ones are scalar here: softplus took 39 ns an element). FTMoMamba's hooks
are taken too: a per-step shift of the state matrix (FreqSSM; ``ssm.stable_state_matrix``'s
A_n = -eps - softplus(-A - shift), computed a step at a time instead of as a (B, L, E, N)
tensor) and a per-sample shift of C (TextSSM).

Inference only (no autograd), float32, CPU; ``SelectiveSSM`` and ``MambaBlock`` take this
path when nothing needs a gradient and fall back to their eager forward otherwise (and
inside ``ssm.eager_scans()``, the bench's "before" arm). The two agree to float rounding
(tests: 1e-5 on a block's output).
"""

from __future__ import annotations

import numpy as np
import torch

from . import numba_kernels
from .kernel_math import CONSTANTS
from .numba_kernels import prange
from .scan_compiled import STATE_EPS

_C32 = CONSTANTS[np.dtype(np.float32)]
_EPS32 = np.float32(STATE_EPS)


if numba_kernels.available():
    from .kernel_math import _exp_inplace, _silu_inplace, _softplus_inplace

    def _mixer(
        x, x_off, e_n, conv_w, conv_b, wx, wdt, dt_bias, At, Dv, mix, rev, a_shift, c_shift, gate_off, eps, c, out
    ):  # pragma: no cover - compiled
        """x (B, L, *): the input in columns [x_off, x_off + E) and, with ``gate_off`` >= 0,
        the gate z in [gate_off, gate_off + E); conv_w (k, K, E); conv_b, dt_bias, Dv, mix
        (k, E); wx (k, E, R + 2N); wdt (k, R, E); At (k, N, E) = A transposed; rev (k,) 1
        where scan i runs back to front; a_shift (B, L, E) or (0, 0, 0); c_shift (B, N) or
        (0, 0); eps: FreqSSM's; c: ``kernel_math.CONSTANTS[float32]``. out (B, L, E),
        zeroed by the caller."""
        b_n, l_n = x.shape[0], x.shape[1]
        k_n, kw = conv_w.shape[0], conv_w.shape[1]
        n_n, r_n = At.shape[1], wdt.shape[1]
        rows = b_n * l_n
        shifted = a_shift.shape[0] > 0
        neg_eps = -eps
        xc = np.empty((rows, e_n), dtype=x.dtype)  # one scan's SiLU(conv(x)), in scan order
        for i in range(k_n):
            ri = rev[i]
            for b in prange(b_n):
                tmp = np.empty(e_n, dtype=x.dtype)
                k32 = np.empty(e_n, dtype=np.int32)
                for s in range(l_n):
                    row = xc[b * l_n + s]
                    cb = conv_b[i]
                    for e in range(e_n):
                        row[e] = cb[e]
                    for j in range(max(0, kw - 1 - s), kw):
                        sp = s - (kw - 1) + j
                        src = x[b, l_n - 1 - sp if ri else sp, x_off : x_off + e_n]
                        wj = conv_w[i, j]
                        for e in range(e_n):
                            row[e] += wj[e] * src[e]
                    _silu_inplace(row, tmp, k32, c)
            proj = np.dot(xc, wx[i])  # (B*L, R + 2N)
            delta = np.dot(np.ascontiguousarray(proj[:, :r_n]), wdt[i])  # (B*L, E)
            for b in prange(b_n):
                tmp = np.empty(e_n, dtype=x.dtype)
                k32 = np.empty(e_n, dtype=np.int32)
                h = np.zeros((n_n, e_n), dtype=x.dtype)
                es = np.empty((n_n, e_n), dtype=x.dtype)
                dtu = np.empty(e_n, dtype=x.dtype)
                y = np.empty(e_n, dtype=x.dtype)
                bias, a_i, d_i, m_i = dt_bias[i], At[i], Dv[i], mix[i]
                for s in range(l_n):
                    t = l_n - 1 - s if ri else s
                    r = b * l_n + s
                    dt, ut, p = delta[r], xc[r], proj[r]
                    for e in range(e_n):
                        dt[e] += bias[e]
                    _softplus_inplace(dt, tmp, k32, c)
                    for n in range(n_n):
                        es_n, a_n = es[n], a_i[n]
                        if shifted:
                            # FreqSSM: A_n = -eps - softplus(-A - shift), eps = 1e-4
                            sh = a_shift[b, t]
                            for e in range(e_n):
                                es_n[e] = -a_n[e] - sh[e]
                            _softplus_inplace(es_n, tmp, k32, c)
                            for e in range(e_n):
                                es_n[e] = dt[e] * (neg_eps - es_n[e])
                        else:
                            for e in range(e_n):
                                es_n[e] = dt[e] * a_n[e]
                        _exp_inplace(es_n, k32, c)
                    for e in range(e_n):
                        dtu[e] = dt[e] * ut[e]
                        y[e] = d_i[e] * ut[e]
                    for n in range(n_n):
                        bn = p[r_n + n]
                        cn = p[r_n + n_n + n]
                        if c_shift.shape[0] > 0:
                            cn += c_shift[b, n]
                        hn, es_n = h[n], es[n]
                        for e in range(e_n):
                            v = es_n[e] * hn[e] + dtu[e] * bn
                            hn[e] = v
                            y[e] += v * cn
                    o = out[b, t]
                    for e in range(e_n):
                        o[e] += m_i[e] * y[e]
        if gate_off >= 0:
            for b in prange(b_n):
                tmp = np.empty(e_n, dtype=x.dtype)
                k32 = np.empty(e_n, dtype=np.int32)
                z = np.empty(e_n, dtype=x.dtype)
                for t in range(l_n):
                    src = x[b, t, gate_off : gate_off + e_n]
                    for e in range(e_n):
                        z[e] = src[e]
                    _silu_inplace(z, tmp, k32, c)
                    o = out[b, t]
                    for e in range(e_n):
                        o[e] *= z[e]

    _KERNEL = numba_kernels.builds(_mixer)


def _np32(x: torch.Tensor) -> np.ndarray:
    return x.detach().contiguous().numpy()


class _Weights:
    """An SSM's parameters laid out as the kernel reads them, rebuilt when any of them
    changes (an optimiser step or a loaded state dict bumps a tensor's version)."""

    def __init__(self, ssm, mix: torch.Tensor | None) -> None:
        k, e, n = ssm.k, ssm.d_inner, ssm.cfg.d_state
        params = [ssm.conv_weight, ssm.conv_bias, ssm.x_proj, ssm.dt_proj, ssm.dt_bias, ssm.A_log, ssm.D]
        params += [mix] if mix is not None else []
        self.key = tuple((p.data_ptr(), p._version) for p in params)
        with torch.no_grad():
            self.conv_w = _np32(ssm.conv_weight.view(k, e, -1).transpose(1, 2))
            self.conv_b = _np32(ssm.conv_bias.view(k, e))
            self.wx = _np32(ssm.x_proj)
            self.wdt = _np32(ssm.dt_proj)
            self.dt_bias = _np32(ssm.dt_bias)
            self.At = _np32((-torch.exp(ssm.A_log)).view(k, e, n).transpose(1, 2))
            self.D = _np32(ssm.D.view(k, e))
            self.mix = _np32(mix) if mix is not None else np.ones((k, e), np.float32)
        self.rev = np.array(ssm._reversed, dtype=np.int64)


_EMPTY3 = np.zeros((0, 0, 0), np.float32)
_EMPTY2 = np.zeros((0, 0), np.float32)


def applies(ssm, *tensors: torch.Tensor | None) -> bool:
    """Whether ``ssm`` (a ``SelectiveSSM``) can take the fused path on these inputs (the
    first the scan input): numba imports, CPU float32, and nothing to differentiate. The
    dispatcher's own conditions (its scan left to "auto", no forced or eager scans) are
    ``SelectiveSSM``'s to check."""
    if not numba_kernels.available():
        return False
    x = tensors[0]
    if x.device.type != "cpu" or x.dtype != torch.float32:
        return False
    if torch.is_grad_enabled() and (
        any(t is not None and t.requires_grad for t in tensors) or any(p.requires_grad for p in ssm.parameters())
    ):
        return False
    return True


def _weights(ssm, mix: torch.Tensor | None) -> _Weights:
    cached = getattr(ssm, "_fused_weights", None)
    params = [ssm.conv_weight, ssm.conv_bias, ssm.x_proj, ssm.dt_proj, ssm.dt_bias, ssm.A_log, ssm.D]
    params += [mix] if mix is not None else []
    if cached is None or cached.key != tuple((p.data_ptr(), p._version) for p in params):
        cached = _Weights(ssm, mix)
        ssm._fused_weights = cached  # plain attribute: not a parameter, not in the state dict
    return cached


def fused_ssm(
    ssm,
    x: torch.Tensor,
    e_range: tuple[int, int] | None = None,
    mix: torch.Tensor | None = None,
    gate_from: int | None = None,
    a_shift: torch.Tensor | None = None,
    c_shift: torch.Tensor | None = None,
) -> torch.Tensor:
    """sum_i mix_i O_i for ``ssm`` (a ``SelectiveSSM`` of k scans over E channels), times
    SiLU(z) where ``gate_from`` is given. x: (B, L, *) holding the scan input in columns
    ``e_range`` (default: all of them) and, with ``gate_from``, z in [gate_from, gate_from +
    E); mix: (k, E) or None (a plain sum); a_shift (B, L, E) and c_shift (B, N) as
    ``SelectiveSSM.forward``'s. Returns (B, L, E)."""
    w = _weights(ssm, mix)
    e = ssm.d_inner
    lo = 0 if e_range is None else e_range[0]
    xn = _np32(x)
    out = np.zeros((x.shape[0], x.shape[1], e), np.float32)
    shift = _np32(a_shift) if a_shift is not None else _EMPTY3
    cs = _np32(c_shift) if c_shift is not None else _EMPTY2
    numba_kernels.run(
        _KERNEL,
        xn,
        lo,
        e,
        w.conv_w,
        w.conv_b,
        w.wx,
        w.wdt,
        w.dt_bias,
        w.At,
        w.D,
        w.mix,
        w.rev,
        shift,
        cs,
        -1 if gate_from is None else gate_from,
        _EPS32,
        _C32,
        out,
    )
    return torch.from_numpy(out)
