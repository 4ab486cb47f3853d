"""FP-DTW Method C, predictive windowing using the cost matrix (Algorithm 3).

Method B without the path: the forecast window's costs are accumulated in reverse, from
the far corner back to (0, 0), and ``T_{n+1}`` is mapped to the input frame with the
lowest accumulated cost in the ``T_{n+1}`` column.
"""

from __future__ import annotations

import numpy as np

from ..costs import geodesic_cost_matrix_numpy
from ..features import MotionFeatures
from .window import (
    WindowAligner,
    WindowSnapshot,
    _step_c,
    reference_forecast_quats,
    reference_mask,
    reference_prologue,
)


class MethodC(WindowAligner):
    """Method C (Algorithm 3): reverse-accumulated forecast window.

    For target frame ``q = n + 1`` (choices where the paper is silent are marked *):

    * ``q = 0``: ``M_0 = 0`` (*).
    * Warm-up, ``n < s`` (``s = 2``): ``M_{n+1} = n + 1``, clipped to ``m``.
    * ``M_n > m`` (strictly, as written) never happens; ``M_n = m`` gives ``w_i = 0``, a
      one-row window whose argmin is row 0, so ``M_{n+1} = m``: that case is short-cut
      (same result, and under Type V the hold at ``m`` is forced whatever the state).
    * Otherwise ``w_i = min(w, m - M_n)``; ``F = [T_{n+1}, T_{n+1} + delta, ...,
      T_{n+1} + (w - 1) delta]`` (``w`` columns; ``T_n`` is not included); ``C`` = eq. 1
      between the ``w_i + 1`` input frames and ``F``; ``D`` = REVERSE accumulation,
      ``D[w_i, w-1] = C[w_i, w-1]``, ``D[i, j] = C[i, j] + min(D[i+1, j+1], D[i+1, j],
      D[i, j+1])``; ``M_{n+1} = M_n + argmin_i D[i, 0]``; ties: the lowest ``i`` (*).
    * Type V (``constraint="typeV"``): before accumulating, ``C[r, 0] = +inf`` for every
      row ``r`` (offset) the state does not allow (all ``r > 3``), and the argmin runs
      over the allowed rows.

    Parameters
    ----------
    I : MotionFeatures
        Input (recorded) motion.
    w : int
        Forecast window size (the paper: 10, 20, 40, 80).
    constraint : None, "typeV" or TypeV
    record : bool
        Keep a :class:`~fpdtw.online.window.WindowSnapshot` of the last step (C, D).

    Paper: FP-DTW Algorithm 3.
    Notebook: 05_run_experiments.ipynb
    """

    label = "Mc"
    #: Smoothing window: frames needed before forecasting (dead reckoning: 2).
    s = 2

    def __init__(self, I: MotionFeatures, w: int, *, constraint=None, record=False):
        super().__init__(I, w, constraint=constraint, record=record)
        k = self._Iq.shape[1]
        self._F = np.empty((k, 4, self.w))
        self._C = np.empty((self.w + 1, self.w))
        self._D = np.empty((self.w + 1, self.w))

    def _step(self, q: int) -> int:
        if q == 0:
            if self.record:
                self._snap(0, "first", -1, 0, 0)
            return 0
        start = int(self._M[q - 1])
        n = q - 1
        if n < self.s:
            m_next = min(n + 1, self.m)
            if self.record:
                self._snap(q, "warmup", start, 0, m_next)
        elif start >= self.m:
            m_next = self.m
            if self.record:
                self._snap(q, "end", start, 0, m_next)
        else:
            w_i = min(self.w, self.m - start)
            off = _step_c(
                self._Iq, self._Tq, self._Te, q, start, self.w, w_i, self._codes,
                self._limit, self._allow(), self._F, self._C, self._D,
            )  # fmt: skip
            m_next = start + int(off)
            if self.record:
                nr, nc = w_i + 1, self.w
                self._snap(
                    q, "window", start, w_i, m_next,
                    C=self._C[:nr, :nc].copy(), D=self._D[:nr, :nc].copy(),
                )  # fmt: skip
        self._advance_state(m_next - start)
        return m_next

    @staticmethod
    def reference_step(I, T_quats, T_euler, M, w, allowed=None) -> WindowSnapshot:
        """Plain-numpy Method C step; see :func:`reference_step_c`."""
        return reference_step_c(I, T_quats, T_euler, M, w, allowed)


def reference_step_c(I, T_quats, T_euler, M, w, allowed=None) -> WindowSnapshot:
    """Plain-numpy reference of one Method C step (for tests).

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

    Paper: FP-DTW Algorithm 3.
    """
    head = reference_prologue(I, T_quats, M, w, MethodC.s)
    if isinstance(head, WindowSnapshot):
        return head
    q, n, Mn, w_i = head
    F = np.concatenate(
        [T_quats[q : q + 1], reference_forecast_quats(T_euler[n : n + 2], I.orders, w)]
    )
    C = geodesic_cost_matrix_numpy(I.quats[Mn : Mn + w_i + 1], F)
    ok = reference_mask(allowed, w_i + 1)
    C[~ok, 0] = np.inf
    D = np.empty_like(C)
    last_i, last_j = C.shape[0] - 1, C.shape[1] - 1
    for i in range(last_i, -1, -1):
        for j in range(last_j, -1, -1):
            if i == last_i and j == last_j:
                D[i, j] = C[i, j]
            elif i == last_i:
                D[i, j] = C[i, j] + D[i, j + 1]
            elif j == last_j:
                D[i, j] = C[i, j] + D[i + 1, j]
            else:
                D[i, j] = C[i, j] + min(D[i + 1, j + 1], D[i + 1, j], D[i, j + 1])
    off = int(np.argmin(np.where(ok, D[:, 0], np.inf)))  # first minimum: lowest row
    return WindowSnapshot(q, "window", Mn, w_i, off, Mn + off, C=C, D=D)


__all__ = ["MethodC", "reference_step_c"]
