"""The hardware limit of one online step, and where a step's time goes (``make bench``).

For every timed aligner :mod:`fpdtw.app.bench` asks: how close is a step to the
unavoidable work of that step on this machine? The unavoidable work of a window step is
the ``rows x cols x joints`` geodesic evaluations (FP-DTW eq. 1) of its cost window plus
the DTW accumulation of that window; the LIMIT is that work done by a lean kernel
(:func:`_limit_window`: one vectorised pass per row over the columns stored joint-major,
then the row's accumulation), on the same data (the step's own input rows and forecast
columns), timed in the same run.

How it is timed. The aligner is first streamed over each pair frame by frame
(:func:`fpdtw.online.base.run_online`, the user's view: every ``step`` call with its
Python overhead). Then a compiled replay (:func:`_replay_window` and its siblings) walks
the same frames with the map just produced and, per frame, times with the CPU's cycle
counter (``rdtsc`` on x86-64, converted to seconds by :func:`ticks_per_second`):

* ``compiled``: the aligner's own compiled step (the same function the streaming call
  runs, without Python);
* ``forecast``: its dead-reckoning forecast alone (Euler angles extrapolated, turned
  into quaternions: six ``sin``/``cos`` per joint and column, libm's, kept for exact maps);
* ``limit``: the limit kernel on the step's window (tiny windows are repeated
  ``reps`` times and divided, so the counter's own ~10 ns does not count).

Per frame, the gap ``step - limit`` splits into forecast, the rest of the compiled step
(masks, back-track, argmin, call structure) and the Python call overhead
(``step - compiled``); :mod:`fpdtw.app.bench` prints their medians.

Method A's limit is its window column, ``w_i + 1`` input frames against ``T_{n+1}`` and
their argmin; OE-DTW and OLTW have their own replays: OE-DTW's window is the whole input
against ``T_q`` (one column), OLTW's the band lines of ``c`` cells it adds in that frame
(their number is read from OLTW's own decision log).

The cycle counter exists on x86-64 only; elsewhere :data:`HAVE_CYCLES` is False and the
bench prints step times without limits.

Paper: FP-DTW Table 2 (per-frame time), eq. 1 (the geodesic distance).
"""

from __future__ import annotations

import platform
import time

import numba
import numpy as np
from llvmlite import ir
from numba.core import types
from numba.extending import intrinsic

from fpdtw.costs import _geo_line
from fpdtw.online import oedtw, oltw
from fpdtw.online import window as W

#: The CPU cycle counter is read with ``rdtsc`` (LLVM's ``readcyclecounter``): x86-64 only
#: (on AArch64 LLVM reads a register user code may not read).
HAVE_CYCLES = platform.machine().lower() in ("x86_64", "amd64")

#: A limit kernel is repeated until a timing covers about this many geodesic
#: evaluations (a few microseconds), so the counter's overhead does not count.
REP_EVALS = 4096

#: Columns of a replay record (int64, one row per target frame).
R_KIND, R_ROWS, R_COLS, R_EVALS, R_COMPILED, R_FORECAST, R_LIMIT, R_SAME = range(8)
N_REC = 8
#: ``R_KIND`` values: the step kinds of :mod:`fpdtw.online.window` (window = 3).
KIND_WINDOW = W.STEP_WINDOW

# --- the clock -----------------------------------------------------------------------


@intrinsic
def _cycles(typingctx):
    """The CPU's cycle counter (x86 ``rdtsc``: constant rate on current CPUs), int64."""
    sig = types.int64()

    def codegen(context, builder, signature, args):
        fnty = ir.FunctionType(ir.IntType(64), [])
        fn = builder.module.declare_intrinsic("llvm.readcyclecounter", fnty=fnty)
        return builder.call(fn, [])

    return sig, codegen


@numba.njit(cache=True)
def _spin(ticks):
    """Busy-wait ``ticks`` counter ticks; returns the ticks actually elapsed."""
    t0 = _cycles()
    t = t0
    while t - t0 < ticks:
        t = _cycles()
    return t - t0


_TICKS_PER_S = None


