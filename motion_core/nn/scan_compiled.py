"""The selective scan as compiled loops (numba): the CPU's fast path, forward and backward.

Same recurrence, arguments and result as ``ssm.scan_sequential``:

    h_t = exp(delta_t * A) * h_{t-1} + delta_t * B_t * u_t,    y_t = <C_t, h_t> + D * u_t

Why: on the CPU the eager scans spend their time in thousands of small tensor ops, each a
pass over (B, D, N) memory; a Motion Mamba training step on a 56-token latent took ~15 s at
batch 64, nearly all of it in the scans' element-wise ops (torch profiler: ``mul`` and
``sum``, 30,000 and 11,000 calls). Here each sample walks the sequence once with its (N, D)
state in a small array; the backward walks it back, recomputing the states from the
forward's inputs rather than keeping a (B, L, D, N) tensor from the forward.

How the walk is laid out, and why (2026-11-26; per element of (B, L, D, N), one thread):
- The innermost loop runs over the channels of one state index n and one group of B and
  C, on 1-D slices: contiguous, no loop-carried dependence, so LLVM vectorises it (AVX-512
  here). It did not while indices ran over ``range(lo, hi)``: numba's negative-index
  wrap-around made every address a select. The old walk (channels outer, the N states
  inner) took 0.7 ns forward and 3.4 backward, given the decays; this one 0.17 and 0.9.
- The decays exp(delta_t A) are computed a step at a time by a vectorised float32 exp
  (``_decays``, ``kernel_math``): numba's ``math.exp`` is a scalar libm call (this numba has no SVML),
  0.25 ns an element against 0.67 for torch's multiply and exp over a buffer.
- Training: a Motion Mamba step (``train step-time``, one thread, two training jobs on the
  other core) took 3.6-4.6 s at batch 64 with the old walk, 2.6-3.6 s with this one and
  torch's decays, 2.0 s with the kernel's exp; the baseline's, which has no scan, 1.0-1.2 s.
  Sampling: one denoiser call at batch 1 took 11.6, 9.2 and 7.7 ms.
- ``fastmath`` (``numba_kernels.FASTMATH``) lets LLVM contract multiply-adds and vectorise
  the sums over a group's channels (dB, dC).

Backward, with g the incoming gradient of y and q_t = dL/dh_t:
    q_t = g_t C_t + exp(delta_{t+1} A) q_{t+1}
    dC_t += g_t h_t    dB_t += q_t delta_t u_t    du_t += <q_t, delta_t B_t> + g_t D
    ddelta_t += <q_t, u_t B_t + A exp(delta_t A) h_{t-1}>    dA += q_t delta_t exp(delta_t A) h_{t-1}

A may be (D, N), or (B, L, D, N) for a per-step state matrix; FTMoMamba's FreqSSM passes
A (D, N) and its (B, L, D) shift instead, and the kernels build each step's matrix and its
gradient themselves (``scan_compiled``'s ``a_shift``). Samples run in
parallel (``numba.prange``) on as many threads as torch uses, the serial build for one
(``numba_kernels``: why numba's thread pool must not start in a one-thread process). Two
"one-thread" training jobs on the 2-core machine took 8 s (Motion Mamba) and 6 s
(FTMoMamba) a step while it did, 2.4 s and 1.9 s without.
Float32 and float64. A shared A's gradient is summed per sample in the input's dtype, then
over the batch in float64; D's in float64 throughout.

``available()`` is False when numba does not import; ``ssm.selective_scan`` then keeps to
the eager scans. The first call in a process compiles (a few seconds; numba caches the
machine code on disk for the next process).
"""

from __future__ import annotations

import math

import numpy as np
import torch

from . import numba_kernels
from .kernel_math import CONSTANTS, exp_constants
from .numba_kernels import available, prange

__all__ = ["available", "exp_constants", "scan_compiled"]


