"""The selective scan as one fused GPU kernel (Triton), forward and backward: the GPU's fast
path where the CUDA kernel of ``mamba-ssm`` is not installed.

Same recurrence, arguments and result as ``ssm.scan_sequential``:

    h_t = exp(delta_t * A) * h_{t-1} + delta_t * B_t * u_t,    y_t = <C_t, h_t> + D * u_t

Why: without it a GPU ran the chunked log-space scan, which materialises several
(B, K, D, N) tensors per chunk and, where a trained model's decay is steep, falls back to
short chunks or the per-step loop (``chunk_size_for``). The shipped Motion Mamba's scans
take chunks of 1, 2 and 8 of its 52 tokens, FTMoMamba's FreqSSM scans chunks of 1: a
training step at batch 256 on an H200 took 0.23 s (Motion Mamba) and 0.20 s (FTMoMamba)
in the loop against 0.15 and 0.07 with the freshly initialised weights that
``train step-time`` builds. Here one program per (sample, block of channels) keeps the
block's N states in registers and walks the sequence once, as the numba kernel does on the
CPU (``scan_compiled``); nothing decays out of range, so no chunking.

The forward stores every step's state (B, L + 1, D, N) when a gradient is wanted; the backward
walks the sequence back with the states read from it (``scan_compiled``'s docstring has
the backward's equations). Per-channel partial gradients of B and C are summed over each
group's channels afterwards, and A's and D's over samples, so no two programs write one
cell.

Float32 only, N a power of two (Triton's block shapes); ``supported`` says whether a call
qualifies, and ``ssm.selective_scan`` uses the chunked scan otherwise. Tested on the CPU
with Triton's interpreter (``TRITON_INTERPRET=1``), which runs these kernels in NumPy.
"""

from __future__ import annotations

import torch

try:
    import triton
    import triton.language as tl
except ImportError:  # optional: the GPU then runs the chunked scan
    triton = None

BLOCK_D = 32


def available() -> bool:
    return triton is not None


def supported(u: torch.Tensor, A: torch.Tensor, Bm: torch.Tensor) -> bool:
    """Whether this kernel takes these inputs: float32 with a power-of-two state size (the
    other inputs are cast to u's dtype, as the numba scan does)."""
    n = A.shape[-1]
    return triton is not None and u.dtype == torch.float32 and n >= 1 and n & (n - 1) == 0


if triton is not None:

    @triton.jit
    def _forward_kernel(
        u_ptr,
        dt_ptr,
        a_ptr,
        b_ptr,
        c_ptr,
        dv_ptr,
        y_ptr,
        h_ptr,
        L,
        D,
        G,
        per_group,
        PER_STEP: tl.constexpr,
        STORE_H: tl.constexpr,
        N: tl.constexpr,
        BD: tl.constexpr,
    ):  # pragma: no cover - compiled (the interpreter runs it in the tests)
        b = tl.program_id(0).to(tl.int64)
        d = tl.program_id(1) * BD + tl.arange(0, BD)
        dm = d < D
        n = tl.arange(0, N)
        m2 = dm[:, None] & (n[None, :] < N)
        g = d // per_group
        a = tl.load(a_ptr + d[:, None] * N + n[None, :], mask=m2, other=0.0)
        dv = tl.load(dv_ptr + d, mask=dm, other=0.0)
        h = tl.zeros((BD, N), dtype=tl.float32)
        for t in range(L):
            row = b * L + t
            ut = tl.load(u_ptr + row * D + d, mask=dm, other=0.0)
            dt = tl.load(dt_ptr + row * D + d, mask=dm, other=0.0)
            if PER_STEP:
                a = tl.load(a_ptr + (row * D + d)[:, None] * N + n[None, :], mask=m2, other=0.0)
            bt = tl.load(b_ptr + (row * G + g)[:, None] * N + n[None, :], mask=m2, other=0.0)
            ct = tl.load(c_ptr + (row * G + g)[:, None] * N + n[None, :], mask=m2, other=0.0)
            h = tl.exp(dt[:, None] * a) * h + (dt * ut)[:, None] * bt
            tl.store(y_ptr + row * D + d, tl.sum(h * ct, axis=1) + dv * ut, mask=dm)
            if STORE_H:  # hs[b, t + 1] = h_t (hs[b, 0] = 0, set by the caller)
                tl.store(h_ptr + ((row + b + 1) * D + d)[:, None] * N + n[None, :], h, mask=m2)

    @triton.jit
    def _backward_kernel(
        u_ptr,
        dt_ptr,
        a_ptr,
        b_ptr,
        c_ptr,
        dv_ptr,
        h_ptr,
        gy_ptr,
        gu_ptr,
        gdt_ptr,
        ga_ptr,
        gb_ptr,
        gc_ptr,
        gd_ptr,
        L,
        D,
        G,
        per_group,
        PER_STEP: tl.constexpr,
        N: tl.constexpr,
        BD: tl.constexpr,
    ):  # pragma: no cover - compiled (the interpreter runs it in the tests)
        b = tl.program_id(0).to(tl.int64)
        d = tl.program_id(1) * BD + tl.arange(0, BD)
        dm = d < D
        n = tl.arange(0, N)
        m2 = dm[:, None] & (n[None, :] < N)
        g = d // per_group
        a = tl.load(a_ptr + d[:, None] * N + n[None, :], mask=m2, other=0.0)
        dv = tl.load(dv_ptr + d, mask=dm, other=0.0)
        q = tl.zeros((BD, N), dtype=tl.float32)  # dLoss/dh_t, carried backwards
        ga = tl.zeros((BD, N), dtype=tl.float32)
        gd = tl.zeros((BD,), dtype=tl.float32)
        for i in range(L):
            t = L - 1 - i
            row = b * L + t
            cell = (row * D + d)[:, None] * N + n[None, :]
            ut = tl.load(u_ptr + row * D + d, mask=dm, other=0.0)
            dt = tl.load(dt_ptr + row * D + d, mask=dm, other=0.0)
            gt = tl.load(gy_ptr + row * D + d, mask=dm, other=0.0)
            if PER_STEP:
                a = tl.load(a_ptr + cell, mask=m2, other=0.0)
            bt = tl.load(b_ptr + (row * G + g)[:, None] * N + n[None, :], mask=m2, other=0.0)
            ct = tl.load(c_ptr + (row * G + g)[:, None] * N + n[None, :], mask=m2, other=0.0)
            h_at = ((row + b) * D + d)[:, None] * N + n[None, :]  # hs[b, t] = h_{t-1}
            h_prev = tl.load(h_ptr + h_at, mask=m2, other=0.0)
            h = tl.load(h_ptr + h_at + D * N, mask=m2, other=0.0)
            e = tl.exp(dt[:, None] * a)
            tl.store(gc_ptr + cell, gt[:, None] * h, mask=m2)
            qn = q + gt[:, None] * ct
            tl.store(gb_ptr + cell, qn * (dt * ut)[:, None], mask=m2)
            w = qn * e * h_prev  # dLoss/d(delta_t * A) through exp
            tl.store(gu_ptr + row * D + d, gt * dv + tl.sum(qn * bt, axis=1) * dt, mask=dm)
            tl.store(gdt_ptr + row * D + d, tl.sum(qn * bt * ut[:, None] + w * a, axis=1), mask=dm)
            if PER_STEP:
                tl.store(ga_ptr + cell, w * dt[:, None], mask=m2)
            else:
                ga += w * dt[:, None]
            gd += gt * ut
            q = qn * e
        if not PER_STEP:
            tl.store(ga_ptr + (b * D + d)[:, None] * N + n[None, :], ga, mask=m2)
        tl.store(gd_ptr + b * D + d, gd, mask=dm)


