"""Shared machinery of the FP-DTW window methods A, B and C (Algorithms 1-3), compiled.

Numba twins of :func:`fpdtw.plain.method_a_step`, ``method_b_step`` and ``method_c_step``
(``tests/test_plain.py`` holds the maps equal; :func:`_window_step` is any method's step),
:class:`WindowSnapshot` (Figs. 2 and 4), :class:`WindowAligner` and :class:`ForecastAligner`.

Window rows are ``I_{M_n}..I_{M_n+w_i}``: ``w_i`` is the last row's offset here (not
everywhere: :func:`fpdtw.plain.method_c_step` writes Algorithm 3's line 6 as printed).
Method C's square window has ``w_i = min(w - 1, m - M_n)``, the literal one
``min(w, m - M_n)`` (:class:`~fpdtw.online.method_c.MethodC`).

Speed: the cost window dominates; its inner loop runs over joint-major forecast columns
(``F[j, c, col]``) so that LLVM vectorises it, with the branch-free arccos of
:func:`fpdtw.costs._acos01`. Kept because removing each cost more than 10 % (2026-11-25,
one commit each, reverted; docs/performance.md): the one-call stream path
(:func:`_stream_step`; without it Ma's median step went from 2.9 to 5.5 us, B and C at
w = 10 1.08-1.19x); the two flat work buffers and the int64 parameter vector it reads
(not measured apart from it); the window cache of a pair's aligners (:class:`WindowCache`,
:func:`run_group`; without all of these the grid took 316-344 s against 135-161 s).
"""

from __future__ import annotations

from abc import abstractmethod
from dataclasses import dataclass

import numba
import numpy as np

from fpdtw import limits
from fpdtw.costs import _geo_frame_w, _geo_line, _geo_line_w
from fpdtw.dtw import _accumulate
from fpdtw.errors import AlignmentError
from fpdtw.forecast import _euler_to_quat, order_codes
from fpdtw.motion.features import Frame, MotionFeatures
from fpdtw.online.base import OnlineAligner, check_count, check_input, compiled_frame
from fpdtw.online.typev import MAX_ADVANCE, resolve_constraint
from fpdtw.weights import joint_weights

#: ``D[0, 0]`` is set to this before Method B back-tracks (Algorithm 2).
B_CORNER = 10000.0


