"""FP-DTW Method B, predictive windowing using DTW (Algorithm 2).

The live target is forecast ``w`` frames ahead by dead reckoning; DTW plots a path
between the input window ``{I_{M_n}..I_{M_n + w_i}}`` and ``[T_n, T_{n+1}, forecast]``;
the incoming frame ``T_{n+1}`` is mapped to the lowest input frame the path visits in
the ``T_{n+1}`` column.
"""

from __future__ import annotations

import numpy as np

from fpdtw.online.window import (
    METHOD_B,
    P_INPUT_FIRST,
    P_METHOD,
    ForecastAligner,
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

    Plain version: fpdtw.plain.method_b_step.
    Paper: FP-DTW Algorithm 2, Fig. 4.
    Notebook: 03_fig2_fig4_windows.ipynb
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

    def _window_record(self, nrows: int, ncols: int, npath: int) -> dict:
        return dict(
            C=self._C[:nrows, :ncols].copy(),
            D=self._D[:nrows, :ncols].copy(),
            path=self._path[:npath][::-1].copy(),
            P=self._P[:ncols].copy(),
        )


__all__ = ["MethodB"]
