"""The papers' equations and algorithms in plain NumPy, line by line in their notation.

What to read beside the papers, and what the notebooks step through on real motions: no
numba, one function per equation or algorithm. The fast kernels name their plain version
("Plain version: fpdtw.plain.xxx"), and ``tests/test_plain.py`` holds the two equal. What
neither paper describes (OLTW, the global band, Method C's other window readings, ...) is
compiled only.

Notation (FP-DTW paper, Section 3): the input ``I = {I_0..I_m}`` (the recording, fully
known), the target ``T = {T_0..T_n}`` (the live motion, received so far), the incoming
frame ``T_{n+1}``, the map so far ``M = {M_0..M_n}`` (``M_q``: the input frame of target
frame ``q``), the window ``w``, the input window ``{I_{M_n}..I_{M_n+w_i}}`` (``w_i`` as
the listings set it in their lines "w_i = w" and "w_i = m - M_n"), the target window
``F``, the cost matrix ``C`` (row ``r``: input frame ``I_{M_n+r}``; column ``c``:
``F_c``), the accumulated cost ``D`` and the path ``P``. A frame is an array of ``k``
unit quaternions ``(w, x, y, z)``, one per joint: shape ``(k, 4)``. The ``line N``
comments number the statements of the paper's listings from their first ``if`` (the
declarations above it are not numbered).
"""

from __future__ import annotations

import dataclasses
import math
from typing import NamedTuple

import numpy as np

from fpdtw.errors import AlignmentError
from fpdtw.motion.rig import cost_input

# --- eq. 1: the geodesic distance of two poses -----------------------------------------


def geo_distance(Q_a, Q_b, weights=None):
    """Geodesic distance between poses: ``d = sum_j (2/pi) arccos |Q_j^a . Q_j^b|``.

    Parameters
    ----------
    Q_a, Q_b : ndarray of float, shape (..., k, 4)
        Unit quaternions of the ``k`` joints (leading axes broadcast).
    weights : ndarray of float, shape (k,), optional
        ``w_j`` multiplying each joint's term (beyond the papers,
        :func:`fpdtw.weights.joint_weights`); None: eq. 1 as written.

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

    Each step goes to the lowest of ``D[i-1, j-1]``, ``D[i, j-1]`` and ``D[i-1, j]``, each
    plus ``C[i, j]`` when ``C`` is given (dtw-python's rule); on equal values the
    diagonal, then ``(i, j-1)``. On row 0 only ``(i, j-1)``, on column 0 only ``(i-1, j)``.

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


def relocate_step(q, Iq, G, lam: float):
    """One target frame of the relocating search (beyond the papers, Q7):
    ``G_n[j] = c(T_n, I_j) + lam min(G_{n-1}[j], G_{n-1}[j-1], G_{n-1}[j-2])``.

    Parameters
    ----------
    q : ndarray of float, shape (k, 4)
        The target frame's rotations.
    Iq : ndarray of float, shape (N, k, 4)
        The input's.
    G : ndarray of float, shape (N,)
        The previous row (zeros before the first frame).
    lam : float
        The forgetting factor.

    Returns
    -------
    G : ndarray of float64, shape (N,)
        The new row.
    j : int
        ``argmin G`` (the first of equal ones).

    Paper: neither (:mod:`fpdtw.online.relocate`); eq. 1 of FP-DTW.
    """
    c = geo_distance(np.asarray(q, dtype=float)[None], np.asarray(Iq, dtype=float))
    G = np.asarray(G, dtype=float)
    prev = np.minimum(G, np.r_[np.inf, G[:-1]])
    prev = np.minimum(prev, np.r_[np.inf, np.inf, G[:-2]])[: G.size]
    G = c + lam * prev
    return G, int(np.argmin(G))


def oe_dtw_end_points(C) -> np.ndarray:
    """Open-end DTW's end point after each target frame: ``e_q = argmin_i D[i, q]``.

    Column ``q`` of ``D`` depends only on target frames ``0..q``: one accumulation for all.

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


