"""The hardware limit of one online step, and where a step's time goes (``make bench``).

For every timed aligner :mod:`fpdtw.paper.bench` asks: how close is a step to the
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
  ``reps`` times and divided, so the counter's own ~10 ns does not count);
* ``limit32``: the same kernel in float32 (the issue's "precision, if it pays" question),
  and whether the float32 window would change the step's choice (``flip``).

Per frame, the gap ``step - limit`` splits into forecast, the rest of the compiled step
(masks, back-track, argmin, call structure) and the Python call overhead
(``step - compiled``); :mod:`fpdtw.paper.bench` prints their medians.

Method A, OE-DTW and OLTW have their own replays: A's window is ``w_i + 1`` input frames
against ``T_{n+1}``, OE-DTW's the whole input against ``T_q`` (one column), OLTW's the
band lines of ``c`` cells it adds in that frame (their number is read from OLTW's own
decision log).

The cycle counter exists on x86-64 only; elsewhere :data:`HAVE_CYCLES` is False and the
bench prints step times without limits.

Paper: FP-DTW Table 2 (per-frame time), eq. 1 (the geodesic distance).
Notebook: 09_table2_timing.ipynb
"""

from __future__ import annotations

import math
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
from fpdtw.online.method_a import _A_HEADER as A_HEADER
from fpdtw.online.method_a import (
    A_KIND,
    A_NS,
    A_STATE,
    A_TIES_HIGH,
    A_TYPEV,
    A_WI,
    A_WINDOW,
    _a_step,
)
from fpdtw.online.typev import MAX_ADVANCE

_TWO_OVER_PI = 2.0 / math.pi

#: The CPU cycle counter is read with ``rdtsc`` (LLVM's ``readcyclecounter``): x86-64 only
#: (on AArch64 LLVM reads a register user code may not read).
HAVE_CYCLES = platform.machine().lower() in ("x86_64", "amd64")

#: A limit kernel is repeated until a timing covers about this many geodesic
#: evaluations (a few microseconds), so the counter's overhead does not count.
REP_EVALS = 4096

#: Columns of a replay record (int64, one row per target frame).
(
    R_KIND, R_ROWS, R_COLS, R_EVALS, R_COMPILED, R_FORECAST, R_LIMIT, R_LIMIT32, R_FLIP, R_SAME,
) = range(10)  # fmt: skip
N_REC = 10
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
    prefix sum, every other row from the row above. Any float dtype (no constants)."""
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
    lowest accumulated value. Any float dtype (no constants)."""
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


# float32: the same kernels in single precision (16 lanes instead of 8), for the
# measurement of the "precision, if it pays"; the polynomial is the float64 one
# rounded to float32 (more terms than float32 needs: an upper bound of its time)
_F32_ONE = np.float32(1.0)
_F32_HALF = np.float32(0.5)
_F32_PI_2 = np.float32(math.pi / 2.0)
_F32_TWO = np.float32(2.0)
_F32_2PI = np.float32(_TWO_OVER_PI)
_P32 = tuple(np.float32(c) for c in (
    0.16666666666666669, 0.07499999999998433, 0.04464285714635543, 0.030381944138531247,
    0.02237217294214989, 0.017352392720869973, 0.013971212973552933, 0.011479177415184906,
    0.01032281435018578, 0.005457506718640358, 0.01740087944269402, -0.014851887071247204,
    0.028757851367421566,
))  # fmt: skip


@numba.njit(cache=True, inline="always")
def _acos01_f32(x):
    """:func:`fpdtw.costs._acos01` in float32 arithmetic."""
    big = x > _F32_HALF
    z = (_F32_ONE - x) * _F32_HALF if big else x * x
    s = np.float32(math.sqrt(z)) if big else x
    p = _P32[12]
    p = _P32[11] + z * p
    p = _P32[10] + z * p
    p = _P32[9] + z * p
    p = _P32[8] + z * p
    p = _P32[7] + z * p
    p = _P32[6] + z * p
    p = _P32[5] + z * p
    p = _P32[4] + z * p
    p = _P32[3] + z * p
    p = _P32[2] + z * p
    p = _P32[1] + z * p
    p = _P32[0] + z * p
    a = s + s * (z * p)
    return _F32_TWO * a if big else _F32_PI_2 - a


