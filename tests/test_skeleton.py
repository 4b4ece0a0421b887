import itertools

import numpy as np

from motion_core.body.features import features_to_joints
from motion_core.body.skeleton import HUMANML3D, KIT, get_skeleton


def test_chains_agree_with_parents():
    for sk in (HUMANML3D, KIT):
        seen = {0}
        for chain in sk.chains:
            for p, c in itertools.pairwise(chain):
                assert sk.parents[c] == p, (sk.name, p, c)
                seen.add(c)
        assert seen == set(range(sk.n_joints)), sk.name
        assert all(sk.parents[j] < j for j in range(1, sk.n_joints))
        assert np.allclose(np.linalg.norm(sk.raw_directions[1:], axis=-1), 1.0)


def test_feature_dims():
    assert HUMANML3D.n_joints == 22 and HUMANML3D.feature_dim == 263 and HUMANML3D.fps == 20
    assert KIT.n_joints == 21 and KIT.feature_dim == 251 and KIT.fps == 12.5
    assert get_skeleton("kit") is KIT


def test_bone_lengths_are_the_fixture_skeleton(real_features):
    """Our rest offsets carry the data set's own bone lengths (re-measured here)."""
    j = features_to_joints(real_features.astype(np.float64))
    measured = HUMANML3D.measure_bone_lengths(j)
    assert np.abs(measured.mean(0) - HUMANML3D.bone_lengths[1:]).max() < 1e-4


def test_rest_pose_is_upright_and_mirrored():
    r = HUMANML3D.rest_joints()
    names = HUMANML3D.joint_names
    assert r[names.index("head"), 1] > r[names.index("neck"), 1] > 0 > r[names.index("left_ankle"), 1]
    assert r[names.index("left_wrist"), 0] > 0 > r[names.index("right_wrist"), 0]  # +x is the body's left
    assert r[names.index("left_foot"), 2] > r[names.index("left_ankle"), 2]  # toes point +z (forward)
    m = HUMANML3D.mirror_map()
    assert names[m[names.index("left_elbow")]] == "right_elbow" and m[0] == 0
