"""Removal of old output folders, so a long-running hosted space does not fill its disk.

Every generation (demo or study) writes into its own folder under the output root
(``viewer.new_output_dir``); ``$MMS_OUTPUT_TTL`` seconds (default 3600) after its last change
a folder is deleted by a background sweeper.
"""

from __future__ import annotations

import shutil
import threading
import time
from pathlib import Path


def sweep_outputs(root: Path, max_age_s: float, now: float | None = None) -> int:
    """Delete the per-request folders under ``root`` older than ``max_age_s``; returns how many.

    Only direct children whose names are 32 hex digits (what ``new_output_dir`` and the study
    create) are touched, and symlinks are never followed, so nothing outside root is removed.
    """
    now = time.time() if now is None else now
    removed = 0
    if not root.is_dir():
        return 0
    for d in root.iterdir():
        name = d.name
        if len(name) != 32 or any(c not in "0123456789abcdef" for c in name):
            continue
        if d.is_symlink() or not d.is_dir():
            continue
        try:
            if now - d.stat().st_mtime > max_age_s:
                shutil.rmtree(d)
                removed += 1
        except OSError:
            continue  # another sweeper got it first
    return removed


def start_sweeper(root: Path, max_age_s: float, every_s: float = 300.0) -> threading.Thread:
    """A daemon thread that runs ``sweep_outputs`` every ``every_s`` seconds."""

    def loop() -> None:
        while True:
            sweep_outputs(root, max_age_s)
            time.sleep(every_s)

    t = threading.Thread(target=loop, name="output-sweeper", daemon=True)
    t.start()
    return t
