"""KMM's key-frame selection by density peaks (Eq. 1-11 of the KMM paper), a pure function.

For a latent token sequence ``x: (n, l)`` (n tokens of dimension l):

* local density ``d_i = sum_j exp(-||x_i - x_j||^2)`` (the sum includes j = i, which adds 1
  to every d_i and changes no ranking);
* distance ``S_i = min_{j: d_j > d_i} ||x_i - x_j||``, the distance to the nearest token of
  strictly higher density. The densest token has no such j; the paper's "infinity" is taken
  as the largest pairwise distance in the sequence (what density-peaks clustering does), so
  gamma stays finite and the densest token still ranks high. Tokens tied for the highest
  density all get that maximum;
* ``gamma_i = d_i * S_i``; key frames are the top ``ratio`` of tokens by gamma.

Padding tokens (``valid`` False) take no part: they are left out of every sum and minimum
and are never selected. Ties in gamma go to the earlier token (stable order).
"""

from __future__ import annotations

import math

import numpy as np


def _pairwise(x: np.ndarray) -> np.ndarray:
    sq = (x * x).sum(1)
    d2 = np.maximum(sq[:, None] + sq[None, :] - 2.0 * x @ x.T, 0.0)
    np.fill_diagonal(d2, 0.0)
    return d2


def density_peaks(x: np.ndarray, valid: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(d, S, gamma), each (n,) float64; zeros on padding tokens.

    x: (n, l) token latents; valid: (n,) bool, False on padding (default: all valid).
    """
    x = np.asarray(x, np.float64)
    if x.ndim != 2:
        raise ValueError(f"x must be (n, l), got shape {x.shape}")
    n = x.shape[0]
    valid = np.ones(n, bool) if valid is None else np.asarray(valid, bool)
    d = np.zeros(n)
    S = np.zeros(n)
    idx = np.flatnonzero(valid)
    if idx.size == 0:
        return d, S, d.copy()
    d2 = _pairwise(x[idx])
    dist = np.sqrt(d2)
    dens = np.exp(-d2).sum(1)
    higher = dens[None, :] > dens[:, None]  # higher[i, j]: token j is strictly denser than i
    far = dist.max()
    s = np.where(higher, dist, np.inf).min(1)
    s[~higher.any(1)] = far
    d[idx], S[idx] = dens, s
    return d, S, d * S


def select_keyframes(x: np.ndarray, ratio: float = 0.3, valid: np.ndarray | None = None) -> np.ndarray:
    """Indices (sorted, int64) of the top ``ratio`` of valid tokens by gamma = d * S.

    At least one key frame when any token is valid and ratio > 0: ceil(ratio * n_valid).
    """
    if not 0.0 <= ratio <= 1.0:
        raise ValueError(f"ratio must be in [0, 1], got {ratio}")
    n = len(x)
    valid = np.ones(n, bool) if valid is None else np.asarray(valid, bool)
    _, _, gamma = density_peaks(x, valid)
    n_valid = int(valid.sum())
    k = min(n_valid, math.ceil(ratio * n_valid)) if ratio > 0 else 0
    order = np.argsort(-np.where(valid, gamma, -np.inf), kind="stable")
    return np.sort(order[:k]).astype(np.int64)
