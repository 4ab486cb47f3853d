"""FP-DTW Method C, predictive windowing using the cost matrix (Algorithm 3).

Method B without the path: the forecast window's costs are accumulated in reverse, from
the far corner back to (0, 0), and ``T_{n+1}`` is mapped to the input frame with the
lowest accumulated cost in the ``T_{n+1}`` column.

Which window? Algorithm 3 declares ``C, D`` of size ``w_i x w`` (square when
``w_i = w``) but fills them from the input range ``{I_{M_n}..I_{M_n+w_i}}``, which has
``w_i + 1`` frames. The difference decides the method: with ``w_i + 1`` rows against
``w`` columns and the path pinned to the far corner, a path from row 0 (a hold) needs
``w + 1`` cells while a path from any other row needs ``w``, so a hold pays one extra
cell's cost and the method almost never holds (it skips ahead and runs out of input).
The square window has no such penalty: every row's path to the corner has ``w`` cells.
The default is the declared square window; the other readings stay available for
notebook 15 (``window=...``).
"""

from __future__ import annotations

import numpy as np

from fpdtw.online.window import (
    C_LITERAL,
    C_NORMALISED,
    C_OPEN_END,
    C_SQUARE,
    C_SQUARE_TN,
    METHOD_C,
    P_METHOD,
    P_READING,
    P_SHIFT,
    P_TIES_HIGH,
    ForecastAligner,
)

#: Method C's window readings: option value -> kernel code.
READINGS = {
    "square": C_SQUARE,
    "literal": C_LITERAL,
    "square-tn": C_SQUARE_TN,
    "open-end": C_OPEN_END,
    "normalised": C_NORMALISED,
}


