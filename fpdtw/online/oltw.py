"""Dixon's on-line time warping (OLTW), the FP-DTW paper's reference 3, as an online aligner.

S. Dixon, "Live tracking of musical performances using on-line time warping", DAFx 2005.
OLTW grows a DTW accumulated-cost matrix one row or one column at a time, only inside a
band of ``c`` cells behind the current corner, and decides after every growth step
which way to grow next. It needs no forecast and no look-ahead.

Names. Dixon aligns a live sequence ``u`` (index ``t``, his "rows") to a reference ``v``
(index ``j``, his "columns"). Here the live sequence is the TARGET ``T`` (index ``q``)
and the reference is the recorded INPUT ``I`` (index ``i``), so:

=================  ==================================  ==========================
Dixon              meaning                             here
=================  ==================================  ==========================
``Row``            ``t <- t + 1``: read a live frame   ``TARGET`` (``q <- q + 1``)
``Column``         ``j <- j + 1``                      ``INPUT`` (``i <- i + 1``)
``Both``           both                                ``BOTH``
``c``              search width                        ``c``
``MaxRunCount``    longest run of one increment        ``max_run_count``
=================  ==================================  ==========================

The algorithm (Dixon's Fig. 1, as implemented here):

* Start with the corner ``(i, q) = (0, 0)``, ``D[0, 0] = d(I_0, T_0)``.
* Repeat: ``inc = GetInc(i, q)``; if ``inc`` is TARGET or BOTH, wait for the next target
  frame, then ``q <- q + 1`` and evaluate the new column ``(i', q)`` for the ``c`` input
  frames ``i' = i - c + 1 .. i``; if ``inc`` is INPUT or BOTH, ``i <- i + 1`` and
  evaluate the new row ``(i, q')`` for ``q' = q - c + 1 .. q``. Then ``runCount <-
  runCount + 1`` if ``inc`` equals the previous non-BOTH increment, else 1, and the
  previous increment becomes ``inc`` unless ``inc`` is BOTH. (Dixon's pseudocode calls
  GetInc three times per loop; like every implementation we know, we call it once per
  loop and use that result three times.)
* ``GetInc(i, q)``: (1) BOTH while the band is not yet full (Dixon: ``t < c`` with his
  1-based ``t``, i.e. ``q + 1 < c``); switchable with ``warmup=False``. (2) If
  ``runCount > MaxRunCount``: TARGET if the previous increment was INPUT, else INPUT
  (Dixon: "if previous == Row return Column else return Row"). (3) Otherwise the cell of
  lowest path cost among the newest column ``(i', q)`` and the newest row ``(i, q')``
  (inside the band): the corner itself -> BOTH; a cell of the newest column with
  ``i' < i`` (the new target frame matches an earlier input frame: the input is ahead)
  -> TARGET; a cell of the newest row with ``q' < q`` (the newest input frame matches an
  earlier target frame: the input is behind) -> INPUT.

Choices where the paper is silent or could not be re-checked here (marked * below):

* Local cost: FP-DTW eq. 1 (the geodesic distance of :mod:`fpdtw.costs`) between the
  8 joints' rotations.
* Step weights: ``D[i, q] = min(D[i-1, q] + d, D[i, q-1] + d, D[i-1, q-1] + 2 d)``, the
  diagonal step counted twice (Dixon 2005, Section 2, as we read it; pymatchmaker's
  implementation of the paper does the same). With these weights every path from
  ``(0, 0)`` to ``(i, q)`` has total weight ``1 + i + q``.
* (*) Path costs are compared normalised, ``D[i, q] / (1 + i + q)`` (mean cost per unit
  of path weight): raw costs grow with path length, so the cells nearest the origin would
  always win. ``normalize=False`` compares raw costs.
* (*) Band: the computed cells are the ``c x c`` block behind the corner; a predecessor
  outside it counts as unreachable.
* (*) Ties in the argmin: the first strict minimum, scanning the newest target column
  by increasing input frame, then the newest input row by increasing target frame
  (pymatchmaker's order).
* (*) End of the input: once ``i = m`` an INPUT or BOTH becomes TARGET (the map holds at
  ``m``); the run count counts the increment actually made.
* Streaming: after target frame ``q`` arrives, OLTW applies the increment that was
  waiting for it, then keeps growing along the input (INPUT increments, at most
  ``max_run_count + 1`` in a row) until GetInc asks for TARGET or BOTH; that increment
  waits for frame ``q + 1`` (never read before it arrives). ``M_q`` is the input index of
  the corner when the step returns: the last point of Dixon's on-line path in target
  frame ``q``. It never decreases.
* Defaults: ``c = 120`` (one second at 120 Hz; Dixon's ``c = 500`` frames is 10 s of
  audio at his 20 ms hop, longer than most of our takes), ``max_run_count = 3`` (Dixon's).

Cost per frame: one or two rows/columns of ``c`` geodesic costs, each line's costs in one
vectorised pass (the input and the last ``c`` target frames are kept joint-major), and an
argmin over ``2c`` cells, in numba.

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
from fpdtw.online.base import OnlineAligner, check_count, check_input, run_online
from fpdtw.weights import joint_weights

#: Increment codes (Dixon's names in brackets).
NONE, TARGET, INPUT, BOTH = 0, 1, 2, 3
#: Printable names of the increment codes.
INC_NAMES = {NONE: "none", TARGET: "target", INPUT: "input", BOTH: "both"}
#: Why a decision was taken: by the argmin, by the band warm-up, by the run count rule.
BY_ARGMIN, BY_WARMUP, BY_RUNCOUNT = 0, 1, 2

# state vector slots
_I, _Q, _PREV, _RUN, _PEND = 0, 1, 2, 3, 4
# decision log columns: target frame received, corner i, corner q, increment, reason,
# argmin cell (i*, q*) (-1 when no argmin was computed)
_LOG_COLS = 7


@numba.njit(cache=True)
def _work_views(work, c, k):
    """OLTW's float64 scratch as views of one buffer: the band ``D`` (c, c), the last c
    target frames joint-major ``R`` (k, 4, c) (frame q' in slot ``q' % c``), a line's
    local costs ``d`` (c) and the cost kernel's scratch ``acc`` (c)."""
    D = work[: c * c].reshape((c, c))
    R = work[c * c : c * c + 4 * k * c].reshape((k, 4, c))
    o = c * c + 4 * k * c
    return D, R, work[o : o + c], work[o + c : o + 2 * c]


