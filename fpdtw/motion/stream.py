"""A motion that arrives one frame at a time: the live target of an online alignment.

:class:`LiveTarget` turns captured frames, as they arrive, into frames at the INPUT's rate
("ticks"), causally; docs/live.md gives the rules for dropped frames (gaps) and other capture
rates, both measured. A take streamed without loss gives the frames and map of ``fpdtw
align`` bit for bit (but a tick just after a received frame at another rate, whose root
translation moves by at most 1e-6 of a frame offline).
"""

from __future__ import annotations

import math

import numba
import numpy as np

from fpdtw import limits
from fpdtw.errors import MotionFormatError
from fpdtw.motion.features import Frame
from fpdtw.motion.joints import OPW_JOINTS, PAPER_JOINTS
from fpdtw.motion.kinematics import (
    ORDER_AXES,
    frame_positions,
    frame_quats,
    frame_quats_into,
    order_codes,
)
from fpdtw.motion.motion import EXACT_FRAMES, blend_poses, sample_points
from fpdtw.motion.rig import FRAME_JOINTS, position_scale, skeleton_body_size, skeleton_rig
from fpdtw.motion.rotations import UnwrapDegrees

#: A frame more than this many frame periods after the previous one ends a gap.
GAP_PERIODS = 1.5
#: Rules for the ticks inside a gap; the first is the default.
GAP_RULES = ("slerp", "hold")


def split_channels(values, rot, trans, n_joints: int):
    """Euler angles (..., J, 3) and root translation (..., 3) of motion lines' ``values``
    (..., n_channels): the rotation channels ``rot`` (n, 3) (column, joint, axis) and root
    translation channels ``trans`` (m, 2) (column, axis); 0 where a joint has no channel.
    :func:`_receive` in NumPy (its general path)."""
    values = np.asarray(values)
    euler = np.zeros((*values.shape[:-1], n_joints, 3))
    r = np.zeros((*values.shape[:-1], 3))
    euler[..., rot[:, 1], rot[:, 2]] = values[..., rot[:, 0]]
    r[..., trans[:, 1]] = values[..., trans[:, 0]]
    return euler, r


@numba.njit(cache=True)
def _receive(values, rot, trans, big, row_of, codes, axes, e, q, r):  # pragma: no cover
    """Whether every rotation and root translation value of a motion line's ``values``
    (n_channels,) is within ``big`` (NaN: not); if so, the Euler angles of the joints kept
    into ``e`` (row ``row_of[j]`` for joint ``j``, -1: not kept; 0 without channels), their
    quaternions (:func:`~fpdtw.motion.kinematics.frame_quats`) into ``q`` and the root
    translation into ``r``. ``rot`` (n, 3): column, joint, axis of each rotation channel;
    ``trans`` (m, 2): column, axis of each translation channel of the root."""
    for i in range(rot.shape[0]):
        if not abs(values[rot[i, 0]]) <= big:
            return False
    for i in range(trans.shape[0]):
        if not abs(values[trans[i, 0]]) <= big:
            return False
    e[:] = 0.0
    r[:] = 0.0
    for i in range(rot.shape[0]):
        n = row_of[rot[i, 1]]
        if n >= 0:
            e[n, rot[i, 2]] = values[rot[i, 0]]
    for i in range(trans.shape[0]):
        r[trans[i, 1]] = values[trans[i, 0]]
    frame_quats_into(e, codes, axes, q)
    return True


