"""HumanML3D motion features <-> global joint positions, and normalisation.

Feature layout per frame (J joints; J = 22 gives 263 dims), see :class:`FeatureLayout`::

    root angular velocity about y (1)   half-angle per frame, as the data set stores it
    root linear velocity x, z (2)       in the body-facing frame of the next frame
    root height (1)
    ric: root-relative positions (J-1)*3  xz relative to the root, y absolute, facing +z
    rot: 6D rotations (J-1)*6           first two columns of each bone's local rotation
    local velocities J*3                 joint velocity in the body-facing frame
    foot contacts (4)                   left ankle, left toe, right ankle, right toe

``features_to_joints`` follows the data set's own recovery from rotation-invariant
coordinates (``recover_from_ric``): the root rotation is integrated from the angular
velocity starting at 0, the root xz from the rotated linear velocities starting at the
origin, the root height is read directly, and the ric positions are rotated back.

``joints_to_features`` is its inverse. T joint frames give T-1 feature frames (velocities
need the next frame), as in the data set. Our departures from the data set's script, all
documented because they change no recovered position:

* The facing direction is smoothed as in HumanML3D (Gaussian, sigma 20 frames), but the
  motion is canonicalised so that the *smoothed* facing of frame 0 is +z; the data set
  canonicalises by the raw facing, which leaves a small constant yaw after recovery. Ours
  makes the round trip exact.
* 6D rotations come from our own swing-only IK (each bone's rotation maps its
  ``raw_directions`` reference onto the observed bone direction, accumulated down each
  chain from the parent's global rotation; arm chains start from spine3's rotation). The
  data set's script starts every chain from the root rotation. Twist about a bone cannot be
  seen in joint positions, so it is zero here.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import torch
from scipy.ndimage import gaussian_filter1d

from .skeleton import HUMANML3D, Skeleton

FOOT_CONTACT_THRESHOLD = 0.002  # squared displacement per frame (m^2), as in HumanML3D
FACING_SMOOTH_SIGMA = 20.0  # frames


@dataclass(frozen=True)
class FeatureLayout:
    """Slices of the feature vector for a skeleton of ``n_joints`` joints."""

    n_joints: int

    @property
    def root_rot_vel(self) -> slice:
        return slice(0, 1)

    @property
    def root_lin_vel(self) -> slice:
        return slice(1, 3)

    @property
    def root_height(self) -> slice:
        return slice(3, 4)

    @property
    def ric(self) -> slice:
        return slice(4, 4 + (self.n_joints - 1) * 3)

    @property
    def rot6d(self) -> slice:
        s = self.ric.stop
        return slice(s, s + (self.n_joints - 1) * 6)

    @property
    def local_vel(self) -> slice:
        s = self.rot6d.stop
        return slice(s, s + self.n_joints * 3)

    @property
    def foot_contact(self) -> slice:
        s = self.local_vel.stop
        return slice(s, s + 4)

    @property
    def dim(self) -> int:
        return self.foot_contact.stop

    def groups(self) -> dict[str, slice]:
        return {
            "root_rot_vel": self.root_rot_vel,
            "root_lin_vel": self.root_lin_vel,
            "root_height": self.root_height,
            "ric": self.ric,
            "rot6d": self.rot6d,
            "local_vel": self.local_vel,
            "foot_contact": self.foot_contact,
        }


HML_LAYOUT = FeatureLayout(HUMANML3D.n_joints)


# ---------------------------------------------------------------------------------------
# Rotation helpers about the y axis. rot_y(v, a) rotates v by angle a (radians) about +y,
# the same matrix a quaternion (cos a/2, 0, sin a/2, 0) applies.
# ---------------------------------------------------------------------------------------


def _rot_y_torch(v: torch.Tensor, ang: torch.Tensor) -> torch.Tensor:
    """v: (..., 3), ang: (...) broadcastable to v[..., 0]."""
    c, s = torch.cos(ang), torch.sin(ang)
    x, y, z = v[..., 0], v[..., 1], v[..., 2]
    return torch.stack([x * c + z * s, y, -x * s + z * c], dim=-1)


def rotate_y(v: np.ndarray, ang: np.ndarray | float) -> np.ndarray:
    """Rotate (..., 3) vectors about +y by ``ang`` radians; the heading atan2(x, z) grows by ang."""
    return _rot_y_np(v, ang)


def _rot_y_np(v: np.ndarray, ang: np.ndarray) -> np.ndarray:
    c, s = np.cos(ang), np.sin(ang)
    x, y, z = v[..., 0], v[..., 1], v[..., 2]
    return np.stack([x * c + z * s, y, -x * s + z * c], axis=-1)


def features_to_joints(
    features: np.ndarray | torch.Tensor, n_joints: int = HUMANML3D.n_joints
) -> np.ndarray | torch.Tensor:
    """Recover global joint positions from un-normalised features.

    Args:
        features: (..., T, D) features, D = feature_dim(n_joints); numpy or torch.
    Returns:
        (..., T, J, 3) joint positions in metres, same array type (torch keeps gradients).
    """
    is_np = isinstance(features, np.ndarray)
    x = torch.from_numpy(np.asarray(features)) if is_np else features
    layout = FeatureLayout(n_joints)
    if x.shape[-1] != layout.dim:
        raise ValueError(f"expected feature dim {layout.dim} for {n_joints} joints, got {x.shape[-1]}")
    x = x.to(torch.float64) if is_np else x
    # Half-angles integrated from frame 0 = 0; the full yaw is twice the stored value.
    half = torch.zeros_like(x[..., 0])
    half[..., 1:] = x[..., :-1, 0]
    yaw = 2.0 * torch.cumsum(half, dim=-1)  # (..., T)

    vel = torch.zeros((*x.shape[:-1], 3), dtype=x.dtype, device=x.device)
    vel[..., 1:, 0] = x[..., :-1, 1]
    vel[..., 1:, 2] = x[..., :-1, 2]
    root = torch.cumsum(_rot_y_torch(vel, -yaw), dim=-2)  # (..., T, 3)
    root = torch.cat([root[..., :1], x[..., 3:4], root[..., 2:3]], dim=-1)

    ric = x[..., layout.ric].reshape((*x.shape[:-1], n_joints - 1, 3))
    body = _rot_y_torch(ric, -yaw[..., None])
    body = body + torch.stack([root[..., 0], torch.zeros_like(root[..., 0]), root[..., 2]], dim=-1)[..., None, :]
    joints = torch.cat([root[..., None, :], body], dim=-2)
    if is_np:
        return joints.numpy().astype(np.asarray(features).dtype, copy=False)
    return joints


# ---------------------------------------------------------------------------------------
# joints -> features
# ---------------------------------------------------------------------------------------


def facing_angles(joints: np.ndarray, skeleton: Skeleton = HUMANML3D, smooth: bool = True) -> np.ndarray:
    """Heading angle per frame: atan2(fx, fz) of the facing direction.

    The facing direction is up x (hip_r - hip_l + shoulder_r - shoulder_l), so a body whose
    left is +x faces +z. Args: joints (T, J, 3). Returns (T,) radians.
    """
    r_hip, l_hip, r_sh, l_sh = skeleton.face_joints
    across = (joints[:, r_hip] - joints[:, l_hip]) + (joints[:, r_sh] - joints[:, l_sh])
    across = across / np.linalg.norm(across, axis=-1, keepdims=True).clip(1e-8)
    forward = np.cross(np.array([0.0, 1.0, 0.0]), across)
    if smooth and len(forward) > 1:
        forward = gaussian_filter1d(forward, FACING_SMOOTH_SIGMA, axis=0, mode="nearest")
    return np.arctan2(forward[:, 0], forward[:, 2])


def canonicalize(joints: np.ndarray, skeleton: Skeleton = HUMANML3D, floor: bool = True) -> np.ndarray:
    """Put a motion where recovery expects it: root xz at the origin and the smoothed facing
    of frame 0 along +z at frame 0; with ``floor`` the lowest joint over the clip at y = 0.

    Args: joints (T, J, 3). Returns (T, J, 3) float64.
    """
    j = np.asarray(joints, dtype=np.float64).copy()
    if floor:
        j[..., 1] -= j[..., 1].min()
    j[..., 0] -= j[0, 0, 0]
    j[..., 2] -= j[0, 0, 2]
    heading0 = facing_angles(j, skeleton)[0]
    return _rot_y_np(j, -heading0)


def _quat_between(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Shortest-arc rotation matrices mapping unit vectors u to v. (N, 3), (N, 3) -> (N, 3, 3)."""
    axis = np.cross(u, v)
    cos = np.einsum("ni,ni->n", u, v)
    w = 1.0 + cos
    q = np.concatenate([w[:, None], axis], axis=-1)
    # Opposite vectors: rotate by pi about any axis perpendicular to u.
    opp = w < 1e-8
    if opp.any():
        perp = np.cross(u[opp], np.array([1.0, 0.0, 0.0]))
        bad = np.linalg.norm(perp, axis=-1) < 1e-6
        perp[bad] = np.cross(u[opp][bad], np.array([0.0, 0.0, 1.0]))
        q[opp] = np.concatenate([np.zeros((opp.sum(), 1)), perp], axis=-1)
    q /= np.linalg.norm(q, axis=-1, keepdims=True)
    return _quat_to_mat(q)


