"""FP-DTW Method C, predictive windowing using the cost matrix (Algorithm 3).

Method B without the path: the forecast window's costs are accumulated in reverse, and
``T_{n+1}`` goes to the input row of lowest accumulated cost. Which window is the
paper's is a reading (:class:`MethodC`).
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

    After the warm-up (:class:`~fpdtw.online.window.ForecastAligner`): ``w`` columns ``[T_{n+1},
    T_{n+1} + delta, ...]``, eq. 1 costs against the window's rows, REVERSE accumulation from
    the far corner, ``M_{n+1} = M_n + argmin_i D[i, 0]``, ties the lowest ``i`` (a silent
    choice; ``ties="high"``). Type V sets ``C[r, 0] = +inf`` on the rows its state forbids.

    The window (``window=``). Algorithm 3 declares ``C, D`` of size ``w_i x w`` but fills them
    from ``{I_{M_n}..I_{M_n+w_i}}``, ``w_i + 1`` rows; with the path pinned to the far corner
    a hold then pays one extra cell, and the method almost never holds.

    * ``"square"`` (default): the declared size, ``w`` rows, ``w_i = min(w - 1, m - M_n)``
      (the end test read as keeping the last row inside the input, or ``m`` is never reached);
    * ``"literal"``: the range as written, ``w_i = min(w, m - M_n)``, ``w_i + 1`` rows;
    * ``"square-tn"``: Method B's columns ``[T_n, T_{n+1}, ...]``, argmin in ``T_n``'s;
    * ``"open-end"``: literal, the path free to end in any row of the last column;
    * ``"normalised"``: literal, symmetric2 weights, ``D[r, 0]`` over its paths' weight.

    Other silent choices (notebook 15): ``forecast="hold"``, ``forecast_start="next"`` (``F``
    from the first prediction), ``start="best"``. Other arguments as
    :class:`~fpdtw.online.method_b.MethodB`'s; ``w >= 2``.

    Plain version: fpdtw.plain.method_c_step.
    Paper: FP-DTW Algorithm 3, Section 3.3.
    Notebook: 03_fig2_fig4_windows.ipynb
    """

    label = "Mc"
    #: ``w = 1`` is refused: the square window's one row ``I_{M_n}`` would hold forever
    #: (and Type V masks it after two holds, leaving no candidate).
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
        """Number of input rows of the window at ``M_n = start`` (0..m)."""
        if self.settings["window"] == "square":
            return min(self.w, self.m - start + 1)
        return min(self.w, self.m - start) + 1

    def _window_record(self, nrows: int, ncols: int, npath: int) -> dict:
        return dict(
            C=self._C[:nrows, :ncols].copy(),
            D=self._D[:nrows, :ncols].copy(),
            score=self._score[:nrows].copy(),
        )
