"""Selective scan implementations agree with the sequential reference; layer shapes and
properties (causality, bidirectionality, HTM scan counts)."""

from __future__ import annotations

import pytest
import torch

from motion_core.models.denoisers import MotionMambaConfig, motion_mamba_denoiser
from motion_core.nn import ssm
from motion_core.nn.ssm import (
    SCANS,
    MambaBlock,
    SSMConfig,
    choose_scan,
    chunk_size_for,
    scan_chunked,
    scan_sequential,
    selective_scan,
)


def _inputs(bsz, L, d, n, g, dtype, seed=0, decay=2.0):
    gen = torch.Generator().manual_seed(seed)
    u = torch.randn(bsz, L, d, generator=gen, dtype=dtype)
    delta = torch.rand(bsz, L, d, generator=gen, dtype=dtype) * decay
    A = -torch.rand(d, n, generator=gen, dtype=dtype) * 4 - 0.1
    Bm = torch.randn(bsz, L, g, n, generator=gen, dtype=dtype)
    Cm = torch.randn(bsz, L, g, n, generator=gen, dtype=dtype)
    D = torch.randn(d, generator=gen, dtype=dtype)
    return [t.requires_grad_() for t in (u, delta, A, Bm, Cm, D)]


def _run(fn, args):
    y = fn(*args)
    grads = torch.autograd.grad((y * torch.cos(y)).sum(), args, allow_unused=True, materialize_grads=True)
    return y.detach(), grads


@pytest.mark.parametrize("impl", [s for s in SCANS if s not in ("sequential", "triton")])
@pytest.mark.parametrize("L", [1, 2, 5, 16, 64, 196])
def test_scans_equal_reference_float64(impl, L):
    args = _inputs(2, L, 8, 4, 2, torch.float64)
    y_ref, g_ref = _run(scan_sequential, args)
    y, g = _run(lambda *a: selective_scan(*a, impl=impl), args)
    assert (y - y_ref).abs().max() < 1e-5
    for a, b in zip(g, g_ref, strict=True):
        assert (a - b).abs().max() < 1e-5


@pytest.mark.parametrize("impl", [s for s in SCANS if s not in ("sequential", "triton")])
def test_scans_equal_reference_float32(impl):
    args = _inputs(3, 64, 16, 8, 1, torch.float32, seed=1, decay=0.3)
    y_ref, g_ref = _run(scan_sequential, args)
    y, g = _run(lambda *a: selective_scan(*a, impl=impl), args)
    assert (y - y_ref).abs().max() < 1e-5 * (1 + y_ref.abs().max())
    for a, b in zip(g, g_ref, strict=True):
        assert (a - b).abs().max() < 1e-4 * (1 + b.abs().max())


def test_chunked_splits_steep_decay_and_stays_exact():
    # decay of ~2000 nats over the sequence cannot be one float64 chunk
    args = _inputs(1, 128, 4, 4, 1, torch.float64, seed=2, decay=8.0)
    k = chunk_size_for(args[1], args[2])
    assert 1 < k < 128
    y_ref, g_ref = _run(scan_sequential, args)
    y, g = _run(scan_chunked, args)
    assert torch.isfinite(y).all()
    assert (y - y_ref).abs().max() < 1e-5
    assert max((a - b).abs().max() for a, b in zip(g, g_ref, strict=True)) < 1e-5


def test_unknown_scan_is_a_clear_error():
    args = [a.detach() for a in _inputs(1, 4, 2, 2, 1, torch.float32)]
    with pytest.raises(ValueError, match="unknown scan"):
        selective_scan(*args, impl="magic")


def test_dispatch_takes_the_compiled_scan_on_the_cpu(monkeypatch):
    used = []
    for name in SCANS:
        monkeypatch.setitem(ssm._IMPLS, name, lambda *a, name=name, **k: used.append(name) or a[0])
    args = _inputs(2, 50, 8, 4, 1, torch.float32)
    selective_scan(*args)
    with torch.no_grad():
        selective_scan(*args)
    assert used == ["compiled", "compiled"]


