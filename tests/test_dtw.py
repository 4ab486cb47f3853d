"""Offline DTW and UTW (fpdtw.dtw): hand-checked answers, dtw-python cross-checks, invariants.

Orientation: C[i, j], i = input frame (rows), j = target frame (columns). dtw-python is
called with the same matrix, so its query (rows) is the input.
"""

from __future__ import annotations

import json
from fractions import Fraction
from pathlib import Path

import dtw as dtwpy
import numpy as np
import pytest
from reference.synthetic import one_joint_motion, random_walk_quats

from fpdtw.costs import geodesic_cost_matrix
from fpdtw.dtw import accumulate, backtrack, dtw, dtw_pair, path_to_map, utw_map
from fpdtw.errors import AlignmentError
from fpdtw.io import load_motion
from fpdtw.metrics import in_range, is_monotonic
from fpdtw.motion.features import MotionFeatures

SQUAT = "hdm05/HDM05_cut_amc/squat1Reps/HDM_bd_squat1Reps_{:03d}_120.amc"
GOLDEN = Path(__file__).parent / "golden" / "dtw_squat1Reps_bd001_bd002.json"
PATTERNS = ("symmetric1", "symmetric2")


random_walk_motion = random_walk_quats


def scalar_motion(values):
    """One joint turning about z by ``values * pi / 8``: geodesic cost = |dv| / 8."""
    return one_joint_motion(22.5 * np.asarray(values, dtype=float), "Z")


def squat_features(data_path, take):
    return MotionFeatures.from_motion(load_motion(data_path(SQUAT.format(take))))


def dtwpy_align(C, step_pattern):
    return dtwpy.dtw(C, step_pattern=getattr(dtwpy, step_pattern), keep_internals=True)


def assert_same_as_dtwpy(C, step_pattern):
    ours = dtw(C, step_pattern)
    ref = dtwpy_align(C, step_pattern)
    # same floating-point operations: bit-identical accumulated costs
    np.testing.assert_array_equal(ours.D, ref.costMatrix)
    assert ours.distance == ref.distance
    np.testing.assert_array_equal(ours.path[:, 0], ref.index1)
    np.testing.assert_array_equal(ours.path[:, 1], ref.index2)
    return ours


# -- hand-checked ------------------------------------------------------------------------------


def test_symmetric1_by_hand():
    C = np.array([[0.0, 1.0, 3.0], [3.0, 2.0, 0.0], [1.0, 0.0, 2.0]])
    # D[i,j] = C[i,j] + min(D[i-1,j-1], D[i-1,j], D[i,j-1]), computed by hand
    D = np.array([[0.0, 1.0, 4.0], [3.0, 2.0, 1.0], [4.0, 2.0, 3.0]])
    np.testing.assert_array_equal(accumulate(C), D)
    r = dtw(C)
    assert r.distance == 3.0
    # from (2,2): preds diag D[1,1]=2, (2,1)=2, (1,2)=1 -> (1,2); then diag D[0,1]=1 vs
    # (1,1)=2, (0,2)=4 -> (0,1); then (0,0)
    np.testing.assert_array_equal(r.path, [[0, 0], [0, 1], [1, 2], [2, 2]])
    np.testing.assert_array_equal(r.map, [0, 0, 1])


def test_symmetric2_by_hand():
    C = np.array([[1.0, 2.0], [3.0, 1.0]])
    # D00 = 1; D01 = 1+2 = 3; D10 = 1+3 = 4; D11 = min(D00 + 2*1, D10 + 1, D01 + 1) = 3
    np.testing.assert_array_equal(accumulate(C, "symmetric2"), [[1.0, 3.0], [4.0, 3.0]])
    r = dtw(C, "symmetric2")
    assert r.distance == 3.0
    np.testing.assert_array_equal(r.path, [[0, 0], [1, 1]])  # diagonal wins the tie with (0,1)


def test_tie_rule_prefers_diagonal_then_same_input_frame():
    C = np.zeros((3, 3))
    np.testing.assert_array_equal(dtw(C).path, [[0, 0], [1, 1], [2, 2]])
    # D = [[0, 0, 5], [5, 0, 0]]; from (1,2): diagonal (0,1) and (1,1) both 0 -> diagonal
    C = np.array([[0.0, 0.0, 5.0], [5.0, 0.0, 0.0]])
    np.testing.assert_array_equal(dtw(C).path, [[0, 0], [0, 1], [1, 2]])
    # D = [[0, 0, 0], [0, 9, 0], [0, 0, 0]]; from (2,2): diagonal 9, (2,1) and (1,2) both 0
    # -> (2,1) (same input frame, previous target frame); from (2,1): diagonal (1,0) = 0
    C = np.zeros((3, 3))
    C[1, 1] = 9.0
    np.testing.assert_array_equal(dtw(C).path, [[0, 0], [1, 0], [2, 1], [2, 2]])
    C = np.array([[0.0, 1.0], [1.0, 0.0], [1.0, 1.0]])
    # from (2,1): diag (1,0)->D=1, (2,0)->D=2, (1,1)->D=0 -> (1,1)
    np.testing.assert_array_equal(dtw(C).path, [[0, 0], [1, 1], [2, 1]])