@numba.njit(cache=True)
def _new_band_line(Iq, Isoa, R, D, dl, acc, c, i, q, column, wts):
    """Evaluate the new line of the band at the corner (i, q): target column q (``column``
    true; cells (i', q), i' = max(0, i - c + 1) .. i) or input row i (cells (i, q'),
    q' = max(0, q - c + 1) .. q).

    D is the (c, c) ring buffer: cell (i', q') lives at ``D[i' % c, q' % c]``; every cell
    of the ``c x c`` block behind the corner is computed, cells outside it are unreachable,
    so the line's first cell has one predecessor only (its target step in a new column,
    its input step in a new row). The line's local costs (eq. 1) are computed first, in
    one vectorised pass (:func:`fpdtw.costs._geo_line`): target frame q against the input
    joint-major ``Isoa`` (k, 4, m + 1), or input frame i against the last c target frames
    ``R`` (k, 4, c), frame q' in slot ``q' % c``; values bit-identical to
    ``_geo_frame(Iq[i'], T[q'])``. ``wts``: eq. 1's per-joint weights, or EMPTY for eq. 1
    as written (exactly the unweighted arithmetic).

    """
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
    # ring slots: of the line's running index k and of k - 1 (advanced without a modulo
    # per cell), and of its fixed index and that minus one
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
            # Dixon's weights: input and target steps add d, the diagonal 2 d. The line's
            # previous cell (x, kept in a register) is the input step in a column, the
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
    """Lowest (normalised) path cost among the newest target column and input row.

    The column is scanned first, from its lowest cell; the first minimum wins.

    """
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
    """Make the increment ``inc`` (a new target column, input row or both), then count
    the run.

    """
    if inc == 1 or inc == 3:  # TARGET or BOTH
        st[1] += 1
        _new_band_line(Iq, Isoa, R, D, dl, acc, c, st[0], st[1], True, wts)
    if inc == 2 or inc == 3:  # INPUT or BOTH
        st[0] += 1
        _new_band_line(Iq, Isoa, R, D, dl, acc, c, st[0], st[1], False, wts)
    if inc == st[2]:
        st[3] += 1
    else:
        st[3] = 1
    if inc != 3:
        st[2] = inc


@numba.njit(cache=True)
def _oltw_step(Iq, Isoa, Tq, base, q_new, work, st, c, max_run, warmup, normalize, log, wts):
    """Receive target frame ``q_new``; grow the matrix; return (M_q, number of log rows).

    Iq : float64 (m + 1, k, 4) the input; Isoa : the same joint-major (k, 4, m + 1).
    Tq : the target frames kept, frame q' in row ``q' - base``; only ``q_new`` is read,
    and copied into the ring of the last c frames (:func:`_work_views`).
    work : float64 scratch of :func:`_work_views`.
    st : int64 (5,) state: corner i, corner q, previous increment, run count, pending.
    log : int64 (rows, 7) decisions of this step (see ``_LOG_COLS``).
    wts : float64 (k,) eq. 1's per-joint weights, or EMPTY (0,) for eq. 1 as written.

    """
    m = Iq.shape[0] - 1
    D, R, dl, acc = _work_views(work, c, Iq.shape[1])
    s = q_new % c
    for j in range(Iq.shape[1]):
        for a in range(4):
            R[j, a, s] = Tq[q_new - base, j, a]
    if q_new == 0:
        D[0, 0] = _geo_frame_w(Iq[0], Tq[0 - base], wts)
        st[0] = 0
        st[1] = 0
        st[2] = 0
        st[3] = 0
        st[4] = 0
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


