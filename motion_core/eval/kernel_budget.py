"""What a denoiser call's fused SSM kernels must compute element by element, at this
machine's rates, against the time they take: how much a faster kernel could still win.

    python -m motion_core.eval kernel-budget [--methods motion_mamba,ftmomamba] [--frames 196] [--out FILE]

One guided call (batch 2, as ``bench --blocks``) runs with its kernel calls recorded
(``ssm_fused``'s arguments). Each call's element-wise functions are counted from its shapes
(B samples, L steps, E channels, N states, k scans):
- the decays exp(delta A): B x L x E x N a scan, one exp each (the scans' state updates);
- softplus of the step sizes: B x L x E a scan, and FreqSSM's shifted state matrix, one more
  softplus a state update (FTMoMamba);
- SiLU of the convolved input: B x L x E a scan; SiLU of a Mamba block's gate: B x L x E.

Each function is timed on this machine (``kernel_math``'s vectorised float32 forms, the ones
the kernels call, on a buffer in cache, one thread), and the counts times those rates are
the functions' share of the kernels' time. The rest is the state walk, the Conv1D, the x-
and delta-projections and memory traffic. One torch thread, as ``bench``.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
from pathlib import Path

import numpy as np
import torch

from ..inference.registry import load_method
from ..nn import numba_kernels, ssm_fused
from ..nn.kernel_math import CONSTANTS
from .bench import guided_call_args, machine, timed

FUNCTIONS = ("exp", "silu", "softplus")


def function_rates(n: int = 1 << 14, repeats: int = 200) -> dict[str, float]:
    """ns an element of each function the kernels call, over ``n`` float32 values in [-8, 2]
    (a fresh copy each pass: SiLU and softplus would otherwise run on their own outputs)."""
    from ..nn.kernel_math import _exp_inplace, _silu_inplace, _softplus_inplace

    c = CONSTANTS[np.dtype(np.float32)]
    src = np.linspace(-8.0, 2.0, n, dtype=np.float32)
    buf, tmp, k32 = np.empty_like(src), np.empty_like(src), np.empty(n, np.int32)
    run = {
        "exp": lambda: _exp_inplace(buf, k32, c),
        "silu": lambda: _silu_inplace(buf, tmp, k32, c),
        "softplus": lambda: _softplus_inplace(buf, tmp, k32, c),
    }
    copy = statistics.median(timed(lambda: np.copyto(buf, src), repeats))
    out = {}
    for name, fn in run.items():
        med = statistics.median(timed(lambda fn=fn: (np.copyto(buf, src), fn()), repeats))
        out[name] = 1e9 * max(med - copy, 0.0) / n
    return out


def recorded_calls(method: str, frames: int) -> list[list]:
    """The kernel's arguments for every fused SSM call of one guided denoiser call."""
    den = load_method(method).denoiser
    args = guided_call_args(den, frames)
    calls: list[list] = []
    real = numba_kernels.run

    def record(kernel, *arrays):
        if kernel is ssm_fused._KERNEL:
            calls.append(list(arrays))
        return real(kernel, *arrays)

    numba_kernels.run = record
    try:
        with torch.no_grad():
            den(*args)
    finally:
        numba_kernels.run = real
    return calls


def counts(call: list) -> dict[str, int]:
    """Elements each function sees in one kernel call (``ssm_fused._mixer``'s arguments:
    x, x_off, E, taps (k, E, K), ..., A_log (k, E, N), ..., a_shift, c_shift, gate_off, ...)."""
    x, e_n, wconv, a_log, a_shift, gate_off = call[0], call[2], call[3], call[8], call[12], call[14]
    b, length, k, n = x.shape[0], x.shape[1], wconv.shape[0], a_log.shape[2]
    per_scan = b * length * e_n
    updates = k * per_scan * n
    return {
        "exp": updates,
        "silu": k * per_scan + (b * length * e_n if gate_off >= 0 else 0),
        "softplus": k * per_scan + (updates if a_shift.shape[0] > 0 else 0),
    }


def budget(method: str, frames: int, rates: dict[str, float], repeats: int) -> dict:
    calls = recorded_calls(method, frames)
    kernel = ssm_fused._KERNEL[False]  # one thread: the serial build

    def all_calls():
        for c in calls:
            c[-1][:] = 0.0  # the kernel adds into its zeroed output
            kernel(*c)

    kernels_ms = 1e3 * statistics.median(timed(all_calls, repeats))
    total = {f: sum(counts(c)[f] for c in calls) for f in FUNCTIONS}
    functions_ms = {f: total[f] * rates[f] / 1e6 for f in FUNCTIONS}
    return {
        "kernel_calls": len(calls),
        "elements": total,
        "functions_ms": functions_ms,
        "kernels_ms": kernels_ms,
        "functions_share": sum(functions_ms.values()) / kernels_ms,
        "ns_per_state_update": 1e6 * kernels_ms / total["exp"],
    }


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--methods", default="motion_mamba,ftmomamba")
    ap.add_argument("--frames", type=int, default=196)
    ap.add_argument("--repeats", type=int, default=50)
    ap.add_argument("--out", default=None)
    args = ap.parse_args(argv)
    threads = torch.get_num_threads()
    torch.set_num_threads(1)
    try:
        rates = function_rates()
        t0 = time.perf_counter()
        out = {
            "machine": machine(),
            "frames": args.frames,
            "ns_per_element": rates,
            "methods": {m: budget(m, args.frames, rates, args.repeats) for m in args.methods.split(",")},
            "seconds": time.perf_counter() - t0,
            "command": "python -m motion_core.eval kernel-budget "
            + " ".join(argv if argv is not None else sys.argv[1:]),
        }
    finally:
        torch.set_num_threads(threads)
    text = json.dumps(out, indent=1)
    print(text)
    if args.out:
        Path(args.out).write_text(text + "\n")


if __name__ == "__main__":
    main()