def test_path_to_map_keeps_lowest_input_frame():
    path = np.array([[0, 0], [1, 0], [2, 1], [2, 2], [3, 2], [4, 3]])
    np.testing.assert_array_equal(path_to_map(path, 3), [0, 2, 2, 4])
    # order of the cells does not matter
    np.testing.assert_array_equal(path_to_map(path[::-1], 3), [0, 2, 2, 4])


def test_path_to_map_rejects_gaps():
    with pytest.raises(AlignmentError, match="target frame 1"):
        path_to_map(np.array([[0, 0], [1, 2]]), 2)
    with pytest.raises(AlignmentError, match="shape"):
        path_to_map(np.array([0, 1, 2]), 2)


def test_scalar_motion_pair_by_hand():
    # one joint turning about z: cost = |v_i - u_j| / 8; I = [0, 2, 6, 8], T = [0, 6, 8]
    # C * 8 = [[0, 6, 8], [2, 4, 6], [6, 0, 2], [8, 2, 0]]
    I = scalar_motion([0, 2, 6, 8])
    T = scalar_motion([0, 6, 8])
    r = dtw_pair(I, T)
    D = np.array([[0, 6, 14], [2, 4, 10], [8, 2, 4], [16, 4, 2]]) / 8
    np.testing.assert_allclose(r.D, D, atol=1e-12)
    np.testing.assert_allclose(r.distance, 0.25, atol=1e-12)
    np.testing.assert_array_equal(r.path, [[0, 0], [1, 0], [2, 1], [3, 2]])
    np.testing.assert_array_equal(r.map, [0, 2, 3])


# -- UTW ---------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "m, n, expected",
    [
        # q * m / n = q / 2 -> 0, .5, 1, 1.5, 2, 2.5, 3, 3.5, 4; halves round up
        (4, 8, [0, 1, 1, 2, 2, 3, 3, 4, 4]),
        (8, 4, [0, 2, 4, 6, 8]),
        (1, 2, [0, 1, 1]),
        (3, 2, [0, 2, 3]),  # 1.5 -> 2
        # 10 * q / 3 = 0, 3.33, 6.67, 10
        (10, 3, [0, 3, 7, 10]),
        (0, 3, [0, 0, 0, 0]),
        (5, 0, [0]),
        (0, 0, [0]),
    ],
)
def test_utw_by_hand(m, n, expected):
    M = utw_map(m, n)
    assert M.dtype == np.int64
    np.testing.assert_array_equal(M, expected)


def test_utw_is_half_up_rounding_of_exact_ratio():
    for m in range(0, 30):
        for n in range(1, 30):
            exact = [int(Fraction(q * m, n) + Fraction(1, 2)) for q in range(n + 1)]
            np.testing.assert_array_equal(utw_map(m, n), exact)


def test_utw_errors():
    with pytest.raises(AlignmentError):
        utw_map(-1, 3)


# -- cross-checks with dtw-python ------------------------------------------------------------


@pytest.mark.parametrize("step_pattern", PATTERNS)
@pytest.mark.parametrize("shape", [(1, 1), (1, 9), (9, 1), (2, 2), (7, 12), (33, 20), (80, 80)])
def test_matches_dtw_python_random(step_pattern, shape):
    rng = np.random.default_rng(hash(shape) % 2**32)
    for _ in range(3):
        assert_same_as_dtwpy(rng.random(shape), step_pattern)
        # small integer costs: many ties, so the tie rule is exercised
        assert_same_as_dtwpy(rng.integers(0, 3, shape).astype(float), step_pattern)


@pytest.mark.parametrize("step_pattern", PATTERNS)
def test_matches_dtw_python_synthetic_motion(step_pattern):
    rng = np.random.default_rng(7)
    I = random_walk_motion(rng, 90)
    T = random_walk_motion(rng, 70)
    C = geodesic_cost_matrix(I.quats, T.quats)
    r = assert_same_as_dtwpy(C, step_pattern)
    np.testing.assert_array_equal(dtw_pair(I, T, step_pattern).map, r.map)


@pytest.mark.parametrize("step_pattern", PATTERNS)
def test_matches_dtw_python_real_pair(data_path, step_pattern):
    I = squat_features(data_path, 1)
    T = squat_features(data_path, 2)
    C = geodesic_cost_matrix(I.quats, T.quats)
    assert C.shape == (I.n_frames, T.n_frames)
    r = assert_same_as_dtwpy(C, step_pattern)
    assert r.map.shape == (T.n_frames,)
    assert is_monotonic(r.map) and in_range(r.map, I.n_frames - 1)
    assert r.map[0] == 0


def test_backtrack_without_c_agrees_for_symmetric1():
    rng = np.random.default_rng(3)
    C = rng.random((40, 50))
    D = accumulate(C)
    np.testing.assert_array_equal(backtrack(D), backtrack(D, C))
    with pytest.raises(AlignmentError, match="needs C"):
        backtrack(accumulate(C, "symmetric2"), step_pattern="symmetric2")