def reverse_accumulate(C) -> np.ndarray:
    """Method C's accumulation in reverse, from the far corner back to (0, 0):
    ``D[i, j] = C[i, j] + min(D[i+1, j+1], D[i+1, j], D[i, j+1])``.

    Parameters
    ----------
    C : ndarray of float, shape (rows, cols)

    Returns
    -------
    D : ndarray of float64, shape (rows, cols)
        ``D[rows-1, cols-1] = C[rows-1, cols-1]``: every path ends in the far corner.

    Paper: FP-DTW Algorithm 3, line 12 (getReverseTotalCostMatrix).
    Notebook: 03_fig2_fig4_windows.ipynb
    """
    C = np.asarray(C, dtype=float)
    D = np.empty_like(C)
    last_i, last_j = C.shape[0] - 1, C.shape[1] - 1
    for i in range(last_i, -1, -1):
        for j in range(last_j, -1, -1):
            c = C[i, j]
            if i == last_i and j == last_j:
                D[i, j] = c
            elif i == last_i:
                D[i, j] = c + D[i, j + 1]
            elif j == last_j:
                D[i, j] = c + D[i + 1, j]
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
    """Global joint positions of one frame from its local rotations, from the root: ``R_j =
    pre_j Q_j post_j``; a root is at ``p_j = o_j + root``, turned by ``G_j = R_j``; another
    joint at ``p_j = p_a + G_a o_j G_a^*``, turned by ``G_j = G_a R_j`` (``a``: its parent).

    Parameters
    ----------
    Q : ndarray of float, shape (J, 4)
        Local rotations of the joints, unit quaternions ``(w, x, y, z)``.
    pre, post : ndarray of float, shape (J, 4)
        Pre- and post-rotations (FBX; the identity for BVH and ASF/AMC).
    offsets : ndarray of float, shape (J, 3)
        Offsets ``o_j`` from the parent (a root's from the origin).
    parents : ndarray of int, shape (J,)
        Each joint's parent, an earlier joint; -1 for a root.
    root : ndarray of float, shape (3,)

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
        t = 2.0 * np.cross(u, offsets[j])  # G_a o G_a^* = o + w t + u x t, t = 2 u x o
        P[j] = P[a] + (offsets[j] + w * t + np.cross(u, t))
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
    advances never are): ndarray of bool, shape (4,).

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


def allowed_rows(allowed, rows: int) -> np.ndarray:
    """Which rows (offsets from ``M_n``) of a window a Type V state allows: bool, shape
    (rows,); ``allowed`` is :func:`type_v_allowed` of the state, None for every row."""
    ok = np.ones(rows, dtype=bool)
    if allowed is not None:
        ok[:] = False
        ok[: min(4, rows)] = np.asarray(allowed, dtype=bool)[: min(4, rows)]
    return ok


def checked_choice(ok, r: int) -> int:
    """Offset ``r`` if the constraint allows it; AlignmentError if not (every row of the
    window is masked: e.g. a one-row window after two holds)."""
    if not ok[r]:
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
        The window's last row is ``I_{M_n + w_i}``; 0 without a window (Algorithm 3:
        ``rows - 1``, see :func:`method_c_step`).
    C, D : ndarray of float64, shape (w_i + 1, columns), or None
        Cost (Type V's masked rows +inf in the choosing column) and accumulated cost.
    path : ndarray of int64, shape (L, 2), or None
        B: the back-tracked path.
    P : ndarray of int64, shape (columns,), or None
        B: the lowest row of the path in each column (``P[1]`` is the choice).
    score : ndarray of float64, shape (w_i + 1,), or None
        C: ``D[:, 0]``, what the argmin compares.
    M_n, q : int or None
        A window step's first input frame and the target frame it maps, ``n + 1``.
    """

    M: int
    kind: str
    w_i: int = 0
    C: np.ndarray | None = None
    D: np.ndarray | None = None
    path: np.ndarray | None = None
    P: np.ndarray | None = None
    score: np.ndarray | None = None
    M_n: int | None = None
    q: int | None = None


