"""Humanoid bone names: exports with Mixamo-style names and a T-pose rest, read
back by our reader, the PyPI parser bvhio and our GLB reader with the same joints."""

from __future__ import annotations

import numpy as np
from motion_helpers import random_fk_motion
from test_bvh import _bvhio_positions

from motion_core.body.skeleton import HUMANML3D, HUMANOID, HUMANOID_NAMES
from motion_core.formats.bvh import bvh_positions_m, joints_to_bvh, read_bvh, write_bvh
from motion_core.formats.gltf import glb_bytes, read_glb_joints


def test_the_humanoid_rig_has_mixamo_names_and_a_t_pose() -> None:
    assert HUMANOID.joint_names[:4] == ("Hips", "LeftUpLeg", "RightUpLeg", "Spine")
    assert set(HUMANOID_NAMES) == set(HUMANML3D.joint_names)
    rest = HUMANOID.rest_joints()
    for side in ("Left", "Right"):
        arm = [HUMANOID.index(f"{side}{j}") for j in ("Arm", "ForeArm", "Hand")]
        # the arm is horizontal and straight, pointing away from the body, at its own length
        assert np.ptp(rest[arm, 1]) < 1e-9 and np.ptp(rest[arm, 2]) < 1e-9
        assert (np.sign(rest[arm[-1], 0] - rest[arm[0], 0]) > 0) == (side == "Left")
    np.testing.assert_allclose(HUMANOID.bone_lengths, HUMANML3D.bone_lengths)


def test_humanoid_bvh_and_glb_reproduce_the_motion(tmp_path) -> None:
    joints = random_fk_motion(50, seed=7)
    path = write_bvh(tmp_path / "h.bvh", joints_to_bvh(joints, 20, skeleton=HUMANOID))
    ours = read_bvh(path)
    assert sorted(ours.names) == sorted(HUMANOID.joint_names)  # in the file's depth-first order
    got = bvh_positions_m(ours)[:, [ours.names.index(n) for n in HUMANOID.joint_names]]
    assert np.abs(got - joints).max() < 1e-3
    theirs = _bvhio_positions(path, ours.n_frames, ours.names)
    assert np.abs(theirs - ours.positions()).max() * 10 < 1.0  # cm -> mm
    # the T-pose rest: the upper arm's rest offset points along x
    text = path.read_text()
    offset = text.split("JOINT LeftForeArm")[1].split("OFFSET")[1].split()[:3]
    assert abs(float(offset[0])) > 20 and abs(float(offset[1])) < 1e-3
    back, _ = read_glb_joints(glb_bytes(joints, 20, skeleton=HUMANOID))
    assert np.abs(back - joints).max() < 1e-5
