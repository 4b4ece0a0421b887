"""The selective scan as compiled loops (numba): the CPU's fast path, forward and backward.

Same recurrence, arguments and result as ``ssm.scan_sequential``:

    h_t = exp(delta_t * A) * h_{t-1} + delta_t * B_t * u_t,    y_t = <C_t, h_t> + D * u_t

Why: on the CPU the eager scans spend their time in thousands of small tensor ops, each a
pass over (B, D, N) memory; a Motion Mamba training step on a 56-token latent took ~15 s at
batch 64, nearly all of it in the scans' element-wise ops (torch profiler: ``mul`` and
``sum``, 30,000 and 11,000 calls). Here every (sample, channel) keeps its N states in
registers and walks the sequence once; the backward walks it back, recomputing the states
from the forward's inputs rather than storing a (B, L, D, N) tensor.

Backward, with g the incoming gradient of y and q_t = dL/dh_t:
    q_t = g_t C_t + exp(delta_{t+1} A) q_{t+1}
    dC_t += g_t h_t    dB_t += q_t delta_t u_t    du_t += <q_t, delta_t B_t> + g_t D
    ddelta_t += <q_t, u_t B_t + A exp(delta_t A) h_{t-1}>    dA += q_t delta_t exp(delta_t A) h_{t-1}

A may be (D, N), or (B, L, D, N) for FTMoMamba's per-step state matrix. Samples run in
parallel (``numba.prange``) on as many threads as torch uses; with one torch thread the
same loops run compiled without ``parallel``, so numba never starts its thread pool. Two
things went wrong while every process started it: its OpenMP layer's idle worker
spin-waited (half a core per process), and starting the pool set OpenMP's thread count,
torch's included, to the pool's size, so a process pinned to one torch thread ran on two
after its first scan. Two "one-thread" training jobs on the 2-core machine took 8 s
(Motion Mamba) and 6 s (FTMoMamba) a step that way, 2.4 s and 1.9 s with neither. Where
more than one thread is wanted, torch's count is restored after each parallel call.
Float32 and float64; the sums over time of dA and dD accumulate in float64.

``available()`` is False when numba does not import; ``ssm.selective_scan`` then keeps to
the eager scans. The first call in a process compiles (a few seconds; numba caches the
machine code on disk for the next process).
"""

from __future__ import annotations

import math
import types
from collections.abc import Callable

import numpy as np
import torch

try:
    import numba
    from numba import prange
except ImportError:  # optional: the eager scans cover every case
    numba = None


def available() -> bool:
    return numba is not None


