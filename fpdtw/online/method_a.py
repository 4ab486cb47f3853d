"""FP-DTW Method A, frame matching in a forward window (Algorithm 1)."""

from __future__ import annotations

import numpy as np

from fpdtw.motion.features import MotionFeatures
from fpdtw.online.window import METHOD_A, P_METHOD, P_TIES_HIGH, WindowAligner


class MethodA(WindowAligner):
    """Method A (Algorithm 1): frame matching in a small forward window.

    ``M_{n+1} = M_n + argmin_i geoDistance(I_{M_n + i}, T_{n+1})`` over ``I_{M_n}..I_{M_n +
    w_i}``, ``w_i = min(w, m - M_n)`` (one target column, no path). Silent choices of the
    paper: ``M_0 = 0`` (``start="best"``); ties the lowest ``i`` (``ties="high"``). Default
    ``w = 2`` (the paper's, like a Type I constraint); Type V as in
    :class:`~fpdtw.online.window.WindowAligner`.

    Plain version: fpdtw.plain.method_a_step.
    Paper: FP-DTW Algorithm 1.
    Notebook: 03_fig2_fig4_windows.ipynb
    """

    label = "Ma"
    options = {"ties": ("low", {"high": "ties high"}), **WindowAligner.options}

    def __init__(self, I: MotionFeatures, w: int = 2, *, constraint=None, record=False, **options):
        super().__init__(I, w, constraint=constraint, record=record, **options)

    @classmethod
    def _base_name_for(cls, w: int) -> str:
        return "Ma" if w == 2 else f"Ma w{w}"

    def params(self) -> np.ndarray:
        p = super().params()
        p[P_METHOD] = METHOD_A
        p[P_TIES_HIGH] = self.settings["ties"] == "high"
        return p

    def _window_record(self, nrows: int, ncols: int, npath: int) -> dict:
        return dict(C=self._C[:nrows, :1].copy())