def method_a_step(I, T, M, w: int = 2, allowed=None) -> Step:
    """Method A, frame matching: ``T_{n+1}`` goes to the closest input frame in
    ``{I_{M_n}..I_{M_n+w}}``; ``n = len(M) - 1``.

    Parameters
    ----------
    I, T : MotionFeatures
        Input and target (the step reads ``T.quats[n + 1]`` only).
    M : sequence of int, length n + 1
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
    # Type V (Section 6): a row the state does not allow is never chosen (no accumulation)
    r = checked_choice(ok, int(np.argmin(np.where(ok, C, np.inf))))
    return Step(M_n + r, "window", w_i, C[:, None], M_n=M_n, q=n + 1)  # line 10


def method_b_step(I, T, M, w: int, allowed=None) -> Step:
    """Method B: a DTW path through a forecast window; ``n = len(M) - 1``.

    Parameters
    ----------
    I, T, M, allowed
        As for :func:`method_a_step` (the step reads ``T_n`` and ``T_{n+1}``).
    w : int
        Forecast window (the paper: 10, 20, 40, 80).

    Returns
    -------
    Step
        ``C, D`` of ``w_i + 1`` rows by ``w + 1`` columns ``[T_n, T_{n+1}, forecasts]``,
        the path and ``P``; ``M_{n+1} = M_n + P_1``.

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
    E = forecast_joints(T.euler[n], T.euler[n + 1], w)  # T_{n+1} + i delta, i = 0..w-1
    F = np.concatenate([T.quats[n : n + 2], euler_to_quat(E[1:], T.orders)])  # lines 10-11
    C = cost_matrix(I.quats[M_n : M_n + w_i + 1], F)  # line 12
    ok = allowed_rows(allowed, len(C))
    # Type V mask rule (Section 6): C[r, 1] = +inf for every row r the state does not
    # allow, BEFORE accumulating: it changes D and the path (hence P_1), not only its check.
    C[~ok, 1] = np.inf
    D = accumulate(C)  # line 13
    D[0, 0] = 10000.0  # line 14: the path must leave (0, 0) through (1, 0) or (0, 1)
    path = backtrack(D)  # line 15
    P = path_to_map(path, w)  # the overwrite rule: the lowest row of each column
    r = checked_choice(ok, int(P[1]))
    return Step(M_n + r, "window", w_i, C, D, path, P, M_n=M_n, q=n + 1)  # line 16


def method_c_step(I, T, M, w: int, allowed=None) -> Step:
    """Method C: the reverse-accumulated forecast window; ``n = len(M) - 1``.

    Reading: the window is the size Algorithm 3 declares, ``C, D`` of ``w_i x w`` after
    line 6's ``w_i = w`` (the default, :data:`fpdtw.registry.C_READINGS` ``[0]``,
    ``"square"``): of line 11's ``w_i + 1`` frames ``{I_{M_n}..I_{M_n+w_i}}`` it keeps the
    first ``w``. The other readings are :class:`fpdtw.online.MethodC`'s ``window=`` option.

    Parameters
    ----------
    I, T, M, w, allowed
        As for :func:`method_b_step`.

    Returns
    -------
    Step
        ``C, D`` of ``rows`` rows by ``w`` columns ``[T_{n+1}, forecasts]`` and ``score =
        D[:, 0]``; ``M_{n+1} = M_n + argmin`` (lowest row on ties); ``w_i = rows - 1``.

    Paper: FP-DTW Algorithm 3.
    Notebook: 03_fig2_fig4_windows.ipynb
    """
    s = 2
    n, m = len(M) - 1, len(I.quats) - 1
    M_n = int(M[n])
    if n < s:  # line 1
        return Step(min(n + 1, m), "warmup")  # line 2
    # line 3 is printed "M_n > m"; we test M_n >= m. Without Type V they agree: M_n never
    # exceeds m, and at M_n = m lines 6-13 see I_m alone and pick M_n = m, as line 4.
    # Under Type V they differ in state "N" (no hold allowed): as printed, that one row
    # is masked and the step has no candidate (AlignmentError); here it holds at I_m.
    if M_n >= m:
        return Step(m, "end")  # line 4
    w_i = w  # line 6, as printed
    if M_n + w_i > m:  # line 7
        w_i = m - M_n  # line 8
    # the declared size w_i x w: at most w rows of line 11's range I_{M_n}..I_{M_n+w_i}
    # (w rows in the middle of the input; all w_i + 1 where line 8 clipped the range)
    rows = min(w_i + 1, w)
    E = forecast_joints(T.euler[n], T.euler[n + 1], w)
    F = np.concatenate([T.quats[n + 1 : n + 2], euler_to_quat(E[1:], T.orders)])  # line 10
    C = cost_matrix(I.quats[M_n : M_n + rows], F)  # line 11
    ok = allowed_rows(allowed, rows)
    # Type V mask rule (Section 6): C[r, 0] = +inf for every row r the state does not
    # allow, BEFORE accumulating: an allowed row's D[r, 0] may no longer reach the far
    # corner through a masked (r + 1, 0) (notebook 15 counts the maps this changes).
    C[~ok, 0] = np.inf
    D = reverse_accumulate(C)  # line 12
    score = D[:, 0].copy()
    r = checked_choice(ok, int(np.argmin(np.where(ok, score, np.inf))))
    return Step(M_n + r, "window", rows - 1, C, D, score=score, M_n=M_n, q=n + 1)  # line 13


