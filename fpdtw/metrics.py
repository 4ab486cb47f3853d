"""Evaluation metrics of the FP-DTW paper: similarity (eq. 2) and deviation (eq. 3).

:func:`kendall_tau_b` is an ``O(n log n)`` numba kernel (Knight 1966: sort by ``(x, y)``,
count the inversions of ``y`` by merge sort) that agrees with ``scipy.stats.kendalltau``
at about 1/100 of its cost. The readings of eq. 2 are the options of :func:`similarity`.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from fpdtw.errors import AlignmentError
from fpdtw.motion.rotations import quat_rotate

#: An axis whose trajectory range (max - min) is below this in a motion is "flat".
FLAT_RANGE = 0.001

#: Score of an axis that is flat in exactly one of the two motions (tau undefined).
ONE_FLAT_SCORE = 0.0

#: The unit vector rotated by each joint's local rotation (the reading notes: (0, 1, 0)).
BONE_AXIS = (0.0, 1.0, 0.0)


def _as_map(M, what="map") -> np.ndarray:
    M = np.asarray(M)
    if M.ndim != 1 or M.shape[0] == 0:
        raise AlignmentError(f"a {what} must be a non-empty 1-D array, got shape {M.shape}")
    if not np.issubdtype(M.dtype, np.integer):
        if not np.issubdtype(M.dtype, np.floating) or not np.all(M == np.round(M)):
            raise AlignmentError(f"a {what} must hold integer frame indices, got {M.dtype}")
    return M.astype(np.int64)


def is_monotonic(M) -> bool:
    """True when the map ``M`` (int, shape (n + 1,)) never goes backwards."""
    M = _as_map(M)
    return bool(np.all(np.diff(M) >= 0))


def in_range(M, m: int) -> bool:
    """True when every entry of the map ``M`` (int, shape (n + 1,)) is in ``0..m``."""
    M = _as_map(M)
    return bool(M.min() >= 0 and M.max() <= m)


#: Frames eq. 3 averages over: ``"printed"`` (default), ``q = 1..n`` divided by ``n`` as
#: the paper prints it; ``"all"``, every target frame ``q = 0..n`` divided by ``n + 1``.
DEVIATION_FRAMES = ("printed", "all")


def deviation(P_a, P_b, frames: str = "printed") -> float:
    """Mean absolute difference between two maps, in frames (eq. 3).

    Reading: ``sum_{q=1..n} |P_a(q) - P_b(q)| / n`` as printed (frame 0 not counted);
    ``frames="all"``: over ``q = 0..n``, divided by ``n + 1`` (what fpdtw computed before).

    Parameters
    ----------
    P_a, P_b : ndarray of int, shape (n + 1,)
        Maps target frame -> input frame.
    frames : {"printed", "all"}

    Returns
    -------
    d : float
        In frames (18 frames = 150 ms at 120 Hz is the paper's benchmark).

    Plain version: fpdtw.plain.deviation.
    Paper: FP-DTW eq. 3.
    Notebook: 06_fig5_fig6_scores.ipynb
    """
    P_a = _as_map(P_a, "map P_a")
    P_b = _as_map(P_b, "map P_b")
    if P_a.shape != P_b.shape:
        raise AlignmentError(
            f"maps of different lengths: {P_a.shape[0]} and {P_b.shape[0]} target frames"
        )
    if frames not in DEVIATION_FRAMES:
        raise AlignmentError(f"frames must be one of {DEVIATION_FRAMES}, got {frames!r}")
    diff = np.abs(P_a - P_b)
    if frames == "all":
        return float(np.mean(diff))
    if diff.size < 2:
        raise AlignmentError(
            "eq. 3 averages over the target frames q = 1..n: maps of one frame have none "
            "(frames='all' counts frame 0)"
        )
    return float(np.mean(diff[1:]))


def step_counts(M, m: int) -> dict:
    """Counts of the steps ``q = 1..n`` of a map ``M`` (int, shape (n + 1,)) by what they did, ``m``
    the last input frame: a dict of ``steps`` (n), ``exhausted`` (taken after the input ran out,
    ``M_{q-1} >= m``), ``live`` (the others) and ``holds`` (live steps with ``M_q = M_{q-1}``)."""
    M = _as_map(M)
    live = M[:-1] < m
    return dict(
        steps=int(M.size - 1),
        exhausted=int(M.size - 1 - np.count_nonzero(live)),
        live=int(np.count_nonzero(live)),
        holds=int(np.count_nonzero((np.diff(M) == 0) & live)),
    )


def hold_share(M, m: int) -> float:
    """Share of the live steps that hold (:func:`step_counts`); 0.0 without live steps."""
    c = step_counts(M, m)
    return c["holds"] / c["live"] if c["live"] else 0.0


def exhausted_share(M, m: int) -> float:
    """Share of the steps taken after the input ran out (:func:`step_counts`).

    Paper: FP-DTW Section 5 ("running out of input frames, early in the alignment").
    """
    c = step_counts(M, m)
    return c["exhausted"] / c["steps"] if c["steps"] else 0.0


def stick_skip_index(M, m: int) -> float:
    """Median over target frames of ``M_q / m - q / n``, in [-1, 1]: < 0 sticks (below
    Fig. 7's diagonal), > 0 skips; ``M`` and ``m`` as in :func:`step_counts`.

    Paper: FP-DTW Section 5 (reading of Fig. 7: "hot areas under the diagonal indicate
    ... sticking ... above the diagonal ... skipping")."""
    M = _as_map(M).astype(np.float64)
    n = max(M.size - 1, 1)
    return float(np.median(M / max(m, 1) - np.arange(M.size) / n))


@numba.njit(cache=True)
def _count_ties(s):
    """Sum of t (t - 1) / 2 over runs of equal values of sorted ``s``."""
    total = 0
    run = 1
    for i in range(1, s.shape[0]):
        if s[i] == s[i - 1]:
            run += 1
        else:
            total += run * (run - 1) // 2
            run = 1
    return total + run * (run - 1) // 2


@numba.njit(cache=True)
def _merge_count(y, buf):
    """Stable bottom-up merge sort of ``y`` in place; returns the number of inversions
    (pairs ``a < b`` with ``y[a] > y[b]``: discordant pairs once sorted by x)."""
    n = y.shape[0]
    swaps = 0
    width = 1
    while width < n:
        lo = 0
        while lo < n - width:
            mid = lo + width
            hi = min(lo + 2 * width, n)
            a = lo
            b = mid
            k = lo
            while a < mid and b < hi:
                if y[b] < y[a]:
                    buf[k] = y[b]
                    swaps += mid - a
                    b += 1
                else:
                    buf[k] = y[a]
                    a += 1
                k += 1
            while a < mid:
                buf[k] = y[a]
                a += 1
                k += 1
            while b < hi:
                buf[k] = y[b]
                b += 1
                k += 1
            for r in range(lo, hi):
                y[r] = buf[r]
            lo += 2 * width
        width *= 2
    return swaps


@numba.njit(cache=True)
def _tau(x, y, variant_a):
    """Kendall tau-b (``variant_a`` False; NaN if either vector is constant) or tau-a
    (``(concordant - discordant) / (N (N - 1) / 2)``) of two float64 vectors; NaN for N < 2."""
    n = x.shape[0]
    if n < 2:
        return np.nan
    # sort by (x, y): stable sort by y, then stable sort by x
    order = np.argsort(y, kind="mergesort")
    order = order[np.argsort(x[order], kind="mergesort")]
    xs = x[order]
    ys = y[order]
    n1 = _count_ties(xs)
    # pairs tied in x and in y
    n3 = 0
    run = 1
    for i in range(1, n):
        if xs[i] == xs[i - 1] and ys[i] == ys[i - 1]:
            run += 1
        else:
            n3 += run * (run - 1) // 2
            run = 1
    n3 += run * (run - 1) // 2
    swaps = _merge_count(ys, np.empty_like(ys))
    n2 = _count_ties(ys)  # ys is sorted now
    n0 = n * (n - 1) // 2
    s = (n0 - n1 - n2 + n3) - 2 * swaps  # concordant - discordant
    if variant_a:
        return s / float(n0)
    if n1 == n0 or n2 == n0:
        return np.nan
    return s / math.sqrt(float(n0 - n1) * float(n0 - n2))


def kendall_tau_b(x, y) -> float:
    """Kendall rank correlation tau-b (ties corrected), ``O(n log n)``.

    Parameters
    ----------
    x, y : ndarray of float, shape (N,)

    Returns
    -------
    tau : float
        NaN when ``N < 2`` or either vector is constant (as ``scipy.stats.kendalltau``).

    Plain version: fpdtw.plain.kendall_tau_b.
    Paper: FP-DTW eq. 2 (Kendall tau per joint axis).
    """
    x = np.ascontiguousarray(x, dtype=np.float64)
    y = np.ascontiguousarray(y, dtype=np.float64)
    if x.ndim != 1 or x.shape != y.shape:
        raise AlignmentError(
            f"kendall_tau_b needs two 1-D arrays of equal length: {x.shape}, {y.shape}"
        )
    return float(_tau(x, y, False))


@numba.njit(cache=True)
def _axis_scores(XA, XT, flat, one_flat, out, variant_a=False, toolkit=False):
    """Per-axis score; XA, XT (N, k, 3) float64; out (k, 3) (the rules of :func:`similarity`)."""
    N = XA.shape[0]
    for j in range(XA.shape[1]):
        for a in range(3):
            xa = np.empty(N)
            xt = np.empty(N)
            for f in range(N):
                xa[f] = XA[f, j, a]
                xt[f] = XT[f, j, a]
            flat_a = xa.max() - xa.min() < flat
            flat_t = xt.max() - xt.min() < flat
            if flat_a and flat_t:
                out[j, a] = 1.0
            elif (flat_a or flat_t) and not toolkit:
                out[j, a] = one_flat
            else:
                t = _tau(xa, xt, variant_a)
                out[j, a] = one_flat if np.isnan(t) else t
    return out


#: Kendall tau variants of :func:`similarity` (``tau=``).
TAU_VARIANTS = ("b", "a")

#: Flat-axis rules of :func:`similarity` (``flat=``).
FLAT_RULES = ("zero", "toolkit", "skip")


def _axis_vectors(axis, k: int) -> np.ndarray:
    """The unit vector of each of k joints, shape (k, 3), from an array (``"y"`` is
    :func:`joint_trajectories`' own case)."""
    if isinstance(axis, str):
        raise AlignmentError(
            f"axis {axis!r}: give 'y' or each joint's own vectors, shape (k, 3) "
            "(fpdtw.motion.rig.bone_directions for the bone reading)"
        )
    v = np.asarray(axis, dtype=np.float64)
    v = np.broadcast_to(v, (k, 3)) if v.shape in ((3,), (k, 3)) else None
    if v is None or not np.all(np.isfinite(v)):
        raise AlignmentError(f"axis vectors must be finite, shape (3,) or ({k}, 3)")
    norm = np.linalg.norm(v, axis=1)
    if np.any(norm < 1e-12):
        raise AlignmentError("axis vectors must not be zero")
    return v / norm[:, None]


def joint_trajectories(quats, axis="y") -> np.ndarray:
    """Joint trajectories: a unit vector rotated by each joint's rotation.

    Parameters
    ----------
    quats : ndarray of float, shape (F, k, 4)
        Unit quaternions (w, x, y, z): the local rotations (the default reading) or
        others (:func:`fpdtw.motion.rig.trajectory_rotations`).
    axis : "y" or ndarray of float, shape (3,) or (k, 3)
        ``"y"``: (0, 1, 0) for every joint; or each joint's own vector, normalised
        (e.g. :func:`fpdtw.motion.rig.bone_directions`).

    Returns
    -------
    X : ndarray of float64, shape (F, k, 3)

    Plain version: fpdtw.plain.joint_trajectories.
    Paper: FP-DTW eq. 2 ("the R^3 translation of a one unit length vector along
    the joint's orientation").
    """
    quats = np.asarray(quats, dtype=np.float64)
    if quats.ndim != 3 or quats.shape[2] != 4:
        raise AlignmentError(f"expected quaternions of shape (F, k, 4), got {quats.shape}")
    if isinstance(axis, str) and axis == "y":
        return np.ascontiguousarray(quat_rotate(quats, np.array(BONE_AXIS)))
    v = _axis_vectors(axis, quats.shape[1])
    return np.ascontiguousarray(quat_rotate(quats, v[None]))


def _check_options(tau, flat, skip):
    if tau not in TAU_VARIANTS:
        raise AlignmentError(f"tau must be one of {TAU_VARIANTS}, got {tau!r}")
    if flat not in FLAT_RULES:
        raise AlignmentError(f"flat must be one of {FLAT_RULES}, got {flat!r}")
    if isinstance(skip, bool) or not isinstance(skip, (int, np.integer)) or skip < 0:
        raise AlignmentError(f"skip must be a non-negative integer, got {skip!r}")


def similarity_per_axis(
    I_quats,
    T_quats,
    M,
    one_flat: float = ONE_FLAT_SCORE,
    *,
    tau: str = "b",
    flat: str = "zero",
    skip: int = 0,
    axis="y",
) -> np.ndarray:
    """Per-axis scores of :func:`similarity`: Kendall tau of each joint axis of the input
    warped by the map (``A = I[M]``) and the target.

    Parameters
    ----------
    I_quats : ndarray of float, shape (m + 1, k, 4)
    T_quats : ndarray of float, shape (n + 1, k, 4)
    M : ndarray of int, shape (n + 1,)
        Map target frame -> input frame, entries in ``0..m``.
    one_flat : float
        Score of an axis flat in exactly one motion (NaN marks such axes).
    tau, flat, skip, axis
        See :func:`similarity`; ``flat="skip"`` sets ``one_flat`` to NaN.

    Returns
    -------
    r : ndarray of float64, shape (k, 3)
        ``r[j, a]`` for joint j and axis a (x, y, z).

    Paper: FP-DTW eq. 2.
    """
    _check_options(tau, flat, skip)
    I_quats = np.asarray(I_quats, dtype=np.float64)
    T_quats = np.asarray(T_quats, dtype=np.float64)
    M = _as_map(M)
    if I_quats.ndim != 3 or T_quats.ndim != 3 or I_quats.shape[1:] != T_quats.shape[1:]:
        raise AlignmentError(
            f"input and target rotations must be (F, k, 4) with the same k: "
            f"{I_quats.shape}, {T_quats.shape}"
        )
    if M.shape[0] != T_quats.shape[0]:
        raise AlignmentError(
            f"the map has {M.shape[0]} entries but the target has {T_quats.shape[0]} frames"
        )
    m = I_quats.shape[0] - 1
    if not in_range(M, m):
        raise AlignmentError(f"the map has entries outside the input frames 0..{m}")
    if skip and M.shape[0] - skip < 2:
        raise AlignmentError(
            f"skip={skip} leaves {M.shape[0] - skip} of the target's {M.shape[0]} frames"
        )
    ax_I, ax_T = axis if isinstance(axis, tuple) and len(axis) == 2 else (axis, axis)
    XA = joint_trajectories(I_quats[M[skip:]], ax_I)
    XT = joint_trajectories(T_quats[skip:], ax_T)
    return trajectory_scores(XA, XT, one_flat, tau=tau, flat=flat)


def trajectory_scores(
    XA, XT, one_flat: float = ONE_FLAT_SCORE, *, tau: str = "b", flat: str = "zero"
) -> np.ndarray:
    """Per-axis scores of eq. 2 from trajectories already warped: ``XA``, ``XT`` (float64, shape (n
    + 1, k, 3)) -> (k, 3); ``joint_trajectories(I)[M]`` is the warped input's, so many maps of one
    pair reuse each motion's trajectories. Options as :func:`similarity_per_axis`.

    Paper: FP-DTW eq. 2.
    """
    _check_options(tau, flat, 0)
    XA = np.ascontiguousarray(XA, dtype=np.float64)
    XT = np.ascontiguousarray(XT, dtype=np.float64)
    if XA.shape != XT.shape or XA.ndim != 3 or XA.shape[2] != 3:
        raise AlignmentError(f"trajectories of different shapes: {XA.shape}, {XT.shape}")
    out = np.empty((XA.shape[1], 3))
    one = np.nan if flat == "skip" else float(one_flat)
    return _axis_scores(XA, XT, FLAT_RANGE, one, out, tau == "a", flat == "toolkit")


def similarity(
    I_quats, T_quats, M, *, tau: str = "b", flat: str = "zero", skip: int = 0, axis="y"
) -> float:
    """Similarity of the warped input and the target (mean Kendall tau over 3k axes).

    An axis flat (range below :data:`FLAT_RANGE`) in both motions scores 1 (the paper's
    rule). Readings of Section 5, the defaults first:

    * ``tau``: ``"b"`` (ties corrected, as scipy and the authors' toolkit) or ``"a"``.
    * ``flat``, an axis flat in one motion only: ``"zero"`` scores 0 (tau is undefined);
      ``"toolkit"`` (the authors' FBXMotionToolkit) takes tau, 0 if undefined; ``"skip"``
      leaves it out of the mean (notebook 15's choice).
    * ``skip``: the first ``skip`` target frames left out (default 0).
    * ``axis``: ``"y"``, (0, 1, 0) for every joint; or each joint's vector, shape (k, 3),
      or a pair ``(input's, target's)`` (:func:`fpdtw.motion.rig.bone_directions`).
    * the rotations passed in: local (default) or those of
      :func:`fpdtw.motion.rig.trajectory_rotations`.

    Parameters as :func:`similarity_per_axis`.

    Returns
    -------
    r : float
        In ``[-1, 1]``; NaN when ``flat="skip"`` leaves out every axis.

    Plain version: fpdtw.plain.similarity.
    Paper: FP-DTW eq. 2.
    Notebook: 06_fig5_fig6_scores.ipynb
    """
    r = similarity_per_axis(I_quats, T_quats, M, tau=tau, flat=flat, skip=skip, axis=axis)
    if flat == "skip":
        return float(np.nanmean(r)) if np.isfinite(r).any() else float("nan")
    return float(np.mean(r))
