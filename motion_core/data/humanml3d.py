"""Reader and writer for the HumanML3D / KIT-ML directory format.

Layout (both data sets)::

    ROOT/new_joint_vecs/<id>.npy   (T, D) float32 features (D = 263 HumanML3D, 251 KIT)
    ROOT/texts/<id>.txt            one annotation a line: caption#tokens#start#end
    ROOT/train.txt val.txt test.txt  ids, one a line
    ROOT/Mean.npy ROOT/Std.npy     feature statistics

``start``/``end`` are seconds into the motion; 0.0/0.0 (or NaN) means the whole clip.
``tokens`` is ``word/POS`` pairs separated by spaces (may be empty in our corpus).
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..body.skeleton import Skeleton, get_skeleton

SPLITS = ("train", "val", "test")


class DatasetError(ValueError):
    """A data set directory or file is missing, corrupt or of the wrong shape."""


@dataclass
class Caption:
    text: str
    tokens: list[str] = field(default_factory=list)
    start: float = 0.0  # seconds; 0/0 = whole clip
    end: float = 0.0

    def to_line(self) -> str:
        return f"{self.text}#{' '.join(self.tokens)}#{self.start:.1f}#{self.end:.1f}"

    @classmethod
    def from_line(cls, line: str, where: str = "") -> Caption:
        parts = line.rstrip("\n").split("#")
        if len(parts) < 4:
            raise DatasetError(f"{where}: expected 'caption#tokens#start#end', got {line!r}")
        text, tokens, start, end = parts[0], parts[1], parts[2], parts[3]
        try:
            s, e = float(start), float(end)
        except ValueError:
            raise DatasetError(f"{where}: start/end are not numbers in {line!r}") from None
        s = 0.0 if math.isnan(s) else s
        e = 0.0 if math.isnan(e) else e
        return cls(text=text.strip(), tokens=tokens.split() if tokens.strip() else [], start=s, end=e)


@dataclass
class MotionSample:
    """One clip. features: (T, D) float32 un-normalised."""

    id: str
    features: np.ndarray
    captions: list[Caption]
    meta: dict = field(default_factory=dict)

    def __len__(self) -> int:
        return len(self.features)


def load_features(path: Path, dim: int) -> np.ndarray:
    """Load one (T, dim) feature file with clear errors for corrupt or wrong files."""
    try:
        arr = np.load(path, allow_pickle=False)
    except FileNotFoundError:
        raise DatasetError(f"missing motion file {path}") from None
    except Exception as exc:  # np.load raises several types on corrupt input
        raise DatasetError(f"corrupt .npy file {path}: {exc}") from None
    if arr.ndim != 2 or arr.shape[1] != dim:
        raise DatasetError(f"{path}: expected shape (T, {dim}), got {arr.shape}")
    if not np.isfinite(arr).all():
        raise DatasetError(f"{path}: contains NaN or inf")
    return arr.astype(np.float32, copy=False)


def read_captions(path: Path) -> list[Caption]:
    if not path.is_file():
        raise DatasetError(f"missing text file {path}")
    caps = [Caption.from_line(ln, str(path)) for ln in path.read_text(encoding="utf-8").splitlines() if ln.strip()]
    if not caps:
        raise DatasetError(f"{path}: no captions")
    return caps


class HumanML3DDataset:
    """Lazy reader of one split of a HumanML3D- or KIT-format directory.

    Iterating yields :class:`MotionSample`; ``dataset[i]`` loads the i-th listed id.
    Clips shorter than ``min_frames`` are skipped, as the data set's loaders do (40 frames
    HumanML3D), and longer ones are kept whole (cropping belongs to the training code).
    """

    def __init__(
        self,
        root: str | Path,
        split: str = "train",
        skeleton: str | Skeleton = "humanml3d",
        min_frames: int = 1,
    ) -> None:
        self.root = Path(root)
        self.skeleton = get_skeleton(skeleton) if isinstance(skeleton, str) else skeleton
        if not self.root.is_dir():
            raise DatasetError(f"data set directory {self.root} does not exist")
        for sub in ("new_joint_vecs", "texts"):
            if not (self.root / sub).is_dir():
                raise DatasetError(f"{self.root} is not a HumanML3D-format directory: no {sub}/")
        if split not in SPLITS:
            raise DatasetError(f"unknown split {split!r}; expected one of {SPLITS}")
        split_file = self.root / f"{split}.txt"
        if not split_file.is_file():
            raise DatasetError(f"missing split file {split_file}")
        self.split = split
        self.min_frames = min_frames
        self.ids = [ln.strip() for ln in split_file.read_text().splitlines() if ln.strip()]

    @property
    def dim(self) -> int:
        return self.skeleton.feature_dim

    def __len__(self) -> int:
        return len(self.ids)

    def load(self, motion_id: str) -> MotionSample:
        feats = load_features(self.root / "new_joint_vecs" / f"{motion_id}.npy", self.dim)
        caps = read_captions(self.root / "texts" / f"{motion_id}.txt")
        return MotionSample(id=motion_id, features=feats, captions=caps)

    def __getitem__(self, i: int) -> MotionSample:
        return self.load(self.ids[i])

    def __iter__(self) -> Iterator[MotionSample]:
        for mid in self.ids:
            s = self.load(mid)
            if len(s) >= self.min_frames:
                yield s

    def normalizer(self):
        from ..body.features import Normalizer

        try:
            return Normalizer.load(self.root)
        except FileNotFoundError:
            raise DatasetError(f"{self.root} has no Mean.npy / Std.npy") from None


def write_sample(root: str | Path, sample: MotionSample) -> None:
    """Write one clip (features + captions) into a HumanML3D-format directory."""
    r = Path(root)
    (r / "new_joint_vecs").mkdir(parents=True, exist_ok=True)
    (r / "texts").mkdir(parents=True, exist_ok=True)
    np.save(r / "new_joint_vecs" / f"{sample.id}.npy", sample.features.astype(np.float32))
    (r / "texts" / f"{sample.id}.txt").write_text(
        "\n".join(c.to_line() for c in sample.captions) + "\n", encoding="utf-8"
    )


def write_splits(root: str | Path, splits: dict[str, list[str]]) -> None:
    r = Path(root)
    r.mkdir(parents=True, exist_ok=True)
    for name, ids in splits.items():
        if name not in SPLITS:
            raise DatasetError(f"unknown split {name!r}")
        (r / f"{name}.txt").write_text("".join(f"{i}\n" for i in ids))
