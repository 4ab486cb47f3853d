"""Rotations: unit quaternions and Euler angles.

Quaternions are ``(w, x, y, z)``, Hamilton product, acting as ``v' = q v q*``. Euler angles are
stored in degrees as ``(x, y, z)`` columns whatever the order. A rotation order lists the axes in
the order they are APPLIED (extrinsic; FBX ``eEulerXYZ``, ASF ``axis XYZ``): ``"XYZ"`` is ``R = Rz
Ry Rx``, which BVH writes ``Zrotation Yrotation Xrotation`` (outermost first).
"""

from __future__ import annotations

import math

import numba
import numpy as np
from scipy.spatial.transform import Rotation

ORDERS = ("XYZ", "XZY", "YXZ", "YZX", "ZXY", "ZYX")
_AXIS = {"X": 0, "Y": 1, "Z": 2}


def check_order(order: str) -> str:
    """Return ``order`` upper-cased if it is one of the six Tait-Bryan orders."""
    o = str(order).upper()
    if o not in ORDERS:
        raise ValueError(f"unknown rotation order {order!r}; expected one of {ORDERS}")
    return o


def euler_to_quat(euler, order="XYZ"):
    """Unit quaternions (..., 4), ``w >= 0``, of Euler angles (..., 3) in rotation ``order``."""
    order = check_order(order)
    e = np.asarray(euler, dtype=float)
    shape = e.shape[:-1]
    flat = e.reshape(-1, 3)[:, [_AXIS[a] for a in order]]
    xyzw = Rotation.from_euler(order.lower(), flat, degrees=True).as_quat()
    q = xyzw[:, [3, 0, 1, 2]]
    q *= np.where(q[:, :1] < 0, -1.0, 1.0)
    return q.reshape(shape + (4,))


def quat_to_euler(q, order="XYZ", scalar_first=True):
    """Euler angles (..., 3; degrees, each in [-180, 180]) of quaternions (..., 4) in rotation
    ``order``: scipy's ``Rotation.from_quat(q).as_euler(order.lower(), degrees=True)``, bit for
    bit (tested), put in ``(x, y, z)`` columns. ``scalar_first=False``: ``q`` is ``x y z w``."""
    order = check_order(order)
    q = np.asarray(q, dtype=float)
    out = np.empty(q.shape[:-1] + (3,))
    i, j, k = (_AXIS[a] for a in order)
    _euler(q.reshape(-1, 4), 1 if scalar_first else 0, 0 if scalar_first else 3, i, j, k,
           out.reshape(-1, 3))  # fmt: skip
    return out


def euler_kernel(order="XYZ", scalar_first=True) -> np.ndarray:
    """What :func:`euler_into` needs to do :func:`quat_to_euler` in compiled code: int64 (5,),
    the vector part's first column, the scalar's and the order's axes."""
    i, j, k = (_AXIS[a] for a in check_order(order))
    return np.array([1 if scalar_first else 0, 0 if scalar_first else 3, i, j, k], np.int64)


@numba.njit(cache=True)
def euler_into(q, kernel, out):  # pragma: no cover - compiled
    """:func:`quat_to_euler` of quaternions ``q`` (n, 4) into ``out`` (n, 3), from compiled
    code; ``kernel``: :func:`euler_kernel` of the order."""
    _euler(q, kernel[0], kernel[1], kernel[2], kernel[3], kernel[4], out)


@numba.njit(cache=True)
def _euler(q, x, w, i, j, k, out):  # pragma: no cover - compiled
    """scipy's ``as_euler`` (Bernardes & Viollet 2022) of the extrinsic Tait-Bryan sequence
    ``i j k`` (axis indices), its operations in its order: ``q[:, x:x+3]`` the vector part,
    ``q[:, w]`` the scalar; the angles (degrees) into ``out``'s columns ``i, j, k``. A second
    angle within 1e-7 of 0 or pi (gimbal lock) sets the third to 0, as scipy does."""
    sign = (i - j) * (j - k) * (k - i) // 2
    for n in range(q.shape[0]):
        v = (q[n, x], q[n, x + 1], q[n, x + 2])
        s = q[n, w]
        norm = math.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2] + s * s)
        qi, qj, qk, qs = v[i] / norm, v[j] / norm, v[k] / norm, s / norm
        a = qs - qj
        b = qi + qk * sign
        c = qj + qs
        d = qk * sign - qi
        second = 2 * math.atan2(math.hypot(c, d), math.hypot(a, b))
        half_sum = math.atan2(b, a)
        half_diff = math.atan2(d, c)
        if abs(second) <= 1e-7:
            first, third = 2 * half_sum, 0.0
        elif abs(second - math.pi) <= 1e-7:
            first, third = -2 * half_diff, 0.0
        else:
            first, third = half_sum - half_diff, half_sum + half_diff
        angles = (first, second - math.pi / 2, third * sign)
        for m, axis in enumerate((i, j, k)):
            e = angles[m]
            if e < -math.pi:
                e += 2 * math.pi
            elif e > math.pi:
                e -= 2 * math.pi
            out[n, axis] = e * (180.0 / math.pi)


def unwrap_degrees(angles, axis=0):
    """Unwrap angles in degrees along ``axis`` (no jump larger than 180 degrees)."""
    return np.rad2deg(np.unwrap(np.deg2rad(np.asarray(angles, dtype=float)), axis=axis))


