"""Dixon's on-line time warping (OLTW; DAFx 2005, the FP-DTW paper's ref. 3) as an aligner.

OLTW grows a DTW matrix one row or column at a time, inside a band of ``c`` cells behind the corner,
deciding after each growth which way to grow next (no forecast). Dixon's live ``u`` (his "rows",
``t``) is the TARGET here (``q``), his reference ``v`` (``j``) the INPUT (``i``): his
``Row``/``Column``/``Both`` are ``TARGET``/``INPUT``/``BOTH``. ``GetInc``: BOTH while ``q + 1 < c``
(``warmup=False`` skips it); after more than ``max_run_count`` equal increments, the other one; else
the lowest-cost cell of the newest column and row: the corner -> BOTH, an earlier input frame ->
TARGET, an earlier target frame -> INPUT. GetInc is called once per loop (his pseudocode calls it
three times; every implementation we know calls it once).

Choices (* where Dixon is silent): eq. 1 as local cost; ``D = min(D[i-1, q] + d, D[i, q-1] + d,
D[i-1, q-1] + 2 d)`` (Dixon's weights, as pymatchmaker reads them); (*) costs compared normalised,
``D / (1 + i + q)`` (``normalize=False``: raw); (*) cells outside the ``c x c`` block behind the
corner are unreachable; (*) ties: the first minimum, the newest column by increasing ``i`` then the
newest row by increasing ``q`` (pymatchmaker's order); (*) once ``i = m`` every increment is TARGET
(hold at ``m``). Streaming: a frame applies the increment waiting for it, then INPUT increments
until GetInc asks for TARGET or BOTH, which waits for the next frame; ``M_q`` is the corner's input
index then (never decreasing). Defaults ``c = 120`` (1 s at 120 Hz; Dixon's 500 is 10 s of his
audio) and ``max_run_count = 3`` (Dixon's).

Paper: FP-DTW reference 3 (Dixon 2005), an extra online baseline.
Notebook: 20_align_a_live_performance.ipynb
"""

from __future__ import annotations

import numba
import numpy as np

from fpdtw import limits
from fpdtw.costs import _geo_frame_w, _geo_line_w
from fpdtw.errors import AlignmentError
from fpdtw.motion.features import MotionFeatures
from fpdtw.online.base import JointMajorInput, OnlineAligner, check_count, check_input
from fpdtw.weights import joint_weights

#: Increment codes.
NONE, TARGET, INPUT, BOTH = 0, 1, 2, 3
#: Printable names of the increment codes.
INC_NAMES = {NONE: "none", TARGET: "target", INPUT: "input", BOTH: "both"}
#: Why a decision was taken: by the argmin, by the band warm-up, by the run count rule.
BY_ARGMIN, BY_WARMUP, BY_RUNCOUNT = 0, 1, 2

# state vector slots
_I, _Q, _PEND = 0, 1, 4
# decision log columns (see OLTW.decisions)
_LOG_COLS = 7


@numba.njit(cache=True)
def _work_views(work, c, k):
    """OLTW's float64 scratch as views of one buffer: the band ``D`` (c, c), the last c target
    frames joint-major ``R`` (k, 4, c) (frame q' in slot ``q' % c``), ``d`` and ``acc`` (c)."""
    D = work[: c * c].reshape((c, c))
    R = work[c * c : c * c + 4 * k * c].reshape((k, 4, c))
    o = c * c + 4 * k * c
    return D, R, work[o : o + c], work[o + c : o + 2 * c]


@numba.njit(cache=True)
def _new_band_line(Iq, Isoa, R, D, dl, acc, c, i, q, column, wts):
    """Evaluate the new line at the corner (i, q): target column q (``column``) or input row i.

    In the ring ``D`` (cell (i', q') at ``D[i' % c, q' % c]``; outside the band unreachable);
    its eq. 1 costs first, in one vectorised pass, bit-identical to ``_geo_frame``."""
    lo = max(0, (i if column else q) - c + 1)
    hi = (i if column else q) + 1
    if column:
        s = q % c
        _geo_line_w(R[:, :, s], Isoa, lo, hi, acc, dl, wts)
    else:
        s0 = lo % c
        s1 = q % c
        if s0 <= s1:
            _geo_line_w(Iq[i], R, s0, s1 + 1, acc, dl, wts)
        else:  # the run of slots wraps around the ring
            _geo_line_w(Iq[i], R, s0, c, acc, dl, wts)
            _geo_line_w(Iq[i], R, 0, s1 + 1, acc, dl[c - s0 :], wts)
    # ring slots of the running index k, of k - 1 (no modulo per cell), of the fixed index and -1
    s = lo % c
    sp = (lo - 1) % c
    f = (q if column else i) % c
    fp = ((q if column else i) - 1) % c
    x = 0.0
    for k in range(lo, hi):
        d = dl[k - lo]
        if column:
            r, cq, rp, pc = s, f, sp, fp
        else:
            r, cq, rp, pc = f, s, fp, sp
        if k > lo:
            # the line's previous cell (x, in a register) is the input step in a column, the
            # target step in a row; a minimum of three is exact in any order
            x = min(min(x + d, (D[r, pc] if column else D[rp, cq]) + d), D[rp, pc] + 2.0 * d)
        elif column:
            x = D[r, pc] + d  # (ii, q - 1)
        else:
            x = D[rp, cq] + d  # (i - 1, qq)
        D[r, cq] = x
        sp = s
        s = s + 1 if s + 1 < c else 0


