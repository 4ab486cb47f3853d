"""Forecasters (dead reckoning, exponential smoothing, Holt) and the numba Euler->quat."""

from __future__ import annotations

import numpy as np
import pytest
from reference.synthetic import features_from_euler, random_walk_features

from fpdtw.costs import geo_distance
from fpdtw.forecast import (
    dead_reckoning,
    euler_to_quat_fast,
    exponential_smoothing,
    forecast_error_curve,
    holt,
    level_to_alpha,
    order_codes,
)
from fpdtw.motion.rotations import ORDERS, euler_to_quat
from fpdtw.plain import forecast_joints


def test_euler_to_quat_fast_equals_rotations_up_to_sign():
    rng = np.random.default_rng(0)
    E = np.concatenate(
        [rng.uniform(-720, 720, (400, 6, 3)), rng.uniform(-5, 5, (50, 6, 3)),
         np.array([[[90.0, 90.0, 90.0]] * 6, [[0.0, 90.0, 0.0]] * 6, [[0.0, 0.0, 0.0]] * 6])]
    )  # fmt: skip
    Q = euler_to_quat_fast(E, ORDERS)
    assert Q.shape == (E.shape[0], 6, 4)
    for j, order in enumerate(ORDERS):
        R = euler_to_quat(E[:, j], order)
        sign = np.where(np.sum(R * Q[:, j], axis=-1) < 0, -1.0, 1.0)[:, None]
        np.testing.assert_allclose(Q[:, j] * sign, R, rtol=0, atol=1e-12, err_msg=order)


def test_euler_to_quat_fast_hand_values():
    # 90 deg about X: (cos 45, sin 45, 0, 0); "XYZ" with x = y = 90: R = Ry(90) Rx(90),
    # q = (c, 0, s, 0)(c, s, 0, 0) = (c^2, c s, s c, -s^2) = (.5, .5, .5, -.5)
    Q = euler_to_quat_fast(np.array([[[90.0, 0, 0], [90.0, 90.0, 0]]]), ("ZYX", "XYZ"))
    h = np.sqrt(0.5)
    np.testing.assert_allclose(Q[0, 0], [h, h, 0, 0], atol=1e-15)
    np.testing.assert_allclose(Q[0, 1], [0.5, 0.5, 0.5, -0.5], atol=1e-15)


def test_order_codes():
    np.testing.assert_array_equal(order_codes(["XYZ", "zyx", "YXZ"]), [0, 5, 2])
    with pytest.raises(ValueError, match="rotation order"):
        order_codes(["XYX"])
    with pytest.raises(ValueError, match="rotation orders for"):
        euler_to_quat_fast(np.zeros((2, 3, 3)), ("XYZ",))


def test_forecast_joints_starts_at_the_incoming_frame():
    E_n = np.array([[10.0, 0.0, -5.0]])
    E_n1 = np.array([[12.0, 1.0, -5.0]])
    F = forecast_joints(E_n, E_n1, 4)
    np.testing.assert_array_equal(F[:, 0], [[12, 1, -5], [14, 2, -5], [16, 3, -5], [18, 4, -5]])


@pytest.mark.parametrize("s", [2, 3, 5])
def test_dead_reckoning_exact_on_linear_sequences(s):
    rng = np.random.default_rng(s)
    a, b = rng.uniform(-90, 90, (2, 8, 3))
    t = np.arange(20, dtype=float)[:, None, None]
    E = a + b * t
    F = dead_reckoning(E[:12], s, 6)
    np.testing.assert_allclose(F, E[12:18], rtol=0, atol=1e-10)


def test_dead_reckoning_known_values():
    E = np.array([0.0, 1.0, 4.0, 9.0])  # squares
    np.testing.assert_allclose(dead_reckoning(E, 2, 2), [14.0, 19.0])  # v = 9 - 4
    np.testing.assert_allclose(dead_reckoning(E, 3, 2), [13.0, 17.0])  # v = (9 - 1) / 2
    np.testing.assert_allclose(dead_reckoning(E, 4, 1), [12.0])  # v = 9 / 3
    with pytest.raises(ValueError, match="s >= 2"):
        dead_reckoning(E, 1, 2)
    with pytest.raises(ValueError, match="at least 5 frames"):
        dead_reckoning(E, 5, 2)


