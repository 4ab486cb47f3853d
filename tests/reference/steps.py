"""Plain-numpy reference steps of Methods A, B and C, for the tests only.

Each reference step recomputes one step of a window method from scratch with numpy and
scipy (no numba, no shared buffers): the forecast with :func:`fpdtw.motion.rotations.euler_to_quat`,
the cost window with :func:`fpdtw.costs.geodesic_cost_matrix_numpy`, the accumulation and
the choice in plain Python loops. :func:`reference_run` runs one over a whole target; the
tests compare it with the fast aligners step by step.
"""

from __future__ import annotations

import inspect

import numpy as np

from fpdtw.costs import geodesic_cost_matrix_numpy
from fpdtw.forecast import forecast_joints
from fpdtw.motion.features import MotionFeatures
from fpdtw.motion.rotations import euler_to_quat
from fpdtw.online.method_b import MethodB
from fpdtw.online.method_c import MethodC
from fpdtw.online.window import B_CORNER, WindowAligner, WindowSnapshot


def reference_prologue(I, T_quats, M, w, s):
    """The branches Methods B and C share before their window (plain Python, for tests).

    Returns either a finished :class:`WindowSnapshot` (first frame, warm-up
    ``n < s``, input exhausted) or the tuple ``(q, n, M_n, w_i)`` of a window step.

    Paper: FP-DTW Algorithms 2 and 3 (first lines).
    """
    q = len(T_quats) - 1
    if q == 0:
        return WindowSnapshot(0, "first", -1, 0, 0, 0)
    m = I.n_frames - 1
    n = q - 1
    Mn = int(M[n])
    if n < s:
        return WindowSnapshot(q, "warmup", Mn, 0, min(n + 1, m) - Mn, min(n + 1, m))
    if Mn >= m:
        return WindowSnapshot(q, "end", Mn, 0, m - Mn, m)
    return q, n, Mn, min(w, m - Mn)


def reference_forecast_quats(T_euler, orders, w: int) -> np.ndarray:
    """Plain-numpy forecast quaternions of frames ``T_{n+1} + i delta``, ``i = 1..w-1``.

    Parameters
    ----------
    T_euler : ndarray of float, shape (q + 1, k, 3)
        Target Euler angles received so far (the last two are used).
    orders : sequence of str, length k
    w : int

    Returns
    -------
    Q : ndarray of float64, shape (w - 1, k, 4)
        Converted with :func:`fpdtw.motion.rotations.euler_to_quat` (scipy), independent of the
        numba conversion.
    """
    E = forecast_joints(T_euler[-2], T_euler[-1], w)[1:]
    k = E.shape[1]
    Q = np.empty((E.shape[0], k, 4))
    for j in range(k):
        Q[:, j] = euler_to_quat(E[:, j], orders[j])
    return Q


def reference_cost(I_quats, start, w_i, W) -> np.ndarray:
    """Reference cost window: :func:`fpdtw.costs.geodesic_cost_matrix_numpy`."""
    return geodesic_cost_matrix_numpy(I_quats[start : start + w_i + 1], W)


def reference_mask(allowed, n_rows) -> np.ndarray:
    """Bool (n_rows,): rows (offsets) allowed; None = unconstrained."""
    ok = np.ones(n_rows, dtype=bool)
    if allowed is not None:
        ok[:] = False
        ok[: min(4, n_rows)] = np.asarray(allowed, dtype=bool)[: min(4, n_rows)]
    return ok


