"""Standing on the floor frame by frame (body.ground): hovering stance is put down, a
jump keeps its flight, no foot goes under the floor."""

from __future__ import annotations

import numpy as np
import pytest

from motion_core.body.features import features_to_joints
from motion_core.body.ground import GroundConfig, ground, support_frames
from motion_core.body.skeleton import HUMANML3D

FEET = [i for pair in HUMANML3D.feet for i in pair]


@pytest.fixture(scope="module")
def standing(real_features: np.ndarray) -> np.ndarray:
    """The real fixture motion, on the floor by its own lowest foot point: (T, 22, 3)."""
    j = features_to_joints(real_features.astype(np.float64))
    return j - np.array([0.0, j[:, FEET, 1].min(), 0.0])


def lift(j: np.ndarray, start: int, end: int, height: float) -> np.ndarray:
    """The whole body raised by a smooth bump of ``height`` m over frames [start, end)."""
    out = j.copy()
    t = np.arange(len(j))
    bump = np.where((t >= start) & (t < end), np.sin(np.pi * (t - start) / (end - start)) ** 2, 0.0)
    out[..., 1] += height * bump[:, None]
    return out


def test_real_motion_moves_only_down_and_only_by_its_stance_hover(standing: np.ndarray) -> None:
    g = ground(standing)
    d = standing - g
    assert np.abs(d[..., [0, 2]]).max() == 0.0  # only heights change
    assert np.abs(d - d[:, :1]).max() < 1e-12  # the whole body by one amount a frame: the pose is kept
    # real stance toes wander a few centimetres over the floor (mocap markers, the data set's
    # floor); that much and no more is taken off
    assert 0.0 <= d[..., 1].min() and d[..., 1].max() < 0.06


def test_a_hovering_stance_is_put_back_on_the_floor(standing: np.ndarray) -> None:
    T = len(standing)
    hovering = lift(standing, T // 4, 3 * T // 4, 0.06)
    g = ground(hovering)
    support = support_frames(hovering - np.array([0.0, hovering[:, FEET, 1].min(), 0.0]))
    assert support[T // 4 : 3 * T // 4].mean() > 0.5
    low = g[:, FEET, 1].min(1)
    assert np.abs(low[support]).max() < 1e-9
    # the 6 cm bump is gone: the hovering motion grounds to nearly what the original grounds
    # to (between support frames the drop is interpolated, so not exactly)
    diff = np.abs(g - ground(standing))[:, 0, 1]
    assert diff.mean() < 0.005 and diff.max() < 0.03
    assert (hovering[:, FEET, 1].min(1)[T // 2] - hovering[:, FEET, 1].min()) > 0.05  # it did hover


def test_a_jump_keeps_its_flight(standing: np.ndarray) -> None:
    T = len(standing)
    s, e = T // 2 - 6, T // 2 + 6
    jump = lift(standing, s, e, 0.30)
    g = ground(jump)
    assert not support_frames(jump)[s + 3 : e - 3].any()
    # the drop inside the flight is interpolated from the support frames around it: the body
    # still rises by nearly the whole jump
    rise = g[T // 2, 0, 1] - g[s - 1, 0, 1]
    assert rise > 0.25


def test_no_foot_below_the_floor_and_the_dtype_kept(standing: np.ndarray) -> None:
    rng = np.random.default_rng(0)
    noisy = (standing + rng.normal(0, 0.02, (len(standing), 1, 1)) * np.array([0, 1, 0])).astype(np.float32)
    g = ground(noisy)
    assert g.dtype == np.float32
    assert g[:, FEET, 1].min() >= -1e-6
    assert abs(g[:, FEET, 1].min()) < 1e-6
    # at most max_shift lower than the clip-floored input anywhere
    floored = noisy - np.array([0, noisy[:, FEET, 1].min(), 0], dtype=np.float32)
    assert (floored - g)[..., 1].max() <= GroundConfig().max_shift + 1e-6


def test_nothing_bears_weight_leaves_the_clip_floored(standing: np.ndarray) -> None:
    # a motion too fast to stand anywhere keeps the whole-clip floor
    cfg = GroundConfig(speed=0.0)
    g = ground(standing + np.array([0, 0.5, 0]), cfg=cfg)
    assert np.allclose(g, standing)