if numba is not None:

    def _forward(u, delta, A, per_step, Bm, Cm, Dv, y):  # pragma: no cover - compiled
        b_n, l_n, d_n = u.shape
        n_n = Bm.shape[3]
        per_group = d_n // Bm.shape[2]
        for b in prange(b_n):
            h = np.zeros(n_n, dtype=u.dtype)
            for d in range(d_n):
                g = d // per_group
                h[:] = 0.0
                for t in range(l_n):
                    dt = delta[b, t, d]
                    ut = u[b, t, d]
                    acc = 0.0
                    for n in range(n_n):
                        a = A[b, t, d, n] if per_step else A[0, 0, d, n]
                        h[n] = math.exp(dt * a) * h[n] + dt * ut * Bm[b, t, g, n]
                        acc += h[n] * Cm[b, t, g, n]
                    y[b, t, d] = acc + Dv[d] * ut

    def _forward_decayed(u, delta, dA, Bm, Cm, Dv, y):  # pragma: no cover - compiled
        """The forward walk with every exp(delta_t A) given, dA: (B, L, D, N), and time outer:
        inference's path (see ``_scan_forward``)."""
        b_n, l_n, d_n = u.shape
        n_n = Bm.shape[3]
        per_group = d_n // Bm.shape[2]
        for b in prange(b_n):
            h = np.zeros((d_n, n_n), dtype=u.dtype)
            for t in range(l_n):
                for d in range(d_n):
                    g = d // per_group
                    ut = u[b, t, d]
                    dtu = delta[b, t, d] * ut
                    acc = 0.0
                    for n in range(n_n):
                        hn = dA[b, t, d, n] * h[d, n] + dtu * Bm[b, t, g, n]
                        h[d, n] = hn
                        acc += hn * Cm[b, t, g, n]
                    y[b, t, d] = acc + Dv[d] * ut

    def _backward(u, delta, A, per_step, Bm, Cm, Dv, gy, gu, gdelta, gA, gB, gC, gD):  # pragma: no cover
        b_n, l_n, d_n = u.shape
        n_n = Bm.shape[3]
        per_group = d_n // Bm.shape[2]
        for b in prange(b_n):
            hs = np.zeros((l_n + 1, n_n), dtype=u.dtype)  # hs[t + 1] = h_t, hs[0] = 0
            es = np.empty((l_n, n_n), dtype=u.dtype)  # exp(delta_t A), kept for the reverse walk
            q = np.zeros(n_n, dtype=u.dtype)
            for d in range(d_n):
                g = d // per_group
                for t in range(l_n):
                    dt = delta[b, t, d]
                    ut = u[b, t, d]
                    for n in range(n_n):
                        a = A[b, t, d, n] if per_step else A[0, 0, d, n]
                        es[t, n] = math.exp(dt * a)
                        hs[t + 1, n] = es[t, n] * hs[t, n] + dt * ut * Bm[b, t, g, n]
                q[:] = 0.0
                for t in range(l_n - 1, -1, -1):
                    dt = delta[b, t, d]
                    ut = u[b, t, d]
                    gt = gy[b, t, d]
                    gD[b, d] += gt * ut
                    g_u = gt * Dv[d]
                    g_dt = 0.0
                    for n in range(n_n):
                        a = A[b, t, d, n] if per_step else A[0, 0, d, n]
                        e = es[t, n]
                        gC[b, t, g, n] += gt * hs[t + 1, n]
                        qn = q[n] + gt * Cm[b, t, g, n]
                        bn = Bm[b, t, g, n]
                        gB[b, t, g, n] += qn * dt * ut
                        g_u += qn * dt * bn
                        w = qn * e * hs[t, n]  # dL/d(delta_t * A) through exp
                        g_dt += qn * ut * bn + w * a
                        if per_step:
                            gA[b, t, d, n] = w * dt
                        else:
                            gA[b, 0, d, n] += w * dt
                        q[n] = qn * e
                    gu[b, t, d] = g_u
                    gdelta[b, t, d] = g_dt


if numba is not None:

    def _jit(fn: types.FunctionType, parallel: bool) -> Callable:
        """``fn`` compiled with or without ``parallel``, under a name of its own: numba's disk
        cache is keyed by the function's name, and the two builds must not share an entry."""
        name = f"{fn.__name__}_{'parallel' if parallel else 'serial'}"
        copy = types.FunctionType(fn.__code__.replace(co_name=name, co_qualname=name), fn.__globals__, name)
        copy.__qualname__ = name
        return numba.njit(parallel=parallel, cache=True)(copy)

    _KERNELS = {
        parallel: (_jit(_forward, parallel), _jit(_backward, parallel), _jit(_forward_decayed, parallel))
        for parallel in (False, True)
    }


def _as4(A: torch.Tensor) -> tuple[np.ndarray, bool]:
    """A as a 4-D array (a (D, N) matrix as (1, 1, D, N)) and whether it varies per step."""
    if A.dim() == 2:
        return _np(A)[None, None], False
    return _np(A), True


def _np(x: torch.Tensor) -> np.ndarray:
    """The tensor's memory as an array; detach and copy only where needed (each is a
    dispatched op, and a sampling step makes a dozen scans of six tensors)."""
    if x.requires_grad:
        x = x.detach()
    return (x if x.is_contiguous() else x.contiguous()).numpy()