@numba.njit(cache=True)
def _best_cell(D, c, i, q, normalize):
    """Lowest (normalised) cost in the newest column, then row; the first minimum wins."""
    best = np.inf
    bi = i
    bq = q
    for column in (True, False):
        lo = max(0, (i if column else q) - c + 1)
        s = lo % c  # ring slot of k, advanced without a modulo per cell
        f = (q if column else i) % c
        for k in range(lo, (i if column else q) + 1):
            ii = k if column else i
            qq = q if column else k
            v = D[s, f] if column else D[f, s]
            s = s + 1 if s + 1 < c else 0
            if normalize:
                v = v / (1.0 + ii + qq)
            if v < best:
                best = v
                bi = ii
                bq = qq
    return bi, bq


@numba.njit(cache=True)
def _apply(Iq, Isoa, R, D, dl, acc, st, c, inc, wts):
    """Make the increment ``inc`` (target column, input row or both), then count the run."""
    if inc == 1 or inc == 3:  # TARGET or BOTH
        st[1] += 1
        _new_band_line(Iq, Isoa, R, D, dl, acc, c, st[0], st[1], True, wts)
    if inc == 2 or inc == 3:  # INPUT or BOTH
        st[0] += 1
        _new_band_line(Iq, Isoa, R, D, dl, acc, c, st[0], st[1], False, wts)
    st[3] = st[3] + 1 if inc == st[2] else 1
    if inc != 3:
        st[2] = inc


@numba.njit(cache=True)
def _oltw_step(Iq, Isoa, Tq, base, q_new, work, st, c, max_run, warmup, normalize, log, wts):
    """Receive target frame ``q_new``, grow the matrix: (M_q, number of log rows). ``st`` (5,):
    corner i, corner q, previous increment, run count, pending increment."""
    m = Iq.shape[0] - 1
    D, R, dl, acc = _work_views(work, c, Iq.shape[1])
    s = q_new % c
    for j in range(Iq.shape[1]):
        for a in range(4):
            R[j, a, s] = Tq[q_new - base, j, a]
    if q_new == 0:
        D[0, 0] = _geo_frame_w(Iq[0], Tq[0 - base], wts)
        st[:] = 0
    else:
        _apply(Iq, Isoa, R, D, dl, acc, st, c, st[4], wts)  # the increment that waited for it
    n = 0
    while True:
        i = st[0]
        q = st[1]
        bi = -1
        bq = -1
        if warmup and q + 1 < c:
            inc = 3
            why = 1
        elif st[3] > max_run:
            inc = 2 if st[2] == 1 else 1
            why = 2
        else:
            bi, bq = _best_cell(D, c, i, q, normalize)
            why = 0
            if bi == i and bq == q:
                inc = 3
            elif bi < i:
                inc = 1
            else:
                inc = 2
        if i >= m and inc != 1:
            inc = 1  # end of the input: hold at m
        if n < log.shape[0]:
            log[n, 0] = q_new
            log[n, 1] = i
            log[n, 2] = q
            log[n, 3] = inc
            log[n, 4] = why
            log[n, 5] = bi
            log[n, 6] = bq
        n += 1
        if inc == 2:
            _apply(Iq, Isoa, R, D, dl, acc, st, c, inc, wts)
        else:
            st[4] = inc
            break
    return st[0], n


