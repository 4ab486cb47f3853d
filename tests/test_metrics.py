"""Metrics (fpdtw.metrics): Kendall tau-b against hand values and scipy, joint trajectories,
similarity (eq. 2) with its flat-axis rule, deviation (eq. 3), map helpers."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.stats import kendalltau

from fpdtw.dtw import dtw_pair, utw_map
from fpdtw.errors import AlignmentError
from fpdtw.io import load_motion
from fpdtw.metrics import (
    FLAT_RANGE,
    deviation,
    in_range,
    is_monotonic,
    joint_trajectories,
    kendall_tau_b,
    similarity,
    similarity_per_axis,
)
from fpdtw.motion.features import MotionFeatures
from fpdtw.motion.rotations import euler_to_quat, quat_normalize

SQUAT = "hdm05/HDM05_cut_amc/squat1Reps/HDM_bd_squat1Reps_{:03d}_120.amc"


def axis_angle_quats(axis, angles):
    """Quaternions (F, 4) turning by ``angles`` (radians) about the unit ``axis``."""
    axis = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    a = np.asarray(angles, dtype=float)[:, None]
    return np.concatenate([np.cos(a / 2), np.sin(a / 2) * axis], axis=1)


def monotone_motion(frames=50, k=3):
    """k joints turning steadily about (1, 0, 1)/sqrt(2) from 0 to 80 degrees (different
    speeds): every coordinate of every joint trajectory is strictly monotone in time."""
    t = np.linspace(0.0, 1.0, frames)
    q = np.stack(
        [axis_angle_quats([1, 0, 1], np.radians(80) * t ** (1 + j)) for j in range(k)], axis=1
    )
    return quat_normalize(q)


# -- Kendall tau-b -----------------------------------------------------------------------------


def test_kendall_tau_by_hand():
    # 6 pairs, only (2, 3) vs (3, 2) discordant: (5 - 1) / 6
    assert kendall_tau_b([1, 2, 3, 4], [1, 3, 2, 4]) == pytest.approx(2 / 3, abs=1e-15)
    # ties: x = [1, 2, 2, 3], y = [1, 2, 3, 3]; concordant 4, discordant 0, one tie in x
    # and one in y: tau_b = 4 / sqrt((6 - 1) * (6 - 1)) = 0.8
    assert kendall_tau_b([1, 2, 2, 3], [1, 2, 3, 3]) == pytest.approx(0.8, abs=1e-15)
    # reversed order: -1; identical: 1
    assert kendall_tau_b([1, 2, 3, 4, 5], [5, 4, 3, 2, 1]) == -1.0
    assert kendall_tau_b([3, 1, 2], [3, 1, 2]) == 1.0
    # constant: undefined (NaN), as scipy
    assert np.isnan(kendall_tau_b([1, 1, 1], [1, 2, 3]))
    assert np.isnan(kendall_tau_b([1.0], [2.0]))


def test_kendall_tau_matches_scipy():
    rng = np.random.default_rng(0)
    for trial in range(400):
        n = int(rng.integers(2, 300))
        x = rng.random(n) if trial % 3 else rng.integers(0, 5, n).astype(float)
        y = rng.integers(0, int(rng.integers(1, 10)), n).astype(float)
        if trial % 4 == 0:
            y = x[np.sort(rng.integers(0, n, n))]  # a warped copy: runs of repeated values
        ours = kendall_tau_b(x, y)
        ref = kendalltau(x, y).statistic
        if np.isnan(ref):
            assert np.isnan(ours)
        else:
            assert ours == pytest.approx(ref, abs=1e-12), (x, y)


def test_kendall_tau_brute_force():
    rng = np.random.default_rng(1)
    x = rng.integers(0, 6, 40).astype(float)
    y = rng.integers(0, 6, 40).astype(float)
    s = np.sign(x[:, None] - x[None, :]) * np.sign(y[:, None] - y[None, :])
    iu = np.triu_indices(40, 1)
    con_minus_dis = s[iu].sum()
    tx = (x[:, None] != x[None, :])[iu].sum()  # pairs not tied in x
    ty = (y[:, None] != y[None, :])[iu].sum()
    assert kendall_tau_b(x, y) == pytest.approx(con_minus_dis / np.sqrt(tx * ty), abs=1e-14)


# -- joint trajectories ------------------------------------------------------------------------


def test_joint_trajectories_by_hand():
    s = np.sqrt(0.5)
    q = np.array(
        [
            [[1, 0, 0, 0], [s, 0, 0, s]],  # identity; 90 deg about z
            [[s, s, 0, 0], [0, 0, 0, 1]],  # 90 deg about x; 180 deg about z
        ]
    )
    X = joint_trajectories(q)
    assert X.shape == (2, 2, 3)
    np.testing.assert_allclose(X[0, 0], [0, 1, 0], atol=1e-15)
    np.testing.assert_allclose(X[0, 1], [-1, 0, 0], atol=1e-15)  # y turned about z
    np.testing.assert_allclose(X[1, 0], [0, 0, 1], atol=1e-15)  # y turned about x
    np.testing.assert_allclose(X[1, 1], [0, -1, 0], atol=1e-15)


def test_joint_trajectories_are_rotated_y_axis():
    rng = np.random.default_rng(2)
    e = rng.uniform(-180, 180, size=(30, 3))
    q = euler_to_quat(e, "XYZ")[:, None, :]
    from fpdtw.motion.rotations import quat_to_matrix

    R = quat_to_matrix(q[:, 0])
    np.testing.assert_allclose(joint_trajectories(q)[:, 0], R[:, :, 1], atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(joint_trajectories(q), axis=2), 1.0, atol=1e-12)


# -- similarity --------------------------------------------------------------------------------


def test_identity_and_reversed_maps_on_monotone_motion():
    q = monotone_motion(50)
    F = q.shape[0]
    assert similarity(q, q, np.arange(F)) == 1.0
    # every axis strictly monotone: reversing time gives tau = -1 on all 3k axes
    r = similarity_per_axis(q, q, np.arange(F)[::-1])
    np.testing.assert_array_equal(r, -np.ones((3, 3)))
    assert similarity(q, q, np.arange(F)[::-1]) == -1.0


def test_similarity_is_mean_of_axes_and_uses_the_map():
    rng = np.random.default_rng(3)
    I = quat_normalize(np.cumsum(0.1 * rng.normal(size=(40, 4, 4)), axis=0) + 1)
    T = quat_normalize(np.cumsum(0.1 * rng.normal(size=(30, 4, 4)), axis=0) + 1)
    M = np.sort(rng.integers(0, 40, 30))
    r = similarity_per_axis(I, T, M)
    assert r.shape == (4, 3)
    assert similarity(I, T, M) == pytest.approx(r.mean(), abs=1e-15)
    XA = joint_trajectories(I)[M]
    XT = joint_trajectories(T)
    for j in range(4):
        for a in range(3):
            ref = kendalltau(XA[:, j, a], XT[:, j, a]).statistic
            assert r[j, a] == pytest.approx(ref, abs=1e-12)


def test_flat_axis_rule():
    F = 20
    t = np.linspace(0, 1, F)
    moving = axis_angle_quats([1, 0, 1], np.radians(60) * t)
    # 0.0002 rad about z: the y axis moves by < 0.001 in x, ~0 in y and z: flat everywhere
    still = axis_angle_quats([0, 0, 1], 0.0002 * t)
    I = np.stack([moving, still], axis=1)
    # target: joint 0 still (flat), joint 1 moving
    T = np.stack([still, moving], axis=1)
    r = similarity_per_axis(I, I, np.arange(F))
    np.testing.assert_array_equal(r, np.ones((2, 3)))  # joint 1 flat in both -> 1
    r = similarity_per_axis(I, T, np.arange(F))
    np.testing.assert_array_equal(r, np.zeros((2, 3)))  # flat in one only: our choice, 0
    # x range 0.0025 (> 0.001) in both: tau is computed (identical series: 1; reversed: -1);
    # y and z stay flat in both -> 1
    Q = axis_angle_quats([0, 0, 1], 0.0025 * t)[:, None, :]
    X = joint_trajectories(Q)
    assert np.ptp(X[:, 0, 0]) > 0.001 > np.ptp(X[:, 0, 1])
    np.testing.assert_array_equal(similarity_per_axis(Q, Q, np.arange(F)), [[1.0, 1.0, 1.0]])
    np.testing.assert_array_equal(similarity_per_axis(Q, Q, np.arange(F)[::-1]), [[-1.0, 1, 1]])
    # x range 0.0008 (< 0.001) in both: counts as 1 even though time is reversed
    Q = axis_angle_quats([0, 0, 1], 0.0008 * t)[:, None, :]
    assert 0.0007 < np.ptp(joint_trajectories(Q)[:, 0, 0]) < 0.001
    np.testing.assert_array_equal(similarity_per_axis(Q, Q, np.arange(F)[::-1]), [[1.0, 1, 1]])
    assert FLAT_RANGE == 0.001


def test_stuck_map_scores_zero_on_moving_axes():
    q = monotone_motion(30, k=1)
    # every target frame mapped to input frame 0: the warped input is constant
    r = similarity_per_axis(q, q, np.zeros(30, dtype=int))
    np.testing.assert_array_equal(r, [[0.0, 0.0, 0.0]])


def test_similarity_real_motions(data_path):
    I = MotionFeatures.from_motion(load_motion(data_path(SQUAT.format(1))))
    T = MotionFeatures.from_motion(load_motion(data_path(SQUAT.format(2))))
    F = I.n_frames
    assert similarity(I.quats, I.quats, np.arange(F)) == 1.0
    # the first 40 frames go down into the squat: reversed time correlates negatively
    q = I.quats[:40]
    assert similarity(q, q, np.arange(40)[::-1]) < -0.2
    # a real pair: DTW and UTW both align two squats well; a reversed map does not
    s_dtw = similarity(I.quats, T.quats, dtw_pair(I, T).map)
    s_utw = similarity(I.quats, T.quats, utw_map(F - 1, T.n_frames - 1))
    s_rev = similarity(I.quats, T.quats, utw_map(F - 1, T.n_frames - 1)[::-1])
    assert 0.5 < s_utw < 1.0 and 0.5 < s_dtw < 1.0
    assert s_rev < s_utw - 0.2
    r = similarity_per_axis(I.quats, T.quats, utw_map(F - 1, T.n_frames - 1))
    assert r.shape == (8, 3) and np.all(np.abs(r) <= 1.0)


def test_similarity_errors():
    q = monotone_motion(10)
    with pytest.raises(AlignmentError, match="10 frames"):
        similarity(q, q, np.arange(9))
    with pytest.raises(AlignmentError, match="outside the input frames 0..9"):
        similarity(q, q, np.arange(1, 11))
    with pytest.raises(AlignmentError, match="same k"):
        similarity(q, q[:, :2], np.arange(10))
    with pytest.raises(AlignmentError, match="integer"):
        similarity(q, q, np.linspace(0, 9, 10) + 0.5)


# -- deviation and map helpers -----------------------------------------------------------------


def test_deviation_by_hand():
    # eq. 3 as printed: |1-2| + |2-2| + |3-5| = 3 over the n = 3 frames q = 1..3
    assert deviation([0, 1, 2, 3], [0, 2, 2, 5]) == 1.0
    assert deviation([0, 2, 2, 5], [0, 1, 2, 3]) == 1.0
    # frames="all": |0-0| + 3 = 3 over the 4 target frames q = 0..3
    assert deviation([0, 1, 2, 3], [0, 2, 2, 5], frames="all") == 0.75
    # frame 0 counts only with frames="all"
    assert deviation([4, 1], [0, 1]) == 0.0 and deviation([4, 1], [0, 1], frames="all") == 2.0
    assert deviation(np.arange(7), np.arange(7)) == 0.0
    # a constant 18-frame lag is exactly the paper's benchmark, either way
    assert deviation(np.arange(100), np.arange(100) + 18) == 18.0
    assert deviation(np.arange(100), np.arange(100) + 18, frames="all") == 18.0
    with pytest.raises(AlignmentError, match="different lengths"):
        deviation([0, 1], [0, 1, 2])
    with pytest.raises(AlignmentError, match="non-empty"):
        deviation([], [])
    with pytest.raises(AlignmentError, match="q = 1..n"):
        deviation([3], [3])
    assert deviation([3], [1], frames="all") == 2.0
    with pytest.raises(AlignmentError, match="frames must be one of"):
        deviation([0, 1], [0, 1], frames="n+1")


def test_map_helpers():
    assert is_monotonic([0, 0, 1, 5, 5])
    assert not is_monotonic([0, 2, 1])
    assert is_monotonic([3])
    assert in_range([0, 3, 4], 4)
    assert not in_range([0, 5], 4)
    assert not in_range([-1, 0], 4)
    with pytest.raises(AlignmentError):
        is_monotonic(np.zeros((2, 2), dtype=int))


def test_trajectory_scores_equal_similarity_per_axis_exactly():
    """The runner scores every map of a pair from each motion's trajectories, computed
    once: joint_trajectories(I)[M] must be joint_trajectories(I[M]) bit for bit."""
    from reference.synthetic import synthetic_pair

    from fpdtw.metrics import joint_trajectories, trajectory_scores

    I, T, _ = synthetic_pair(150, seed=7)
    rng = np.random.default_rng(1)
    XI, XT = joint_trajectories(I.quats), joint_trajectories(T.quats)
    for _ in range(5):
        M = np.sort(rng.integers(0, I.n_frames, T.n_frames))
        a = similarity_per_axis(I.quats, T.quats, M)
        b = trajectory_scores(XI[M], XT)
        assert np.array_equal(a, b)
    with pytest.raises(AlignmentError, match="different shapes"):
        trajectory_scores(XI[:5], XT)


def test_map_shape_metrics_by_hand():
    from fpdtw.metrics import exhausted_share, hold_share, step_counts, stick_skip_index

    M = np.array([0, 0, 1, 3, 3, 5, 5, 5])  # m = 5: steps 7, holds while live: q=1, q=4
    assert step_counts(M, 5) == dict(steps=7, exhausted=2, live=5, holds=2)
    assert hold_share(M, 5) == pytest.approx(2 / 5)
    assert exhausted_share(M, 5) == pytest.approx(2 / 7)
    # M/m - q/n over q = 0..7 (n = 7): median of [0, -1/7, 0.2-2/7, ...]
    d = M / 5 - np.arange(8) / 7
    assert stick_skip_index(M, 5) == pytest.approx(np.median(d))
    assert stick_skip_index(np.arange(8), 7) == 0.0  # the diagonal
    assert hold_share(np.array([0, 5, 5]), 5) == 0.0  # every hold after the input ran out