@numba.njit(cache=True)
def _geo_line_f32(a, B, lo, hi, acc, out):
    """:func:`_geo_line` in float32 (a, B, acc, out float32)."""
    n = hi - lo
    for c in range(n):
        acc[c] = 0
    for j in range(a.shape[0]):
        a0 = a[j, 0]
        a1 = a[j, 1]
        a2 = a[j, 2]
        a3 = a[j, 3]
        b0 = B[j, 0, lo:hi]
        b1 = B[j, 1, lo:hi]
        b2 = B[j, 2, lo:hi]
        b3 = B[j, 3, lo:hi]
        for c in range(n):
            d = abs(a0 * b0[c] + a1 * b1[c] + a2 * b2[c] + a3 * b3[c])
            acc[c] += _acos01_f32(min(d, _F32_ONE))
    for c in range(n):
        out[c] = acc[c] * _F32_2PI


@numba.njit(cache=True)
def _limit_window_f32(Iq, start, nrows, F, ncols, C, D, acc):
    """:func:`_limit_window` in float32 (every array float32)."""
    for r in range(nrows):
        _geo_line_f32(Iq[start + r], F, 0, ncols, acc, C[r])
        _accumulate_row(C, D, r, ncols)
    return nrows * ncols * Iq.shape[1]


@numba.njit(cache=True)
def _limit_column_f32(t, Isoa, start, nrows, prev, cur, acc, mode):
    """:func:`_limit_column` in float32."""
    _geo_line_f32(t, Isoa, start, start + nrows, acc, cur)
    return nrows * t.shape[0], _scan_column(prev, cur, nrows, mode)


@numba.njit(cache=True)
def _dixon_line(prev, out, n):
    """A band line's DTW accumulation in place from the previous line ``prev`` (Dixon's
    weights: the diagonal step counts its cost twice, written ``d + d``, exactly
    ``2 d`` in any float dtype)."""
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


@numba.njit(cache=True)
def _limit_line_f32(a, B, lo, hi, prev, acc, out):
    """:func:`_limit_line` in float32."""
    _geo_line_f32(a, B, lo, hi, acc, out)
    _dixon_line(prev, out, hi - lo)
    return (hi - lo) * a.shape[0]


# --- replays: the aligners' own compiled steps, timed per frame -----------------------


@numba.njit(cache=True)
def _allowed(state, typev, table, allow):
    """Type V: the offsets 0..3 allowed in ``state`` (all without the constraint)."""
    for a in range(4):
        allow[a] = 1 if (not typev or table[state, a] >= 0) else 0
    return MAX_ADVANCE if typev else np.iinfo(np.int64).max


