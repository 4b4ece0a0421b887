"""``ik``'s rotation fit and forward kinematics as compiled loops (numba): the CPU's fast path.

Every generated motion is put on rigid bones (``ik.rigidify``), and every export fits a rig
(``ik.fit_rig``). In numpy the fit is a Python loop over the 22 joints of array operations
over the frames, about 25 of them per joint, plus 3 x 2 batched 3 x 3 SVDs for the branch
joints (pelvis, spine3): 14 ms for a 10 s motion, a third of Motion Mamba's whole sampling
time for one. Here the same arithmetic runs frame by frame in one compiled call.

The maths is ``ik._fit_global``'s, step for step (that numpy form stays the reference and
the path where numba does not import): shortest arcs by Rodrigues' formula with the
rotation-vector form for nearly opposite or zero vectors, and Kabsch for joints with several
children, their offsets refitted three times. The reference's Kabsch is an SVD; here it is an
eigen-decomposition (``_kabsch``). No fast-math: the results equal the reference's to 1e-10
(tests). The exception is a branch joint whose children coincide with it or lie on one line.
There the best rotation is not unique, and the two may pick different ones; both are
rotations. Compiled at the first call (about 6 s on the 2-core
machine; whole-array assignments and reductions inside the loops had made it 14.5), then
cached on disk (0.4 s to load).
"""

from __future__ import annotations

import numpy as np

try:
    import numba
except ImportError:  # optional: ``ik`` keeps to numpy
    numba = None


def available() -> bool:
    return numba is not None


def _shortest_arc(u, v, out):  # pragma: no cover - compiled
    """out (3, 3) = the smallest rotation taking unit vector u (3,) to v (3,): ``ik.shortest_arc``."""
    w0 = u[1] * v[2] - u[2] * v[1]
    w1 = u[2] * v[0] - u[0] * v[2]
    w2 = u[0] * v[1] - u[1] * v[0]
    c = u[0] * v[0] + u[1] * v[1] + u[2] * v[2]
    ww = w0 * w0 + w1 * w1 + w2 * w2
    if c >= -0.999 and c * c + ww >= 0.5:
        k = 1.0 / (1.0 + c)
        out[0, 0] = c + w0 * w0 * k
        out[0, 1] = w0 * w1 * k - w2
        out[0, 2] = w0 * w2 * k + w1
        out[1, 0] = w1 * w0 * k + w2
        out[1, 1] = c + w1 * w1 * k
        out[1, 2] = w1 * w2 * k - w0
        out[2, 0] = w2 * w0 * k - w1
        out[2, 1] = w2 * w1 * k + w0
        out[2, 2] = c + w2 * w2 * k
        return
    # the rotation-vector form (``ik._shortest_arc_rotvec``)
    s = np.sqrt(ww)
    ang = np.arctan2(s, c)
    a0 = a1 = a2 = 0.0
    if s > 1e-12:
        a0, a1, a2 = w0 / s, w1 / s, w2 / s
    elif c < 0:  # u == -v: any perpendicular axis will do
        a0, a1, a2 = 0.0, u[2], -u[1]  # u x (1, 0, 0)
        n = np.sqrt(a1 * a1 + a2 * a2)
        if n < 1e-6:
            a0, a1, a2 = u[1], -u[0], 0.0  # u x (0, 0, 1)
            n = np.sqrt(a0 * a0 + a1 * a1)
        a0, a1, a2 = a0 / n, a1 / n, a2 / n
    else:
        # u == v, or v zero (a bone of no length): the identity. Not through the angle:
        # u . 0 can be -0.0, whose arctan2 is pi (the reference's zero rotation vector
        # multiplies it away)
        for i in range(3):
            for k in range(3):
                out[i, k] = 1.0 if i == k else 0.0
        return
    sn, cs = np.sin(ang), np.cos(ang)
    t = 1.0 - cs
    out[0, 0] = cs + t * a0 * a0
    out[0, 1] = t * a0 * a1 - sn * a2
    out[0, 2] = t * a0 * a2 + sn * a1
    out[1, 0] = t * a1 * a0 + sn * a2
    out[1, 1] = cs + t * a1 * a1
    out[1, 2] = t * a1 * a2 - sn * a0
    out[2, 0] = t * a2 * a0 - sn * a1
    out[2, 1] = t * a2 * a1 + sn * a0
    out[2, 2] = cs + t * a2 * a2