def ticks_per_second() -> float:
    """Rate of the cycle counter, ticks per second, measured against ``time.perf_counter``.

    The median of five 20 ms spins (cached for the process). On x86-64 the counter runs at
    a constant rate (the TSC), whatever the core's current clock.

    Returns
    -------
    rate : float
    """
    global _TICKS_PER_S
    if _TICKS_PER_S is None:
        if not HAVE_CYCLES:
            raise RuntimeError(f"no cycle counter on {platform.machine()} (x86-64 only)")
        _spin(1000)  # compile / load
        t0 = time.perf_counter()
        ticks = _spin(10_000_000)
        rough = ticks / (time.perf_counter() - t0)
        rates = []
        for _ in range(5):
            t0 = time.perf_counter()
            ticks = _spin(int(0.02 * rough))
            rates.append(ticks / (time.perf_counter() - t0))
        _TICKS_PER_S = float(np.median(rates))
    return _TICKS_PER_S


#: Modes of :func:`_limit_column`: Method A's argmin, OE-DTW's first column (a prefix
#: sum), OE-DTW's recursion from the previous column.
COL_ARGMIN, COL_FIRST, COL_DTW = 0, 1, 2


# --- the limit kernels -----------------------------------------------------------------


@numba.njit(cache=True)
def _accumulate_row(C, D, r, ncols):
    """Row ``r`` of the forward DTW accumulation (symmetric1) of ``C`` into ``D``: row 0 a
    prefix sum, every other row from the row above (the limit's own, row by row, so that
    each row is accumulated while its costs are in cache; :func:`fpdtw.dtw._accumulate`
    is the aligners' whole-matrix one)."""
    if r == 0:
        x = C[0, 0]
        D[0, 0] = x
        for c in range(1, ncols):
            x = x + C[0, c]
            D[0, c] = x
    else:
        x = D[r - 1, 0] + C[r, 0]
        D[r, 0] = x
        for c in range(1, ncols):
            x = C[r, c] + min(D[r - 1, c - 1], min(D[r - 1, c], x))
            D[r, c] = x


@numba.njit(cache=True)
def _scan_column(prev, cur, nrows, mode):
    """A column's argmin (:data:`COL_ARGMIN`), or its DTW accumulation in place
    (:data:`COL_FIRST`: a prefix sum; :data:`COL_DTW`: from ``prev``) and the row of the
    lowest accumulated value."""
    best = cur[0]
    bi = 0
    if mode == COL_ARGMIN:
        for i in range(1, nrows):
            if cur[i] < best:
                best = cur[i]
                bi = i
        return bi
    x = cur[0] if mode == COL_FIRST else prev[0] + cur[0]
    cur[0] = x
    best = x
    for i in range(1, nrows):
        ci = cur[i]
        if mode == COL_FIRST:
            x = x + ci
        else:
            x = min(min(prev[i - 1] + ci, prev[i] + ci), x + ci)
        cur[i] = x
        if x < best:
            best = x
            bi = i
    return bi


@numba.njit(cache=True)
def _limit_window(Iq, start, nrows, F, ncols, C, D, acc):
    """The unavoidable work of a window step: ``C[r, c] = geoDistance(I[start + r], F[.., c])``
    for ``r < nrows``, ``c < ncols`` (eq. 1), and its forward DTW accumulation ``D``.

    Iq : float64 (m + 1, k, 4); F : float64 (k, 4, >= ncols), the step's target columns
    joint-major; C, D : float64 (>= nrows, >= ncols); acc : scratch (>= ncols).
    Returns the number of geodesic evaluations, ``nrows * ncols * k``.
    """
    for r in range(nrows):
        _geo_line(Iq[start + r], F, 0, ncols, acc, C[r])
        _accumulate_row(C, D, r, ncols)
    return nrows * ncols * Iq.shape[1]


@numba.njit(cache=True)
def _limit_column(t, Isoa, start, nrows, prev, cur, acc, mode):
    """One target frame against ``nrows`` input frames, a window column (Method A, OE-DTW):
    ``cur[i] = geoDistance(I[start + i], t)`` (eq. 1), then (``mode``) the argmin
    (:data:`COL_ARGMIN`) or the DTW accumulation down the column (:data:`COL_FIRST`:
    a prefix sum; :data:`COL_DTW`: from the previous column ``prev``, symmetric1).

    t : float64 (k, 4); Isoa : float64 (k, 4, m + 1), the input joint-major.
    Returns (geodesic evaluations ``nrows * k``, row of the lowest value).
    """
    _geo_line(t, Isoa, start, start + nrows, acc, cur)
    return nrows * t.shape[0], _scan_column(prev, cur, nrows, mode)