def _quat_to_mat(q: np.ndarray) -> np.ndarray:
    w, x, y, z = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    return np.stack(
        [
            np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
            np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
            np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1),
        ],
        -2,
    )


def _yaw_mat(ang: np.ndarray) -> np.ndarray:
    """(T,) -> (T, 3, 3) rotation about +y by ang."""
    c, s = np.cos(ang), np.sin(ang)
    z, o = np.zeros_like(ang), np.ones_like(ang)
    return np.stack([np.stack([c, z, s], -1), np.stack([z, o, z], -1), np.stack([-s, z, c], -1)], -2)


def local_rotations(joints: np.ndarray, skeleton: Skeleton = HUMANML3D, yaw: np.ndarray | None = None) -> np.ndarray:
    """Swing-only IK: local rotation matrix per bone, indexed by the bone's child joint.

    Args:
        joints: (T, J, 3) global positions.
        yaw: (T,) root heading (rotation about +y mapping +z to the facing); computed if None.
    Returns:
        (T, J, 3, 3); entry 0 is the root's global rotation (the yaw), entry c the rotation of
        bone parent(c)->c relative to the parent's accumulated global rotation.
    """
    T, J = joints.shape[:2]
    if yaw is None:
        yaw = facing_angles(joints, skeleton)
    local = np.tile(np.eye(3), (T, J, 1, 1))
    glob = np.tile(np.eye(3), (T, J, 1, 1))
    glob[:, 0] = local[:, 0] = _yaw_mat(yaw)
    for chain in skeleton.chains:
        for p, c in itertools.pairwise(chain):
            v = joints[:, c] - joints[:, p]
            v = v / np.linalg.norm(v, axis=-1, keepdims=True).clip(1e-9)
            v_parent = np.einsum("tji,tj->ti", glob[:, p], v)  # R_p^T v
            u = np.broadcast_to(skeleton.raw_directions[c], v.shape)
            local[:, c] = _quat_between(u, v_parent)
            glob[:, c] = glob[:, p] @ local[:, c]
    return local