def _det3(m):  # pragma: no cover - compiled
    return (
        m[0, 0] * (m[1, 1] * m[2, 2] - m[1, 2] * m[2, 1])
        - m[0, 1] * (m[1, 0] * m[2, 2] - m[1, 2] * m[2, 0])
        + m[0, 2] * (m[1, 0] * m[2, 1] - m[1, 1] * m[2, 0])
    )


def _sym_eigen3(a, w, v):  # pragma: no cover - compiled
    """Eigen-decomposition of the symmetric (3, 3) ``a`` (overwritten) by cyclic Jacobi
    rotations: w (3,) eigenvalues, descending; v (3, 3) their unit eigenvectors as columns."""
    for i in range(3):
        for k in range(3):
            v[i, k] = 1.0 if i == k else 0.0
    for _ in range(32):
        off = a[0, 1] * a[0, 1] + a[0, 2] * a[0, 2] + a[1, 2] * a[1, 2]
        diag = a[0, 0] * a[0, 0] + a[1, 1] * a[1, 1] + a[2, 2] * a[2, 2]
        if off <= 1e-36 * diag or off == 0.0:
            break
        for p, q in ((0, 1), (0, 2), (1, 2)):
            apq = a[p, q]
            if apq == 0.0:
                continue
            theta = (a[q, q] - a[p, p]) / (2.0 * apq)
            t = 1.0 / (abs(theta) + np.sqrt(theta * theta + 1.0))
            if theta < 0.0:
                t = -t
            c = 1.0 / np.sqrt(t * t + 1.0)
            s = t * c
            # a <- J^T a J and v <- v J, J the rotation by (c, s) in the (p, q) plane
            for k in range(3):
                akp, akq = a[k, p], a[k, q]
                a[k, p] = c * akp - s * akq
                a[k, q] = s * akp + c * akq
            for k in range(3):
                apk, aqk = a[p, k], a[q, k]
                a[p, k] = c * apk - s * aqk
                a[q, k] = s * apk + c * aqk
            for k in range(3):
                vkp, vkq = v[k, p], v[k, q]
                v[k, p] = c * vkp - s * vkq
                v[k, q] = s * vkp + c * vkq
    for i in range(3):
        w[i] = a[i, i]
    for i in range(2):  # selection sort, descending, columns along
        m = i
        for k in range(i + 1, 3):
            if w[k] > w[m]:
                m = k
        if m != i:
            w[i], w[m] = w[m], w[i]
            for k in range(3):
                v[k, i], v[k, m] = v[k, m], v[k, i]


def _unit_perpendicular(a, out):  # pragma: no cover - compiled
    """out (3,) = a unit vector perpendicular to the unit vector a (3,): a crossed with the
    axis a is least along."""
    m = 0
    if abs(a[1]) < abs(a[m]):
        m = 1
    if abs(a[2]) < abs(a[m]):
        m = 2
    e0, e1, e2 = (1.0 if m == 0 else 0.0), (1.0 if m == 1 else 0.0), (1.0 if m == 2 else 0.0)
    out[0] = a[1] * e2 - a[2] * e1
    out[1] = a[2] * e0 - a[0] * e2
    out[2] = a[0] * e1 - a[1] * e0
    n = np.sqrt(out[0] * out[0] + out[1] * out[1] + out[2] * out[2])
    for i in range(3):
        out[i] /= n


