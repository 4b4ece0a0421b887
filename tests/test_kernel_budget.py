"""`python -m motion_core.eval kernel-budget` (eval/kernel_budget.py): the fused SSM kernels'
element-wise functions, counted from the calls one guided denoiser call makes, against the
kernels' time."""

from __future__ import annotations

import numpy as np
import torch


def _call(b=2, length=5, e=3, k=2, n=4, shifted=False, gate=True) -> list:
    """A kernel argument list with only the shapes ``counts`` reads."""
    args: list = [None] * 18
    args[0] = np.zeros((b, length, 2 * e), np.float32)
    args[2] = e
    args[3] = np.zeros((k, e, 4), np.float32)
    args[8] = np.zeros((k, e, n), np.float32)
    args[12] = np.zeros((b, length, e) if shifted else (0, 0, 0), np.float32)
    args[14] = e if gate else -1
    return args


def test_each_function_is_counted_from_the_calls_shapes():
    from motion_core.eval import kernel_budget

    scan, updates = 2 * 5 * 3, 2 * 5 * 3 * 4
    plain = kernel_budget.counts(_call(gate=False))
    assert plain == {"exp": 2 * updates, "silu": 2 * scan, "softplus": 2 * scan}
    # a Mamba block's gate adds a SiLU a channel; FreqSSM's shifted matrix a softplus an update
    gated = kernel_budget.counts(_call(shifted=True))
    assert gated == {"exp": 2 * updates, "silu": 2 * scan + scan, "softplus": 2 * scan + 2 * updates}


def test_a_calls_decays_are_its_scans_state_updates_and_the_budget_is_timed():
    from motion_core.eval import kernel_budget
    from motion_core.eval.bench import guided_call_args
    from motion_core.inference.registry import load_method
    from motion_core.nn.ssm import counted_state_updates

    calls = kernel_budget.recorded_calls("motion_mamba", 40)
    assert len(calls) == 12  # six levels' HTM and BSM blocks, one kernel call each
    den = load_method("motion_mamba").denoiser
    with torch.no_grad(), counted_state_updates() as updates:
        den(*guided_call_args(den, 40))
    assert sum(kernel_budget.counts(c)["exp"] for c in calls) == updates[0]
    rates = {"exp": 1.0, "silu": 2.0, "softplus": 3.0}
    out = kernel_budget.budget("motion_mamba", 40, rates, repeats=2)
    assert out["kernel_calls"] == 12 and out["kernels_ms"] > 0
    assert out["functions_ms"]["silu"] == out["elements"]["silu"] * 2.0 / 1e6
    assert out["functions_share"] == sum(out["functions_ms"].values()) / out["kernels_ms"]
    assert all(r > 0 for r in kernel_budget.function_rates(n=4096, repeats=20).values())
