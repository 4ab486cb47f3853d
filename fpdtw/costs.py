"""Frame-to-frame costs: FP-DTW eq. 1 (geodesic) and OPW poster eq. 5 (positions).

Eq. 1's ``arccos`` is :func:`_acos01`, a branch-free polynomial within 1 ulp of libm's
(tested), about five times faster; every cost in fpdtw uses it, so offline DTW, OE-DTW and
the window methods see bit-identical costs.
"""

from __future__ import annotations

import math

import numba
import numpy as np

_TWO_OVER_PI = 2.0 / math.pi
_PI_OVER_2 = math.pi / 2.0

# asin(s) = s + s z P(z), z = s^2 <= 1/4: P interpolates (asin(sqrt z)/sqrt z - 1)/z at the
# 13 Chebyshev nodes of [0, 1/4] (50-digit Taylor values rounded to float64); its relative
# error below 1e-15 is shrunk below 1 ulp of asin by the factor z and the final "+ s".
_P = (
    0.16666666666666669,
    0.07499999999998433,
    0.04464285714635543,
    0.030381944138531247,
    0.02237217294214989,
    0.017352392720869973,
    0.013971212973552933,
    0.011479177415184906,
    0.01032281435018578,
    0.005457506718640358,
    0.01740087944269402,
    -0.014851887071247204,
    0.028757851367421566,
)


@numba.njit(cache=True, inline="always")
def _acos01(x):
    """arccos(x) for x in [0, 1], branch-free (vectorisable), within 1 ulp of libm.

    x <= 1/2: acos = pi/2 - asin(x); x > 1/2: acos = 2 asin(sqrt((1 - x)/2)) (exact
    argument reduction: 1 - x is exact for x >= 1/2)."""
    big = x > 0.5
    z = (1.0 - x) * 0.5 if big else x * x
    s = math.sqrt(z) if big else x
    p = _P[12]
    p = _P[11] + z * p
    p = _P[10] + z * p
    p = _P[9] + z * p
    p = _P[8] + z * p
    p = _P[7] + z * p
    p = _P[6] + z * p
    p = _P[5] + z * p
    p = _P[4] + z * p
    p = _P[3] + z * p
    p = _P[2] + z * p
    p = _P[1] + z * p
    p = _P[0] + z * p
    a = s + s * (z * p)
    return 2.0 * a if big else _PI_OVER_2 - a


#: Eq. 1 as written: the empty weights of the kernels below.
_NO_WEIGHTS = np.empty(0)


@numba.njit(cache=True, fastmath=False, inline="always")
def _geo_frame_w(qa, qb, wts):
    """eq. 1 between two frames; qa, qb : float64 (k, 4); ``wts`` : float64 (k,) per-joint
    weights, or EMPTY (0,) for eq. 1 as written (exactly the unweighted sum).

    Plain version: fpdtw.plain.geo_distance.
    """
    weighted = wts.shape[0] > 0
    total = 0.0
    for j in range(qa.shape[0]):
        d = abs(
            qa[j, 0] * qb[j, 0] + qa[j, 1] * qb[j, 1] + qa[j, 2] * qb[j, 2] + qa[j, 3] * qb[j, 3]
        )
        if d > 1.0:
            d = 1.0
        if weighted:
            total += wts[j] * _acos01(d)
        else:
            total += _acos01(d)
    return _TWO_OVER_PI * total


@numba.njit(cache=True, fastmath=False, inline="always")
def _geo_frame(qa, qb):
    """eq. 1 between two frames; qa, qb : float64 (k, 4) (:func:`_geo_frame_w` unweighted).

    Plain version: fpdtw.plain.geo_distance.
    """
    return _geo_frame_w(qa, qb, _NO_WEIGHTS)


@numba.njit(cache=True)
def _geo_line_w(a, B, lo, hi, acc, out, wts):
    """``out[c] = geoDistance(a, B[:, :, lo + c])`` for ``c < hi - lo``, bit-identical to
    :func:`_geo_frame_w`; a (k, 4); B (k, 4, n) joint-major, so the loop over frames
    vectorises; acc: scratch.

    Plain version: fpdtw.plain.geo_distance.
    """
    weighted = wts.shape[0] > 0
    n = hi - lo
    for c in range(n):
        acc[c] = 0.0
    for j in range(a.shape[0]):
        a0 = a[j, 0]
        a1 = a[j, 1]
        a2 = a[j, 2]
        a3 = a[j, 3]
        b0 = B[j, 0, lo:hi]
        b1 = B[j, 1, lo:hi]
        b2 = B[j, 2, lo:hi]
        b3 = B[j, 3, lo:hi]
        if weighted:
            wj = wts[j]
            for c in range(n):
                d = abs(a0 * b0[c] + a1 * b1[c] + a2 * b2[c] + a3 * b3[c])
                acc[c] += wj * _acos01(min(d, 1.0))
        else:
            for c in range(n):
                d = abs(a0 * b0[c] + a1 * b1[c] + a2 * b2[c] + a3 * b3[c])
                acc[c] += _acos01(min(d, 1.0))
    for c in range(n):
        out[c] = acc[c] * _TWO_OVER_PI