def _kabsch(h, r, w, v):  # pragma: no cover - compiled
    """r (3, 3) = the rotation R maximising trace(R h), h = sum_k src_k dst_k^T (3, 3):
    ``ik.kabsch``'s V diag(1, 1, d) U^T for h = U S V^T. numba's LAPACK SVD cost 10 us a
    call, most of the fit's time; here V comes from the eigenvectors of h^T h
    (``_sym_eigen3``, always a proper orthonormal basis), u_1 = h v_1 and u_2 = h v_2
    orthonormalised (Gram-Schmidt: h^T h's rounding leaves them 1e-6 from orthogonal for
    nearly collinear children), u_3 = u_1 x u_2, so that U is a rotation and d = det(V) (a
    reflection when det h < 0). Where h has rank 0 or 1 (children on their joint, or on one
    line) the missing u_i are any completing an orthonormal basis: R is then one of the
    rotations that maximise trace(R h) (the SVD picks another), and a rotation always."""
    a = np.empty((3, 3))
    for i in range(3):
        for k in range(3):
            a[i, k] = h[0, i] * h[0, k] + h[1, i] * h[1, k] + h[2, i] * h[2, k]
    _sym_eigen3(a, w, v)
    u = np.empty((3, 3))
    u0, u1, hv = np.empty(3), np.empty(3), np.empty(3)
    for i in range(3):
        hv[i] = h[i, 0] * v[0, 0] + h[i, 1] * v[1, 0] + h[i, 2] * v[2, 0]
    n0 = np.sqrt(hv[0] * hv[0] + hv[1] * hv[1] + hv[2] * hv[2])
    scale = 0.0  # sum |h_ik|: 0 only for h = 0
    for i in range(3):
        for k in range(3):
            scale += abs(h[i, k])
    if n0 > 1e-12 * scale:
        for i in range(3):
            u0[i] = hv[i] / n0
    else:  # h = 0: every rotation is as good; the identity, as the SVD gives
        u0[0], u0[1], u0[2] = v[0, 0], v[1, 0], v[2, 0]
    for i in range(3):
        hv[i] = h[i, 0] * v[0, 1] + h[i, 1] * v[1, 1] + h[i, 2] * v[2, 1]
    p = u0[0] * hv[0] + u0[1] * hv[1] + u0[2] * hv[2]
    for i in range(3):
        hv[i] -= p * u0[i]
    n1 = np.sqrt(hv[0] * hv[0] + hv[1] * hv[1] + hv[2] * hv[2])
    if n1 > 1e-9 * max(n0, 1e-300) and n0 > 1e-12 * scale:
        for i in range(3):
            u1[i] = hv[i] / n1
    elif n0 > 1e-12 * scale:
        _unit_perpendicular(u0, u1)
    else:
        u1[0], u1[1], u1[2] = v[0, 1], v[1, 1], v[2, 1]
    for i in range(3):
        u[i, 0], u[i, 1] = u0[i], u1[i]
    u[0, 2] = u0[1] * u1[2] - u0[2] * u1[1]
    u[1, 2] = u0[2] * u1[0] - u0[0] * u1[2]
    u[2, 2] = u0[0] * u1[1] - u0[1] * u1[0]
    d = 1.0 if _det3(v) >= 0.0 else -1.0
    for i in range(3):
        for k in range(3):
            r[i, k] = v[i, 0] * u[k, 0] + v[i, 1] * u[k, 1] + d * v[i, 2] * u[k, 2]


def _fit_rotations(joints, parents, kid_start, kids, rest_dir, lengths, imposed, offsets, glob):  # pragma: no cover
    """``ik._fit_global``'s loop: writes offsets (J, 3) and glob (T, J, 3, 3).

    joints (T, J, 3) float64; parents (J,) int64 (-1: root), parents before children;
    ``kids[kid_start[j]:kid_start[j + 1]]`` are joint j's children; rest_dir (J, 3) unit
    rest directions; lengths (J,) bone lengths; ``imposed``: keep them when refitting the
    offsets of a branch joint's children (else those take the motion's lengths)."""
    n_t, n_j = joints.shape[0], joints.shape[1]
    for j in range(n_j):
        for d in range(3):
            offsets[j, d] = rest_dir[j, d] * lengths[j]
    arc = np.empty((3, 3))
    cur = np.empty(3)
    tgt = np.empty(3)
    h = np.empty((3, 3))
    ev = np.empty(3)
    evec = np.empty((3, 3))
    for j in range(n_j):
        p = parents[j]
        lo, hi = kid_start[j], kid_start[j + 1]
        if hi == lo:
            for t in range(n_t):
                r = glob[t, j]
                for a in range(3):
                    for b in range(3):
                        r[a, b] = glob[t, p, a, b] if p >= 0 else (1.0 if a == b else 0.0)
        elif hi - lo == 1 and p >= 0:
            c = kids[lo]
            for t in range(n_t):
                for d in range(3):
                    tgt[d] = joints[t, c, d] - joints[t, j, d]
                n = max(np.sqrt(tgt[0] * tgt[0] + tgt[1] * tgt[1] + tgt[2] * tgt[2]), 1e-12)
                for d in range(3):
                    tgt[d] /= n
                pr = glob[t, p]
                for d in range(3):
                    cur[d] = pr[d, 0] * rest_dir[c, 0] + pr[d, 1] * rest_dir[c, 1] + pr[d, 2] * rest_dir[c, 2]
                _shortest_arc(cur, tgt, arc)
                r = glob[t, j]
                for a in range(3):
                    for b in range(3):
                        r[a, b] = arc[a, 0] * pr[0, b] + arc[a, 1] * pr[1, b] + arc[a, 2] * pr[2, b]
        else:
            n_k = hi - lo
            for _ in range(3):
                acc = np.zeros((n_k, 3))
                for t in range(n_t):
                    for a in range(3):
                        for b in range(3):
                            h[a, b] = 0.0
                    for q in range(n_k):
                        k = kids[lo + q]
                        for a in range(3):
                            for b in range(3):
                                h[a, b] += offsets[k, a] * (joints[t, k, b] - joints[t, j, b])
                    _kabsch(h, glob[t, j], ev, evec)
                    r = glob[t, j]
                    # the children's offsets refitted: their mean position in the fitted frame
                    for q in range(n_k):
                        k = kids[lo + q]
                        for a in range(3):
                            acc[q, a] += (
                                r[0, a] * (joints[t, k, 0] - joints[t, j, 0])
                                + r[1, a] * (joints[t, k, 1] - joints[t, j, 1])
                                + r[2, a] * (joints[t, k, 2] - joints[t, j, 2])
                            )
                for q in range(n_k):
                    k = kids[lo + q]
                    for a in range(3):
                        offsets[k, a] = acc[q, a] / n_t
                    if imposed:  # keep the refitted directions, not the motion's lengths
                        n = max(np.sqrt(offsets[k, 0] ** 2 + offsets[k, 1] ** 2 + offsets[k, 2] ** 2), 1e-12)
                        for a in range(3):
                            offsets[k, a] *= lengths[k] / n


