"""FP-DTW Method B, predictive windowing using DTW (Algorithm 2).

The live target is forecast ``w`` frames ahead by dead reckoning; DTW plots a path
between the input window ``{I_{M_n}..I_{M_n + w_i}}`` and ``[T_n, T_{n+1}, forecast]``;
the incoming frame ``T_{n+1}`` is mapped to the lowest input frame the path visits in
the ``T_{n+1}`` column.
"""

from __future__ import annotations

import numpy as np

from fpdtw.costs import geodesic_cost_matrix_numpy
from fpdtw.online.window import (
    B_CORNER,
    METHOD_B,
    P_INPUT_FIRST,
    P_METHOD,
    ForecastAligner,
    WindowSnapshot,
    reference_forecast_quats,
    reference_mask,
    reference_prologue,
)


class MethodB(ForecastAligner):
    """Method B (Algorithm 2): DTW path through a forecast window.

    For target frame ``q = n + 1`` (choices where the paper is silent are marked *):

    * ``q = 0``: ``M_0 = 0`` (*; ``start="best"``: the best match of ``T_0`` in
      ``I_0..I_w``).
    * Warm-up, ``n < s`` (``s = 2``, dead reckoning on two frames): ``M_{n+1} = n + 1``,
      clipped to ``m``.
    * ``M_n >= m``: ``M_{n+1} = m``.
    * Otherwise ``w_i = min(w, m - M_n)``; ``F = [T_n, T_{n+1}, T_{n+1} + delta, ...,
      T_{n+1} + (w - 1) delta]`` (``w + 1`` columns, ``delta = T_{n+1} - T_n`` in
      unwrapped Euler angles, forecasts turned into quaternions per joint order; the two
      known frames keep their received quaternions); ``C`` = eq. 1 between the
      ``w_i + 1`` input frames and ``F``; ``D`` = symmetric DTW accumulation from (0, 0),
      ``D[i, j] = C[i, j] + min(D[i-1, j-1], D[i-1, j], D[i, j-1])``; then ``D[0, 0] =
      10000`` (after accumulating: it only steers the back-track off the diagonal into
      (0, 0), through (1, 0) or (0, 1)); back-track from ``(w_i, w)`` to (0, 0) with the
      paper's overwrite rule, so each column keeps the LOWEST input row the path visits;
      ``M_{n+1} = M_n + P_1`` (``P_1`` = that row in column 1, the ``T_{n+1}`` column).
    * Back-tracking ties (*): diagonal first, then the step back one target frame (same
      input frame), then the step back one input frame (``backtrack="input-first"``
      swaps the last two). The order between the last two matters at (1, 1), where
      ``D[0, 0] = 10000`` leaves (0, 1) (hold) and (1, 0) (advance): when ``T_n, T_{n+1}``
      match ``I_{M_n}, I_{M_n+1}`` symmetrically (an input aligned to itself) the two tie
      exactly, and advancing keeps the identity map.
    * Type V (``constraint="typeV"``): before accumulating, ``C[r, 1] = +inf`` for every
      row ``r`` (offset) the state does not allow (all ``r > 3``), so the path's ``P_1``
      is allowed (every cell the path visits has a finite accumulated cost).

    Window shape: ``w_i + 1`` input rows (``I_{M_n}..I_{M_n+w_i}``, the range as
    written) by ``w + 1`` target columns (``T_n`` prepended): square while
    ``w_i = w``. The path runs from the fixed corner (0, 0) to the far corner, so its
    length does not depend on the choice in column 1: holding and advancing cost the
    same number of cells (unlike Method C's literal window).

    Other options, the paper's silent choices (notebook 15 measures each):
    ``forecast="hold"`` (zero-order hold instead of dead reckoning),
    ``backtrack="input-first"``, ``start="best"``.

    Parameters
    ----------
    I : MotionFeatures
        Input (recorded) motion.
    w : int
        Forecast window size (the paper: 10, 20, 40, 80).
    constraint : None, "typeV" or TypeV
    forecast : {"dead-reckoning", "hold"}
    backtrack : {"target-first", "input-first"}
    start : {"zero", "best"}
    record : bool
        Keep a :class:`~fpdtw.online.window.WindowSnapshot` of the last step (C, D, the
        path, P).
    cache : WindowCache, optional
        Shared with other B/C aligners stepping over the same target together (speed
        only; see :class:`~fpdtw.online.window.WindowCache`).

    Paper: FP-DTW Algorithm 2, Fig. 4.
    Notebook: 05_run_experiments.ipynb
    """

    label = "Mb"
    options = {
        "forecast": ("dead-reckoning", {"hold": "hold forecast"}),
        "backtrack": ("target-first", {"input-first": "back-track input first"}),
        **ForecastAligner.options,
    }

    def params(self) -> np.ndarray:
        p = super().params()
        p[P_METHOD] = METHOD_B
        p[P_INPUT_FIRST] = self.settings["backtrack"] == "input-first"
        return p

    def _window_record(self, nrows: int, ncols: int, npath: int) -> tuple:
        arrays = dict(
            C=self._C[:nrows, :ncols].copy(),
            D=self._D[:nrows, :ncols].copy(),
            path=self._path[:npath][::-1].copy(),
            P=self._P[:ncols].copy(),
        )
        return nrows - 1, arrays

    @staticmethod
    def reference_step(I, T_quats, T_euler, M, w, allowed=None) -> WindowSnapshot:
        """Plain-numpy Method B step; see :func:`reference_step_b`."""
        return reference_step_b(I, T_quats, T_euler, M, w, allowed)


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

    Parameters
    ----------
    I : MotionFeatures
        Input motion.
    T_quats : ndarray of float, shape (q + 1, k, 4)
        Target frames received so far (``T_{n+1}`` last).
    T_euler : ndarray of float, shape (q + 1, k, 3)
        Their unwrapped Euler angles.
    M : ndarray of int, shape (q,)
        Map so far.
    w : int
    allowed : ndarray of bool, shape (4,), or None
        Type V: offsets 0..3 allowed (larger offsets never are); None: unconstrained.

    Returns
    -------
    snap : WindowSnapshot

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


__all__ = ["MethodB", "backtrack_lowest", "reference_step_b"]
