"""Small generated motions for tests (forward kinematics of smooth random rotations)."""

from __future__ import annotations

import numpy as np
from scipy.ndimage import gaussian_filter1d
from scipy.spatial.transform import Rotation

from motion_core.body.skeleton import HUMANML3D


def random_fk_motion(T: int = 120, seed: int = 0, turn: float = 2.0) -> np.ndarray:
    """(T, 22, 3) joints: random smooth joint rotations on the rest skeleton, a root that
    walks and turns by ``turn`` radians. Bone lengths are exact by construction."""
    rng = np.random.default_rng(seed)
    S = HUMANML3D
    rotvec = gaussian_filter1d(rng.normal(0, 1.5, (T, S.n_joints, 3)), 6, axis=0)
    rotvec[:, 0] = 0.0
    local = Rotation.from_rotvec(rotvec.reshape(-1, 3)).as_matrix().reshape(T, S.n_joints, 3, 3)
    yaw = np.linspace(0, turn, T) + 0.3
    root_rot = Rotation.from_euler("y", yaw[:, None]).as_matrix()
    glob = np.zeros_like(local)
    joints = np.zeros((T, S.n_joints, 3))
    heading = np.stack([np.sin(yaw), np.zeros(T), np.cos(yaw)], -1)
    joints[:, 0] = np.cumsum(heading * 0.05, axis=0) + np.array([1.0, 0.95, -2.0])
    for j, p in enumerate(S.parents):
        if p < 0:
            glob[:, j] = root_rot @ local[:, j]
            continue
        glob[:, j] = glob[:, p] @ local[:, j]
        joints[:, j] = joints[:, p] + np.einsum("tij,j->ti", glob[:, p], S.rest_offsets[j])
    return joints
