"""Shared machinery of the FP-DTW window methods A, B and C (Algorithms 1-3), compiled.

The optimised version of :func:`fpdtw.plain.method_a_step`, :func:`~fpdtw.plain.method_b_step`
and :func:`~fpdtw.plain.method_c_step` (read those first: the same steps, line by line in
the paper's notation; ``tests/test_plain.py`` holds the maps equal):

* numba kernels for one step: dead-reckoning forecast -> quaternions -> geodesic cost
  window -> accumulation (forward for B, reverse for C) -> back-tracking (B) or argmin
  (A, C), all into scratch buffers the aligner preallocates once; :func:`_window_step`
  is the whole step of any of the three methods;
* :class:`WindowSnapshot`, the debug record of the last step (``record=True``), used to
  draw the paper's Fig. 2 and Fig. 4 from a real run;
* :class:`WindowAligner`, the common base class: argument checks, the work buffers, the
  end-of-input rule, the Type V state, the snapshot; :class:`ForecastAligner` adds the
  warm-up and the shared :class:`WindowCache` of Methods B and C.

Window sizes: the input window is always ``{I_{M_n}..I_{M_n+w_i}}``, ``w_i + 1`` rows
(``w_i`` here: the offset of the window's last row, as in Algorithms 1 and 2;
:func:`fpdtw.plain.method_c_step` writes Algorithm 3's line 6 as printed, ``w_i = w``, and
names the rows it keeps ``rows``); Method C's readings
differ in how far it reaches (the default square window: ``w_i = min(w - 1, m - M_n)``,
``w`` rows; the literal one: ``w_i = min(w, m - M_n)``; see
:class:`~fpdtw.online.method_c.MethodC`).

Speed. The ``(w_i + 1) x w`` geodesic cost window, recomputed every frame, dominates.
Its inner loop runs over the forecast frames, stored joint-major as ``F[j, c, col]``
(structure of arrays), so that LLVM vectorises it; the ``arccos`` of eq. 1 is
:func:`fpdtw.costs._acos01`, a branch-free polynomial arccos on [0, 1] (1 ulp from
``math.acos``) that vectorises, where libm's ``acos`` is a scalar call five times slower.

Kept because removing them was measured to cost more than 10 % (2026-11-25; each removal
was a commit of its own, then reverted; the commands are in docs/performance.md):

* the one-call stream path (:func:`_stream_step`): streaming through the general Python
  step instead made make bench's median step of Ma 1.9 times as long (2.9 to 5.5 us) and
  of Methods B and C at w = 10 1.08 to 1.19 times (w = 40 and 80: within 4 %); paired
  runs on one core, five repetitions;
* the two flat work buffers (:func:`_work_views`) and the int64 parameter vector (``prm``,
  ``P_*``): the one-call path reads them, passing two buffers instead of nineteen arrays.
  Removed on top of the stream path's removal they cost nothing measurable; they were not
  measured with the stream path kept, and stay with it;
* the window cache shared by the aligners of a pair (:class:`WindowCache`,
  :func:`run_group`): without it (and the three above) the grid's compute time on 316
  pairs x 41 algorithms (two workers) was 316-344 s against 135-161 s.
"""

from __future__ import annotations

import math
from abc import abstractmethod
from dataclasses import dataclass

import numba
import numpy as np

from fpdtw.costs import _geo_frame_w, _geo_line, _geo_line_w
from fpdtw.dtw import _accumulate
from fpdtw.errors import AlignmentError
from fpdtw.forecast import _euler_to_quat, order_codes
from fpdtw.motion.features import Frame, MotionFeatures
from fpdtw.online.base import OnlineAligner, check_count, check_input, compiled_frame
from fpdtw.online.typev import MAX_ADVANCE, resolve_constraint
from fpdtw.weights import joint_weights

_TWO_OVER_PI = 2.0 / math.pi

#: ``D[0, 0]`` is set to this before Method B back-tracks (Algorithm 2).
B_CORNER = 10000.0

# --- one step's kernels ----------------------------------------------------------------


@numba.njit(cache=True)
def _forecast_columns(Tq, Te, q, first, last, codes, F, c0=0, shift=0, hold=False):
    """Fill ``F[j, :, c0 + i]`` for i = first..last-1 with the frame ``i + shift`` frames
    ahead of T_{n+1} (= T[q]).

    A frame 0 ahead is T_{n+1} itself (its received quaternion); a frame ``i >= 1`` ahead
    is T_{n+1} + i * (T_{n+1} - T_n) in Euler angles (dead reckoning), as quaternions, or
    T_{n+1} itself when ``hold`` (zero-order hold).

    Plain version: fpdtw.plain.forecast_joints, then fpdtw.plain.euler_to_quat.
    """
    k = Tq.shape[1]
    for i in range(first, last):
        col = c0 + i
        ahead = i + shift
        if ahead == 0 or hold:
            for j in range(k):
                for a in range(4):
                    F[j, a, col] = Tq[q, j, a]
            continue
        fi = float(ahead)
        for j in range(k):
            e0 = Te[q, j, 0] + fi * (Te[q, j, 0] - Te[q - 1, j, 0])
            e1 = Te[q, j, 1] + fi * (Te[q, j, 1] - Te[q - 1, j, 1])
            e2 = Te[q, j, 2] + fi * (Te[q, j, 2] - Te[q - 1, j, 2])
            qw, qx, qy, qz = _euler_to_quat(e0, e1, e2, codes[j])
            F[j, 0, col] = qw
            F[j, 1, col] = qx
            F[j, 2, col] = qy
            F[j, 3, col] = qz


@numba.njit(cache=True)
def _forecast_window(Tq, Te, q, w, with_prev, codes, F, shift=0, hold=False):
    """Fill ``F[j, :, col]`` (k, 4, ncols) with the target window of the step at q.

    with_prev (Method B; Method C's "square-tn" reading): col 0 = T_n (= T[q-1]), then
    the ``w`` columns of :func:`_forecast_columns` (``shift = 0`` starts with T_{n+1}
    itself, the paper's column ``T_{n+1}``; ``shift = 1`` with the first forecast).
    Returns the number of columns.
    """
    c0 = 0
    if with_prev:
        for j in range(Tq.shape[1]):
            for a in range(4):
                F[j, a, 0] = Tq[q - 1, j, a]
        c0 = 1
    _forecast_columns(Tq, Te, q, 0, w, codes, F, c0, shift, hold)
    return c0 + w


@numba.njit(cache=True)
def _cost_window(Iq, start, nrows, F, ncols, C, wts):
    """C[r, col] = geoDistance(I[start + r], F[:, :, col]) (eq. 1), r < nrows, col < ncols;
    ``wts``: per-joint weights, or empty for eq. 1 as written.

    Plain version: fpdtw.plain.cost_matrix.
    """
    acc = np.empty(ncols)
    for r in range(nrows):
        _geo_line_w(Iq[start + r], F, 0, ncols, acc, C[r], wts)


