"""FP-DTW Method A, frame matching (Algorithm 1).

Each incoming target frame ``T_{n+1}`` is mapped to the input frame that matches it best
(eq. 1) within the window ``{I_{M_n}..I_{M_n + w}}``, which starts at, and includes, the
input frame of the previous target frame.
"""

from __future__ import annotations

import numpy as np

from fpdtw.motion.features import MotionFeatures
from fpdtw.online.window import METHOD_A, P_METHOD, P_TIES_HIGH, WindowAligner


class MethodA(WindowAligner):
    """Method A (Algorithm 1): frame matching in a small forward window.

    Rules (choices where the paper is silent are marked *):

    * ``M_0 = 0`` (*: both motions start aligned).
    * ``w_i = min(w, m - M_n)``; the window ``{I_{M_n}..I_{M_n + w_i}}`` has ``w_i + 1``
      frames (inclusive). ``w_i = 0`` (input exhausted): ``M_{n+1} = M_n``.
    * ``M_{n+1} = M_n + argmin_i geoDistance(I_{M_n + i}, T_{n+1})``; ties: the lowest
      ``i`` (*).
    * Default ``w = 2`` (the paper's choice, mimicking a Type I constraint).
    * Type V (``constraint="typeV"``): window offsets the state does not allow are
      skipped (advance 1 is always allowed, so a window of 2+ frames always has one).

    Window shape: ``w_i + 1`` input rows by ONE target column (``T_{n+1}``); no path,
    so holding (row 0) and advancing are compared on their frame cost alone.

    Parameters
    ----------
    I : MotionFeatures
        Input (recorded) motion.
    w : int
        Window size, default 2.
    constraint : None, "typeV" or TypeV
    record : bool
        Keep a :class:`~fpdtw.online.window.WindowSnapshot` of the last step
        (``C`` has one column, ``T_{n+1}``).

    The compiled step is :func:`fpdtw.online.window._window_step`, the one of Methods B
    and C.

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


__all__ = ["MethodA"]
