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
- The decays exp(delta_t A) are computed ahead by torch, a few samples at a time into one
  reused buffer laid out (b, L, N, D). numba's exp is a scalar libm call (this numba has no
  SVML); torch's is vectorised, 0.7 ns an element in a buffer that stays mapped (a fresh
  64 MB tensor per call spent more in page faults than in exp).
- The innermost loop runs over the channels of one state index n and one group of B and
  C, on 1-D slices: contiguous, no loop-carried dependence, so LLVM vectorises it (AVX-512
  here). It did not while indices ran over ``range(lo, hi)``: numba's negative-index
  wrap-around made every address a select. The old walk (channels outer, the N states
  inner, scalar exp) took 0.7 ns forward and 3.4 backward, given the decays; this one 0.17
  and 0.9. A Motion Mamba training step at batch 64 went from 3.6-4.6 s to 2.6-3.6 s
  (``train step-time``, alternating runs on the 2-core machine beside two training jobs;
  the baseline's, which has no scan, stayed at 1.0-1.2 s).
- ``fastmath`` (``numba_kernels.FASTMATH``) lets LLVM contract multiply-adds and vectorise
  the sums over a group's channels (dB, dC).

Backward, with g the incoming gradient of y and q_t = dL/dh_t:
    q_t = g_t C_t + exp(delta_{t+1} A) q_{t+1}
    dC_t += g_t h_t    dB_t += q_t delta_t u_t    du_t += <q_t, delta_t B_t> + g_t D
    ddelta_t += <q_t, u_t B_t + A exp(delta_t A) h_{t-1}>    dA += q_t delta_t exp(delta_t A) h_{t-1}

A may be (D, N), or (B, L, D, N) for FTMoMamba's per-step state matrix. Samples run in
parallel (``numba.prange``) on as many threads as torch uses, the serial build for one
(``numba_kernels``: why numba's thread pool must not start in a one-thread process). Two
"one-thread" training jobs on the 2-core machine took 8 s (Motion Mamba) and 6 s
(FTMoMamba) a step while it did, 2.4 s and 1.9 s without.
Float32 and float64; dA's per-sample sums are added over the batch in float64, dD's in float64.

``available()`` is False when numba does not import; ``ssm.selective_scan`` then keeps to
the eager scans. The first call in a process compiles (a few seconds; numba caches the
machine code on disk for the next process).
"""

from __future__ import annotations

import numpy as np
import torch

from . import numba_kernels
from .numba_kernels import available

try:
    from numba import prange
except ImportError:  # optional: the eager scans cover every case
    prange = range

__all__ = ["available", "scan_compiled"]


if available():

    def _forward(u, delta, dA, Bm, Cm, Dv, y):  # pragma: no cover - compiled
        """u, delta, y: (B, L, D); dA = exp(delta_t A): (B, L, N, D); Bm, Cm: (B, L, G, N)."""
        b_n, l_n, d_n = u.shape
        g_n, n_n = Bm.shape[2], Bm.shape[3]
        pg = d_n // g_n
        for b in prange(b_n):
            h = np.zeros((n_n, d_n), dtype=u.dtype)
            dtu = np.empty(d_n, dtype=u.dtype)
            for t in range(l_n):
                ut, dt, yt = u[b, t], delta[b, t], y[b, t]
                for d in range(d_n):
                    dtu[d] = dt[d] * ut[d]
                    yt[d] = Dv[d] * ut[d]
                for g in range(g_n):
                    lo = g * pg
                    x, acc = dtu[lo : lo + pg], yt[lo : lo + pg]
                    for n in range(n_n):
                        bg, cg = Bm[b, t, g, n], Cm[b, t, g, n]
                        hn, e = h[n, lo : lo + pg], dA[b, t, n, lo : lo + pg]
                        for i in range(pg):
                            v = e[i] * hn[i] + x[i] * bg
                            hn[i] = v
                            acc[i] += v * cg

    def _backward(u, delta, dA, At, Bm, Cm, Dv, gy, gu, gdelta, gAt, gB, gC, gD):  # pragma: no cover
        """As ``_forward``, with At: A as (1, 1, N, D) or per step (B, L, N, D), and the
        gradients: gu, gdelta (B, L, D) written; gAt (B, 1 or L, N, D), gB, gC, gD (B, D)
        added to (zeroed by the caller)."""
        b_n, l_n, d_n = u.shape
        g_n, n_n = Bm.shape[2], Bm.shape[3]
        pg = d_n // g_n
        # 1 where A varies per sample and step, else 0: index arithmetic, because under
        # ``parallel`` numba typed ``b if per_step else 0`` as a float
        per_step = 1 if At.shape[1] > 1 else 0
        for b in prange(b_n):
            ab = b * per_step
            hs = np.zeros((l_n + 1, n_n, d_n), dtype=u.dtype)  # hs[t + 1] = h_t, hs[0] = 0
            dtu = np.empty(d_n, dtype=u.dtype)
            for t in range(l_n):
                ut, dt = u[b, t], delta[b, t]
                for d in range(d_n):
                    dtu[d] = dt[d] * ut[d]
                for g in range(g_n):
                    lo = g * pg
                    x = dtu[lo : lo + pg]
                    for n in range(n_n):
                        bg = Bm[b, t, g, n]
                        h0, h1 = hs[t, n, lo : lo + pg], hs[t + 1, n, lo : lo + pg]
                        e = dA[b, t, n, lo : lo + pg]
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
                        c, bn = Cm[b, t, g, n], Bm[b, t, g, n]
                        qn, e = q[n, lo:hi], dA[b, t, n, lo:hi]
                        h0, h1 = hs[t, n, lo:hi], hs[t + 1, n, lo:hi]
                        a, ga = At[ab, at, n, lo:hi], gAt[b, at, n, lo:hi]
                        sc = h0[0] * 0  # the array's dtype: a float64 sum would halve the vector width
                        sb = h0[0] * 0
                        for i in range(pg):
                            v = qn[i] + gt[i] * c  # q_t
                            sc += gt[i] * h1[i]
                            sb += v * x[i]
                            g_u[i] += v * dt[i] * bn
                            w = v * e[i] * h0[i]  # dL/d(delta_t * A) through exp
                            g_dt[i] += v * ut[i] * bn + w * a[i]
                            ga[i] += w * dt[i]
                            qn[i] = v * e[i]  # carried to t - 1
                        gC[b, t, g, n] += sc
                        gB[b, t, g, n] += sb


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


# The decays are computed this many (B, L, N, D) elements at a time at most (4 MiB of
# float32), into one buffer: a whole training batch's would be hundreds of MB of fresh pages
# per scan. At least as many samples as threads, so that each runs one.
DECAYS_CHUNK_NUMEL = 1 << 20


def _chunks(u: torch.Tensor, n: int):
    """Slices of the batch whose decays fit ``DECAYS_CHUNK_NUMEL``, and one buffer for them."""
    b, length, d = u.shape
    per_sample = length * d * n
    size = min(b, max(numba_kernels.threads(), DECAYS_CHUNK_NUMEL // per_sample, 1))
    buf = torch.empty(size, length, n, d, dtype=u.dtype)
    return [slice(i, min(b, i + size)) for i in range(0, b, size)], buf


def _transposed_a(A: torch.Tensor) -> torch.Tensor:
    """A laid out as the kernels read it: (D, N) -> (1, 1, N, D); (B, L, D, N) -> (B, L, N, D)."""
    return A.detach().t().contiguous()[None, None] if A.dim() == 2 else A.detach().transpose(2, 3).contiguous()


def _decays(delta: torch.Tensor, At: torch.Tensor, rows: slice, buf: torch.Tensor) -> np.ndarray:
    """exp(delta_t A) of the samples ``rows`` into ``buf``: (b, L, N, D)."""
    out = buf[: rows.stop - rows.start]
    a = At if At.shape[0] == 1 else At[rows]
    torch.mul(delta[rows].unsqueeze(2), a, out=out)
    return out.exp_().numpy()


class _Scan(torch.autograd.Function):
    @staticmethod
    def forward(ctx, u, delta, A, Bm, Cm, D):  # type: ignore[override]
        Dv = D if D is not None else torch.zeros(u.shape[-1], dtype=u.dtype)
        ctx.save_for_backward(u, delta, A, Bm, Cm, Dv)
        ctx.has_d = D is not None
        return _scan_forward(u, delta, A, Bm, Cm, Dv)

    @staticmethod
    def backward(ctx, gy):  # type: ignore[override]
        u, delta, A, Bm, Cm, Dv = ctx.saved_tensors
        with torch.no_grad():
            return _scan_backward(u, delta, A, Bm, Cm, Dv, gy, ctx.has_d)


def _scan_backward(u, delta, A, Bm, Cm, Dv, gy, has_d: bool):
    per_step = A.dim() == 4
    b, length, d = u.shape
    n = A.shape[-1]
    un, deltan, bn, cn, dn, gyn = (_np(x) for x in (u, delta, Bm, Cm, Dv, gy))
    delta = delta.detach()
    At = _transposed_a(A)
    Atn = At.numpy()
    gu, gdelta = np.empty_like(un), np.empty_like(un)
    # per-sample partial sums of the parameters' gradients (no two threads write one cell)
    gAt = np.zeros((b, length if per_step else 1, n, d), dtype=un.dtype)
    gB, gC = np.zeros(bn.shape, un.dtype), np.zeros(cn.shape, un.dtype)
    gD = np.zeros((b, d), np.float64)
    rows_list, buf = _chunks(u, n)
    for r in rows_list:
        dA = _decays(delta, At, r, buf)
        a = Atn if not per_step else Atn[r]
        _run(1, un[r], deltan[r], dA, a, bn[r], cn[r], dn, gyn[r], gu[r], gdelta[r], gAt[r], gB[r], gC[r], gD[r])
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
    )


def scan_compiled(u, delta, A, Bm, Cm, D=None):
    """Compiled selective scan on CPU tensors; same arguments and result as ``scan_sequential``."""
    if not available():
        raise RuntimeError("the compiled scan needs numba (pip install numba)")
    if u.is_cuda:
        raise ValueError("the compiled scan runs on the CPU")
    if u.shape[2] % Bm.shape[2]:
        raise ValueError(f"{u.shape[2]} channels cannot be split into {Bm.shape[2]} groups")
    dtype = u.dtype
    args = [t if t is None or t.dtype == dtype else t.to(dtype) for t in (u, delta, A, Bm, Cm, D)]
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
) -> torch.Tensor:
    """The compiled forward pass alone; shapes as ``scan_compiled``."""
    Dv = D if D is not None else torch.zeros(u.shape[-1], dtype=u.dtype)
    un, deltan, bn, cn, dn = (_np(x) for x in (u, delta, Bm, Cm, Dv))
    y = np.empty(un.shape, dtype=un.dtype)
    rows_list, buf = _chunks(u, A.shape[-1])
    with torch.no_grad():
        At = _transposed_a(A)
        for r in rows_list:
            _run(0, un[r], deltan[r], _decays(delta.detach(), At, r, buf), bn[r], cn[r], dn, y[r])
    return torch.from_numpy(y)