@numba.njit(cache=True)
def _fill_shared(Iq, Tq, Te, q, codes, start, nrows, w, c0, C, cF, cG, cN, cMeta, cKey):
    """Fill ``C[:nrows, c0:c0 + w]`` from a :class:`WindowCache` (computing what it lacks).

    The cache holds the dead-reckoned forecast ``[T_{n+1}, T_{n+1} + delta, ...]`` of step
    ``cMeta[0]`` (``cMeta[1]`` columns of it in ``cF``) and, per input frame r, the costs
    ``cG[r, :cN[r]]`` against it. A new step, or other frames than the cached ones at the
    same step (checked against ``cKey``), empties it first.
    """
    k = Tq.shape[1]
    same = cMeta[0] == q
    if same:
        for j in range(k):
            for a in range(3):
                if cKey[0, j, a] != Te[q - 1, j, a] or cKey[1, j, a] != Te[q, j, a]:
                    same = False
            for a in range(4):
                if cKey[2, j, a] != Tq[q, j, a]:
                    same = False
    if not same:
        cMeta[0] = q
        cMeta[1] = 0
        cN[:] = 0
        for j in range(k):
            for a in range(3):
                cKey[0, j, a] = Te[q - 1, j, a]
                cKey[1, j, a] = Te[q, j, a]
            for a in range(4):
                cKey[2, j, a] = Tq[q, j, a]
    if cMeta[1] < w:
        _forecast_columns(Tq, Te, q, cMeta[1], w, codes, cF)
        cMeta[1] = w
    acc = np.empty(w)
    for r in range(nrows):
        row = start + r
        if cN[row] < w:
            _geo_line(Iq[row], cF, cN[row], w, acc, cG[row, cN[row] : w])
            cN[row] = w
        for col in range(w):
            C[r, c0 + col] = cG[row, col]


@numba.njit(cache=True)
def _fill_prev_column(Iq, Tq, q, start, nrows, F1, C):
    """C[r, 0] = geoDistance(I[start + r], T_n) (Method B's first column), r < nrows."""
    for j in range(Tq.shape[1]):
        for a in range(4):
            F1[j, a, 0] = Tq[q - 1, j, a]
    tmp = np.empty(1)
    acc = np.empty(1)
    for r in range(nrows):
        _geo_line(Iq[start + r], F1, 0, 1, acc, tmp)
        C[r, 0] = tmp[0]


@numba.njit(cache=True, inline="always")
def _is_allowed(r, limit, allow):
    """Offset r allowed? ``limit`` = largest allowed offset; allow[0..3] per offset.

    Plain version: fpdtw.plain.allowed_rows.
    """
    if r > limit:
        return False
    if r <= 3:
        return allow[r] != 0
    return True


@numba.njit(cache=True)
def _accumulate_reverse(C, nrows, ncols, D, open_end=False, wd=1.0):
    """Reverse accumulation from the far corner (nrows-1, ncols-1) back to (0, 0).

    ``D[i, j] = min(D[i+1, j+1] + wd C[i, j], min(D[i+1, j], D[i, j+1]) + C[i, j])``:
    symmetric1 with ``wd = 1`` (the same as ``C[i, j] + min(...)``: adding ``C[i, j]`` keeps
    the order of the three), the symmetric2 weights with ``wd = 2``, which give every path
    from ``(r, 0)`` to the corner the same total weight ``(nrows - r) + ncols - 1``
    (dtw-python's normalizable ``symmetric2``). ``open_end``: the path may end in ANY row
    of the last column, ``D[r, ncols-1] = C[r, ncols-1]`` (Tormene et al.'s open-end DTW
    with the time axis reversed).

    Plain version: fpdtw.plain.reverse_accumulate.
    """
    lr = nrows - 1
    lc = ncols - 1
    D[lr, lc] = C[lr, lc]
    for col in range(lc - 1, -1, -1):
        D[lr, col] = C[lr, col] + D[lr, col + 1]
    for r in range(lr - 1, -1, -1):
        D[r, lc] = C[r, lc] if open_end else C[r, lc] + D[r + 1, lc]
        for col in range(lc - 1, -1, -1):
            c = C[r, col]
            D[r, col] = min(D[r + 1, col + 1] + wd * c, min(D[r + 1, col], D[r, col + 1]) + c)


@numba.njit(cache=True)
def _backtrack_lowest(D, nrows, ncols, P, path, input_first=False):
    """Method B's back-track (plotPath) from (nrows-1, ncols-1) to (0, 0) with the
    overwrite rule.

    Steps: diagonal (r-1, c-1), target (r, c-1), input (r-1, c); ties prefer the
    diagonal, then the target step (which keeps the higher input frame), or with
    ``input_first`` the input step. On row 0 only target steps, on column 0 only input
    steps. ``P[c]`` ends as the lowest row the path visits in column c (a step back one
    input frame on the same column overwrites it). ``path`` gets the cells from the far
    corner back to (0, 0); returns their number.

    Plain version: fpdtw.plain.backtrack, then fpdtw.plain.path_to_map (the lowest rows).
    """
    r = nrows - 1
    c = ncols - 1
    P[c] = r
    path[0, 0] = r
    path[0, 1] = c
    n = 1
    while r > 0 or c > 0:
        if r == 0:
            c -= 1
        elif c == 0:
            r -= 1
        else:
            dd = D[r - 1, c - 1]
            dh = D[r, c - 1]
            dv = D[r - 1, c]
            if dd <= dh and dd <= dv:
                r -= 1
                c -= 1
            elif dh < dv or (dh == dv and not input_first):
                c -= 1
            else:
                r -= 1
        P[c] = r
        path[n, 0] = r
        path[n, 1] = c
        n += 1
    return n


@numba.njit(cache=True)
def _choose_b(C, nrows, ncols, limit, allow, D, P, path, input_first):
    """Method B on a filled window: Type V mask, accumulate, D[0, 0] = 10000, back-track.

    Returns (P_1, path length).

    Plain version: fpdtw.plain.method_b_step (lines 13-16).
    """
    for r in range(nrows):
        if not _is_allowed(r, limit, allow):
            C[r, 1] = np.inf
    _accumulate(C[:nrows, :ncols], 1.0, D[:nrows, :ncols])
    D[0, 0] = B_CORNER
    n = _backtrack_lowest(D, nrows, ncols, P, path, input_first)
    return P[1], n


#: Method C's window readings (``P_READING`` codes of :func:`_window_step`; see MethodC).
C_SQUARE, C_LITERAL, C_SQUARE_TN, C_OPEN_END, C_NORMALISED = 0, 1, 2, 3, 4


@numba.njit(cache=True)
def _choose_c(C, nrows, ncols, limit, allow, D, score, reading, ties_high):
    """Method C on a filled window: Type V mask, reverse accumulation, argmin of column 0.

    The accumulation is pinned to the far corner, open in the last column
    (:data:`C_OPEN_END`) or symmetric2 (:data:`C_NORMALISED`); ``score[r] = D[r, 0]``, or
    ``D[r, 0] / ((nrows - r) + ncols)`` for :data:`C_NORMALISED`. Ties: the lowest row,
    or the highest with ``ties_high``. Returns the chosen offset, -1 if no row is allowed.

    Plain version: fpdtw.plain.method_c_step (lines 12-13).
    """
    for r in range(nrows):
        if not _is_allowed(r, limit, allow):
            C[r, 0] = np.inf
    _accumulate_reverse(
        C, nrows, ncols, D, reading == C_OPEN_END, 2.0 if reading == C_NORMALISED else 1.0
    )
    best = -1
    for r in range(nrows):
        s = D[r, 0]
        if reading == C_NORMALISED:
            s = s / ((nrows - r) + ncols)
        score[r] = s
        if _is_allowed(r, limit, allow):
            if best < 0 or s < score[best] or (ties_high and s == score[best]):
                best = r
    return best


