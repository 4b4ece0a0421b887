"""Fitting joint rotations to joint positions, for exports that need a rig (BVH, glTF).

HumanML3D motions are joint positions; BVH and the animated glTF a DCC tool imports want a
rest skeleton plus per-frame local rotations. ``fit_rig`` finds them:

* bone offsets: the skeleton's rest directions scaled to the motion's mean bone lengths;
* a joint with one child: the shortest-arc rotation onto that child, its twist carried over
  from the parent (positions alone do not determine twist);
* a joint with several children (pelvis, spine3): the least-squares (Kabsch) rotation onto
  all of them, with those children's offsets refitted as their mean position in the fitted
  frame, so a rigid input (real HumanML3D data, mocap) is reproduced exactly and not only up
  to the rest pose's branch angles;
* leaves (head, feet, wrists) keep their parent's orientation.

A generated motion, whose bones stretch a little, is reproduced to within that stretch;
``residual`` gives the per-frame local translations that make it exact, which the glTF
export animates too.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from . import rig_compiled
from .skeleton import HUMANML3D, Skeleton


@dataclass
class RigFit:
    """Rotations fitted to a motion.

    Attributes:
        offsets: (J, 3) rest offset of each joint from its parent, metres (row 0 zero).
        local_rot: (T, J, 3, 3) rotation of each joint relative to its parent (root: global).
        global_rot: (T, J, 3, 3) accumulated rotations.
        root_pos: (T, 3) root position, metres.
        local_trans: (T, J, 3) exact offset of each joint from its parent in the parent's frame
            (equals ``offsets`` for a rigid input); row 0 is the root position.
        end_sites: leaf joint -> (3,) end-site offset (5 cm along the leaf's rest direction).
        parents: (J,) the skeleton's parent list.
    """

    offsets: np.ndarray
    local_rot: np.ndarray
    global_rot: np.ndarray
    root_pos: np.ndarray
    local_trans: np.ndarray
    end_sites: dict[int, np.ndarray]
    parents: tuple[int, ...]

    def positions(self, exact: bool = False) -> np.ndarray:
        """(T, J, 3) forward kinematics of the fit (rigid offsets, or the exact translations)."""
        return forward_kinematics(
            self.global_rot, self.root_pos, self.local_trans if exact else self.offsets, self.parents
        )


def forward_kinematics(
    global_rot: np.ndarray, root_pos: np.ndarray, offsets: np.ndarray, parents: tuple[int, ...]
) -> np.ndarray:
    """(T, J, 3) joint positions: global rotations (T, J, 3, 3), root path (T, 3), and each
    joint's offset from its parent in the parent's frame, (J, 3) rest offsets or (T, J, 3)
    per-frame translations."""
    T, J = global_rot.shape[:2]
    out = np.empty((T, J, 3))
    out[:, 0] = root_pos
    for j in range(1, J):
        p = parents[j]
        # matmul, not einsum: this runs for every generated motion (rigidify)
        out[:, j] = out[:, p] + (global_rot[:, p] @ offsets[..., j, :, None])[..., 0]
    return out


def kabsch(src: np.ndarray, dst: np.ndarray) -> np.ndarray:
    """Best rotations R with R @ src_k ~ dst_k. src (K, 3) rest vectors, dst (T, K, 3) -> (T, 3, 3)."""
    h = np.einsum("ki,tkj->tij", src, dst)
    u, _, vt = np.linalg.svd(h)
    d = np.sign(np.linalg.det(np.einsum("tij,tjk->tik", u, vt)))
    fix = np.ones((len(d), 3))
    fix[:, 2] = d
    return np.einsum("tji,tj,tkj->tik", vt, fix, u)


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(T, 3) x (T, 3) -> (T, 3): np.cross's arithmetic without its axis handling, which costs
    more than the products at these sizes."""
    out = np.empty(np.broadcast_shapes(a.shape, b.shape))
    out[..., 0] = a[..., 1] * b[..., 2] - a[..., 2] * b[..., 1]
    out[..., 1] = a[..., 2] * b[..., 0] - a[..., 0] * b[..., 2]
    out[..., 2] = a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]
    return out


