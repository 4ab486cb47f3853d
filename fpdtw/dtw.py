"""Offline baselines: classic DTW and uniform time warping (UTW).

A cost matrix ``C[i, j]`` has a row per INPUT frame ``I_i`` (``i = 0..m``) and a column
per TARGET frame ``T_j`` (``j = 0..n``); a map ``M`` (int, length ``n + 1``) holds the
input frame of each target frame.

Reading: the paper's "classic DTW" (and Method B's "in the same manner as DTW") is Sakoe
and Chiba's recursion without slope weights, ``"symmetric1"`` (the default):
``D[i, j] = C[i, j] + min(D[i-1, j-1], D[i-1, j], D[i, j-1])``; ``"symmetric2"`` weighs
the diagonal step 2 (dtw-python's default). ``D`` and the paths equal dtw-python's, ties
included: the back-track takes the lowest ``D[prev] + w * C[i, j]`` and prefers the
diagonal, then ``(i, j-1)``, then ``(i-1, j)``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np

from fpdtw import limits
from fpdtw.costs import geodesic_cost_matrix
from fpdtw.errors import AlignmentError
from fpdtw.motion.rig import pair_rotations

#: Weight of the diagonal step of each supported step pattern (side steps weigh 1).
STEP_PATTERNS = {"symmetric1": 1.0, "symmetric2": 2.0}


def diagonal_weight(step_pattern: str) -> float:
    """Diagonal step weight of a step pattern (AlignmentError if unknown)."""
    try:
        return STEP_PATTERNS[step_pattern]
    except (KeyError, TypeError):
        raise AlignmentError(
            f"unknown step pattern {step_pattern!r}; expected one of {sorted(STEP_PATTERNS)}"
        ) from None


def _check_d_size(shape) -> None:
    """The accumulated cost matrix of this shape fits :data:`fpdtw.limits.MAX_MATRIX_BYTES`."""
    rows, cols = shape
    limits.check_bytes(
        8 * rows * cols, None, f"DTW's accumulated cost matrix would be {rows} x {cols} float64"
    )


def _check_cost(C, what="cost matrix", finite=True) -> np.ndarray:
    C = np.ascontiguousarray(C, dtype=np.float64)
    if C.ndim != 2:
        raise AlignmentError(f"{what} must be 2-D (input frames x target frames), got {C.shape}")
    if C.shape[0] == 0 or C.shape[1] == 0:
        raise AlignmentError(f"{what} is empty, shape {C.shape}")
    if finite and not np.isfinite(C).all():
        i, j = np.argwhere(~np.isfinite(C))[0]
        raise AlignmentError(f"{what} has a non-finite value {C[i, j]} at [{i}, {j}]")
    return C


@numba.njit(cache=True)
def _accumulate(C, wd, D):
    """Fill ``D`` (shape of ``C``) with the accumulated cost, ``wd`` the diagonal weight, by
    dtw-python's floating-point operations (so bit for bit).

    Plain version: fpdtw.plain.accumulate.
    """
    m1, n1 = C.shape
    x = C[0, 0]
    D[0, 0] = x
    for j in range(1, n1):
        x = x + C[0, j]
        D[0, j] = x
    for i in range(1, m1):
        x = D[i - 1, 0] + C[i, 0]
        D[i, 0] = x
        for j in range(1, n1):
            c = C[i, j]
            # the two steps from row i-1 do not depend on x: only "x + c, min" is serial
            best = min(D[i - 1, j - 1] + wd * c, D[i - 1, j] + c)
            x = min(best, x + c)
            D[i, j] = x
    return D


@numba.njit(cache=True)
def _backtrack(D, C, wd, use_c):
    """Path from ``(m, n)`` back to ``(0, 0)``, in forward order, int64 (L, 2); with
    ``use_c`` the steps compare ``D[prev] + w * C[i, j]`` (dtw-python's rule), else ``D[prev]``.

    Plain version: fpdtw.plain.backtrack.
    """
    i = D.shape[0] - 1
    j = D.shape[1] - 1
    out = np.empty((i + j + 1, 2), dtype=np.int64)
    k = out.shape[0] - 1
    out[k, 0] = i
    out[k, 1] = j
    while i > 0 or j > 0:
        if i == 0:
            j -= 1
        elif j == 0:
            i -= 1
        else:
            c = C[i, j] if use_c else 0.0
            d = D[i - 1, j - 1] + wd * c
            h = D[i, j - 1] + c
            v = D[i - 1, j] + c
            if d <= h and d <= v:
                i -= 1
                j -= 1
            elif h <= v:
                j -= 1
            else:
                i -= 1
        k -= 1
        out[k, 0] = i
        out[k, 1] = j
    return out[k:]


@numba.njit(cache=True)
def _path_to_map(path, n1):
    M = np.full(n1, -1, dtype=np.int64)
    for r in range(path.shape[0]):
        i = path[r, 0]
        j = path[r, 1]
        if 0 <= j < n1 and (M[j] < 0 or i < M[j]):
            M[j] = i
    return M


def accumulate(C, step_pattern: str = "symmetric1") -> np.ndarray:
    """Accumulated cost matrix of classic DTW (AlignmentError: ``C`` not 2-D, empty or not
    finite, or an unknown step pattern).

    Parameters
    ----------
    C : ndarray of float, shape (m + 1, n + 1)
        Rows: input frames; columns: target frames.
    step_pattern : {"symmetric1", "symmetric2"}

    Returns
    -------
    D : ndarray of float64, shape (m + 1, n + 1)

    Plain version: fpdtw.plain.accumulate (symmetric1).
    Paper: FP-DTW Section 2, Algorithm 2; Sakoe & Chiba 1978.
    """
    wd = diagonal_weight(step_pattern)
    C = _check_cost(C)
    _check_d_size(C.shape)
    return _accumulate(C, wd, np.empty_like(C))


def backtrack(D, C=None, step_pattern: str = "symmetric1") -> np.ndarray:
    """Optimal warping path through an accumulated cost matrix (ties: module docstring).

    Parameters
    ----------
    D : ndarray of float, shape (m + 1, n + 1)
        Accumulated cost from :func:`accumulate`.
    C : ndarray of float, shape (m + 1, n + 1), optional
        The local cost ``D`` was built from: steps are then compared as dtw-python does;
        required for ``"symmetric2"``.
    step_pattern : {"symmetric1", "symmetric2"}

    Returns
    -------
    path : ndarray of int64, shape (L, 2)
        Cells (input frame, target frame) from ``(0, 0)`` to ``(m, n)``.

    Plain version: fpdtw.plain.backtrack (symmetric1).
    Paper: FP-DTW Section 3.2.
    """
    wd = diagonal_weight(step_pattern)
    # no full finiteness scan: the back-track reads only O(m + n) cells
    D = _check_cost(D, "accumulated cost matrix", finite=False)
    if C is None:
        if wd != 1.0:
            raise AlignmentError(f"backtrack with step pattern {step_pattern!r} needs C")
        return _backtrack(D, D, wd, False)
    C = _check_cost(C, finite=False)
    if C.shape != D.shape:
        raise AlignmentError(f"C has shape {C.shape} but D has shape {D.shape}")
    return _backtrack(D, C, wd, True)


def path_to_map(path, n: int) -> np.ndarray:
    """A warping path's map target frame -> input frame: the LOWEST input frame of each
    target frame (the paper's Method B rule and the authors' toolkit).

    Parameters
    ----------
    path : ndarray of int, shape (L, 2)
        Cells ``(input frame, target frame)``.
    n : int
        Index of the last target frame (the map has ``n + 1`` entries).

    Returns
    -------
    M : ndarray of int64, shape (n + 1,)

    Plain version: fpdtw.plain.path_to_map.
    """
    path = np.asarray(path)
    if path.ndim != 2 or path.shape[1] != 2 or path.shape[0] == 0:
        raise AlignmentError(f"a path must have shape (L, 2), got {path.shape}")
    if n < 0:
        raise AlignmentError(f"n must be >= 0, got {n}")
    path = np.ascontiguousarray(path, dtype=np.int64)
    if (path < 0).any():
        raise AlignmentError("a path cell has a negative frame index")
    M = _path_to_map(path, int(n) + 1)
    if (M < 0).any():
        q = int(np.flatnonzero(M < 0)[0])
        raise AlignmentError(f"target frame {q} is not on the path")
    return M


@dataclass(frozen=True)
class DTWResult:
    """Result of :func:`dtw`: ``distance = D[m, n]`` (not normalised), ``D`` (float64,
    (m + 1, n + 1)), ``path`` (int64, (L, 2)) and its ``map`` (int64, (n + 1,))."""

    distance: float
    D: np.ndarray
    path: np.ndarray
    map: np.ndarray


def dtw(C, step_pattern: str = "symmetric1") -> DTWResult:
    """Classic DTW over a full cost matrix ``C`` (float, shape (m + 1, n + 1)).

    Paper: FP-DTW Sections 2 and 4 (DTW baseline for eq. 3).
    """
    wd = diagonal_weight(step_pattern)
    C = _check_cost(C)
    _check_d_size(C.shape)
    D = _accumulate(C, wd, np.empty_like(C))
    path = _backtrack(D, C, wd, True)
    M = _path_to_map(path, C.shape[1])
    return DTWResult(float(D[-1, -1]), D, path, M)


def dtw_pair(I, T, step_pattern: str = "symmetric1") -> DTWResult:
    """DTW between two motions with the geodesic cost (eq. 1); LimitError, before allocating,
    past :data:`fpdtw.limits.MAX_MATRIX_BYTES`.

    Parameters
    ----------
    I, T : MotionFeatures
        Input (``m + 1`` frames) and target (``n + 1``), the same joints; of different
        rigs, compared by :func:`fpdtw.motion.rig.pair_rotations`.
    step_pattern : {"symmetric1", "symmetric2"}

    Returns
    -------
    DTWResult

    Paper: FP-DTW eq. 1 and Section 4.
    Notebook: 10_fig8_walk_pair.ipynb
    """
    if I.quats.shape[1:] != T.quats.shape[1:]:
        raise AlignmentError(
            f"input and target have different joints: {I.quats.shape} vs {T.quats.shape}"
        )
    check_dtw_size(I.n_frames, T.n_frames, (I.name, T.name))
    return dtw(geodesic_cost_matrix(*pair_rotations(I, T)), step_pattern)


def check_dtw_size(input_frames: int, target_frames: int, names=None) -> None:
    """Offline DTW's two float64 matrices of ``input_frames x target_frames`` fit
    :data:`fpdtw.limits.MAX_MATRIX_BYTES` (LimitError naming ``names`` otherwise)."""
    limits.check_bytes(
        limits.dtw_bytes(input_frames, target_frames),
        names,
        f"offline DTW of {input_frames} input x {target_frames} target frames needs two "
        f"{input_frames} x {target_frames} float64 matrices",
    )


def utw_map(m: int, n: int) -> np.ndarray:
    """Uniform time warping map ``M_q = round(q * m / n)``, q = 0..n.

    Halves round up, in exact integers: ``(2*q*m + n) // (2*n)``; ``n = 0`` gives ``[0]``.

    Parameters
    ----------
    m, n : int
        Last input frame and last target frame, both ``>= 0``.

    Returns
    -------
    M : ndarray of int64, shape (n + 1,)

    Paper: FP-DTW Section 4 (UTW benchmark, Fu et al. 2008).
    """
    m, n = int(m), int(n)
    if m < 0 or n < 0:
        raise AlignmentError(f"utw_map needs m >= 0 and n >= 0, got m={m}, n={n}")
    if n == 0:
        return np.zeros(1, dtype=np.int64)
    q = np.arange(n + 1, dtype=np.int64)
    return (2 * q * m + n) // (2 * n)