def run(step, I, T, w: int, type_v: bool = False, steps: list | None = None) -> np.ndarray:
    """A whole target through one method, a step per target frame, from ``M_0 = 0``.

    Parameters
    ----------
    step : callable
        :func:`method_a_step`, :func:`method_b_step` or :func:`method_c_step`.
    I, T : MotionFeatures
    w : int
    type_v : bool
        The Type V constraint, its state carried from step to step (a step the table does
        not allow, as a hold forced at the end of the input, leaves it as it is).
    steps : list, optional
        Each step's :class:`Step` is appended to it (``steps[q - 1]`` maps frame ``q``).

    Returns
    -------
    M : ndarray of int64, shape (T.n_frames,)

    Paper: FP-DTW Sections 3 and 6.
    Notebook: 11_fig9_typev.ipynb
    """
    # two rigs: eq. 1 compares the input expressed in the target's rig (fpdtw.motion.rig)
    I = dataclasses.replace(I, quats=cost_input(I.quats, I.rig, T.rig))
    M, state = [0], TYPE_V_START
    for _ in range(len(T.quats) - 1):
        allowed = type_v_allowed(state) if type_v else None
        st = step(I, T, M, w, allowed)
        M.append(st.M)
        if steps is not None:
            steps.append(st)
        state = type_v_next(state, M[-1] - M[-2]) or state
    return np.array(M, dtype=np.int64)


# --- eqs. 2 and 3: similarity and deviation ---------------------------------------------


