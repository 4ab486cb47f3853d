"""Forecasting joint rotations: dead reckoning and smoothing (FP-DTW Section 3.2, Fig. 3).

Methods B and C dead-reckon the target on unwrapped Euler angles (``forecastJoints``), then
turn the forecast into quaternions for eq. 1 (:func:`euler_to_quat_fast`; the window methods
inline its kernel). Fig. 3's forecasters read a smoothing level ``s`` as ``alpha = 2 / (s + 1)``
(:func:`level_to_alpha`); :func:`forecast_error_curve` measures their eq. 1 error.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from fpdtw.motion.kinematics import ORDER_AXES, order_codes

_HALF_RAD_PER_DEG = math.pi / 360.0


@numba.njit(cache=True, inline="always")
def _euler_to_quat(ex, ey, ez, code):
    """Quaternion (w, x, y, z) of Euler angles in degrees (x, y, z) for order ``code``:
    ``q = q_a3 q_a2 q_a1`` for the axes applied in that order; the sign is not normalised."""
    w = 1.0
    x = 0.0
    y = 0.0
    z = 0.0
    for step in range(3):
        axis = ORDER_AXES[code, step]
        if axis == 0:
            h = ex * _HALF_RAD_PER_DEG
        elif axis == 1:
            h = ey * _HALF_RAD_PER_DEG
        else:
            h = ez * _HALF_RAD_PER_DEG
        c = math.cos(h)
        s = math.sin(h)
        # left-multiply by the axis quaternion (c, s * e_axis)
        if axis == 0:
            w, x, y, z = c * w - s * x, c * x + s * w, c * y - s * z, c * z + s * y
        elif axis == 1:
            w, x, y, z = c * w - s * y, c * x + s * z, c * y + s * w, c * z - s * x
        else:
            w, x, y, z = c * w - s * z, c * x - s * y, c * y + s * x, c * z + s * w
    return w, x, y, z


@numba.njit(cache=True)
def _euler_to_quat_block(E, codes, out):
    """out[f, j] = quaternion of E[f, j] (degrees) in order codes[j]; E (F, k, 3)."""
    for f in range(E.shape[0]):
        for j in range(E.shape[1]):
            w, x, y, z = _euler_to_quat(E[f, j, 0], E[f, j, 1], E[f, j, 2], codes[j])
            out[f, j, 0] = w
            out[f, j, 1] = x
            out[f, j, 2] = y
            out[f, j, 3] = z
    return out


def euler_to_quat_fast(E, orders) -> np.ndarray:
    """Convert per-joint Euler angles to quaternions (numba).

    Parameters
    ----------
    E : ndarray of float, shape (..., k, 3)
        Angles in degrees, columns (x, y, z).
    orders : sequence of str, length k
        Rotation order of each joint.

    Returns
    -------
    Q : ndarray of float64, shape (..., k, 4)
        :func:`fpdtw.motion.rotations.euler_to_quat` up to sign.

    Plain version: fpdtw.plain.euler_to_quat.
    Paper: FP-DTW Algorithms 2 and 3 (forecastJoints output turned into quaternions).
    """
    E = np.asarray(E, dtype=np.float64)
    if E.ndim < 2 or E.shape[-1] != 3:
        raise ValueError(f"expected Euler angles of shape (..., k, 3), got {E.shape}")
    codes = order_codes(orders)
    k = E.shape[-2]
    if codes.shape[0] != k:
        raise ValueError(f"{codes.shape[0]} rotation orders for {k} joints")
    lead = E.shape[:-2]
    flat = np.ascontiguousarray(E.reshape(-1, k, 3))
    out = np.empty((flat.shape[0], k, 4))
    _euler_to_quat_block(flat, codes, out)
    return out.reshape(lead + (k, 4))


def level_to_alpha(s) -> float:
    """Smoothing factor ``alpha = 2 / (s + 1)`` of level ``s >= 1``: the centre of mass
    of an ``s``-frame moving average, ``(s - 1) / 2`` frames back."""
    s = float(s)
    if not s >= 1:
        raise ValueError(f"smoothing level must be >= 1, got {s}")
    return 2.0 / (s + 1.0)


def _check_hist(E_hist, need, what):
    E = np.asarray(E_hist, dtype=np.float64)
    if E.ndim < 1 or E.shape[0] < need:
        raise ValueError(f"{what} needs at least {need} frames of history, got {E.shape}")
    return E


def _check_H(H):
    H = int(H)
    if H < 1:
        raise ValueError(f"forecast horizon H must be >= 1, got {H}")
    return H


def _ahead(H, E):
    """Column vector i = 1..H broadcastable against one frame of E."""
    return np.arange(1, H + 1, dtype=np.float64).reshape((-1,) + (1,) * (E.ndim - 1))


def dead_reckoning(E_hist, s: int, H: int) -> np.ndarray:
    """Dead reckoning from the ``s`` latest frames.

    Parameters
    ----------
    E_hist : ndarray of float, shape (t, ...)
        Unwrapped Euler angles (degrees) received so far, oldest first.
    s : int
        Smoothing level, ``s >= 2``: velocity ``v = (E[-1] - E[-s]) / (s - 1)``.
    H : int

    Returns
    -------
    F : ndarray of float64, shape (H, ...)
        ``F[i - 1] = E[-1] + i * v`` for ``i = 1..H``.

    Paper: FP-DTW Section 3.2 and Fig. 3 (s = 2 is the paper's choice).
    """
    s = int(s)
    if s < 2:
        raise ValueError(f"dead reckoning needs a smoothing level s >= 2, got {s}")
    H = _check_H(H)
    E = _check_hist(E_hist, s, "dead reckoning")
    v = (E[-1] - E[-s]) / (s - 1)
    return E[-1] + _ahead(H, E) * v


@numba.njit(cache=True)
def _smooth(E, alpha, beta, holt, level, trend):
    """Causal exponential / Holt smoothing of E (t, d) into level, trend (t, d)."""
    t, d = E.shape
    for c in range(d):
        lv = E[0, c]
        tr = E[1, c] - E[0, c] if (holt and t > 1) else 0.0
        level[0, c] = lv
        trend[0, c] = tr
        for f in range(1, t):
            if holt:
                new = alpha * E[f, c] + (1.0 - alpha) * (lv + tr)
                tr = beta * (new - lv) + (1.0 - beta) * tr
                lv = new
            else:
                lv = alpha * E[f, c] + (1.0 - alpha) * lv
            level[f, c] = lv
            trend[f, c] = tr


def _smoothed(E, alpha, beta, holt):
    E2 = np.ascontiguousarray(E.reshape(E.shape[0], -1))
    level = np.empty_like(E2)
    trend = np.empty_like(E2)
    _smooth(E2, float(alpha), float(beta), bool(holt), level, trend)
    return level.reshape(E.shape), trend.reshape(E.shape)


def _check_factor(x, name):
    x = float(x)
    if not 0.0 < x <= 1.0:
        raise ValueError(f"{name} must be in (0, 1], got {x}")
    return x


def exponential_smoothing(E_hist, alpha: float, H: int) -> np.ndarray:
    """Simple exponential smoothing: ``l_0 = E_0``, ``l_t = alpha E_t + (1 - alpha)
    l_{t-1}``; every ``i = 1..H`` is forecast as the last level.

    Parameters
    ----------
    E_hist : ndarray of float, shape (t, ...)
        As :func:`dead_reckoning`, ``t >= 1``.
    alpha : float
        In (0, 1].
    H : int

    Returns
    -------
    F : ndarray of float64, shape (H, ...)

    Paper: FP-DTW Fig. 3 (alternative smoothing function, ref. 7).
    """
    alpha = _check_factor(alpha, "alpha")
    H = _check_H(H)
    E = _check_hist(E_hist, 1, "exponential smoothing")
    level, _ = _smoothed(E, alpha, 1.0, False)
    return np.broadcast_to(level[-1], (H,) + E.shape[1:]).copy()


def holt(E_hist, alpha: float, beta: float, H: int) -> np.ndarray:
    """Holt's double exponential smoothing: ``l_0 = E_0``, ``b_0 = E_1 - E_0``; ``l_t =
    alpha E_t + (1 - alpha)(l_{t-1} + b_{t-1})``, ``b_t = beta (l_t - l_{t-1}) + (1 - beta)
    b_{t-1}``; forecast ``l_t + i b_t``, ``i = 1..H``.

    Parameters
    ----------
    E_hist : ndarray of float, shape (t, ...)
        As :func:`dead_reckoning`, ``t >= 2``.
    alpha, beta : float
        Level and trend factors in (0, 1].
    H : int

    Returns
    -------
    F : ndarray of float64, shape (H, ...)

    Paper: FP-DTW Fig. 3 (alternative smoothing function, ref. 7).
    """
    alpha = _check_factor(alpha, "alpha")
    beta = _check_factor(beta, "beta")
    H = _check_H(H)
    E = _check_hist(E_hist, 2, "Holt smoothing")
    level, trend = _smoothed(E, alpha, beta, True)
    return level[-1] + _ahead(H, E) * trend[-1]


FORECASTERS = ("dead_reckoning", "exponential", "holt")


def _geo_rows(Qa, Qb):
    """eq. 1 between matching frames: Qa, Qb (N, k, 4) -> (N,)."""
    dots = Qa[..., 0] * Qb[..., 0]
    for c in (1, 2, 3):
        dots = dots + Qa[..., c] * Qb[..., c]
    return (2.0 / np.pi) * np.arccos(np.clip(np.abs(dots), 0.0, 1.0)).sum(axis=-1)


def forecast_error_curve(motions_features, method: str, levels, H: int) -> np.ndarray:
    """Mean geodesic forecast error vs frames ahead, per smoothing level.

    From every start frame ``t`` of every motion, ``max(s_max - 1, 1) <= t <= F - 1 - H``
    (the same for every level), the forecast of frame ``t + i`` is compared with it by
    eq. 1; every start frame weighs the same.

    Parameters
    ----------
    motions_features : sequence of MotionFeatures
    method : {"dead_reckoning", "exponential", "holt"}
        ``dead_reckoning``: ``s`` frames for the velocity (s >= 2); the others ``alpha
        = 2 / (s + 1)`` (Holt: ``beta = alpha`` too).
    levels : sequence of int
        Smoothing levels ``s``.
    H : int

    Returns
    -------
    err : ndarray of float64, shape (len(levels), H)
        ``err[l, i - 1]``: mean eq.-1 error of level ``levels[l]`` at ``i`` frames ahead.

    Paper: FP-DTW Fig. 3.
    """
    if method not in FORECASTERS:
        raise ValueError(f"unknown forecaster {method!r}; expected one of {FORECASTERS}")
    H = _check_H(H)
    levels = [int(s) for s in levels]
    if not levels:
        raise ValueError("no smoothing levels given")
    lo = 2 if method == "dead_reckoning" else 1
    for s in levels:
        if s < lo:
            raise ValueError(f"smoothing level {s} < {lo} for method {method!r}")
    t0 = max(max(levels) - 1, 1)
    total = np.zeros((len(levels), H))
    count = 0
    for mf in motions_features:
        E = np.asarray(mf.euler, dtype=np.float64)
        Q = np.asarray(mf.quats, dtype=np.float64)
        n = E.shape[0]
        t = np.arange(t0, n - H)
        if t.size == 0:
            continue
        codes = order_codes(mf.orders)
        count += t.size
        for li, s in enumerate(levels):
            if method == "dead_reckoning":
                base = E[t]
                v = (E[t] - E[t - s + 1]) / (s - 1)
            else:
                a = level_to_alpha(s)
                level, trend = _smoothed(E, a, a, method == "holt")
                base = level[t]
                v = trend[t] if method == "holt" else np.zeros_like(base)
            pred = np.empty((t.size,) + Q.shape[1:])
            for i in range(1, H + 1):
                _euler_to_quat_block(np.ascontiguousarray(base + i * v), codes, pred)
                total[li, i - 1] += _geo_rows(pred, Q[t + i]).sum()
    if count == 0:
        raise ValueError(f"no motion has more than {t0 + H} frames: nothing to evaluate")
    return total / count
