"""BABEL-style segment annotations: one motion with a list of (start_s, end_s, text).

We read the structure BABEL's JSON releases use (a dict of sequences, each with ``dur``,
``feat_p`` and ``frame_ann.labels[*]`` holding ``proc_label``/``raw_label`` and
``start_t``/``end_t`` in seconds). ``feat_p`` is resolved relative to the annotation
file's folder and must point at a (T, D) feature ``.npy`` (we store HumanML3D features;
BABEL's own 135-dim format is a different representation that we do not train on).
Sequences with only a sequence-level label (``frame_ann`` null) become one segment.
"""

from __future__ import annotations

import json
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..body.skeleton import HUMANML3D, Skeleton
from .humanml3d import DatasetError, load_features


@dataclass
class Segment:
    start: float  # seconds
    end: float
    text: str


@dataclass
class SegmentedMotion:
    """features: (T, D) float32; segments sorted by start time."""

    id: str
    features: np.ndarray
    fps: float
    segments: list[Segment]

    def segment_frames(self) -> list[tuple[int, int, str]]:
        """(start_frame, end_frame, text) with end exclusive, clipped to the motion."""
        T = len(self.features)
        out = []
        for s in self.segments:
            a = max(0, min(T, round(s.start * self.fps)))
            b = max(a, min(T, round(s.end * self.fps)))
            out.append((a, b, s.text))
        return out


def _labels(entry: dict, sid: str, where: Path) -> list[Segment]:
    frame_ann = entry.get("frame_ann")
    if frame_ann and frame_ann.get("labels"):
        labels = frame_ann["labels"]
    elif entry.get("seq_ann") and entry["seq_ann"].get("labels"):
        labels = [{**lb, "start_t": 0.0, "end_t": entry.get("dur", 0.0)} for lb in entry["seq_ann"]["labels"]]
    else:
        raise DatasetError(f"{where}: sequence {sid} has no labels")
    segs = []
    for lb in labels:
        text = lb.get("raw_label") or lb.get("proc_label")
        if not text or "start_t" not in lb or "end_t" not in lb:
            raise DatasetError(f"{where}: sequence {sid} has a label without text or times: {lb}")
        s, e = float(lb["start_t"]), float(lb["end_t"])
        if e <= s:
            raise DatasetError(f"{where}: sequence {sid} has a segment ending before it starts ({s}, {e})")
        segs.append(Segment(s, e, str(text).strip()))
    return sorted(segs, key=lambda g: (g.start, g.end))


class BabelSegments:
    """Reader of one BABEL-style annotation file; iterating yields SegmentedMotion."""

    def __init__(self, path: str | Path, skeleton: Skeleton = HUMANML3D, fps: float | None = None) -> None:
        self.path = Path(path)
        if not self.path.is_file():
            raise DatasetError(f"missing BABEL annotation file {self.path}")
        try:
            self.raw: dict = json.loads(self.path.read_text(encoding="utf-8"))
        except json.JSONDecodeError as exc:
            raise DatasetError(f"{self.path}: not valid JSON ({exc})") from None
        if not isinstance(self.raw, dict):
            raise DatasetError(f"{self.path}: expected a JSON object of sequences")
        self.skeleton = skeleton
        self.fps = fps or skeleton.fps

    def __len__(self) -> int:
        return len(self.raw)

    def __iter__(self) -> Iterator[SegmentedMotion]:
        for sid in self.raw:
            yield self.load(sid)

    def load(self, sid: str) -> SegmentedMotion:
        entry = self.raw[sid]
        if "feat_p" not in entry:
            raise DatasetError(f"{self.path}: sequence {sid} has no feat_p")
        feats = load_features(self.path.parent / entry["feat_p"], self.skeleton.feature_dim)
        return SegmentedMotion(id=str(sid), features=feats, fps=self.fps, segments=_labels(entry, sid, self.path))


def write_babel(path: str | Path, motions: list[tuple[str, str, float, list[Segment]]]) -> None:
    """Write annotations: (id, feat_p relative to the file, duration s, segments)."""
    out = {}
    for sid, feat_p, dur, segs in motions:
        out[sid] = {
            "babel_sid": sid,
            "feat_p": feat_p,
            "dur": round(dur, 3),
            "seq_ann": {"labels": [{"raw_label": " then ".join(s.text for s in segs), "proc_label": "sequence"}]},
            "frame_ann": {
                "labels": [
                    {"raw_label": s.text, "proc_label": s.text, "start_t": round(s.start, 3), "end_t": round(s.end, 3)}
                    for s in segs
                ]
            },
        }
    p = Path(path)
    p.parent.mkdir(parents=True, exist_ok=True)
    p.write_text(json.dumps(out, indent=1), encoding="utf-8")