class MethodC(ForecastAligner):
    """Method C (Algorithm 3): reverse-accumulated forecast window.

    For target frame ``q = n + 1`` (choices where the paper is silent are marked *):

    * ``q = 0``: ``M_0 = 0`` (*; ``start="best"``: the best match of ``T_0`` in
      ``I_0..I_w``).
    * Warm-up, ``n < s`` (``s = 2``): ``M_{n+1} = n + 1``, clipped to ``m``.
    * ``M_n > m`` (strictly, as written) never happens; at ``M_n = m`` every reading's
      window has the single row ``I_m`` and maps to ``m``: that case is short-cut (same
      result, and under Type V the hold at ``m`` is forced whatever the state).
    * Otherwise the window of the reading (``window=``), ``F = [T_{n+1}, T_{n+1} +
      delta, ..., T_{n+1} + (w - 1) delta]`` (``w`` columns; ``delta = T_{n+1} - T_n`` in
      unwrapped Euler angles, forecasts turned into quaternions per joint order, the
      known frame keeps its received quaternion), ``C`` = eq. 1 between the input rows
      and ``F``, ``D`` = REVERSE accumulation from the far corner,
      ``D[i, j] = C[i, j] + min(D[i+1, j+1], D[i+1, j], D[i, j+1])``, and
      ``M_{n+1} = M_n + argmin_i D[i, 0]``; ties: the lowest ``i`` (*; ``ties="high"``).
    * Type V (``constraint="typeV"``): before accumulating, ``C[r, 0] = +inf`` for every
      row ``r`` (offset) the state does not allow (all ``r > 3``), and the argmin runs
      over the allowed rows.

    Window shape, by reading (``window=``; rows are input frames from ``I_{M_n}``; in
    fpdtw ``w_i`` is always the offset of the last row, ``I_{M_n}..I_{M_n+w_i}``):

    ``"square"`` (default)
        Algorithm 3's declared size ``w_i x w``, where the paper's ``w_i`` counts rows:
        ``w`` rows ``I_{M_n}..I_{M_n+w-1}`` by ``w`` columns, so ``w_i = min(w - 1,
        m - M_n)``. The end test ``if M_n + w_i > m`` is read as keeping the LAST ROW
        inside the input (*): taken as written (``m - M_n`` rows) the last row would be
        ``I_{m-1}`` and the map could never reach ``m``. Every row's path to the corner
        has ``w`` cells: holding costs no more than advancing.
    ``"literal"``
        The range as written, ``{I_{M_n}..I_{M_n+w_i}}``: ``w_i + 1`` rows,
        ``w_i = min(w, m - M_n)``, by ``w`` columns. A hold (row 0) pays one extra cell.
    ``"square-tn"``
        Method B's target window with ``F_0 = T_n`` (``w + 1`` columns
        ``[T_n, T_{n+1}, ...]``) by ``w_i + 1`` rows, square, and the argmin over the
        first column, literally ``argmin{D_{0,0}..D_{m,0}}``: that column is ``T_n``'s,
        so ``T_{n+1}`` is mapped by how well the path from ``(r, T_n)`` fits.
    ``"open-end"``
        The literal window, but the path may end in any row of the last column
        (``D[r, w-1] = C[r, w-1]``): no pinned corner, no extra cell.
    ``"normalised"``
        The literal window, accumulated with the symmetric2 weights and each row's
        ``D[r, 0]`` divided by its paths' total weight ``(w_i + 1 - r) + w``
        (dtw-python's normalised distance): cost per unit of path, not per path.

    Other options, the paper's silent choices (notebook 15 measures each):
    ``forecast="hold"`` (zero-order hold instead of dead reckoning),
    ``forecast_start="next"`` (``F = [T^_{n+2}..T^_{n+w+1}]``: ``forecastJoints`` returns
    predictions only, column 0 is the first prediction), ``ties="high"``,
    ``start="best"``.

    Parameters
    ----------
    I, w, constraint, forecast, start, cache
        As for :class:`~fpdtw.online.method_b.MethodB`; ``w >= 2`` (:attr:`min_w`).
    window : {"square", "literal", "square-tn", "open-end", "normalised"}
        The reading of Algorithm 3's window (above).
    forecast_start : {"T_{n+1}", "next"}
    ties : {"low", "high"}
    record : bool
        Keep a :class:`~fpdtw.online.window.WindowSnapshot` of the last step (C, D and
        the per-row ``score``).

    Plain version: fpdtw.plain.method_c_step.
    Paper: FP-DTW Algorithm 3, Section 3.3.
    Notebook: 03_fig2_fig4_windows.ipynb
    """

    label = "Mc"
    #: ``w = 1`` is refused: the square window then has the one row ``I_{M_n}``, so the
    #: map would hold at ``M_2`` forever (and under Type V that row is masked after two
    #: holds, leaving no candidate).
    min_w = 2
    options = {
        "window": (
            "square",
            {
                "literal": "literal window",
                "square-tn": "square window from T_n",
                "open-end": "open end",
                "normalised": "normalised",
            },
        ),
        "forecast": ("dead-reckoning", {"hold": "hold forecast"}),
        "forecast_start": ("T_{n+1}", {"next": "forecast from T_n+2"}),
        "ties": ("low", {"high": "ties high"}),
        **ForecastAligner.options,
    }

    def params(self) -> np.ndarray:
        p = super().params()
        st = self.settings
        p[P_METHOD] = METHOD_C
        p[P_READING] = READINGS[st["window"]]
        p[P_SHIFT] = st["forecast_start"] == "next"
        p[P_TIES_HIGH] = st["ties"] == "high"
        return p

    def window_rows(self, start: int) -> int:
        """Number of input rows of the window at ``M_n = start`` (see the readings).

        Parameters
        ----------
        start : int
            ``M_n``, in ``0..m``.

        Returns
        -------
        rows : int
        """
        if self.settings["window"] == "square":
            return min(self.w, self.m - start + 1)
        return min(self.w, self.m - start) + 1

    def _window_record(self, nrows: int, ncols: int, npath: int) -> dict:
        return dict(
            C=self._C[:nrows, :ncols].copy(),
            D=self._D[:nrows, :ncols].copy(),
            score=self._score[:nrows].copy(),
        )


__all__ = ["READINGS", "MethodC"]