@numba.njit(cache=True)
def _replay_window(
    Iq, Tq, Te, M, prm, table, codes, F, C, D, Pcol, path, score, cF, cG, cN, cMeta, cKey,
    Iq32, reps, rec,
):  # fmt: skip
    """Replay a Method B or C aligner over a target along its map ``M``, timing each frame.

    Calls :func:`fpdtw.online.window._forecast_step` per frame (the aligner's own step;
    its result must equal ``M[q]``, else returns ``q``), then on window steps times the
    forecast alone, :func:`_limit_window` and :func:`_limit_window_f32` on the step's own
    rows and forecast columns, and checks the limit's costs equal the step's (``R_SAME``)
    and whether float32 costs would change the choice (``R_FLIP``). Returns -1 when the
    replay reproduced the map. ``rec`` : int64 (n, N_REC).
    """
    n = Tq.shape[0]
    W1 = C.shape[0]
    k = Iq.shape[1]
    state = np.zeros(1, dtype=np.int64)  # Type V's start state, as in run_group
    out = np.zeros(4, dtype=np.int64)
    Cl = np.empty((W1, W1))
    Dl = np.empty((W1, W1))
    acc = np.empty(W1)
    F32 = np.empty((k, 4, W1), dtype=np.float32)
    C32 = np.empty((W1, W1), dtype=np.float32)
    D32 = np.empty((W1, W1), dtype=np.float32)
    acc32 = np.empty(W1, dtype=np.float32)
    Cf = np.empty((W1, W1))
    Df = np.empty((W1, W1))
    P2 = np.empty(W1, dtype=np.int64)
    path2 = np.empty((2 * W1, 2), dtype=np.int64)
    score2 = np.empty(W1)
    allow = np.ones(4, dtype=np.int64)
    typev = prm[W.P_TYPEV] != 0
    w = prm[W.P_W]
    is_b = prm[W.P_METHOD] == W.METHOD_B
    reading = prm[W.P_READING]
    with_prev = is_b or reading == W.C_SQUARE_TN
    for q in range(n):
        s_before = state[0]
        t0 = _cycles()
        m_next = W._forecast_step(
            Iq, Tq, Te, q, M, state, prm, table, codes, F, C, D, Pcol, path, score,
            cF, cG, cN, cMeta, cKey, out,
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
        start = M[q - 1]
        rec[q, R_ROWS] = nrows
        rec[q, R_COLS] = ncols
        # the step's costs, before the forecast is recomputed (Type V masks are +inf)
        for r in range(nrows):
            for c in range(ncols):
                Cf[r, c] = C[r, c]
        t0 = _cycles()
        W._forecast_window(Tq, Te, q, w, with_prev, codes, F, prm[W.P_SHIFT], prm[W.P_HOLD] != 0)
        t1 = _cycles()
        rec[q, R_FORECAST] = t1 - t0
        t0 = _cycles()
        for _ in range(reps):
            ev = _limit_window(Iq, start, nrows, F, ncols, Cl, Dl, acc)
        t1 = _cycles()
        rec[q, R_LIMIT] = (t1 - t0) // reps
        rec[q, R_EVALS] = ev
        same = 1
        for r in range(nrows):
            for c in range(ncols):
                if Cf[r, c] != Cl[r, c] and Cf[r, c] != np.inf:
                    same = 0
        rec[q, R_SAME] = same
        for j in range(k):
            for a in range(4):
                for c in range(ncols):
                    F32[j, a, c] = F[j, a, c]
        t0 = _cycles()
        for _ in range(reps):
            _limit_window_f32(Iq32, start, nrows, F32, ncols, C32, D32, acc32)
        t1 = _cycles()
        rec[q, R_LIMIT32] = (t1 - t0) // reps
        # the float32 window's choice (Type V masks as in the step)
        for r in range(nrows):
            for c in range(ncols):
                Cf[r, c] = C32[r, c] if Cf[r, c] != np.inf else np.inf
        limit = _allowed(s_before, typev, table, allow)
        if is_b:
            off, _ = W._choose_b(
                Cf, nrows, ncols, limit, allow, Df, P2, path2, prm[W.P_INPUT_FIRST] != 0
            )
        else:
            off = W._choose_c(
                Cf, nrows, ncols, limit, allow, Df, score2, reading, prm[W.P_TIES_HIGH] != 0
            )
        rec[q, R_FLIP] = 1 if start + off != m_next else 0
    return -1


def window_reps(rows: int, cols: int, k: int) -> int:
    """Repetitions of a limit kernel of ``rows x cols x k`` evaluations per timing."""
    return max(1, -(-REP_EVALS // max(1, rows * cols * k)))


@numba.njit(cache=True)
def _replay_a(Iq, Tq, M, C, iwork, Isoa, Isoa32, Tq32, reps, rec):
    """Replay Method A along its map ``M`` (see :func:`_replay_window`): its compiled step
    (:func:`fpdtw.online.method_a._a_step`), then the limit, ``w_i + 1`` input frames
    against ``T_q`` and their argmin (:func:`_limit_column`), in float64 and float32."""
    n = Tq.shape[0]
    W1 = C.shape[0]
    cur = np.empty(W1)
    acc = np.empty(W1)
    chk = np.empty(W1)
    cur32 = np.empty(W1, dtype=np.float32)
    acc32 = np.empty(W1, dtype=np.float32)
    allow = np.ones(4, dtype=np.int64)
    typev = iwork[A_TYPEV] != 0
    ns = iwork[A_NS]
    table = iwork[A_HEADER : A_HEADER + 4 * ns].reshape((ns, 4))
    for q in range(n):
        s_before = iwork[A_STATE]
        t0 = _cycles()
        m_next = _a_step(Iq, Tq, q, M, C, iwork)
        t1 = _cycles()
        if m_next != M[q]:
            return q
        rec[q, R_COMPILED] = t1 - t0
        if iwork[A_KIND] != A_WINDOW:
            rec[q, R_KIND] = W.STEP_FIRST if q == 0 else W.STEP_END
            continue
        rec[q, R_KIND] = KIND_WINDOW
        start = M[q - 1]
        nrows = iwork[A_WI] + 1
        rec[q, R_ROWS] = nrows
        rec[q, R_COLS] = 1
        ev = 0
        t0 = _cycles()
        for _ in range(reps):
            ev, _ = _limit_column(Tq[q], Isoa, start, nrows, cur, cur, acc, COL_ARGMIN)
        t1 = _cycles()
        rec[q, R_LIMIT] = (t1 - t0) // reps
        rec[q, R_EVALS] = ev
        _geo_line(Tq[q], Isoa, start, start + nrows, acc, chk)
        same = 1
        for r in range(nrows):
            if chk[r] != C[r]:
                same = 0
        rec[q, R_SAME] = same
        t0 = _cycles()
        for _ in range(reps):
            _limit_column_f32(Tq32[q], Isoa32, start, nrows, cur32, cur32, acc32, COL_ARGMIN)
        t1 = _cycles()
        rec[q, R_LIMIT32] = (t1 - t0) // reps
        # the float32 costs' choice (Type V and ties as in the step)
        limit = _allowed(s_before, typev, table, allow)
        best = -1
        for r in range(nrows):
            if W._is_allowed(r, limit, allow):
                v = cur32[r]
                if best < 0 or v < cur32[best] or (iwork[A_TIES_HIGH] != 0 and v == cur32[best]):
                    best = r
        rec[q, R_FLIP] = 1 if start + max(best, 0) != m_next else 0
    return -1


@numba.njit(cache=True)
def _replay_oe(Isoa, Tq, cols, wd, c, Isoa32, Tq32, reps, rec, M):
    """Replay OE-DTW (symmetric1, end point = argmin): its compiled step
    (:func:`fpdtw.online.oedtw._oe_step`), then the limit, the whole input against
    ``T_q`` accumulated from the previous column (:func:`_limit_column`), in float64 and
    float32 (whose own recursion gives the float32 end point, for ``R_FLIP``)."""
    n = Tq.shape[0]
    m1 = Isoa.shape[2]
    prev = np.zeros(m1)
    cur = np.empty(m1)
    acc = np.empty(m1)
    chk = np.empty(m1)
    prev32 = np.zeros(m1, dtype=np.float32)
    cur32 = np.empty(m1, dtype=np.float32)
    acc32 = np.empty(m1, dtype=np.float32)
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
        e32 = 0
        t0 = _cycles()
        for _ in range(reps):
            _, e32 = _limit_column_f32(Tq32[q], Isoa32, 0, m1, prev32, cur32, acc32, mode)
        t1 = _cycles()
        rec[q, R_LIMIT32] = (t1 - t0) // reps
        rec[q, R_FLIP] = 1 if e32 != e else 0
        prev, cur = cur, prev
        prev32, cur32 = cur32, prev32
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
    Tsoa, Iq32, Isoa32, Tq32, Tsoa32, reps, rec, M,
):  # fmt: skip
    """Replay OLTW: its compiled step (:func:`fpdtw.online.oltw._oltw_step`), then the
    limit, the band lines the step added (:func:`_oltw_lines`, ``c`` cells each at most),
    each line's geodesic costs and accumulation (:func:`_limit_line`), in float64 and
    float32."""
    n = Tq.shape[0]
    prev = np.zeros(c)
    out = np.empty(c)
    acc = np.empty(c)
    prev32 = np.zeros(c, dtype=np.float32)
    out32 = np.empty(c, dtype=np.float32)
    acc32 = np.empty(c, dtype=np.float32)
    lines = np.zeros((log.shape[0] + 3, 3), dtype=np.int64)
    for q in range(n):
        pend = st[4]
        i0 = st[0]
        q0 = st[1]
        t0 = _cycles()
        mq, nlog = oltw._oltw_step(Iq, Isoa, Tq, 0, q, work, st, c, max_run, warmup, normalize, log)
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
        t0 = _cycles()
        for _ in range(reps):
            for li in range(nl):
                i = lines[li, 1]
                qq = lines[li, 2]
                if lines[li, 0] == 1:
                    lo = max(0, i - c + 1)
                    _limit_line_f32(Tq32[qq], Isoa32, lo, i + 1, prev32, acc32, out32)
                else:
                    lo = max(0, qq - c + 1)
                    _limit_line_f32(Iq32[i], Tsoa32, lo, qq + 1, prev32, acc32, out32)
        t1 = _cycles()
        rec[q, R_LIMIT32] = (t1 - t0) // reps
        rec[q, R_FLIP] = -1  # not checked
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

    Notebook: 09_table2_timing.ipynb
    """
    from fpdtw.online.method_a import MethodA
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
    if isinstance(a, W.ForecastAligner) and a.cache is None:
        a.reset()
        reps = window_reps(a.w + 1, a.w + 1, k)
        q = _replay_window(
            a._Iq, Tq, Te, M, a._params, a._table, a._codes, a._F, a._C, a._D, a._P,
            a._path, a._score, *a._cache_arrays, a._Iq.astype(np.float32), reps, rec,
        )  # fmt: skip
    elif isinstance(a, MethodA):
        a.reset()
        reps = window_reps(a.w + 1, 1, k)
        Isoa = _soa(a._Iq)
        q = _replay_a(
            a._Iq, Tq, M, a._C, a._iwork, Isoa, Isoa.astype(np.float32),
            Tq.astype(np.float32), reps, rec,
        )  # fmt: skip
    elif isinstance(a, OEDTW) and a._wd == 1.0 and not a.normalize:
        a.reset()
        cols = np.empty((n, a.I.n_frames))
        reps = window_reps(a.I.n_frames, 1, k)
        q = _replay_oe(
            a._Isoa, Tq, cols, a._wd, a._c, a._Isoa.astype(np.float32),
            Tq.astype(np.float32), reps, rec, M,
        )  # fmt: skip
    elif isinstance(a, OLTW):
        a.reset()
        Tsoa = _soa(Tq)
        reps = window_reps(a.c, 1, k)
        q = _replay_oltw(
            a._Iq, a._Isoa, Tq, a._work, a._st, a.c, a.max_run_count, a.warmup, a.normalize,
            a._log, Tsoa, a._Iq.astype(np.float32), a._Isoa.astype(np.float32),
            Tq.astype(np.float32), Tsoa.astype(np.float32), reps, rec, M,
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
