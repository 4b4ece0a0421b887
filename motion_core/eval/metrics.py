"""The papers' metric suite, on embeddings and on joint positions (numpy, no torch).

Embedding metrics follow the T2M evaluation protocol (Guo et al. 2022) as MLD, Motion
Mamba, KMM and FTMoMamba report it:

* ``fid(a, b)``: Frechet distance between Gaussians fitted to two embedding sets (N, D).
* ``r_precision(text, motion, batch=32)``: in batches of 32 matched (text, motion) pairs, the
  share of texts whose own motion is among the k nearest motions (k = 1, 2, 3), plus
  MM-Dist, the mean distance of matched pairs.
* ``diversity(emb, pairs=300)``: mean distance between randomly drawn pairs.
* ``multimodality(groups, pairs=10)``: per text, the mean distance between pairs of its own
  generations (groups: (n_texts, n_samples, D)), averaged over texts.
* ``repeat(fn, times=20)``: the protocol's 20 repetitions, mean and 95% half-width
  1.96 std / sqrt(times).

Motion metrics on joint positions (T, J, 3) in metres:

* ``jerk_curve``: FlowMDM's jerk per frame, the third finite difference of every joint's
  position, L1 over x, y, z, the maximum over joints. We scale by fps^3 so that it is in
  m/s^3 and comparable across frame rates (FlowMDM leaves it per frame^3).
* ``transition_jerk``: the jerk curve in a window centred on each segment boundary, averaged
  over boundaries; ``peak_jerk`` its maximum; ``area_under_jerk`` the sum over the window of
  |curve - reference|, the reference being the ground truth's mean jerk (FlowMDM's constant).
* ``foot_skating_ratio``: share of frames in which a foot in contact with the ground (height
  below 5 cm) slides more than 2.5 cm to the next frame (GMD's definition, Karunratanakul
  et al. 2023).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
from scipy import linalg

# ---------------------------------------------------------------- embedding metrics


def frechet_distance(mu1: np.ndarray, cov1: np.ndarray, mu2: np.ndarray, cov2: np.ndarray) -> float:
    """||mu1 - mu2||^2 + Tr(C1 + C2 - 2 sqrt(C1 C2))."""
    diff = mu1 - mu2
    covmean = linalg.sqrtm(cov1 @ cov2)
    if not np.isfinite(covmean).all():  # near-singular product: regularise as the reference code does
        eps = np.eye(len(mu1)) * 1e-6
        covmean = linalg.sqrtm((cov1 + eps) @ (cov2 + eps))
    covmean = np.real(covmean)
    # max(0, .): identical sets give -1e-12 and the like from the square root's rounding
    return max(0.0, float(diff @ diff + np.trace(cov1) + np.trace(cov2) - 2.0 * np.trace(covmean)))


def fid(a: np.ndarray, b: np.ndarray) -> float:
    """FID between two embedding sets (N, D) and (M, D)."""
    a, b = np.asarray(a, np.float64), np.asarray(b, np.float64)
    return frechet_distance(a.mean(0), np.cov(a, rowvar=False), b.mean(0), np.cov(b, rowvar=False))


def distance_matrix(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Euclidean distances (N, M) between rows of a (N, D) and b (M, D)."""
    sq = (a * a).sum(1)[:, None] + (b * b).sum(1)[None, :] - 2.0 * a @ b.T
    return np.sqrt(np.maximum(sq, 0.0))


def r_precision(
    text: np.ndarray, motion: np.ndarray, batch: int = 32, top_k: int = 3, rng: np.random.Generator | None = None
) -> tuple[np.ndarray, float]:
    """(top-1..top_k R-precision, MM-Dist) over shuffled batches of ``batch`` matched pairs.

    text, motion: (N, D), row i of each describing the same sample. Pairs that do not fill a
    last batch are dropped, as in the protocol.
    """
    text, motion = np.asarray(text, np.float64), np.asarray(motion, np.float64)
    order = (rng or np.random.default_rng(0)).permutation(len(text))
    hits = np.zeros(top_k)
    matched, count = 0.0, 0
    for start in range(0, len(order) - batch + 1, batch):
        idx = order[start : start + batch]
        d = distance_matrix(text[idx], motion[idx])
        rank = (d < np.diag(d)[:, None]).sum(1)  # how many motions are closer than the true one
        for k in range(top_k):
            hits[k] += (rank <= k).sum()
        matched += np.trace(d)
        count += batch
    if count == 0:
        raise ValueError(f"R-precision needs at least {batch} pairs, got {len(text)}")
    return hits / count, matched / count


