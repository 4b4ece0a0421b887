"""Every download of a generated motion: GLB (viewer, three.js, Blender), BVH and NPY.

The exporters take a ``generation.Motion`` and a target path; ``export_all`` writes the full
set into one directory (the app gives every request its own directory, so concurrent users
never share a file).
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np

from ..body.features import joints_to_features
from ..body.ik import RigFit, fit_rig
from ..body.skeleton import HUMANML3D, HUMANOID, Skeleton
from ..body.terrain import steps
from ..inference.base import Motion
from .bvh import joints_to_bvh, write_bvh
from .gltf import write_glb

# the bone names an export can use: HumanML3D's own (the default), or a humanoid rig's
# (Mixamo-style names, T-pose rest) that retargeting tools map automatically
RIGS: dict[str, Skeleton] = {"humanml3d": HUMANML3D, "humanoid": HUMANOID}


def rig_skeleton(rig: str) -> Skeleton:
    try:
        return RIGS[rig]
    except KeyError:
        raise ValueError(f"unknown rig {rig!r}; known: {', '.join(RIGS)}") from None


def motion_extras(motion: Motion, skeleton: Skeleton = HUMANML3D) -> dict[str, Any]:
    """What the viewer needs besides the animation: timeline, key frames, provenance; and, for
    a motion whose feet stand on steps, the boxes under them (``steps``, from
    ``body.terrain.steps``; a flat motion's extras have no such key, as before)."""
    out = {
        "fps": motion.fps,
        "frames": motion.frames,
        "method": motion.method,
        "seed": motion.seed,
        "segments": [{"text": t, "start": int(s), "end": int(e)} for s, e, t in motion.segments],
        "keyframes": [int(k) for k in motion.keyframes] if motion.keyframes is not None else [],
        "joint_names": list(skeleton.joint_names),
    }
    boxes = steps(motion.joints)
    if boxes:
        out["steps"] = boxes
    return out


def export_glb(motion: Motion, path: str | Path, rig: str = "humanml3d", fit: RigFit | None = None) -> Path:
    """``fit``: the motion's ``fit_rig`` on the rig's skeleton, where the caller has it."""
    sk = rig_skeleton(rig)
    return write_glb(path, motion.joints, motion.fps, skeleton=sk, extras=motion_extras(motion, sk), fit=fit)


def export_bvh(motion: Motion, path: str | Path, rig: str = "humanml3d", fit: RigFit | None = None) -> Path:
    return write_bvh(path, joints_to_bvh(motion.joints, motion.fps, skeleton=rig_skeleton(rig), fit=fit))


def export_npy(motion: Motion, features_path: str | Path, joints_path: str | Path) -> tuple[Path, Path]:
    """HumanML3D features (T-1, 263) float32, unnormalised, canonical as the data set stores
    them; and the joints (T, 22, 3) float32 in metres as generated (world placement kept)."""
    features_path, joints_path = Path(features_path), Path(joints_path)
    np.save(features_path, joints_to_features(motion.joints).astype(np.float32))
    np.save(joints_path, np.asarray(motion.joints, dtype=np.float32))
    return features_path, joints_path


def export_files(
    motion: Motion, out_dir: str | Path, stem: str = "motion", rig: str = "humanml3d"
) -> Iterator[tuple[str, Path]]:
    """``export_all`` one file at a time, the GLB first: yields ("glb", path), ("bvh", path),
    ("features", path), ("joints", path) as each is written. A viewer needs only the GLB, so
    a caller can show the motion before the other downloads exist."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    fit = fit_rig(motion.joints, rig_skeleton(rig))  # the GLB's and the BVH's rotations, fitted once
    yield "glb", export_glb(motion, out / f"{stem}.glb", rig, fit)
    yield "bvh", export_bvh(motion, out / f"{stem}.bvh", rig, fit)
    feats, joints = export_npy(motion, out / f"{stem}_features.npy", out / f"{stem}_joints.npy")
    yield "features", feats
    yield "joints", joints


def export_all(motion: Motion, out_dir: str | Path, stem: str = "motion", rig: str = "humanml3d") -> dict[str, Path]:
    """Write ``stem``.glb/.bvh, ``stem``_features.npy and ``stem``_joints.npy into out_dir;
    ``rig`` names the GLB's and BVH's bones ("humanml3d" or "humanoid", see ``RIGS``)."""
    return dict(export_files(motion, out_dir, stem, rig))
