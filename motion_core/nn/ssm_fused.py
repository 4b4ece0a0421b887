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
from .scan_compiled import _NO_SHIFT, STATE_EPS, _np

_C32 = CONSTANTS[np.dtype(np.float32)]
_EPS32 = np.float32(STATE_EPS)


if numba_kernels.available():
    from .kernel_math import _exp_inplace, _silu_inplace, _softplus_inplace

    def _mixer(
        x, x_off, e_n, wconv, conv_b, wx, wdt, dt_bias, A_log, Dv, mix, rev, a_shift, c_shift, gate_off, eps, c, out
    ):  # pragma: no cover - compiled
        """x (B, L, *): the input in columns [x_off, x_off + E) and, with ``gate_off`` >= 0,
        the gate z in [gate_off, gate_off + E); wconv (k, E, K): the conv taps; conv_b,
        dt_bias, Dv, mix (k, E); wx (k, E, R + 2N); wdt (k, R, E); A_log (k, E, N); rev (k,)
        1 where scan i runs back to front; a_shift (B, L, E) or (0, 0, 0); c_shift (B, N) or
        (0, 0); eps: FreqSSM's; c: ``kernel_math.CONSTANTS[float32]``. out (B, L, E), zeroed
        by the caller. The parameters are the module's own memory, read as they are at this call."""
        b_n, l_n = x.shape[0], x.shape[1]
        k_n, kw = wconv.shape[0], wconv.shape[2]
        n_n, r_n = A_log.shape[2], wdt.shape[1]
        # the layouts the loops below read contiguously: taps (k, K, E), A = -exp(A_log) (k, N, E)
        conv_w = np.empty((k_n, kw, e_n), dtype=x.dtype)
        At = np.empty((k_n, n_n, e_n), dtype=x.dtype)
        for i in range(k_n):
            for e in range(e_n):
                for j in range(kw):
                    conv_w[i, j, e] = wconv[i, e, j]
                for n in range(n_n):
                    At[i, n, e] = A_log[i, e, n]
        k32a = np.empty(n_n * e_n, dtype=np.int32)
        for i in range(k_n):
            a = At[i].reshape(n_n * e_n)
            _exp_inplace(a, k32a, c)
            for j in range(n_n * e_n):
                a[j] = -a[j]
        shifted = a_shift.shape[0] > 0
        neg_eps = -eps
        le, lne = l_n * e_n, l_n * n_n * e_n
        # the element-wise functions run once over a sample's whole (L, E) or (L, N, E) block:
        # called per step on E channels, their call and loop overheads cost a third more
        xc = np.empty((b_n * l_n, e_n), dtype=x.dtype)  # one scan's SiLU(conv(x)), in scan order
        for i in range(k_n):
            ri = rev[i]
            for b in prange(b_n):
                tmp = np.empty(le, dtype=x.dtype)
                k32 = np.empty(le, dtype=np.int32)
                cb = conv_b[i]
                for s in range(l_n):
                    row = xc[b * l_n + s]
                    for e in range(e_n):
                        row[e] = cb[e]
                    for j in range(max(0, kw - 1 - s), kw):
                        sp = s - (kw - 1) + j
                        src = x[b, l_n - 1 - sp if ri else sp, x_off : x_off + e_n]
                        wj = conv_w[i, j]
                        for e in range(e_n):
                            row[e] += wj[e] * src[e]
                _silu_inplace(xc[b * l_n : (b + 1) * l_n].reshape(le), tmp, k32, c)
            proj = np.dot(xc, wx[i])  # (B*L, R + 2N)
            delta = np.dot(np.ascontiguousarray(proj[:, :r_n]), wdt[i])  # (B*L, E)
            for b in prange(b_n):
                tmp = np.empty(lne, dtype=x.dtype)
                k32 = np.empty(lne, dtype=np.int32)
                es = np.empty((l_n, n_n, e_n), dtype=x.dtype)  # every step's decays
                h = np.zeros((n_n, e_n), dtype=x.dtype)
                dtu = np.empty(e_n, dtype=x.dtype)
                y = np.empty(e_n, dtype=x.dtype)
                bias, a_i, d_i, m_i = dt_bias[i], At[i], Dv[i], mix[i]
                dl = delta[b * l_n : (b + 1) * l_n]
                for s in range(l_n):
                    dt = dl[s]
                    for e in range(e_n):
                        dt[e] += bias[e]
                _softplus_inplace(dl.reshape(le), tmp, k32, c)
                if shifted:
                    # FreqSSM: A_n = -eps - softplus(-A - shift), the shift read in scan order
                    for s in range(l_n):
                        sh = a_shift[b, l_n - 1 - s if ri else s]
                        for n in range(n_n):
                            es_n, a_n = es[s, n], a_i[n]
                            for e in range(e_n):
                                es_n[e] = -a_n[e] - sh[e]
                    _softplus_inplace(es.reshape(lne), tmp, k32, c)
                    for s in range(l_n):
                        dt = dl[s]
                        for n in range(n_n):
                            es_n = es[s, n]
                            for e in range(e_n):
                                es_n[e] = dt[e] * (neg_eps - es_n[e])
                else:
                    for s in range(l_n):
                        dt = dl[s]
                        for n in range(n_n):
                            es_n, a_n = es[s, n], a_i[n]
                            for e in range(e_n):
                                es_n[e] = dt[e] * a_n[e]
                _exp_inplace(es.reshape(lne), k32, c)
                for s in range(l_n):
                    t = l_n - 1 - s if ri else s
                    r = b * l_n + s
                    dt, ut, p = dl[s], xc[r], proj[r]
                    for e in range(e_n):
                        dtu[e] = dt[e] * ut[e]
                        y[e] = d_i[e] * ut[e]
                    for n in range(n_n):
                        bn = p[r_n + n]
                        cn = p[r_n + n_n + n]
                        if c_shift.shape[0] > 0:
                            cn += c_shift[b, n]
                        hn, es_n = h[n], es[s, n]
                        for e in range(e_n):
                            v = es_n[e] * hn[e] + dtu[e] * bn
                            hn[e] = v
                            y[e] += v * cn
                    o = out[b, t]
                    for e in range(e_n):
                        o[e] += m_i[e] * y[e]
        if gate_off >= 0:
            for b in prange(b_n):
                tmp = np.empty(le, dtype=x.dtype)
                k32 = np.empty(le, dtype=np.int32)
                z = np.empty((l_n, e_n), dtype=x.dtype)
                for t in range(l_n):
                    src, zt = x[b, t, gate_off : gate_off + e_n], z[t]
                    for e in range(e_n):
                        zt[e] = src[e]
                _silu_inplace(z.reshape(le), tmp, k32, c)
                for t in range(l_n):
                    o, zt = out[b, t], z[t]
                    for e in range(e_n):
                        o[e] *= zt[e]

    _KERNEL = numba_kernels.builds(_mixer)