def reference_run(aligner: WindowAligner, T: MotionFeatures):
    """Run the plain-numpy reference of ``aligner``'s method over a whole target.

    Uses the reference step of the aligner's method (:data:`REFERENCE_STEPS`) with the
    aligner's input, window, constraint and the options the reference takes (Method C:
    ``window``, ``ties``); tracks the Type V state with the pure-Python state table.

    Returns
    -------
    M : ndarray of int64, shape (n,)
    snaps : list of WindowSnapshot
        One per target frame.
    """
    step = REFERENCE_STEPS[type(aligner).__name__]
    accepted = inspect.signature(step).parameters
    options = {k: v for k, v in aligner.settings.items() if k in accepted}
    tv = aligner.constraint
    state = None if tv is None else tv.start
    M = np.empty(T.n_frames, dtype=np.int64)
    snaps = []
    for q in range(T.n_frames):
        allowed = None if tv is None else tv.allowed(state)
        snap = step(
            aligner.I, T.quats[: q + 1], T.euler[: q + 1], M[:q], aligner.w, allowed, **options
        )
        M[q] = snap.M
        if tv is not None:
            snap.allowed = allowed
            snap.state = tv.states[state]
            if q > 0:
                nxt = tv.next_state(state, int(M[q] - M[q - 1]))
                state = nxt if nxt >= 0 else state
        snaps.append(snap)
    return M, snaps


def reference_step_a(I, T_quats, T_euler, M, w=2, allowed=None) -> WindowSnapshot:
    """Plain-numpy reference of one Method A step (for tests).

    Parameters
    ----------
    I : MotionFeatures
        Input motion.
    T_quats : ndarray of float, shape (q + 1, k, 4)
        Target frames received so far (``T_{n+1}`` last).
    T_euler : ndarray of float, shape (q + 1, k, 3)
        The target's unwrapped Euler angles: unused by Method A (it does not forecast),
        kept for a signature shared with the steps of B and C.
    M : ndarray of int, shape (q,)
        Map so far.
    w : int
    allowed : ndarray of bool, shape (4,), or None
        Type V: offsets 0..3 allowed (larger offsets never are); None: unconstrained.

    Returns
    -------
    snap : WindowSnapshot

    Paper: FP-DTW Algorithm 1.
    """
    q = len(T_quats) - 1
    if q == 0:
        return WindowSnapshot(0, "first", -1, 0, 0, 0)
    m = I.n_frames - 1
    Mn = int(M[q - 1])
    w_i = w
    if Mn + w_i > m:
        w_i = m - Mn
    if w_i == 0:
        return WindowSnapshot(q, "end", Mn, 0, 0, Mn)
    C = geodesic_cost_matrix_numpy(I.quats[Mn : Mn + w_i + 1], T_quats[q : q + 1])
    ok = reference_mask(allowed, w_i + 1)
    cand = np.where(ok, C[:, 0], np.inf)
    off = int(np.argmin(cand))  # first minimum: the lowest offset
    return WindowSnapshot(q, "window", Mn, w_i, off, Mn + off, C=C)


def backtrack_lowest(D) -> tuple:
    """Plain-Python back-track of Method B with the paper's overwrite rule.

    Parameters
    ----------
    D : ndarray of float, shape (r, c)
        Accumulated cost (with ``D[0, 0]`` already set to 10000).

    Returns
    -------
    path : ndarray of int64, shape (L, 2)
        Cells from (0, 0) to (r - 1, c - 1).
    P : ndarray of int64, shape (c,)
        Lowest row of the path in each column.

    Paper: FP-DTW Section 3.2 (plotPath), Fig. 4.
    """
    i, j = D.shape[0] - 1, D.shape[1] - 1
    cells = [(i, j)]
    P = np.full(D.shape[1], -1, dtype=np.int64)
    P[j] = i
    while (i, j) != (0, 0):
        if i == 0:
            j -= 1
        elif j == 0:
            i -= 1
        else:
            options = [(D[i - 1, j - 1], 0), (D[i, j - 1], 1), (D[i - 1, j], 2)]
            best = min(options)[1]  # equal costs: the earlier option (diagonal first)
            i, j = [(i - 1, j - 1), (i, j - 1), (i - 1, j)][best]
        P[j] = i  # same column: overwrite with the lower row
        cells.append((i, j))
    return np.array(cells[::-1], dtype=np.int64), P


