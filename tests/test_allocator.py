"""The allocator setting sampling relies on (``inference/allocator.py``)."""

from __future__ import annotations

import platform

from motion_core.inference import allocator
from motion_core.inference.registry import load_method


def test_loading_a_method_keeps_freed_memory_where_the_c_library_is_glibc():
    load_method("kmm")
    glibc = platform.libc_ver()[0] == "glibc"
    assert allocator._applied is glibc
    assert allocator.keep_freed_memory() is glibc  # once per process: asking again changes nothing
