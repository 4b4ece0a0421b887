"""The fit's fast paths (body/ik.py): every generated motion goes through ``rigidify``, so it
skips what only a rig needs and builds the shortest arcs by Rodrigues' formula; both must
give what the general forms give."""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from motion_core.body.ik import _shortest_arc_rotvec, fit_rig, rigidify, shortest_arc
from motion_core.body.skeleton import HUMANML3D


def _units(rng: np.random.Generator, n: int) -> np.ndarray:
    v = rng.standard_normal((n, 3))
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def _tilted(u: np.ndarray, degrees: float, rng: np.random.Generator) -> np.ndarray:
    """Each row of u turned by ``degrees`` about a random axis perpendicular to it."""
    axis = np.cross(u, _units(rng, len(u)))
    axis /= np.linalg.norm(axis, axis=1, keepdims=True)
    return Rotation.from_rotvec(np.radians(degrees) * axis).apply(u)


def test_shortest_arc_by_rodrigues_equals_the_rotation_vector_form_near_opposite_too():
    rng = np.random.default_rng(0)
    u, v = _units(rng, 400), _units(rng, 400)
    v[:10] = -u[:10]  # opposite: any perpendicular axis; the rotation-vector path decides
    v[10:20] = _tilted(-u[10:20], 1.0, rng)  # inside the 2.56 degrees handed to that path
    v[20:30] = _tilted(-u[20:30], 5.0, rng)  # outside: Rodrigues' formula
    v[30:40] = u[30:40]  # the identity
    r = shortest_arc(u, v)
    np.testing.assert_allclose(r, _shortest_arc_rotvec(u, v), atol=1e-12)
    np.testing.assert_allclose(np.einsum("tij,tj->ti", r, u), v, atol=1e-12)
    np.testing.assert_allclose(np.linalg.det(r), 1.0, atol=1e-12)


def test_a_bone_of_no_length_gets_the_identity_not_a_zero_matrix():
    # a parent and child joint at one point (an imported clip can have it): the old form
    # gave the identity, and a zero matrix would collapse every descendant onto the joint
    u = _units(np.random.default_rng(2), 3)
    v = np.array([[0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 0.0]])
    v[1] = u[1]
    r = shortest_arc(u, v)
    np.testing.assert_allclose(r, np.broadcast_to(np.eye(3), (3, 3, 3)), atol=1e-12)
    joints = np.zeros((4, 22, 3))
    for j in range(1, 22):
        joints[:, j] = joints[:, HUMANML3D.parents[j]] + HUMANML3D.rest_offsets[j]
    joints[:, 19] = joints[:, 17]  # the right elbow on the right shoulder, its parent
    fast = rigidify(joints)
    assert np.isfinite(fast).all()
    bones = np.linalg.norm(fast[:, 1:] - fast[:, list(HUMANML3D.parents[1:])], axis=-1)
    np.testing.assert_allclose(bones, np.broadcast_to(HUMANML3D.bone_lengths[1:], bones.shape), atol=1e-5)


def test_rigidify_is_the_fits_forward_kinematics_on_rest_lengths():
    rng = np.random.default_rng(1)
    rest = np.zeros((22, 3))
    for j in range(1, 22):
        rest[j] = rest[HUMANML3D.parents[j]] + HUMANML3D.rest_offsets[j]
    # a turning, stretching body: rotations, a path and bone noise of centimetres
    rot = Rotation.from_rotvec(np.linspace(0, 3, 60)[:, None] * np.array([0.1, 1.0, 0.2])).as_matrix()
    joints = np.einsum("tij,kj->tki", rot, rest) + 0.02 * rng.standard_normal((60, 22, 3))
    joints[:, :, 2] += np.linspace(0, 2, 60)[:, None]
    fast = rigidify(joints)
    full = fit_rig(joints, lengths=HUMANML3D.bone_lengths).positions()
    assert fast.dtype == np.float32
    np.testing.assert_allclose(fast, full, atol=1e-6)
    bones = np.linalg.norm(fast[:, 1:] - fast[:, list(HUMANML3D.parents[1:])], axis=-1)
    np.testing.assert_allclose(bones, np.broadcast_to(HUMANML3D.bone_lengths[1:], bones.shape), atol=1e-5)
