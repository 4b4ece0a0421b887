"""Real motion capture archives (the Bandai Namco Research motion data sets, BVH).

CC BY-NC 4.0: anything derived from these clips is for non-commercial use, with attribution
to Bandai Namco Research Inc. (arXiv 2306.08861). They are unpacked into a cache directory,
never into the repository.
"""

from __future__ import annotations

import subprocess
from pathlib import Path


def unpack_archive(archive: str | Path, cache_dir: str | Path) -> Path:
    """Unpack ``archive`` (.tar.xz) into ``cache_dir`` once; returns ``cache_dir``.

    A marker file records a finished unpack, so an interrupted one is redone.
    """
    archive, cache = Path(archive), Path(cache_dir)
    marker = cache / ".unpacked"
    stamp = f"{archive.name} {archive.stat().st_size}"
    if marker.is_file() and marker.read_text() == stamp:
        return cache
    cache.mkdir(parents=True, exist_ok=True)
    # the system tar (xz in C) unpacks the 550 MB in ~10 s; Python's tarfile takes minutes
    subprocess.run(["tar", "xJf", str(archive), "-C", str(cache)], check=True)
    marker.write_text(stamp)
    return cache


def bvh_files(root: str | Path) -> list[Path]:
    """All clips under an unpacked archive, sorted by name."""
    return sorted(Path(root).glob("Bandai-Namco-Research-Motiondataset-*/data/*.bvh"))