@numba.njit(cache=True)
def _dixon_line(prev, out, n):
    """A band line's DTW accumulation in place from the previous line ``prev`` (Dixon's
    weights: the diagonal step counts its cost twice)."""
    x = prev[0] + out[0]
    out[0] = x
    for c in range(1, n):
        d = out[c]
        x = min(min(prev[c] + d, x + d), prev[c - 1] + (d + d))
        out[c] = x


@numba.njit(cache=True)
def _limit_line(a, B, lo, hi, prev, acc, out):
    """One band line of OLTW: ``out[c] = geoDistance(a, B[:, :, lo + c])`` (eq. 1) and the
    line's DTW accumulation (Dixon's weights) from the previous line ``prev``. Returns the
    geodesic evaluations."""
    _geo_line(a, B, lo, hi, acc, out)
    _dixon_line(prev, out, hi - lo)
    return (hi - lo) * a.shape[0]


# --- replays: the aligners' own compiled steps, timed per frame -----------------------


@numba.njit(cache=True)
def _replay_window(
    Iq, Tq, Te, M, prm, table, codes, F, C, D, Pcol, path, score, cF, cG, cN, cMeta, cKey,
    Isoa, reps, rec,
):  # fmt: skip
    """Replay a Method A, B or C aligner over a target along its map ``M``, timing each frame.

    Calls :func:`fpdtw.online.window._window_step` per frame (the aligner's own step;
    its result must equal ``M[q]``, else returns ``q``), then on window steps times the
    limit on the step's own rows: A, its column against ``T_q`` and the argmin
    (:func:`_limit_column`); B and C, the forecast alone and :func:`_limit_window` on the
    step's forecast columns. Checks that the limit's costs equal the step's
    (``R_SAME``). Returns -1 when the replay reproduced the map. ``Isoa`` : the input
    joint-major (Method A); ``rec`` : int64 (n, N_REC).
    """
    n = Tq.shape[0]
    W1 = C.shape[0]
    state = np.zeros(1, dtype=np.int64)  # Type V's start state, as in run_group
    out = np.zeros(W.N_OUT, dtype=np.int64)
    Cf = np.empty((W1, W1))
    Cl = np.empty((W1, W1))
    Dl = np.empty((W1, W1))
    acc = np.empty(W1)
    cur = np.empty(W1)
    w = prm[W.P_W]
    is_a = prm[W.P_METHOD] == W.METHOD_A
    with_prev = prm[W.P_METHOD] == W.METHOD_B or prm[W.P_READING] == W.C_SQUARE_TN
    unweighted = np.empty(0)  # eq. 1 as written
    for q in range(n):
        t0 = _cycles()
        m_next = W._window_step(
            Iq, Tq, Te, q, M, state, prm, table, codes, F, C, D, Pcol, path, score,
            cF, cG, cN, cMeta, cKey, out, unweighted,
        )  # fmt: skip
        t1 = _cycles()
        if m_next != M[q]:
            return q
        rec[q, R_KIND] = out[0]
        rec[q, R_COMPILED] = t1 - t0
        if out[0] != W.STEP_WINDOW:
            continue
        nrows = out[1]
        ncols = out[2]
        start = M[q - 1] + out[4]  # the window's first row (a clipping band may skip M_n)
        rec[q, R_ROWS] = nrows
        rec[q, R_COLS] = ncols
        ev = 0
        if is_a:
            t0 = _cycles()
            for _ in range(reps):
                ev, _ = _limit_column(Tq[q], Isoa, start, nrows, cur, cur, acc, COL_ARGMIN)
            t1 = _cycles()
            _geo_line(Tq[q], Isoa, start, start + nrows, acc, cur)
            same = 1
            for r in range(nrows):
                if cur[r] != C[r, 0]:
                    same = 0
        else:
            # the step's costs, before the forecast is recomputed (Type V masks are +inf)
            for r in range(nrows):
                for c in range(ncols):
                    Cf[r, c] = C[r, c]
            f0 = _cycles()
            W._forecast_window(
                Tq, Te, q, w, with_prev, codes, F, prm[W.P_SHIFT], prm[W.P_HOLD] != 0
            )
            rec[q, R_FORECAST] = _cycles() - f0
            same = 1
            t0 = _cycles()
            for _ in range(reps):
                ev = _limit_window(Iq, start, nrows, F, ncols, Cl, Dl, acc)
            t1 = _cycles()
            for r in range(nrows):
                for c in range(ncols):
                    if Cf[r, c] != Cl[r, c] and Cf[r, c] != np.inf:
                        same = 0
        rec[q, R_LIMIT] = (t1 - t0) // reps
        rec[q, R_EVALS] = ev
        rec[q, R_SAME] = same
    return -1


