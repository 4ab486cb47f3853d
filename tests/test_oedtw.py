"""OE-DTW (fpdtw.online.oedtw): incremental end points against dtw-python's open-end DTW
and against our own offline accumulation, hand-checked columns, partial paths."""

from __future__ import annotations

import dtw as dtwpy
import numpy as np
import pytest
from reference.synthetic import one_joint_motion, random_walk_quats

from fpdtw.costs import geodesic_cost_matrix
from fpdtw.dtw import accumulate, dtw
from fpdtw.errors import AlignmentError
from fpdtw.io import load_motion
from fpdtw.motion.features import MotionFeatures
from fpdtw.online.base import run_online
from fpdtw.online.oedtw import OEDTW

SQUAT = "hdm05/HDM05_cut_amc/squat1Reps/HDM_bd_squat1Reps_{:03d}_120.amc"

#: dtw-python refuses open_end for "symmetric1" (hint "NA": not normalisable). The same
#: recursion with hint "N" divides the last row by the query length, a constant, so its
#: open-end argmin is the plain argmin of the last row: exactly our default OE-DTW.
SYMMETRIC1_N = dtwpy.StepPattern(dtwpy.symmetric1.mx, hint="N")


random_walk_motion = random_walk_quats


def scalar_motion(values):
    """One joint turning about z by ``values * pi / 8``: geodesic cost = |dv| / 8."""
    return one_joint_motion(22.5 * np.asarray(values, dtype=float), "Z")


def dtwpy_open_end(C, q, pattern):
    """dtw-python open-end DTW of the target prefix T_0..T_q (query) against the whole input."""
    return dtwpy.dtw(C[:, : q + 1].T, step_pattern=pattern, open_end=True, distance_only=True).jmin


@pytest.fixture(scope="module")
def squat_pair(data_path):
    I = MotionFeatures.from_motion(load_motion(data_path(SQUAT.format(1))))
    T = MotionFeatures.from_motion(load_motion(data_path(SQUAT.format(2))))
    return I, T


# -- hand-checked ------------------------------------------------------------------------------


def test_end_point_moves_backwards_by_hand():
    """Fig. 1's phenomenon on a hand-checked case (no ties anywhere).

    One joint turning about z, cost * 8 = |I_i - T_q|; I = [0, 1, 0, 3], T = [0, 0, 1, 3, 0].
    col0 (T=0): C = [0, 1, 0, 3], D = [0, 1, 1, 4]                               e_0 = 0
    col1 (T=0): D = [0, 1 + min(0, 1, 0), 0 + min(1, 1, 1), 3 + min(1, 4, 1)]
                  = [0, 1, 1, 4]                                                   e_1 = 0
    col2 (T=1): C = [1, 0, 1, 2],
                D = [1, 0 + min(0, 1, 1), 1 + min(1, 1, 0), 2 + min(1, 4, 1)]
                  = [1, 0, 1, 3]                                                   e_2 = 1
    col3 (T=3): C = [3, 2, 3, 0],
                D = [4, 2 + min(1, 0, 4), 3 + min(0, 1, 2), 0 + min(1, 3, 3)]
                  = [4, 2, 3, 1]                                                   e_3 = 3
    col4 (T=0): C = [0, 1, 0, 3],
                D = [4, 1 + min(4, 2, 4), 0 + min(2, 3, 3), 3 + min(3, 1, 2)]
                  = [4, 3, 2, 4]                                                   e_4 = 2
    (min order in each cell: D[i-1, q-1], D[i, q-1], D[i-1, q]).
    Path of frame 3 from (3, 3): diagonal (2, 2) = 1 beats 3, 3; from (2, 2): (1, 2) = 0
    beats 1, 1; from (1, 2): diagonal (0, 1) = 0 beats 1, 1; then (0, 0).
    Path of frame 4 from (2, 4): diagonal (1, 3) = 2 beats 3, 3; from (1, 3): (1, 2) = 0
    beats 1, 4; then as above.
    """
    oe = OEDTW(scalar_motion([0, 1, 0, 3]))
    ends = [oe.step(f) for f in scalar_motion([0, 0, 1, 3, 0]).frames()]
    D = np.array([[0, 0, 1, 4, 4], [1, 1, 0, 2, 3], [1, 1, 1, 3, 2], [4, 4, 3, 1, 4]]) / 8
    np.testing.assert_allclose(oe.D, D, atol=1e-12)
    assert ends == [0, 0, 1, 3, 2]
    np.testing.assert_array_equal(oe.end_points, ends)
    np.testing.assert_array_equal(oe.path(3), [[0, 0], [0, 1], [1, 2], [2, 2], [3, 3]])
    np.testing.assert_array_equal(oe.path(4), [[0, 0], [0, 1], [1, 2], [1, 3], [2, 4]])


