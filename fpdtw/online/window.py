"""Shared machinery of the FP-DTW window methods A, B and C (Algorithms 1-3).

* numba kernels for one step: dead-reckoning forecast -> quaternions -> geodesic cost
  window -> accumulation (forward for B, reverse for C) -> back-tracking (B), all into
  scratch buffers the aligner preallocates once;
* :class:`WindowSnapshot`, the debug record of the last step (``record=True``), used to
  draw the paper's Fig. 2 and Fig. 4 from a real run;
* :class:`WindowAligner`, the common base class: argument checks, the warm-up and
  end-of-input rules, the Type V state, the snapshot;
* :func:`reference_run`, which runs the plain-numpy reference step of a method
  (``reference_step_a/b/c``) over a whole target, for the tests.

Speed. The ``(w_i + 1) x w`` geodesic cost window, recomputed every frame, dominates.
Its inner loop runs over the forecast frames, stored joint-major as ``F[j, c, col]``
(structure of arrays), so that LLVM vectorises it; the ``arccos`` of eq. 1 is
:func:`fpdtw.costs._acos01`, a branch-free polynomial arccos on [0, 1] (1 ulp from
``math.acos``) that vectorises, where libm's ``acos`` is a scalar call five times slower.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba
import numpy as np

from ..costs import _acos01, geodesic_cost_matrix_numpy
from ..errors import AlignmentError
from ..features import Frame, MotionFeatures
from ..forecast import _euler_to_quat, forecast_joints, order_codes
from ..rotations import euler_to_quat
from .base import OnlineAligner
from .typev import MAX_ADVANCE, resolve_constraint

_TWO_OVER_PI = 2.0 / math.pi

#: ``D[0, 0]`` is set to this before Method B back-tracks (Algorithm 2).
B_CORNER = 10000.0

# --- one step's kernels ----------------------------------------------------------------


@numba.njit(cache=True)
def _forecast_window(Tq, Te, q, w, with_prev, codes, F):
    """Fill ``F[j, :, col]`` (k, 4, ncols) with the target window of the step at q.

    with_prev (Method B): col 0 = T_n (= T[q-1]), col 1 = T_{n+1}, col 1+i = forecast i.
    Otherwise (Method C): col 0 = T_{n+1} (= T[q]), col i = forecast i, i = 1..w-1.
    Forecast i is T_{n+1} + i * (T_{n+1} - T_n) in Euler angles, as quaternions; the
    known frames keep their received quaternions. Returns the number of columns.
    """
    k = Tq.shape[1]
    c0 = 0
    if with_prev:
        for j in range(k):
            for a in range(4):
                F[j, a, 0] = Tq[q - 1, j, a]
        c0 = 1
    for j in range(k):
        for a in range(4):
            F[j, a, c0] = Tq[q, j, a]
    for i in range(1, w):
        col = c0 + i
        fi = float(i)
        for j in range(k):
            e0 = Te[q, j, 0] + fi * (Te[q, j, 0] - Te[q - 1, j, 0])
            e1 = Te[q, j, 1] + fi * (Te[q, j, 1] - Te[q - 1, j, 1])
            e2 = Te[q, j, 2] + fi * (Te[q, j, 2] - Te[q - 1, j, 2])
            qw, qx, qy, qz = _euler_to_quat(e0, e1, e2, codes[j])
            F[j, 0, col] = qw
            F[j, 1, col] = qx
            F[j, 2, col] = qy
            F[j, 3, col] = qz
    return c0 + w


@numba.njit(cache=True)
def _cost_window(Iq, start, nrows, F, ncols, C):
    """C[r, col] = geoDistance(I[start + r], F[:, :, col]) (eq. 1), r < nrows, col < ncols.

    The joint sum runs in joint order and the dot product in (w, x, y, z) order, as in
    :func:`fpdtw.costs.geodesic_cost_matrix`.
    """
    k = Iq.shape[1]
    for r in range(nrows):
        row = C[r]
        for col in range(ncols):
            row[col] = 0.0
        for j in range(k):
            a0 = Iq[start + r, j, 0]
            a1 = Iq[start + r, j, 1]
            a2 = Iq[start + r, j, 2]
            a3 = Iq[start + r, j, 3]
            f0 = F[j, 0]
            f1 = F[j, 1]
            f2 = F[j, 2]
            f3 = F[j, 3]
            for col in range(ncols):
                d = abs(a0 * f0[col] + a1 * f1[col] + a2 * f2[col] + a3 * f3[col])
                d = min(d, 1.0)
                row[col] += _acos01(d)
        for col in range(ncols):
            row[col] *= _TWO_OVER_PI


@numba.njit(cache=True, inline="always")
def _is_allowed(r, limit, allow):
    """Offset r allowed? ``limit`` = largest allowed offset; allow[0..3] per offset."""
    if r > limit:
        return False
    if r <= 3:
        return allow[r] != 0
    return True


@numba.njit(cache=True)
def _accumulate(C, nrows, ncols, D):
    """Forward DTW accumulation (symmetric1) from (0, 0)."""
    D[0, 0] = C[0, 0]
    for col in range(1, ncols):
        D[0, col] = C[0, col] + D[0, col - 1]
    for r in range(1, nrows):
        D[r, 0] = C[r, 0] + D[r - 1, 0]
        for col in range(1, ncols):
            D[r, col] = C[r, col] + min(D[r - 1, col - 1], min(D[r - 1, col], D[r, col - 1]))


@numba.njit(cache=True)
def _accumulate_reverse(C, nrows, ncols, D):
    """Reverse accumulation from the far corner (nrows-1, ncols-1) back to (0, 0)."""
    lr = nrows - 1
    lc = ncols - 1
    D[lr, lc] = C[lr, lc]
    for col in range(lc - 1, -1, -1):
        D[lr, col] = C[lr, col] + D[lr, col + 1]
    for r in range(lr - 1, -1, -1):
        D[r, lc] = C[r, lc] + D[r + 1, lc]
        for col in range(lc - 1, -1, -1):
            D[r, col] = C[r, col] + min(D[r + 1, col + 1], min(D[r + 1, col], D[r, col + 1]))


@numba.njit(cache=True)
def _backtrack(D, nrows, ncols, P, path):
    """Method B's back-track from (nrows-1, ncols-1) to (0, 0) with the overwrite rule.

    Steps: diagonal (r-1, c-1), target (r, c-1), input (r-1, c); ties prefer the
    diagonal, then the target step (which keeps the higher input frame). On row 0 only
    target steps, on column 0 only input steps. ``P[c]`` ends as the lowest row the path
    visits in column c (a step back one input frame on the same column overwrites it).
    ``path`` gets the cells from the far corner back to (0, 0); returns their number.
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
            elif dh <= dv:
                c -= 1
            else:
                r -= 1
        P[c] = r
        path[n, 0] = r
        path[n, 1] = c
        n += 1
    return n