def test_exponential_smoothing_known_values():
    E = np.array([0.0, 10.0, 20.0])
    # l0 = 0, l1 = .5*10 + .5*0 = 5, l2 = .5*20 + .5*5 = 12.5; flat forecast
    np.testing.assert_allclose(exponential_smoothing(E, 0.5, 3), [12.5, 12.5, 12.5])
    np.testing.assert_allclose(exponential_smoothing(E, 1.0, 2), [20.0, 20.0])
    E2 = np.stack([E, -E], axis=1)
    np.testing.assert_allclose(exponential_smoothing(E2, 0.5, 1), [[12.5, -12.5]])
    with pytest.raises(ValueError, match="alpha"):
        exponential_smoothing(E, 0.0, 3)


@pytest.mark.parametrize("alpha,beta", [(0.2, 0.1), (0.5, 0.5), (0.9, 0.3), (1.0, 1.0)])
def test_holt_exact_on_linear_trend(alpha, beta):
    t = np.arange(15, dtype=float)[:, None, None]
    E = 7.0 - 2.5 * t + np.zeros((1, 2, 3))
    F = holt(E[:10], alpha, beta, 5)
    np.testing.assert_allclose(F, E[10:15], rtol=0, atol=1e-10)


def test_holt_known_values():
    E = np.array([0.0, 2.0, 3.0])
    # l0 = 0, b0 = 2; l1 = .5*2 + .5*(0+2) = 2, b1 = .5*(2-0) + .5*2 = 2;
    # l2 = .5*3 + .5*(2+2) = 3.5, b2 = .5*(3.5-2) + .5*2 = 1.75; forecast 3.5 + 1.75 i
    np.testing.assert_allclose(holt(E, 0.5, 0.5, 2), [5.25, 7.0])


def test_holt_with_alpha_beta_one_is_two_frame_dead_reckoning():
    E = random_walk_features(40, seed=2).euler
    np.testing.assert_allclose(holt(E, 1.0, 1.0, 5), dead_reckoning(E, 2, 5), atol=1e-9)


def test_level_to_alpha():
    assert level_to_alpha(1) == 1.0
    assert level_to_alpha(3) == 0.5
    assert level_to_alpha(9) == 0.2
    with pytest.raises(ValueError):
        level_to_alpha(0)


def _naive_curve(motions, method, levels, H):
    """Per-start-frame Python loops with scipy quaternions and the eq.-1 kernel."""
    t0 = max(max(levels) - 1, 1)
    out = np.zeros((len(levels), H))
    count = 0
    for mf in motions:
        n = mf.n_frames
        for t in range(t0, n - H):
            count += 1
            for li, s in enumerate(levels):
                hist = mf.euler[: t + 1]
                if method == "dead_reckoning":
                    F = dead_reckoning(hist, s, H)
                elif method == "exponential":
                    F = exponential_smoothing(hist, level_to_alpha(s), H)
                else:
                    F = holt(hist, level_to_alpha(s), level_to_alpha(s), H)
                for i in range(1, H + 1):
                    q = np.stack([euler_to_quat(F[i - 1, j], mf.orders[j]) for j in range(8)])
                    out[li, i - 1] += geo_distance(q, mf.quats[t + i])
    return out / count


@pytest.mark.parametrize("method", ["dead_reckoning", "exponential", "holt"])
def test_forecast_error_curve_matches_naive_loops(method):
    motions = [random_walk_features(30, seed=7), random_walk_features(24, seed=8)]
    levels = [2, 3, 5]
    got = forecast_error_curve(motions, method, levels, 4)
    assert got.shape == (3, 4)
    np.testing.assert_allclose(got, _naive_curve(motions, method, levels, 4), rtol=1e-9, atol=1e-12)


def test_forecast_error_curve_properties():
    rng = np.random.default_rng(1)
    t = np.arange(80, dtype=float)[:, None, None]
    lin = features_from_euler(rng.uniform(-50, 50, (1, 8, 3)) + t * rng.uniform(-1, 1, (1, 8, 3)))
    err = forecast_error_curve([lin], "dead_reckoning", [2, 4], 10)
    assert np.all(err < 1e-6)  # exact on linear motion (quaternion round-off only)
    rw = [random_walk_features(200, seed=s) for s in range(2)]
    err = forecast_error_curve(rw, "dead_reckoning", [2, 3, 6], 12)
    assert np.all(np.diff(err, axis=1) > 0)  # error grows with the frames ahead
    assert np.all(err > 0)
    with pytest.raises(ValueError, match="unknown forecaster"):
        forecast_error_curve(rw, "kalman", [2], 3)
    with pytest.raises(ValueError, match="level 1"):
        forecast_error_curve(rw, "dead_reckoning", [1, 2], 3)
    with pytest.raises(ValueError, match="no motion"):
        forecast_error_curve([lin.slice(0, 5)], "holt", [2], 10)