def reference_step_b(I, T_quats, T_euler, M, w, allowed=None) -> WindowSnapshot:
    """Plain-numpy reference of one Method B step (for tests).

    The arguments are those of :func:`reference_step_a` (here ``T_euler``, the target's
    unwrapped Euler angles, feeds the forecast). Returns a :class:`WindowSnapshot`.

    Paper: FP-DTW Algorithm 2.
    """
    head = reference_prologue(I, T_quats, M, w, MethodB.s)
    if isinstance(head, WindowSnapshot):
        return head
    q, n, Mn, w_i = head
    F = np.concatenate(
        [T_quats[n : n + 2], reference_forecast_quats(T_euler[n : n + 2], I.orders, w)]
    )
    C = geodesic_cost_matrix_numpy(I.quats[Mn : Mn + w_i + 1], F)
    C[~reference_mask(allowed, w_i + 1), 1] = np.inf
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
    D[0, 0] = B_CORNER
    path, P = backtrack_lowest(D)
    off = int(P[1])
    return WindowSnapshot(q, "window", Mn, w_i, off, Mn + off, C=C, D=D, path=path, P=P)


def reference_step_c(
    I, T_quats, T_euler, M, w, allowed=None, window="square", ties="low"
) -> WindowSnapshot:
    """Plain-numpy reference of one Method C step (for tests).

    The arguments are those of :func:`reference_step_b`, and two more: ``window``, the
    reading of Algorithm 3 (see :class:`MethodC`), and ``ties`` (``"low"`` or ``"high"``),
    which of equal window scores wins. Returns a :class:`WindowSnapshot`.

    Paper: FP-DTW Algorithm 3.
    """
    head = reference_prologue(I, T_quats, M, w, MethodC.s)
    if isinstance(head, WindowSnapshot):
        return head
    q, n, Mn, w_i = head
    m = I.n_frames - 1
    rows = min(w, m - Mn + 1) if window == "square" else w_i + 1
    F = reference_forecast_quats(T_euler[n : n + 2], I.orders, w)
    F = np.concatenate([T_quats[q : q + 1], F])
    if window == "square-tn":
        F = np.concatenate([T_quats[n : n + 1], F])
    C = geodesic_cost_matrix_numpy(I.quats[Mn : Mn + rows], F)
    ok = reference_mask(allowed, rows)
    C[~ok, 0] = np.inf
    D = np.empty_like(C)
    last_i, last_j = C.shape[0] - 1, C.shape[1] - 1
    for i in range(last_i, -1, -1):
        for j in range(last_j, -1, -1):
            c = C[i, j]
            if j == last_j and (i == last_i or window == "open-end"):
                D[i, j] = c
            elif i == last_i:
                D[i, j] = c + D[i, j + 1]
            elif j == last_j:
                D[i, j] = c + D[i + 1, j]
            elif window == "normalised":
                D[i, j] = min(D[i + 1, j + 1] + 2 * c, D[i + 1, j] + c, D[i, j + 1] + c)
            else:
                D[i, j] = c + min(D[i + 1, j + 1], D[i + 1, j], D[i, j + 1])
    score = D[:, 0].copy()
    if window == "normalised":
        score = score / ((C.shape[0] - np.arange(C.shape[0])) + C.shape[1])
    cand = np.where(ok, score, np.inf)
    if ties == "high":
        off = int(len(cand) - 1 - np.argmin(cand[::-1]))
    else:
        off = int(np.argmin(cand))  # first minimum: lowest row
    w_i = rows if window == "square" else rows - 1
    return WindowSnapshot(q, "window", Mn, w_i, off, Mn + off, C=C, D=D, score=score)


#: The reference step of each window method, by class name.
REFERENCE_STEPS = {
    "MethodA": reference_step_a,
    "MethodB": reference_step_b,
    "MethodC": reference_step_c,
}
