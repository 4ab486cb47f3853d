"""Open-end DTW (OE-DTW, Tormene et al. 2009), computed incrementally.

After each target frame ``T_q``, the input frame ``e_q`` where the cheapest alignment of
``T_0..T_q`` with some ``I_0..I_e`` ends (rows = input frames), one accumulated column per
frame, ``O(m)``. The end points may move backwards (the FP-DTW paper's Fig. 1); to draw that,
every column is kept for :meth:`OEDTW.path`.
"""

from __future__ import annotations

import numba
import numpy as np

from fpdtw import limits
from fpdtw.costs import _geo_block, _geo_line
from fpdtw.dtw import _backtrack, diagonal_weight
from fpdtw.errors import AlignmentError
from fpdtw.motion.features import MotionFeatures
from fpdtw.online.base import JointMajorInput, OnlineAligner


@numba.njit(cache=True)
def _oe_column(Isoa, t, prev, cur, first, wd, norm_offset, c):
    """Accumulated column ``cur`` of a new target frame ``t`` (k, 4); returns the end point.

    From ``prev``; the end point is the argmin of ``cur`` (lowest i on ties), or with
    ``norm_offset >= 0`` of ``cur[i] / (norm_offset + i)`` (dtw-python's N+M normalisation).
    ``Isoa``: the input joint-major (k, 4, m+1); ``c``: scratch."""
    m1 = cur.shape[0]
    _geo_line(t, Isoa, 0, m1, c, c)  # c[i] = geoDistance(I_i, t) (eq. 1)
    x = c[0] if first else prev[0] + c[0]
    cur[0] = x
    for i in range(1, m1):
        ci = c[i]
        if first:
            x = x + ci
        else:
            best = min(prev[i - 1] + wd * ci, prev[i] + ci)
            x = min(best, x + ci)
        cur[i] = x
    best_i = 0
    if norm_offset < 0:
        best_v = cur[0]
        for i in range(1, m1):
            if cur[i] < best_v:
                best_v = cur[i]
                best_i = i
    else:
        best_v = cur[0] / norm_offset
        for i in range(1, m1):
            v = cur[i] / (norm_offset + i)
            if v < best_v:
                best_v = v
                best_i = i
    return best_i


@numba.njit(cache=True)
def _oe_step(Isoa, Tq, cols, q, wd, norm_offset, c):
    """:func:`_oe_column` of target frame ``q``: column ``q`` of ``cols`` from column ``q - 1``."""
    prev = cols[q - 1] if q > 0 else cols[0]
    return _oe_column(Isoa, Tq[q], prev, cols[q], q == 0, wd, norm_offset, c)


class OEDTW(JointMajorInput, OnlineAligner):
    """Open-end DTW: ``step`` returns the best end point ``e_q`` (not monotonic).

    ``step_pattern``: "symmetric1" or "symmetric2" (:func:`fpdtw.dtw.accumulate`); ``normalize``:
    divide by ``(q + 1) + (i + 1)`` first, as dtw-python's ``open_end=True`` (symmetric2 only).

    Plain version: fpdtw.plain.oe_dtw_end_points (symmetric1, not normalised).
    Paper: FP-DTW Section 2 and Fig. 1 (Tormene et al. 2009).
    """

    name = "OE-DTW"

    def __init__(self, I: MotionFeatures, step_pattern: str = "symmetric1", normalize=False):
        self.step_pattern = step_pattern
        self._wd = diagonal_weight(step_pattern)
        self.normalize = bool(normalize)
        if self.normalize and step_pattern != "symmetric2":
            raise AlignmentError(
                f"normalize=True needs step_pattern='symmetric2' (N+M normalisation); "
                f"{step_pattern!r} is not normalisable"
            )
        super().__init__(I)
        self._use_input(I.quats, I.orders)
        self._c = np.empty(I.n_frames)

    def reset(self) -> None:
        """Forget every target frame and every stored column."""
        super().reset()
        self._check_columns(256)
        self._cols = np.empty((256, self.I.n_frames))

    @staticmethod
    def column_bytes(input_frames: int, target_frames: int) -> int:
        """Bytes of the columns kept for a target of this length (256 columns, doubling)."""
        cap = 256
        while cap < target_frames:
            cap *= 2
        return 8 * cap * int(input_frames)

    def _check_columns(self, n: int) -> None:
        """``n`` stored columns fit :data:`fpdtw.limits.MAX_MATRIX_BYTES` (else LimitError)."""
        m1 = self.I.n_frames
        limits.check_bytes(
            8 * n * m1,
            self.I.name,
            f"OE-DTW keeps every accumulated column (for path()): {n} target frames x "
            f"{m1} input frames of float64",
            hint="OE-DTW's memory grows with target x input frames: use a method with a "
            "bounded window (a, b, c, oltw) for long takes, or shorter takes",
        )

    def _step(self, q: int) -> int:
        if q == self._cols.shape[0]:
            self._check_columns(2 * q)
            grown = np.empty((2 * q, self._cols.shape[1]))
            grown[:q] = self._cols
            self._cols = grown
        offset = float(q + 2) if self.normalize else -1.0
        # rows of the stored arrays are taken inside the kernel: fewer Python-side views
        return _oe_step(self._Isoa, self._Tq, self._cols, q, self._wd, offset, self._c)

    @property
    def end_points(self) -> np.ndarray:
        """End point ``e_q`` of every target frame received so far, int64 (n + 1,)."""
        return self.M

    @property
    def D(self) -> np.ndarray:
        """A copy of the accumulated cost so far, ``D[i, q]``, float64 (m + 1, n + 1)."""
        return self._cols[: self.n_received].T.copy()

    def path(self, q: int | None = None) -> np.ndarray:
        """Partial alignment path (L, 2) of target frame ``q`` (default the last).

        From ``(0, 0)`` to ``(e_q, q)``: :func:`fpdtw.dtw.dtw`'s path on ``C[:e_q + 1, :q + 1]``.

        Paper: FP-DTW Fig. 1 (paths for consecutive target frames).
        """
        n1 = self.n_received
        if n1 == 0:
            raise AlignmentError("OE-DTW has received no target frame yet")
        if q is None:
            q = n1 - 1
        q = int(q)
        if q < 0:
            q += n1
        if not 0 <= q < n1:
            raise AlignmentError(f"target frame {q} not received (have 0..{n1 - 1})")
        e = int(self.M[q])
        D = np.ascontiguousarray(self._cols[: q + 1, : e + 1].T)
        C = _geo_block(self._Iq[: e + 1], self._Tq[: q + 1], np.empty_like(D))
        return _backtrack(D, C, self._wd, True)