def _run(which: int, *arrays) -> None:
    """Kernel ``which`` (0 forward, 1 backward, 2 forward with the decays given) on as many
    threads as torch's intra-op pool (training jobs pin one per process): the serial build
    for one, else the parallel one on that many, with torch's thread count put back
    afterwards (the pool's start sets it)."""
    torch_threads = torch.get_num_threads()
    threads = max(1, min(torch_threads, numba.config.NUMBA_NUM_THREADS))
    if threads == 1:
        _KERNELS[False][which](*arrays)
        return
    numba.set_num_threads(threads)
    try:
        _KERNELS[True][which](*arrays)
    finally:
        if torch.get_num_threads() != torch_threads:
            torch.set_num_threads(torch_threads)


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
        un = _np(u)
        A4, per_step = _as4(A)
        b, length, d = u.shape
        gu, gdelta = np.empty_like(un), np.empty_like(un)
        # per-sample partial sums of the parameters' gradients (no two threads write one cell)
        gA = np.zeros((b, length if per_step else 1, d, A.shape[-1]), dtype=np.float64 if not per_step else un.dtype)
        gB, gC = np.zeros(Bm.shape, un.dtype), np.zeros(Cm.shape, un.dtype)
        gD = np.zeros((b, d), np.float64)
        gy_np = _np(gy)
        _run(1, un, _np(delta), A4, per_step, _np(Bm), _np(Cm), _np(Dv), gy_np, gu, gdelta, gA, gB, gC, gD)
        grad_a = torch.from_numpy(gA) if per_step else torch.from_numpy(gA.sum((0, 1))).to(A.dtype)
        grad_d = torch.from_numpy(gD.sum(0)).to(u.dtype) if ctx.has_d else None
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
    if numba is None:
        raise RuntimeError("the compiled scan needs numba (pip install numba)")
    if u.is_cuda:
        raise ValueError("the compiled scan runs on the CPU")
    if u.shape[2] % Bm.shape[2]:
        raise ValueError(f"{u.shape[2]} channels cannot be split into {Bm.shape[2]} groups")
    dtype = u.dtype
    args = [t if t is None or t.dtype == dtype else t.to(dtype) for t in (u, delta, A, Bm, Cm, D)]
    if torch.is_grad_enabled() and any(t is not None and t.requires_grad for t in args):
        return _Scan.apply(*args)
    return _scan_forward(*args, decays_first=True)  # nothing to differentiate: no autograd node, no saved tensors


# The largest (B, L, D, N) decay tensor the forward computes ahead (64 MiB of float32): a
# sampling call's is under 2 MiB, a training batch's could be hundreds.
DECAYS_MAX_NUMEL = 1 << 24


def _scan_forward(
    u: torch.Tensor,
    delta: torch.Tensor,
    A: torch.Tensor,
    Bm: torch.Tensor,
    Cm: torch.Tensor,
    D: torch.Tensor | None,
    decays_first: bool = False,
) -> torch.Tensor:
    """The compiled forward pass alone; shapes as ``scan_compiled``.

    ``decays_first``: compute every exp(delta_t A) at once as one torch op, then walk. The
    walk's scalar exp was most of a sampling scan's time (numba does not vectorise it here;
    torch's exp is vectorised): a (1, 256, 208) x 4-state scan of Motion Mamba's BSM took
    600 us, 455 this way. Not for training, whose backward recomputes the decays in its own
    walk, nor where the decays would exceed ``DECAYS_MAX_NUMEL``. Same result to float
    rounding (torch's exp and libm's may differ in the last bit)."""
    Dv = D if D is not None else torch.zeros(u.shape[-1], dtype=u.dtype)
    un = _np(u)
    y = np.empty(un.shape, dtype=un.dtype)
    b, length, d = u.shape
    if decays_first and b * length * d * A.shape[-1] <= DECAYS_MAX_NUMEL:
        dA = torch.exp(delta.unsqueeze(-1) * A)  # A: (D, N) broadcasts, (B, L, D, N) matches
        _run(2, un, _np(delta), _np(dA), _np(Bm), _np(Cm), _np(Dv), y)
        return torch.from_numpy(y)
    A4, per_step = _as4(A)
    _run(0, un, _np(delta), A4, per_step, _np(Bm), _np(Cm), _np(Dv), y)
    return torch.from_numpy(y)
