"""Time-warp curve of the OPW poster: a piecewise cubic Bezier through keys (an "F-curve").

``t' = f(t)`` maps LIVE time (the poster's B / X) to time in the RECORDING (A / Y). Between
keys ``(x_i, y_i)`` it is one cubic Bezier segment (poster eq. 3) with ``P1 = P0 + (h/3,
m_i h/3)`` and ``P2 = P3 - (h/3, m_{i+1} h/3)``, ``h = x_{i+1} - x_i``: one slope ``m_i``
per key (tangents parallel, Fig. 2), and ``x`` linear in ``u``, so no root finding.
Outside the keys ``f`` is clamped to ``y_0`` / ``y_{K-1}``.

Reading (the poster's MotionBuilder rule is not published): an interior key's slope is the
central difference ``(y_{i+1} - y_{i-1}) / (x_{i+1} - x_{i-1})`` limited as Fritsch and
Carlson (1980) do, so the curve is monotonic where its keys are (0 where the neighbouring
secants differ in sign, at most 3 times the smaller one); an end key's is its segment's
secant, so two keys give a straight line. Every change of the keys recomputes the slopes.
"""

from __future__ import annotations

import bisect

import numpy as np


class WarpCurve:
    """Monotone-preserving piecewise cubic Bezier time-warp curve ``t' = f(t)``.

    Parameters
    ----------
    x : array_like of float, shape (K,)
        Key times (live axis), strictly increasing, K >= 2.
    y : array_like of float, shape (K,)
        Key values (recording axis).

    Paper: OPW poster Section 3, eq. 3, Fig. 2, Table 1.
    Notebook: 13_opw_fig4.ipynb
    """

    def __init__(self, x, y):
        x = [float(v) for v in np.asarray(x, dtype=float).ravel()]
        y = [float(v) for v in np.asarray(y, dtype=float).ravel()]
        if len(x) != len(y):
            raise ValueError(f"{len(x)} key times but {len(y)} key values")
        if len(x) < 2:
            raise ValueError("a warp curve needs at least two keys")
        if not (np.isfinite(x).all() and np.isfinite(y).all()):
            raise ValueError("key times and values must be finite")
        if any(b <= a for a, b in zip(x[:-1], x[1:])):
            raise ValueError("key times must be strictly increasing")
        self._x = x
        self._y = y
        self._m = None

    @classmethod
    def identity(cls, duration: float) -> WarpCurve:
        """The straight line ``t' = t`` from ``(0, 0)`` to ``(duration, duration)``."""
        duration = float(duration)
        if not duration > 0:
            raise ValueError(f"duration must be positive, got {duration}")
        return cls([0.0, duration], [0.0, duration])

    def copy(self) -> WarpCurve:
        """An independent copy."""
        return WarpCurve(self._x, self._y)

    @property
    def keys(self) -> np.ndarray:
        """The keys ``(x_i, y_i)``, float64 (K, 2), a copy."""
        return np.column_stack([self._x, self._y])

    @property
    def x(self) -> np.ndarray:
        """Key times, shape (K,)."""
        return np.asarray(self._x)

    @property
    def y(self) -> np.ndarray:
        """Key values, shape (K,)."""
        return np.asarray(self._y)

    @property
    def n_keys(self) -> int:
        return len(self._x)

    def __repr__(self):
        return f"WarpCurve({self.n_keys} keys, t in [{self._x[0]:g}, {self._x[-1]:g}])"

    def add_key(self, x: float, y: float) -> int:
        """Insert a key; returns its index (ValueError: a key at that time, or not finite)."""
        x, y = float(x), float(y)
        if not (np.isfinite(x) and np.isfinite(y)):
            raise ValueError("key time and value must be finite")
        i = bisect.bisect_left(self._x, x)
        if i < len(self._x) and self._x[i] == x:
            raise ValueError(f"there is a key at t = {x} already")
        self._x.insert(i, x)
        self._y.insert(i, y)
        self._m = None
        return i

    def move_key(self, i: int, x: float | None = None, y: float | None = None) -> None:
        """Move key ``i`` (negative: from the end) to a new time and/or value; ValueError
        unless the time stays strictly between the neighbouring keys."""
        K = len(self._x)
        if not -K <= i < K:
            raise IndexError(f"key index {i} out of range for {K} keys")
        i %= K
        if x is not None:
            x = float(x)
            lo = self._x[i - 1] if i > 0 else -np.inf
            hi = self._x[i + 1] if i < K - 1 else np.inf
            if not (lo < x < hi) or not np.isfinite(x):
                raise ValueError(
                    f"key {i} cannot move to t = {x}: it must stay strictly between "
                    f"its neighbours ({lo}, {hi})"
                )
            self._x[i] = x
        if y is not None:
            y = float(y)
            if not np.isfinite(y):
                raise ValueError("key value must be finite")
            self._y[i] = y
        self._m = None

    @property
    def slopes(self) -> np.ndarray:
        """The slope ``m_i = dy/dx`` at each key, float64 (K,)."""
        return np.asarray(self._slopes())

    def _slopes(self) -> list:
        if self._m is None:
            self._m = _auto_slopes(self._x, self._y)
        return self._m

    def control_points(self) -> np.ndarray:
        """Bezier control points, float64 (K - 1, 4, 2): ``(P0, P1, P2, P3)`` per segment."""
        x = np.asarray(self._x)
        y = np.asarray(self._y)
        m = np.asarray(self._slopes())
        h = np.diff(x)
        P = np.empty((len(h), 4, 2))
        P[:, 0, 0], P[:, 0, 1] = x[:-1], y[:-1]
        P[:, 1, 0], P[:, 1, 1] = x[:-1] + h / 3, y[:-1] + m[:-1] * h / 3
        P[:, 2, 0], P[:, 2, 1] = x[1:] - h / 3, y[1:] - m[1:] * h / 3
        P[:, 3, 0], P[:, 3, 1] = x[1:], y[1:]
        return P

    def value(self, t: float) -> float:
        """``f(t)`` for one time (fast scalar path, used every frame by OPW)."""
        xs, ys = self._x, self._y
        if t <= xs[0]:
            return ys[0]
        if t >= xs[-1]:
            return ys[-1]
        m = self._slopes()
        k = bisect.bisect_right(xs, t) - 1
        h = xs[k + 1] - xs[k]
        u = (t - xs[k]) / h
        v = 1.0 - u
        p0, p3 = ys[k], ys[k + 1]
        p1 = p0 + m[k] * h / 3.0
        p2 = p3 - m[k + 1] * h / 3.0
        return v * v * v * p0 + 3.0 * u * v * v * p1 + 3.0 * u * u * v * p2 + u * u * u * p3

    def __call__(self, t):
        """``f(t)`` for a time or an array of times (seconds)."""
        if np.ndim(t) == 0:
            return self.value(float(t))
        t = np.asarray(t, dtype=float)
        u, v, _, (p0, p1, p2, p3) = self._segments(t)
        return v**3 * p0 + 3.0 * u * v * v * p1 + 3.0 * u * u * v * p2 + u**3 * p3

    def _segments(self, t):
        """Per time of ``t`` (array): ``u``, ``1 - u``, ``h`` and its segment's control values."""
        x = np.asarray(self._x)
        y = np.asarray(self._y)
        m = np.asarray(self._slopes())
        k = np.clip(np.searchsorted(x, t, side="right") - 1, 0, len(x) - 2)
        h = x[k + 1] - x[k]
        u = np.clip((t - x[k]) / h, 0.0, 1.0)
        p0, p3 = y[k], y[k + 1]
        return u, 1.0 - u, h, (p0, p0 + m[k] * h / 3.0, p3 - m[k + 1] * h / 3.0, p3)

    def derivative(self, t):
        """``df/dt`` at times ``t`` (0 outside the keys), same shape as ``t``."""
        t = np.asarray(t, dtype=float)
        x = self._x
        u, v, h, (p0, p1, p2, p3) = self._segments(t)
        dy_du = 3.0 * (v * v * (p1 - p0) + 2.0 * u * v * (p2 - p1) + u * u * (p3 - p2))
        out = np.where((t < x[0]) | (t > x[-1]), 0.0, dy_du / h)
        return out[()] if out.ndim == 0 else out


def _auto_slopes(x, y) -> list:
    """Slopes at the keys: limited central differences inside, secants at the ends."""
    K = len(x)
    d = [(y[i + 1] - y[i]) / (x[i + 1] - x[i]) for i in range(K - 1)]
    m = [0.0] * K
    m[0] = d[0]
    m[-1] = d[-1]
    for i in range(1, K - 1):
        a, b = d[i - 1], d[i]
        if a * b <= 0.0:
            m[i] = 0.0
            continue
        c = (y[i + 1] - y[i - 1]) / (x[i + 1] - x[i - 1])
        lim = 3.0 * min(abs(a), abs(b))
        m[i] = c if abs(c) <= lim else (lim if c > 0 else -lim)
    return m