@numba.njit(cache=True)
def _choose_a(Iq, t, start, nrows, limit, allow, c, ties_high, wts):
    """Method A's window: ``c[r] = geoDistance(I[start + r], t)`` (eq. 1) for
    ``r < nrows``, and the argmin over the allowed rows (ties: the lowest row, or the
    highest with ``ties_high``). Returns the chosen offset, -1 if no row is allowed.

    Plain version: fpdtw.plain.method_a_step (lines 7-10).
    """
    best = -1
    for r in range(nrows):
        cost = _geo_frame_w(Iq[start + r], t, wts)
        c[r] = cost
        if _is_allowed(r, limit, allow):
            if best < 0 or cost < c[best] or (ties_high and cost == c[best]):
                best = r
    return best


@numba.njit(cache=True)
def _checked(off, limit, allow):
    """``off`` if the constraint allows it: no method ever picks a masked candidate
    (``off = -1``: no row of the window was allowed).

    Plain version: fpdtw.plain.checked_choice.
    """
    if off < 0 or not _is_allowed(off, limit, allow):
        raise AlignmentError("no row of the window is allowed by the Type V state")
    return off


# --- one whole step of Method A, B or C --------------------------------------------------

#: Entries of an aligner's parameter vector (int64) for :func:`_window_step`.
P_METHOD, P_W, P_READING, P_SHIFT, P_HOLD, P_TIES_HIGH, P_INPUT_FIRST, P_START_BEST = range(8)
P_TYPEV, P_SHARED = 8, 9
#: Half-width in frames of the global band around the diagonal ``M = q`` (0: no band;
#: beyond the papers, see :class:`ForecastAligner`).
P_BAND = 10
#: 1: the aligner weights eq. 1's joints (:func:`fpdtw.weights.joint_weights`; beyond the
#: papers, see :class:`ForecastAligner`); the weights go to the kernels beside ``prm``.
P_WEIGHTED = 11
#: 1: the band clips the window's rows (``band="half-w"``: the rows outside it are not
#: computed); 0: it masks them (``band="1s"``). See :class:`ForecastAligner`.
P_BAND_CLIP = 12
N_PARAMS = 13
#: Method codes of ``P_METHOD``.
METHOD_A, METHOD_B, METHOD_C = 0, 1, 2
#: Kinds of step (``out[0]`` of :func:`_window_step`).
STEP_FIRST, STEP_WARMUP, STEP_END, STEP_WINDOW = 0, 1, 2, 3
#: Length of a step's ``out`` record: kind, the window's rows and columns, (B) the path
#: length, and the offset of the window's first row from ``M_n`` (0 but under a clipping band).
N_OUT = 5
#: Frames needed before forecasting (dead reckoning on two frames).
SMOOTHING = 2


@numba.njit(cache=True)
def _mask_band(C, nrows, col, q, start, band):
    """Global band (``band > 0``): ``C[r, col] = +inf`` for every row whose input frame
    ``start + r`` lies more than ``band`` frames from the diagonal ``q``.

    Beyond the papers (notebook 16, Q3); tested in tests/test_open_questions.py.
    """
    if band <= 0:
        return
    for r in range(nrows):
        if abs(start + r - q) > band:
            C[r, col] = np.inf


@numba.njit(cache=True)
def _clip_band(start, nrows, q, band):
    """The rows of a window ``I_{start}..I_{start + nrows - 1}`` inside the band, as
    ``(first, rows)``: offsets ``first..first + rows - 1``; ``(0, nrows)`` (the whole window,
    to be masked and refused as by :func:`_mask_band` and :func:`_check_band`) when no row
    lies inside.

    Beyond the papers (notebook 16, Q3); tested in tests/test_open_questions.py.
    """
    lo = max(0, q - band - start)
    hi = min(nrows - 1, q + band - start)
    if lo > hi:
        return 0, nrows
    return lo, hi - lo + 1


@numba.njit(cache=True)
def _check_band(off, q, start, band):
    """Never a masked candidate: raise when the chosen row lies outside the band (only when
    no row of the window was inside it).

    Beyond the papers (notebook 16, Q3); tested in tests/test_open_questions.py.
    """
    if band > 0 and abs(start + off - q) > band:
        raise ValueError("global band: no input frame of the window lies inside the band")


@numba.njit(cache=True)
def _first_frame(Iq, Tq, w, m, start_best, wts):
    """``M_0``: 0, or the best match (eq. 1, weighted by ``wts`` unless empty) of T_0
    among I_0..I_w."""
    if not start_best:
        return 0
    best = 0
    best_cost = np.inf
    for r in range(min(w, m) + 1):
        c = _geo_frame_w(Iq[r], Tq[0], wts)
        if c < best_cost:
            best_cost = c
            best = r
    return best


@numba.njit(cache=True)
def _allowed_offsets(state, prm, table):
    """``(limit, allow)`` of :func:`_is_allowed` in Type V state ``state[0]`` (every
    offset without the constraint)."""
    allow = np.ones(4, dtype=np.int64)
    if prm[P_TYPEV] == 0:
        return np.iinfo(np.int64).max, allow
    for a in range(4):
        allow[a] = 1 if table[state[0], a] >= 0 else 0
    return MAX_ADVANCE, allow


@numba.njit(cache=True)
def _advance_state(state, prm, table, advance):
    """Type V: the state after an advance (an illegal move is only ever a forced hold at m,
    which leaves the state as it is)."""
    if prm[P_TYPEV] != 0 and 0 <= advance <= MAX_ADVANCE and table[state[0], advance] >= 0:
        state[0] = table[state[0], advance]


@numba.njit(cache=True)
def _a_step(Iq, Tq, q, M, state, prm, table, c, out, wts):
    """``M_q`` of a Method A aligner at target frame q: :func:`_window_step` for Method A,
    with only the arrays it needs (``c`` : float64 (>= w + 1,), the window's costs;
    ``wts`` : eq. 1's joint weights, empty for none).

    Plain version: fpdtw.plain.method_a_step.
    """
    m = Iq.shape[0] - 1
    w = prm[P_W]
    out[1] = 0
    out[2] = 0
    out[3] = 0
    out[4] = 0
    if q == 0:
        out[0] = STEP_FIRST
        return _first_frame(Iq, Tq, w, m, prm[P_START_BEST] != 0, wts)
    start = M[q - 1]
    if start >= m:
        out[0] = STEP_END
        m_next = m
    else:
        out[0] = STEP_WINDOW
        limit, allow = _allowed_offsets(state, prm, table)
        nrows = min(w, m - start) + 1
        off = _choose_a(Iq, Tq[q], start, nrows, limit, allow, c, prm[P_TIES_HIGH] != 0, wts)
        off = _checked(off, limit, allow)
        out[1] = nrows
        out[2] = 1
        m_next = start + off
    _advance_state(state, prm, table, m_next - start)
    return m_next


