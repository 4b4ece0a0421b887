"""BVH reading, forward kinematics, units, resampling and writing, on real files and round trips."""

from __future__ import annotations

import numpy as np
import pytest
from motion_helpers import random_fk_motion

from motion_core.body.features import features_to_joints
from motion_core.body.ik import fit_rig, rigidify
from motion_core.body.skeleton import HUMANML3D
from motion_core.data.mocap import bvh_files
from motion_core.formats.bvh import (
    BvhError,
    bvh_positions_m,
    detect_unit,
    format_bvh,
    joints_to_bvh,
    parse_bvh,
    read_bvh,
    resample,
    write_bvh,
)


def _by_name(bvh, positions):
    return positions[:, [bvh.names.index(n) for n in HUMANML3D.joint_names]]


def _bvhio_positions(path, n_frames: int, names: list[str]) -> np.ndarray:
    """World joint positions as the PyPI parser bvhio computes them (file units)."""
    import bvhio

    root = bvhio.readAsHierarchy(str(path))
    layout = root.layout()
    out = np.zeros((n_frames, len(names), 3))
    for f in range(n_frames):
        root.loadPose(f, recursive=True)
        for joint, _, _ in layout:
            out[f, names.index(joint.Name)] = np.array(joint.PositionWorld)
    return out


def test_real_humanml3d_motion_round_trips_exactly(real_features, tmp_path):
    joints = features_to_joints(real_features.astype(np.float64))
    path = write_bvh(tmp_path / "m.bvh", joints_to_bvh(joints, 20))
    bvh = read_bvh(path)
    assert detect_unit(bvh) == "cm" and bvh.fps == pytest.approx(20, rel=1e-6)
    back = _by_name(bvh, bvh_positions_m(bvh))
    assert np.abs(back - joints).max() < 1e-4  # 0.1 mm; the file keeps 6 decimals of cm


def test_export_is_read_identically_by_a_pypi_parser(tmp_path):
    joints = random_fk_motion(60, seed=3)
    path = write_bvh(tmp_path / "m.bvh", joints_to_bvh(joints, 20))
    ours = read_bvh(path)
    theirs = _bvhio_positions(path, ours.n_frames, ours.names)
    assert np.abs(theirs - ours.positions()).max() * 10 < 1.0  # cm -> mm: within 1 mm
    assert np.abs(_by_name(ours, bvh_positions_m(ours)) - joints).max() < 1e-3


def test_stretchy_motion_is_fitted_in_least_squares_and_rigidify_makes_it_exact(tmp_path):
    rng = np.random.default_rng(0)
    joints = random_fk_motion(50, seed=1)
    joints = joints + rng.normal(0, 0.01, joints.shape)  # bones now stretch by ~1.4 cm
    fit = fit_rig(joints)
    assert np.abs(fit.positions(exact=True) - joints).max() < 1e-9
    rigid = rigidify(joints)
    assert HUMANML3D.measure_bone_lengths(rigid).std(axis=0).max() < 1e-5
    bvh = parse_bvh(format_bvh(joints_to_bvh(rigid, 20)))
    assert np.abs(_by_name(bvh, bvh_positions_m(bvh)) - rigid).max() < 1e-3


def test_real_mocap_files_read_with_units_and_resample(bandai_dir):
    files = bvh_files(bandai_dir)
    assert len(files) == 3076
    bvh = read_bvh(files[0])
    assert len(bvh.names) == 22 and bvh.fps == pytest.approx(30, rel=1e-4)
    assert detect_unit(bvh) == "cm"
    pos = bvh_positions_m(bvh, fps=20)
    assert pos.shape[0] == int(np.floor((bvh.n_frames - 1) / 30 * 20 + 1e-9)) + 1
    height = pos[0, :, 1].max() - pos[0, :, 1].min()
    assert 1.2 < height < 2.0
    # a real file written back and re-read gives the same positions
    again = parse_bvh(format_bvh(bvh))
    assert np.abs(again.positions() - bvh.positions()).max() < 1e-3


def test_resample_keeps_span_and_endpoints():
    x = np.arange(31, dtype=float)[:, None]  # 1 s at 30 fps
    y = resample(x, 30, 20)
    assert y.shape == (21, 1) and y[0, 0] == 0 and y[-1, 0] == pytest.approx(30)
    assert np.allclose(np.diff(y[:, 0]), 1.5)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("", "end of file"),
        ("HIERARCHY\nJOINT x {", "expected ROOT"),
        ("HIERARCHY\nROOT a\n{\nOFFSET 0 0 0\nCHANNELS 1 Wrotation\n}\nMOTION\n", "unknown channels"),
        (
            "HIERARCHY\nROOT a\n{\nOFFSET 0 0 0\nCHANNELS 1 Xrotation\n}\nMOTION\nFrames: 3\nFrame Time: 0.05\n1 2\n",
            "3 frames of 1 channels announced, 2 values found",
        ),
        ("HIERARCHY\nROOT a\n{\nOFFSET 0 x 0\n}\n", "bad number"),
    ],
)
def test_broken_files_give_clear_errors(text, message):
    with pytest.raises(BvhError, match=message):
        parse_bvh(text, source="upload.bvh")


def test_unit_detection_refuses_implausible_sizes():
    text = (
        "HIERARCHY\nROOT a\n{\nOFFSET 0 0 0\nCHANNELS 3 Xposition Yposition Zposition\n"
        "JOINT b\n{\nOFFSET 0 10 0\nEnd Site\n{\nOFFSET 0 1 0\n}\n}\n}\nMOTION\nFrames: 1\nFrame Time: 0.05\n0 0 0\n"
    )
    bvh = parse_bvh(text)
    with pytest.raises(BvhError, match="pass unit"):
        detect_unit(bvh)
    assert np.allclose(bvh_positions_m(bvh, unit="cm")[0, 1], [0, 0.1, 0])


def test_frame_lines_are_each_value_at_six_decimals_with_no_negative_zero():
    """The MOTION lines are written a frame at a time; each value reads as ``f"{v:.6f}"``
    would write it, except that the values that round to zero from below are written "0.000000"
    (as the per-value writer did), and no other value is touched by that rule."""
    bvh = joints_to_bvh(random_fk_motion(12), 20)
    specials = [-0.0, -1e-9, -4.9e-7, -5e-7, -5.1e-7, 1e-9, -10.0, -0.0000001, -100.0000004, 0.0]
    bvh.motion[: len(specials), 0] = specials
    lines = format_bvh(bvh).split("Frame Time:")[1].splitlines()[1:]
    assert len(lines) == bvh.n_frames

    def expected(v: float) -> str:
        s = f"{v:.6f}"
        return "0.000000" if s.strip("-0.") == "" else s

    starts = bvh._columns()
    # the root's columns come first in the file (it is written first, depth first)
    for i, v in enumerate(specials):
        assert lines[i].split(" ")[0] == expected(v), (v, lines[i].split(" ")[0])
    order = []

    def walk(j: int) -> None:
        order.append(j)
        for c, p in enumerate(bvh.parents):
            if p == j:
                walk(c)

    walk(bvh.parents.index(-1))
    cols = [starts[j] + k for j in order for k in range(len(bvh.channels[j]))]
    for line, row in zip(lines, bvh.motion[:, cols], strict=True):
        assert line.split(" ") == [expected(v) for v in row]