@numba.njit(cache=True)
def _forecast_columns(Tq, Te, q, first, last, codes, F, c0=0, shift=0, hold=False):
    """Fill ``F[j, :, c0 + i]``, i = first..last-1, with the frame ``i + shift`` ahead of T[q]
    (T[q] itself at 0 or with ``hold``, else dead reckoning).

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
    """Fill ``F`` (k, 4, ncols) with the step's target window; return ncols.

    ``with_prev`` (B, C's "square-tn"): T_n first; ``shift = 1``: from the first forecast."""
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
    """C[r, col] = eq. 1 of I[start + r] and F[:, :, col] (``wts`` empty: unweighted).

    Plain version: fpdtw.plain.cost_matrix.
    """
    acc = np.empty(ncols)
    for r in range(nrows):
        _geo_line_w(Iq[start + r], F, 0, ncols, acc, C[r], wts)


@numba.njit(cache=True)
def _fill_shared(Iq, Tq, Te, q, codes, start, nrows, w, c0, C, cF, cG, cN, cMeta, cKey):
    """Fill ``C[:nrows, c0:c0 + w]`` from a :class:`WindowCache`, computing what it lacks
    (a new step, or other frames at the same step (``cKey``), empties it first)."""
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
    """C[r, 0] = eq. 1 of I[start + r] and T_n (Method B's first column)."""
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
    """Offset r allowed (``limit``: the largest allowed; ``allow``: offsets 0..3)?

    Plain version: fpdtw.plain.allowed_rows.
    """
    if r > limit:
        return False
    if r <= 3:
        return allow[r] != 0
    return True


@numba.njit(cache=True)
def _accumulate_reverse(C, nrows, ncols, D, open_end=False, wd=1.0):
    """Reverse accumulation from the far corner back to (0, 0), symmetric1 (``wd = 1``) or
    symmetric2 (``wd = 2``); ``open_end``: the path may end in any row of the last column.

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
    """Method B's back-track to (0, 0): ties to the diagonal, then the target step
    (``input_first``: the input step); ``P[c]``: the lowest row visited in column c.
    Returns the number of cells in ``path``.

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
    """Method B on a filled window (mask, accumulate, ``D[0, 0] = 10000``, back-track):
    returns (P_1, path length).

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
    """Method C on a filled window (mask, reverse accumulation by ``reading``, argmin of
    column 0, ties low or with ``ties_high`` high): the offset, -1 if no row is allowed.

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
    """Method A's window: ``c[r]`` = eq. 1 of I[start + r] and t; the argmin over the
    allowed rows (ties as :func:`_choose_c`), -1 if no row is allowed.

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
    """``off``, or AlignmentError when no row was allowed: a masked row is never picked.

    Plain version: fpdtw.plain.checked_choice.
    """
    if off < 0 or not _is_allowed(off, limit, allow):
        raise AlignmentError("no row of the window is allowed by the Type V state")
    return off


#: Entries of an aligner's parameter vector (int64) for :func:`_window_step`.
P_METHOD, P_W, P_READING, P_SHIFT, P_HOLD, P_TIES_HIGH, P_INPUT_FIRST, P_START_BEST = range(8)
P_TYPEV, P_SHARED = 8, 9
#: Half-width of the global band around ``M = q`` (0: none; see :class:`ForecastAligner`).
P_BAND = 10
#: 1: eq. 1's joints weighted (the weights go to the kernels beside ``prm``).
P_WEIGHTED = 11
#: 1: the band clips the window's rows (``"half-w"``); 0: it masks them (``"1s"``).
P_BAND_CLIP = 12
N_PARAMS = 13
#: Method codes of ``P_METHOD``.
METHOD_A, METHOD_B, METHOD_C = 0, 1, 2
#: Kinds of step (``out[0]`` of :func:`_window_step`).
STEP_FIRST, STEP_WARMUP, STEP_END, STEP_WINDOW = 0, 1, 2, 3
#: Length of ``out``: kind, rows, columns, (B) path length, offset of the first row.
N_OUT = 5
#: Frames needed before forecasting (dead reckoning on two frames).
SMOOTHING = 2


@numba.njit(cache=True)
def _mask_band(C, nrows, col, q, start, band):
    """Global band (beyond the papers): ``C[r, col] = +inf`` where ``|start + r - q| > band``."""
    if band <= 0:
        return
    for r in range(nrows):
        if abs(start + r - q) > band:
            C[r, col] = np.inf


@numba.njit(cache=True)
def _clip_band(start, nrows, q, band):
    """``(first, rows)``: the rows of the window inside the band; ``(0, nrows)`` when no
    row is (then masked, and refused by :func:`_check_band`)."""
    lo = max(0, q - band - start)
    hi = min(nrows - 1, q + band - start)
    if lo > hi:
        return 0, nrows
    return lo, hi - lo + 1


@numba.njit(cache=True)
def _check_band(off, q, start, band):
    """Raise when the chosen row lies outside the band (no row of the window was inside)."""
    if band > 0 and abs(start + off - q) > band:
        raise ValueError("global band: no input frame of the window lies inside the band")


@numba.njit(cache=True)
def _first_frame(Iq, Tq, w, m, start_best, wts):
    """``M_0``: 0, or with ``start_best`` the best match (eq. 1) of T_0 among I_0..I_w."""
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
    """``(limit, allow)`` of :func:`_is_allowed` in Type V state ``state[0]``."""
    allow = np.ones(4, dtype=np.int64)
    if prm[P_TYPEV] == 0:
        return np.iinfo(np.int64).max, allow
    for a in range(4):
        allow[a] = 1 if table[state[0], a] >= 0 else 0
    return MAX_ADVANCE, allow


@numba.njit(cache=True)
def _advance_state(state, prm, table, advance):
    """Type V: the state after an advance (a forced hold at m leaves it as it is)."""
    if prm[P_TYPEV] != 0 and 0 <= advance <= MAX_ADVANCE and table[state[0], advance] >= 0:
        state[0] = table[state[0], advance]


@numba.njit(cache=True)
def _a_step(Iq, Tq, q, M, state, prm, table, c, out, wts):
    """:func:`_window_step` for Method A, with only the arrays it needs.

    Plain version: fpdtw.plain.method_a_step.
    """
    m = Iq.shape[0] - 1
    w = prm[P_W]
    out[1:5] = 0
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

    ``M[:q]``: the map so far; ``state[0]``: the Type V state; ``prm``: the ``P_*`` vector;
    ``cF..cKey``: a :class:`WindowCache` (with ``P_SHARED``); ``out``: the step's record;
    ``wts``: eq. 1's joint weights, or empty for eq. 1 as written; the rest scratch.

    Plain version: fpdtw.plain.method_a_step, method_b_step and method_c_step.
    """
    method = prm[P_METHOD]
    if method == METHOD_A:
        return _a_step(Iq, Tq, q, M, state, prm, table, C[:, 0], out, wts)
    m = Iq.shape[0] - 1
    w = prm[P_W]
    out[1:5] = 0
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
    """Every aligner of ``params`` (one row each) over the whole target, in lockstep, with
    shared scratch; ``M`` (aligners, frames) gets the maps."""
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


#: Header of the int64 work buffer: joints k, window capacity W = w + 1, Type V states.
_H_K, _H_W, _H_NS = 0, 1, 2
_HEADER = 3


@numba.njit(cache=True)
def _head_views(work, iwork):
    """``prm, table, tv, out`` and column 0 of ``C``: all Method A needs, in one reshape
    (each of :func:`_work_views`' reshapes costs about 0.1 us)."""
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
    """An aligner's scratch, parameters and state as views of ``work`` (float64) and
    ``iwork`` (int64, after the header ``k, W, ns``): a compiled call costs about 0.1 us per
    array argument, and :func:`_stream_step` runs once per frame."""
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
def _stream_step(Iq, Tq, Te, M, q, fq, fe, work, iwork):
    """The whole ``step`` in one call: store the frame in row ``q``, step, store ``M[q]``;
    -1 (a frame of another shape, or not finite) or -2 (weighted joints): the caller takes the
    general path."""
    if iwork[_HEADER + P_WEIGHTED] != 0:
        return -2
    k = Iq.shape[1]
    if fq.shape[0] != k or fq.shape[1] != 4 or fe.shape[0] != k or fe.shape[1] != 3:
        return -1  # none stored
    finite = True  # else the general path names the frame and the joint
    for j in range(k):
        for a in range(4):
            Tq[q, j, a] = fq[j, a]
            finite &= np.isfinite(fq[j, a])
        for a in range(3):
            Te[q, j, a] = fe[j, a]
            finite &= np.isfinite(fe[j, a])
    if not finite:
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


class WindowCache:
    """Forecast and window costs shared by B/C aligners stepping over one target together.

    The forecast at a target frame, and each cost cell against it, is the same for Methods B
    and C at every window and reading: aligners given one cache (of input ``I``, windows up
    to ``w_max``) and fed the same frames in lockstep compute each once. Other frames at the
    same step empty it: the maps are the same with or without it (tested)."""

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


@dataclass
class WindowSnapshot:
    """What one step of a window method did (``record=True``).

    ``q``: the target frame mapped (``n + 1``); ``kind``: ``"first"``, ``"warmup"``,
    ``"end"`` (input exhausted) or ``"window"``; ``start`` = ``M_n`` (-1 at q = 0);
    the rows are ``I_{M_n + first}..I_{M_n + w_i}``; ``offset`` = ``M_{n+1} - M_n``; ``M`` =
    ``M_{n+1}``. ``C``, ``D`` (rows, ncols): the costs (eq. 1; Type V-masked cells +inf, but
    Method A's) and their accumulation (B: ``D[0, 0]`` then 10000; C: reverse); ``path``
    (L, 2) and ``P`` (ncols,): Method B's path and lowest row per column (``P[1]`` is the
    choice); ``score`` (rows,): what Method C's argmin compares; ``allowed`` (4,) and
    ``state``: Type V's offsets and state before the step.

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


class WindowAligner(OnlineAligner):
    """Common base of Methods A, B and C (``I``: the input motion; ``w``: the window in frames).

    ``M_0 = 0``, or with ``start="best"`` the best match of ``T_0`` among ``I_0..I_w`` (a
    silent choice of the paper, switchable for notebook 15). The input window shrinks at the
    end of the input. ``constraint="typeV"`` masks the offsets the Type V state does not
    allow (:mod:`fpdtw.online.typev`); once the input is exhausted the hold at ``m`` is
    forced whatever the state. Non-default ``options`` are named in brackets (``"Mc w40
    (literal window)"``). ``record=True`` keeps a :class:`WindowSnapshot` of the last step
    in ``last_window``. Subclasses give :meth:`params` and :meth:`_window_record`."""

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
        # EMPTY weights: eq. 1 as written, exactly
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
        ns = table.shape[0]
        self._work = np.zeros(W * W + k * 4 * W + W * W + W + 4 * k + 1 + 12 * k)
        self._iwork = np.zeros(_HEADER + N_PARAMS + 4 * ns + 1 + N_OUT + k + 5 * W + 3, np.int64)
        self._iwork[[_H_K, _H_W, _H_NS]] = k, W, ns
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
        name = self.name_for(self.w, **self.settings)
        self.name = name if self.constraint is None else f"{name} + {self.constraint.name}"

    def _configure(self) -> None:
        """Fill the parameter vector; choose the cache arrays and the one-call path."""
        self._params[:] = self.params()
        self._cache_arrays = self._placeholder if self.cache is None else self.cache.arrays()
        # the one-call path: no debug record, no shared cache, eq. 1 unweighted
        self._lean = not self.record and self.cache is None and self._wts.shape[0] == 0

    def params(self) -> np.ndarray:
        """This aligner's parameter vector (int64, ``N_PARAMS``)."""
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
        """The name of a configuration, e.g. ``"Mc w40 (literal window)"``.

        ``MethodC.name_for(40, window="literal")``; ``typev`` adds ``" + Type V"``."""
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
        """Receive ``T_{n+1}``, return ``M_{n+1}``: one compiled call (:func:`_stream_step`)
        in the common case, else the general path after checking the frame's shape."""
        if self.n_received == 0:
            self._begin_take(frame)
        i = self.n_received - self._start
        if self._lean and i == self._M.shape[0]:  # full: room made here, for the compiled call
            self._make_room()
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

    def _snap(self, q, kind, start, w_i, m_next, state=None, **arrays):
        """Keep the debug record of a step; ``state``: the Type V state before it."""
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

    Warm-up ``n < s`` (``s = 2``): ``M_{n+1} = min(M_n + 1, m)`` (the paper's ``n + 1``
    from ``M_0 = 0``); ``M_n >= m``: ``m``."""

    #: Smoothing window: frames needed before forecasting (dead reckoning: 2).
    s = SMOOTHING
    #: Beyond the papers (notebook 16): the conclusion's global band; weighted joints.
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
        """Options beyond the papers (notebook 16): a global band, weighted joints.

        Bands around the diagonal ``M_q = q``: ``"1s"`` masks the rows more than ``round(1 s x
        fps)`` frames away in the column that decides the step; ``"half-w"`` (``B = max(1,
        floor(w / 2))``, chosen on 2026-11-24 after the 1 s band's results, before any run of
        it) does not compute them, the conclusion's global constraint. A step with no row inside
        the band raises ValueError; a band with Type V is refused. ``weights="travel"``: eq. 1
        weighted by :func:`fpdtw.weights.joint_weights` of the input."""
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
    """Run Method B and C aligners of one input over target ``T`` in one compiled loop: their
    maps (int64 (n,) each), those of streaming each, without a Python call per frame."""
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