if available():
    from .kernel_math import _exp_inplace, _sigmoid_inplace, _softplus_inplace

    def _decays(dt, At_t, es, k32, c):  # pragma: no cover - compiled
        """es[n, d] = exp(dt[d] * A[n, d]) for one step: dt (D,), At_t (N, D), es (N, D).

        float32: ``_exp_inplace``. The models' decays are never above 1 (A < 0, delta > 0).
        float64 (the tests' references) takes libm's exp, scalar."""
        n_n, d_n = At_t.shape
        if es.itemsize == 8:
            for n in range(n_n):
                a, e = At_t[n], es[n]
                for i in range(d_n):
                    e[i] = math.exp(dt[i] * a[i])
            return
        for n in range(n_n):
            a, e = At_t[n], es[n]
            for i in range(d_n):
                e[i] = dt[i] * a[i]
            _exp_inplace(e, k32, c)

    _decays = numba_kernels.helper(_decays)

    def _shifted_state(At_t, sh, an, sg, tmp, k32, c, eps, with_sig):  # pragma: no cover - compiled
        """FreqSSM's state matrix for one step, an[n, d] = -eps - softplus(-A[n, d] - sh[d])
        (``ssm.stable_state_matrix``), and with ``with_sig`` its derivative in A and in the
        shift, sg[n, d] = sigmoid(-A[n, d] - sh[d]). At_t, an, sg: (N, D); sh, tmp, k32: (D,)."""
        n_n, d_n = At_t.shape
        for n in range(n_n):
            a, o = At_t[n], an[n]
            for d in range(d_n):
                o[d] = -a[d] - sh[d]
            if with_sig:
                s = sg[n]
                for d in range(d_n):
                    s[d] = o[d]
                _sigmoid_inplace(s, tmp, k32, c)
            _softplus_inplace(o, tmp, k32, c)
            for d in range(d_n):
                o[d] = -eps - o[d]

    _shifted_state = numba_kernels.helper(_shifted_state)

    def _forward(u, delta, At, per_step, shift, Bm, Cm, Dv, y, eps, c):  # pragma: no cover - compiled
        """u, delta, y: (B, L, D); At: A as (1, 1, N, D), or per step (B, L, N, D) with
        ``per_step`` 1 (an int for index arithmetic: under ``parallel`` numba typed
        ``b if per_step else 0`` as a float); shift: FreqSSM's (B, L, D) shift of a shared A
        (``_shifted_state``; eps its floor), or (0, 0, 0); Bm, Cm: (B, L, G, N); c:
        ``kernel_math.CONSTANTS``."""
        b_n, l_n, d_n = u.shape
        g_n, n_n = Bm.shape[2], Bm.shape[3]
        pg = d_n // g_n
        shifted = shift.shape[0] > 0
        for b in prange(b_n):
            ab = b * per_step
            h = np.zeros((n_n, d_n), dtype=u.dtype)
            es = np.empty((n_n, d_n), dtype=u.dtype)
            an = np.empty((n_n, d_n), dtype=u.dtype)
            tmp = np.empty(d_n, dtype=u.dtype)
            k32 = np.empty(d_n, dtype=np.int32)
            dtu = np.empty(d_n, dtype=u.dtype)
            for t in range(l_n):
                ut, dt, yt = u[b, t], delta[b, t], y[b, t]
                if shifted:
                    _shifted_state(At[0, 0], shift[b, t], an, an, tmp, k32, c, eps, False)
                    _decays(dt, an, es, k32, c)
                else:
                    _decays(dt, At[ab, t * per_step], es, k32, c)
                for d in range(d_n):
                    dtu[d] = dt[d] * ut[d]
                    yt[d] = Dv[d] * ut[d]
                for g in range(g_n):
                    lo = g * pg
                    x, acc = dtu[lo : lo + pg], yt[lo : lo + pg]
                    for n in range(n_n):
                        bg, cg = Bm[b, t, g, n], Cm[b, t, g, n]
                        hn, e = h[n, lo : lo + pg], es[n, lo : lo + pg]
                        for i in range(pg):
                            v = e[i] * hn[i] + x[i] * bg
                            hn[i] = v
                            acc[i] += v * cg

    def _backward(
        u, delta, At, per_step, shift, Bm, Cm, Dv, gy, eps, c, gu, gdelta, gAt, gB, gC, gD, gshift
    ):  # pragma: no cover - compiled
        """As ``_forward``, and the gradients: gu, gdelta (B, L, D) and, with a shift, gshift
        (B, L, D) written; gAt (B, 1 or L, N, D), gB, gC (B, L, G, N) and gD (B, D) added to
        (zeroed by the caller). With a shift the gradient of each step's A_n goes through
        sigmoid(-A - shift) into A's (gAt[b, 0]) and the shift's."""
        b_n, l_n, d_n = u.shape
        g_n, n_n = Bm.shape[2], Bm.shape[3]
        pg = d_n // g_n
        shifted = shift.shape[0] > 0
        for b in prange(b_n):
            ab = b * per_step
            hs = np.zeros((l_n + 1, n_n, d_n), dtype=u.dtype)  # hs[t + 1] = h_t, hs[0] = 0
            es = np.empty((l_n, n_n, d_n), dtype=u.dtype)  # the decays, kept for the walk back
            ls = l_n if shifted else 0
            ans = np.empty((ls, n_n, d_n), dtype=u.dtype)  # FreqSSM: each step's A_n ...
            sgs = np.empty((ls, n_n, d_n), dtype=u.dtype)  # ... and its derivative
            gstep = np.zeros((n_n, d_n), dtype=u.dtype)  # the gradient of one step's A_n
            tmp = np.empty(d_n, dtype=u.dtype)
            k32 = np.empty(d_n, dtype=np.int32)
            dtu = np.empty(d_n, dtype=u.dtype)
            for t in range(l_n):
                ut, dt = u[b, t], delta[b, t]
                if shifted:
                    _shifted_state(At[0, 0], shift[b, t], ans[t], sgs[t], tmp, k32, c, eps, True)
                    _decays(dt, ans[t], es[t], k32, c)
                else:
                    _decays(dt, At[ab, t * per_step], es[t], k32, c)
                for d in range(d_n):
                    dtu[d] = dt[d] * ut[d]
                for g in range(g_n):
                    lo = g * pg
                    x = dtu[lo : lo + pg]
                    for n in range(n_n):
                        bg = Bm[b, t, g, n]
                        h0, h1 = hs[t, n, lo : lo + pg], hs[t + 1, n, lo : lo + pg]
                        e = es[t, n, lo : lo + pg]
                        for i in range(pg):
                            h1[i] = e[i] * h0[i] + x[i] * bg
            q = np.zeros((n_n, d_n), dtype=u.dtype)
            for t in range(l_n - 1, -1, -1):
                at = t * per_step
                gt_all, ut_all, dt_all = gy[b, t], u[b, t], delta[b, t]
                gu_t, gdt_t = gu[b, t], gdelta[b, t]
                for d in range(d_n):
                    gD[b, d] += gt_all[d] * ut_all[d]
                    gu_t[d] = gt_all[d] * Dv[d]
                    gdt_t[d] = 0.0
                    dtu[d] = dt_all[d] * ut_all[d]
                for g in range(g_n):
                    lo, hi = g * pg, (g + 1) * pg
                    gt, ut, dt, x = gt_all[lo:hi], ut_all[lo:hi], dt_all[lo:hi], dtu[lo:hi]
                    g_u, g_dt = gu_t[lo:hi], gdt_t[lo:hi]
                    for n in range(n_n):
                        cn, bn = Cm[b, t, g, n], Bm[b, t, g, n]
                        qn, e = q[n, lo:hi], es[t, n, lo:hi]
                        h0, h1 = hs[t, n, lo:hi], hs[t + 1, n, lo:hi]
                        if shifted:
                            a, ga = ans[t, n, lo:hi], gstep[n, lo:hi]
                        else:
                            a, ga = At[ab, at, n, lo:hi], gAt[b, at, n, lo:hi]
                        sc = h0[0] * 0  # the array's dtype: a float64 sum would halve the vector width
                        sb = h0[0] * 0
                        for i in range(pg):
                            v = qn[i] + gt[i] * cn  # q_t
                            sc += gt[i] * h1[i]
                            sb += v * x[i]
                            g_u[i] += v * dt[i] * bn
                            w = v * e[i] * h0[i]  # dL/d(delta_t * A) through exp
                            g_dt[i] += v * ut[i] * bn + w * a[i]
                            ga[i] += w * dt[i]
                            qn[i] = v * e[i]  # carried to t - 1
                        gC[b, t, g, n] += sc
                        gB[b, t, g, n] += sb
                if shifted:
                    # dA_n/dA = dA_n/dshift = sigmoid(-A - shift)
                    gsh = gshift[b, t]
                    for d in range(d_n):
                        gsh[d] = 0.0
                    for n in range(n_n):
                        gs, sg, gacc = gstep[n], sgs[t, n], gAt[b, 0, n]
                        for d in range(d_n):
                            v = gs[d] * sg[d]
                            gacc[d] += v
                            gsh[d] += v
                            gs[d] = 0.0