@numba.njit(cache=True)
def _window_step(
    Iq, Tq, Te, q, M, state, prm, table, codes, F, C, D, Pcol, path, score,
    cF, cG, cN, cMeta, cKey, out, wts,
):  # fmt: skip
    """``M_q`` of one Method A, B or C aligner at target frame q (frames 0..q received).

    ``M[:q]`` is the map so far; ``state[0]`` the Type V state (advanced in place);
    ``prm`` the aligner's parameter vector (``P_*``); ``table`` the Type V state table;
    ``F, C, D, Pcol, path, score`` scratch; ``cF..cKey`` a :class:`WindowCache`'s
    arrays (used when ``prm[P_SHARED]``). ``out`` (``N_OUT``) gets the kind of step, the
    window's rows and columns, (B) the path length and the offset of the window's first
    row from ``M_n``, for the debug record. With a clipping band (``prm[P_BAND_CLIP]``)
    the window's rows are those of :func:`_clip_band`: rows outside the band are not
    computed, and the window is the same method's on ``I_{M_n + first}..``. ``wts`` : float64
    (k,) eq. 1's per-joint weights, or EMPTY (0,) for eq. 1 as written (exactly the
    unweighted arithmetic); an aligner with weights never shares a cache (``prm[P_SHARED]``
    is 0), whose costs are unweighted.

    Plain version: fpdtw.plain.method_a_step, fpdtw.plain.method_b_step and
    fpdtw.plain.method_c_step (one step each; fpdtw.plain.run steps through a target).
    """
    method = prm[P_METHOD]
    if method == METHOD_A:
        return _a_step(Iq, Tq, q, M, state, prm, table, C[:, 0], out, wts)
    m = Iq.shape[0] - 1
    w = prm[P_W]
    out[1] = 0
    out[2] = 0
    out[3] = 0
    out[4] = 0
    if q == 0:
        out[0] = STEP_FIRST
        return _first_frame(Iq, Tq, w, m, prm[P_START_BEST] != 0, wts)
    start = M[q - 1]
    if q - 1 < SMOOTHING:
        out[0] = STEP_WARMUP
        m_next = min(start + 1, m)
    elif start >= m:
        out[0] = STEP_END
        m_next = m
    else:
        out[0] = STEP_WINDOW
        limit, allow = _allowed_offsets(state, prm, table)
        shared = prm[P_SHARED] != 0
        band = prm[P_BAND]
        if method == METHOD_B:
            nrows = min(w, m - start) + 1
        else:
            # w_i = min(w - 1, m - M_n) for the square window (w rows), else min(w, m - M_n)
            nrows = min(w - 1 if prm[P_READING] == C_SQUARE else w, m - start) + 1
        first = 0
        if band > 0 and prm[P_BAND_CLIP] != 0:  # only the rows inside the band
            first, nrows = _clip_band(start, nrows, q, band)
        s0 = start + first  # the window's first row
        if method == METHOD_B:
            ncols = w + 1
            if shared:
                _fill_prev_column(Iq, Tq, q, s0, nrows, F, C)
                _fill_shared(Iq, Tq, Te, q, codes, s0, nrows, w, 1, C, cF, cG, cN, cMeta, cKey)
            else:
                _forecast_window(Tq, Te, q, w, True, codes, F, 0, prm[P_HOLD] != 0)
                _cost_window(Iq, s0, nrows, F, ncols, C, wts)
            _mask_band(C, nrows, 1, q, s0, band)
            off, npath = _choose_b(
                C, nrows, ncols, limit, allow, D, Pcol, path, prm[P_INPUT_FIRST] != 0
            )
            _check_band(off, q, s0, band)
            out[3] = npath
        else:
            reading = prm[P_READING]
            with_prev = reading == C_SQUARE_TN
            ncols = w + 1 if with_prev else w
            if shared:
                c0 = 0
                if with_prev:
                    _fill_prev_column(Iq, Tq, q, s0, nrows, F, C)
                    c0 = 1
                _fill_shared(Iq, Tq, Te, q, codes, s0, nrows, w, c0, C, cF, cG, cN, cMeta, cKey)
            else:
                _forecast_window(Tq, Te, q, w, with_prev, codes, F, prm[P_SHIFT], prm[P_HOLD] != 0)
                _cost_window(Iq, s0, nrows, F, ncols, C, wts)
            _mask_band(C, nrows, 0, q, s0, band)
            off = _choose_c(C, nrows, ncols, limit, allow, D, score, reading, prm[P_TIES_HIGH] != 0)
            _check_band(off, q, s0, band)
        off = _checked(off, limit, allow)  # (a band is never combined with Type V: first = 0)
        out[1] = nrows
        out[2] = ncols
        out[4] = first
        m_next = s0 + off
    _advance_state(state, prm, table, m_next - start)
    return m_next


@numba.njit(cache=True)
def _run_group(
    Iq, Tq, Te, codes, params, table, M, F, C, D, Pcol, path, score, cF, cG, cN, cMeta, cKey,
    wts,
):  # fmt: skip
    """Every aligner of ``params`` (one row each) over the whole target, in lockstep.

    ``wts`` (aligners, k): eq. 1's joint weights of the aligners with ``P_WEIGHTED``
    (the rows of the others are not read: they get an empty slice, eq. 1 as written).

    ``M`` (aligners, frames) receives the maps; each aligner's step only reads the
    frames up to its own (as when streaming). Scratch buffers are shared: the steps
    run one after the other.
    """
    n = Tq.shape[0]
    A = params.shape[0]
    state = np.zeros((A, 1), dtype=np.int64)
    out = np.zeros(N_OUT, dtype=np.int64)
    k = Iq.shape[1]
    for q in range(n):
        for a in range(A):
            nw = k if params[a, P_WEIGHTED] != 0 else 0
            M[a, q] = _window_step(
                Iq, Tq, Te, q, M[a], state[a], params[a], table, codes, F, C, D, Pcol, path,
                score, cF, cG, cN, cMeta, cKey, out, wts[a, :nw],
            )  # fmt: skip


# --- one call per streamed frame --------------------------------------------------------

#: Header of an aligner's int64 work buffer (:func:`_work_views`): joints k, window
#: capacity W = w + 1, number of Type V states.
_H_K, _H_W, _H_NS = 0, 1, 2
_HEADER = 3


def _work_sizes(k: int, W: int, ns: int) -> tuple:
    """Lengths of the float64 and int64 work buffers of :func:`_work_views`."""
    floats = W * W + k * 4 * W + W * W + W + 4 * k + 1 + 12 * k
    ints = _HEADER + N_PARAMS + 4 * ns + 1 + N_OUT + k + W + 4 * W + 1 + 2
    return floats, ints


@numba.njit(cache=True)
def _head_views(work, iwork):
    """The views every method uses, at the start of the two buffers: ``prm``, ``table``,
    ``tv``, ``out`` and column 0 of ``C`` (all Method A's step needs: one reshape, where
    each of :func:`_work_views`' reshapes costs about 0.1 us)."""
    W = iwork[_H_W]
    ns = iwork[_H_NS]
    i = _HEADER
    prm = iwork[i : i + N_PARAMS]
    i += N_PARAMS
    table = iwork[i : i + 4 * ns].reshape((ns, 4))
    i += 4 * ns
    tv = iwork[i : i + 1]
    i += 1
    out = iwork[i : i + N_OUT]
    return prm, table, tv, out, work[0 : W * W : W]


