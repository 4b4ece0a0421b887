"""What a results file records about how it was made: command, date, machine, commit."""

from __future__ import annotations

import datetime as dt
import os
import platform
import subprocess


def git(*args: str) -> str:
    """``git ARGS``'s output, or "" where there is no git or no repository."""
    try:
        return subprocess.run(["git", *args], capture_output=True, text=True, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return ""


def provenance(command: str) -> dict:
    """{command, date (UTC), machine, commit}; the commit says so when motion_core/ has
    uncommitted changes (the figures then come from code no commit holds)."""
    dirty = bool(git("status", "--porcelain", "--", "motion_core"))
    return {
        "command": command,
        "date": dt.datetime.now(dt.UTC).strftime("%Y-%m-%dT%H:%M:%SZ"),
        "machine": f"{platform.node()} {platform.machine()} {os.cpu_count()} cores, Python {platform.python_version()}",
        "commit": git("rev-parse", "HEAD") + (" (motion_core modified)" if dirty else ""),
    }