if available():
    _KERNELS = (numba_kernels.builds(_forward), numba_kernels.builds(_backward))


def _np(x: torch.Tensor) -> np.ndarray:
    """The tensor's memory as an array; detach and copy only where needed (each is a
    dispatched op, and a sampling step makes a dozen scans of six tensors)."""
    if x.requires_grad:
        x = x.detach()
    return (x if x.is_contiguous() else x.contiguous()).numpy()


def _run(which: int, *arrays) -> None:
    """Kernel ``which`` (0 forward, 1 backward)."""
    numba_kernels.run(_KERNELS[which], *arrays)


def _transposed_a(A: torch.Tensor) -> np.ndarray:
    """A laid out as the kernels read it: (D, N) -> (1, 1, N, D); (B, L, D, N) -> (B, L, N, D)."""
    return _np(A.t())[None, None] if A.dim() == 2 else _np(A.transpose(2, 3))


#: FreqSSM's floor under its state matrix (``ssm.stable_state_matrix``)
STATE_EPS = 1e-4
_NO_SHIFT = {torch.float32: np.zeros((0, 0, 0), np.float32), torch.float64: np.zeros((0, 0, 0), np.float64)}


def _shift_arg(shift: torch.Tensor | None, dtype: torch.dtype) -> np.ndarray:
    return _NO_SHIFT[dtype] if shift is None else _np(shift)


