"""glibc's allocator kept from handing memory back between sampling calls.

A denoiser call allocates and frees dozens of 0.2-2 MiB tensors. glibc serves an allocation
over its mmap threshold (128 KiB at start) from fresh pages, and trims the heap's free top
back to the OS past its trim threshold, so each call faulted the same pages in again.
Raising both thresholds (``mallopt``, as the ``MALLOC_MMAP_THRESHOLD_`` and
``MALLOC_TRIM_THRESHOLD_`` variables would before start-up) keeps the freed memory in the
heap for the next call. With the scan's decays computed ahead (``nn/scan_compiled``), whose
tensors are the largest, one Motion Mamba denoiser call went from 14.8 to 12.5 ms at batch 1
on our 2-core machine (both changes together; alternating runs, commit 07a8d85).
The cost is up to ``TRIM_BYTES`` of freed memory held by the process.

Where the C library is not glibc (macOS, musl, Windows) nothing changes.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import threading

M_TRIM_THRESHOLD, M_MMAP_THRESHOLD = -1, -3  # glibc's malloc.h
MMAP_BYTES = 64 << 20
TRIM_BYTES = 128 << 20

_lock = threading.Lock()
_applied: bool | None = None


def keep_freed_memory() -> bool:
    """Raise glibc's mmap and trim thresholds once per process; True where they were set."""
    global _applied
    with _lock:
        if _applied is None:
            _applied = _mallopt(M_MMAP_THRESHOLD, MMAP_BYTES) and _mallopt(M_TRIM_THRESHOLD, TRIM_BYTES)
        return _applied


def _mallopt(param: int, value: int) -> bool:
    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6")
        fn = libc.mallopt
    except (OSError, AttributeError):
        return False
    fn.argtypes, fn.restype = [ctypes.c_int, ctypes.c_int], ctypes.c_int
    return fn(param, value) == 1
