"""Every download of a generated motion: GLB (viewer, three.js, Blender), BVH and NPY.

The exporters take a ``generation.Motion`` and a target path; ``export_all`` writes the full
set into one directory (the app gives every request its own directory, so concurrent users
never share a file).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from ..body.features import joints_to_features
from ..body.skeleton import HUMANML3D
from ..inference.base import Motion
from .bvh import joints_to_bvh, write_bvh
from .gltf import write_glb


def motion_extras(motion: Motion) -> dict[str, Any]:
    """What the viewer needs besides the animation: timeline, key frames, provenance."""
    return {
        "fps": motion.fps,
        "frames": motion.frames,
        "method": motion.method,
        "seed": motion.seed,
        "segments": [{"text": t, "start": int(s), "end": int(e)} for s, e, t in motion.segments],
        "keyframes": [int(k) for k in motion.keyframes] if motion.keyframes is not None else [],
        "joint_names": list(HUMANML3D.joint_names),
    }


def export_glb(motion: Motion, path: str | Path) -> Path:
    return write_glb(path, motion.joints, motion.fps, extras=motion_extras(motion))


def export_bvh(motion: Motion, path: str | Path) -> Path:
    return write_bvh(path, joints_to_bvh(motion.joints, motion.fps))


def export_npy(motion: Motion, features_path: str | Path, joints_path: str | Path) -> tuple[Path, Path]:
    """HumanML3D features (T-1, 263) float32, unnormalised, canonical as the data set stores
    them; and the joints (T, 22, 3) float32 in metres as generated (world placement kept)."""
    features_path, joints_path = Path(features_path), Path(joints_path)
    np.save(features_path, joints_to_features(motion.joints).astype(np.float32))
    np.save(joints_path, np.asarray(motion.joints, dtype=np.float32))
    return features_path, joints_path


def export_all(motion: Motion, out_dir: str | Path, stem: str = "motion") -> dict[str, Path]:
    """Write ``stem``.glb/.bvh, ``stem``_features.npy and ``stem``_joints.npy into out_dir."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    feats, joints = export_npy(motion, out / f"{stem}_features.npy", out / f"{stem}_joints.npy")
    return {
        "glb": export_glb(motion, out / f"{stem}.glb"),
        "bvh": export_bvh(motion, out / f"{stem}.bvh"),
        "features": feats,
        "joints": joints,
    }
