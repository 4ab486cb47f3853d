"""The OPW time-warp curve: a piecewise cubic Bezier through keys, G1, monotone-preserving.

Hand values use the poster's example curve, keys (0, 0), (1.25, 1.5), (2.5, 2.5): secants
1.2 and 0.8, so the slopes are 1.2 (first key: its secant), (2.5 - 0)/(2.5 - 0) = 1.0
(middle: Catmull-Rom, below the limit 3 * 0.8) and 0.8 (last key).
"""

from __future__ import annotations

import numpy as np
import pytest

from fpdtw.warpcurve import WarpCurve


def example():
    return WarpCurve([0.0, 1.25, 2.5], [0.0, 1.5, 2.5])


def test_passes_through_keys_and_clamps_outside():
    c = WarpCurve([0.0, 0.3, 1.1, 2.0, 2.4], [0.1, 0.2, 1.5, 1.6, 2.6])
    assert np.allclose(c(c.x), c.y, atol=1e-15)
    for x, y in c.keys:
        assert c.value(x) == pytest.approx(y, abs=1e-15)
    assert c(-1.0) == 0.1 and c(10.0) == 2.6
    assert np.array_equal(c(np.array([-5.0, 99.0])), [0.1, 2.6])


def test_hand_computed_three_key_curve():
    c = example()
    assert np.allclose(c.slopes, [1.2, 1.0, 0.8])
    # segment 0 at u = 1/2: Bezier y = (P0 + 3 P1 + 3 P2 + P3) / 8 with
    # P1 = 0 + 1.2 * 1.25 / 3 = 0.5, P2 = 1.5 - 1.0 * 1.25 / 3 = 13/12
    # -> (0 + 1.5 + 3.25 + 1.5) / 8 = 0.78125
    assert c(0.625) == pytest.approx(0.78125, abs=1e-15)
    # segment 1 at u = 1/2: P1 = 1.5 + 1.25/3 = 23/12, P2 = 2.5 - 0.8 * 1.25/3 = 13/6
    # -> (1.5 + 5.75 + 6.5 + 2.5) / 8 = 2.03125
    assert c(1.875) == pytest.approx(2.03125, abs=1e-15)
    P = c.control_points()
    assert P.shape == (2, 4, 2)
    assert np.allclose(P[0], [[0, 0], [1.25 / 3, 0.5], [2.5 / 3, 13 / 12], [1.25, 1.5]])
    assert np.allclose(P[1], [[1.25, 1.5], [1.25 + 1.25 / 3, 23 / 12], [2.5 - 1.25 / 3, 13 / 6],
                              [2.5, 2.5]])  # fmt: skip


def test_x_is_linear_in_u_so_evaluation_needs_no_root_finding():
    # the control points split each segment's time span in thirds
    c = WarpCurve([0.0, 0.4, 1.5, 1.7], [0.0, 0.9, 1.0, 2.0])
    P = c.control_points()
    assert np.allclose(np.diff(P[:, :, 0], axis=1), np.diff(c.x)[:, None] / 3)
    # evaluating the Bezier at parameter u gives the point (x_k + u h, f(x_k + u h))
    for k, Pk in enumerate(P):
        for u in (0.1, 0.37, 0.8):
            b = ((1 - u) ** 3 * Pk[0] + 3 * u * (1 - u) ** 2 * Pk[1] + 3 * u**2 * (1 - u) * Pk[2]
                 + u**3 * Pk[3])  # fmt: skip
            assert b[0] == pytest.approx(c.x[k] + u * (c.x[k + 1] - c.x[k]))
            assert c(b[0]) == pytest.approx(b[1], abs=1e-14)


def test_g1_continuity_at_every_key():
    rng = np.random.default_rng(3)
    x = np.cumsum(rng.uniform(0.05, 1.0, 12))
    y = rng.normal(size=12)  # not monotonic: includes slope sign changes
    c = WarpCurve(x, y)
    P = c.control_points()
    for k in range(1, len(x) - 1):
        left = P[k - 1, 3] - P[k - 1, 2]
        right = P[k, 1] - P[k, 0]
        assert left[0] > 0 and right[0] > 0
        # parallel and pointing the same way (cross product 0): equal directions
        assert left[0] * right[1] - left[1] * right[0] == pytest.approx(0.0, abs=1e-12)
        assert left[1] / left[0] == pytest.approx(right[1] / right[0])
    # the derivative is continuous across every key
    d = c.derivative(np.concatenate([x[1:-1] - 1e-9, x[1:-1] + 1e-9]))
    n = len(x) - 2
    assert np.allclose(d[:n], d[n:], atol=1e-6)
    assert np.allclose(c.derivative(x), c.slopes)


