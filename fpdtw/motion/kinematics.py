"""Forward kinematics of one frame, compiled: the joint positions of a streamed frame.

:meth:`fpdtw.motion.Motion.forward_kinematics` computes every frame of a motion at once
with NumPy, one joint after another; on a single frame its per-call overhead (tens of
microseconds per joint) would make a frame of a 33-joint skeleton take milliseconds.
:func:`frame_positions` computes the same positions for one frame in a compiled loop,
operation for operation as the NumPy code (the same products and sums in the same order,
no fused multiply-add), so that it returns the same numbers bit for bit; its NumPy twin,
which the tests hold it equal to, is :meth:`~fpdtw.motion.Motion.forward_kinematics`.
"""

from __future__ import annotations

import numba
import numpy as np


@numba.njit(cache=True, fastmath=False, inline="always")
def _mul(aw, ax, ay, az, bw, bx, by, bz):
    """Hamilton product, term for term as :func:`fpdtw.motion.rotations.quat_mul`."""
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
    """Global positions ``pos`` (J, 3) of one frame; ``rot`` (J, 4) scratch."""
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
    """Joint positions of one frame by forward kinematics.

    The same numbers, bit for bit, as
    ``Motion.positions(joints, root_relative)`` gives for that frame of a motion.

    Parameters
    ----------
    skeleton : Skeleton
    quats : ndarray of float64, shape (J, 4)
        Local rotations of the frame, unit quaternions ``(w, x, y, z)``.
    root_translation : ndarray of float64, shape (3,)
    joints : ndarray of int, optional
        Skeleton indices of the joints to return (default: all).
    root_relative : bool
        Subtract the root's position.

    Returns
    -------
    positions : ndarray of float64, shape (len(joints), 3)

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


__all__ = ["frame_positions"]
