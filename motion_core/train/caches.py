"""Training caches and what they were built from.

A cache (a denoiser's latents and caption embeddings, KMM's tokenised corpus and caption
tokens) carries a fingerprint of its sources: the training split's clip ids, feature file
sizes and captions, and the bytes of the network that encoded it. One built from other
sources is refused, not reused: a stale cache pairs captions with the wrong clips, or trains
on a smoke run's few clips, and nothing downstream would notice.
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import numpy as np

from ..data.humanml3d import HumanML3DDataset, read_captions


class StaleCache(RuntimeError):
    """A cache was built from other sources than the run it is read for."""


def corpus_fingerprint(data: str | Path, limit: int | None = None) -> str:
    """sha256 over the training split as ``load_clips`` reads it: each clip's id, the size of
    its feature file (which fixes its frame count) and its captions, in order. Reads the
    split file, the captions and one stat per clip, not the motions."""
    ds = HumanML3DDataset(data, "train")
    h = hashlib.sha256()
    root = Path(data)
    for mid in ds.ids[:limit] if limit else ds.ids:
        size = (root / "new_joint_vecs" / f"{mid}.npy").stat().st_size
        caps = [c.text for c in read_captions(root / "texts" / f"{mid}.txt")]
        h.update(json.dumps([mid, size, caps]).encode())
    return h.hexdigest()


def file_fingerprint(path: str | Path) -> str:
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def cached(cache: Path, fingerprint: str, sources: str = "corpus or VAE") -> dict[str, np.ndarray] | None:
    """The cache's arrays without its fingerprint, None when there is none; StaleCache when
    it was built from other ``sources`` (delete it to rebuild)."""
    if not cache.is_file():
        return None
    data = dict(np.load(cache))
    found = str(data.pop("fingerprint", "none (built before caches were fingerprinted)"))
    if found != fingerprint:
        raise StaleCache(
            f"{cache} was built from another {sources} (fingerprint {found[:12]}, now {fingerprint[:12]}); "
            "delete it to rebuild"
        )
    return data


def write_cache(cache: Path, data: dict[str, np.ndarray], fingerprint: str) -> None:
    """``data`` saved with the fingerprint ``cached`` checks."""
    np.savez(cache, **data, fingerprint=np.array(fingerprint))