def window_reps(rows: int, cols: int, k: int) -> int:
    """Repetitions of a limit kernel of ``rows x cols x k`` evaluations per timing."""
    return max(1, -(-REP_EVALS // max(1, rows * cols * k)))


@numba.njit(cache=True)
def _replay_oe(Isoa, Tq, cols, wd, c, reps, rec, M):
    """Replay OE-DTW (symmetric1, end point = argmin): its compiled step
    (:func:`fpdtw.online.oedtw._oe_step`), then the limit, the whole input against
    ``T_q`` accumulated from the previous column (:func:`_limit_column`)."""
    n = Tq.shape[0]
    m1 = Isoa.shape[2]
    prev = np.zeros(m1)
    cur = np.empty(m1)
    acc = np.empty(m1)
    chk = np.empty(m1)
    for q in range(n):
        t0 = _cycles()
        e = oedtw._oe_step(Isoa, Tq, cols, q, wd, -1.0, c)
        t1 = _cycles()
        if e != M[q]:
            return q
        rec[q, R_KIND] = KIND_WINDOW
        rec[q, R_COMPILED] = t1 - t0
        rec[q, R_ROWS] = m1
        rec[q, R_COLS] = 1
        mode = COL_FIRST if q == 0 else COL_DTW
        ev = 0
        t0 = _cycles()
        for _ in range(reps):
            ev, _ = _limit_column(Tq[q], Isoa, 0, m1, prev, cur, acc, mode)
        t1 = _cycles()
        rec[q, R_LIMIT] = (t1 - t0) // reps
        rec[q, R_EVALS] = ev
        _geo_line(Tq[q], Isoa, 0, m1, acc, chk)
        same = 1
        for i in range(m1):
            if chk[i] != c[i]:
                same = 0
        rec[q, R_SAME] = same
        prev, cur = cur, prev
    return -1


@numba.njit(cache=True)
def _oltw_lines(q, pend, i0, q0, log, nlog, lines):
    """The band lines OLTW added at target frame q, as rows ``(column?, i, q)`` of
    ``lines``: the increment that waited for the frame (corner (i0, q0) before it), then
    one input row per INPUT decision of the step's log. Returns their number."""
    nl = 0
    if q == 0:
        lines[0, 0] = 1
        lines[0, 1] = 0
        lines[0, 2] = 0
        return 1
    if pend == oltw.TARGET or pend == oltw.BOTH:
        lines[nl, 0] = 1
        lines[nl, 1] = i0
        lines[nl, 2] = q0 + 1
        nl += 1
    if pend == oltw.BOTH:
        lines[nl, 0] = 0
        lines[nl, 1] = i0 + 1
        lines[nl, 2] = q0 + 1
        nl += 1
    for r in range(min(nlog, log.shape[0])):
        if log[r, 3] == oltw.INPUT:
            lines[nl, 0] = 0
            lines[nl, 1] = log[r, 1] + 1
            lines[nl, 2] = log[r, 2]
            nl += 1
    return nl


@numba.njit(cache=True)
def _replay_oltw(
    Iq, Isoa, Tq, work, st, c, max_run, warmup, normalize, log,
    Tsoa, reps, rec, M,
):  # fmt: skip
    """Replay OLTW: its compiled step (:func:`fpdtw.online.oltw._oltw_step`), then the
    limit, the band lines the step added (:func:`_oltw_lines`, ``c`` cells each at most),
    each line's geodesic costs and accumulation (:func:`_limit_line`)."""
    n = Tq.shape[0]
    prev = np.zeros(c)
    out = np.empty(c)
    acc = np.empty(c)
    lines = np.zeros((log.shape[0] + 3, 3), dtype=np.int64)
    unweighted = np.empty(0)  # eq. 1 as written
    for q in range(n):
        pend = st[4]
        i0 = st[0]
        q0 = st[1]
        t0 = _cycles()
        mq, nlog = oltw._oltw_step(
            Iq, Isoa, Tq, 0, q, work, st, c, max_run, warmup, normalize, log, unweighted
        )
        t1 = _cycles()
        if mq != M[q]:
            return q
        rec[q, R_KIND] = KIND_WINDOW
        rec[q, R_COMPILED] = t1 - t0
        nl = _oltw_lines(q, pend, i0, q0, log, nlog, lines)
        ev = 0
        t0 = _cycles()
        for _ in range(reps):
            ev = 0
            for li in range(nl):
                i = lines[li, 1]
                qq = lines[li, 2]
                if lines[li, 0] == 1:
                    ev += _limit_line(Tq[qq], Isoa, max(0, i - c + 1), i + 1, prev, acc, out)
                else:
                    ev += _limit_line(Iq[i], Tsoa, max(0, qq - c + 1), qq + 1, prev, acc, out)
        t1 = _cycles()
        rec[q, R_LIMIT] = (t1 - t0) // reps
        rec[q, R_EVALS] = ev
        rec[q, R_ROWS] = nl
        rec[q, R_COLS] = ev // Iq.shape[1]
        rec[q, R_SAME] = -1  # the step keeps no costs to compare
    return -1


def _soa(X) -> np.ndarray:
    """Frames (n, k, 4) joint-major, (k, 4, n), C-contiguous."""
    return np.ascontiguousarray(np.asarray(X, dtype=np.float64).transpose(1, 2, 0))


def replay(aligner, T, M) -> np.ndarray | None:
    """Per-frame record of an aligner over target ``T`` along its map ``M``.

    Parameters
    ----------
    aligner : OnlineAligner
        Method A, B or C (without a shared cache), OE-DTW (symmetric1, unnormalised) or
        OLTW; reset here.
    T : MotionFeatures
    M : ndarray of int64, shape (n,)
        The map the aligner produced streaming over ``T``.

    Returns
    -------
    rec : ndarray of int64, shape (n, N_REC), or None
        Columns ``R_*``, times in cycle-counter ticks; None for an aligner without a
        replay (OPW, a registry entry of another kind) or without a cycle counter.

    Raises
    ------
    RuntimeError
        The replay did not reproduce ``M`` (it runs the aligner's own compiled step).
    """
    from fpdtw.online.oedtw import OEDTW
    from fpdtw.online.oltw import OLTW

    if not HAVE_CYCLES:
        return None
    a = aligner
    n = T.n_frames
    rec = np.zeros((n, N_REC), dtype=np.int64)
    Tq = np.ascontiguousarray(T.quats, dtype=np.float64)
    Te = np.ascontiguousarray(T.euler, dtype=np.float64)
    M = np.ascontiguousarray(M, dtype=np.int64)
    k = Tq.shape[1]
    if isinstance(a, W.WindowAligner) and a.cache is None:
        a.reset()
        reps = window_reps(a.w + 1, 1 if a._params[W.P_METHOD] == W.METHOD_A else a.w + 1, k)
        q = _replay_window(
            a._Iq, Tq, Te, M, a._params, a._table, a._codes, a._F, a._C, a._D, a._P,
            a._path, a._score, *a._cache_arrays, _soa(a._Iq), reps, rec,
        )  # fmt: skip
    elif isinstance(a, OEDTW) and a._wd == 1.0 and not a.normalize:
        a.reset()
        cols = np.empty((n, a.I.n_frames))
        reps = window_reps(a.I.n_frames, 1, k)
        q = _replay_oe(a._Isoa, Tq, cols, a._wd, a._c, reps, rec, M)
    elif isinstance(a, OLTW):
        a.reset()
        reps = window_reps(a.c, 1, k)
        q = _replay_oltw(
            a._Iq, a._Isoa, Tq, a._work, a._st, a.c, a.max_run_count, a.warmup, a.normalize,
            a._log, _soa(Tq), reps, rec, M,
        )  # fmt: skip
    else:
        return None
    a.reset()
    if q >= 0:
        raise RuntimeError(f"{a.name}: the compiled replay left the map at target frame {q}")
    return rec


__all__ = [
    "HAVE_CYCLES",
    "N_REC",
    "REP_EVALS",
    "replay",
    "ticks_per_second",
    "window_reps",
]