class _Scan(torch.autograd.Function):
    @staticmethod
    def forward(ctx, u, delta, A, Bm, Cm, D, shift):  # type: ignore[override]
        Dv = D if D is not None else torch.zeros(u.shape[-1], dtype=u.dtype)
        ctx.save_for_backward(u, delta, A, Bm, Cm, Dv, shift)
        ctx.has_d = D is not None
        return _scan_forward(u, delta, A, Bm, Cm, Dv, shift)

    @staticmethod
    def backward(ctx, gy):  # type: ignore[override]
        u, delta, A, Bm, Cm, Dv, shift = ctx.saved_tensors
        with torch.no_grad():
            return _scan_backward(u, delta, A, Bm, Cm, Dv, shift, gy, ctx.has_d)


def _scan_backward(u, delta, A, Bm, Cm, Dv, shift, gy, has_d: bool):
    per_step = A.dim() == 4
    b, length, d = u.shape
    n = A.shape[-1]
    un, deltan, bn, cn, dn, gyn = (_np(x) for x in (u, delta, Bm, Cm, Dv, gy))
    gu, gdelta = np.empty_like(un), np.empty_like(un)
    # per-sample partial sums of the parameters' gradients (no two threads write one cell)
    gAt = np.zeros((b, length if per_step else 1, n, d), dtype=un.dtype)
    gB, gC = np.zeros(bn.shape, un.dtype), np.zeros(cn.shape, un.dtype)
    gD = np.zeros((b, d), np.float64)
    gshift = np.empty_like(un) if shift is not None else _NO_SHIFT[u.dtype]
    eps, consts = un.dtype.type(STATE_EPS), CONSTANTS[un.dtype]
    sh = _shift_arg(shift, u.dtype)
    _run(
        1,
        un,
        deltan,
        _transposed_a(A),
        int(per_step),
        sh,
        bn,
        cn,
        dn,
        gyn,
        eps,
        consts,
        gu,
        gdelta,
        gAt,
        gB,
        gC,
        gD,
        gshift,
    )
    if per_step:
        grad_a = torch.from_numpy(gAt).transpose(2, 3)
    else:
        grad_a = torch.from_numpy(gAt).sum((0, 1), dtype=torch.float64).t().to(A.dtype)
    grad_d = torch.from_numpy(gD.sum(0)).to(u.dtype) if has_d else None
    return (
        torch.from_numpy(gu),
        torch.from_numpy(gdelta),
        grad_a,
        torch.from_numpy(gB),
        torch.from_numpy(gC),
        grad_d,
        torch.from_numpy(gshift) if shift is not None else None,
    )


