"""Building and running the CPU's compiled kernels (numba): the selective scan's
(``scan_compiled``) and the causal convolution's (``causal_conv``).

Each kernel has two builds: without ``parallel`` for one thread, and with ``prange`` over
the samples for more. With one torch thread the serial build runs, so numba never starts
its thread pool: its OpenMP layer's idle worker spin-waited (half a core per process), and
starting the pool set OpenMP's thread count, torch's included, to the pool's size, so a
process pinned to one torch thread ran on two after its first call. Where more than one
thread is wanted, torch's count is restored after each parallel call.

``fastmath`` is LLVM's fast-math short of ``nnan``/``ninf`` (a NaN or Inf stays one): it lets
LLVM contract multiply-adds and vectorise sums over channels.
"""

from __future__ import annotations

import types
from collections.abc import Callable

import torch

try:
    import numba
    from numba import prange  # the kernels' loop over samples
except ImportError:  # optional: every kernel has a torch reference
    numba = None
    prange = range

FASTMATH = frozenset({"contract", "reassoc", "nsz", "arcp"})


def available() -> bool:
    return numba is not None


def builds(fn: types.FunctionType) -> dict[bool, Callable]:
    """``fn`` compiled without and with ``parallel`` (keys False, True), each under a name of
    its own: numba's disk cache is keyed by the function's name, and the two builds must not
    share an entry. Compiled lazily at the first call, then cached on disk."""
    out = {}
    for parallel in (False, True):
        name = f"{fn.__name__}_{'parallel' if parallel else 'serial'}"
        copy = types.FunctionType(fn.__code__.replace(co_name=name, co_qualname=name), fn.__globals__, name)
        copy.__qualname__ = name
        out[parallel] = numba.njit(parallel=parallel, cache=True, fastmath=set(FASTMATH))(copy)
    return out


def helper(fn: types.FunctionType) -> Callable:
    """``fn`` compiled to be called from kernels (and from Python, as tests do)."""
    return numba.njit(cache=True, fastmath=set(FASTMATH))(fn)


def threads() -> int:
    """The threads a kernel runs on: torch's intra-op count, at most numba's."""
    return max(1, min(torch.get_num_threads(), numba.config.NUMBA_NUM_THREADS))


def run(kernel: dict[bool, Callable], *arrays) -> None:
    """``kernel`` (from ``builds``) on as many threads as torch's intra-op pool (training jobs
    pin one per process), with torch's thread count put back afterwards."""
    torch_threads = torch.get_num_threads()
    n = threads()
    if n == 1:
        kernel[False](*arrays)
        return
    numba.set_num_threads(n)
    try:
        kernel[True](*arrays)
    finally:
        if torch.get_num_threads() != torch_threads:
            torch.set_num_threads(torch_threads)