@numba.njit(cache=True)
def _geo_line(a, B, lo, hi, acc, out):
    """:func:`_geo_line_w` unweighted (eq. 1 as written).

    Plain version: fpdtw.plain.geo_distance.
    """
    _geo_line_w(a, B, lo, hi, acc, out, _NO_WEIGHTS)


@numba.njit(cache=True)
def _geo_block(A, B, out):
    """Fill ``out[i, j] = geoDistance(A[i], B[j])``; A (m, k, 4), B (n, k, 4).

    Plain version: fpdtw.plain.cost_matrix.
    """
    for i in range(A.shape[0]):
        for j in range(B.shape[0]):
            out[i, j] = _geo_frame(A[i], B[j])
    return out


def geo_distance(qa, qb, weights=None) -> float:
    """Geodesic distance between two frames.

    Parameters
    ----------
    qa, qb : ndarray of float, shape (k, 4)
        Unit quaternions of the k joints of each frame.
    weights : ndarray of float, shape (k,), optional
        Per-joint weights (:func:`fpdtw.weights.joint_weights`); None: eq. 1 as written.

    Returns
    -------
    d : float
        In ``[0, k]`` unweighted.

    Plain version: fpdtw.plain.geo_distance.
    Paper: FP-DTW eq. 1.
    """
    qa = np.ascontiguousarray(qa, dtype=np.float64)
    qb = np.ascontiguousarray(qb, dtype=np.float64)
    if weights is None:
        return float(_geo_frame(qa, qb))
    wts = np.ascontiguousarray(weights, dtype=np.float64)
    if wts.shape != (qa.shape[0],):
        raise ValueError(f"expected {qa.shape[0]} weights, got shape {wts.shape}")
    return float(_geo_frame_w(qa, qb, wts))


def geodesic_cost_matrix(QA, QB) -> np.ndarray:
    """``C[i, j] = geoDistance(QA_i, QB_j)``, float64 (m, n), of quaternions QA (m, k, 4)
    and QB (n, k, 4).

    Plain version: fpdtw.plain.cost_matrix.
    Paper: FP-DTW eq. 1.
    """
    QA = np.ascontiguousarray(QA, dtype=np.float64)
    QB = np.ascontiguousarray(QB, dtype=np.float64)
    if QA.ndim != 3 or QB.ndim != 3 or QA.shape[1:] != QB.shape[1:] or QA.shape[2] != 4:
        raise ValueError(
            f"expected (m, k, 4) and (n, k, 4) quaternions, got {QA.shape}, {QB.shape}"
        )
    out = np.empty((QA.shape[0], QB.shape[0]))
    return _geo_block(QA, QB, out)


@numba.njit(cache=True)
def _pos_block(A, B, out):
    for i in range(A.shape[0]):
        for j in range(B.shape[0]):
            total = 0.0
            for k in range(A.shape[1]):
                dx = A[i, k, 0] - B[j, k, 0]
                dy = A[i, k, 1] - B[j, k, 1]
                dz = A[i, k, 2] - B[j, k, 2]
                total += math.sqrt(dx * dx + dy * dy + dz * dz)
            out[i, j] = total
    return out


def position_cost_matrix(PA, PB) -> np.ndarray:
    """Sum of Euclidean joint-position distances, float64 (m, n), between every frame of
    PA (m, k, 3) and of PB (n, k, 3) (root-relative positions for OPW).

    Paper: OPW poster eq. 5.
    """
    PA = np.ascontiguousarray(PA, dtype=np.float64)
    PB = np.ascontiguousarray(PB, dtype=np.float64)
    if PA.ndim != 3 or PB.ndim != 3 or PA.shape[1:] != PB.shape[1:] or PA.shape[2] != 3:
        raise ValueError(f"expected (m, k, 3) and (n, k, 3) positions, got {PA.shape}, {PB.shape}")
    out = np.empty((PA.shape[0], PB.shape[0]))
    return _pos_block(PA, PB, out)