class LiveTarget:
    """The target motion of a live alignment, built from frames as they arrive.

    ``skeleton``: the streamed one (the features come from it); ``fps``: its frame rate;
    ``rate``: ticks per second, the input's rate; ``joint_map``: canonical -> its names;
    ``joints``: cost joints; ``position_joints``: whose root-relative positions the frames
    carry (OPW), rescaled by :func:`fpdtw.motion.rig.position_scale` of ``input_body_size``
    and the skeleton's and turned into the world of body axes ``input_axes`` (3, 3); ``up``,
    ``facing``: :func:`fpdtw.motion.rig.world_axes` overrides; ``gap``: "slerp" or "hold";
    ``where``: what errors name (None: a stream). MotionFormatError for a joint the skeleton
    lacks or an implausible offset."""

    def __init__(
        self,
        skeleton,
        fps: float,
        rate: float,
        *,
        joint_map=None,
        joints=PAPER_JOINTS,
        position_joints=None,
        gap: str = "slerp",
        input_body_size=None,
        input_axes=None,
        up=None,
        facing=None,
        where=None,
    ):
        if gap not in GAP_RULES:
            raise ValueError(f"gap must be one of {GAP_RULES}, got {gap!r}")
        self.skeleton, self.fps, self.rate = skeleton, float(fps), float(rate)
        self.gap, self.where = gap, where
        self.same_rate = abs(self.fps - self.rate) <= 1e-9 * max(self.fps, self.rate)
        jm = joint_map or {}
        cost = self._indices(joints, jm, "the 8 joints FP-DTW compares")
        self._pos_joints = None
        #: The streamed body's size in its units (None without positions).
        self.body_size = None
        #: The factor applied to the positions (1 unless the bodies' units differ).
        self.position_scale = 1.0
        if position_joints is not None:
            what = "the 16 OPW joints" if tuple(position_joints) == OPW_JOINTS else "joints"
            self._pos_joints = self._indices(position_joints, jm, what)
            ends = self._indices(("head", "left_ankle", "right_ankle"), jm, "a body's size")
            self.body_size = skeleton_body_size(skeleton, *ends)
            self.position_scale = position_scale(input_body_size, self.body_size)
        # the joints whose rotations a frame keeps (all of them for forward kinematics),
        # and the rows of the cost joints among them
        if self._pos_joints is None:
            self._need, self._cost = cost, np.arange(len(cost))
        else:
            self._need, self._cost = np.arange(skeleton.n_joints), cost
        self._row_of = np.full(skeleton.n_joints, -1, dtype=np.int64)  # joint -> row kept
        self._row_of[self._need] = np.arange(self._need.size)
        J = skeleton.n_joints  # push's channels: the root translation, then (J, 3) rotations
        self._plain = (
            np.stack([3 + np.arange(3 * J), np.arange(3 * J) // 3, np.arange(3 * J) % 3], axis=1),
            np.stack([np.arange(3)] * 2, 1),
        )
        self._orders = tuple(skeleton.rotation_orders[j] for j in self._need)
        self._codes = order_codes(self._orders)
        #: Rotation order of each cost joint (the streamed skeleton's).
        self.orders = tuple(skeleton.rotation_orders[j] for j in cost)
        #: The cost joints' :class:`~fpdtw.motion.rig.RigTransform` (rest: zero rotations).
        try:
            ends = self._indices(FRAME_JOINTS, jm, "")
        except MotionFormatError:
            ends = None
        self.rig = skeleton_rig(skeleton, cost, None, ends, up, facing)
        self._turn = None  # positions into the input's world, if its axes differ
        if input_axes is not None and not np.array_equal(input_axes, self.rig.axes):
            self._turn = (np.asarray(input_axes).T @ self.rig.axes).T
        # the limits of a take are those in force when it starts
        self._big = float(limits.get("max_abs_value"))
        self._max_gap = float(limits.get("max_gap_s"))
        self._max_ticks = int(limits.get("max_frames"))
        self._check_values(skeleton.offsets, "joint offset", None, None)
        self._unwrap = UnwrapDegrees()
        self._prev = None  # (slot, q, e, r) of the previous frame received
        self._cur = None
        self._last_t = None
        self.n_received = 0
        self.n_ticks = 0
        self.n_filled = 0
        self.n_lost = 0

    def _indices(self, names, joint_map, what):
        idx = []
        for name in names:
            own = joint_map.get(name, name)
            if own not in self.skeleton.joint_names:
                raise MotionFormatError(
                    self.where,
                    f"the skeleton has no joint for {name!r} (one of {what}); the input and "
                    "the streamed take must share these joints",
                )
            idx.append(self.skeleton.joint_names.index(own))
        return np.asarray(idx, dtype=np.int64)

    def _check_values(self, values, what, line, frame):
        over = np.abs(values) > self._big
        if over.any():
            v = np.asarray(values)[over][0]
            raise MotionFormatError(
                self.where,
                f"implausible {what} {v:g} (larger in magnitude than {self._big:g}, "
                f"{limits.env_name('max_abs_value')})",
                line=line,
                frame=frame,
            )

    def _slot(self, t, line, frame, arrival) -> int:
        if self._cur is None:
            return 0
        dt = t - self._last_t
        if arrival and dt <= 0:  # arrived together (or a clock step back): consecutive
            return self._cur[0] + 1
        if not dt > 0:
            raise MotionFormatError(
                self.where,
                f"time t={t!r} s is not after the previous frame's t={self._last_t!r} s",
                line=line,
                frame=frame,
            )
        max_gap = self._max_gap
        if dt > max_gap:
            raise MotionFormatError(
                self.where,
                f"{dt:.3f} s since the previous frame, more than the limit of {max_gap:g} s "
                f"({limits.env_name('max_gap_s')}): a new take, not a dropped frame",
                line=line,
                frame=frame,
            )
        periods = dt * self.fps
        step = round(periods) if periods > GAP_PERIODS else 1
        return self._cur[0] + max(step, 1)

    def push(
        self, euler, root_translation, t: float, *, arrival=False, line=None, frame=None
    ) -> list:
        """Receive the next frame; return the ticks it completes, ``[(tick, Frame, filled)]``.

        ``euler`` (J, 3): local Euler angles in degrees; ``root_translation`` (3,); ``t``: its
        capture time, or with ``arrival`` its arrival time (frames that arrived together are
        consecutive); ``line``, ``frame``: named in errors. MotionFormatError for a value beyond
        :data:`fpdtw.limits.MAX_ABS_VALUE`, a time not after the previous, a gap beyond
        :data:`fpdtw.limits.MAX_GAP_S`, or too many ticks."""
        J = self.skeleton.n_joints
        euler = np.asarray(euler, dtype=float).reshape(J * 3)
        r = np.asarray(root_translation, dtype=float).reshape(3)
        return self.push_channels(np.concatenate([r, euler]), *self._plain, t, arrival=arrival,
                                  line=line, frame=frame)  # fmt: skip

    def push_channels(
        self, values, rot, trans, t: float, *, arrival=False, line=None, frame=None
    ) -> list:
        """:meth:`push` of a motion line's ``values`` (n_channels,) float64: its rotation
        channels ``rot`` (n, 3) int64 (column, joint, axis) and root translation channels
        ``trans`` (m, 2) int64 (column, axis), :attr:`fpdtw.io.bvh.BVHHeader.channel_map`
        (one compiled call when every value is within the limit)."""
        t = float(t)
        if not math.isfinite(t):
            raise MotionFormatError(self.where, f"time {t!r} is not finite", line=line, frame=frame)
        n = self._need.size
        e, q, r = np.empty((n, 3)), np.empty((n, 4)), np.empty(3)
        if not _receive(values, rot, trans, self._big, self._row_of, self._codes, ORDER_AXES,
                        e, q, r):  # fmt: skip
            euler, r = split_channels(values, rot, trans, self.skeleton.n_joints)
            self._check_values(euler, "rotation value", line, frame)
            self._check_values(r, "translation value", line, frame)
            e = euler[self._need]  # NaN: on to the aligner, which names it
            q = frame_quats(e, self._codes)
        slot = self._slot(t, line, frame, arrival)
        self._prev, self._cur = self._cur, (slot, q, e, r)
        if self._prev is not None:
            self.n_lost += slot - self._prev[0] - 1
        self._last_t = t
        self.n_received += 1
        due = self._due(slot)
        limit = self._max_ticks
        if self.n_ticks + len(due) > limit:
            raise MotionFormatError(
                self.where,
                f"the take reaches {self.n_ticks + len(due)} frames, more than the limit of "
                f"{limit} frames ({limits.env_name('max_frames')})",
                line=line,
                frame=frame,
            )
        out = [self._tick(k, x) for k, x in due]
        self.n_ticks += len(out)
        return out

    def _due(self, slot: int) -> list:
        """(tick, x) of the ticks complete once slot ``slot`` has arrived, in order."""
        out = []
        k = self.n_ticks
        while True:
            x = float(k) if self.same_rate else (k / self.rate) * self.fps  # tick k, in slots
            if self.same_rate:
                ok = k <= slot
            else:
                i0, _, a = (float(v[0]) for v in sample_points(np.array([x]), 2**62))
                exact = abs(x - round(x)) < EXACT_FRAMES
                ok = (exact and round(x) <= slot) or i0 + 1 <= slot or (a == 0 and i0 <= slot)
            if not ok:
                return out
            out.append((k, x))
            k += 1

    def _frame_at(self, s):
        for f in (self._cur, self._prev):
            if f is not None and f[0] == s:
                return f
        return None

    def _tick(self, k: int, x: float):
        """Tick ``k`` at ``x`` slots: (k, Frame, filled)."""
        prev, cur = self._prev, self._cur
        near = round(x)
        src = self._frame_at(near) if abs(x - near) < EXACT_FRAMES else None
        filled = False
        if src is not None:  # on a received frame: that frame
            _, q, e, r = src
            if self._pos_joints is not None:  # else every joint kept is a cost joint
                e = e[self._cost]
            if not self.same_rate:  # the root translation as Motion.resample blends it
                i0, i1, a = sample_points(np.array([x]), 2**62)
                f0, f1 = self._frame_at(int(i0[0])), self._frame_at(int(i1[0]))
                if a[0] > 0 and f0 is not None and f1 is not None:
                    r = (1 - a[0]) * f0[3] + a[0] * f1[3]
        else:
            s0, s1 = prev[0], cur[0]
            if s1 - s0 == 1:  # between two consecutive frames: as Motion.resample
                _, _, a = sample_points(np.array([x]), 2**62)
            else:  # inside a gap
                filled = True
                a = np.array([(x - s0) / (s1 - s0)])
            if filled and self.gap == "hold":
                _, q, e, r = prev
                e = e[self._cost]
            else:
                qb, eb, rb = blend_poses(
                    prev[1][None], cur[1][None], prev[2][None], cur[2][None],
                    prev[3][None], cur[3][None], a, self._orders, joints=self._cost,
                )  # fmt: skip
                q, e, r = qb[0], eb[0], rb[0]
        if filled:
            self.n_filled += 1
        pos = None
        if self._pos_joints is not None:
            pos = frame_positions(self.skeleton, q, r, self._pos_joints)
            if self._turn is not None:
                pos = pos @ self._turn
            if self.position_scale != 1.0:
                pos = pos * self.position_scale
        if self._pos_joints is not None:
            q = np.ascontiguousarray(q[self._cost])
        frame = Frame(q, self._unwrap(e), pos, self.orders, self.rig)
        return k, frame, filled