def test_identity_curve_is_t():
    c = WarpCurve.identity(2.5)
    t = np.linspace(0, 2.5, 1001)
    assert np.allclose(c(t), t, atol=1e-15)
    assert np.allclose(c.slopes, 1.0)
    assert c(-0.5) == 0.0 and c(3.0) == 2.5
    # a key on the line keeps it the identity
    c.add_key(1.0, 1.0)
    assert np.allclose(c(t), t, atol=1e-15)
    with pytest.raises(ValueError):
        WarpCurve.identity(0.0)


def test_monotonic_for_random_monotonic_keys():
    rng = np.random.default_rng(0)
    for trial in range(300):
        K = int(rng.integers(2, 15))
        x = np.cumsum(rng.uniform(0.01, 1.0, K))
        dy = rng.exponential(1.0, K) * (rng.uniform(size=K) < 0.8)  # some flat segments
        if trial % 3 == 0:
            dy *= rng.uniform(0.01, 50.0, K)  # very uneven secants: the limiter matters
        y = np.cumsum(dy)
        c = WarpCurve(x, y)
        t = np.linspace(x[0] - 0.1, x[-1] + 0.1, 4000)
        v = c(t)
        assert np.all(np.diff(v) >= -1e-12), trial
        assert v.min() >= y[0] - 1e-12 and v.max() <= y[-1] + 1e-12


def test_slope_limiter_and_extremum_by_hand():
    # secants 0.1 and 2.0: Catmull-Rom 2.1 / 2 = 1.05 is above 3 * 0.1 -> limited to 0.3
    c = WarpCurve([0, 1, 2], [0, 0.1, 2.1])
    assert np.allclose(c.slopes, [0.1, 0.3, 2.0])
    t = np.linspace(0, 2, 2001)
    assert np.all(np.diff(c(t)) >= 0)
    # an extremum key gets slope 0 (secants of opposite sign)
    c = WarpCurve([0, 1, 2], [0, 1, 0])
    assert c.slopes[1] == 0.0
    assert c(np.linspace(0, 2, 501)).max() == pytest.approx(1.0)


def test_add_and_move_keys():
    c = WarpCurve.identity(2.0)
    i = c.add_key(1.0, 1.5)
    assert i == 1 and c.n_keys == 3
    assert np.allclose(c.keys, [[0, 0], [1, 1.5], [2, 2]])
    # secants 1.5 and 0.5; middle slope (2 - 0) / 2 = 1; Hermite at the middle of segment 0:
    # (0 + 1.5) / 2 + 1 * (1.5 - 1.0) / 8 = 0.8125
    assert np.allclose(c.slopes, [1.5, 1.0, 0.5])
    assert c(0.5) == pytest.approx(0.8125)
    assert c.add_key(0.25, 0.3) == 1  # inserted in time order
    assert np.allclose(c.x, [0, 0.25, 1, 2])
    c.move_key(-1, x=2.5)
    assert c.x[-1] == 2.5 and c(2.5) == 2.0 and c(3.0) == 2.0
    c.move_key(2, y=1.2)
    assert c(1.0) == pytest.approx(1.2)
    c.move_key(1, x=0.5, y=0.6)
    assert np.allclose(c.keys, [[0, 0], [0.5, 0.6], [1, 1.2], [2.5, 2]])
    with pytest.raises(ValueError):
        c.add_key(1.0, 3.0)  # a key at t = 1 exists
    with pytest.raises(ValueError):
        c.move_key(1, x=1.0)  # may not reach its neighbour
    with pytest.raises(ValueError):
        c.move_key(-1, x=0.9)  # may not pass it
    with pytest.raises(IndexError):
        c.move_key(7, y=0.0)
    before = c.keys
    cc = c.copy()
    cc.add_key(2.0, 1.9)
    assert np.array_equal(c.keys, before)


def test_scalar_and_vector_evaluation_agree():
    rng = np.random.default_rng(1)
    x = np.cumsum(rng.uniform(0.05, 0.5, 20))
    y = np.cumsum(rng.uniform(0.0, 0.5, 20))
    c = WarpCurve(x, y)
    t = rng.uniform(x[0] - 0.2, x[-1] + 0.2, 500)
    assert np.allclose([c.value(v) for v in t], c(t), atol=1e-14)
    assert isinstance(c(0.3), float)


def test_invalid_keys():
    with pytest.raises(ValueError):
        WarpCurve([0.0], [0.0])
    with pytest.raises(ValueError):
        WarpCurve([0.0, 1.0, 1.0], [0.0, 1.0, 2.0])
    with pytest.raises(ValueError):
        WarpCurve([0.0, 1.0], [0.0, np.nan])
    with pytest.raises(ValueError):
        WarpCurve([0.0, 1.0], [0.0])
