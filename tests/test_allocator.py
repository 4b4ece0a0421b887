"""The allocator settings sampling and training rely on (``nn/allocator.py``)."""

from __future__ import annotations

import platform
import subprocess
import sys

from motion_core.inference.registry import load_method
from motion_core.nn import allocator


def test_loading_a_method_keeps_freed_memory_where_the_c_library_is_glibc():
    load_method("kmm")
    glibc = platform.libc_ver()[0] == "glibc"
    assert allocator._applied is glibc
    assert allocator.keep_freed_memory() is glibc  # once per process: asking again changes nothing


def test_every_training_command_keeps_its_memory_in_the_heap():
    # in a fresh process: the setting is per process, and this one's must stay as sampling set it
    code = (
        "from motion_core.nn import allocator\n"
        "from motion_core.train.__main__ import main\n"
        "try:\n"
        "    main(['no-such-command'])\n"
        "except SystemExit:\n"
        "    pass\n"
        "print(allocator._training)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == str(platform.libc_ver()[0] == "glibc")
