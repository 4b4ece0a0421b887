"""The compiled rig fit (body/rig_compiled.py) against ik's numpy loop, its reference: every
generated motion and every export goes through the compiled one."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from motion_core.body import ik, rig_compiled
from motion_core.body.skeleton import HUMANML3D


@pytest.fixture
def numpy_only(monkeypatch):
    """Within the fixture's scope ``ik`` runs its numpy reference."""

    def use_reference():
        monkeypatch.setattr(rig_compiled, "available", lambda: False)

    return use_reference


def _turning_body(rng: np.random.Generator, frames: int = 80) -> np.ndarray:
    """(T, 22, 3): a body turning about a tilted axis along a path, bones stretched by cm."""
    rest = np.zeros((22, 3))
    for j in range(1, 22):
        rest[j] = rest[HUMANML3D.parents[j]] + HUMANML3D.rest_offsets[j]
    rot = Rotation.from_rotvec(np.linspace(0, 5, frames)[:, None] * np.array([0.3, 1.0, -0.2])).as_matrix()
    joints = np.einsum("tij,kj->tki", rot, rest) + 0.03 * rng.standard_normal((frames, 22, 3))
    joints[:, :, 0] += np.linspace(0, 3, frames)[:, None]
    return joints


def test_the_compiled_module_is_the_one_that_runs():
    assert rig_compiled.available()  # numba is pinned in requirements.txt


def test_rigidify_and_fit_rig_equal_the_numpy_reference(numpy_only):
    joints = _turning_body(np.random.default_rng(0))
    joints[:, 19] = joints[:, 17]  # a bone of no length: the rotation-vector path's identity
    # the left forearm folded exactly back onto its rest direction as the elbow's parent
    # turns it: the shortest arc of two opposite vectors (any perpendicular axis)
    _, glob, rest_dir, _ = ik._fit_global(joints, HUMANML3D, HUMANML3D.bone_lengths)
    back = -np.einsum("tij,j->ti", glob[5:9, 16], rest_dir[20])
    joints[5:9, 20] = joints[5:9, 18] + 0.25 * back
    fast = ik.rigidify(joints)
    fit = ik.fit_rig(joints)
    imposed = ik.fit_rig(joints, lengths=HUMANML3D.bone_lengths)
    numpy_only()
    _, ref_glob, _, _ = ik._fit_global(joints, HUMANML3D, HUMANML3D.bone_lengths)
    current = np.einsum("tij,j->ti", ref_glob[5:9, 16], rest_dir[20])
    target = joints[5:9, 20] - joints[5:9, 18]
    target /= np.linalg.norm(target, axis=1, keepdims=True)
    np.testing.assert_allclose(np.einsum("ti,ti->t", current, target), -1.0, atol=1e-12)  # opposite
    ref = ik.rigidify(joints)
    ref_fit = ik.fit_rig(joints)
    ref_imposed = ik.fit_rig(joints, lengths=HUMANML3D.bone_lengths)
    np.testing.assert_allclose(fast, ref, atol=1e-6)
    for a, b in ((fit, ref_fit), (imposed, ref_imposed)):
        np.testing.assert_allclose(a.offsets, b.offsets, atol=1e-12)
        np.testing.assert_allclose(a.global_rot, b.global_rot, atol=1e-10)
        np.testing.assert_allclose(a.local_rot, b.local_rot, atol=1e-10)
        np.testing.assert_allclose(a.positions(), b.positions(), atol=1e-10)


def test_a_frame_with_every_joint_on_one_point_keeps_its_bones(numpy_only):
    """Children on their branch joint (h = 0) or on one line (rank 1): the rotation is not
    unique, but it is a rotation, so every bone keeps its length (an eigenvector form that
    divided by the zero singular value collapsed the body onto the root)."""
    joints = _turning_body(np.random.default_rng(4), frames=12)
    joints[3] = joints[3, 0]  # every joint on the root
    joints[6, [1, 2]] = joints[6, 0]  # both hips on the pelvis: its children on one line
    fast = ik.rigidify(joints)
    bones = np.linalg.norm(fast[:, 1:] - fast[:, list(HUMANML3D.parents[1:])], axis=-1)
    np.testing.assert_allclose(bones, np.broadcast_to(HUMANML3D.bone_lengths[1:], bones.shape), atol=1e-5)
    glob = ik.fit_rig(joints).global_rot
    np.testing.assert_allclose(glob @ np.swapaxes(glob, -1, -2), np.broadcast_to(np.eye(3), glob.shape), atol=1e-9)
    np.testing.assert_allclose(np.linalg.det(glob), 1.0, atol=1e-9)
    numpy_only()
    ref = ik.rigidify(joints)
    ok = [t for t in range(len(joints)) if t not in (3, 6)]
    np.testing.assert_allclose(fast[ok], ref[ok], atol=1e-6)  # the other frames as before


