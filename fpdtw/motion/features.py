"""Per-frame features the aligners consume.

An aligner never sees a :class:`~fpdtw.motion.Motion` frame by frame; it sees
:class:`Frame` records cut from a :class:`MotionFeatures`: the 8 paper joints'
local rotations (quaternions, for eq. 1), their Euler angles unwrapped over time
(for dead reckoning), and optionally joint positions (for the OPW poster's eq. 5).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fpdtw.motion.joints import OPW_JOINTS, PAPER_JOINTS
from fpdtw.motion.rotations import unwrap_degrees


@dataclass(frozen=True)
class Frame:
    """One frame of a motion as an online aligner receives it.

    Attributes
    ----------
    quats : ndarray of float, shape (k, 4)
        Local rotations of the k cost joints, unit quaternions (w, x, y, z).
    euler : ndarray of float, shape (k, 3)
        The same rotations as Euler angles in degrees (x, y, z), unwrapped over
        the frames received so far.
    positions : ndarray of float, shape (p, 3) or None
        Root-relative joint positions (OPW only).
    """

    quats: np.ndarray
    euler: np.ndarray
    positions: np.ndarray | None = None


@dataclass(frozen=True)
class MotionFeatures:
    """Feature arrays of a whole motion.

    Attributes
    ----------
    quats : ndarray of float64, shape (F, k, 4)
        C-contiguous unit quaternions of the k cost joints.
    euler : ndarray of float64, shape (F, k, 3)
        Euler angles in degrees, unwrapped along time.
    orders : tuple of str, length k
        Rotation order of each joint (needed to turn forecast Euler angles back
        into quaternions).
    fps : float
        Frame rate in Hz.
    positions : ndarray of float64, shape (F, p, 3) or None
        Root-relative positions of the position joints (OPW's 16 by default).
    name : str
        Motion name.
    """

    quats: np.ndarray
    euler: np.ndarray
    orders: tuple
    fps: float
    positions: np.ndarray | None = None
    name: str = ""

    @classmethod
    def from_motion(cls, motion, joints=PAPER_JOINTS, position_joints=None):
        """Cut the features out of a :class:`~fpdtw.motion.Motion`.

        Parameters
        ----------
        motion : Motion
        joints : sequence of str
            Cost joints (canonical names), default the paper's 8.
        position_joints : sequence of str or None
            Joints whose root-relative positions to include (e.g.
            :data:`fpdtw.motion.joints.OPW_JOINTS`); None skips forward kinematics.
        """
        quats = np.ascontiguousarray(motion.rotations(joints), dtype=np.float64)
        euler = np.ascontiguousarray(unwrap_degrees(motion.eulers(joints), axis=0))
        pos = None
        if position_joints is not None:
            pos = np.ascontiguousarray(motion.positions(position_joints, root_relative=True))
        return cls(quats, euler, motion.rotation_orders(joints), motion.fps, pos, motion.name)

    @classmethod
    def from_arrays(cls, quats, euler=None, orders=None, fps=120.0, positions=None, name=""):
        """Build features from raw arrays (tests, synthetic data).

        ``euler`` defaults to the quaternions converted with ``orders``
        (default ``"XYZ"`` for every joint).
        """
        from fpdtw.motion.rotations import quat_normalize, quat_to_euler

        quats = np.ascontiguousarray(quat_normalize(np.asarray(quats, dtype=np.float64)))
        k = quats.shape[1]
        orders = tuple(orders) if orders is not None else ("XYZ",) * k
        if euler is None:
            euler = np.stack([quat_to_euler(quats[:, j], orders[j]) for j in range(k)], axis=1)
        euler = np.ascontiguousarray(unwrap_degrees(euler, axis=0))
        return cls(quats, euler, orders, float(fps), positions, name)

    def __len__(self):
        return self.quats.shape[0]

    @property
    def n_frames(self) -> int:
        return self.quats.shape[0]

    def frame(self, i: int) -> Frame:
        """Frame ``i`` as an aligner receives it."""
        pos = None if self.positions is None else self.positions[i]
        return Frame(self.quats[i], self.euler[i], pos)

    def frames(self):
        """Iterate over the frames in order (a simulated live stream)."""
        for i in range(self.n_frames):
            yield self.frame(i)

    def slice(self, a: int, b: int) -> MotionFeatures:
        """Frames ``a`` to ``b - 1``."""
        pos = None if self.positions is None else self.positions[a:b]
        return MotionFeatures(
            self.quats[a:b].copy(), self.euler[a:b].copy(), self.orders, self.fps, pos, self.name
        )


__all__ = ["Frame", "MotionFeatures", "OPW_JOINTS", "PAPER_JOINTS"]
