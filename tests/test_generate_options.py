"""generate()'s options: feet locked by default (legs only), seconds left to
the length estimator, humanoid bone names in the downloads."""

from __future__ import annotations

import numpy as np

import motion_core
from motion_core.body.skeleton import HUMANML3D, HUMANOID
from motion_core.formats.bvh import read_bvh
from motion_core.formats.gltf import read_glb_joints

LEGS = {HUMANML3D.index(n) for n in ("left_knee", "right_knee", "left_ankle", "right_ankle", "left_foot", "right_foot")}


def test_foot_lock_is_on_by_default_and_moves_only_the_legs() -> None:
    seg = [("a person walks forward", 3.0)]
    locked = motion_core.generate(seg, method="kmm", seed=3)
    free = motion_core.generate(seg, method="kmm", seed=3, foot_lock=False)
    moved = {j for j in range(22) if np.abs(locked.joints[:, j] - free.joints[:, j]).max() > 0}
    assert moved and moved <= LEGS, moved
    assert "foot_lock" in locked.timings and "foot_lock" not in free.timings
    # the bones stay rigid: the same lengths as the unlocked (rigidified) motion
    np.testing.assert_allclose(
        HUMANML3D.measure_bone_lengths(locked.joints), HUMANML3D.measure_bone_lengths(free.joints), atol=1e-5
    )


def test_a_segment_without_seconds_gets_the_estimate() -> None:
    m = motion_core.generate([("a person claps twice", None), ("a person walks forward", 2.0)], method="kmm", seed=0)
    first = m.segments[0][1] - m.segments[0][0]
    assert 20 <= first <= 200 and m.segments[1][1] - m.segments[1][0] == 40
    again = motion_core.generate([("a person claps twice", None)], method="kmm", seed=0)
    assert again.segments[0][1] == first  # the estimate is deterministic


def test_exports_can_use_humanoid_bone_names(tmp_path) -> None:
    m = motion_core.generate([("a person waves with the right hand", 2.0)], method="kmm", seed=0)
    files = motion_core.export_all(m, tmp_path, rig="humanoid")
    joints, extras = read_glb_joints(files["glb"].read_bytes())
    assert extras["joint_names"] == list(HUMANOID.joint_names)
    assert np.abs(joints - m.joints).max() < 1e-5
    assert "Hips" in read_bvh(files["bvh"]).names
