"""FP-DTW Method A, frame matching (Algorithm 1).

Each incoming target frame ``T_{n+1}`` is mapped to the input frame that matches it best
(eq. 1) within the window ``{I_{M_n}..I_{M_n + w}}``, which starts at, and includes, the
input frame of the previous target frame.
"""

from __future__ import annotations

import numba
import numpy as np

from fpdtw.costs import _geo_frame
from fpdtw.motion.features import MotionFeatures
from fpdtw.online.window import WindowAligner, _is_allowed


@numba.njit(cache=True)
def _step_a(Iq, Tq, q, start, w_i, limit, allow, C, ties_high=False):
    """Method A window branch: argmin over allowed rows of geoDistance(I_{start+r}, T_q).

    Ties: the lowest row, or the highest with ``ties_high``.
    """
    best = -1
    for r in range(w_i + 1):
        C[r] = _geo_frame(Iq[start + r], Tq[q])
        if _is_allowed(r, limit, allow):
            if best < 0 or C[r] < C[best] or (ties_high and C[r] == C[best]):
                best = r
    return max(best, 0)


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

    Paper: FP-DTW Algorithm 1.
    Notebook: 05_run_experiments.ipynb
    """

    label = "Ma"
    options = {"ties": ("low", {"high": "ties high"}), **WindowAligner.options}

    def __init__(self, I: MotionFeatures, w: int = 2, *, constraint=None, record=False, **options):
        super().__init__(I, w, constraint=constraint, record=record, **options)
        self._C = np.empty(self.w + 1)
        self._ties_high = self.settings["ties"] == "high"

    @classmethod
    def _base_name_for(cls, w: int) -> str:
        return "Ma" if w == 2 else f"Ma w{w}"

    def _step(self, q: int) -> int:
        if q == 0:
            return self._first()
        start = int(self._M[q - 1])
        w_i = min(self.w, self.m - start)
        if w_i <= 0:
            m_next = start
            if self.record:
                self._snap(q, "end", start, 0, m_next)
        else:
            off = _step_a(
                self._Iq, self._Tq, q, start, w_i, self._limit, self._allow(), self._C,
                self._ties_high,
            )  # fmt: skip
            m_next = start + off
            if self.record:
                C = self._C[: w_i + 1, None].copy()
                self._snap(q, "window", start, w_i, m_next, C=C)
        self._advance_state(m_next - start)
        return m_next


__all__ = ["MethodA"]