def test_ties_pick_the_lowest_end_point():
    # I = [1, 0, 1], T_0 = 0: C*8 = [1, 0, 1], D*8 = [1, 1, 2]; C[1, 0] is exactly 0
    # (identical identity rotations), so i = 0 and i = 1 tie exactly -> the lowest, 0
    oe = OEDTW(scalar_motion([1, 0, 1]))
    assert oe.step(scalar_motion([0]).frame(0)) == 0


# -- cross-checks ------------------------------------------------------------------------------


def _check_against_references(I, T, step_pattern="symmetric1", normalize=False):
    oe = OEDTW(I, step_pattern, normalize=normalize)
    M, dt = run_online(oe, T)
    assert dt.shape == M.shape == (T.n_frames,)
    C = geodesic_cost_matrix(I.quats, T.quats)
    D = accumulate(C, step_pattern)
    # the stored columns are exactly the offline accumulated cost matrix
    np.testing.assert_array_equal(oe.D, D)
    if not normalize:
        # end point of frame q = argmin (lowest on ties) of column q of the offline D
        np.testing.assert_array_equal(M, D.argmin(axis=0))
    # dtw-python's open-end DTW of every target prefix
    pattern = dtwpy.symmetric2 if normalize else SYMMETRIC1_N
    if step_pattern == "symmetric1" or normalize:
        for q in range(T.n_frames):
            assert M[q] == dtwpy_open_end(C, q, pattern), f"target frame {q}"
    else:  # symmetric2 without normalisation: argmin of dtw-python's last row
        for q in range(0, T.n_frames, 7):
            ref = dtwpy.dtw(C[:, : q + 1].T, step_pattern=dtwpy.symmetric2, keep_internals=True)
            assert M[q] == np.argmin(ref.costMatrix[-1])
    return oe, M, C


@pytest.mark.parametrize(
    "step_pattern, normalize",
    [("symmetric1", False), ("symmetric2", False), ("symmetric2", True)],
)
def test_matches_references_synthetic(step_pattern, normalize):
    rng = np.random.default_rng(21)
    I = random_walk_motion(rng, 70)
    T = random_walk_motion(rng, 45)
    _check_against_references(I, T, step_pattern, normalize)


def test_matches_dtw_python_open_end_real_pair(squat_pair):
    I, T = squat_pair
    oe, M, C = _check_against_references(I, T)
    # the real pair shows Fig. 1's phenomenon: end points move backwards at least once
    assert (np.diff(M) < 0).any()


def test_matches_dtw_python_open_end_normalized_real_pair(squat_pair):
    I, T = squat_pair
    _check_against_references(I.slice(0, 80), T.slice(0, 60), "symmetric2", normalize=True)


def test_partial_paths_equal_offline_dtw(squat_pair):
    I, T = squat_pair
    oe = OEDTW(I)
    M, _ = run_online(oe, T)
    C = geodesic_cost_matrix(I.quats, T.quats)
    for q in [0, 1, 15, 16, 60, T.n_frames - 1]:
        e = M[q]
        p = oe.path(q)
        assert tuple(p[0]) == (0, 0) and tuple(p[-1]) == (e, q)
        np.testing.assert_array_equal(p, dtw(C[: e + 1, : q + 1]).path)
    np.testing.assert_array_equal(oe.path(), oe.path(T.n_frames - 1))
    np.testing.assert_array_equal(oe.path(-2), oe.path(T.n_frames - 2))


def test_many_frames_grow_storage_and_reset():
    rng = np.random.default_rng(4)
    I = random_walk_motion(rng, 12, k=2)
    T = random_walk_motion(rng, 600, k=2)  # > 256: the column store and the base buffers grow
    oe = OEDTW(I)
    M, _ = run_online(oe, T)
    D = accumulate(geodesic_cost_matrix(I.quats, T.quats))
    np.testing.assert_array_equal(oe.D, D)
    np.testing.assert_array_equal(M, D.argmin(axis=0))
    oe.reset()
    assert oe.n_received == 0 and oe.D.shape == (I.n_frames, 0)
    M2, _ = run_online(oe, T.slice(0, 10), reset=False)
    np.testing.assert_array_equal(M2, M[:10])


def test_single_frame_input():
    rng = np.random.default_rng(8)
    oe = OEDTW(random_walk_motion(rng, 1))
    M, _ = run_online(oe, random_walk_motion(rng, 5))
    np.testing.assert_array_equal(M, 0)
    np.testing.assert_array_equal(oe.path(), [[0, 0], [0, 1], [0, 2], [0, 3], [0, 4]])


def test_errors():
    rng = np.random.default_rng(0)
    I = random_walk_motion(rng, 5)
    with pytest.raises(AlignmentError, match="normalis"):
        OEDTW(I, "symmetric1", normalize=True)
    with pytest.raises(AlignmentError, match="unknown step pattern"):
        OEDTW(I, "typeV")
    oe = OEDTW(I)
    with pytest.raises(AlignmentError, match="no target frame"):
        oe.path()
    oe.step(I.frame(0))
    with pytest.raises(AlignmentError, match="not received"):
        oe.path(3)
    assert OEDTW.name == "OE-DTW"
