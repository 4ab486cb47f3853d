"""One frame at a time, compiled (a Motion's scipy and NumPy calls take tens of microseconds).

The kernels do one frame operation for operation as their twins (no fused multiply-add), so
bit for bit (tested): :func:`frame_quats` as :func:`fpdtw.motion.motion.joint_quats`,
:func:`frame_positions` as :meth:`~fpdtw.motion.Motion.forward_kinematics`.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from fpdtw.motion.rotations import ORDERS, check_order

#: ``ORDER_AXES[code]``: the axes (0 = X, 1 = Y, 2 = Z) of ``ORDERS[code]`` in the order applied.
ORDER_AXES = np.array([["XYZ".index(a) for a in o] for o in ORDERS], dtype=np.int64)
_RAD_PER_DEG = math.pi / 180.0


@numba.njit(cache=True, fastmath=False)
def frame_quats_into(E, codes, axes, out):  # pragma: no cover - compiled
    """:func:`frame_quats` from compiled code: ``out[j]`` (J, 4) the unit quaternion
    (``w >= 0``) of ``E[j]`` (J, 3; degrees) in order ``codes[j]``, as scipy does; ``axes``:
    :data:`ORDER_AXES`.

    Plain version: fpdtw.plain.euler_to_quat (which leaves the sign as it comes).
    """
    for j in range(E.shape[0]):
        rw, rx, ry, rz = 1.0, 0.0, 0.0, 0.0
        for k in range(3):
            a = axes[codes[j], k]
            h = E[j, a] * _RAD_PER_DEG / 2.0
            s, c = math.sin(h), math.cos(h)
            px = s if a == 0 else 0.0
            py = s if a == 1 else 0.0
            pz = s if a == 2 else 0.0
            if k == 0:
                rw, rx, ry, rz = c, px, py, pz
                continue
            cx = py * rz - pz * ry
            cy = pz * rx - px * rz
            cz = px * ry - py * rx
            rw, rx, ry, rz = (
                c * rw - px * rx - py * ry - pz * rz,
                c * rx + rw * px + cx,
                c * ry + rw * py + cy,
                c * rz + rw * pz + cz,
            )
        sign = -1.0 if rw < 0 else 1.0
        out[j, 0], out[j, 1], out[j, 2], out[j, 3] = rw * sign, rx * sign, ry * sign, rz * sign


def order_codes(orders) -> np.ndarray:
    """Indices into :data:`fpdtw.motion.rotations.ORDERS`, int64 (k,), of rotation orders.

    ValueError for another order."""
    return np.array([ORDERS.index(check_order(o)) for o in orders], dtype=np.int64)


def frame_quats(euler, codes) -> np.ndarray:
    """Local rotations (J, 4), ``w >= 0``, of one frame's Euler angles ``euler`` (J, 3).

    ``codes``: :func:`order_codes` of the joints' orders."""
    E = np.ascontiguousarray(euler, dtype=np.float64)
    out = np.empty((E.shape[0], 4))
    frame_quats_into(E, codes, ORDER_AXES, out)
    return out


@numba.njit(cache=True, fastmath=False, inline="always")
def _mul(aw, ax, ay, az, bw, bx, by, bz):
    """Hamilton product, term for term as :func:`fpdtw.motion.rotations.quat_mul`.

    Plain version: fpdtw.plain.quat_multiply.
    """
    return (
        aw * bw - ax * bx - ay * by - az * bz,
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
    )


@numba.njit(cache=True, fastmath=False, inline="always")
def _cross(a0, a1, a2, b0, b1, b2):
    """Cross product, term for term as ``numpy.cross``."""
    return a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0


@numba.njit(cache=True, fastmath=False)
def _frame_positions(quats, pre, post, offsets, parents, root, pos, rot):
    """Global positions ``pos`` (J, 3) of one frame; ``rot`` (J, 4) scratch.

    Plain version: fpdtw.plain.forward_kinematics.
    """
    for j in range(quats.shape[0]):
        q = quats[j]
        a = _mul(pre[j, 0], pre[j, 1], pre[j, 2], pre[j, 3], q[0], q[1], q[2], q[3])
        w, x, y, z = _mul(a[0], a[1], a[2], a[3], post[j, 0], post[j, 1], post[j, 2], post[j, 3])
        p = parents[j]
        if p < 0:
            for c in range(3):
                pos[j, c] = offsets[j, c] + root[c]
            rot[j, 0], rot[j, 1], rot[j, 2], rot[j, 3] = w, x, y, z
            continue
        rw, rx, ry, rz = rot[p, 0], rot[p, 1], rot[p, 2], rot[p, 3]
        v0, v1, v2 = offsets[j, 0], offsets[j, 1], offsets[j, 2]
        c0, c1, c2 = _cross(rx, ry, rz, v0, v1, v2)
        t0, t1, t2 = 2.0 * c0, 2.0 * c1, 2.0 * c2
        d0, d1, d2 = _cross(rx, ry, rz, t0, t1, t2)
        pos[j, 0] = pos[p, 0] + (v0 + rw * t0 + d0)
        pos[j, 1] = pos[p, 1] + (v1 + rw * t1 + d1)
        pos[j, 2] = pos[p, 2] + (v2 + rw * t2 + d2)
        rot[j, 0], rot[j, 1], rot[j, 2], rot[j, 3] = _mul(rw, rx, ry, rz, w, x, y, z)


def frame_positions(skeleton, quats, root_translation, joints=None, root_relative=True):
    """Joint positions (len(joints), 3) of one frame, by forward kinematics.

    From its local rotations ``quats`` (J, 4) and ``root_translation`` (3,); ``joints``:
    skeleton indices (default all). Bit for bit ``Motion.positions(joints, root_relative)``.

    Paper: OPW poster eq. 5 (poses compared by root-relative joint positions).
    """
    sk = skeleton
    J = sk.n_joints
    pos = np.empty((J, 3))
    rot = np.empty((J, 4))
    _frame_positions(
        np.ascontiguousarray(quats, dtype=np.float64),
        sk.pre_rotations,
        sk.post_rotations,
        sk.offsets,
        sk.parents,
        np.ascontiguousarray(root_translation, dtype=np.float64),
        pos,
        rot,
    )
    out = pos if joints is None else pos[np.asarray(joints)]
    return out - pos[0] if root_relative else out