@numba.njit(cache=True)
def _work_views(work, iwork):
    """An aligner's scratch, parameters and state as views of two flat buffers.

    ``work`` (float64) holds ``C (W, W), F (k, 4, W), D (W, W), score (W)`` and the
    placeholder cache arrays ``cF (k, 4, 1), cG (1, 1), cKey (3, k, 4)``; ``iwork``
    (int64) the header ``k, W, ns``, then ``prm (N_PARAMS), table (ns, 4), tv (1),
    out (N_OUT)`` (:func:`_head_views`), ``codes (k), Pcol (W), path (2W, 2), cN (1),
    cMeta (2)``. Two buffers instead of nineteen arrays: a compiled function costs about
    0.1 us per array argument to call, and :func:`_stream_step` is called once per frame.
    """
    k = iwork[_H_K]
    W = iwork[_H_W]
    ns = iwork[_H_NS]
    prm, table, tv, out, _ = _head_views(work, iwork)
    o = 0
    C = work[o : o + W * W].reshape((W, W))
    o += W * W
    F = work[o : o + k * 4 * W].reshape((k, 4, W))
    o += k * 4 * W
    D = work[o : o + W * W].reshape((W, W))
    o += W * W
    score = work[o : o + W]
    o += W
    cF = work[o : o + 4 * k].reshape((k, 4, 1))
    o += 4 * k
    cG = work[o : o + 1].reshape((1, 1))
    o += 1
    cKey = work[o : o + 12 * k].reshape((3, k, 4))
    i = _HEADER + N_PARAMS + 4 * ns + 1 + N_OUT
    codes = iwork[i : i + k]
    i += k
    Pcol = iwork[i : i + W]
    i += W
    path = iwork[i : i + 4 * W].reshape((2 * W, 2))
    i += 4 * W
    cN = iwork[i : i + 1]
    i += 1
    cMeta = iwork[i : i + 2]
    return F, C, D, score, cF, cG, cKey, prm, table, codes, tv, Pcol, path, out, cN, cMeta


@numba.njit(cache=True)
def _store_frame(k, Tq, Te, q, fq, fe):
    """Store a streamed frame (quaternions ``fq`` (k, 4), Euler angles ``fe`` (k, 3)) in
    row ``q`` of ``Tq, Te``; False (nothing stored) for a frame of another shape."""
    if fq.shape[0] != k or fq.shape[1] != 4 or fe.shape[0] != k or fe.shape[1] != 3:
        return False
    for j in range(k):
        for a in range(4):
            Tq[q, j, a] = fq[j, a]
        for a in range(3):
            Te[q, j, a] = fe[j, a]
    return True


@numba.njit(cache=True)
def _stream_step(Iq, Tq, Te, M, q, fq, fe, work, iwork):
    """Receive one streamed frame: store it in row ``q`` of ``Tq, Te``, run
    :func:`_window_step`, store ``M[q]``; the whole ``step`` of a B/C aligner in one call.

    ``fq`` (k, 4) and ``fe`` (k, 3) are the frame's quaternions and Euler angles; a frame
    of another shape changes nothing and returns -1 (the caller then raises). Eq. 1 as
    written only: an aligner that weights the joints never takes this path (its ``step``
    takes the general one, :meth:`WindowAligner._step`).
    """
    if iwork[_HEADER + P_WEIGHTED] != 0:
        return -2
    if not _store_frame(Iq.shape[1], Tq, Te, q, fq, fe):
        return -1
    if iwork[_HEADER + P_METHOD] == METHOD_A:
        prm, table, tv, out, c = _head_views(work, iwork)
        m = _a_step(Iq, Tq, q, M, tv, prm, table, c, out, work[0:0])
    else:
        views = _work_views(work, iwork)
        F, C, D, score, cF, cG, cKey, prm, table, codes, tv, Pcol, path, out, cN, cMeta = views
        m = _window_step(
            Iq, Tq, Te, q, M, tv, prm, table, codes, F, C, D, Pcol, path, score,
            cF, cG, cN, cMeta, cKey, out, work[0:0],
        )  # fmt: skip
    M[q] = m
    return m


# --- costs shared by aligners that step together ---------------------------------------


class WindowCache:
    """Forecast and window costs shared by B/C aligners that step over the same target together.

    At a target frame ``T_{n+1}``, the dead-reckoned forecast ``[T_{n+1}, T_{n+1} + delta,
    ...]`` is the same for Methods B and C at every window size and reading, and so is
    the cost (eq. 1) of any input frame against any of its columns. Aligners given the
    same cache (``cache=`` of :class:`MethodB` and :class:`MethodC`) and fed the same
    frames in lockstep (:func:`fpdtw.online.base.run_together`) compute each forecast
    column and each cost cell once per target frame, however many of them need it;
    each aligner still masks, accumulates and chooses on its own copy of its window.
    The cached values are computed by the same code as an aligner's own, so maps are
    identical with and without a cache (tested). The cache checks the frames it is
    given: fed other frames at the same step, it starts afresh, so sharing is only ever
    a matter of speed.

    Aligners with a non-default forecast (``forecast="hold"``, ``forecast_start="next"``)
    do not use it.

    Parameters
    ----------
    I : MotionFeatures
        The input motion of every aligner sharing the cache.
    w_max : int
        The largest window among them.

    Attributes
    ----------
    F : ndarray of float64, shape (k, 4, w_max)
        Forecast columns of the cached step.
    G : ndarray of float64, shape (m + 1, w_max)
        ``G[r, :N[r]]``: costs of input frame r against them.
    N : ndarray of int64, shape (m + 1,)
    meta : ndarray of int64, shape (2,)
        Cached step q and number of forecast columns filled.
    key : ndarray of float64, shape (3, k, 4)
        The frames the cached step was computed from (Euler angles of T_n, T_{n+1}; the
        quaternion of T_{n+1}).
    """

    def __init__(self, I: MotionFeatures, w_max: int):
        self.I = I
        self.w_max = check_count(w_max, "w_max", "WindowCache")
        k = np.shape(I.quats)[1]
        self.F = np.empty((k, 4, self.w_max))
        self.G = np.empty((I.n_frames, self.w_max))
        self.N = np.zeros(I.n_frames, dtype=np.int64)
        self.meta = np.array([-1, 0], dtype=np.int64)
        self.key = np.zeros((3, k, 4))

    def arrays(self) -> tuple:
        """``(F, G, N, meta, key)`` for the kernels."""
        return self.F, self.G, self.N, self.meta, self.key


# --- the debug record -----------------------------------------------------------------


