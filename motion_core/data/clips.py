"""In-memory training data: one split of a HumanML3D-format directory, padded batches.

The built-in corpus is a few hundred MB per split as float32, so training holds a split
in memory and batches clips of similar length together (less padding, less compute).
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import torch

from .humanml3d import HumanML3DDataset


@dataclass
class Clip:
    """One motion: features (T, 263) un-normalised, its captions and structured labels."""

    id: str
    features: np.ndarray
    captions: list[str]
    labels: dict = field(default_factory=dict)

    @property
    def frames(self) -> int:
        return int(self.features.shape[0])


def read_labels(root: str | Path) -> dict[str, dict]:
    """id -> labels from the corpus's labels.jsonl ({} when the directory has none)."""
    path = Path(root) / "labels.jsonl"
    if not path.is_file():
        return {}
    out = {}
    for line in path.read_text().splitlines():
        if line.strip():
            rec = json.loads(line)
            out[rec["id"]] = rec.get("labels", {})
    return out


def load_clips(root: str | Path, split: str, limit: int | None = None, max_frames: int = 200) -> list[Clip]:
    """Load a split into memory (the first ``limit`` ids when given), clips cropped to max_frames."""
    ds = HumanML3DDataset(root, split)
    labels = read_labels(root)
    ids = ds.ids[:limit] if limit else ds.ids
    out = []
    for mid in ids:
        s = ds.load(mid)
        caps = [c.text for c in s.captions] or [""]
        out.append(Clip(mid, s.features[:max_frames].astype(np.float32), caps, labels.get(mid, {})))
    return out


def normalized_features(
    root: str | Path, split: str, norm, limit: int | None = None, max_frames: int = 200
) -> list[np.ndarray]:
    """Each clip of a split as normalised float32 features (T_i, D), cropped to max_frames, in
    ``load_clips``'s order. Loaded one clip at a time, so the raw copies never pile up: a
    trainer that needs only the features holds half what ``load_clips`` then normalising does
    (6 GB, not 12, for the 48,575 training clips of the grown corpus)."""
    ds = HumanML3DDataset(root, split)
    ids = ds.ids[:limit] if limit else ds.ids
    return [norm.normalize(ds.load(mid).features[:max_frames].astype(np.float32)).astype(np.float32) for mid in ids]


def spread_clips(root: str | Path, split: str, n: int, source: str = "procedural") -> list[Clip]:
    """n clips of one source ("procedural" or "real") spread evenly over a split: the
    evaluation's test prompts and the training curves' validation prompts."""
    clips = [c for c in load_clips(root, split) if c.labels.get("source", "procedural") == source]
    if len(clips) <= n:
        return clips
    idx = np.linspace(0, len(clips) - 1, n).round().astype(int)
    return [clips[i] for i in idx]


def length_batches(lengths: list[int], batch_size: int, rng: np.random.Generator) -> list[np.ndarray]:
    """Shuffled batches of indices whose clips have similar lengths.

    Sort by length with random tie-breaking, cut into batches, shuffle the batch order.
    """
    order = np.lexsort((rng.random(len(lengths)), np.asarray(lengths)))
    batches = [order[i : i + batch_size] for i in range(0, len(order), batch_size)]
    rng.shuffle(batches)
    return batches


def pad_batch(arrays: list[np.ndarray], multiple: int = 1) -> tuple[torch.Tensor, torch.Tensor]:
    """Stack (T_i, D) arrays into (B, T, D) zero-padded to a multiple of ``multiple``,
    with a (B, T) bool mask that is True on real frames."""
    t_max = max(a.shape[0] for a in arrays)
    t_max = -(-t_max // multiple) * multiple
    x = np.zeros((len(arrays), t_max, arrays[0].shape[1]), dtype=np.float32)
    mask = np.zeros((len(arrays), t_max), dtype=bool)
    for i, a in enumerate(arrays):
        x[i, : len(a)] = a
        mask[i, : len(a)] = True
    return torch.from_numpy(x), torch.from_numpy(mask)