def scan_compiled(u, delta, A, Bm, Cm, D=None, a_shift=None):
    """Compiled selective scan on CPU tensors; same arguments and result as ``scan_sequential``,
    and ``a_shift`` (B, L, D): FreqSSM's shift of a shared A (D, N), the state matrix of each
    step being ``ssm.stable_state_matrix(A, a_shift[..., None])``, built a step at a time
    inside the kernel instead of as a (B, L, D, N) tensor (FTMoMamba's training step at
    batch 64 spent about a third of its time building, transposing and differentiating that
    tensor)."""
    if not available():
        raise RuntimeError("the compiled scan needs numba (pip install numba)")
    if u.device.type != "cpu":
        raise ValueError("the compiled scan runs on the CPU")
    if u.dtype not in (torch.float32, torch.float64):
        raise ValueError(f"the compiled scan takes float32 or float64, not {u.dtype}")
    if A.dim() == 4 and A.shape != (*u.shape, A.shape[-1]):
        raise ValueError(f"a per-step A must be (B, L, D, N) = {(*u.shape, A.shape[-1])}, not {tuple(A.shape)}")
    if a_shift is not None and (A.dim() != 2 or a_shift.shape != u.shape):
        raise ValueError(f"a shift of A must be (B, L, D) = {tuple(u.shape)} with A (D, N)")
    if u.shape[2] % Bm.shape[2]:
        raise ValueError(f"{u.shape[2]} channels cannot be split into {Bm.shape[2]} groups")
    dtype = u.dtype
    args = [t if t is None or t.dtype == dtype else t.to(dtype) for t in (u, delta, A, Bm, Cm, D, a_shift)]
    if torch.is_grad_enabled() and any(t is not None and t.requires_grad for t in args):
        return _Scan.apply(*args)
    return _scan_forward(*args)  # nothing to differentiate: no autograd node, no saved tensors


def _scan_forward(
    u: torch.Tensor,
    delta: torch.Tensor,
    A: torch.Tensor,
    Bm: torch.Tensor,
    Cm: torch.Tensor,
    D: torch.Tensor | None,
    shift: torch.Tensor | None = None,
) -> torch.Tensor:
    """The compiled forward pass alone; shapes as ``scan_compiled``."""
    Dv = D if D is not None else torch.zeros(u.shape[-1], dtype=u.dtype)
    un, deltan, bn, cn, dn = (_np(x) for x in (u, delta, Bm, Cm, Dv))
    y = np.empty(un.shape, dtype=un.dtype)
    eps, consts = un.dtype.type(STATE_EPS), CONSTANTS[un.dtype]
    _run(0, un, deltan, _transposed_a(A), int(A.dim() == 4), _shift_arg(shift, u.dtype), bn, cn, dn, y, eps, consts)
    return torch.from_numpy(y)