@pytest.mark.parametrize("per_step", [False, True])
def test_compiled_scan_is_deterministic_and_handles_groups_without_d(per_step):
    args = _inputs(3, 20, 8, 4, 2, torch.float32, seed=3)[:5]
    if per_step:  # FTMoMamba's per-step state matrix (B, L, D, N)
        args[2] = (-torch.rand(3, 20, 8, 4) * 3 - 0.1).requires_grad_()
    y_ref, g_ref = _run(scan_sequential, args)
    runs = [_run(lambda *a: selective_scan(*a, impl="compiled"), args) for _ in range(2)]
    assert torch.equal(runs[0][0], runs[1][0])
    assert all(torch.equal(a, b) for a, b in zip(runs[0][1], runs[1][1], strict=True))
    y, g = runs[0]
    assert (y - y_ref).abs().max() < 1e-5 * (1 + y_ref.abs().max())
    for a, b in zip(g, g_ref, strict=True):
        assert (a - b).abs().max() < 1e-4 * (1 + b.abs().max())


def test_compiled_scan_serial_and_parallel_builds_agree_and_keep_torchs_threads():
    # one torch thread takes the build without ``parallel``, two the prange one; starting
    # numba's pool set OpenMP's (torch's) thread count to the pool's size, which must not
    # stick. In a subprocess with a pool of 4, so that it holds on a one-core CI machine too.
    import os
    import subprocess
    import sys

    code = (
        "import torch\n"
        "from tests.test_ssm import _inputs, _run, scan_sequential\n"
        "from motion_core.nn.ssm import selective_scan\n"
        "args = _inputs(4, 30, 8, 4, 2, torch.float32, seed=5)\n"
        "ref = _run(scan_sequential, args)\n"
        "runs = []\n"
        "for threads in (1, 2):\n"
        "    torch.set_num_threads(threads)\n"
        "    runs.append(_run(lambda *a: selective_scan(*a, impl='compiled'), args))\n"
        "    assert torch.get_num_threads() == threads, torch.get_num_threads()\n"
        "(y1, g1), (y2, g2) = runs\n"
        "assert torch.equal(y1, y2) and all(torch.equal(a, b) for a, b in zip(g1, g2))\n"
        "assert (y1 - ref[0]).abs().max() < 1e-5 * (1 + ref[0].abs().max())\n"
        "assert all((a - b).abs().max() < 1e-4 * (1 + b.abs().max()) for a, b in zip(g1, ref[1]))\n"
        "print('ok')\n"
    )
    env = {**os.environ, "NUMBA_NUM_THREADS": "4"}
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env)
    assert out.returncode == 0 and out.stdout.strip() == "ok", out.stderr[-2000:]


def test_compiled_scan_without_grad_equals_its_autograd_path():
    # under no_grad the kernel runs without an autograd node (inference's path): the same walk
    args = _inputs(3, 12, 8, 4, 2, torch.float32, seed=6)
    y_grad = selective_scan(*args, impl="compiled")
    assert y_grad.requires_grad
    with torch.no_grad():
        y = selective_scan(*args, impl="compiled")
    assert not y.requires_grad and torch.allclose(y, y_grad.detach(), rtol=1e-6, atol=1e-6)
    # a non-contiguous input is copied, not misread
    u = args[0].detach().transpose(0, 1).contiguous().transpose(0, 1)
    with torch.no_grad():
        assert torch.equal(selective_scan(u, *[a.detach() for a in args[1:]], impl="compiled"), y)


@pytest.mark.parametrize("per_step", [False, True])
@pytest.mark.parametrize("dtype", [torch.float32, torch.float64])
def test_compiled_scan_with_a_per_step_state_matrix_equals_the_reference(per_step, dtype):
    """A per-step A as FTMoMamba's FreqSSM gives, in both dtypes (float32's decays come from
    the kernel's own exp, float64's from libm's)."""
    u, delta, A, Bm, Cm, D = (a.detach() for a in _inputs(5, 40, 12, 4, 3, dtype, seed=7))
    if per_step:
        A = A.expand(5, 40, 12, 4) * (1 + torch.rand(5, 40, 12, 4, dtype=dtype))
    args = [t.clone().requires_grad_() for t in (u, delta, A, Bm, Cm, D)]
    y, g = _run(lambda *a: selective_scan(*a, impl="compiled"), args)
    y_ref, g_ref = _run(scan_sequential, args)
    tol = 1e-5 if dtype == torch.float32 else 1e-12
    assert (y - y_ref).abs().max() <= tol * (1 + y_ref.abs().max())
    for a, b in zip(g, g_ref, strict=True):
        assert (a - b).abs().max() <= 10 * tol * (1 + b.abs().max())


