"""The public generation API on the shipped checkpoints: inputs, determinism, joins."""

from __future__ import annotations

import time

import numpy as np
import pytest

import motion_core
from motion_core.generation import InputError, join_segments, validate
from motion_core.registry import _LOADED, REGISTRY, UnknownMethod, load_method
from motion_core.skeleton import HUMANML3D


def test_methods_lists_the_shipped_diffusion_methods():
    names = {m["name"] for m in motion_core.methods()}
    assert {"motion_mamba", "baseline"} <= names
    for m in motion_core.methods():
        assert m["display_name"] and m["description"]


@pytest.mark.parametrize(
    ("segments", "method", "message"),
    [
        ([], "motion_mamba", "empty"),
        ([("   ", 3.0)], "motion_mamba", "text is empty"),
        ([("walk" * 80, 3.0)], "motion_mamba", "at most 300"),
        ([("walk", 0.5)], "motion_mamba", "outside 1-10 s"),
        ([("walk", 11)], "motion_mamba", "outside 1-10 s"),
        ([("walk", 3.0)] * 11, "motion_mamba", "too many segments"),
        ([("walk", 10.0)] * 7, "motion_mamba", "at most 60 s"),
        ([("walk", "soon")], "motion_mamba", "expected a text and a duration"),
    ],
)
def test_bad_timelines_get_clear_messages(segments, method, message):
    with pytest.raises(InputError, match=message):
        validate(segments, method)


def test_unknown_method_names_the_available_ones():
    with pytest.raises(UnknownMethod, match="motion_mamba"):
        motion_core.generate([("walk", 2.0)], method="nope")


def test_checkpoints_are_small_and_load_fast():
    for name in ("motion_mamba", "baseline"):
        info = REGISTRY[name]
        from motion_core.registry import WEIGHTS

        assert (WEIGHTS / info.checkpoint).stat().st_size < 20 * 2**20
        _LOADED.pop(name, None)
        t0 = time.perf_counter()
        load_method(name)
        assert time.perf_counter() - t0 < 2.0
    assert (WEIGHTS / "vae.pt").stat().st_size < 20 * 2**20


@pytest.mark.parametrize("method", ["motion_mamba", "baseline"])
def test_generate_is_deterministic_and_well_formed(method):
    segs = [("a person walks forward", 2.5), ("a person waves with the right hand", 2.0)]
    a = motion_core.generate(segs, method=method, seed=3, steps=10)
    b = motion_core.generate(segs, method=method, seed=3, steps=10)
    c = motion_core.generate(segs, method=method, seed=4, steps=10)
    assert a.joints.shape == (90, 22, 3) and a.joints.dtype == np.float32
    assert a.fps == 20 and a.method == method
    assert a.segments == [(0, 50, segs[0][0]), (50, 90, segs[1][0])]
    assert np.array_equal(a.joints, b.joints)
    assert not np.array_equal(a.joints, c.joints)
    assert {"text", "denoise", "decode", "total"} <= set(a.timings)
    assert np.isfinite(a.joints).all()
    feet = [i for pair in HUMANML3D.feet for i in pair]
    assert abs(a.joints[:, feet, 1].min()) < 1e-6  # standing on the floor
    bones = np.linalg.norm(a.joints[:, 1:] - a.joints[:, HUMANML3D.parents[1:]], axis=-1)
    assert np.abs(bones.mean(0) - HUMANML3D.bone_lengths[1:]).max() < 0.05


def test_join_is_continuous_in_position_and_velocity():
    t = np.arange(60, dtype=np.float64)
    base = np.zeros((60, 22, 3))
    a = base + np.stack([np.zeros_like(t), np.ones_like(t), 0.05 * t], -1)[:, None]  # walks +z
    b = base + np.stack([np.zeros_like(t), np.ones_like(t), 0.02 * t], -1)[:, None]
    # give both a body so the facing is defined (+z)
    for m in (a, b):
        m[:, 2, 0] -= 0.1  # right hip at -x
        m[:, 1, 0] += 0.1
        m[:, 17, 0] -= 0.2
        m[:, 16, 0] += 0.2
    out = join_segments([a, b], [50, 40], overlap=10).astype(np.float64)
    assert out.shape == (90, 22, 3)
    root = out[:, 0, 2]
    v = np.diff(root)
    # velocity moves from 0.05 to 0.02 m/frame spread over the overlap: a hard cut would
    # change it by 0.03 in one frame; the smoothstep blend's largest one-frame change is ~1/3 of that
    assert np.abs(np.diff(v)).max() < 0.4 * 0.03
    assert abs(v[:45].mean() - 0.05) < 1e-6 and abs(v[-20:].mean() - 0.02) < 1e-6