def _launch_forward(u, delta, A, Bm, Cm, Dv, store_h: bool):
    bsz, length, d = u.shape
    g, n = Bm.shape[2], Bm.shape[3]
    per_step = A.dim() == 4
    y = torch.empty_like(u)
    h = y  # not written unless store_h
    if store_h:  # hs[:, t + 1] = h_t, hs[:, 0] = 0: the backward reads h_{t-1} without a branch
        h = torch.empty(bsz, length + 1, d, n, dtype=u.dtype, device=u.device)
        h[:, 0].zero_()
    grid = (bsz, triton.cdiv(d, BLOCK_D))
    _forward_kernel[grid](
        u, delta, A, Bm, Cm, Dv, y, h, length, d, g, d // g, PER_STEP=per_step, STORE_H=store_h, N=n, BD=BLOCK_D
    )
    return y, (h if store_h else None)


class _Scan(torch.autograd.Function):
    @staticmethod
    def forward(ctx, u, delta, A, Bm, Cm, Dv, has_d):  # type: ignore[override]
        y, h = _launch_forward(u, delta, A, Bm, Cm, Dv, store_h=True)
        ctx.save_for_backward(u, delta, A, Bm, Cm, Dv, h)
        ctx.has_d = has_d
        return y

    @staticmethod
    def backward(ctx, gy):  # type: ignore[override]
        u, delta, A, Bm, Cm, Dv, h = ctx.saved_tensors
        bsz, length, d = u.shape
        g, n = Bm.shape[2], Bm.shape[3]
        per_step = A.dim() == 4
        gu, gdelta = torch.empty_like(u), torch.empty_like(u)
        # per-channel (B and C) and per-sample (A and D) partial sums, reduced below
        gb = torch.empty(bsz, length, d, n, dtype=u.dtype, device=u.device)
        gc = torch.empty_like(gb)
        ga = torch.empty_like(A) if per_step else torch.empty(bsz, d, n, dtype=u.dtype, device=u.device)
        gd = torch.empty(bsz, d, dtype=u.dtype, device=u.device)
        grid = (bsz, triton.cdiv(d, BLOCK_D))
        _backward_kernel[grid](
            u, delta, A, Bm, Cm, Dv, h, gy.contiguous(), gu, gdelta, ga, gb, gc, gd,
            length, d, g, d // g, PER_STEP=per_step, N=n, BD=BLOCK_D,
        )  # fmt: skip
        grad_b = gb.view(bsz, length, g, d // g, n).sum(3)
        grad_c = gc.view(bsz, length, g, d // g, n).sum(3)
        grad_a = ga if per_step else ga.sum(0)
        return gu, gdelta, grad_a, grad_b, grad_c, gd.sum(0) if ctx.has_d else None, None


def scan_triton(u, delta, A, Bm, Cm, D=None):
    """Fused selective scan; same arguments and result as ``scan_sequential``. On CUDA
    tensors, or any tensors under ``TRITON_INTERPRET=1``."""
    if triton is None:
        raise RuntimeError("the fused GPU scan needs triton (installed with torch's CUDA builds)")
    if not supported(u, A, Bm):
        raise ValueError("the fused scan takes float32 inputs with a power-of-two state size")
    if u.shape[2] % Bm.shape[2]:
        raise ValueError(f"{u.shape[2]} channels cannot be split into {Bm.shape[2]} groups")
    has_d = D is not None
    Dv = D if has_d else u.new_zeros(u.shape[-1])
    args = [x.to(u.dtype).contiguous() for x in (u, delta, A, Bm, Cm, Dv)]
    if torch.is_grad_enabled() and any(x.requires_grad for x in (u, delta, A, Bm, Cm, Dv)):
        return _Scan.apply(*args, has_d)
    return _launch_forward(*args, store_h=False)[0]
