"""KMM's density-peak key frames against a direct transcription of the equations and hand cases."""

from __future__ import annotations

import math

import numpy as np
import pytest

from motion_core.models.keyframes import density_peaks, select_keyframes


def transcription(x: np.ndarray) -> tuple[list[float], list[float], list[float]]:
    """Eq. 1-11 written out with loops, no vectorisation."""
    n = len(x)
    dist = [[math.sqrt(sum((a - b) ** 2 for a, b in zip(x[i], x[j], strict=True))) for j in range(n)] for i in range(n)]
    d = [sum(math.exp(-(dist[i][j] ** 2)) for j in range(n)) for i in range(n)]
    far = max(max(row) for row in dist)
    S = []
    for i in range(n):
        higher = [dist[i][j] for j in range(n) if d[j] > d[i]]
        S.append(min(higher) if higher else far)
    return d, S, [a * b for a, b in zip(d, S, strict=True)]


def test_equals_the_transcription_on_random_sequences():
    rng = np.random.default_rng(0)
    for n, l in ((5, 3), (12, 8), (30, 4)):
        x = rng.normal(scale=0.7, size=(n, l))
        d, S, g = density_peaks(x)
        td, tS, tg = transcription(x)
        assert d == pytest.approx(td, rel=1e-9)
        assert S == pytest.approx(tS, rel=1e-9)
        assert g == pytest.approx(tg, rel=1e-9)


def test_hand_made_line_of_points():
    # four tokens on a line: a tight cluster at 0, 0.1, 0.2 and an outlier at 3
    x = np.array([[0.0], [0.1], [0.2], [3.0]])
    d, S, _ = density_peaks(x)
    assert np.argmax(d) == 1  # the middle of the cluster is the densest
    assert S[1] == pytest.approx(3.0)  # densest token: the largest distance in the sequence
    assert S[0] == pytest.approx(0.1) and S[2] == pytest.approx(0.1)
    assert S[3] == pytest.approx(2.8)  # the outlier's nearest denser token is at 0.2
    # gamma: the cluster centre (high d, far) and the outlier (low d, far) are the peaks
    assert list(select_keyframes(x, 0.5)) == [1, 3]
    assert list(select_keyframes(x, 0.25)) == [1]
    assert list(select_keyframes(x, 0.0)) == []
    assert list(select_keyframes(x, 1.0)) == [0, 1, 2, 3]


def test_two_clusters_give_one_key_frame_each():
    rng = np.random.default_rng(1)
    a = rng.normal(scale=0.05, size=(10, 4))
    b = rng.normal(scale=0.05, size=(10, 4)) + 5.0
    keys = select_keyframes(np.concatenate([a, b]), ratio=0.1)
    assert len(keys) == 2 and (keys < 10).sum() == 1 and (keys >= 10).sum() == 1


def test_padding_is_never_selected_and_does_not_change_the_rest():
    rng = np.random.default_rng(2)
    x = rng.normal(size=(8, 3))
    pad = np.concatenate([x, np.zeros((4, 3))])  # zeros would be dense if they counted
    valid = np.array([True] * 8 + [False] * 4)
    d, S, g = density_peaks(pad, valid)
    d0, S0, g0 = density_peaks(x)
    assert d[:8] == pytest.approx(d0) and S[:8] == pytest.approx(S0) and g[:8] == pytest.approx(g0)
    assert (d[8:] == 0).all() and (g[8:] == 0).all()
    keys = select_keyframes(pad, 1.0, valid)
    assert list(keys) == list(range(8))
    assert list(select_keyframes(pad, 0.3, valid)) == list(select_keyframes(x, 0.3))


def test_ties_and_bad_input():
    x = np.zeros((4, 2))  # all tokens equal: equal density, none strictly denser
    d, S, _ = density_peaks(x)
    assert (d == 4).all() and (S == 0).all()  # the largest distance in the sequence is 0
    assert list(select_keyframes(x, 0.5)) == [0, 1]  # ties go to the earlier tokens
    with pytest.raises(ValueError, match="ratio"):
        select_keyframes(x, 1.5)
    with pytest.raises(ValueError, match=r"\(n, l\)"):
        density_peaks(np.zeros(4))
    assert select_keyframes(x, 0.3, np.zeros(4, bool)).size == 0