@dataclass
class WindowSnapshot:
    """What one step of a window method did (``record=True``).

    Attributes
    ----------
    q : int
        Target frame mapped by this step (the paper's ``n + 1``).
    kind : str
        ``"first"`` (q = 0, M_0 = 0), ``"warmup"`` (B/C: ``n < s``), ``"end"`` (input
        exhausted: ``M_n = m``, hold at m) or ``"window"``.
    start : int
        Window start ``M_n`` (-1 for q = 0).
    w_i : int
        The window's input rows are ``I_{M_n}..I_{M_n + w_i}`` (``w_i + 1`` rows, for
        every method and reading; 0 without a window); under ``band="half-w"``
        ``I_{M_n + first}..I_{M_n + w_i}`` (``w_i - first + 1`` rows).
    offset : int
        Chosen offset, ``M_{n+1} - M_n``.
    M : int
        ``M_{n+1}``.
    C : ndarray of float64, shape (w_i - first + 1, ncols) or None
        Cost window (eq. 1); rows = input frames ``M_n + first + r``, columns = target window:
        A: ``[T_{n+1}]``; B: ``[T_n, T_{n+1}, forecasts]`` (w + 1); C: ``[T_{n+1},
        forecasts]`` (w; w + 1 with ``T_n`` first for the "square-tn" reading). Cells
        masked by Type V are +inf (B and C; Method A records its costs unmasked).
    D : ndarray of float64, same shape, or None
        B: forward accumulation with ``D[0, 0]`` then set to 10000 (it was ``C[0, 0]``);
        C: reverse accumulation.
    path : ndarray of int64, shape (L, 2) or None
        B: the back-tracked path, (row, column) cells from (0, 0) to the far corner.
    P : ndarray of int64, shape (ncols,) or None
        B: lowest row of the path in each column (``P[1]`` is the choice).
    allowed : ndarray of bool, shape (4,) or None
        Type V: offsets 0..3 allowed in this step's state (offsets > 3 never are).
    state : str or None
        Type V state before the step.
    score : ndarray of float64, shape (w_i - first + 1,) or None
        C: what the argmin compares per row, ``D[r, 0]`` (normalised reading:
        divided by the paths' weight).
    first : int
        Offset from ``M_n`` of the window's first row: 0, but under ``band="half-w"`` when
        ``I_{M_n}`` lies outside the band (its rows are not computed).

    Paper: FP-DTW Fig. 2 (window), Fig. 4 (Method B's path and choice).
    """

    q: int
    kind: str
    start: int
    w_i: int
    offset: int
    M: int
    C: np.ndarray | None = None
    D: np.ndarray | None = None
    path: np.ndarray | None = None
    P: np.ndarray | None = None
    allowed: np.ndarray | None = None
    state: str | None = None
    score: np.ndarray | None = None
    first: int = 0


# --- the common aligner ---------------------------------------------------------------