def joints_to_features(
    joints: np.ndarray | torch.Tensor, skeleton: Skeleton = HUMANML3D, canonical: bool = True
) -> np.ndarray:
    """Global joint positions to HumanML3D features.

    Args:
        joints: (T, J, 3) metres, y up, T >= 2.
        canonical: canonicalise first (floor, origin, facing +z); pass False only for joints
            that are already canonical (the round trip is then exact).
    Returns:
        (T-1, D) float32 features.
    """
    j = np.asarray(joints.detach().cpu() if isinstance(joints, torch.Tensor) else joints, dtype=np.float64)
    if j.ndim != 3 or j.shape[1] != skeleton.n_joints or j.shape[2] != 3:
        raise ValueError(f"expected joints of shape (T, {skeleton.n_joints}, 3), got {j.shape}")
    if len(j) < 2:
        raise ValueError("need at least 2 frames to compute velocities")
    if canonical:
        j = canonicalize(j, skeleton)
    heading = facing_angles(j, skeleton)
    yaw = -heading  # rotation that turns the body's facing onto +z
    yaw = yaw - yaw[0] if canonical else yaw  # frame 0 exactly identity after canonicalising

    root = j[:, 0]
    d_yaw = np.angle(np.exp(1j * (yaw[1:] - yaw[:-1])))  # wrapped to (-pi, pi]
    rot_vel = d_yaw / 2.0  # the data set stores half-angles (arcsin of a quaternion's y)
    lin_vel = _rot_y_np(root[1:] - root[:-1], yaw[1:])[:, [0, 2]]
    root_y = root[:-1, 1:2]

    rel = j.copy()
    rel[..., 0] -= root[:, None, 0]
    rel[..., 2] -= root[:, None, 2]
    ric = _rot_y_np(rel, yaw[:, None])[:, 1:]  # (T, J-1, 3)

    # Global rotation of the root is the inverse of the canonicalising yaw.
    local = local_rotations(j, skeleton, yaw=-yaw)
    rot6d = np.concatenate([local[:, 1:, :, 0], local[:, 1:, :, 1]], axis=-1)  # (T, J-1, 6)

    local_vel = _rot_y_np(j[1:] - j[:-1], yaw[:-1, None])  # (T-1, J, 3)

    contacts = []
    for ankle, toe in skeleton.feet:
        sq = ((j[1:, [ankle, toe]] - j[:-1, [ankle, toe]]) ** 2).sum(-1)
        contacts.append((sq < FOOT_CONTACT_THRESHOLD).astype(np.float64))
    T1 = len(j) - 1
    feats = np.concatenate(
        [
            rot_vel[:, None],
            lin_vel,
            root_y,
            ric[:-1].reshape(T1, -1),
            rot6d[:-1].reshape(T1, -1),
            local_vel.reshape(T1, -1),
            contacts[0],
            contacts[1],
        ],
        axis=-1,
    )
    return feats.astype(np.float32)