@pytest.mark.skipif(not ssm._compiled.available(), reason="the compiled kernels need numba")
@pytest.mark.parametrize("dtype", [torch.float32, torch.float64])
def test_compiled_scan_builds_freqssms_state_matrix_itself_and_differentiates_it(dtype):
    """``a_shift``: the kernel builds stable_state_matrix(A, shift) a step at a time; values
    and gradients (the shift's and A's included) equal the reference given the built tensor.
    Shifts up to +-8 reach both sides of the softplus, A + shift near and past zero."""
    u, delta, A, Bm, Cm, D = (a.detach() for a in _inputs(4, 30, 12, 4, 3, dtype, seed=9))
    shift = 8 * torch.rand(4, 30, 12, dtype=dtype) - 4
    leaves = [t.clone().requires_grad_() for t in (u, delta, A, Bm, Cm, D, shift)]

    def compiled(u, delta, A, Bm, Cm, D, shift):
        return selective_scan(u, delta, A, Bm, Cm, D, impl="compiled", a_shift=shift)

    def reference(u, delta, A, Bm, Cm, D, shift):
        return scan_sequential(u, delta, ssm.stable_state_matrix(A, shift.unsqueeze(-1)), Bm, Cm, D)

    y, g = _run(compiled, leaves)
    y_ref, g_ref = _run(reference, leaves)
    tol = 1e-5 if dtype == torch.float32 else 1e-12
    assert (y - y_ref).abs().max() <= tol * (1 + y_ref.abs().max())
    assert len(g) == 7 and g[6].shape == shift.shape
    for a, b in zip(g, g_ref, strict=True):
        assert (a - b).abs().max() <= 10 * tol * (1 + b.abs().max())
    # the dispatcher's other scans take the same argument as a built tensor
    y_seq = selective_scan(*leaves[:6], impl="sequential", a_shift=leaves[6])
    assert (y_seq - y_ref).abs().max() <= tol * (1 + y_ref.abs().max())
    with pytest.raises(ValueError, match="shift of A must be"):
        selective_scan(*leaves[:6], impl="compiled", a_shift=leaves[6][:, :5])


@pytest.mark.skipif(not ssm._compiled.available(), reason="the compiled kernels need numba")
def test_compiled_scan_refuses_what_it_cannot_read_and_handles_one_step():
    u, delta, A, Bm, Cm, D = (a.detach() for a in _inputs(3, 1, 8, 4, 2, torch.float32, seed=8))
    A4 = A.expand(3, 1, 8, 4) * (1 + torch.rand(3, 1, 8, 4))  # per step, one step, three samples
    args = [t.clone().requires_grad_() for t in (u, delta, A4, Bm, Cm, D)]
    y, g = _run(lambda *a: selective_scan(*a, impl="compiled"), args)
    y_ref, g_ref = _run(scan_sequential, args)
    assert (y - y_ref).abs().max() < 1e-5
    assert all((a - b).abs().max() < 1e-5 for a, b in zip(g, g_ref, strict=True))
    with pytest.raises(ValueError, match="per-step A must be"):
        selective_scan(u, delta, A4[:1], Bm, Cm, D, impl="compiled")
    with pytest.raises(ValueError, match="float32 or float64"):
        selective_scan(*(t.to(torch.bfloat16) for t in (u, delta, A, Bm, Cm, D)), impl="compiled")
    # the dispatcher leaves such a dtype to the eager scans
    y16 = selective_scan(*(t.to(torch.bfloat16) for t in (u, delta, A, Bm, Cm, D)))
    assert y16.dtype == torch.bfloat16 and torch.isfinite(y16).all()


@pytest.mark.skipif(not ssm._compiled.available(), reason="the compiled kernels need numba")
def test_the_kernels_float32_exp_is_within_3e7_of_exact():
    import numpy as np

    from motion_core.nn import scan_compiled as sc

    rng = np.random.default_rng(0)
    d = 4096
    dt = np.concatenate([rng.random(d - 4) * 3, [0.0, 1.0, 1.0, 1.0]]).astype(np.float32)
    At = np.stack([-rng.random(d) * 28, rng.random(d) * 2 - 1]).astype(np.float32)  # arguments in [-84, 3]
    At[0, -3:] = [-80.0, -0.3466, 0.3466]  # near the clamp and at the reduction's edges
    es = np.empty((2, d), np.float32)
    sc._decays(dt, At, es, np.empty(d, np.int32), sc.exp_constants(np.float32))
    exact = np.exp((dt * At).astype(np.float64))  # of the float32 product, as torch's exp would be
    assert np.abs(es / exact - 1).max() < 3e-7  # 2-3 float32 ulps
    # the clamp's ends are exact to the same bound; past them the value is the end's
    x = np.array([-86.0, -85.9, 87.9, 88.0, 88.5, 1e30, -1e30], np.float32)
    out = np.empty((1, x.size), np.float32)
    sc._decays(np.ones(x.size, np.float32), x[None], out, np.empty(x.size, np.int32), sc.exp_constants(np.float32))
    want = np.exp(np.clip(x.astype(np.float64), -86.0, 88.0))
    assert np.all(np.isfinite(out)) and np.abs(out[0] / want - 1).max() < 3e-7
    # below exp(-86) the decay is exp(-86) = 4e-38, as good as zero for a state
    sc._decays(
        np.full(4, 2.0, np.float32),
        np.full((1, 4), -60.0, np.float32),
        es[:1, :4],
        np.empty(4, np.int32),
        sc.exp_constants(np.float32),
    )
    assert np.allclose(es[0, :4], np.exp(-86.0), rtol=1e-6)