# -- invariants --------------------------------------------------------------------------------


@pytest.mark.parametrize("step_pattern", PATTERNS)
def test_self_alignment_is_identity(data_path, step_pattern):
    rng = np.random.default_rng(11)
    for feats in (random_walk_motion(rng, 120), squat_features(data_path, 3)):
        r = dtw_pair(feats, feats, step_pattern)
        F = feats.n_frames
        np.testing.assert_array_equal(r.map, np.arange(F))
        np.testing.assert_array_equal(r.path, np.stack([np.arange(F)] * 2, axis=1))


@pytest.mark.parametrize("step_pattern", PATTERNS)
def test_paths_are_connected_and_maps_monotonic(step_pattern):
    rng = np.random.default_rng(5)
    for shape in [(1, 6), (6, 1), (15, 40), (40, 15), (25, 25)]:
        r = dtw(rng.random(shape), step_pattern)
        p = r.path
        assert tuple(p[0]) == (0, 0) and tuple(p[-1]) == (shape[0] - 1, shape[1] - 1)
        steps = {tuple(s) for s in np.diff(p, axis=0)}
        assert steps <= {(1, 1), (0, 1), (1, 0)}
        assert r.map.shape == (shape[1],)
        assert is_monotonic(r.map) and in_range(r.map, shape[0] - 1)


def test_path_cost_equals_distance():
    rng = np.random.default_rng(9)
    C = rng.random((30, 45))
    r = dtw(C, "symmetric1")
    np.testing.assert_allclose(C[r.path[:, 0], r.path[:, 1]].sum(), r.distance, rtol=1e-12)
    r2 = dtw(C, "symmetric2")
    diag = np.r_[False, (np.diff(r2.path, axis=0) == 1).all(axis=1)]
    w = np.where(diag, 2.0, 1.0)
    np.testing.assert_allclose((w * C[r2.path[:, 0], r2.path[:, 1]]).sum(), r2.distance)


def test_distance_is_brute_force_minimum_on_tiny_matrices():
    """Enumerate every monotone connected path of a 3 x 4 matrix."""
    rng = np.random.default_rng(13)
    C = rng.random((3, 4))

    def paths(i, j):
        if (i, j) == (0, 0):
            yield [(0, 0)]
            return
        for di, dj in ((1, 1), (0, 1), (1, 0)):
            if i - di >= 0 and j - dj >= 0:
                for p in paths(i - di, j - dj):
                    yield p + [(i, j)]

    costs = [sum(C[c] for c in p) for p in paths(2, 3)]
    assert len(costs) == 25  # Delannoy number D(2, 3) = 1 + 2*3*2 + 1*3*4
    np.testing.assert_allclose(dtw(C).distance, min(costs), rtol=1e-12)


# -- errors ------------------------------------------------------------------------------------


def test_bad_cost_matrices_raise():
    with pytest.raises(AlignmentError, match="non-finite.*\\[1, 2\\]"):
        C = np.zeros((3, 4))
        C[1, 2] = np.nan
        dtw(C)
    with pytest.raises(AlignmentError, match="2-D"):
        dtw(np.zeros(5))
    with pytest.raises(AlignmentError, match="empty"):
        dtw(np.zeros((0, 3)))
    with pytest.raises(AlignmentError, match="unknown step pattern"):
        dtw(np.zeros((2, 2)), "asymmetric")
    with pytest.raises(AlignmentError, match="different joints"):
        rng = np.random.default_rng(0)
        dtw_pair(random_walk_motion(rng, 5, k=8), random_walk_motion(rng, 5, k=4))


# -- golden file -------------------------------------------------------------------------------


def test_golden_real_pair(data_path):
    """Regression against tests/golden/dtw_squat1Reps_bd001_bd002.json.

    Regenerate (only after a deliberate change) with
    ``FPDTW_MIRROR=../shared/data python tests/golden/make_dtw_golden.py``.
    """
    from fpdtw.metrics import similarity
    from fpdtw.online.base import run_online
    from fpdtw.online.oedtw import OEDTW

    g = json.loads(GOLDEN.read_text())
    I = MotionFeatures.from_motion(load_motion(data_path(g["input"])))
    T = MotionFeatures.from_motion(load_motion(data_path(g["target"])))
    assert (I.n_frames - 1, T.n_frames - 1) == (g["m"], g["n"])
    r = dtw_pair(I, T, g["step_pattern"])
    np.testing.assert_allclose(r.distance, g["distance"], rtol=1e-9)
    np.testing.assert_array_equal(r.map, g["dtw_map"])
    M, _ = run_online(OEDTW(I, g["step_pattern"]), T)
    np.testing.assert_array_equal(M, g["oedtw_end_points"])
    np.testing.assert_allclose(similarity(I.quats, T.quats, r.map), g["similarity_dtw"], atol=1e-12)
    U = utw_map(g["m"], g["n"])
    np.testing.assert_allclose(similarity(I.quats, T.quats, U), g["similarity_utw"], atol=1e-12)
