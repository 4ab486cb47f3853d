"""FP-DTW Method A, frame matching (Algorithm 1).

Each incoming target frame ``T_{n+1}`` is mapped to the input frame that matches it best
(eq. 1) within the window ``{I_{M_n}..I_{M_n + w}}``, which starts at, and includes, the
input frame of the previous target frame.
"""

from __future__ import annotations

import numba
import numpy as np

from fpdtw.costs import _geo_frame
from fpdtw.motion.features import Frame, MotionFeatures
from fpdtw.online.base import compiled_frame
from fpdtw.online.typev import MAX_ADVANCE
from fpdtw.online.window import WindowAligner, _first_frame, _is_allowed, _store_frame


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


#: Entries of Method A's int64 work buffer (:func:`_a_step`): w, Type V on, ties high,
#: start best, Type V state, kind of the last step, its w_i, number of Type V states,
#: then the Type V table (states x 4).
A_W, A_TYPEV, A_TIES_HIGH, A_START_BEST, A_STATE, A_KIND, A_WI, A_NS = range(8)
_A_HEADER = 8
#: ``A_KIND`` values.
A_FIRST, A_END, A_WINDOW = 0, 1, 2


@numba.njit(cache=True)
def _a_step(Iq, Tq, q, M, C, iwork):
    """``M_q`` of Method A at target frame q (frames 0..q received), Type V state included.

    ``iwork`` : int64, the header above (the state is advanced in place, the kind of step
    and ``w_i`` stored for the debug record) then the Type V table; ``C`` : float64
    (w + 1,) scratch, the window's costs after a window step.
    """
    m = Iq.shape[0] - 1
    w = iwork[A_W]
    typev = iwork[A_TYPEV] != 0
    ns = iwork[A_NS]
    table = iwork[_A_HEADER : _A_HEADER + 4 * ns].reshape((ns, 4))
    if q == 0:
        iwork[A_KIND] = A_FIRST
        iwork[A_WI] = 0
        return _first_frame(Iq, Tq, w, m, iwork[A_START_BEST] != 0)
    start = M[q - 1]
    w_i = min(w, m - start)
    iwork[A_WI] = max(w_i, 0)
    if w_i <= 0:
        iwork[A_KIND] = A_END
        m_next = start
    else:
        iwork[A_KIND] = A_WINDOW
        allow = np.ones(4, dtype=np.int64)
        limit = np.iinfo(np.int64).max
        if typev:
            limit = MAX_ADVANCE
            for a in range(4):
                allow[a] = 1 if table[iwork[A_STATE], a] >= 0 else 0
        m_next = start + _step_a(Iq, Tq, q, start, w_i, limit, allow, C, iwork[A_TIES_HIGH] != 0)
    if typev:
        adv = m_next - start
        if 0 <= adv <= MAX_ADVANCE and table[iwork[A_STATE], adv] >= 0:
            iwork[A_STATE] = table[iwork[A_STATE], adv]  # an illegal move: a forced hold at m
    return m_next


@numba.njit(cache=True)
def _a_stream_step(Iq, Tq, Te, M, q, fq, fe, C, iwork):
    """Receive one streamed frame (store it in row ``q``), run :func:`_a_step`, store
    ``M[q]``: Method A's whole ``step`` in one call. A frame of another shape changes
    nothing and returns -1 (the caller then raises)."""
    if not _store_frame(Iq.shape[1], Tq, Te, q, fq, fe):
        return -1
    m = _a_step(Iq, Tq, q, M, C, iwork)
    M[q] = m
    return m


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
        table = (
            np.zeros((3, 4), dtype=np.int64)
            if self.constraint is None
            else np.ascontiguousarray(self.constraint.table, dtype=np.int64)
        )
        self._iwork = np.zeros(_A_HEADER + table.size, dtype=np.int64)
        self._iwork[_A_HEADER:] = table.ravel()
        self._iwork[[A_W, A_TYPEV, A_TIES_HIGH, A_START_BEST, A_NS]] = (
            self.w,
            self.constraint is not None,
            self.settings["ties"] == "high",
            self.settings["start"] == "best",
            table.shape[0],
        )
        self.reset()

    @classmethod
    def _base_name_for(cls, w: int) -> str:
        return "Ma" if w == 2 else f"Ma w{w}"

    def reset(self) -> None:
        super().reset()
        iw = getattr(self, "_iwork", None)  # None while the base class's __init__ resets
        if iw is not None:
            iw[A_STATE] = 0 if self.constraint is None else self.constraint.start

    def step(self, frame: Frame) -> int:
        """Receive target frame ``T_{n+1}`` and return ``M_{n+1}``.

        The common case (numpy arrays, room in the buffers, no debug record) is one
        compiled call, :func:`_a_stream_step`; anything else takes the general path of
        :meth:`WindowAligner.step` (same result).
        """
        i = self.n_received - self._start
        arrays = None if self.record else compiled_frame(frame, i, self._M.shape[0], self._Tp)
        if arrays is not None:
            fq, fe = arrays
            m = _a_stream_step(
                self._Iq, self._Tq, self._Te, self._M, i, fq, fe, self._C, self._iwork
            )
            if m >= 0:
                self.n_received += 1
                if self.constraint is not None:
                    self.state = int(self._iwork[A_STATE])
                return m
        return super().step(frame)

    def _step(self, q: int) -> int:
        state = self.state
        m_next = int(_a_step(self._Iq, self._Tq, q, self._M, self._C, self._iwork))
        if self.constraint is not None:
            self.state = int(self._iwork[A_STATE])
        if self.record:
            kind = int(self._iwork[A_KIND])
            w_i = int(self._iwork[A_WI])
            if kind == A_FIRST:
                self._snap(0, "first", -1, 0, m_next)
            elif kind == A_END:
                self._snap(q, "end", int(self._M[q - 1]), 0, m_next, state=state)
            else:
                C = self._C[: w_i + 1, None].copy()
                self._snap(q, "window", int(self._M[q - 1]), w_i, m_next, state=state, C=C)
        return m_next


__all__ = ["MethodA"]