@numba.njit(cache=True)
def _step_b(Iq, Tq, Te, q, start, w, w_i, codes, limit, allow, F, C, D, P, path):
    """One Method B step (Algorithm 2, window branch); returns (P_1, path length)."""
    nrows = w_i + 1
    ncols = _forecast_window(Tq, Te, q, w, True, codes, F)
    _cost_window(Iq, start, nrows, F, ncols, C)
    for r in range(nrows):
        if not _is_allowed(r, limit, allow):
            C[r, 1] = np.inf
    _accumulate(C, nrows, ncols, D)
    D[0, 0] = B_CORNER
    n = _backtrack(D, nrows, ncols, P, path)
    return P[1], n


@numba.njit(cache=True)
def _step_c(Iq, Tq, Te, q, start, w, w_i, codes, limit, allow, F, C, D):
    """One Method C step (Algorithm 3, window branch); returns the chosen offset."""
    nrows = w_i + 1
    ncols = _forecast_window(Tq, Te, q, w, False, codes, F)
    _cost_window(Iq, start, nrows, F, ncols, C)
    for r in range(nrows):
        if not _is_allowed(r, limit, allow):
            C[r, 0] = np.inf
    _accumulate_reverse(C, nrows, ncols, D)
    best = -1
    for r in range(nrows):
        if _is_allowed(r, limit, allow) and (best < 0 or D[r, 0] < D[best, 0]):
            best = r
    return max(best, 0)


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
        exhausted: ``w_i = 0`` / ``M_n >= m``, hold at m) or ``"window"``.
    start : int
        Window start ``M_n`` (-1 for q = 0).
    w_i : int
        Input window size: rows ``I_{M_n}..I_{M_n + w_i}``.
    offset : int
        Chosen offset, ``M_{n+1} - M_n``.
    M : int
        ``M_{n+1}``.
    C : ndarray of float64, shape (w_i + 1, ncols) or None
        Cost window (eq. 1); rows = input frames ``M_n + r``, columns = target window:
        A: ``[T_{n+1}]``; B: ``[T_n, T_{n+1}, forecasts]`` (w + 1); C: ``[T_{n+1},
        forecasts]`` (w). Cells masked by Type V are +inf.
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

    Paper: FP-DTW Fig. 2 (window), Fig. 4 (Method B's path and choice).
    Notebook: 03_fig2_fig4_windows.ipynb
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


# --- the common aligner ---------------------------------------------------------------


class WindowAligner(OnlineAligner):
    """Common base of Methods A, B and C.

    Common rules (each method's docstring repeats the ones it uses):

    * First target frame: ``M_0 = 0`` (both motions start aligned, DTW's boundary
      condition).
    * Window sizes are in frames; the input window ``{I_{M_n}..I_{M_n + w_i}}`` has
      ``w_i + 1`` rows, ``w_i = min(w, m - M_n)`` (it shrinks at the end of the input).
    * ``constraint="typeV"``: before choosing, offsets the Type V state table
      (:mod:`fpdtw.online.typev`) does not allow are masked; the state advances with
      every step (warm-up included). When the input is exhausted the only choice is a
      hold at ``m``, whatever the state (the constraint cannot hold there).
    * ``record=True`` keeps a :class:`WindowSnapshot` of the last step in
      ``last_window`` (off by default: it copies the window every frame).
    * ``state`` holds the current Type V state (index into ``constraint.states``), None
      without a constraint; ``reset()`` puts it back to the start state.

    Parameters
    ----------
    I : MotionFeatures
        Input (recorded) motion.
    w : int
        Window size in frames, >= 1.
    constraint : None, "typeV" or TypeV
    record : bool
    """

    #: Method letter in names ("Ma", "Mb", "Mc").
    label = "M?"

    def __init__(self, I: MotionFeatures, w: int, *, constraint=None, record=False):
        if isinstance(w, bool) or not isinstance(w, int | np.integer) or w < 1:
            raise AlignmentError(f"{type(self).__name__}: window w must be an int >= 1, got {w!r}")
        if not isinstance(I, MotionFeatures):
            raise AlignmentError("the input motion must be given as MotionFeatures")
        if I.n_frames < 1:
            raise AlignmentError(f"input motion {I.name!r} has no frames")
        from .. import limits

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
        Q, E = np.shape(I.quats), np.shape(I.euler)
        if len(Q) != 3 or Q[2] != 4 or E != Q[:2] + (3,) or len(I.orders) != Q[1]:
            raise AlignmentError(
                f"input motion {I.name!r}: inconsistent features: quats {I.quats.shape}, "
                f"euler {I.euler.shape}, {len(I.orders)} rotation orders"
            )
        try:
            self._codes = order_codes(I.orders)
        except ValueError as e:
            raise AlignmentError(f"input motion {I.name!r}: {e}") from None
        self._Iq = np.ascontiguousarray(I.quats, dtype=np.float64)
        if self.constraint is None:
            self._limit = np.iinfo(np.int64).max
        else:
            self._limit = MAX_ADVANCE
        self._all = np.ones(4, dtype=np.int64)
        if self.constraint is not None:
            self._allow_by_state = (self.constraint.table >= 0).astype(np.int64)
        super().__init__(I)
        self.name = self._make_name()

    def _make_name(self) -> str:
        base = f"{self.label} w{self.w}"
        return base if self.constraint is None else f"{base} + {self.constraint.name}"

    def reset(self) -> None:
        super().reset()
        self.state = None if self.constraint is None else self.constraint.start
        self.last_window = None

    def window_snapshot(self) -> WindowSnapshot | None:
        """The :class:`WindowSnapshot` of the last step (needs ``record=True``)."""
        return self.last_window

    def step(self, frame: Frame) -> int:
        """Receive target frame ``T_{n+1}`` and return ``M_{n+1}``."""
        k = self._Iq.shape[1]
        if np.shape(frame.quats) != (k, 4) or np.shape(frame.euler) != (k, 3):
            raise AlignmentError(
                f"target frame {self.n_received}: expected quats ({k}, 4) and euler ({k}, 3) "
                f"like the input motion {self.I.name!r}, got {np.shape(frame.quats)} and "
                f"{np.shape(frame.euler)}"
            )
        return super().step(frame)

    # -- helpers for subclasses ----------------------------------------------------------
    def _allow(self):
        """Allowed-offset vector (int64, shape (4,)) of the current Type V state."""
        if self.constraint is None:
            return self._all
        return self._allow_by_state[self.state]

    def _advance_state(self, advance: int) -> None:
        if self.constraint is not None:
            nxt = self.constraint.next_state(self.state, advance)
            if nxt >= 0:  # an illegal move is only ever a forced hold at m
                self.state = nxt

    def _snap(self, q, kind, start, w_i, m_next, **arrays):
        allowed = None
        state = None
        if self.constraint is not None:
            allowed = self._allow_by_state[self.state].astype(bool)
            state = self.constraint.states[self.state]
        offset = m_next - max(start, 0)
        self.last_window = WindowSnapshot(
            q, kind, start, w_i, offset, m_next, allowed=allowed, state=state, **arrays
        )


# --- reference runs -------------------------------------------------------------------


def reference_prologue(I, T_quats, M, w, s):
    """The branches Methods B and C share before their window (plain Python, for tests).

    Returns either a finished :class:`WindowSnapshot` (first frame, warm-up
    ``n < s``, input exhausted) or the tuple ``(q, n, M_n, w_i)`` of a window step.

    Paper: FP-DTW Algorithms 2 and 3 (first lines).
    """
    q = len(T_quats) - 1
    if q == 0:
        return WindowSnapshot(0, "first", -1, 0, 0, 0)
    m = I.n_frames - 1
    n = q - 1
    Mn = int(M[n])
    if n < s:
        return WindowSnapshot(q, "warmup", Mn, 0, min(n + 1, m) - Mn, min(n + 1, m))
    if Mn >= m:
        return WindowSnapshot(q, "end", Mn, 0, m - Mn, m)
    return q, n, Mn, min(w, m - Mn)


def reference_forecast_quats(T_euler, orders, w: int) -> np.ndarray:
    """Plain-numpy forecast quaternions of frames ``T_{n+1} + i delta``, ``i = 1..w-1``.

    Parameters
    ----------
    T_euler : ndarray of float, shape (q + 1, k, 3)
        Target Euler angles received so far (the last two are used).
    orders : sequence of str, length k
    w : int

    Returns
    -------
    Q : ndarray of float64, shape (w - 1, k, 4)
        Converted with :func:`fpdtw.rotations.euler_to_quat` (scipy), independent of the
        numba conversion.
    """
    E = forecast_joints(T_euler[-2], T_euler[-1], w)[1:]
    k = E.shape[1]
    Q = np.empty((E.shape[0], k, 4))
    for j in range(k):
        Q[:, j] = euler_to_quat(E[:, j], orders[j])
    return Q


def reference_cost(I_quats, start, w_i, W) -> np.ndarray:
    """Reference cost window: :func:`fpdtw.costs.geodesic_cost_matrix_numpy`."""
    return geodesic_cost_matrix_numpy(I_quats[start : start + w_i + 1], W)


def reference_mask(allowed, n_rows) -> np.ndarray:
    """Bool (n_rows,): rows (offsets) allowed; None = unconstrained."""
    ok = np.ones(n_rows, dtype=bool)
    if allowed is not None:
        ok[:] = False
        ok[: min(4, n_rows)] = np.asarray(allowed, dtype=bool)[: min(4, n_rows)]
    return ok


def reference_run(aligner: WindowAligner, T: MotionFeatures):
    """Run the plain-numpy reference of ``aligner``'s method over a whole target.

    Uses ``type(aligner).reference_step`` with the aligner's input, window and
    constraint; tracks the Type V state with the pure-Python state table.

    Returns
    -------
    M : ndarray of int64, shape (n,)
    snaps : list of WindowSnapshot
        One per target frame.
    """
    step = type(aligner).reference_step
    tv = aligner.constraint
    state = None if tv is None else tv.start
    M = np.empty(T.n_frames, dtype=np.int64)
    snaps = []
    for q in range(T.n_frames):
        allowed = None if tv is None else tv.allowed(state)
        snap = step(aligner.I, T.quats[: q + 1], T.euler[: q + 1], M[:q], aligner.w, allowed)
        M[q] = snap.M
        if tv is not None:
            snap.allowed = allowed
            snap.state = tv.states[state]
            if q > 0:
                nxt = tv.next_state(state, int(M[q] - M[q - 1]))
                state = nxt if nxt >= 0 else state
        snaps.append(snap)
    return M, snaps


__all__ = [
    "B_CORNER",
    "WindowAligner",
    "WindowSnapshot",
    "reference_cost",
    "reference_forecast_quats",
    "reference_mask",
    "reference_run",
]
