"""FP-DTW Method B, predictive windowing using DTW (Algorithm 2)."""

from __future__ import annotations

import numpy as np

from fpdtw.online.window import METHOD_B, P_INPUT_FIRST, P_METHOD, ForecastAligner


class MethodB(ForecastAligner):
    """Method B (Algorithm 2): DTW path through a forecast window.

    After the warm-up (:class:`~fpdtw.online.window.ForecastAligner`): rows ``I_{M_n}..I_{M_n +
    w_i}``, ``w_i = min(w, m - M_n)``, against ``w + 1`` columns ``[T_n, T_{n+1}, T_{n+1} +
    delta, ..., T_{n+1} + (w - 1) delta]`` (dead reckoning on unwrapped Euler angles); eq. 1
    costs, symmetric DTW from (0, 0), then ``D[0, 0] = 10000`` (after accumulating: it only
    steers the back-track into (0, 0) through (1, 0) or (0, 1)); back-track with the
    overwrite rule; ``M_{n+1} = M_n + P_1``, the LOWEST row the path visits in column
    ``T_{n+1}``. Type V sets ``C[r, 1] = +inf`` on the rows its state forbids.

    Silent choices (notebook 15 measures each): ``M_0 = 0`` (``start="best"``); back-track
    ties take the diagonal, then the step back one target frame (``backtrack="input-first"``:
    one input frame; at (1, 1) the two tie for an input aligned to itself, and advancing
    keeps the identity map); dead reckoning (``forecast="hold"``). ``w``: the paper's 10,
    20, 40 or 80; ``cache``: a shared :class:`~fpdtw.online.window.WindowCache`.

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
