"""Time-warp curve of the OPW poster: a piecewise cubic Bezier through keys (an "F-curve").

The curve maps LIVE time ``t`` (the motion being captured, the poster's B / X, on the
x-axis) to WARPED time ``t' = f(t)`` in the RECORDING (the poster's A / Y, on the
y-axis). It passes through its keys ``(x_i, y_i)`` (``x`` strictly increasing); between
two keys it is one cubic Bezier segment (poster eq. 3)::

    B(u) = (1-u)^3 P0 + 3u(1-u)^2 P1 + 3u^2(1-u) P2 + u^3 P3,   u in [0, 1]

with ``P0 = (x_i, y_i)``, ``P3 = (x_{i+1}, y_{i+1})`` and control points placed
automatically, as MotionBuilder places an F-curve's (poster Section 3, Fig. 2)::

    h  = x_{i+1} - x_i
    P1 = P0 + (h/3, m_i h/3)
    P2 = P3 - (h/3, m_{i+1} h/3)

Each key has ONE slope ``m_i`` shared by the segments on both of its sides, so the
left and right tangents at a key are parallel (G1, poster Fig. 2; in fact C1 as a
function of t). Because the control points split ``[x_i, x_{i+1}]`` in thirds, the
x-coordinate of a segment is LINEAR in ``u`` (``x(u) = x_i + u h``): evaluating the
curve at a time ``t`` needs no root finding, ``u = (t - x_i) / h``. The segment is
then the cubic Hermite interpolant with end slopes ``m_i, m_{i+1}``.

Slopes (our automatic rule; the poster's MotionBuilder rule is not published):

* interior key: the Catmull-Rom / central finite difference
  ``c_i = (y_{i+1} - y_{i-1}) / (x_{i+1} - x_{i-1})`` (MotionBuilder's "auto" tangent
  is also the direction between the neighbouring keys), LIMITED so that the curve is
  monotonic whenever its keys are (Fritsch & Carlson 1980): with the secants
  ``d_{i-1}, d_i`` of the two neighbouring segments, ``m_i = 0`` if they differ in sign
  or one is zero, else ``m_i = sign(c_i) * min(|c_i|, 3 min(|d_{i-1}|, |d_i|))``.
  Then every segment has ``m_i / d_i`` and ``m_{i+1} / d_i`` in ``[0, 3]``, the
  Fritsch-Carlson square in which a cubic Hermite segment is monotonic.
* first / last key: the secant of its only segment (``m_0 = d_0``,
  ``m_{K-1} = d_{K-2}``), so a two-key curve is exactly the straight line through its
  keys (the identity curve is ``t' = t`` everywhere, poster Table 1 row 1).

Outside ``[x_0, x_{K-1}]`` the curve is clamped: ``f(t) = y_0`` before the first key,
``y_{K-1}`` after the last (the recording holds its first / last pose).

Keys can be added and moved while the curve is being built (OPW does this online);
every change of the keys recomputes the slopes (O(K)), so an added key also changes the
slopes of its neighbours, as auto tangents in an F-curve editor do.
"""

from __future__ import annotations

import bisect

import numpy as np


class WarpCurve:
    """Monotone-preserving piecewise cubic Bezier time-warp curve ``t' = f(t)``.

    Parameters
    ----------
    x : array_like of float, shape (K,)
        Key times on the live (target) axis, strictly increasing, K >= 2.
    y : array_like of float, shape (K,)
        Key values on the warped (recording) axis.

    Attributes
    ----------
    keys : ndarray of float64, shape (K, 2)
        The keys ``(x_i, y_i)`` (a copy).
    slopes : ndarray of float64, shape (K,)
        The slope ``m_i = dy/dx`` of the curve at each key.

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

    # ------------------------------------------------------------------ constructors
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

    # ------------------------------------------------------------------ keys
    @property
    def keys(self) -> np.ndarray:
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

    def __len__(self):
        return len(self._x)

    def __repr__(self):
        return f"WarpCurve({self.n_keys} keys, t in [{self._x[0]:g}, {self._x[-1]:g}])"

    def add_key(self, x: float, y: float) -> int:
        """Insert a key; returns its index.

        Raises
        ------
        ValueError
            A key at the same time exists already, or a value is not finite.
        """
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
        """Move key ``i`` (negative indices count from the end) to a new time and/or value.

        Raises
        ------
        ValueError
            The new time would not lie strictly between the neighbouring keys.
        """
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

    # ------------------------------------------------------------------ slopes
    @property
    def slopes(self) -> np.ndarray:
        return np.asarray(self._slopes())

    def _slopes(self) -> list:
        if self._m is None:
            self._m = _auto_slopes(self._x, self._y)
        return self._m

    def control_points(self) -> np.ndarray:
        """Bezier control points of every segment.

        Returns
        -------
        P : ndarray of float64, shape (K - 1, 4, 2)
            ``P[k] = (P0, P1, P2, P3)`` of segment k, each ``(x, y)``.
        """
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

    # ------------------------------------------------------------------ evaluation
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
        """Evaluate ``f`` at times ``t`` (scalar or array, seconds).

        Parameters
        ----------
        t : float or array_like of float, shape (N,)

        Returns
        -------
        t_warped : float or ndarray of float64, shape (N,)
            Clamped to ``y_0`` / ``y_{K-1}`` outside the keys.
        """
        if np.ndim(t) == 0:
            return self.value(float(t))
        t = np.asarray(t, dtype=float)
        u, v, _, (p0, p1, p2, p3) = self._segments(t)
        return v**3 * p0 + 3.0 * u * v * v * p1 + 3.0 * u * u * v * p2 + u**3 * p3

    def _segments(self, t):
        """For times ``t`` (array): the Bezier parameter ``u``, ``1 - u``, the segment
        width ``h`` and the control values ``(P0, P1, P2, P3)`` of each time's segment."""
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
    """Slopes at the keys: limited Catmull-Rom inside, secants at the ends (module doc)."""
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


__all__ = ["WarpCurve"]
