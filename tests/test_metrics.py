"""The metric suite on cases whose answer is known."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from motion_core.body.skeleton import HUMANML3D
from motion_core.eval import metrics


def test_fid_of_a_set_with_itself_is_zero_and_grows_with_noise():
    rng = np.random.default_rng(0)
    a = rng.normal(size=(2000, 16))
    assert metrics.fid(a, a) == pytest.approx(0.0, abs=1e-6)
    noisy = [metrics.fid(a, a + rng.normal(scale=s, size=a.shape)) for s in (0.1, 0.5, 1.0, 2.0)]
    assert all(x < y for x, y in itertools.pairwise(noisy)), noisy
    # two Gaussians with known parameters: ||mu||^2 + Tr(C1 + C2 - 2 sqrt(C1 C2))
    b = rng.normal(loc=1.0, scale=2.0, size=(20000, 4))
    c = rng.normal(size=(20000, 4))
    assert metrics.fid(b, c) == pytest.approx(4 * 1.0 + 4 * (4 + 1 - 2 * 2), rel=0.05)


def test_r_precision_of_matched_pairs_beats_shuffled_pairs():
    rng = np.random.default_rng(1)
    text = rng.normal(size=(320, 32))
    motion = text + rng.normal(scale=0.3, size=text.shape)
    top, mm_dist = metrics.r_precision(text, motion, rng=np.random.default_rng(0))
    shuffled, mm_shuffled = metrics.r_precision(text, motion[rng.permutation(320)], rng=np.random.default_rng(0))
    assert top[0] > 0.95 and top[0] <= top[1] <= top[2] <= 1.0
    assert shuffled[2] < 0.25  # chance for top-3 in batches of 32 is 3/32
    assert mm_dist < mm_shuffled
    with pytest.raises(ValueError, match="at least 32"):
        metrics.r_precision(text[:10], motion[:10])


def test_r_precision_ranks_by_hand():
    # batch of 3: text i is closest to motion (i + 1) % 3 except text 0, which finds its own
    text = np.array([[0.0], [10.0], [20.0]])
    motion = np.array([[0.1], [19.0], [30.0]])
    top, mm = metrics.r_precision(text, motion, batch=3, top_k=3, rng=np.random.default_rng(0))
    # text 0: own motion nearest (rank 0); text 1: motion 0 at 9.9 < own 9 ? no: own 9.0 nearest
    # text 2: motion 1 at 1.0 is nearer than own at 10.0 (rank 1)
    assert list(top) == pytest.approx([2 / 3, 1.0, 1.0])
    assert mm == pytest.approx((0.1 + 9.0 + 10.0) / 3)


def test_diversity_and_multimodality_on_known_sets():
    rng = np.random.default_rng(2)
    same = np.ones((400, 8))
    assert metrics.diversity(same) == 0.0
    two_points = np.repeat([[0.0, 0.0], [3.0, 4.0]], 200, axis=0)
    # pairs of a 50/50 mix of two points 5 apart: about half of the pairs are 5 apart
    assert metrics.diversity(two_points, rng=rng) == pytest.approx(2.5, abs=0.5)
    groups = np.repeat(rng.normal(size=(20, 1, 8)), 30, axis=1)
    assert metrics.multimodality(groups) == 0.0
    spread = groups + rng.normal(scale=1.0, size=groups.shape)
    # distance of two independent N(0, I_8) draws: E ||x - y|| = sqrt(2) E chi_8 ~ 3.87
    assert metrics.multimodality(spread) == pytest.approx(3.87, rel=0.15)


def test_repeat_reports_mean_and_95_percent_half_width():
    mean, half = metrics.repeat(lambda rng: float(rng.integers(0, 2)), times=20, seed=0)
    values = [float(np.random.default_rng(r).integers(0, 2)) for r in range(20)]
    assert mean == pytest.approx(np.mean(values))
    assert half == pytest.approx(1.96 * np.std(values) / np.sqrt(20))


def _walk(T: int, speed: float, fps: float = 20.0) -> np.ndarray:
    rest = HUMANML3D.rest_joints()
    t = np.arange(T) / fps
    joints = np.repeat(rest[None], T, axis=0).astype(np.float64)
    joints[:, :, 2] += speed * t[:, None]
    return joints


def test_peak_jerk_of_constant_velocity_is_zero_and_of_a_cubic_is_six():
    assert metrics.peak_jerk(metrics.jerk_curve(_walk(100, 1.3))) == pytest.approx(0.0, abs=1e-6)
    T, fps = 60, 20.0
    cubic = _walk(T, 0.0)
    cubic[:, :, 0] += ((np.arange(T) / fps) ** 3)[:, None]  # x = t^3: jerk 6 m/s^3 everywhere
    assert metrics.jerk_curve(cubic, fps) == pytest.approx(np.full(T - 3, 6.0), rel=1e-6)


def test_transition_jerk_finds_a_jump_at_the_boundary():
    joints = _walk(120, 1.0)
    joints[60:, :, 0] += 0.2  # a 20 cm jump where the second segment starts
    curve = metrics.transition_jerk(joints, [60], window=30)
    assert curve.shape == (30,)
    assert np.argmax(curve) in (13, 14, 15, 16)  # at the centre of the window
    # third difference of a step h is (h, -2h, h): the peak is 2 h fps^3
    assert metrics.peak_jerk(curve) == pytest.approx(2 * 0.2 * 20**3, rel=1e-6)
    smooth = metrics.transition_jerk(_walk(120, 1.0), [60], window=30)
    assert metrics.area_under_jerk(smooth, 0.0) == pytest.approx(0.0, abs=1e-6)
    assert metrics.area_under_jerk(curve, 0.0) > 1000
    with pytest.raises(ValueError, match="window"):
        metrics.transition_jerk(joints, [5], window=30)


def test_foot_skating_ratio():
    standing = _walk(40, 0.0)
    standing[:, :, 1] -= standing[:, :, 1].min()  # feet on the floor
    assert metrics.foot_skating_ratio(standing) == 0.0
    sliding = standing.copy()
    sliding[:, :, 2] += 0.05 * np.arange(40)[:, None]  # 5 cm per frame along the floor
    assert metrics.foot_skating_ratio(sliding) == 1.0
    flying = sliding.copy()
    flying[:, :, 1] += 0.5  # the same slide half a metre up is not skating
    assert metrics.foot_skating_ratio(flying) == 0.0