def test_joint_positions_must_be_finite():
    joints = _turning_body(np.random.default_rng(5), frames=4)
    joints[2, 7, 1] = np.nan
    with pytest.raises(ValueError, match="finite"):
        ik.rigidify(joints)


def test_kabsch_by_eigenvectors_equals_the_svd_form_for_reflections_too():
    rng = np.random.default_rng(1)
    src = rng.standard_normal((3, 3))
    dst = rng.standard_normal((200, 3, 3))
    dst[100:] = np.einsum("tij,kj->tki", Rotation.random(100, random_state=2).as_matrix(), src)
    dst[150:] += 1e-3 * rng.standard_normal((50, 3, 3))
    ref = ik.kabsch(src, dst)
    h = np.einsum("ki,tkj->tij", src, dst)
    assert (np.linalg.det(h[:100]) < 0).any() and (np.linalg.det(h[:100]) > 0).any()
    out, w, v = np.empty((3, 3)), np.empty(3), np.empty((3, 3))
    for t in range(len(dst)):
        rig_compiled._kabsch(np.ascontiguousarray(h[t]), out, w, v)
        np.testing.assert_allclose(out, ref[t], atol=1e-9)
        np.testing.assert_allclose(out @ out.T, np.eye(3), atol=1e-12)
        assert np.linalg.det(out) == pytest.approx(1.0, abs=1e-12)


def test_kabsch_of_a_degenerate_h_is_a_best_rotation():
    """Rank 0, 1 and 2 (two children), and nearly collinear children: a rotation whose
    trace(R h) is the reference's maximum."""
    rng = np.random.default_rng(6)
    d = rng.standard_normal(3)
    cases = [
        np.zeros((3, 3)),
        np.outer(rng.standard_normal(3), d),  # rank 1
        np.outer(rng.standard_normal(3), d) + 1e-12 * rng.standard_normal((3, 3)),
        rng.standard_normal((2, 3)).T @ rng.standard_normal((2, 3)),  # rank 2: two children
        np.outer([1.0, 0.0, 0.0], d) + np.outer([1.0, 1e-7, 0.0], 1.01 * d + 1e-7),  # nearly collinear
    ]
    out, w, v = np.empty((3, 3)), np.empty(3), np.empty((3, 3))
    for h in cases:
        ref = ik.kabsch(np.eye(3), h[None])[0]  # src = I: h itself
        rig_compiled._kabsch(np.ascontiguousarray(h), out, w, v)
        np.testing.assert_allclose(out @ out.T, np.eye(3), atol=1e-12)
        assert np.linalg.det(out) == pytest.approx(1.0, abs=1e-12)
        assert np.trace(out @ h) == pytest.approx(np.trace(ref @ h), abs=1e-9 * max(1.0, np.abs(h).sum()))


def test_shortest_arc_equals_the_numpy_form_near_opposite_and_for_zero_vectors():
    rng = np.random.default_rng(3)
    u = rng.standard_normal((60, 3))
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    v = rng.standard_normal((60, 3))
    v /= np.linalg.norm(v, axis=1, keepdims=True)
    v[:10] = -u[:10]
    v[10:20] = Rotation.from_rotvec(0.01 * np.cross(u[10:20], [0.0, 0.0, 1.0])).apply(-u[10:20])
    v[20:25] = u[20:25]
    v[25:30] = 0.0
    u[0] = [1.0, 0.0, 0.0]  # opposite along x: u x (1, 0, 0) = 0, the second axis is used
    v[0] = [-1.0, 0.0, 0.0]
    ref = ik.shortest_arc(u, v)
    out = np.empty((3, 3))
    for t in range(len(u)):
        rig_compiled._shortest_arc(u[t], v[t], out)
        np.testing.assert_allclose(out, ref[t], atol=1e-12)
