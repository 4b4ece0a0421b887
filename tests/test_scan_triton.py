"""The fused GPU scan (``nn/scan_triton.py``) equals the reference loop, values and
gradients, run by Triton's interpreter on the CPU (``TRITON_INTERPRET=1``, set before
Triton decorates the kernels, hence a fresh process). On a GPU, ``tools/gpu_scan_check.py``
checks the compiled kernel the same way."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

CHECK = r"""
import json, torch
from motion_core.nn.scan_triton import scan_triton
from motion_core.nn.ssm import scan_sequential

def inputs(bsz, L, d, n, g, per_step, has_d, seed, steep):
    gen = torch.Generator().manual_seed(seed)
    u = torch.randn(bsz, L, d, generator=gen)
    delta = torch.rand(bsz, L, d, generator=gen) * 0.5
    if steep:  # steps that decay past the chunked scan's range, as trained models' do
        delta[:, ::5] *= 300
    shape = (bsz, L, d, n) if per_step else (d, n)
    A = -torch.rand(*shape, generator=gen) * 3 - 0.1
    Bm, Cm = torch.randn(bsz, L, g, n, generator=gen), torch.randn(bsz, L, g, n, generator=gen)
    D = torch.randn(d, generator=gen) if has_d else None
    return [t.requires_grad_() for t in (u, delta, A, Bm, Cm, D) if t is not None], has_d

def run(fn, args, has_d, dtype=torch.float32):
    args = [a.detach().to(dtype).requires_grad_() for a in args]
    y = fn(*args) if has_d else fn(*args, None)
    grads = torch.autograd.grad((y * torch.cos(y)).sum(), args)
    return y.detach().double(), [g.double() for g in grads]

rel = lambda a, b: float((a - b).abs().max() / (1 + b.abs().max()))
rows = []
# (B, L, D, N, G, per-step A, D): channels not a multiple of the kernel's block, one step,
# grouped B/C, FTMoMamba's per-step A, with and without D; mild and steep decay
for case in [(2, 7, 40, 4, 2, False, True), (3, 1, 8, 8, 1, False, False), (2, 19, 36, 4, 4, True, True),
             (1, 33, 64, 8, 2, True, False)]:
    for steep in (False, True):
        args, has_d = inputs(*case, seed=len(rows), steep=steep)
        y64, g64 = run(scan_sequential, args, has_d, torch.float64)  # the truth
        y0, g0 = run(scan_sequential, args, has_d)  # the float32 loop: its error is the yardstick
        y1, g1 = run(scan_triton, args, has_d)
        with torch.no_grad():
            y2 = scan_triton(*args) if has_d else scan_triton(*args, None)
        rows.append({"case": case, "steep": steep, "no_grad_same": bool(torch.equal(y1, y2.double())),
                     "finite": bool(torch.isfinite(y1).all()),
                     "y": rel(y1, y64), "y_loop": rel(y0, y64),
                     "grads": [rel(a, b) for a, b in zip(g1, g64)],
                     "grads_loop": [rel(a, b) for a, b in zip(g0, g64)]})
print(json.dumps(rows))
"""


def test_fused_scan_equals_the_loop_in_values_and_gradients():
    pytest.importorskip("triton", reason="requirements-dev.txt installs triton for this test")
    env = {**os.environ, "TRITON_INTERPRET": "1", "PYTHONPATH": str(ROOT)}
    out = subprocess.run([sys.executable, "-c", CHECK], env=env, capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr[-3000:]
    rows = json.loads(out.stdout.strip().splitlines()[-1])
    assert len(rows) == 8
    for row in rows:
        assert row["finite"], row
        assert row["no_grad_same"], row
        # against float64: within float32 rounding, the float32 loop's own error being the
        # yardstick (steep decay with large outputs costs it up to ~1e-3 of a gradient); a
        # wrong term in the kernel moves values by their own size
        assert row["y"] < max(1e-5, 4 * row["y_loop"]), row
        for mine, loop in zip(row["grads"], row["grads_loop"], strict=True):
            assert mine < max(1e-4, 4 * loop), row


def test_fused_scan_refuses_what_it_cannot_take():
    pytest.importorskip("triton", reason="requirements-dev.txt installs triton for this test")
    import torch

    from motion_core.nn.scan_triton import scan_triton, supported

    u = torch.zeros(1, 4, 6)
    assert not supported(u, torch.zeros(6, 3), torch.zeros(1, 4, 1, 3))  # N = 3: not a power of two
    assert not supported(u.double(), torch.zeros(6, 4).double(), torch.zeros(1, 4, 1, 4).double())
    with pytest.raises(ValueError, match="power-of-two"):
        scan_triton(u, u, torch.zeros(6, 3), torch.zeros(1, 4, 1, 3), torch.zeros(1, 4, 1, 3))