class WindowAligner(OnlineAligner):
    """Common base of Methods A, B and C.

    Common rules (each method's docstring repeats the ones it uses and states its
    window's shape):

    * First target frame: ``M_0 = 0`` (both motions start aligned, DTW's boundary
      condition); ``start="best"`` instead maps ``T_0`` to its best match (eq. 1) among
      ``I_0..I_w`` (a silent choice of the paper, kept switchable for notebook 15).
    * Window sizes are in frames; the input window ``I_{M_n}..I_{M_n+w_i}`` shrinks at
      the end of the input.
    * ``constraint="typeV"``: before choosing, offsets the Type V state table
      (:mod:`fpdtw.online.typev`) does not allow are masked; the state advances with
      every step (warm-up included). When the input is exhausted the only choice is a
      hold at ``m``, whatever the state (the constraint cannot hold there).
    * Options (keyword arguments listed in each class's :attr:`options`): a value other
      than the default is named in brackets, e.g. ``"Mc w40 (literal window)"``.
    * ``record=True`` keeps a :class:`WindowSnapshot` of the last step in
      ``last_window`` (off by default: it copies the window every frame).
    * ``state`` holds the current Type V state (index into ``constraint.states``), None
      without a constraint; ``reset()`` puts it back to the start state.

    The whole step runs in one compiled function, :func:`_window_step`; its scratch
    arrays, the parameter vector (:meth:`params`) and the Type V state live in two flat
    buffers (:func:`_work_views`), so that one streamed frame is one compiled call with
    few arguments (:func:`_stream_step`). Subclasses give their :meth:`params` and
    :meth:`_window_record`.

    Parameters
    ----------
    I : MotionFeatures
        Input (recorded) motion.
    w : int
        Window size in frames, >= 1.
    constraint : None, "typeV" or TypeV
    record : bool
    **options
        The method's options (see :attr:`options`), e.g. ``window="literal"``.
    """

    #: Method letter in names ("Ma", "Mb", "Mc").
    label = "M?"
    #: The smallest window ``w`` the method takes.
    min_w = 1
    #: ``{option: (default, {other value: label in names})}``, in the order of names.
    options = {"start": ("zero", {"best": "M_0 best match"})}
    #: A :class:`WindowCache` shared with other aligners (Methods B and C only).
    cache = None

    def __init__(self, I: MotionFeatures, w: int, *, constraint=None, record=False, **options):
        check_count(w, "window w", type(self).__name__, minimum=self.min_w)
        check_input(I, who=type(self).__name__)
        from fpdtw import limits

        limits.check_bytes(
            limits.window_bytes(w),
            I.name,
            f"{type(self).__name__}'s window matrices would be up to two {w + 1} x {w + 1} float64",
            hint="use a smaller window w (--window)",
        )
        self.history = 1  # a step reads T[q - 1], T[q] and M[q - 1]: bounded history
        self.w = int(w)
        self.constraint = resolve_constraint(constraint)
        self.record = bool(record)
        self.settings = self._resolve_options(options)
        Q, E = np.shape(I.quats), np.shape(I.euler)
        if len(Q) != 3 or Q[2] != 4 or E != Q[:2] + (3,) or len(I.orders) != Q[1]:
            raise AlignmentError(
                f"input motion {I.name!r}: inconsistent features: quats {I.quats.shape}, "
                f"euler {I.euler.shape}, {len(I.orders)} rotation orders"
            )
        try:
            codes = order_codes(I.orders)
        except ValueError as e:
            raise AlignmentError(f"input motion {I.name!r}: {e}") from None
        self._Iq = np.ascontiguousarray(I.quats, dtype=np.float64)
        # eq. 1's joint weights (option weights="travel"), EMPTY for eq. 1 as written
        self._wts = (
            joint_weights(I) if self.settings.get("weights", "none") == "travel" else np.empty(0)
        )
        if self.constraint is not None:
            self._allow_by_state = (self.constraint.table >= 0).astype(np.int64)

        k = self._Iq.shape[1]
        W = self.w + 1
        table = (
            np.zeros((3, 4), dtype=np.int64)
            if self.constraint is None
            else np.ascontiguousarray(self.constraint.table, dtype=np.int64)
        )
        nf, ni = _work_sizes(k, W, table.shape[0])
        self._work = np.zeros(nf)
        self._iwork = np.zeros(ni, dtype=np.int64)
        self._iwork[[_H_K, _H_W, _H_NS]] = k, W, table.shape[0]
        (
            self._F, self._C, self._D, self._score, cF, cG, cKey, self._params, self._table,
            self._codes, self._tv, self._P, self._path, self._out, cN, cMeta,
        ) = _work_views(self._work, self._iwork)  # fmt: skip
        self._table[:] = table
        self._codes[:] = codes
        cMeta[:] = (-1, 0)
        self._placeholder = (cF, cG, cN, cMeta, cKey)
        super().__init__(I)
        self._configure()
        self.name = self._make_name()

    def _configure(self) -> None:
        """Fill the parameter vector and choose the cache arrays and the one-call path
        from the aligner's settings (again after a subclass sets :attr:`cache`)."""
        self._params[:] = self.params()
        self._cache_arrays = self._placeholder if self.cache is None else self.cache.arrays()
        # the one-call path: no debug record, no shared cache, eq. 1 unweighted
        self._lean = not self.record and self.cache is None and self._wts.shape[0] == 0

    def params(self) -> np.ndarray:
        """This aligner's parameter vector for :func:`_window_step` (int64, ``N_PARAMS``)."""
        p = np.zeros(N_PARAMS, dtype=np.int64)
        p[P_W] = self.w
        p[P_START_BEST] = self.settings["start"] == "best"
        p[P_TYPEV] = self.constraint is not None
        p[P_SHARED] = self.cache is not None
        p[P_WEIGHTED] = self._wts.shape[0] > 0
        return p

    @classmethod
    def _resolve_options(cls, given: dict) -> dict:
        out = {}
        for key, value in given.items():
            if key not in cls.options:
                known = ", ".join(cls.options) or "none"
                raise AlignmentError(f"{cls.__name__}: unknown option {key}= (known: {known})")
            default, others = cls.options[key]
            if value != default and value not in others:
                allowed = ", ".join(repr(v) for v in (default, *others))
                raise AlignmentError(f"{cls.__name__}: {key}={value!r}; expected one of {allowed}")
        for key, (default, _) in cls.options.items():
            out[key] = given.get(key, default)
        return out

    @classmethod
    def name_for(cls, w: int, typev: bool = False, **options) -> str:
        """The name of a configuration, e.g. ``MethodC.name_for(40, window="literal")``
        -> ``"Mc w40 (literal window)"``; options at their default are not named.

        Parameters
        ----------
        w : int
        typev : bool
            With the Type V constraint (suffix ``" + Type V"``).
        **options
            See :attr:`options`.

        Returns
        -------
        name : str
        """
        settings = cls._resolve_options(options)
        labels = [
            cls.options[key][1][value]
            for key, value in settings.items()
            if value != cls.options[key][0]
        ]
        name = cls._base_name_for(w)
        if labels:
            name += f" ({', '.join(labels)})"
        return name + " + Type V" if typev else name

    @classmethod
    def _base_name_for(cls, w: int) -> str:
        return f"{cls.label} w{w}"

    def _make_name(self) -> str:
        c = self.constraint
        name = self.name_for(self.w, **self.settings)
        return name if c is None else f"{name} + {c.name}"

    def reset(self) -> None:
        super().reset()
        self.state = None if self.constraint is None else self.constraint.start
        self.last_window = None
        tv = getattr(self, "_tv", None)
        if tv is not None:
            tv[0] = 0 if self.constraint is None else self.constraint.start

    def window_snapshot(self) -> WindowSnapshot | None:
        """The :class:`WindowSnapshot` of the last step (needs ``record=True``)."""
        return self.last_window

    def step(self, frame: Frame) -> int:
        """Receive target frame ``T_{n+1}`` and return ``M_{n+1}``.

        The common case (numpy arrays, room in the buffers, no debug record, no shared
        cache) is one compiled call, :func:`_stream_step`; anything else takes the
        general path of :meth:`OnlineAligner.step` (same result), after checking the
        frame's shape.
        """
        if self.n_received == 0:
            self._begin_take(frame)
        i = self.n_received - self._start
        arrays = compiled_frame(frame, i, self._M.shape[0], self._Tp) if self._lean else None
        if arrays is not None:
            fq, fe = arrays
            m = _stream_step(
                self._Iq, self._Tq, self._Te, self._M, i, fq, fe, self._work, self._iwork
            )
            if m >= 0:
                self.n_received += 1
                if self.constraint is not None:
                    self.state = int(self._tv[0])
                return m
        k = self._Iq.shape[1]
        if np.shape(frame.quats) != (k, 4) or np.shape(frame.euler) != (k, 3):
            raise AlignmentError(
                f"target frame {self.n_received}: expected quats ({k}, 4) and euler ({k}, 3) "
                f"like the input motion {self.I.name!r}, got {np.shape(frame.quats)} and "
                f"{np.shape(frame.euler)}"
            )
        return super().step(frame)

    def _use_input(self, Iq, orders) -> None:
        """Eq. 1 against ``Iq``; the forecasts in the target's rotation ``orders``."""
        if Iq is not self._Iq:
            self._Iq = np.ascontiguousarray(Iq, dtype=np.float64)
            if self.cache is not None:
                self.cache.meta[0] = -1  # its costs were computed against other rotations
        try:
            self._codes[:] = order_codes(orders)
        except ValueError as e:
            raise AlignmentError(f"target of {self.name}: {e}") from None

    def _step(self, q: int) -> int:
        state = self.state
        m_next = int(
            _window_step(
                self._Iq, self._Tq, self._Te, q, self._M, self._tv, self._params, self._table,
                self._codes, self._F, self._C, self._D, self._P, self._path, self._score,
                *self._cache_arrays, self._out, self._wts,
            )
        )  # fmt: skip
        if self.constraint is not None:
            self.state = int(self._tv[0])
        if self.record:
            kind = ("first", "warmup", "end", "window")[int(self._out[0])]
            start = -1 if q == 0 else int(self._M[q - 1])
            arrays = {}
            w_i = 0
            if kind == "window":
                nr, nc, first = int(self._out[1]), int(self._out[2]), int(self._out[4])
                w_i, arrays = first + nr - 1, self._window_record(nr, nc, int(self._out[3]))
                arrays["first"] = first
            self._snap(q, kind, start, w_i, m_next, state=state, **arrays)
        return m_next

    @abstractmethod
    def _window_record(self, nrows: int, ncols: int, npath: int) -> dict:
        """The arrays of the debug record of a window step (``record=True``)."""

    # -- helpers for subclasses ----------------------------------------------------------
    def _snap(self, q, kind, start, w_i, m_next, state=None, **arrays):
        """Keep the debug record of a step; ``state``: the Type V state before it
        (default: the current one)."""
        allowed = None
        if self.constraint is not None:
            state = self.state if state is None else state
            allowed = self._allow_by_state[state].astype(bool)
            state = self.constraint.states[state]
        offset = m_next - max(start, 0)
        self.last_window = WindowSnapshot(
            q, kind, start, w_i, offset, m_next, allowed=allowed, state=state, **arrays
        )