def joint_trajectories(Q, axis="y") -> np.ndarray:
    """A unit vector rotated by each joint's rotation: ``v + w t + u x t`` with
    ``t = 2 u x v`` for ``Q = (w, u)``.

    Parameters
    ----------
    Q : ndarray of float, shape (F, k, 4)
    axis : "y" or ndarray of float, shape (3,) or (k, 3)
        ``"y"``: (0, 1, 0) for every joint; or each joint's own vector, normalised.

    Returns
    -------
    X : ndarray of float64, shape (F, k, 3)

    Paper: FP-DTW eq. 2 ("a one unit length vector along the joint's orientation").
    """
    Q = np.asarray(Q, dtype=float)
    v = np.array([0.0, 1.0, 0.0]) if isinstance(axis, str) and axis == "y" else axis
    v = np.asarray(v, dtype=float)
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

    Paper: FP-DTW eq. 2 (r^t, "the Kendall Tau rank correlation coefficient").
    """
    sx = np.sign(np.subtract.outer(x, x)).astype(np.int8)
    sy = np.sign(np.subtract.outer(y, y)).astype(np.int8)
    pairs_x, pairs_y = np.sum(sx * sx, dtype=np.int64), np.sum(sy * sy, dtype=np.int64)
    if pairs_x == 0 or pairs_y == 0:
        return math.nan
    return np.sum(sx * sy, dtype=np.int64) / math.sqrt(float(pairs_x) * float(pairs_y))


#: Section 5: "if both joint axes have a range less than 0.001 ..."
FLAT_RANGE = 0.001


def similarity(I_quats, T_quats, M, *, flat: str = "zero", skip: int = 0, axis="y") -> float:
    """``r = (1 / 3k) sum_j sum_a tau(A_{j,a}, T_{j,a})`` for the input warped by the map,
    ``A_q = I_{M_q}``, over target frames ``q = skip..n``.

    An axis whose range is below :data:`FLAT_RANGE` in both motions scores 1 (the paper's
    rule). In only one of them (reading): 0 (``flat="zero"``: tau is undefined there),
    left out of the mean (``"skip"``), or tau as computed (``"toolkit"``; 0 if undefined).

    Parameters
    ----------
    I_quats : ndarray of float, shape (m + 1, k, 4)
    T_quats : ndarray of float, shape (n + 1, k, 4)
    M : ndarray of int, shape (n + 1,)
    flat : {"zero", "toolkit", "skip"}
    skip : int
        Target frames left out at the start.
    axis : "y" or ndarray of float, shape (3,) or (k, 3), or a pair (input's, target's)
        As :func:`joint_trajectories`.

    Returns
    -------
    r : float

    Paper: FP-DTW eq. 2.
    Notebook: 06_fig5_fig6_scores.ipynb
    """
    ax_I, ax_T = axis if isinstance(axis, tuple) and len(axis) == 2 else (axis, axis)
    A = joint_trajectories(np.asarray(I_quats)[np.asarray(M)[skip:]], ax_I)
    X = joint_trajectories(np.asarray(T_quats)[skip:], ax_T)
    r = np.empty(A.shape[1:])
    for j in range(A.shape[1]):
        for a in range(3):
            x, y = A[:, j, a], X[:, j, a]
            flat_x, flat_y = np.ptp(x) < FLAT_RANGE, np.ptp(y) < FLAT_RANGE
            if flat_x and flat_y:
                r[j, a] = 1.0
            elif (flat_x or flat_y) and flat != "toolkit":
                r[j, a] = math.nan if flat == "skip" else 0.0
            else:
                t = kendall_tau_b(x, y)
                r[j, a] = 0.0 if math.isnan(t) else t
    return float(np.nanmean(r)) if flat == "skip" else float(np.mean(r))


def deviation(P_a, P_b, frames: str = "printed") -> float:
    """``D(P^a, P^b) = sum_{q=1..n} |P^a_q - P^b_q| / n``, in frames, as printed.

    Parameters
    ----------
    P_a, P_b : ndarray of int, shape (n + 1,)
        Maps of target frames ``q = 0..n``.
    frames : {"printed", "all"}
        ``"printed"``: eq. 3 as printed; ``"all"`` (reading): ``q = 0..n``, over ``n + 1``.

    Returns
    -------
    d : float

    Paper: FP-DTW eq. 3.
    Notebook: 06_fig5_fig6_scores.ipynb
    """
    P_a, P_b = np.asarray(P_a, np.int64), np.asarray(P_b, np.int64)
    n = len(P_a) - 1
    if frames == "all":
        return float(sum(abs(P_a[q] - P_b[q]) for q in range(0, n + 1)) / (n + 1))
    if frames != "printed":
        raise ValueError(f"frames must be 'printed' or 'all', got {frames!r}")
    return float(sum(abs(P_a[q] - P_b[q]) for q in range(1, n + 1)) / n)


# --- OPW: one step of the poster's Algorithm 1 ------------------------------------------


def interpolate_positions(P, fps: float, t: float, last: int | None = None) -> np.ndarray:
    """Positions (p, 3) at time ``t`` of frames ``P`` (F, p, 3) at ``fps``: linear between
    the two frames around it, clamped to ``[0, last / fps]`` (``last``: default ``F - 1``).

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


#: OPW's two readings of where the recording is read (:func:`opw_step`'s ``read_at``).
OPW_READ_AT = ("eq4", "listing")


