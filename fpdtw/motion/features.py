"""The features aligners consume: a whole motion's (:class:`MotionFeatures`), a frame's."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from fpdtw.motion.joints import PAPER_JOINTS
from fpdtw.motion.rig import RigTransform, position_scale, rig_transform
from fpdtw.motion.rig import body_size as _body_size
from fpdtw.motion.rotations import quat_normalize, quat_to_euler, unwrap_degrees


@dataclass(frozen=True)
class Frame:
    """One frame of a motion as an online aligner receives it.

    ``quats`` (k, 4) of the k cost joints; ``euler`` (k, 3) the same in degrees, unwrapped
    over the frames so far; ``positions`` (p, 3) root-relative (OPW) or None; ``orders`` and
    ``rig`` (None: the input motion's; a take's frames share those of its first)."""

    quats: np.ndarray
    euler: np.ndarray
    positions: np.ndarray | None = None
    orders: tuple | None = None
    rig: RigTransform | None = None


@dataclass(frozen=True)
class MotionFeatures:
    """Feature arrays of a whole motion.

    ``quats`` (F, k, 4) and ``euler`` (F, k, 3; degrees, unwrapped) of the k cost joints, their
    ``orders`` (for the forecasts), ``fps``, root-relative ``positions`` (F, p, 3) or None,
    ``name``, ``rig`` (:func:`fpdtw.motion.rig.rig_transform`; None: unknown, taken to be the
    other's) and ``body_size`` (:func:`fpdtw.motion.rig.body_size`; None without positions)."""

    quats: np.ndarray
    euler: np.ndarray
    orders: tuple
    fps: float
    positions: np.ndarray | None = None
    name: str = ""
    rig: RigTransform | None = None
    body_size: float | None = None

    @classmethod
    def from_motion(
        cls, motion, joints=PAPER_JOINTS, position_joints=None, *, rest_frame=None, rig=None
    ):
        """Cut the features out of a :class:`~fpdtw.motion.Motion`.

        ``joints``: the cost joints (default the paper's 8); ``position_joints``: whose
        root-relative positions to include (None: no forward kinematics); ``rig``: default
        computed, from ``rest_frame`` if given."""
        quats = np.ascontiguousarray(motion.rotations(joints), dtype=np.float64)
        euler = np.ascontiguousarray(unwrap_degrees(motion.eulers(joints), axis=0))
        if rig is None:
            rig = rig_transform(motion, joints, rest_frame)
        pos = size = None
        if position_joints is not None:
            pos = np.ascontiguousarray(motion.positions(position_joints, root_relative=True))
            size = _body_size(motion)
        orders = motion.rotation_orders(joints)
        return cls(quats, euler, orders, motion.fps, pos, motion.name, rig, size)

    def scaled_positions(self, scale: float) -> MotionFeatures:
        """These features with positions and body size times ``scale`` (self when 1)."""
        if scale == 1.0 or self.positions is None:
            return self
        size = None if self.body_size is None else self.body_size * float(scale)
        return dataclasses.replace(self, positions=self.positions * float(scale), body_size=size)

    @classmethod
    def from_arrays(
        cls, quats, euler=None, orders=None, fps=120.0, positions=None, name="", rig=None
    ):
        """Features from raw arrays (tests, synthetic data).

        ``euler`` defaults to the quaternions in ``orders`` (default ``"XYZ"``); ``rig`` to None."""
        quats = np.ascontiguousarray(quat_normalize(np.asarray(quats, dtype=np.float64)))
        k = quats.shape[1]
        orders = tuple(orders) if orders is not None else ("XYZ",) * k
        if euler is None:
            euler = np.stack([quat_to_euler(quats[:, j], orders[j]) for j in range(k)], axis=1)
        euler = np.ascontiguousarray(unwrap_degrees(euler, axis=0))
        return cls(quats, euler, orders, float(fps), positions, name, rig)

    def __len__(self):
        return self.quats.shape[0]

    @property
    def n_frames(self) -> int:
        return self.quats.shape[0]

    def frame(self, i: int) -> Frame:
        """Frame ``i`` as an aligner receives it."""
        pos = None if self.positions is None else self.positions[i]
        return Frame(self.quats[i], self.euler[i], pos, self.orders, self.rig)

    def frames(self):
        """Iterate over the frames in order (a simulated live stream)."""
        for i in range(self.n_frames):
            yield self.frame(i)

    def slice(self, a: int, b: int) -> MotionFeatures:
        """Frames ``a`` to ``b - 1``."""
        pos = None if self.positions is None else self.positions[a:b]
        return dataclasses.replace(
            self, quats=self.quats[a:b].copy(), euler=self.euler[a:b].copy(), positions=pos
        )


def pair_features(
    input_motion,
    target_motion,
    joints=PAPER_JOINTS,
    position_joints=None,
    *,
    rest_frames=(None, None),
    rigs=(None, None),
    positions: str = "auto",
) -> tuple:
    """The features of an (input, target) pair, ready to align whatever their rigs.

    With positions, the target's are turned into the input's world (their rigs' body axes)
    and rescaled by :func:`fpdtw.motion.rig.position_scale`
    (rule ``positions``: "auto", "raw" or "body-size"). ``rest_frames`` and ``rigs`` (one
    per motion) are passed to :meth:`MotionFeatures.from_motion`. Returns ``(I, T)``.

    Paper: FP-DTW eq. 1 (local rotations, made comparable across rigs); OPW poster eq. 5.
    """
    I, T = (
        MotionFeatures.from_motion(mo, joints, position_joints, rest_frame=rest, rig=rig)
        for mo, rest, rig in zip((input_motion, target_motion), rest_frames, rigs)
    )
    if position_joints is not None:
        if I.rig is not None and T.rig is not None and not np.array_equal(I.rig.axes, T.rig.axes):
            T = dataclasses.replace(T, positions=T.rig.positions_in(T.positions, I.rig))
        T = T.scaled_positions(position_scale(I.body_size, T.body_size, positions))
    return I, T
