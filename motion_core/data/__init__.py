"""Data set readers: HumanML3D / KIT-ML directories and BABEL-style segment annotations."""

from .babel import BabelSegments, Segment, SegmentedMotion, write_babel
from .humanml3d import Caption, DatasetError, HumanML3DDataset, MotionSample, write_sample, write_splits

__all__ = [
    "BabelSegments",
    "Caption",
    "DatasetError",
    "HumanML3DDataset",
    "MotionSample",
    "Segment",
    "SegmentedMotion",
    "write_babel",
    "write_sample",
    "write_splits",
]