class UnwrapDegrees:
    """:func:`unwrap_degrees` along time, one frame at a time: called with ``a[0], a[1], ...``
    it returns ``unwrap_degrees(a, axis=0)[k]`` bit for bit (numpy.unwrap's operations)."""

    _PERIOD = 2 * np.pi

    def __init__(self):
        self._p = None
        self._acc = None

    def __call__(self, angles) -> np.ndarray:
        """The unwrapped angles (degrees) of the next frame, same shape as ``angles``."""
        a = np.asarray(angles, dtype=float)
        if self._p is not None and a.ndim == 2 and a.shape == self._p.shape:
            # no correction anywhere (numpy.unwrap's adds 0): one compiled call
            p, out = np.empty_like(a), np.empty_like(a)
            acc = self._acc
            if _unwrap_step(a, self._p, p if acc is None else acc, acc is not None, p, out):
                self._p = p
                return out
        p = np.deg2rad(a)
        if self._p is None:
            up = p.copy()
        else:
            period = self._PERIOD
            high = period / 2
            dd = p - self._p
            if np.abs(dd).max() < high:  # no correction anywhere (numpy.unwrap's adds 0)
                self._p = p
                up = p if self._acc is None else p + self._acc
                return np.rad2deg(up)
            ddmod = np.mod(dd - (-high), period) + (-high)
            np.copyto(ddmod, high, where=(ddmod == -high) & (dd > 0))
            corr = ddmod - dd
            np.copyto(corr, 0, where=np.abs(dd) < high)
            self._acc = corr if self._acc is None else self._acc + corr
            up = p + self._acc
        self._p = p
        return np.rad2deg(up)


@numba.njit(cache=True)
def _unwrap_step(a, prev, acc, has_acc, p, out):  # pragma: no cover - compiled
    """:class:`UnwrapDegrees`'s step when no angle moved by pi or more (NaN: it may have):
    ``p = deg2rad(a)``, ``out = rad2deg(p + acc)`` (``p`` without ``has_acc``), as NumPy's
    ufuncs compute them; False (``p``, ``out`` half written) otherwise."""
    for i in range(a.shape[0]):
        for c in range(a.shape[1]):
            p[i, c] = a[i, c] * (math.pi / 180.0)
            if not abs(p[i, c] - prev[i, c]) < math.pi:
                return False
    for i in range(a.shape[0]):
        for c in range(a.shape[1]):
            up = p[i, c] + acc[i, c] if has_acc else p[i, c]
            out[i, c] = up * (180.0 / math.pi)
    return True


def quat_normalize(q):
    """Normalise quaternions to unit length; shape (..., 4) in, same out."""
    q = np.asarray(q, dtype=float)
    return q / np.linalg.norm(q, axis=-1, keepdims=True)


def quat_mul(a, b):
    """Hamilton product ``a * b`` of quaternions of shape (..., 4) (broadcasting)."""
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    aw, ax, ay, az = np.moveaxis(a, -1, 0)
    bw, bx, by, bz = np.moveaxis(b, -1, 0)
    return np.stack(
        [
            aw * bw - ax * bx - ay * by - az * bz,
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
        ],
        axis=-1,
    )


def quat_conj(q):
    """Conjugate (= inverse for unit quaternions), shape (..., 4)."""
    q = np.asarray(q, dtype=float)
    return q * np.array([1.0, -1.0, -1.0, -1.0])


def quat_rotate(q, v):
    """Rotate vectors ``v`` (..., 3) by unit quaternions ``q`` (..., 4)."""
    q = np.asarray(q, dtype=float)
    v = np.asarray(v, dtype=float)
    w = q[..., :1]
    u = q[..., 1:]
    t = 2.0 * np.cross(u, v)
    return v + w * t + np.cross(u, t)


def quat_to_matrix(q):
    """Rotation matrices of shape (..., 3, 3) for quaternions (..., 4)."""
    q = quat_normalize(q)
    w, x, y, z = np.moveaxis(q, -1, 0)
    return np.stack(
        [
            np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
            np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
            np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1),
        ],
        axis=-2,
    )


def quat_slerp(q0, q1, t):
    """Spherical linear interpolation from ``q0`` to ``q1`` (..., 4) at ``t``, shortest arc."""
    q0 = quat_normalize(q0)
    q1 = quat_normalize(q1)
    t = np.asarray(t, dtype=float)[..., None]
    dot = np.sum(q0 * q1, axis=-1, keepdims=True)
    q1 = np.where(dot < 0, -q1, q1)
    dot = np.abs(dot)
    theta = np.arccos(np.clip(dot, -1.0, 1.0))
    sin_theta = np.sin(theta)
    small = sin_theta < 1e-9
    safe = np.where(small, 1.0, sin_theta)
    w0 = np.where(small, 1.0 - t, np.sin((1.0 - t) * theta) / safe)
    w1 = np.where(small, t, np.sin(t * theta) / safe)
    return quat_normalize(w0 * q0 + w1 * q1)


def geodesic_angle(a, b):
    """Rotation angle in [0, pi] between unit quaternions, ``2 arccos |a . b|`` (eq. 1 / pi)."""
    d = np.abs(np.sum(quat_normalize(a) * quat_normalize(b), axis=-1))
    return 2.0 * np.arccos(np.clip(d, 0.0, 1.0))