def opw_times(f, t: float, omega: float, read_at: str = "eq4") -> list:
    """The recording times ``A`` is compared at in the step at live time ``t``.

    ``"eq4"`` (the poster's eq. 4 and the sentence above it, "values y_{t'+i omega}"):
    ``f(t) + i omega``, the recording read at its own rate from the warped time.
    ``"listing"`` (Algorithm 1, lines 2-3 and 8: the sample times ``{t - omega, t, t +
    omega, t + 2 omega}``, then "unwarp sample times" through ``f``): ``f(t + i omega)``.
    The two agree where ``f`` has slope 1 between ``t`` and ``t + 2 omega`` and differ
    elsewhere (``f(t + omega) - f(t)`` is about ``f'(t) omega``).

    Parameters
    ----------
    f : WarpCurve
        ``t' = f(t)``.
    t, omega : float
    read_at : {"eq4", "listing"}

    Returns
    -------
    times : list of float, length 3
        For ``i = 0, 1, 2``.

    Paper: OPW poster eq. 4; Algorithm 1, lines 2-3 and 8.
    """
    if read_at == "eq4":
        t_w = f.value(t)
        return [t_w + i * omega for i in range(3)]
    if read_at == "listing":
        return [f.value(t + i * omega) for i in range(3)]
    raise ValueError(f"read_at must be one of {OPW_READ_AT}, got {read_at!r}")


def opw_step(f, t: float, A, B, omega: float, gamma: float, fps_A: float, fps_B: float,
             read_at: str = "eq4"):  # fmt: skip
    """One OPW step at live time ``t``: forecast the live motion ``B`` one step ahead,
    compare it with the recording ``A`` at three nearby times (eq. 5), and slow ``A`` down
    (``s = 0``) or speed it up (``s = 2``) by moving the curve's last key (eq. 2).

    Parameters
    ----------
    f : WarpCurve
        The warp curve ``t' = f(t)`` so far (live -> recording time); changed in place.
    t : float
        Live time of the step (s).
    A, B : ndarray of float, shapes (F_A, p, 3), (F_B, p, 3)
        Joint positions of the recording (the poster's Y) and of the live motion so far (X).
    omega, gamma : float
        Sample period (s) and warp parameter.
    fps_A, fps_B : float
    read_at : {"eq4", "listing"}
        The reading of where ``A`` is read (:func:`opw_times`).

    Returns
    -------
    s : int
        0, 1 or 2 (eq. 1).
    p : list of float, length 3
        The costs ``p_0, p_1, p_2`` (the listing's ``p_1..p_3``).

    Paper: OPW poster Algorithm 1, eqs. 1, 2, 4, 5.
    Notebook: 13_opw_fig4.ipynb
    """
    t_w = f.value(t)  # t' = f(t), where the key is pinned
    times = opw_times(f, t, omega, read_at)  # lines 2-3 and 8 (listing) or eq. 4
    x_t = interpolate_positions(B, fps_B, t)  # line 6: the current sample of X
    x_hat = x_t + (x_t - interpolate_positions(B, fps_B, t - omega))  # line 7: dead reckoning
    A_t = [interpolate_positions(A, fps_A, tau) for tau in times]  # line 8
    p = [float(np.sqrt(((x_hat - a) ** 2).sum(axis=1)).sum()) for a in A_t]  # lines 9-10, eq. 5
    s = 1  # eq. 1: argmin p_i; ties keep the alignment
    if p[0] < p[1] and p[0] < p[2]:  # line 12 (the listing writes ">": inverted)
        s = 0
    elif p[2] < p[1] and p[2] < p[0]:  # line 15 (inverted likewise)
        s = 2
    if s != 1:
        x_k = f.x[-1]  # the last key's live time
        f.add_key(t, t_w)  # lines 13 / 16: pin a key at the current time
        f.move_key(-1, x=x_k - (x_k - t) * gamma * (s - 1))  # lines 14 / 17, as eq. 2
    return s, p


__all__ = ["FLAT_RANGE", "OPW_READ_AT", "TYPE_V_START", "TYPE_V_TABLE", "Step",
           "accumulate", "allowed_rows", "backtrack", "checked_choice", "cost_matrix",
           "deviation", "euler_to_quat", "forecast_joints", "forward_kinematics",
           "geo_distance", "interpolate_positions", "joint_trajectories",
           "kendall_tau_b", "method_a_step", "method_b_step", "method_c_step",
           "oe_dtw_end_points", "opw_step", "opw_times", "path_to_map", "quat_multiply",
           "relocate_step",
           "reverse_accumulate", "run", "similarity", "type_v_allowed", "type_v_next"]  # fmt: skip