class _Views:
    """An SSM's parameters as arrays over their own memory, shaped as the kernel reads them.
    Nothing is copied or precomputed, so no change of the weights can leave them stale (an
    in-place ``.data`` write, a fused optimiser step, a loaded state dict); they are rebuilt
    only when a parameter is replaced by another tensor (``.to()``, a deep copy)."""

    def __init__(self, ssm, mix: torch.Tensor | None) -> None:
        k, e, n = ssm.k, ssm.d_inner, ssm.cfg.d_state
        self.key = _key(ssm, mix)
        self.conv_w = _np(ssm.conv_weight.view(k, e, -1))
        self.conv_b = _np(ssm.conv_bias.view(k, e))
        self.wx = _np(ssm.x_proj)
        self.wdt = _np(ssm.dt_proj)
        self.dt_bias = _np(ssm.dt_bias)
        self.A_log = _np(ssm.A_log.view(k, e, n))
        self.D = _np(ssm.D.view(k, e))
        self.mix = _np(mix) if mix is not None else np.ones((k, e), np.float32)
        self.rev = np.array(ssm._reversed, dtype=np.int64)


def _key(ssm, mix: torch.Tensor | None) -> tuple:
    params = (ssm.conv_weight, ssm.conv_bias, ssm.x_proj, ssm.dt_proj, ssm.dt_bias, ssm.A_log, ssm.D, mix)
    return tuple(p.data_ptr() if p is not None else 0 for p in params)


_EMPTY3 = _NO_SHIFT[torch.float32]
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


def _views(ssm, mix: torch.Tensor | None) -> _Views:
    cached = getattr(ssm, "_fused_views", None)
    if cached is None or cached.key != _key(ssm, mix):
        cached = _Views(ssm, mix)
        ssm._fused_views = cached  # plain attribute: not a parameter, not in the state dict
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
    w = _views(ssm, mix)
    e = ssm.d_inner
    lo = 0 if e_range is None else e_range[0]
    # the kernel does not check bounds: what it would read past is refused here
    bsz, L = x.shape[0], x.shape[1]
    if x.dim() != 3 or lo < 0 or x.shape[2] < lo + e or (gate_from is not None and x.shape[2] < gate_from + e):
        raise ValueError(f"x {tuple(x.shape)} does not hold {e} input (and gate) channels where asked")
    if a_shift is not None and tuple(a_shift.shape) != (bsz, L, e):
        raise ValueError(f"a_shift must be (B, L, E) = {(bsz, L, e)}, not {tuple(a_shift.shape)}")
    if c_shift is not None and tuple(c_shift.shape) != (bsz, ssm.cfg.d_state):
        raise ValueError(f"c_shift must be (B, N) = {(bsz, ssm.cfg.d_state)}, not {tuple(c_shift.shape)}")
    if mix is not None and tuple(mix.shape) != (ssm.k, e):
        raise ValueError(f"mix must be (k, E) = {(ssm.k, e)}, not {tuple(mix.shape)}")
    xn = _np(x)
    out = np.zeros((x.shape[0], x.shape[1], e), np.float32)
    shift = _np(a_shift) if a_shift is not None else _EMPTY3
    cs = _np(c_shift) if c_shift is not None else _EMPTY2
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
        w.A_log,
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