class OLTW(OnlineAligner):
    """Dixon's on-line time warping behind the streaming interface.

    See the module docstring for the algorithm and every choice made.

    Parameters
    ----------
    I : MotionFeatures
        Input (recorded) motion, fully known.
    c : int
        Search width (band) in frames, >= 2; default 120 (1 s at 120 Hz).
    max_run_count : int
        Dixon's MaxRunCount, >= 1: after more than this many equal increments in a row
        the other direction is forced. Default 3 (Dixon's).
    warmup : bool
        Dixon's start rule, BOTH until the band is full (``q + 1 < c``). Default True;
        False starts with the argmin at once (as pymatchmaker's frame tracker does).
    normalize : bool
        Compare path costs divided by the path weight ``1 + i + q`` (default True).
    constraint : None
        Accepted for the common constructor signature ``cls(I, w, constraint=...)`` of
        :mod:`fpdtw.app.bench`; OLTW has no local constraint (anything but None is an error).
    record : bool
        Keep every decision (:attr:`decisions`) and the on-line path (:attr:`path`).
    weights : {"none", "travel"}
        ``"travel"`` (beyond the papers, notebook 16's Q2; name ``"OLTW (weighted
        joints)"``): eq. 1 becomes ``sum_j w_j (2/pi) arccos |q_a,j . q_b,j|`` with ``w =``
        :func:`fpdtw.weights.joint_weights` of the input, computed once here.

    Attributes
    ----------
    name : str
        ``"OLTW"`` (``"OLTW c60"`` etc. for another search width).


    Paper: FP-DTW reference 3 (Dixon, DAFx 2005).
    Notebook: 20_align_a_live_performance.ipynb
    """

    name = "OLTW"
    #: ``{option: (default, {other value: label in names})}``, as the window methods'
    #: (:attr:`fpdtw.online.window.WindowAligner.options`): ``"OLTW (weighted joints)"``.
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
        self._Iq = np.ascontiguousarray(I.quats, dtype=np.float64)
        self._Isoa = np.ascontiguousarray(self._Iq.transpose(1, 2, 0))  # (k, 4, m+1)
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

    def _use_input(self, Iq, orders) -> None:
        """Eq. 1 against ``Iq`` (the input as compared with this take's rig)."""
        if Iq is not self._Iq:
            self._Iq = np.ascontiguousarray(Iq, dtype=np.float64)
            self._Isoa = np.ascontiguousarray(self._Iq.transpose(1, 2, 0))

    def _step(self, q: int) -> int:
        m, n = _oltw_step(
            self._Iq, self._Isoa, self._Tq, self.history_start, self.n_received - 1,
            self._work, self._st, self.c, self.max_run_count, self.warmup, self.normalize,
            self._log, self._wts,
        )  # fmt: skip
        if self.record:
            self._decisions.append(self._log[:n].copy())
        return int(m)

    # -- inspection --------------------------------------------------------------------
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

        Columns: target frame being processed, corner ``i``, corner ``q`` when deciding,
        increment (:data:`TARGET`, :data:`INPUT`, :data:`BOTH`), reason
        (:data:`BY_ARGMIN`, :data:`BY_WARMUP`, :data:`BY_RUNCOUNT`), argmin cell ``i*``,
        ``q*`` (-1 when no argmin was computed).
        """
        if not self.record:
            raise AlignmentError("decisions are kept only with record=True")
        if not self._decisions:
            return np.zeros((0, _LOG_COLS), dtype=np.int64)
        return np.concatenate(self._decisions)

    @property
    def path(self) -> np.ndarray:
        """Dixon's on-line path (``record=True``): the corner after every increment.

        Returns
        -------
        path : ndarray of int64, shape (L, 2)
            Cells ``(i, q)`` from ``(0, 0)``; the increments already applied (the one
            waiting for the next target frame is not included).
        """
        dec = self.decisions
        pts = [(0, 0)] if self.n_received else []
        for i, q, inc in zip(dec[:, 1], dec[:, 2], dec[:, 3]):
            nxt = (int(i) + (inc in (INPUT, BOTH)), int(q) + (inc in (TARGET, BOTH)))
            if nxt[1] < self.n_received:
                pts.append(nxt)
        return np.array(pts, dtype=np.int64).reshape(-1, 2)


def run_pair(I: MotionFeatures, T: MotionFeatures, pair_info=None, *, c: int = 120):
    """OLTW over one (input, target) pair: ``(M, seconds)`` (the experiment-grid hook).

    For :func:`fpdtw.paper.runner.run.register_algorithm` (``register_algorithm("OLTW",
    run_pair)``): a module-level function, so it pickles to worker processes.

    Returns
    -------
    M : ndarray of int64, shape (n + 1,)
    seconds : ndarray of float64, shape (n + 1,)
        Per-frame step times.

    Paper: FP-DTW reference 3 (Dixon 2005); the evaluation of Section 4.
    """
    return run_online(OLTW(I, c), T)


__all__ = ["BOTH", "BY_ARGMIN", "BY_RUNCOUNT", "BY_WARMUP", "INPUT", "OLTW", "TARGET", "run_pair"]
