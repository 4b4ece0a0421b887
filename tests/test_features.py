import itertools

import numpy as np
import pytest
import torch
from motion_helpers import random_fk_motion

from motion_core.body.features import (
    HML_LAYOUT,
    Normalizer,
    canonicalize,
    facing_angles,
    features_to_joints,
    joints_to_features,
    local_rotations,
)
from motion_core.body.skeleton import HUMANML3D


def test_layout_is_263():
    assert HML_LAYOUT.dim == 263
    assert (HML_LAYOUT.ric.start, HML_LAYOUT.rot6d.start, HML_LAYOUT.local_vel.start) == (4, 67, 193)
    assert HML_LAYOUT.foot_contact == slice(259, 263)


def test_real_fixture_is_a_plausible_human(real_features):
    j = features_to_joints(real_features)
    assert j.shape == (170, 22, 3) and j.dtype == np.float32
    # Root height as stored in the file (~0.84 m at the start), recovered unchanged.
    assert abs(j[0, 0, 1] - 0.837) < 0.01 and 0.75 < j[:, 0, 1].mean() < 0.95
    # Feet touch the ground: the lowest joint of the clip is at y = 0 and it is a foot joint.
    feet = [7, 8, 10, 11]
    assert abs(j[..., 1].min()) < 0.01
    assert j[:, feet, 1].min() == pytest.approx(j[..., 1].min())
    # Where the file's own contact labels say a foot joint is down, it is mostly on the floor
    # (the labels are velocity-based, so a foot held still in the air also counts as 'contact':
    # only the bulk is checked), and lower than when it is not in contact.
    contact = real_features[:-1, HML_LAYOUT.foot_contact] > 0.5  # (T-1, 4): l ankle, l toe, r ankle, r toe
    heights = j[1:, [7, 10, 8, 11], 1]  # contact t is measured between frames t and t+1
    assert contact.mean() > 0.3
    assert np.median(heights[contact]) < 0.06 and np.percentile(heights[contact], 90) < 0.10
    assert np.median(heights[contact]) < np.median(heights[~contact])
    # Bone lengths are constant over the clip.
    lengths = HUMANML3D.measure_bone_lengths(j)
    assert lengths.std(axis=0).max() < 1e-4
    # The head is above the pelvis in every frame, well above it in a typical frame
    # (this clip bends down deeply at one point, so no per-frame margin is asserted).
    assert (j[:, 15, 1] > j[:, 0, 1]).all() and np.median(j[:, 15, 1] - j[:, 0, 1]) > 0.4


def test_foot_contacts_in_file_match_recovered_velocity(real_features):
    """The stored contact labels agree with contacts recomputed from recovered joints."""
    j = features_to_joints(real_features.astype(np.float64))
    f = joints_to_features(j, canonical=False)
    stored = real_features[:-1, HML_LAYOUT.foot_contact]
    assert (f[:, HML_LAYOUT.foot_contact] == stored).mean() > 0.97


@pytest.mark.parametrize("dtype", [np.float64, np.float32])
def test_round_trip_real(real_features, dtype):
    joints = features_to_joints(real_features.astype(np.float64))
    canon = canonicalize(joints)
    back = features_to_joints(joints_to_features(joints).astype(dtype))
    assert np.abs(back - canon[:-1]).max() < 1e-4


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_round_trip_generated(seed):
    joints = random_fk_motion(T=150, seed=seed, turn=4.0)
    canon = canonicalize(joints)
    back = features_to_joints(joints_to_features(joints))
    assert np.abs(back - canon[:-1]).max() < 1e-4
    # canonical frame 0: root xz at the origin, facing +z
    assert np.allclose(canon[0, 0, [0, 2]], 0.0) and abs(facing_angles(canon)[0]) < 1e-9


def test_canonicalize_is_idempotent_and_invariant_to_world_yaw():
    joints = random_fk_motion(T=80, seed=3)
    c1 = canonicalize(joints)
    assert np.abs(canonicalize(c1) - c1).max() < 1e-9
    ang = 1.1
    R = np.array([[np.cos(ang), 0, np.sin(ang)], [0, 1, 0], [-np.sin(ang), 0, np.cos(ang)]])
    c2 = canonicalize(joints @ R.T + np.array([5.0, 0.2, -3.0]))
    assert np.abs(c2 - c1).max() < 1e-9


def test_ik_rotations_reproduce_bone_directions():
    joints = canonicalize(random_fk_motion(T=40, seed=5))
    local = local_rotations(joints)
    glob = np.zeros_like(local)
    glob[:, 0] = local[:, 0]
    for chain in HUMANML3D.chains:
        for p, c in itertools.pairwise(chain):
            glob[:, c] = glob[:, p] @ local[:, c]
            bone = joints[:, c] - joints[:, p]
            pred = np.einsum("tij,j->ti", glob[:, c], HUMANML3D.raw_directions[c])
            assert np.abs(pred - bone / np.linalg.norm(bone, axis=-1, keepdims=True)).max() < 1e-6
    # 6D is a valid rotation representation: orthonormal first two columns.
    f = joints_to_features(joints)
    r6 = f[:, HML_LAYOUT.rot6d].reshape(len(f), 21, 6)
    assert np.allclose(np.linalg.norm(r6[..., :3], axis=-1), 1, atol=1e-5)
    assert np.allclose((r6[..., :3] * r6[..., 3:]).sum(-1), 0, atol=1e-5)


def test_torch_input_and_gradients(real_features):
    x = torch.tensor(real_features[None], requires_grad=True)  # batch dim (1, T, 263)
    j = features_to_joints(x)
    assert isinstance(j, torch.Tensor) and j.shape == (1, 170, 22, 3)
    ref = features_to_joints(real_features)
    assert np.abs(j[0].detach().numpy() - ref).max() < 1e-5
    j.pow(2).sum().backward()
    assert x.grad is not None and torch.isfinite(x.grad).all() and x.grad.abs().sum() > 0


def test_shape_errors():
    with pytest.raises(ValueError, match="feature dim"):
        features_to_joints(np.zeros((10, 250), np.float32))
    with pytest.raises(ValueError, match="shape"):
        joints_to_features(np.zeros((10, 21, 3)))
    with pytest.raises(ValueError, match="2 frames"):
        joints_to_features(np.zeros((1, 22, 3)))


def test_normalizer_on_fixture_stats(hml_fixture_dir, real_features, tmp_path):
    norm = Normalizer.load(hml_fixture_dir)
    assert norm.dim == 263
    z = norm.normalize(real_features)
    assert np.isfinite(z).all() and z.shape == real_features.shape
    # A real HumanML3D motion is typical of its own statistics.
    assert np.abs(z.mean()) < 1.0 and 0.2 < z.std() < 3.0
    assert np.allclose(norm.denormalize(z), real_features, atol=1e-5)
    zt = norm.normalize(torch.from_numpy(real_features))
    assert np.allclose(zt.numpy(), z, atol=1e-6)
    norm.save(tmp_path)
    again = Normalizer.load(tmp_path)
    assert np.array_equal(again.mean, norm.mean) and np.array_equal(again.std, norm.std)
    with pytest.raises(ValueError, match="does not match"):
        norm.normalize(np.zeros((3, 251), np.float32))


def test_normalizer_fit_uses_group_std():
    rng = np.random.default_rng(0)
    x = [rng.normal(0, 1, (50, 263)).astype(np.float32) * np.linspace(0.5, 2, 263) for _ in range(4)]
    n = Normalizer.fit(x)
    for sl in HML_LAYOUT.groups().values():
        assert np.allclose(n.std[sl], n.std[sl][0])