def diversity(emb: np.ndarray, pairs: int = 300, rng: np.random.Generator | None = None) -> float:
    """Mean distance between ``pairs`` random pairs of rows (drawn as two index sets)."""
    emb = np.asarray(emb, np.float64)
    rng = rng or np.random.default_rng(0)
    if len(emb) < 2:
        raise ValueError("diversity needs at least 2 samples")
    n = min(pairs, len(emb))
    i, j = rng.choice(len(emb), n, replace=False), rng.choice(len(emb), n, replace=False)
    return float(np.linalg.norm(emb[i] - emb[j], axis=1).mean())


def multimodality(groups: np.ndarray, pairs: int = 10, rng: np.random.Generator | None = None) -> float:
    """groups (n_texts, n_samples, D): per text, mean distance of ``pairs`` pairs of its samples."""
    groups = np.asarray(groups, np.float64)
    rng = rng or np.random.default_rng(0)
    n_texts, n_samples, _ = groups.shape
    if n_samples < 2:
        raise ValueError("multimodality needs at least 2 samples per text")
    k = min(pairs, n_samples)
    total = 0.0
    for g in groups:
        i, j = rng.choice(n_samples, k, replace=False), rng.choice(n_samples, k, replace=False)
        total += np.linalg.norm(g[i] - g[j], axis=1).mean()
    return float(total / n_texts)


def repeat(fn: Callable[[np.random.Generator], float], times: int = 20, seed: int = 0) -> tuple[float, float]:
    """(mean, 95% half-width) of fn(rng) over ``times`` independent repetitions."""
    values = np.array([fn(np.random.default_rng(seed + r)) for r in range(times)], np.float64)
    half = 1.96 * values.std() / np.sqrt(times) if times > 1 else 0.0
    return float(values.mean()), float(half)


# ---------------------------------------------------------------- motion metrics


def jerk_curve(joints: np.ndarray, fps: float = 20.0) -> np.ndarray:
    """(T-3,) per-frame jerk in m/s^3: max over joints of the L1 norm of the third difference.

    Entry t is centred between frames t+1 and t+2 (the third difference spans t..t+3).
    """
    joints = np.asarray(joints, np.float64)
    if joints.shape[0] < 4:
        raise ValueError("jerk needs at least 4 frames")
    d3 = np.diff(joints, n=3, axis=0) * fps**3
    return np.abs(d3).sum(-1).max(-1)


def transition_jerk(joints: np.ndarray, boundaries: Sequence[int], window: int = 60, fps: float = 20.0) -> np.ndarray:
    """(window,) mean jerk curve around the boundaries (frame index where a segment starts).

    Windows that do not fit inside the motion are left out.
    """
    curve = jerk_curve(joints, fps)
    half = window // 2
    rows = []
    for b in boundaries:
        # curve index t is centred at frame t + 1.5: shift so that the window is centred on b
        start = int(b) - half - 1
        if start >= 0 and start + window <= len(curve):
            rows.append(curve[start : start + window])
    if not rows:
        raise ValueError("no boundary has a full window inside the motion")
    return np.mean(rows, axis=0)


def peak_jerk(curve: np.ndarray) -> float:
    return float(np.max(curve))


def area_under_jerk(curve: np.ndarray, reference: float) -> float:
    """Sum over the window of |curve - reference| (FlowMDM's AUJ), in m/s^3 x frames."""
    return float(np.abs(np.asarray(curve) - reference).sum())


def foot_skating_ratio(
    joints: np.ndarray,
    feet: Sequence[int] = (10, 11),
    height: float = 0.05,
    slide: float = 0.025,
) -> float:
    """Share of frame transitions where a foot below ``height`` (m) moves more than ``slide``
    (m) horizontally. joints (T, J, 3), y up, floor at y = 0; feet: the toe joints of the
    HumanML3D skeleton by default."""
    joints = np.asarray(joints, np.float64)
    if joints.shape[0] < 2:
        raise ValueError("foot skating needs at least 2 frames")
    f = joints[:, list(feet)]  # (T, F, 3)
    contact = (f[:-1, :, 1] < height) & (f[1:, :, 1] < height)
    step = np.linalg.norm(f[1:, :, [0, 2]] - f[:-1, :, [0, 2]], axis=-1)
    skating = (contact & (step > slide)).any(axis=1)
    return float(skating.mean())