def shortest_arc(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """(T, 3), (T, 3) unit vectors -> (T, 3, 3) smallest rotations taking u to v.

    Rodrigues' formula for unit vectors, R = c I + [w]x + w w^T / (1 + c) with w = u x v and
    c = u . v (no trigonometry, unlike building a rotation vector); pairs within about 2.6
    degrees of opposite, where 1 / (1 + c) loses digits, and zero vectors go through the
    rotation vector."""
    w = _cross(u, v)
    c = np.einsum("ti,ti->t", u, v)
    # c^2 + |w|^2 = |u|^2 |v|^2: under 1/2 a vector was zero (a bone of no length), for
    # which the rotation-vector form gives the identity and this one would give 0
    use_rotvec = (c < -0.999) | (c * c + np.einsum("ti,ti->t", w, w) < 0.5)
    k = 1.0 / np.where(use_rotvec, 1.0, 1.0 + c)
    out = w[:, :, None] * w[:, None, :] * k[:, None, None]
    out[:, 0, 0] += c
    out[:, 1, 1] += c
    out[:, 2, 2] += c
    out[:, 0, 1] -= w[:, 2]
    out[:, 0, 2] += w[:, 1]
    out[:, 1, 0] += w[:, 2]
    out[:, 1, 2] -= w[:, 0]
    out[:, 2, 0] -= w[:, 1]
    out[:, 2, 1] += w[:, 0]
    if use_rotvec.any():
        out[use_rotvec] = _shortest_arc_rotvec(u[use_rotvec], v[use_rotvec])
    return out


def _shortest_arc_rotvec(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """``shortest_arc`` through a rotation vector: exact for nearly opposite pairs too."""
    axis = np.cross(u, v)
    s = np.linalg.norm(axis, axis=-1)
    c = np.einsum("ti,ti->t", u, v)
    ang = np.arctan2(s, c)
    unit_axis = np.where(s[:, None] > 1e-12, axis / np.maximum(s, 1e-12)[:, None], 0.0)
    flip = (s <= 1e-12) & (c < 0)  # u == -v: any perpendicular axis will do
    if flip.any():
        perp = np.cross(u[flip], [1.0, 0.0, 0.0])
        small = np.linalg.norm(perp, axis=-1) < 1e-6
        perp[small] = np.cross(u[flip][small], [0.0, 0.0, 1.0])
        unit_axis[flip] = perp / np.linalg.norm(perp, axis=-1, keepdims=True)
    return Rotation.from_rotvec(unit_axis * ang[:, None]).as_matrix()


def fit_rig(joints: np.ndarray, skeleton: Skeleton = HUMANML3D, lengths: np.ndarray | None = None) -> RigFit:
    """Fit rest offsets and per-frame rotations to (T, J, 3) joint positions in metres.

    ``lengths``: (J,) bone length per joint to impose, branch children included (default:
    the motion's mean lengths).
    """
    joints = np.asarray(joints, dtype=np.float64)
    offsets, glob, rest_dir, children = _fit_global(joints, skeleton, lengths)
    parents = skeleton.parents
    local = np.empty_like(glob)
    trans = np.empty(joints.shape)
    for j, p in enumerate(parents):
        if p < 0:
            local[:, j], trans[:, j] = glob[:, j], joints[:, j]
        else:
            local[:, j] = np.swapaxes(glob[:, p], -1, -2) @ glob[:, j]
            trans[:, j] = np.einsum("tji,tj->ti", glob[:, p], joints[:, j] - joints[:, p])
    end_sites = {j: rest_dir[j] * 0.05 for j in range(len(parents)) if not children[j]}
    return RigFit(offsets, local, glob, joints[:, 0].copy(), trans, end_sites, tuple(parents))


def _fit_global(
    joints: np.ndarray, skeleton: Skeleton, lengths: np.ndarray | None
) -> tuple[np.ndarray, np.ndarray, np.ndarray, list[list[int]]]:
    """``fit_rig``'s fit itself: rest offsets (J, 3), global rotations (T, J, 3, 3), rest
    directions (J, 3) and each joint's children, for float64 joints (T, J, 3). The loop below
    is the reference; where numba imports, ``rig_compiled`` runs the same arithmetic frame
    by frame in one compiled call (about 15x faster for a 10 s motion)."""
    T, J, _ = joints.shape
    if J != skeleton.n_joints:
        raise ValueError(f"{J} joints given for the {skeleton.name} skeleton of {skeleton.n_joints}")
    if skeleton.rest_offsets is None:
        raise ValueError(f"skeleton {skeleton.name!r} has no rest offsets")
    if not np.isfinite(joints).all():
        # numpy's SVD refused NaN only at branch joints; elsewhere it flowed into the rig
        raise ValueError("joint positions must be finite (NaN or inf given)")
    parents = skeleton.parents
    children: list[list[int]] = [[] for _ in range(J)]
    for c, p in enumerate(parents):
        if p >= 0:
            children[p].append(c)
    norms = np.linalg.norm(skeleton.rest_offsets, axis=-1, keepdims=True)
    rest_dir = skeleton.rest_offsets / np.maximum(norms, 1e-12)
    imposed = lengths is not None
    if lengths is None:
        lengths = np.zeros(J)
        lengths[1:] = skeleton.measure_bone_lengths(joints).mean(axis=0)
    if rig_compiled.available():
        offsets, glob = rig_compiled.fit_rotations(joints, parents, rest_dir, lengths, imposed)
        return offsets, glob, rest_dir, children
    offsets = rest_dir * lengths[:, None]

    glob = np.empty((T, J, 3, 3))
    eye = np.tile(np.eye(3), (T, 1, 1))
    for j in range(J):  # parents precede children in every skeleton we define
        p = parents[j]
        kids = children[j]
        parent_rot = glob[:, p] if p >= 0 else eye
        if not kids:
            glob[:, j] = parent_rot
        elif len(kids) == 1 and p >= 0:
            c = kids[0]
            target = joints[:, c] - joints[:, j]
            target /= np.maximum(np.linalg.norm(target, axis=-1, keepdims=True), 1e-12)
            current = parent_rot @ rest_dir[c]
            glob[:, j] = shortest_arc(current, target) @ parent_rot
        else:
            dst = joints[:, kids] - joints[:, j : j + 1]
            for _ in range(3):
                glob[:, j] = kabsch(offsets[kids], dst)
                offsets[kids] = np.einsum("tji,tkj->ki", glob[:, j], dst) / T
                if imposed:  # keep the refitted directions, not the motion's lengths
                    norm = np.linalg.norm(offsets[kids], axis=-1, keepdims=True)
                    offsets[kids] *= lengths[kids, None] / np.maximum(norm, 1e-12)
    return offsets, glob, rest_dir, children


def rigidify(joints: np.ndarray, skeleton: Skeleton = HUMANML3D) -> np.ndarray:
    """(T, J, 3) -> (T, J, 3) float32: the motion on rigid bones of the skeleton's rest lengths.

    The HumanML3D recovery reads joint positions straight from the features and nothing
    keeps bones rigid; a generated motion's bones stretch by centimetres. Keeping the fitted
    rotations and the root path and replacing every bone by the skeleton's gives a figure
    whose bones never stretch, the same body for every method (fair side-by-side comparison),
    and one that the BVH and glTF exports reproduce exactly. ``fit_rig(...).positions()``
    without the local rotations and translations a rig needs and positions do not: every
    generated motion comes through here.
    """
    joints = np.asarray(joints, dtype=np.float64)
    offsets, glob, _, _ = _fit_global(joints, skeleton, skeleton.bone_lengths)
    fk = rig_compiled.forward_kinematics if rig_compiled.available() else forward_kinematics
    return fk(glob, joints[:, 0], offsets, skeleton.parents).astype(np.float32)
