"""The papers' equations and algorithms in plain NumPy, line by line in their notation.

This module is what to read beside the papers: no numba, no scratch buffers, no parameter
vectors; one function per equation or algorithm, written as the paper writes it, and the
notebooks step through these functions on real motions. The library's fast kernels
(:mod:`fpdtw.costs`, :mod:`fpdtw.dtw`, :mod:`fpdtw.online`, :mod:`fpdtw.metrics`) are
optimised versions of the same computations: each names its plain version in its
docstring ("Plain version: fpdtw.plain.xxx"), and ``tests/test_plain.py`` holds the two
equal (the same maps on every pair of the smoke grid and on the hand-worked cases).

Notation (FP-DTW paper, Section 3): the input ``I = {I_0..I_m}`` (the recording, fully
known), the target ``T = {T_0..T_n}`` (the live motion, received so far), the incoming
frame ``T_{n+1}``, the map so far ``M = {M_0..M_n}`` (``M_q``: the input frame of target
frame ``q``), the window ``w``, the input window ``{I_{M_n}..I_{M_n+w_i}}`` (``w_i + 1``
rows: ``w_i`` is always the offset of its last row), the target window ``F``, the cost
matrix ``C`` (row ``r``: input frame ``I_{M_n+r}``; column ``c``: ``F_c``), the
accumulated cost ``D`` and the path ``P``. A frame is an array of ``k`` unit quaternions
``(w, x, y, z)``, one per joint: shape ``(k, 4)``. The ``line N`` comments number the
statements of the paper's listings from their first ``if`` (the declarations above it
are not numbered).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np

# --- eq. 1: the geodesic distance of two poses -----------------------------------------


def geo_distance(Q_a, Q_b, weights=None):
    """Geodesic distance between poses: ``d = sum_j (2/pi) arccos |Q_j^a . Q_j^b|``.

    With ``weights`` (beyond the papers, notebook 16's Q2): ``d = sum_j w_j (2/pi)
    arccos |Q_j^a . Q_j^b|`` (see :func:`fpdtw.weights.joint_weights`).

    Parameters
    ----------
    Q_a, Q_b : ndarray of float, shape (..., k, 4)
        Unit quaternions of the ``k`` joints (leading axes broadcast).
    weights : ndarray of float, shape (k,), optional
        Per-joint weights; None: every joint counts 1 (eq. 1 as written).

    Returns
    -------
    d : float or ndarray of float64, shape (...)
        In ``[0, k]``: 0 for the same pose, 1 per joint turned by pi.

    Paper: FP-DTW eq. 1.
    Notebook: 02_fig1_oedtw.ipynb
    """
    Q_a, Q_b = np.asarray(Q_a, dtype=float), np.asarray(Q_b, dtype=float)
    dot = Q_a[..., 0] * Q_b[..., 0]
    for c in (1, 2, 3):
        dot = dot + Q_a[..., c] * Q_b[..., c]
    angle = np.arccos(np.minimum(np.abs(dot), 1.0))  # |dot| clipped to [0, 1]
    if weights is not None:
        angle = angle * np.asarray(weights, dtype=float)
    d = angle[..., 0]
    for j in range(1, angle.shape[-1]):  # joints summed in order
        d = d + angle[..., j]
    return (2 / np.pi) * d


def cost_matrix(A, B, weights=None) -> np.ndarray:
    """``C[i, j] = geo_distance(A_i, B_j)`` (eq. 1) for every pair of frames.

    Parameters
    ----------
    A : ndarray of float, shape (r, k, 4)
    B : ndarray of float, shape (c, k, 4)
    weights : ndarray of float, shape (k,), optional
        Per-joint weights of eq. 1 (see :func:`geo_distance`).

    Returns
    -------
    C : ndarray of float64, shape (r, c)

    Paper: FP-DTW eq. 1 (getCostMatrix of Algorithms 2 and 3).
    Notebook: 02_fig1_oedtw.ipynb
    """
    return np.array([geo_distance(A_i, np.asarray(B), weights) for A_i in np.asarray(A)]).reshape(
        len(A), len(B)
    )


# --- DTW: accumulation, back-tracking, open end -----------------------------------------


def accumulate(C) -> np.ndarray:
    """Classic DTW accumulation from (0, 0): ``D[i, j] = C[i, j] + min(D[i-1, j-1],
    D[i-1, j], D[i, j-1])`` (Sakoe and Chiba's symmetric form without weights).

    Parameters
    ----------
    C : ndarray of float, shape (rows, cols)
        Rows: input frames; columns: target frames.

    Returns
    -------
    D : ndarray of float64, shape (rows, cols)

    Paper: FP-DTW Section 2; getTotalCostMatrix of Algorithm 2.
    Notebook: 02_fig1_oedtw.ipynb
    """
    C = np.asarray(C, dtype=float)
    D = np.empty_like(C)
    for i in range(C.shape[0]):
        for j in range(C.shape[1]):
            if i == 0 and j == 0:
                D[i, j] = C[i, j]
            elif i == 0:
                D[i, j] = C[i, j] + D[i, j - 1]
            elif j == 0:
                D[i, j] = C[i, j] + D[i - 1, j]
            else:
                D[i, j] = C[i, j] + min(D[i - 1, j - 1], D[i - 1, j], D[i, j - 1])
    return D


def backtrack(D, C=None) -> np.ndarray:
    """The path back from the far corner of ``D`` to (0, 0), in forward order.

    Each step goes to the neighbour the accumulation came from: the lowest of
    ``D[i-1, j-1]``, ``D[i, j-1]`` (same input frame, previous target frame) and
    ``D[i-1, j]``, each plus ``C[i, j]`` when ``C`` is given (the recursion read
    backwards, dtw-python's rule); on equal values the diagonal, then ``(i, j-1)``.
    On row 0 only ``(i, j-1)``, on column 0 only ``(i-1, j)``.

    Parameters
    ----------
    D : ndarray of float, shape (rows, cols)
    C : ndarray of float, same shape, optional

    Returns
    -------
    path : ndarray of int64, shape (L, 2)
        Cells (input row, target column) from (0, 0) to (rows - 1, cols - 1).

    Paper: FP-DTW Section 3.2 (plotPath of Algorithm 2).
    Notebook: 02_fig1_oedtw.ipynb
    """
    i, j = D.shape[0] - 1, D.shape[1] - 1
    path = [(i, j)]
    while (i, j) != (0, 0):
        if i == 0:
            j -= 1
        elif j == 0:
            i -= 1
        else:
            c = 0.0 if C is None else C[i, j]
            steps = [
                (D[i - 1, j - 1] + c, (i - 1, j - 1)),  # diagonal
                (D[i, j - 1] + c, (i, j - 1)),  # previous target frame, same input frame
                (D[i - 1, j] + c, (i - 1, j)),  # previous input frame, same target frame
            ]
            i, j = min(steps, key=lambda s: s[0])[1]  # min keeps the first of equal values
        path.append((i, j))
    return np.array(path[::-1], dtype=np.int64)


def path_to_map(path, n: int) -> np.ndarray:
    """The map of a path: per target frame ``q = 0..n`` the LOWEST input frame the path
    visits in its column (Method B's overwrite rule; the DTW maps of eq. 3).

    Parameters
    ----------
    path : ndarray of int, shape (L, 2)
        Cells (input frame, target frame).
    n : int
        Last target frame.

    Returns
    -------
    M : ndarray of int64, shape (n + 1,)

    Paper: FP-DTW Section 3.2, Fig. 4.
    Notebook: 06_fig5_fig6_scores.ipynb
    """
    M = np.full(n + 1, np.iinfo(np.int64).max)
    for i, j in path:
        M[j] = min(M[j], i)
    return M


def oe_dtw_end_points(C) -> np.ndarray:
    """Open-end DTW's end point after each target frame: ``e_q = argmin_i D[i, q]``.

    Column ``q`` of the accumulation depends only on the target frames ``0..q``, so
    accumulating the whole cost matrix once gives what OE-DTW computes one column per
    arriving frame.

    Parameters
    ----------
    C : ndarray of float, shape (m + 1, n + 1)

    Returns
    -------
    e : ndarray of int64, shape (n + 1,)
        Lowest row on ties.

    Paper: FP-DTW Section 2, Fig. 1 (Tormene et al.'s open-end DTW).
    Notebook: 02_fig1_oedtw.ipynb
    """
    return np.argmin(accumulate(C), axis=0)


def reverse_accumulate(C, open_end=False, normalised=False) -> np.ndarray:
    """Method C's accumulation in reverse, from the far corner back to (0, 0):
    ``D[i, j] = C[i, j] + min(D[i+1, j+1], D[i+1, j], D[i, j+1])``.

    Parameters
    ----------
    C : ndarray of float, shape (rows, cols)
    open_end : bool
        The path may end in any row of the last column: ``D[i, cols-1] = C[i, cols-1]``.
    normalised : bool
        The symmetric2 weights (the diagonal step counts ``2 C[i, j]``).

    Returns
    -------
    D : ndarray of float64, shape (rows, cols)

    Paper: FP-DTW Algorithm 3, getReverseTotalCostMatrix.
    """
    C = np.asarray(C, dtype=float)
    D = np.empty_like(C)
    last_i, last_j = C.shape[0] - 1, C.shape[1] - 1
    for i in range(last_i, -1, -1):
        for j in range(last_j, -1, -1):
            c = C[i, j]
            if j == last_j and (i == last_i or open_end):
                D[i, j] = c
            elif i == last_i:
                D[i, j] = c + D[i, j + 1]
            elif j == last_j:
                D[i, j] = c + D[i + 1, j]
            elif normalised:
                D[i, j] = min(D[i + 1, j + 1] + 2 * c, D[i + 1, j] + c, D[i, j + 1] + c)
            else:
                D[i, j] = c + min(D[i + 1, j + 1], D[i + 1, j], D[i, j + 1])
    return D


# --- forecastJoints ---------------------------------------------------------------------


def forecast_joints(E_n, E_n1, w: int) -> np.ndarray:
    """Dead reckoning from the two latest frames (``forecastJoints``).

    Parameters
    ----------
    E_n, E_n1 : ndarray of float, shape (k, 3)
        Unwrapped Euler angles (degrees) of ``T_n`` and ``T_{n+1}``.
    w : int
        Forecast length.

    Returns
    -------
    E : ndarray of float64, shape (w, k, 3)
        ``E[i] = T_{n+1} + i (T_{n+1} - T_n)``, ``i = 0..w-1`` (``E[0] = T_{n+1}``).

    Paper: FP-DTW Algorithms 2 and 3, forecastJoints.
    Notebook: 04_fig3_forecast.ipynb
    """
    E_n = np.asarray(E_n, dtype=np.float64)
    E_n1 = np.asarray(E_n1, dtype=np.float64)
    delta = E_n1 - E_n
    i = np.arange(int(w), dtype=np.float64).reshape((-1,) + (1,) * E_n1.ndim)
    return E_n1 + i * delta


def quat_multiply(a, b) -> np.ndarray:
    """Hamilton product ``a b`` of quaternions ``(w, x, y, z)``, shape (..., 4)."""
    aw, ax, ay, az = np.moveaxis(np.asarray(a, dtype=float), -1, 0)
    bw, bx, by, bz = np.moveaxis(np.asarray(b, dtype=float), -1, 0)
    return np.stack([aw * bw - ax * bx - ay * by - az * bz, aw * bx + ax * bw + ay * bz - az * by,
                     aw * by - ax * bz + ay * bw + az * bx, aw * bz + ax * by - ay * bx + az * bw],
                    axis=-1)  # fmt: skip


def euler_to_quat(E, orders) -> np.ndarray:
    """Unit quaternions of per-joint Euler angles: ``q = q_3 q_2 q_1`` for the axes of each
    joint's rotation order, applied in that order (``"ZXY"``: Z first).

    Parameters
    ----------
    E : ndarray of float, shape (..., k, 3)
        Angles in degrees about X, Y, Z.
    orders : sequence of str, length k

    Returns
    -------
    Q : ndarray of float64, shape (..., k, 4)
        The sign is not normalised (eq. 1 uses ``|Q_a . Q_b|``).

    Paper: FP-DTW Algorithms 2 and 3 (the forecast turned into quaternions for eq. 1).
    Notebook: 04_fig3_forecast.ipynb
    """
    E = np.asarray(E, dtype=float)
    Q = np.zeros(E.shape[:-1] + (4,))
    Q[..., 0] = 1.0
    for j, order in enumerate(orders):
        for axis in order:
            a = "XYZ".index(axis)
            h = E[..., j, a] * (math.pi / 360.0)  # half the angle, in radians
            q = np.zeros(h.shape + (4,))
            q[..., 0], q[..., 1 + a] = np.cos(h), np.sin(h)
            Q[..., j, :] = quat_multiply(q, Q[..., j, :])
    return Q


def forward_kinematics(Q, pre, post, offsets, parents, root) -> np.ndarray:
    """Global joint positions of one frame from its local rotations, joint after joint
    from the root: the joint's rotation is ``R_j = pre_j Q_j post_j``; a root is at
    ``p_j = o_j + root`` and turned by ``G_j = R_j``; any other joint is at ``p_j = p_a +
    G_a o_j G_a^*`` and turned by ``G_j = G_a R_j`` (``a``: its parent).

    ``G_a o_j G_a^*`` is computed as ``o + w t + u x t`` with ``t = 2 u x o`` for ``G_a =
    (w, u)``.

    Parameters
    ----------
    Q : ndarray of float, shape (J, 4)
        Local rotations of the joints, unit quaternions ``(w, x, y, z)``.
    pre, post : ndarray of float, shape (J, 4)
        Each joint's pre- and post-rotation (FBX; the identity for BVH and ASF/AMC).
    offsets : ndarray of float, shape (J, 3)
        Each joint's offset ``o_j`` from its parent (a root's from the origin).
    parents : ndarray of int, shape (J,)
        Each joint's parent, an earlier joint; -1 for a root.
    root : ndarray of float, shape (3,)
        The root translation of the frame.

    Returns
    -------
    P : ndarray of float64, shape (J, 3)
        Global positions ``p_j``.

    Paper: OPW poster eq. 5 (poses compared by their joints' positions).
    """
    P, G = np.empty((len(Q), 3)), np.empty((len(Q), 4))
    for j in range(len(Q)):
        R_j = quat_multiply(quat_multiply(pre[j], Q[j]), post[j])
        a = parents[j]
        if a < 0:
            P[j], G[j] = offsets[j] + root, R_j
            continue
        w, u = G[a, 0], G[a, 1:]
        t = 2.0 * np.cross(u, offsets[j])
        P[j] = P[a] + (offsets[j] + w * t + np.cross(u, t))  # p_a + G_a o_j G_a^*
        G[j] = quat_multiply(G[a], R_j)
    return P


# --- the Type V constraint (Fig. 9) -----------------------------------------------------

#: Fig. 9 iv: per state, the next state after an advance of 0, 1, 2, 3 input frames
#: (None: not allowed). N: no hold allowed; A1: just advanced by 1; H1: held once after it.
TYPE_V_TABLE = {
    "N": (None, "A1", "N", "N"),
    "A1": ("H1", "A1", "N", "N"),
    "H1": ("N", "A1", "N", "N"),
}
#: The state before target frame 1 (``M_0 = 0``; a Type V path leaves (0, 0) diagonally).
TYPE_V_START = "N"


def type_v_allowed(state: str) -> np.ndarray:
    """The advances 0..3 the forward Type V constraint allows in ``state`` (larger
    advances never are).

    Returns
    -------
    allowed : ndarray of bool, shape (4,)

    Paper: FP-DTW Section 6, Fig. 9 iv.
    Notebook: 11_fig9_typev.ipynb
    """
    return np.array([nxt is not None for nxt in TYPE_V_TABLE[state]])


def type_v_next(state: str, advance: int):
    """The state after an advance of ``advance`` input frames; None if not allowed.

    Paper: FP-DTW Section 6, Fig. 9 iv.
    Notebook: 11_fig9_typev.ipynb
    """
    return TYPE_V_TABLE[state][advance] if 0 <= advance <= 3 else None


def band_rows(start: int, rows: int, q: int, band: int) -> np.ndarray:
    """Which rows (offsets from ``M_n``) of a window lie inside the global band.

    Beyond the papers (their conclusion's global constraint; notebook 16): row ``r`` (input
    frame ``M_n + r``) is inside when ``|M_n + r - q| <= band``, the diagonal ``M_q = q``.

    Parameters
    ----------
    start : int
        ``M_n``.
    rows : int
    q : int
        The target frame being mapped, ``n + 1``.
    band : int
        Half-width in frames (> 0).

    Returns
    -------
    inside : ndarray of bool, shape (rows,)

    Paper: FP-DTW Section 7 (conclusion: a global constraint).
    """
    return np.abs(start + np.arange(rows) - q) <= band


#: Half-width of ``band="1s"`` in seconds (multiplied by the input's frame rate).
BAND_SECONDS = 1.0


def band_half_width(band: str, w: int, fps: float) -> int:
    """The half-width ``B`` in frames of a global band option (beyond the papers, notebook
    16): ``"1s"``, one second of the input, ``round(fps)``; ``"half-w"``, half the window,
    ``floor(w / 2)``; each at least 1. ``"none"``: 0.

    Paper: FP-DTW Section 7 (conclusion: a global constraint).
    """
    if band == "none":
        return 0
    if band == "1s":
        return max(1, int(round(BAND_SECONDS * fps)))
    if band == "half-w":
        return max(1, int(w) // 2)
    raise ValueError(f"band must be 'none', '1s' or 'half-w', got {band!r}")


def band_window(start: int, w_i: int, q: int, band: int):
    """The rows of the window ``I_{M_n}..I_{M_n + w_i}`` that lie inside the global band,
    as the offsets of the first and the last: what ``band="half-w"`` computes.

    Row ``r`` is inside when ``|M_n + r - q| <= band`` (:func:`band_rows`); those rows are
    consecutive, from ``max(0, q - band - M_n)`` to ``min(w_i, q + band - M_n)``.

    Parameters
    ----------
    start : int
        ``M_n``.
    w_i : int
        Offset of the window's last row.
    q : int
        The target frame being mapped, ``n + 1``.
    band : int
        Half-width in frames (> 0).

    Returns
    -------
    rows : tuple of int (first, last), or None
        The window clipped to the band, ``I_{M_n + first}..I_{M_n + last}``; None when no row
        of the window lies inside it.

    Paper: FP-DTW Section 7 ("a global constraint would restrict the area in which a path
    can be plotted within the cost matrix, reducing the number of cells which need to be
    calculated").
    Notebook: 16_open_questions.ipynb
    """
    first, last = max(0, q - band - start), min(w_i, q + band - start)
    return (first, last) if first <= last else None


def band_cells(M, m: int, w: int, method: str, band: str = "half-w"):
    """Cells of eq. 1 a band aligner's window computes at each of its window steps, with its
    band and without it, from its map alone.

    A step at target frame ``q`` (``n = q - 1``) has a window when ``n >= 2`` (after the
    warm-up) and ``M_n < m``; its window is ``w_i + 1`` rows by ``cols`` columns (Method B:
    ``w_i = min(w, m - M_n)``, ``w + 1`` columns; Method C's square window: ``w_i = min(w -
    1, m - M_n)``, ``w`` columns). Without the band every row is computed; with
    ``band="half-w"`` only those of :func:`band_window` (all of them when none lies inside
    the band, where the step raises); with ``band="1s"`` every row (it masks, computes
    all).

    Parameters
    ----------
    M : ndarray of int, shape (n + 1,)
        The band aligner's map (``M_0..``).
    m : int
        The input's last frame.
    w : int
    method : {"B", "C"}
        Method C: the default square window.
    band : {"half-w", "1s"}

    Returns
    -------
    q : ndarray of int64, shape (s,)
        The target frames of the window steps.
    full, banded : ndarray of int64, shape (s,)
        Cells computed without and with the band at each of them.

    Paper: FP-DTW Section 7 (conclusion: a global constraint).
    """
    M = np.asarray(M, dtype=np.int64)
    B = band_half_width(band, w, 0.0) if band == "half-w" else 0  # "1s" clips nothing
    reach, cols = (w, w + 1) if method == "B" else (w - 1, w)
    qs, full, banded = [], [], []
    for q in range(3, len(M)):  # n = q - 1 >= s = 2
        start = int(M[q - 1])
        if start >= m:
            continue
        w_i = min(reach, m - start)
        rows = w_i + 1
        if band == "half-w" and (r := band_window(start, w_i, q, B)) is not None:
            rows = r[1] - r[0] + 1
        qs.append(q)
        full.append((w_i + 1) * cols)
        banded.append(rows * cols)
    as_int = lambda x: np.array(x, dtype=np.int64)  # noqa: E731
    return as_int(qs), as_int(full), as_int(banded)


def allowed_rows(allowed, rows: int) -> np.ndarray:
    """Which rows (offsets from ``M_n``) of a window a Type V state allows.

    Parameters
    ----------
    allowed : ndarray of bool, shape (4,), or None
        :func:`type_v_allowed` of the state; None: no constraint (every row).
    rows : int

    Returns
    -------
    ok : ndarray of bool, shape (rows,)
    """
    ok = np.ones(rows, dtype=bool)
    if allowed is not None:
        ok[:] = False
        ok[: min(4, rows)] = np.asarray(allowed, dtype=bool)[: min(4, rows)]
    return ok


def checked_choice(ok, r: int) -> int:
    """Offset ``r`` if the constraint allows it; no method ever picks a masked row.

    Raises
    ------
    AlignmentError
        ``r`` is a row the Type V state does not allow (every row of the window is
        masked: e.g. a one-row window after two holds).
    """
    if not ok[r]:
        from fpdtw.errors import AlignmentError

        raise AlignmentError(
            f"no row of the window is allowed by the Type V state (rows {len(ok)}, chosen {r})"
        )
    return r


# --- Algorithms 1-3: one step of Methods A, B and C -------------------------------------


class Step(NamedTuple):
    """What one step of Method A, B or C did.

    Attributes
    ----------
    M : int
        ``M_{n+1}``, the input frame mapped to ``T_{n+1}``.
    kind : str
        ``"warmup"`` (B, C: ``n < s``), ``"end"`` (the input is exhausted) or ``"window"``.
    w_i : int
        The window's last row is ``I_{M_n + w_i}`` (``w_i + 1`` rows); 0 without a window.
    C, D : ndarray of float64, shape (w_i + 1, columns), or None
        Cost (eq. 1; rows Type V does not allow are +inf in the column that chooses) and
        accumulated cost (B: ``D[0, 0]`` set to 10000 after accumulating).
    path : ndarray of int64, shape (L, 2), or None
        B: the back-tracked path.
    P : ndarray of int64, shape (columns,), or None
        B: the lowest row of the path in each column (``P[1]`` is the choice).
    score : ndarray of float64, shape (w_i + 1,), or None
        C: what the argmin compares per row.
    first : int
        The window's first row is ``I_{M_n + first}``: 0, but under ``band="half-w"`` when
        ``I_{M_n}`` lies outside the band; then ``C, D, score`` have ``w_i - first + 1``
        rows (row ``r``: input frame ``I_{M_n + first + r}``).
    """

    M: int
    kind: str
    w_i: int = 0
    C: np.ndarray | None = None
    D: np.ndarray | None = None
    path: np.ndarray | None = None
    P: np.ndarray | None = None
    score: np.ndarray | None = None
    first: int = 0


def _band_of_window(I, M_n: int, w_i: int, q: int, w: int, band: str, allowed):
    """``(B, first, w_i)`` of a step under a band option: its half-width and the window's
    rows (clipped to the band for ``"half-w"`` when a row lies inside it)."""
    B = band_half_width(band, w, I.fps)
    if B and allowed is not None:
        raise ValueError("the global band is not combined with Type V")
    if band == "half-w" and (rows := band_window(M_n, w_i, q, B)) is not None:
        return B, rows[0], rows[1]  # the rows outside the band are not computed
    return B, 0, w_i


def _check_band(inside, r: int) -> int:
    """Row ``r`` if it lies inside the band (``inside``: :func:`band_rows`); a masked row is
    never chosen: the step raises when no row of the window lies inside."""
    if not inside[r]:
        raise ValueError("global band: no input frame of the window lies inside the band")
    return r


def method_a_step(I, T, M, w: int = 2, allowed=None) -> Step:
    """Method A, frame matching: ``T_{n+1}`` goes to the closest input frame in
    ``{I_{M_n}..I_{M_n+w}}``; ``n = len(M) - 1``.

    Parameters
    ----------
    I, T : MotionFeatures
        Input and target; the step reads ``T_{n+1}`` (``T.quats[n + 1]``) only.
    M : sequence of int
        The map so far, ``M_0..M_n``.
    w : int
        Window (the paper: 2).
    allowed : ndarray of bool, shape (4,), or None
        Type V: :func:`type_v_allowed` of the current state.

    Returns
    -------
    Step
        ``C`` has one column, ``T_{n+1}``; ties go to the lowest row.

    Paper: FP-DTW Algorithm 1.
    Notebook: 03_fig2_fig4_windows.ipynb
    """
    n, m = len(M) - 1, len(I.quats) - 1
    M_n = int(M[n])
    w_i = w  # Algorithm 1 shrinks w itself; we call the shrunk window w_i, as Algorithms 2-3
    if M_n + w_i > m:  # line 1
        w_i = m - M_n  # line 2
    if w_i == 0:  # line 4
        return Step(M_n, "end")  # line 5
    C = np.array([geo_distance(I.quats[M_n + i], T.quats[n + 1]) for i in range(w_i + 1)])  # 7-9
    ok = allowed_rows(allowed, w_i + 1)
    r = checked_choice(ok, int(np.argmin(np.where(ok, C, np.inf))))
    return Step(M_n + r, "window", w_i, C[:, None])  # line 10


def method_b_step(I, T, M, w: int, allowed=None, band: str = "none") -> Step:
    """Method B: a DTW path through a forecast window; ``n = len(M) - 1``.

    Parameters
    ----------
    I, T, M, allowed
        As for :func:`method_a_step`; the step reads ``T_n`` and ``T_{n+1}`` only.
    w : int
        Forecast window (the paper: 10, 20, 40, 80).
    band : {"none", "1s", "half-w"}
        The global band (beyond the papers, :class:`fpdtw.online.window.ForecastAligner`):
        ``"1s"`` masks the rows of column ``T_{n+1}`` outside it (:func:`band_rows`);
        ``"half-w"`` computes only the rows inside it (:func:`band_window`), the path
        starting at the first of them. Not with Type V.

    Returns
    -------
    Step
        ``C, D`` of ``w_i + 1`` rows by ``w + 1`` columns ``[T_n, T_{n+1}, forecasts]``,
        the path and ``P``; ``M_{n+1} = M_n + P_1`` (``M_n + first + P_1`` under a clipping
        band).

    Raises
    ------
    ValueError
        Under a band, no row of the window lies inside it.

    Paper: FP-DTW Algorithm 2, Fig. 4.
    Notebook: 03_fig2_fig4_windows.ipynb
    """
    s = 2  # smoothing window: dead reckoning needs T_n and T_{n+1}
    n, m = len(M) - 1, len(I.quats) - 1
    M_n = int(M[n])
    if n < s:  # line 1
        return Step(min(n + 1, m), "warmup")  # line 2 (clipped to a shorter input)
    if M_n >= m:  # line 3
        return Step(m, "end")  # line 4
    w_i = w  # line 6
    if M_n + w_i > m:  # line 7
        w_i = m - M_n  # line 8
    B, first, w_i = _band_of_window(I, M_n, w_i, n + 1, w, band, allowed)
    E = forecast_joints(T.euler[n], T.euler[n + 1], w)  # T_{n+1} + i delta, i = 0..w-1
    F = np.concatenate([T.quats[n : n + 2], euler_to_quat(E[1:], T.orders)])  # lines 10-11
    C = cost_matrix(I.quats[M_n + first : M_n + w_i + 1], F)  # line 12
    ok = allowed_rows(allowed, len(C))
    C[~ok, 1] = np.inf  # Type V: only allowed rows for T_{n+1}
    inside = band_rows(M_n + first, len(C), n + 1, B) if B else np.ones(len(C), dtype=bool)
    C[~inside, 1] = np.inf  # the band: only rows inside it for T_{n+1}
    D = accumulate(C)  # line 13
    D[0, 0] = 10000.0  # line 14: the path must leave (0, 0) through (1, 0) or (0, 1)
    path = backtrack(D)  # line 15
    P = path_to_map(path, w)  # the overwrite rule: the lowest row of each column
    r = _check_band(inside, checked_choice(ok, int(P[1])))
    return Step(M_n + first + r, "window", w_i, C, D, path, P, first=first)  # line 16


def method_c_step(
    I, T, M, w: int, allowed=None, window="square", ties="low", band: str = "none"
) -> Step:
    """Method C: the reverse-accumulated forecast window; ``n = len(M) - 1``.

    Parameters
    ----------
    I, T, M, w, allowed
        As for :func:`method_b_step`.
    window : {"square", "literal", "square-tn", "open-end", "normalised"}
        The reading of Algorithm 3's window (:class:`fpdtw.online.MethodC`): ``"square"``,
        its declared ``w_i x w`` size, ``w`` input rows; ``"literal"``, its range
        ``{I_{M_n}..I_{M_n+w}}``, ``w + 1`` rows; the others as there.
    ties : {"low", "high"}
        Which of equal scores wins.
    band : {"none", "1s", "half-w"}
        The global band, as for :func:`method_b_step` (masked or clipped rows of column
        ``T_{n+1}``; the reverse accumulation from the far corner of the clipped window).

    Returns
    -------
    Step
        ``C, D`` and ``score = D[:, 0]`` (normalised: divided by each row's path weight);
        ``M_{n+1} = M_n + first + argmin``.

    Raises
    ------
    ValueError
        Under a band, no row of the window lies inside it.

    Paper: FP-DTW Algorithm 3.
    Notebook: 03_fig2_fig4_windows.ipynb
    """
    s = 2
    n, m = len(M) - 1, len(I.quats) - 1
    M_n = int(M[n])
    if n < s:  # line 1
        return Step(min(n + 1, m), "warmup")  # line 2
    if M_n >= m:  # line 3 (written M_n > m; at M_n = m every window is I_m alone: the same)
        return Step(m, "end")  # line 4
    w_i = w - 1 if window == "square" else w  # line 6 (square: w rows I_{M_n}..I_{M_n+w-1})
    if M_n + w_i > m:  # line 7
        w_i = m - M_n  # line 8
    B, first, w_i = _band_of_window(I, M_n, w_i, n + 1, w, band, allowed)
    E = forecast_joints(T.euler[n], T.euler[n + 1], w)
    F = np.concatenate([T.quats[n + 1 : n + 2], euler_to_quat(E[1:], T.orders)])  # line 10
    if window == "square-tn":
        F = np.concatenate([T.quats[n : n + 1], F])  # Method B's F_0 = T_n first
    C = cost_matrix(I.quats[M_n + first : M_n + w_i + 1], F)  # line 11
    ok = allowed_rows(allowed, len(C))
    C[~ok, 0] = np.inf  # Type V: only allowed rows for T_{n+1}
    inside = band_rows(M_n + first, len(C), n + 1, B) if B else np.ones(len(C), dtype=bool)
    C[~inside, 0] = np.inf  # the band: only rows inside it for T_{n+1}
    D = reverse_accumulate(C, window == "open-end", window == "normalised")  # line 12
    score = D[:, 0].copy()
    if window == "normalised":
        score = score / ((C.shape[0] - np.arange(C.shape[0])) + C.shape[1])
    choice = np.where(ok, score, np.inf)
    r = int(np.argmin(choice)) if ties == "low" else len(choice) - 1 - int(np.argmin(choice[::-1]))
    r = _check_band(inside, checked_choice(ok, r))
    return Step(M_n + first + r, "window", w_i, C, D, score=score, first=first)  # line 13


def run(step, I, T, w: int, type_v: bool = False, **options) -> np.ndarray:
    """A whole target through one method, a step per target frame, from ``M_0 = 0``.

    Parameters
    ----------
    step : callable
        :func:`method_a_step`, :func:`method_b_step` or :func:`method_c_step`.
    I, T : MotionFeatures
    w : int
    type_v : bool
        The Type V constraint, its state carried from step to step (a hold forced at the
        end of the input, where the constraint cannot hold, leaves the state as it is).
    **options
        Of the step (Method C: ``window``, ``ties``).

    Returns
    -------
    M : ndarray of int64, shape (T.n_frames,)

    Paper: FP-DTW Sections 3 and 6.
    Notebook: 11_fig9_typev.ipynb
    """
    from fpdtw.motion.rig import cost_input

    # motions of two rigs: eq. 1 between the input expressed in the target's rig and the
    # target (fpdtw.motion.rig); the same motion of one rig: the local rotations as they are
    I = dataclasses.replace(I, quats=cost_input(I.quats, I.rig, T.rig))
    M, state = [0], TYPE_V_START
    for _ in range(len(T.quats) - 1):
        allowed = type_v_allowed(state) if type_v else None
        M.append(step(I, T, M, w, allowed, **options).M)
        state = type_v_next(state, M[-1] - M[-2]) or state
    return np.array(M, dtype=np.int64)


# --- OLTW: Dixon's on-line time warping (the FP-DTW paper's reference 3) ----------------
#
# Dixon (DAFx 2005, Fig. 1) grows the accumulated cost D one target column or one input
# row at a time, only inside the c x c band behind the corner (i, q), and after every
# growth asks GetInc which way to grow next. His live sequence (index t) is our target T
# (index q), his reference (index j) our input I (index i): his "Row" increment is our
# "target", his "Column" our "input".


@dataclass
class OLTWState:
    """Where Dixon's loop stands between two target frames.

    Attributes
    ----------
    i, q : int
        The corner: the last input frame (Dixon's ``j``) and target frame (his ``t``) of D.
    D : dict of (int, int) to float
        The path costs computed so far (Dixon's ``pathCost``), ``D[i, q]``.
    previous : str or None
        The last increment other than ``"both"`` (Dixon's ``previous``).
    run_count : int
        How many times in a row that increment was made (Dixon's ``runCount``).
    pending : str or None
        The increment waiting for the next target frame (``"target"`` or ``"both"``).
    """

    i: int = 0
    q: int = 0
    D: dict = field(default_factory=dict)
    previous: str | None = None
    run_count: int = 1
    pending: str | None = None


def oltw_path_cost(s: OLTWState, i: int, q: int, c: int) -> float:
    """``D[i, q]`` if the cell lies in the ``c x c`` band behind the corner, else +inf (a
    predecessor outside the band is unreachable; every cell inside it is computed).

    Paper: Dixon 2005, Section 3 (the search width c).
    """
    inside = s.i - c < i <= s.i and s.q - c < q <= s.q
    return s.D.get((i, q), math.inf) if inside else math.inf


def oltw_evaluate_line(s: OLTWState, I, T, c: int, column: bool) -> None:
    """Dixon's EvaluatePathCost over the band's new line: the new target column ``q``
    (``column``: cells ``(i', q)``, ``i' = i - c + 1 .. i``) or the new input row ``i``
    (cells ``(i, q')``, ``q' = q - c + 1 .. q``); indices below 0 are left out.

    ``D[i, q] = min(D[i-1, q] + d, D[i, q-1] + d, D[i-1, q-1] + 2 d)`` with ``d =
    geo_distance(I_i, T_q)`` (eq. 1): Dixon's step weights, the diagonal counted twice.

    Parameters
    ----------
    s : OLTWState
        Its corner already moved onto the new line; ``s.D`` is filled in.
    I, T : MotionFeatures
        Input and target; the line reads target frames up to ``s.q`` only.
    c : int
        Search width.
    column : bool

    Paper: Dixon 2005, Fig. 1 (EvaluatePathCost) and Section 2 (the step weights).
    """
    if column:
        lo = max(0, s.i - c + 1)
        cells = [(i, s.q) for i in range(lo, s.i + 1)]
        d = geo_distance(I.quats[lo : s.i + 1], T.quats[s.q])  # eq. 1, one cost per cell
    else:
        lo = max(0, s.q - c + 1)
        cells = [(s.i, q) for q in range(lo, s.q + 1)]
        d = geo_distance(I.quats[s.i], T.quats[lo : s.q + 1])
    for (i, q), d_iq in zip(cells, d):  # along the line: each cell after its predecessor
        s.D[i, q] = min(oltw_path_cost(s, i - 1, q, c) + d_iq,
                        oltw_path_cost(s, i, q - 1, c) + d_iq,
                        oltw_path_cost(s, i - 1, q - 1, c) + 2 * d_iq)  # fmt: skip


def oltw_get_inc(s: OLTWState, c: int, max_run_count: int = 3, warmup: bool = True,
                 normalize: bool = True):  # fmt: skip
    """Dixon's GetInc: which way to grow next.

    (1) ``"both"`` while the band is not yet full (Dixon's ``t < c``, his ``t`` counted
    from 1); (2) after more than ``max_run_count`` equal increments in a row, the other
    one; (3) else by the cell of lowest path cost in the newest target column and the
    newest input row (``D[i, q] / (1 + i + q)`` with ``normalize``: the cost per unit of
    path weight): the first of equal ones, the column first, each from its lowest index.

    Parameters
    ----------
    s : OLTWState
    c, max_run_count : int
        Search width and Dixon's MaxRunCount.
    warmup, normalize : bool
        Rule (1); the normalised costs of rule (3).

    Returns
    -------
    inc : str
        ``"target"`` (Dixon's Row: read the next target frame), ``"input"`` (Column: the
        next input frame) or ``"both"``.
    why : str
        The rule that decided: ``"warmup"``, ``"runcount"`` or ``"argmin"``.
    best : tuple of int or None
        The argmin cell ``(i*, q*)`` (rule 3 only).

    Paper: Dixon 2005, Fig. 1 (GetInc).
    """
    if warmup and s.q + 1 < c:  # if t < c return Both
        return "both", "warmup", None
    if s.run_count > max_run_count:  # if previous == Row return Column else return Row
        return ("input" if s.previous == "target" else "target"), "runcount", None
    cells = [(i, s.q) for i in range(max(0, s.i - c + 1), s.i + 1)]  # the newest column
    cells += [(s.i, q) for q in range(max(0, s.q - c + 1), s.q + 1)]  # the newest row
    cost = [s.D[i, q] / (1 + i + q) if normalize else s.D[i, q] for i, q in cells]
    # (x, y) := argmin pathCost; of equal costs the first cell of this list wins
    best = cells[cost.index(min(cost))]
    if best[1] < s.q:  # if x < t return Column: the newest input frame matches an earlier
        return "input", "argmin", best  # target frame (the input is behind)
    if best[0] < s.i:  # if y < j return Row: the newest target frame matches an earlier
        return "target", "argmin", best  # input frame (the input is ahead)
    return "both", "argmin", best  # the corner itself


def oltw_apply(s: OLTWState, I, T, inc: str, c: int) -> None:
    """The body of Dixon's loop for the increment ``inc``: a new target column (his Row),
    a new input row (his Column) or both, then the run count.

    Paper: Dixon 2005, Fig. 1 (the main loop).
    """
    if inc in ("target", "both"):  # if GetInc != Column: t := t + 1
        s.q += 1
        oltw_evaluate_line(s, I, T, c, column=True)
    if inc in ("input", "both"):  # if GetInc != Row: j := j + 1
        s.i += 1
        oltw_evaluate_line(s, I, T, c, column=False)
    s.run_count = s.run_count + 1 if inc == s.previous else 1
    if inc != "both":
        s.previous = inc


def oltw_step(s: OLTWState, I, T, q_new: int, c: int = 120, max_run_count: int = 3,
              warmup: bool = True, normalize: bool = True):  # fmt: skip
    """Target frame ``q_new`` has arrived: make the increment that waited for it, then grow
    along the input until GetInc asks for the next target frame.

    Dixon's loop calls GetInc three times per pass; here it is called once and its answer
    used three times. At the end of the input (``i = m``) an ``"input"`` or ``"both"``
    becomes ``"target"``: the map holds at ``I_m``.

    Parameters
    ----------
    s : OLTWState
        A new state for ``q_new = 0``; changed in place.
    I, T : MotionFeatures
        Input and target; the step reads target frames up to ``q_new`` only.
    q_new : int
        The target frame received (0, 1, 2, ... in turn).
    c, max_run_count, warmup, normalize
        As for :func:`oltw_get_inc`.

    Returns
    -------
    M_q : int
        The corner's input frame: the last point of the on-line path in target frame
        ``q_new``.
    decisions : list of tuple
        Every GetInc of the step, ``(q_new, i, q, inc, why, best)`` with the corner
        ``(i, q)`` when deciding.

    Paper: Dixon 2005, Fig. 1.
    """
    m = len(I.quats) - 1
    if q_new == 0:
        s.D[0, 0] = float(geo_distance(I.quats[0], T.quats[0]))  # EvaluatePathCost(1, 1)
    else:
        oltw_apply(s, I, T, s.pending, c)
    decisions = []
    while True:
        inc, why, best = oltw_get_inc(s, c, max_run_count, warmup, normalize)
        if s.i >= m and inc != "target":
            inc = "target"  # the end of the input: hold at I_m
        decisions.append((q_new, s.i, s.q, inc, why, best))
        if inc != "input":  # "target" or "both" waits for the next target frame
            s.pending = inc
            return s.i, decisions
        oltw_apply(s, I, T, inc, c)


def oltw(I, T, c: int = 120, max_run_count: int = 3, warmup: bool = True,
         normalize: bool = True):  # fmt: skip
    """Dixon's on-line time warping over a whole target, one :func:`oltw_step` per frame.

    Parameters
    ----------
    I, T : MotionFeatures
        Input (the recording) and target (the live motion).
    c : int
        Search width (the band), >= 2.
    max_run_count : int
        Dixon's MaxRunCount, >= 1.
    warmup : bool
        GetInc's start rule: ``"both"`` while ``q + 1 < c``.
    normalize : bool
        Compare path costs divided by the path weight ``1 + i + q``.

    Returns
    -------
    M : ndarray of int64, shape (T.n_frames,)
        ``M_q``: the corner's input frame after target frame ``q``.
    decisions : list of tuple
        Every GetInc, as :func:`oltw_step` lists them.

    Paper: FP-DTW reference 3 (Dixon, DAFx 2005, Fig. 1: the algorithm and GetInc).
    """
    s, M, decisions = OLTWState(), [], []
    for q in range(len(T.quats)):
        M_q, step_decisions = oltw_step(s, I, T, q, c, max_run_count, warmup, normalize)
        M.append(M_q)
        decisions += step_decisions
    return np.array(M, dtype=np.int64), decisions


# --- eqs. 2 and 3: similarity and deviation ---------------------------------------------


def joint_trajectories(Q, axis=(0.0, 1.0, 0.0)) -> np.ndarray:
    """A unit vector rotated by each joint's rotation: ``v + w t + u x t`` with
    ``t = 2 u x v`` for ``Q = (w, u)``.

    Parameters
    ----------
    Q : ndarray of float, shape (F, k, 4)
    axis : ndarray of float, shape (3,) or (k, 3)
        (0, 1, 0) by default; normalised.

    Returns
    -------
    X : ndarray of float64, shape (F, k, 3)

    Paper: FP-DTW eq. 2 ("a one unit length vector along the joint's orientation").
    """
    Q = np.asarray(Q, dtype=float)
    v = np.asarray(axis, dtype=float)
    v = np.broadcast_to(v / np.linalg.norm(v, axis=-1, keepdims=True), Q.shape[:-1] + (3,))
    t = 2.0 * np.cross(Q[..., 1:], v)
    return v + Q[..., :1] * t + np.cross(Q[..., 1:], t)


def kendall_tau_b(x, y) -> float:
    """Kendall's tau-b: ``sum sgn(x_a - x_b) sgn(y_a - y_b)`` over all pairs of frames,
    divided by ``sqrt(sum sgn(x_a - x_b)^2 sum sgn(y_a - y_b)^2)`` (ties corrected).

    Parameters
    ----------
    x, y : ndarray of float, shape (N,)

    Returns
    -------
    tau : float
        NaN when either is constant.

    Paper: FP-DTW eq. 2.
    """
    sx = np.sign(np.subtract.outer(x, x)).astype(np.int8)
    sy = np.sign(np.subtract.outer(y, y)).astype(np.int8)
    pairs_x, pairs_y = np.sum(sx * sx, dtype=np.int64), np.sum(sy * sy, dtype=np.int64)
    if pairs_x == 0 or pairs_y == 0:
        return math.nan
    return np.sum(sx * sy, dtype=np.int64) / math.sqrt(float(pairs_x) * float(pairs_y))


def kendall_tau_a(x, y) -> float:
    """Kendall's tau-a: ``sum_{a<b} sgn(x_a - x_b) sgn(y_a - y_b) / (N (N - 1) / 2)``.

    Parameters
    ----------
    x, y : ndarray of float, shape (N,)

    Returns
    -------
    tau : float
        NaN when ``N < 2``.

    Paper: FP-DTW eq. 2 (tau read without the ties correction).
    """
    N = len(x)
    if N < 2:
        return math.nan
    s = np.sign(np.subtract.outer(x, x)) * np.sign(np.subtract.outer(y, y))
    return float(np.sum(np.triu(s, 1)) / (N * (N - 1) / 2))


def similarity(
    I_quats, T_quats, M, flat: float = 0.001, *, tau="b", rule="zero", skip=0, axis=(0, 1, 0)
) -> float:
    """``r = (1 / 3k) sum_j sum_a tau(A_{j,a}, T_{j,a})`` for the input warped by the map,
    ``A_q = I_{M_q}``, over target frames ``q = skip..n``.

    An axis whose range is below ``flat`` in both motions scores 1 (the paper's rule). In
    only one of them: 0 (``rule="zero"``, tau is undefined there; our choice), left out of
    the mean (``"skip"``), or tau as computed (``"toolkit"``; 0 if undefined).

    Parameters
    ----------
    I_quats : ndarray of float, shape (m + 1, k, 4)
    T_quats : ndarray of float, shape (n + 1, k, 4)
    M : ndarray of int, shape (n + 1,)
    tau : {"b", "a"}
    rule : {"zero", "toolkit", "skip"}
        The ``flat=`` option of :func:`fpdtw.metrics.similarity`.
    skip : int
    axis : ndarray of float, shape (3,) or (k, 3), or a pair (input's, target's)

    Returns
    -------
    r : float

    Paper: FP-DTW eq. 2.
    Notebook: 06_fig5_fig6_scores.ipynb
    """
    ax_I, ax_T = axis if isinstance(axis, tuple) and len(axis) == 2 else (axis, axis)
    A = joint_trajectories(np.asarray(I_quats)[np.asarray(M)[skip:]], ax_I)
    X = joint_trajectories(np.asarray(T_quats)[skip:], ax_T)
    kendall = kendall_tau_a if tau == "a" else kendall_tau_b
    r = np.empty(A.shape[1:])
    for j in range(A.shape[1]):
        for a in range(3):
            x, y = A[:, j, a], X[:, j, a]
            flat_x, flat_y = np.ptp(x) < flat, np.ptp(y) < flat
            if flat_x and flat_y:
                r[j, a] = 1.0
            elif (flat_x or flat_y) and rule != "toolkit":
                r[j, a] = math.nan if rule == "skip" else 0.0
            else:
                t = kendall(x, y)
                r[j, a] = 0.0 if math.isnan(t) else t
    return float(np.nanmean(r)) if rule == "skip" else float(np.mean(r))


def deviation(P_a, P_b) -> float:
    """``D(P^a, P^b) = sum_{q=1..n} |P^a_q - P^b_q| / n``, in frames, as printed.

    Parameters
    ----------
    P_a, P_b : ndarray of int, shape (n + 1,)
        Maps of target frames ``q = 0..n``; frame 0 is not in the sum.

    Returns
    -------
    d : float

    Paper: FP-DTW eq. 3.
    Notebook: 06_fig5_fig6_scores.ipynb
    """
    P_a, P_b = np.asarray(P_a, np.int64), np.asarray(P_b, np.int64)
    n = len(P_a) - 1
    return float(sum(abs(P_a[q] - P_b[q]) for q in range(1, n + 1)) / n)


# --- the evaluation's intervals: medians of resampled pairs ------------------------------


def pair_weights(c, i_in, i_tg) -> np.ndarray:
    """How often each pair counts when its movement's motions were drawn ``c`` times.

    A pair (input ``a``, target ``b``) of two distinct motions counts ``c_a * c_b`` times in
    a resample in which motion ``a`` was drawn ``c_a`` times and ``b`` ``c_b`` times (pairs of
    a motion with itself do not exist).

    Parameters
    ----------
    c : ndarray of int, shape (k,)
        Draws of each motion of one movement.
    i_in, i_tg : ndarray of int, shape (P,)
        Each pair's input and target motion (indices into ``c``).

    Returns
    -------
    w : ndarray of int, shape (P,)
    """
    c = np.asarray(c)
    return c[np.asarray(i_in)] * c[np.asarray(i_tg)]


def weighted_median(values, weights) -> float:
    """The median of ``values`` with each value repeated ``weights`` times.

    Parameters
    ----------
    values : ndarray of float, shape (P,)
        One value per pair (a non-finite value counts as absent).
    weights : ndarray of int, shape (P,)
        How often each pair was drawn.

    Returns
    -------
    median : float
        ``np.median`` of the repeated values; NaN when no weight is left.
    """
    values, weights = np.asarray(values, dtype=float), np.asarray(weights)
    keep = np.isfinite(values) & (weights > 0)
    if not keep.any():
        return float("nan")
    return float(np.median(np.repeat(values[keep], weights[keep])))


# --- OPW: one step of the poster's Algorithm 1 ------------------------------------------


def interpolate_positions(P, fps: float, t: float, last: int | None = None) -> np.ndarray:
    """Positions at time ``t``: linear between the two frames around it, clamped to
    ``[0, last / fps]``.

    Parameters
    ----------
    P : ndarray of float, shape (F, p, 3)
        Frames ``0..F-1`` at ``fps``.
    fps, t : float
    last : int, optional
        Last usable frame (default ``F - 1``).

    Returns
    -------
    pos : ndarray of float64, shape (p, 3)

    Paper: OPW poster Section 3 (A and B between their samples).
    """
    eps = 1e-9
    last = P.shape[0] - 1 if last is None else last
    x = min(max(t * fps, 0.0), float(last))
    i0 = min(int(np.floor(x + eps)), last)
    a = x - i0
    if a <= eps or i0 >= last:
        return P[i0]
    return (1.0 - a) * P[i0] + a * P[i0 + 1]


def opw_step(
    f,
    t: float,
    A,
    B,
    omega: float,
    gamma: float,
    fps_A: float,
    fps_B: float,
    reference: str = "curve",
    direction: str = "code",
):
    """One OPW step at live time ``t``: forecast the live motion ``B`` one step ahead,
    compare it with the recording ``A`` at three nearby times (eq. 5), and slow ``A`` down
    (``s = 0``) or speed it up (``s = 2``) by moving the curve's last key (eq. 2).

    Parameters
    ----------
    f : WarpCurve
        The warp curve ``t' = f(t)`` so far (live time -> recording time); changed in place.
    t : float
        Live time of the step (s).
    A : ndarray of float, shape (F_A, p, 3)
        The recording's joint positions (the poster's Y).
    B : ndarray of float, shape (F_B, p, 3)
        The live motion's joint positions received so far (the poster's X).
    omega, gamma : float
        Sample period (s) and warp parameter.
    fps_A, fps_B : float
    reference : {"curve", "ratio"}
        Where ``A`` is read. ``"curve"`` (the poster, eq. 4): at ``t' + i omega``,
        ``t' = f(t)``. ``"ratio"`` (the authors' MotionBuilder plugin): at
        ``(t + i omega) r`` with the global ratio ``r = D_A / x_last`` (the recording's
        duration, which is the last key's value, over the last key's live time), not read
        through the curve.
    direction : {"code", "readme"}
        ``"code"`` (eq. 1's bullets and the plugin's code): ``s = 0`` slows ``A`` down
        (the last key moves later). ``"readme"`` (the plugin's readme): ``s = 0`` speeds
        it up, ``s = 2`` slows it down.

    Returns
    -------
    s : int
        0, 1 or 2 (eq. 1).
    p : list of float, length 3
        The costs ``p_0, p_1, p_2`` (the listing's ``p_1..p_3``).

    Paper: OPW poster Algorithm 1, eqs. 1, 2, 4, 5.
    Notebook: 13_opw_fig4.ipynb
    """
    sign = {"code": 1.0, "readme": -1.0}.get(direction)
    if sign is None:
        raise ValueError(f"direction must be 'code' or 'readme', got {direction!r}")
    t_w = f.value(t)  # t' = f(t) (lines 2-3: the sample times)
    x_t = interpolate_positions(B, fps_B, t)
    x_hat = x_t + (x_t - interpolate_positions(B, fps_B, t - omega))  # line 7: dead reckoning
    if reference == "curve":
        times = [t_w + i * omega for i in range(3)]  # line 8, eq. 4
    elif reference == "ratio":
        r = f.y[-1] / f.x[-1]  # the plugin: D_A / (live time of the last key)
        times = [(t + i * omega) * r for i in range(3)]
    else:
        raise ValueError(f"reference must be 'curve' or 'ratio', got {reference!r}")
    A_t = [interpolate_positions(A, fps_A, tau) for tau in times]
    p = [float(np.sqrt(((x_hat - a) ** 2).sum(axis=1)).sum()) for a in A_t]  # lines 9-10, eq. 5
    s = 1  # eq. 1: argmin p_i; ties keep the alignment
    if p[0] < p[1] and p[0] < p[2]:  # line 12 (the listing writes ">": inverted)
        s = 0
    elif p[2] < p[1] and p[2] < p[0]:  # line 15 (inverted likewise)
        s = 2
    if s != 1:
        x_k = f.x[-1]  # the last key's live time
        f.add_key(t, t_w)  # lines 13 / 16: pin a key at the current time
        f.move_key(-1, x=x_k - (x_k - t) * gamma * (s - 1) * sign)  # lines 14 / 17, as eq. 2
    return s, p


__all__ = [
    "TYPE_V_START",
    "TYPE_V_TABLE",
    "OLTWState",
    "Step",
    "accumulate",
    "allowed_rows",
    "BAND_SECONDS",
    "band_cells",
    "band_half_width",
    "band_rows",
    "band_window",
    "backtrack",
    "checked_choice",
    "cost_matrix",
    "deviation",
    "euler_to_quat",
    "forecast_joints",
    "forward_kinematics",
    "geo_distance",
    "interpolate_positions",
    "joint_trajectories",
    "kendall_tau_b",
    "method_a_step",
    "method_b_step",
    "method_c_step",
    "oe_dtw_end_points",
    "oltw",
    "oltw_apply",
    "oltw_evaluate_line",
    "oltw_get_inc",
    "oltw_path_cost",
    "oltw_step",
    "opw_step",
    "pair_weights",
    "path_to_map",
    "quat_multiply",
    "reverse_accumulate",
    "run",
    "similarity",
    "type_v_allowed",
    "type_v_next",
    "weighted_median",
]