class ForecastAligner(WindowAligner):
    """Common base of Methods B and C: warm-up, end of input, then a forecast window.

    * Warm-up, ``n < s`` (``s = 2``, dead reckoning on two frames): ``M_{n+1} = n + 1``
      (the paper), clipped to ``m``; written ``min(M_n + 1, m)``, which is the same
      from ``M_0 = 0`` and keeps advancing from another ``M_0`` (``start="best"``).
    * ``M_n >= m`` (input exhausted): ``M_{n+1} = m``.
    * Otherwise the method's window.
    * ``cache``: a :class:`WindowCache` shared with other aligners stepping over the same
      target together (speed only: the maps are the same).

    :func:`run_group` loops the same compiled step, :func:`_window_step`, over several
    aligners at once: streaming and batch runs share one implementation.
    """

    #: Smoothing window: frames needed before forecasting (dead reckoning: 2).
    s = SMOOTHING
    #: Options of Methods B and C (beyond :attr:`WindowAligner.options`): ``band="1s"`` and
    #: ``band="half-w"``, the global band of the FP-DTW paper's conclusion (an open
    #: question, notebook 16).
    #: ``weights="travel"``: eq. 1's joints weighted by their travel in the input
    #: (:func:`fpdtw.weights.joint_weights`; an open question, notebook 16).
    options = {
        **WindowAligner.options,
        "band": ("none", {"1s": "band 1 s", "half-w": "band w/2"}),
        "weights": ("none", {"travel": "weighted joints"}),
    }
    #: Half-width of ``band="1s"``, seconds (120 frames at 120 Hz).
    BAND_SECONDS = 1.0

    def __init__(
        self, I: MotionFeatures, w: int, *, constraint=None, record=False, cache=None, **options
    ):
        """Global band (``band="1s"``, beyond the papers): the live take is assumed to last
        as long as the recording, so the uniform-time diagonal is ``M_q = q`` (input rate /
        target rate = 1: every run of this package has both motions at one rate). At every
        window step, candidates whose input frame lies more than ``B`` = round(1 s x the
        input's rate) frames from ``q`` are masked (cost +inf in the column that decides the
        step, as Type V masks: column ``T_{n+1}`` of Method B's path, column 0 of Method C),
        so the map picks the best candidate inside the band: a map that would leave it is
        kept at most on its edge. A masked candidate is never picked: if no row of the
        window were inside the band the step raises ValueError; that cannot happen without
        Type V (``M_n`` within the band at ``q - 1`` leaves row 0 or row 1 within it at
        ``q``), and a band with Type V is refused. Warm-up and the forced hold at ``m``
        once the input is exhausted are as without the band. A band aligner keeps every
        target frame (its step reads the frame number ``q``).

        The band of half the window (``band="half-w"``, names ``"Mc w40 (band w/2)"``;
        beyond the papers): half-width ``B = max(1, floor(w / 2))`` frames around the same
        diagonal, and the window's rows outside it are NOT COMPUTED: the window's row range
        is clipped to the band, ``I_{M_n + first}..I_{M_n + w_i'}`` with ``first = max(0, q -
        B - M_n)`` and ``w_i' = min(w_i, q + B - M_n)``, and the method runs unchanged on
        that smaller window (Method B's path starts at its first row; the chosen row is
        ``M_n + first + P_1``, or Method C's argmin from there). Fewer rows, fewer cells of
        eq. 1 per frame: the global constraint of the paper's conclusion, which "would
        restrict the area in which a path can be plotted within the cost matrix, reducing
        the number of cells which need to be calculated". If no row of the window lies in
        the band the step is the 1 s band's: the whole window computed and masked, and
        ValueError (:func:`_check_band`); without Type V that needs a map already outside
        the band, which the band never makes (``M_0 = 0`` starts on the diagonal): only
        ``start="best"`` with ``M_0 > B + 1`` can. The rule ``w / 2`` was chosen on
        2026-11-24, after the 1 s band's results were seen (inconclusive: a 1 s band barely
        binds a window of 40 frames, and masking computes every cell anyway) and before any
        run of this band.

        Weighted joints (``weights="travel"``, beyond the papers): eq. 1 becomes
        ``sum_j w_j (2/pi) arccos |q_a,j . q_b,j|`` with ``w =``
        :func:`fpdtw.weights.joint_weights` of the input, computed once here. Such an
        aligner computes its own costs (a shared :class:`WindowCache` holds unweighted ones,
        so it is not used) and streams through the general path of :meth:`step`."""
        super().__init__(I, w, constraint=constraint, record=record, **options)
        if self.settings.get("band", "none") != "none":
            if self.constraint is not None:
                raise AlignmentError(f"{self.name}: the global band is not combined with Type V")
            self.history = None
        if cache is not None:
            if not isinstance(cache, WindowCache):
                raise AlignmentError(f"cache must be a WindowCache, got {type(cache).__name__}")
            if cache.I is not I or cache.w_max < self.w:
                raise AlignmentError(
                    f"{self.name}: the cache is for another input or smaller windows "
                    f"(w_max {cache.w_max} < w {self.w})"
                )
            if self.settings.get("forecast", "dead-reckoning") != "dead-reckoning" or (
                self.settings.get("forecast_start", "T_{n+1}") != "T_{n+1}"
            ):
                cache = None  # its forecast is not the shared one
            if self._wts.shape[0]:
                cache = None  # the cache's costs are unweighted
        self.cache = cache
        self._configure()

    def params(self) -> np.ndarray:
        p = super().params()
        p[P_HOLD] = self.settings.get("forecast", "dead-reckoning") == "hold"
        band = self.settings.get("band", "none")
        if band == "1s":
            p[P_BAND] = max(1, int(round(self.BAND_SECONDS * self.I.fps)))
        elif band == "half-w":
            p[P_BAND] = max(1, self.w // 2)
            p[P_BAND_CLIP] = 1
        return p


def run_group(aligners, T: MotionFeatures) -> list:
    """Run Method B and C aligners over one target together, in one compiled loop.

    The same steps as streaming each of them (:func:`fpdtw.online.base.run_online`; the
    maps are equal, tested), without a Python call per frame; aligners given one
    :class:`WindowCache` share its forecast and costs. Only the maps are returned (with
    shared work, nothing is timed per aligner).

    Parameters
    ----------
    aligners : sequence of ForecastAligner
        All with the same input motion; those with a cache all with the same one.
    T : MotionFeatures
        Target motion with the input's joints.

    Returns
    -------
    maps : list of ndarray of int64, shape (n,)
    """
    aligners = list(aligners)
    if not aligners:
        return []
    a0 = aligners[0]
    tables, caches = set(), {}
    for a in aligners:
        if not isinstance(a, ForecastAligner) or a.I is not a0.I:
            raise AlignmentError("run_group needs Method B/C aligners with one input and one cache")
        if a.cache is not None:
            caches[id(a.cache)] = a
        if a.constraint is not None:
            tables.add(a.constraint.table.tobytes())
    if len(caches) > 1:
        raise AlignmentError("run_group needs Method B/C aligners with one input and one cache")
    if len(tables) > 1:
        raise AlignmentError("run_group needs one Type V table")
    holder = next(iter(caches.values()), a0)  # its arrays serve every aligner with P_SHARED
    k = a0._Iq.shape[1]
    if np.shape(T.quats)[1:] != (k, 4) or np.shape(T.euler)[1:] != (k, 3):
        raise AlignmentError(
            f"target {T.name!r}: expected {k} joints like the input {a0.I.name!r}, got "
            f"quats {np.shape(T.quats)} and euler {np.shape(T.euler)}"
        )
    if T.n_frames:
        first = T.frame(0)
        for a in aligners:  # the target's rotation orders and rig, as a stream's first frame
            a._begin_take(first)
    W = max(a.w for a in aligners) + 1
    params = np.stack([a.params() for a in aligners])
    wts = np.ones((len(aligners), k))
    for row, a in zip(wts, aligners):
        if a._wts.shape[0]:
            row[:] = a._wts
    table = next((a._table for a in aligners if a.constraint is not None), a0._table)
    M = np.zeros((len(aligners), T.n_frames), dtype=np.int64)
    _run_group(
        a0._Iq, np.ascontiguousarray(T.quats, dtype=np.float64),
        np.ascontiguousarray(T.euler, dtype=np.float64), a0._codes, params, table, M,
        np.empty((k, 4, W)), np.empty((W, W)), np.empty((W, W)), np.empty(W, dtype=np.int64),
        np.empty((2 * W, 2), dtype=np.int64), np.empty(W), *holder._cache_arrays, wts,
    )  # fmt: skip
    return list(M)


__all__ = [
    "B_CORNER",
    "WindowAligner",
    "WindowSnapshot",
]
