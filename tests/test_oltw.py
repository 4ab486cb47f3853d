"""Dixon's on-line time warping (fpdtw.online.oltw): hand-worked cases, a plain-Python
transcription of Dixon's Fig. 1, pymatchmaker's decisions (golden file), invariants.

Hand-worked cases use one-joint motions whose frame ``f`` is a rotation about X by
``18 * u[f]`` degrees: the geodesic cost (eq. 1) between frames is ``|u_a - u_b| / 10``.
Costs and accumulated costs below are written in tenths.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from reference.synthetic import random_walk_features, synthetic_pair

from fpdtw.app.bench import bench_online
from fpdtw.costs import geodesic_cost_matrix
from fpdtw.errors import AlignmentError
from fpdtw.motion.features import MotionFeatures
from fpdtw.online.base import run_online
from fpdtw.online.oltw import (
    BOTH,
    BY_ARGMIN,
    BY_RUNCOUNT,
    BY_WARMUP,
    INPUT,
    OLTW,
    TARGET,
)

GOLDEN = Path(__file__).parent / "golden" / "oltw_pymatchmaker.json"


def units(u):
    """One-joint motion: frame f is a rotation about X by 18 * u[f] degrees."""
    ang = np.deg2rad(18.0 * np.asarray(u, dtype=float))
    Q = np.zeros((ang.size, 1, 4))
    Q[:, 0, 0] = np.cos(ang / 2)
    Q[:, 0, 1] = np.sin(ang / 2)
    return MotionFeatures.from_arrays(Q, orders=("XYZ",))


def run(I, T, **kw):
    a = OLTW(I, record=True, **kw)
    M, _ = run_online(a, T)
    return M, a


def decisions(a):
    """(i, q, increment, reason, best_i, best_q) of every decision."""
    return [tuple(int(v) for v in row[1:]) for row in a.decisions]


# ------------------------------------------------------------------------ hand-worked
def test_hand_worked_no_warmup():
    """c = 2, no warm-up. Costs (rows i = input 0 1 2 3, columns q = target 0 2 3 3):

    i=0: 0 2 3 3      q=0: D00 = 0; only (0,0) -> BOTH.
    i=1: 1 1 2 2      q=1: column 1 (rows 0..0): D01 = 0 + 2 = 2; row 1 (cols 0..1):
    i=2: 2 0 1 1           D10 = 0 + 1 = 1, D11 = min(2+1, 1+1, 0+2*1) = 2.
    i=3: 3 1 0 0           argmin of D/(1+i+q): column 1: 2/2, 2/3; row 1: 1/2 <- (1,0),
                           an earlier target frame in the newest row -> INPUT.
    i=2 (cols 0..1): D20 = 1 + 2 = 3, D21 = min(2+0, 3+0, 1+2*0) = 1.
    argmin: column 1 rows 1..2: 2/3, 1/4 <- (2,1); row 2: 3/3 -> corner -> BOTH. M_1 = 2.
    q=2: column 2 rows 1..2: D12 = D11 + 2 = 4 (row 1 is the band's first: no (0, .)),
         D22 = min(1+1, 4+1, 2+2*1) = 2; row 3 cols 1..2: D31 = 1 + 1 = 2,
         D32 = min(2+0, 2+0, 1+0) = 1. argmin: 4/4, 2/5, 1/6 <- corner (3,2); row 3:
         2/5 -> BOTH, but i = m = 3: TARGET. M_2 = 3.
    q=3: column 3 rows 2..3: D23 = 2 + 1 = 3, D33 = min(1+0, 3+0, 2+0) = 1 -> corner,
         TARGET (end of input). M_3 = 3.
    """
    M, a = run(units([0, 1, 2, 3]), units([0, 2, 3, 3]), c=2, warmup=False)
    np.testing.assert_array_equal(M, [0, 2, 3, 3])
    assert decisions(a) == [
        (0, 0, BOTH, BY_ARGMIN, 0, 0),
        (1, 1, INPUT, BY_ARGMIN, 1, 0),
        (2, 1, BOTH, BY_ARGMIN, 2, 1),
        (3, 2, TARGET, BY_ARGMIN, 3, 2),
        (3, 3, TARGET, BY_ARGMIN, 3, 3),
    ]
    np.testing.assert_array_equal(a.path, [[0, 0], [1, 1], [2, 1], [3, 2], [3, 3]])
    assert a.corner == (3, 3) and a.pending == "target"


def test_hand_worked_warmup():
    """The same motions with c = 3 and Dixon's start rule (BOTH while q + 1 < c).

    q=0, q=1: BOTH by the warm-up. D01 = 2, D10 = 1, D11 = min(3, 2, 2) = 2.
    q=2: column 2 rows 0..1: D02 = 2 + 3 = 5, D12 = min(2+2, 5+2, 2+2*2) = 4; row 2 cols
    0..2: D20 = 1 + 2 = 3, D21 = min(2+0, 3+0, 1+0) = 1, D22 = min(4+1, 1+1, 2+2) = 2.
    argmin: column 2: 5/3, 4/4, 2/5; row 2: 3/3, 1/4 <- (2,1) -> INPUT.
    i=3 (cols 0..2): D30 = 3 + 3 = 6, D31 = min(1+1, 6+1, 3+2) = 2, D32 = min(2, 2, 1) = 1.
    argmin: column 2 rows 1..3: 4/4, 2/5, 1/6 <- corner; row 3: 6/4, 2/5 -> BOTH -> TARGET
    (end of input). M = 0, 1, 3, 3.
    """
    M, a = run(units([0, 1, 2, 3]), units([0, 2, 3, 3]), c=3, warmup=True)
    np.testing.assert_array_equal(M, [0, 1, 3, 3])
    assert decisions(a) == [
        (0, 0, BOTH, BY_WARMUP, -1, -1),
        (1, 1, BOTH, BY_WARMUP, -1, -1),
        (2, 2, INPUT, BY_ARGMIN, 2, 1),
        (3, 2, TARGET, BY_ARGMIN, 3, 2),
        (3, 3, TARGET, BY_ARGMIN, 3, 3),
    ]


def test_hand_worked_run_count_rule():
    """c = 2, max_run_count = 1, no warm-up; input 0..6, target 0 4 6 (costs in tenths):

    q=0: BOTH. q=1: D01 = 4; D10 = 1, D11 = min(4+3, 1+3, 0+6) = 4. argmin: column 1:
    4/2, 4/3; row 1: 1/2 <- (1,0) -> INPUT (run 1). i=2: D20 = 3, D21 = min(4+2, 3+2,
    1+4) = 5; argmin: 4/3, 5/4; row 2: 3/3 <- (2,0) -> INPUT (run 2). i=3: D30 = 6,
    D31 = min(5+1, 6+1, 3+2) = 5. Now runCount 2 > 1 and the previous was INPUT:
    TARGET, forced. M_1 = 3.
    q=2: column 2 rows 2..3: D22 = 5 + 4 = 9, D32 = min(5+3, 9+3, 5+6) = 8. argmin:
    9/5, 8/6; row 3 cols 1..2: 5/5 <- (3,1) -> INPUT. i=4: D41 = 5 + 0 = 5, D42 =
    min(8+2, 5+2, 5+4) = 7; argmin: 8/6, 7/7; row 4: 5/6 <- (4,1) -> INPUT (run 2).
    i=5: D51 = 6, D52 = 7; run 2 > 1: TARGET, forced. M_2 = 5.
    """
    M, a = run(units(range(7)), units([0, 4, 6]), c=2, max_run_count=1, warmup=False)
    np.testing.assert_array_equal(M, [0, 3, 5])
    assert decisions(a) == [
        (0, 0, BOTH, BY_ARGMIN, 0, 0),
        (1, 1, INPUT, BY_ARGMIN, 1, 0),
        (2, 1, INPUT, BY_ARGMIN, 2, 0),
        (3, 1, TARGET, BY_RUNCOUNT, -1, -1),
        (3, 2, INPUT, BY_ARGMIN, 3, 1),
        (4, 2, INPUT, BY_ARGMIN, 4, 1),
        (5, 2, TARGET, BY_RUNCOUNT, -1, -1),
    ]


# ------------------------------------------------------ a plain transcription of Dixon
def reference_oltw(C, c, max_run=3, warmup=True, normalize=True):
    """Dixon's Fig. 1 on a full cost matrix C (rows input, columns target), in plain Python.

    Cells live in a dict; a predecessor counts only if it was computed and lies in the
    ``c x c`` block behind the corner. Returns the map and the decisions
    (i, q, increment, reason, best_i, best_q).
    """
    m, n = C.shape[0] - 1, C.shape[1] - 1
    D = {(0, 0): C[0, 0]}
    st = {"i": 0, "q": 0, "prev": None, "run": 0}

    def cell(i, q):
        ok = (i, q) in D and i > st["i"] - c and q > st["q"] - c
        return D[(i, q)] if ok else math.inf

    def evaluate(i, q):
        d = C[i, q]
        D[(i, q)] = min(cell(i - 1, q) + d, cell(i, q - 1) + d, cell(i - 1, q - 1) + 2 * d)

    def apply(inc):
        if inc in (TARGET, BOTH):
            st["q"] += 1
            for k in range(max(0, st["i"] - c + 1), st["i"] + 1):
                evaluate(k, st["q"])
        if inc in (INPUT, BOTH):
            st["i"] += 1
            for k in range(max(0, st["q"] - c + 1), st["q"] + 1):
                evaluate(st["i"], k)
        st["run"] = st["run"] + 1 if inc == st["prev"] else 1
        if inc != BOTH:
            st["prev"] = inc

    def get_inc():
        i, q = st["i"], st["q"]
        if warmup and q + 1 < c:
            return BOTH, BY_WARMUP, -1, -1
        if st["run"] > max_run:
            return (INPUT if st["prev"] == TARGET else TARGET), BY_RUNCOUNT, -1, -1
        cells = [(k, q) for k in range(max(0, i - c + 1), i + 1)]
        cells += [(i, k) for k in range(max(0, q - c + 1), q + 1)]
        best, bi, bq = math.inf, i, q
        for a, b in cells:
            v = D[(a, b)] / (1.0 + a + b) if normalize else D[(a, b)]
            if v < best:
                best, bi, bq = v, a, b
        if (bi, bq) == (i, q):
            return BOTH, BY_ARGMIN, bi, bq
        return (TARGET if bi < i else INPUT), BY_ARGMIN, bi, bq

    M, log, pending = [], [], None
    for qn in range(n + 1):
        if qn > 0:
            apply(pending)
        while True:
            inc, why, bi, bq = get_inc()
            if st["i"] >= m and inc != TARGET:
                inc = TARGET
            log.append((st["i"], st["q"], inc, why, bi, bq))
            if inc == INPUT:
                apply(INPUT)
            else:
                pending = inc
                break
        M.append(st["i"])
    return np.array(M), log


@pytest.mark.parametrize(
    "seed,c,max_run,warmup,normalize",
    [
        (0, 120, 3, True, True),
        (1, 30, 3, False, True),
        (2, 7, 1, False, True),
        (3, 12, 2, True, False),
        (4, 2, 3, False, True),
    ],
)
def test_numba_kernel_equals_plain_transcription(seed, c, max_run, warmup, normalize):
    I, T, _ = synthetic_pair(260, k=8, seed=seed)
    kw = dict(c=c, max_run_count=max_run, warmup=warmup, normalize=normalize)
    M, a = run(I, T, **kw)
    C = geodesic_cost_matrix(I.quats, T.quats)
    M_ref, log_ref = reference_oltw(C, c, max_run, warmup, normalize)
    np.testing.assert_array_equal(M, M_ref)
    assert decisions(a) == log_ref


# ------------------------------------------------------------------- pymatchmaker golden
def test_matches_pymatchmaker_oltw_dixon():
    """tools/oltw_crosscheck.py ran pymatchmaker 0.3.0's OnlineTimeWarpingDixonFrame on a
    1-D reference and a warped copy (Euclidean cost |x - y|); fpdtw gets the same local
    costs through one joint rotated by pi * x (geodesic = |x - y|). Every decision (corner,
    increment, argmin cell) must agree; pymatchmaker has no start rule (warmup=False) and
    forced nothing in this case, so neither may we."""
    g = json.loads(GOLDEN.read_text())

    def feats(x):
        th = np.pi * np.asarray(x)
        Q = np.zeros((th.size, 1, 4))
        Q[:, 0, 0] = np.cos(th / 2)
        Q[:, 0, 1] = np.sin(th / 2)
        return MotionFeatures.from_arrays(Q, orders=("XYZ",))

    theirs = np.array(g["decisions"])
    assert g["forced_decisions"] == 0 and len(theirs) > 150
    M, a = run(feats(g["x"]), feats(g["y"]), c=g["params"]["c"], max_run_count=3, warmup=False)
    ours = a.decisions
    # pymatchmaker takes the decision waiting for the next live frame only when it arrives
    assert len(ours) == len(theirs) + 1
    np.testing.assert_array_equal(ours[:-1, [1, 2, 3, 5, 6]], theirs[:, [0, 1, 2, 4, 5]])
    assert (ours[:, 4] == BY_ARGMIN).all()
    assert list(a.corner) == g["final_corner"]
    # the case exercises all three increments
    assert set(theirs[:, 2]) == {TARGET, INPUT, BOTH}


# ---------------------------------------------------------------------------- invariants
def test_input_aligned_to_itself_is_the_identity():
    I = random_walk_features(300, seed=3)
    M, a = run(I, I)
    np.testing.assert_array_equal(M, np.arange(300))
    # every step diagonal; the last one, waiting for a frame 300, holds at the input's end
    assert set(a.decisions[:-1, 3]) == {BOTH} and a.decisions[-1, 3] == TARGET


@pytest.mark.parametrize("c,warmup", [(120, True), (40, False)])
def test_map_is_monotonic_in_range_and_bounded_per_frame(c, warmup):
    I, T, _ = synthetic_pair(500, seed=7, warp=0.6)
    M, a = run(I, T, c=c, warmup=warmup)
    assert M.shape == (T.n_frames,) and M[0] >= 0 and M.max() <= I.n_frames - 1
    assert np.all(np.diff(M) >= 0)
    dec = a.decisions
    # at most max_run_count + 1 INPUT increments per target frame (the run-count rule)
    per_frame = np.bincount(dec[dec[:, 3] == INPUT, 0], minlength=T.n_frames)
    assert per_frame.max() <= a.max_run_count + 1
    # runs of equal TARGET or INPUT increments never exceed max_run_count + 1
    incs = dec[:, 3]
    edges = np.flatnonzero(np.diff(np.r_[-1, incs, -1]) != 0)
    lengths, kinds = np.diff(edges), incs[edges[:-1]]
    assert lengths[kinds != BOTH].max() <= a.max_run_count + 1
    forced = dec[dec[:, 4] == BY_RUNCOUNT, 3]
    assert forced.size > 0 and set(forced) <= {TARGET, INPUT}  # the rule did act


def test_follows_a_known_warp():
    """A smooth synthetic pair: OLTW stays close to the true warp."""
    I, T, s = synthetic_pair(600, seed=11, warp=0.35, noise=0.3)
    M, _ = run(I, T)
    assert np.median(np.abs(M - s)) < 6.0


def test_prefix_does_not_depend_on_future_frames():
    I, T, _ = synthetic_pair(300, seed=5)
    M, _ = run(I, T, c=40)
    rng = np.random.default_rng(1)
    for q in (0, 1, 39, 40, 150):
        Q = rng.normal(size=T.quats.shape)
        Q /= np.linalg.norm(Q, axis=-1, keepdims=True)
        Q[: q + 1] = T.quats[: q + 1]
        T2 = MotionFeatures(Q, T.euler.copy(), T.orders, T.fps)
        M2, _ = run(I, T2, c=40)
        np.testing.assert_array_equal(M2[: q + 1], M[: q + 1])


def test_end_of_input_holds_at_last_frame():
    I = units(range(5))
    T = units([0, 1, 2, 3, 4, 4, 4, 4, 4, 4])
    M, a = run(I, T, c=3, warmup=False)
    np.testing.assert_array_equal(M, [0, 1, 2, 3, 4, 4, 4, 4, 4, 4])
    assert a.decisions[-1, 3] == TARGET


def test_reset_and_rerun_give_the_same_map():
    I, T, _ = synthetic_pair(200, seed=2)
    a = OLTW(I, c=30, record=True)
    M1, _ = run_online(a, T)
    d1 = a.decisions
    M2, _ = run_online(a, T)  # run_online resets
    np.testing.assert_array_equal(M1, M2)
    np.testing.assert_array_equal(d1, a.decisions)


def test_bad_arguments():
    I = units(range(5))
    for bad in (1, 0, 2.5, True, "10"):
        with pytest.raises(AlignmentError, match="search width"):
            OLTW(I, bad)
    with pytest.raises(AlignmentError, match="max_run_count"):
        OLTW(I, max_run_count=0)
    with pytest.raises(AlignmentError, match="constraint"):
        OLTW(I, constraint="typeV")
    with pytest.raises(AlignmentError, match="record=True"):
        OLTW(I).decisions  # noqa: B018
    with pytest.raises(AlignmentError, match="MotionFeatures"):
        OLTW(np.zeros((5, 1, 4)))
    assert OLTW(I).name == "OLTW" and OLTW(I, 60).name == "OLTW c60"


def test_bench_online_times_oltw():
    """``make bench`` support: bench_online times any aligner given a constructor."""
    I, T, _ = synthetic_pair(150, seed=4)
    rows = bench_online([(I, T)], make=lambda I: OLTW(I, 120))
    assert len(rows) == 1 and rows[0]["name"] == "OLTW" and rows[0]["frames"] == T.n_frames
    assert rows[0]["median_s"] > 0


@pytest.mark.parametrize("normalize", [True, False])
def test_ties_go_to_the_first_cell_in_scan_order_as_the_transcription(normalize):
    """Equal path costs: a pose held in both motions makes many cells of the newest column
    and row cost the same; of equal costs the first cell in scan order (the column from its
    lowest input frame, then the row) wins. A rule that took the last minimum instead gives
    other decisions here."""
    I = units([0, 0, 0, 0, 0, 1, 1, 1, 2, 2, 2, 2])
    T = units([0, 0, 0, 1, 1, 1, 1, 2, 2, 2, 2, 2, 2])
    M, a = run(I, T, c=4, warmup=False, normalize=normalize)
    M_ref, log_ref = reference_oltw(geodesic_cost_matrix(I.quats, T.quats), 4, 3, False, normalize)
    np.testing.assert_array_equal(M, M_ref)
    assert decisions(a) == log_ref
