"""The skinned mannequin: one watertight body whose proportions follow the
motion's bones, with smooth weights that bend a knee without tearing."""

from __future__ import annotations

import numpy as np
import trimesh
from scipy.spatial.transform import Rotation

from motion_core.body.mannequin import build_mannequin
from motion_core.body.skeleton import HUMANML3D


def test_the_body_is_one_watertight_mesh_with_normalised_weights() -> None:
    m = build_mannequin(HUMANML3D.rest_joints())
    mesh = trimesh.Trimesh(m.vertices, m.faces, process=False)
    assert mesh.is_watertight and mesh.is_winding_consistent and mesh.body_count == 1
    assert 500 < len(m.vertices) < 5000  # low-poly
    assert m.joints.shape == m.weights.shape == (len(m.vertices), 4)
    np.testing.assert_allclose(m.weights.sum(1), 1.0, atol=1e-6)
    assert (m.weights >= 0).all() and int(m.joints.max()) < 22
    # every joint that moves a part drives some vertices (head, hands, feet, spine, ...)
    driven = set(np.unique(m.joints[m.weights > 0.5]).tolist())
    assert {HUMANML3D.joint_names.index(n) for n in ("head", "left_wrist", "right_knee", "spine3")} <= driven


def test_its_proportions_follow_the_rest_joints() -> None:
    rest = HUMANML3D.rest_joints()
    a = build_mannequin(rest)
    b = build_mannequin(rest * np.array([1.0, 1.25, 1.0]))  # a taller skeleton
    height = lambda m: float(np.ptp(m.vertices[:, 1]))  # noqa: E731
    assert height(b) > 1.2 * height(a) * 0.95
    # the feet reach the rest ankles' level, the head tops the head joint
    head = HUMANML3D.joint_names.index("head")
    assert a.vertices[:, 1].max() > rest[head, 1] + 0.05
    assert a.vertices[:, 1].min() < rest[:, 1].min()


def stretch(m, rest: np.ndarray, joint: str, axis: str, weights: np.ndarray | None = None) -> float:
    """Largest edge stretch (posed / rest length, edges over 1 mm) with ``joint`` bent 90
    degrees about ``axis`` by linear-blend skinning."""
    knee = HUMANML3D.joint_names.index(joint)
    below = {knee}
    for j, p in enumerate(HUMANML3D.parents):
        if p in below:
            below.add(j)
    # per-joint transforms: joints at and below the knee rotate about the knee
    R = Rotation.from_euler(axis, 90, degrees=True).as_matrix()
    mats = np.tile(np.eye(4), (22, 1, 1))
    for j in below:
        mats[j, :3, :3] = R
        mats[j, :3, 3] = rest[knee] - R @ rest[knee]
    w = m.weights if weights is None else weights
    v = np.c_[m.vertices, np.ones(len(m.vertices))]
    posed = sum(w[:, k, None] * np.einsum("vij,vj->vi", mats[m.joints[:, k]], v)[:, :3] for k in range(4))
    edges = trimesh.Trimesh(m.vertices, m.faces, process=False).edges_unique
    rest_len = np.linalg.norm(m.vertices[edges[:, 0]] - m.vertices[edges[:, 1]], axis=-1)
    posed_len = np.linalg.norm(posed[edges[:, 0]] - posed[edges[:, 1]], axis=-1)
    keep = rest_len > 1e-3  # the union leaves a few sub-millimetre slivers where parts meet
    return float((posed_len[keep] / rest_len[keep]).max())


def test_a_bent_knee_or_elbow_tears_nothing_apart() -> None:
    """Bent 90 degrees, rigid weights (each vertex on its one strongest joint) stretch the
    triangles across the joint into long slivers; the smooth weights keep every edge within
    a small factor of its rest length."""
    rest = HUMANML3D.rest_joints()
    m = build_mannequin(rest)
    rigid = np.zeros_like(m.weights)
    rigid[:, 0] = 1.0
    for joint, axis in (("left_knee", "x"), ("right_elbow", "z")):
        assert stretch(m, rest, joint, axis) < 3.0, joint
        assert stretch(m, rest, joint, axis, rigid) > 10.0, joint