def _forward_kinematics(glob, root_pos, offsets, parents, out):  # pragma: no cover - compiled
    """``ik.forward_kinematics`` with rest offsets (J, 3): writes out (T, J, 3)."""
    n_t, n_j = glob.shape[0], glob.shape[1]
    for t in range(n_t):
        for d in range(3):
            out[t, 0, d] = root_pos[t, d]
        for j in range(1, n_j):
            p = parents[j]
            r = glob[t, p]
            for d in range(3):
                out[t, j, d] = (
                    out[t, p, d] + r[d, 0] * offsets[j, 0] + r[d, 1] * offsets[j, 1] + r[d, 2] * offsets[j, 2]
                )


if numba is not None:
    _shortest_arc = numba.njit(cache=True)(_shortest_arc)
    _det3 = numba.njit(cache=True)(_det3)
    _sym_eigen3 = numba.njit(cache=True)(_sym_eigen3)
    _unit_perpendicular = numba.njit(cache=True)(_unit_perpendicular)
    _kabsch = numba.njit(cache=True)(_kabsch)
    _fit_rotations = numba.njit(cache=True)(_fit_rotations)
    _forward_kinematics = numba.njit(cache=True)(_forward_kinematics)


def children_table(parents: tuple[int, ...]) -> tuple[np.ndarray, np.ndarray]:
    """(kid_start (J + 1,), kids (J - roots,)) int64: joint j's children are
    ``kids[kid_start[j]:kid_start[j + 1]]``, in index order (as ``ik._fit_global`` lists them)."""
    n = len(parents)
    counts = np.zeros(n + 1, dtype=np.int64)
    for p in parents:
        if p >= 0:
            counts[p + 1] += 1
    start = np.cumsum(counts)
    kids = np.array([c for j in range(n) for c, p in enumerate(parents) if p == j], dtype=np.int64)
    return start, kids


def fit_rotations(
    joints: np.ndarray, parents: tuple[int, ...], rest_dir: np.ndarray, lengths: np.ndarray, imposed: bool
) -> tuple[np.ndarray, np.ndarray]:
    """(offsets (J, 3), global rotations (T, J, 3, 3)) fitted to float64 joints (T, J, 3)."""
    T, J, _ = joints.shape
    start, kids = children_table(parents)
    offsets = np.empty((J, 3))
    glob = np.empty((T, J, 3, 3))
    _fit_rotations(
        np.ascontiguousarray(joints, dtype=np.float64),
        np.asarray(parents, dtype=np.int64),
        start,
        kids,
        np.ascontiguousarray(rest_dir, dtype=np.float64),
        np.ascontiguousarray(lengths, dtype=np.float64),
        imposed,
        offsets,
        glob,
    )
    return offsets, glob


def forward_kinematics(
    glob: np.ndarray, root_pos: np.ndarray, offsets: np.ndarray, parents: tuple[int, ...]
) -> np.ndarray:
    """(T, J, 3) joint positions from global rotations (T, J, 3, 3), the root path (T, 3) and
    rest offsets (J, 3)."""
    out = np.empty((*glob.shape[:2], 3))
    _forward_kinematics(
        np.ascontiguousarray(glob, dtype=np.float64),
        np.ascontiguousarray(root_pos, dtype=np.float64),
        np.ascontiguousarray(offsets, dtype=np.float64),
        np.asarray(parents, dtype=np.int64),
        out,
    )
    return out