# ---------------------------------------------------------------------------------------
# Normalisation
# ---------------------------------------------------------------------------------------


@dataclass
class Normalizer:
    """Feature-wise standardisation with a data set's Mean.npy / Std.npy.

    mean, std: (D,). ``normalize(x) = (x - mean) / std``; works on numpy or torch (..., D).
    """

    mean: np.ndarray
    std: np.ndarray

    def __post_init__(self) -> None:
        self.mean = np.asarray(self.mean, dtype=np.float32)
        self.std = np.asarray(self.std, dtype=np.float32)
        if self.mean.shape != self.std.shape or self.mean.ndim != 1:
            raise ValueError(f"mean/std must be equal 1-D shapes, got {self.mean.shape} and {self.std.shape}")
        if (self.std <= 0).any():
            raise ValueError("std must be positive everywhere")

    @property
    def dim(self) -> int:
        return int(self.mean.shape[0])

    @classmethod
    def load(cls, directory: str | Path) -> Normalizer:
        d = Path(directory)
        return cls(np.load(d / "Mean.npy"), np.load(d / "Std.npy"))

    def save(self, directory: str | Path) -> None:
        d = Path(directory)
        d.mkdir(parents=True, exist_ok=True)
        np.save(d / "Mean.npy", self.mean)
        np.save(d / "Std.npy", self.std)

    @classmethod
    def fit(cls, motions: list[np.ndarray], layout: FeatureLayout = HML_LAYOUT, eps: float = 1e-3) -> Normalizer:
        """Statistics as the data set computes them: per-feature mean; each feature group's
        std replaced by the group's mean std, so no single coordinate dominates a group."""
        allx = np.concatenate(motions, axis=0).astype(np.float64)
        mean = allx.mean(0)
        std = allx.std(0)
        for sl in layout.groups().values():
            std[sl] = std[sl].mean()
        return cls(mean, np.maximum(std, eps))

    @classmethod
    def from_moments(
        cls, s1: np.ndarray, s2: np.ndarray, n: int, layout: FeatureLayout = HML_LAYOUT, eps: float = 1e-3
    ) -> Normalizer:
        """Same statistics as :meth:`fit` from running sums (sum, sum of squares, count),
        so that a data set built in parallel never has to be held in memory at once."""
        mean = s1 / n
        std = np.sqrt(np.maximum(s2 / n - mean**2, 0.0))
        for sl in layout.groups().values():
            std[sl] = std[sl].mean()
        return cls(mean, np.maximum(std, eps))

    def _cast(self, x: np.ndarray | torch.Tensor) -> tuple[np.ndarray | torch.Tensor, ...]:
        if x.shape[-1] != self.dim:
            raise ValueError(f"feature dim {x.shape[-1]} does not match statistics dim {self.dim}")
        if isinstance(x, torch.Tensor):
            return torch.as_tensor(self.mean, dtype=x.dtype, device=x.device), torch.as_tensor(
                self.std, dtype=x.dtype, device=x.device
            )
        return self.mean, self.std

    def normalize(self, x: np.ndarray | torch.Tensor) -> np.ndarray | torch.Tensor:
        m, s = self._cast(x)
        return (x - m) / s

    def denormalize(self, x: np.ndarray | torch.Tensor) -> np.ndarray | torch.Tensor:
        m, s = self._cast(x)
        return x * s + m
