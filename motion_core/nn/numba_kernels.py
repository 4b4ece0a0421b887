"""Building and running the CPU's compiled kernels (numba): the selective scan's
(``scan_compiled``) and the causal convolution's (``causal_conv``).

Each kernel has two builds: without ``parallel`` for one thread, and with ``prange`` over
the samples for more. With one torch thread the serial build runs, so numba never starts
its thread pool: its OpenMP layer's idle worker spin-waited (half a core per process), and
starting the pool set OpenMP's thread count, torch's included, to the pool's size, so a
process pinned to one torch thread ran on two after its first call. Where more than one
thread is wanted, torch's count is restored after each parallel call.

``fastmath`` is LLVM's fast-math short of ``nnan``/``ninf`` (a NaN or Inf stays one): it lets
LLVM contract multiply-adds and vectorise sums over channels. ``error_model="numpy"``: a
division by zero gives Inf or NaN as in numpy instead of raising; Python's model put a zero
test before every division, and that branch kept LLVM from vectorising any loop that
divides (``ssm_fused``'s SiLU and softplus ran scalar, 2.1 and 3.7 ns an element).
"""

from __future__ import annotations

import hashlib
import os
import types
from collections.abc import Callable
from pathlib import Path

import torch

try:
    import numba
    from numba import prange  # the kernels' loop over samples
except ImportError:  # optional: every kernel has a torch reference
    numba = None
    prange = range

FASTMATH = frozenset({"contract", "reassoc", "nsz", "arcp"})
ERROR_MODEL = "numpy"


def available() -> bool:
    return numba is not None


def _shared_source_hash() -> str:
    """A hash of the sources every kernel compiles in: this file's settings and
    ``kernel_math``'s functions. numba's disk cache checks only the cached function's own
    file, so a kernel cached before a change to a helper it calls from another file would
    go on running the old helper (against, say, a new layout of ``kernel_math.CONSTANTS``).
    The hash is part of every cached name, so such a change compiles afresh."""
    here = Path(__file__).resolve().parent
    text = b"".join((here / f).read_bytes() for f in ("numba_kernels.py", "kernel_math.py"))
    return hashlib.sha256(text).hexdigest()[:10]


_SOURCES = _shared_source_hash()


def _renamed(fn: types.FunctionType, name: str) -> types.FunctionType:
    copy = types.FunctionType(fn.__code__.replace(co_name=name, co_qualname=name), fn.__globals__, name)
    copy.__qualname__ = name
    copy.__doc__ = fn.__doc__
    return copy


def builds(fn: types.FunctionType) -> dict[bool, Callable]:
    """``fn`` compiled without and with ``parallel`` (keys False, True), each under a name of
    its own: numba's disk cache is keyed by the function's name, and the two builds must not
    share an entry (nor one compiled against other shared sources: ``_shared_source_hash``).
    Compiled lazily at the first call, then cached on disk."""
    out = {}
    for parallel in (False, True):
        copy = _renamed(fn, f"{fn.__name__}_{'parallel' if parallel else 'serial'}_{_SOURCES}")
        out[parallel] = numba.njit(parallel=parallel, cache=True, fastmath=set(FASTMATH), error_model=ERROR_MODEL)(copy)
    return out


def helper(fn: types.FunctionType) -> Callable:
    """``fn`` compiled to be called from kernels (and from Python, as tests do), cached under
    a name that carries ``_shared_source_hash``."""
    copy = _renamed(fn, f"{fn.__name__}_{_SOURCES}")
    return numba.njit(cache=True, fastmath=set(FASTMATH), error_model=ERROR_MODEL)(copy)


def threads() -> int:
    """The threads a kernel runs on: torch's intra-op count, at most numba's."""
    return max(1, min(torch.get_num_threads(), numba.config.NUMBA_NUM_THREADS))


_blas_threads: int | None = None


def _match_blas_threads(n: int) -> None:
    """Keep scipy's OpenBLAS (the one numba's ``np.dot`` calls) to the kernels' ``n`` threads.
    Left alone it starts as many threads as cores for a product of a few hundred thousand
    multiply-adds: with another job on the second core, ``ssm_fused``'s projections then
    waited on a busy core, and a Motion Mamba sampling step took 65 ms against 33 ms at one
    BLAS thread (and 37 ms unfused). Set once per change of ``n`` (the discovery scans the
    loaded libraries), and only for the libraries scipy ships (``scipy.libs``; numpy's own
    BLAS is left alone). Without threadpoolctl, or with a scipy built against a shared
    BLAS, nothing is set and the kernels still run."""
    global _blas_threads
    if _blas_threads == n:
        return
    _blas_threads = n
    try:
        import scipy
        from threadpoolctl import ThreadpoolController
    except ImportError:
        return
    libs = os.path.realpath(os.path.dirname(scipy.__file__) + ".libs") + os.sep
    for lib in ThreadpoolController().select(user_api="blas").lib_controllers:
        if os.path.realpath(lib.filepath).startswith(libs):
            lib.set_num_threads(n)


def run(kernel: dict[bool, Callable], *arrays) -> None:
    """``kernel`` (from ``builds``) on as many threads as torch's intra-op pool (training jobs
    pin one per process), with torch's thread count put back afterwards, and scipy's BLAS
    (the kernels' ``np.dot``) on as many."""
    torch_threads = torch.get_num_threads()
    n = threads()
    _match_blas_threads(n)
    if n == 1:
        kernel[False](*arrays)
        return
    numba.set_num_threads(n)
    try:
        kernel[True](*arrays)
    finally:
        if torch.get_num_threads() != torch_threads:
            torch.set_num_threads(torch_threads)