class OLTW(JointMajorInput, OnlineAligner):
    """Dixon's on-line time warping behind the streaming interface (module docstring).

    ``c``: the search width in frames (>= 2); ``max_run_count``: Dixon's MaxRunCount; ``warmup``:
    BOTH until the band is full (False: the argmin at once); ``normalize``: compare costs divided
    by ``1 + i + q``; ``constraint``: None only; ``record``: keep :attr:`decisions` and
    :attr:`path`; ``weights="travel"``: eq. 1 weighted by :func:`fpdtw.weights.joint_weights`.

    Paper: FP-DTW reference 3 (Dixon, DAFx 2005).
    Notebook: 20_align_a_live_performance.ipynb
    """

    name = "OLTW"
    #: As :attr:`fpdtw.online.window.WindowAligner.options`: ``"OLTW (weighted joints)"``.
    options = {"weights": ("none", {"travel": "weighted joints"})}

    def __init__(
        self,
        I: MotionFeatures,
        c: int = 120,
        *,
        max_run_count: int = 3,
        warmup: bool = True,
        normalize: bool = True,
        constraint=None,
        record: bool = False,
        weights: str = "none",
    ):
        check_count(c, "search width c", "OLTW", minimum=2)
        if weights not in ("none", "travel"):
            raise AlignmentError(f"OLTW: weights={weights!r}; expected one of 'none', 'travel'")
        check_count(max_run_count, "max_run_count", "OLTW")
        if constraint is not None:
            raise AlignmentError(f"OLTW has no local constraint (got {constraint!r})")
        check_input(I, who="OLTW")
        limits.check_bytes(
            limits.band_bytes(c),
            I.name,
            f"OLTW's search band would be c x c = {c} x {c} float64",
            hint="use a smaller search width c (--window)",
        )
        self.c = int(c)
        self.history = self.c - 1  # new input rows read target frames q - c + 1 .. q
        self.max_run_count = int(max_run_count)
        self.warmup = bool(warmup)
        self.normalize = bool(normalize)
        self.record = bool(record)
        self.name = "OLTW" if self.c == 120 else f"OLTW c{self.c}"
        self.weights = weights
        if weights == "travel":
            self.name += " (weighted joints)"
        self._wts = joint_weights(I) if weights == "travel" else np.empty(0)
        self._use_input(I.quats, I.orders)
        self._log = np.zeros((self.max_run_count + 4, _LOG_COLS), dtype=np.int64)
        super().__init__(I)

    def reset(self) -> None:
        """Forget every target frame and the matrix."""
        super().reset()
        c, k = self.c, self._Iq.shape[1]
        self._work = np.zeros(c * c + 4 * k * c + 2 * c)
        self._D, _, _, _ = _work_views(self._work, c, k)
        self._D[:] = np.inf
        self._st = np.zeros(5, dtype=np.int64)
        self._decisions = []

    def _step(self, q: int) -> int:
        m, n = _oltw_step(
            self._Iq, self._Isoa, self._Tq, self.history_start, self.n_received - 1,
            self._work, self._st, self.c, self.max_run_count, self.warmup, self.normalize,
            self._log, self._wts,
        )  # fmt: skip
        if self.record:
            self._decisions.append(self._log[:n].copy())
        return int(m)

    @property
    def corner(self) -> tuple:
        """The current corner ``(i, q)`` of the computed matrix."""
        return int(self._st[_I]), int(self._st[_Q])

    @property
    def pending(self) -> str:
        """The increment waiting for the next target frame (``"target"`` or ``"both"``)."""
        return INC_NAMES[int(self._st[_PEND])]

    @property
    def decisions(self) -> np.ndarray:
        """Every GetInc decision so far (``record=True``), int64 (N, 7).

        Columns: target frame, corner ``i``, corner ``q``, increment, reason (``BY_*``), argmin
        cell ``i*``, ``q*`` (-1 if none)."""
        if not self.record:
            raise AlignmentError("decisions are kept only with record=True")
        if not self._decisions:
            return np.zeros((0, _LOG_COLS), dtype=np.int64)
        return np.concatenate(self._decisions)

    @property
    def path(self) -> np.ndarray:
        """Dixon's on-line path (``record=True``): the corner after each increment, (L, 2)."""
        dec = self.decisions
        pts = [(0, 0)] if self.n_received else []
        for i, q, inc in zip(dec[:, 1], dec[:, 2], dec[:, 3]):
            nxt = (int(i) + (inc in (INPUT, BOTH)), int(q) + (inc in (TARGET, BOTH)))
            if nxt[1] < self.n_received:
                pts.append(nxt)
        return np.array(pts, dtype=np.int64).reshape(-1, 2)