def test_one_torch_thread_never_starts_numbas_thread_pool():
    # an idle worker of numba's OpenMP pool spin-waited, half a core per one-thread process
    import subprocess
    import sys

    code = (
        "import torch; torch.set_num_threads(1)\n"
        "from motion_core.nn.ssm import selective_scan\n"
        "import numba.np.ufunc.parallel as par\n"
        "u = torch.randn(2, 9, 4, requires_grad=True); A = -torch.rand(4, 3)\n"
        "bc = torch.randn(2, 9, 1, 3)\n"
        "y = selective_scan(u, torch.rand(2, 9, 4), A, bc, bc, impl='compiled')\n"
        "y.sum().backward()\n"
        "print(par._is_initialized)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


def test_dispatch_prefers_the_loop_when_the_scan_will_be_differentiated(monkeypatch):
    # without numba (the compiled scan unavailable) the eager scans are chosen by size:
    # KMM's training batch (B 32, L 50, D 128, N 8): chunked for inference, the loop for
    # training (README scan table); the choice must follow autograd, not the call site
    assert choose_scan(50, 32 * 128 * 8) == "chunked"
    assert choose_scan(50, 32 * 128 * 8, grad=True) == "sequential"
    monkeypatch.setattr(ssm._compiled, "available", lambda: False)
    used = []
    for name in SCANS:
        monkeypatch.setitem(ssm._IMPLS, name, lambda *a, name=name, **k: used.append(name) or a[0])
    args = _inputs(32, 50, 128, 8, 1, torch.float32)
    selective_scan(*args)
    with torch.no_grad():
        selective_scan(*args)
    selective_scan(*[a.detach() for a in args])
    assert used == ["sequential", "chunked", "chunked"]


def test_forward_block_is_causal_and_bidirectional_block_is_not():
    torch.manual_seed(0)
    x = torch.randn(1, 12, 16)
    x2 = x.clone()
    x2[:, 8:] += 1.0  # change the future only
    fwd = MambaBlock(16, (1,), SSMConfig(d_state=4)).eval()
    bi = MambaBlock(16, (1, -1), SSMConfig(d_state=4)).eval()
    with torch.no_grad():
        assert torch.allclose(fwd(x)[:, :8], fwd(x2)[:, :8], atol=1e-6)
        assert not torch.allclose(bi(x)[:, :8], bi(x2)[:, :8], atol=1e-4)


def test_backward_scan_equals_forward_scan_on_reversed_input():
    torch.manual_seed(0)
    blk = MambaBlock(8, (-1,), SSMConfig(d_state=4)).eval()
    ref = MambaBlock(8, (1,), SSMConfig(d_state=4)).eval()
    ref.load_state_dict(blk.state_dict())
    x = torch.randn(2, 10, 8)
    with torch.no_grad():
        assert torch.allclose(blk(x), ref(x.flip(1)).flip(1), atol=1e-6)


def test_htm_scan_counts_follow_eq6():
    cfg = MotionMambaConfig(levels=5)
    assert cfg.scan_counts() == [9, 7, 5, 3, 1]
    den = motion_mamba_denoiser(MotionMambaConfig(levels=3, htm_ssm=SSMConfig(expand=0.25, d_state=4)))
    enc = [lvl.htm.mamba.n_scans for lvl in den.body.enc]
    dec = [lvl.htm.mamba.n_scans for lvl in den.body.dec]
    assert enc == [5, 3, 1] and dec == [1, 3, 5]
    # each scan has its own A: A_log rows per block = scans * d_inner
    blk = den.body.enc[0].htm.mamba
    assert blk.ssm.A_log.shape[0] == 5 * blk.d_inner
    out = den(torch.randn(2, 2, 256), torch.tensor([10, 900]), torch.randn(2, 384), torch.tensor([40, 196]))
    assert out.shape == (2, 2, 256)


def test_causal_conv_equals_torch_conv1d():
    torch.manual_seed(0)
    blk = MambaBlock(8, (1, 1, -1), SSMConfig(d_state=4))
    ssm = blk.ssm
    x = torch.randn(2, 9, ssm.k * ssm.d_inner)
    ref = torch.nn.functional.conv1d(
        torch.nn.functional.pad(x.transpose(1, 2), (ssm.cfg.d_conv - 1, 0)),
        ssm.conv_weight,
        ssm.conv_bias,
        groups=x.shape[-1],
    ).transpose(1, 2)
    assert torch.allclose(ssm._causal_conv(x), ref, atol=1e-5)


def test_chunks_are_sized_from_the_steepest_chunk_not_the_average():
    # 200 nats of decay packed into 8 of 128 steps: sized from the average (a 32-step chunk
    # holds 50 nats on average) the chunk holding them overflowed float32's exp(-c)
    u, delta, A, Bm, Cm, D = _inputs(1, 128, 8, 4, 1, torch.float32, seed=3, decay=0.01)
    delta = delta.detach().clone()
    delta[:, 40:48] = 200.0 / 8 / (-A).amax()
    k = chunk_size_for(delta, A)
    rate = (delta[0] * (-A).amax(-1)).detach()  # (L, D) nats per step of each channel's steepest state
    for s in range(0, 128, k):
        assert float(rate[s : s + k].sum(0).amax()) <= 60.0
    y = scan_chunked(u, delta, A, Bm, Cm, D)
    y_ref = scan_sequential(u, delta, A, Bm, Cm, D)
    assert torch.isfinite(y).all()
    assert (y - y_ref).abs().max() < 1e-4 * (1 + y_ref.abs().max())


def test_forced_scan_overrides_the_dispatcher_inside_its_block_only(monkeypatch):
    monkeypatch.setattr(ssm._compiled, "available", lambda: False)
    used = []
    for name in SCANS:
        monkeypatch.setitem(ssm._IMPLS, name, lambda *a, name=name, **k: used.append(name) or a[0])
    args = _inputs(2, 50, 8, 4, 1, torch.float32)
    with torch.no_grad():
        with ssm.forced_scan("sequential"):
            selective_scan(*args)
            selective_scan(*args, impl="parallel")  # an explicit choice stays explicit
        selective_scan(*args)
    assert used == ["sequential", "parallel", "chunked"]
    with pytest.raises(ValueError, match="unknown scan"), ssm.forced_scan("magic"):
        pass


def test_eager_scans_turn_the_compiled_scan_off_inside_their_block_only(monkeypatch):
    used = []
    for name in SCANS:
        monkeypatch.setitem(ssm._IMPLS, name, lambda *a, name=name, **k: used.append(name) or a[0])
    args = _inputs(2, 50, 8, 4, 1, torch.float32)
    with torch.no_grad():
        with ssm.eager_scans():
            selective_scan(*args)
        selective_scan(*args)
    assert used == ["chunked", "compiled"]


def test_state_updates_are_counted_for_every_scan_fused_or_not():
    """B x L x D x N per scan: a block of three scans over E channels with N states counts
    3 x B x L x E x N, though outside the counter the same call takes the fused kernel
    (which passes no ``selective_scan``); a counter inside another counts its own block,
    and the outer one counts it too."""
    cfg = SSMConfig(d_state=4, expand=1.0)
    block = MambaBlock(8, (1, 1, -1), cfg).eval()
    x = torch.randn(2, 10, 8)
    calls = []
    real = ssm.selective_scan
    with torch.no_grad():
        assert block.ssm.fusable(x)  # the path the count must not miss
        fused = block(x)
        with ssm.counted_state_updates() as outer:
            assert not block.ssm.fusable(x)
            ssm.selective_scan = lambda *a, **k: calls.append(1) or real(*a, **k)
            try:
                counted = block(x)
                with ssm.counted_state_updates() as inner:
                    block(x[:1])
            finally:
                ssm.selective_scan = real
        assert inner[0] == 3 * 1 * 10 * 8 * 4
        assert outer[0] == 3 * 2 * 10 * 8 * 4 + inner[0]
        assert calls == [1, 1]
        assert block.ssm.fusable(x)  # the counter is gone: back to the fused kernel
    assert torch.allclose(fused, counted, atol=1e-5)
