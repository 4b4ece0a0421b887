"""glibc's allocator kept from handing memory back: between sampling calls, and in training.

A denoiser call allocates and frees dozens of 0.2-2 MiB tensors. glibc serves an allocation
over its mmap threshold (128 KiB at start) from fresh pages, and trims the heap's free top
back to the OS past its trim threshold, so each call faulted the same pages in again.
Raising both thresholds (``mallopt``, as the ``MALLOC_MMAP_THRESHOLD_`` and
``MALLOC_TRIM_THRESHOLD_`` variables would before start-up) keeps the freed memory in the
heap for the next call. Together with the scan's decays computed ahead as torch tensors,
then a call's largest (the kernels now compute them themselves), one Motion Mamba denoiser
call went from 14.8 to 12.5 ms at batch 1 on our 2-core machine (alternating runs, commit
07a8d85).
The cost is up to ``TRIM_BYTES`` of freed memory held by the process.

Training (``keep_training_memory``, every ``python -m motion_core.train`` command) goes
further: the main heap serves every allocation, however large (``M_MMAP_MAX`` 0; another
thread's arena still maps a request past 64 MiB), and it is never trimmed. At batch 256
Motion Mamba's activations are 50+ MiB tensors, past the 32 MiB up to which glibc raises its
mmap threshold by itself, so each of a step's hundreds of element-wise ops faulted in fresh
pages: a step took 19.3 s, 12.8 s from the heap (``train step-time``, one thread; the
baseline's 4.2 and 4.1 s). At batch 64, whose tensors stay under that, nothing changed.
A training process's working set is the same every step, so the memory it keeps is what
its next step uses.

Where the C library is not glibc (macOS, musl, Windows) nothing changes.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import threading

M_TRIM_THRESHOLD, M_MMAP_THRESHOLD, M_MMAP_MAX = -1, -3, -4  # glibc's malloc.h
MMAP_BYTES = 64 << 20
TRIM_BYTES = 128 << 20
NEVER_TRIM = (1 << 31) - 1  # the largest int mallopt takes

_lock = threading.Lock()
_applied: bool | None = None
_training: bool | None = None


def keep_freed_memory() -> bool:
    """Raise glibc's mmap and trim thresholds once per process; True where they were set."""
    global _applied
    with _lock:
        if _applied is None:
            # a training process's never-trim setting stays (a lower threshold would undo it)
            _applied = _mallopt(M_MMAP_THRESHOLD, MMAP_BYTES) and (
                bool(_training) or _mallopt(M_TRIM_THRESHOLD, TRIM_BYTES)
            )
        return _applied


def keep_training_memory() -> bool:
    """Serve every allocation from the heap (no mmap) and never trim it, once per process;
    True where that was set."""
    global _training
    with _lock:
        if _training is None:
            _training = _mallopt(M_MMAP_MAX, 0) and _mallopt(M_TRIM_THRESHOLD, NEVER_TRIM)
        return _training


def _mallopt(param: int, value: int) -> bool:
    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6")
        fn = libc.mallopt
    except (OSError, AttributeError):
        return False
    fn.argtypes, fn.restype = [ctypes.c_int, ctypes.c_int], ctypes.c_int
    return fn(param, value) == 1
