"""One motion type for every source format: :class:`Skeleton` and :class:`Motion`.

Forward kinematics, joint ``j`` with parent ``p``: ``G_j = G_p T(offset_j) pre_j R_j(t) post_j``,
the root at ``offset_root + root_translation[t]``. ASF ``axis`` and FBX pre/post rotations
live in ``pre``/``post``; BVH has the identity there.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np

from fpdtw import limits
from fpdtw.errors import LimitError, MotionFormatError
from fpdtw.motion.joints import OPW_JOINTS, PAPER_JOINTS, find_joint_map, missing_joints_message
from fpdtw.motion.rotations import (
    check_order,
    euler_to_quat,
    quat_mul,
    quat_normalize,
    quat_rotate,
    quat_slerp,
    quat_to_euler,
)

_IDENTITY = np.array([1.0, 0.0, 0.0, 0.0])
_AXIS = {"X": 0, "Y": 1, "Z": 2}


def _euler_near(q, order, ref):
    """Euler angles of ``q`` (N, 4) in ``order`` nearest ``ref`` (N, 3): ``(a, b, c)`` or
    ``(a + 180, 180 - b, c + 180)``, each up to multiples of 360."""
    e = quat_to_euler(q, order)
    cols = [_AXIS[c] for c in order]
    alt = e.copy()
    alt[:, cols[0]] += 180.0
    alt[:, cols[1]] = 180.0 - alt[:, cols[1]]
    alt[:, cols[2]] += 180.0
    best = None
    for cand in (e, alt):
        cand = cand + 360.0 * np.round((ref - cand) / 360.0)
        if best is None:
            best = cand
        else:
            closer = np.abs(cand - ref).sum(axis=1) < np.abs(best - ref).sum(axis=1)
            best = np.where(closer[:, None], cand, best)
    return best


def joint_quats(euler, orders) -> np.ndarray:
    """Local rotations (F, J, 4), ``w >= 0``, from Euler angles (F, J, 3), per joint order."""
    euler = np.asarray(euler, dtype=float)
    q = np.empty(euler.shape[:2] + (4,))
    by_order = np.array(orders)
    for order in set(orders):
        cols = np.flatnonzero(by_order == order)
        q[:, cols] = euler_to_quat(euler[:, cols], order)
    return q


def blend_poses(q0, q1, e0, e1, r0, r1, a, orders, joints=None):
    """Poses a fraction ``a`` (N,) of the way between two poses, row by row: ``(q, euler, r)``.

    Rotations ``q0, q1`` (N, J, 4) by slerp, root translations ``r0, r1`` (N, 3) linearly,
    Euler angles (N, len(joints), 3) of the slerped quaternions in ``orders``, on the branch
    nearest the linear interpolation of ``e0, e1`` (N, J, 3)."""
    q = quat_slerp(q0, q1, a[:, None] * np.ones(q0.shape[1]))
    r = (1 - a)[:, None] * r0 + a[:, None] * r1
    a3 = a[:, None, None]
    joints = np.arange(q0.shape[1]) if joints is None else np.asarray(joints)
    ref = (1 - a3) * e0[:, joints] + a3 * e1[:, joints]
    qj = q[:, joints]
    euler = np.empty(qj.shape[:2] + (3,))
    by_order = np.array([orders[j] for j in joints])
    for order in set(by_order.tolist()):
        cols = np.flatnonzero(by_order == order)
        near = _euler_near(qj[:, cols].reshape(-1, 4), order, ref[:, cols].reshape(-1, 3))
        euler[:, cols] = near.reshape(len(a), len(cols), 3)
    return q, euler, r


def sample_points(x, n: int):
    """``(i0, i1, a)``: the frames of an ``n``-frame motion either side of positions ``x`` (N,),
    in frames, and the fraction between; within 1e-9 below a frame counts as it."""
    i0 = np.minimum(np.floor(x + 1e-9).astype(np.int64), n - 1)
    i1 = np.minimum(i0 + 1, n - 1)
    a = np.clip(x - i0, 0.0, 1.0)
    return i0, i1, a


#: A resampled frame within this many frames of a source frame IS that frame (copied exactly).
EXACT_FRAMES = 1e-6


@dataclass(frozen=True, eq=False)
class Skeleton:
    """Joint hierarchy with rest offsets.

    ``joint_names`` (J,) parents first; ``parents`` (J,) int, -1 for the root (one, first);
    ``offsets`` (J, 3) from the parent, in its frame; ``rotation_orders`` (J,);
    ``pre_rotations``, ``post_rotations`` (J, 4): fixed rotations around the animated one
    (default identity); ``units``: the length unit, for information."""

    joint_names: tuple
    parents: np.ndarray
    offsets: np.ndarray
    rotation_orders: tuple
    pre_rotations: np.ndarray = None
    post_rotations: np.ndarray = None
    units: str = ""

    def __post_init__(self):
        J = len(self.joint_names)
        object.__setattr__(self, "joint_names", tuple(self.joint_names))
        object.__setattr__(self, "parents", np.asarray(self.parents, dtype=np.int64).reshape(J))
        object.__setattr__(self, "offsets", np.asarray(self.offsets, dtype=float).reshape(J, 3))
        object.__setattr__(
            self, "rotation_orders", tuple(check_order(o) for o in self.rotation_orders)
        )
        for name in ("pre_rotations", "post_rotations"):
            v = getattr(self, name)
            v = np.tile(_IDENTITY, (J, 1)) if v is None else quat_normalize(np.reshape(v, (J, 4)))
            object.__setattr__(self, name, v)
        if len(self.rotation_orders) != J:
            raise ValueError("one rotation order per joint is required")
        if len(set(self.joint_names)) != J:
            raise ValueError("joint names must be unique")
        roots = np.flatnonzero(self.parents < 0)
        if len(roots) != 1 or roots[0] != 0:
            raise ValueError("the skeleton must have exactly one root, listed first")
        if np.any(self.parents[1:] >= np.arange(1, J)):
            raise ValueError("joints must be listed parents before children")

    @property
    def n_joints(self) -> int:
        return len(self.joint_names)

    def index(self, name: str) -> int:
        """Index of a joint by its own name."""
        try:
            return self.joint_names.index(name)
        except ValueError:
            raise KeyError(f"no joint named {name!r} in this skeleton") from None

    def same_topology(self, other: Skeleton) -> bool:
        """True when both skeletons have the same joints and hierarchy."""
        return self.joint_names == other.joint_names and np.array_equal(self.parents, other.parents)


@dataclass(eq=False)
class Motion:
    """A motion clip: local joint rotations over time on a skeleton.

    ``euler`` (F, J, 3): local Euler angles in degrees, (x, y, z) columns, each joint in its
    order; ``root_translation`` (F, 3), added to the root's offset; ``quats`` (F, J, 4),
    computed from ``euler`` when omitted; ``source``: ``"fbx"``, ``"asf"`` or ``"bvh"`` (whose
    joint maps come first); ``path``: named in errors; ``joint_map``: canonical name ->
    skeleton name (default :func:`fpdtw.motion.joints.find_joint_map`).

    MotionFormatError for shapes that do not fit, no frames, a rate that is not positive, a
    non-finite value or one beyond :data:`fpdtw.limits.MAX_ABS_VALUE`."""

    name: str
    fps: float
    skeleton: Skeleton
    euler: np.ndarray
    root_translation: np.ndarray
    quats: np.ndarray = None
    source: str = ""
    path: str = ""
    joint_map: dict = field(default=None)

    def __post_init__(self):
        J = self.skeleton.n_joints
        self.euler = np.asarray(self.euler, dtype=float)
        self.root_translation = np.asarray(self.root_translation, dtype=float)
        self.fps = float(self.fps)
        where = self.path or self.name or None
        if self.euler.ndim != 3 or self.euler.shape[1:] != (J, 3):
            raise MotionFormatError(
                where, f"Euler angles have shape {self.euler.shape}, expected (frames, {J}, 3)"
            )
        F = self.euler.shape[0]
        if F == 0:
            raise MotionFormatError(where, "motion has no frames")
        if self.root_translation.shape != (F, 3):
            raise MotionFormatError(
                where,
                f"root translation has shape {self.root_translation.shape}, expected ({F}, 3)",
            )
        if not np.isfinite(self.fps) or self.fps <= 0:
            raise MotionFormatError(where, f"frame rate must be positive, got {self.fps}")
        big = limits.get("max_abs_value")
        for arr, what in ((self.euler, "rotation"), (self.root_translation, "translation")):
            bad = ~np.isfinite(arr.reshape(F, -1)).all(axis=1)
            if bad.any():
                raise MotionFormatError(
                    where, f"non-finite {what} value", frame=int(np.flatnonzero(bad)[0])
                )
            self._check_magnitude(arr.reshape(F, -1), big, f"{what} value", where)
        self._check_magnitude(self.skeleton.offsets, big, "joint offset", where, frames=False)
        if self.quats is None:
            self.quats = joint_quats(self.euler, self.skeleton.rotation_orders)
        else:
            self.quats = np.asarray(self.quats, dtype=float)
            norms = np.linalg.norm(self.quats, axis=-1)
            if not np.all(np.abs(norms - 1.0) < 1e-12):
                self.quats = quat_normalize(self.quats)
            if self.quats.shape != (F, J, 4):
                raise MotionFormatError(where, f"quaternions have shape {self.quats.shape}")
        if self.joint_map is None:
            self.joint_map, _ = find_joint_map(self.skeleton.joint_names, self.source or "fbx")

    @staticmethod
    def _check_magnitude(rows, big, what, where, frames=True):
        """MotionFormatError if a value of ``rows`` (N, d) exceeds ``big`` in magnitude."""
        over = np.abs(rows) > big
        if over.any():
            k, c = (int(x) for x in np.argwhere(over)[0])
            raise MotionFormatError(
                where,
                f"implausible {what} {rows[k, c]:g} (larger in magnitude than "
                f"{big:g}, {limits.env_name('max_abs_value')})",
                frame=k if frames else None,
            )

    @property
    def n_frames(self) -> int:
        return self.euler.shape[0]

    @property
    def joint_names(self) -> tuple:
        return self.skeleton.joint_names

    @property
    def duration(self) -> float:
        """Time of the last frame in seconds (first frame at t = 0)."""
        return (self.n_frames - 1) / self.fps

    @property
    def times(self) -> np.ndarray:
        """Frame times in seconds, shape (F,)."""
        return np.arange(self.n_frames) / self.fps

    def __repr__(self):
        return (
            f"Motion({self.name!r}, {self.n_frames} frames @ {self.fps:g} Hz, "
            f"{self.skeleton.n_joints} joints, source={self.source!r})"
        )

    def replace(self, **changes) -> Motion:
        """Copy with some fields replaced (like :func:`dataclasses.replace`)."""
        return dataclasses.replace(self, **changes)

    def require_joints(self, joints=PAPER_JOINTS, what: str = "") -> np.ndarray:
        """Skeleton indices (int64) of ``joints``, by canonical or own names.

        Else a MotionFormatError naming the file, every joint missing, those the skeleton has
        and ``--joint-map``; ``what`` says what the joints are for."""
        names = self.skeleton.joint_names
        own = [self.joint_map.get(name, name) for name in joints]
        missing = [j for j, o in zip(joints, own) if o not in names]
        if missing:
            raise MotionFormatError(
                self.path or self.name, missing_joints_message(missing, names, what)
            )
        return np.asarray([names.index(o) for o in own], dtype=np.int64)

    joint_indices = require_joints

    def with_joint_map(self, *maps) -> Motion:
        """This motion with the first of ``maps`` (then the built-in maps) its skeleton fits."""
        jm, _ = find_joint_map(self.skeleton.joint_names, self.source or "fbx", maps)
        return self.replace(joint_map=jm)

    def rotations(self, joints=PAPER_JOINTS) -> np.ndarray:
        """Local rotations (F, k, 4) of the chosen joints.

        Paper: FP-DTW Section 4 (8 joints); the input of eq. 1.
        """
        return self.quats[:, self.joint_indices(joints)]

    def eulers(self, joints=PAPER_JOINTS) -> np.ndarray:
        """Local Euler angles (degrees) of the chosen joints, shape (F, k, 3)."""
        return self.euler[:, self.joint_indices(joints)]

    def rotation_orders(self, joints=PAPER_JOINTS) -> tuple:
        """Rotation orders of the chosen joints."""
        return tuple(self.skeleton.rotation_orders[i] for i in self.joint_indices(joints))

    def forward_kinematics(self):
        """Global joint positions (F, J, 3) and orientations (F, J, 4)."""
        sk = self.skeleton
        F, J = self.n_frames, sk.n_joints
        pos = np.empty((F, J, 3))
        rot = np.empty((F, J, 4))
        for j in range(J):
            local = quat_mul(quat_mul(sk.pre_rotations[j], self.quats[:, j]), sk.post_rotations[j])
            p = sk.parents[j]
            if p < 0:
                pos[:, j] = sk.offsets[j] + self.root_translation
                rot[:, j] = local
            else:
                pos[:, j] = pos[:, p] + quat_rotate(rot[:, p], sk.offsets[j])
                rot[:, j] = quat_mul(rot[:, p], local)
        return pos, quat_normalize(rot)

    def positions(self, joints=OPW_JOINTS, root_relative=True) -> np.ndarray:
        """Global positions (F, k, 3) of the chosen joints, relative to the root's by default.

        Paper: OPW poster eq. 5.
        """
        pos, _ = self.forward_kinematics()
        out = pos[:, self.joint_indices(joints)]
        if root_relative:
            out = out - pos[:, :1]
        return out

    def crop(self, start=0.0, stop=None) -> Motion:
        """Frames with ``start <= t <= stop`` (seconds; ``stop=None`` = to the end)."""
        t = self.times
        stop = self.duration if stop is None else stop
        keep = np.flatnonzero((t >= start - 1e-9) & (t <= stop + 1e-9))
        if keep.size == 0:
            raise ValueError(f"crop [{start}, {stop}] s leaves no frame of {self.name}")
        return self.slice_frames(int(keep[0]), int(keep[-1]) + 1)

    def slice_frames(self, a: int, b: int) -> Motion:
        """Frames ``a`` to ``b - 1``."""
        return self.replace(
            euler=self.euler[a:b].copy(),
            root_translation=self.root_translation[a:b].copy(),
            quats=self.quats[a:b].copy(),
        )

    def sample(self, t) -> tuple:
        """Rotations (slerp) and root translation (linear) at times ``t`` (s, clipped)."""
        t = np.clip(np.asarray(t, dtype=float), 0.0, self.duration)
        i0, i1, a = sample_points(t * self.fps, self.n_frames)
        q = quat_slerp(self.quats[i0], self.quats[i1], a[:, None] * np.ones(self.quats.shape[1]))
        r = (1 - a)[:, None] * self.root_translation[i0] + a[:, None] * self.root_translation[i1]
        return q, r

    def retime(self, t, fps=None, name=None) -> Motion:
        """A new motion whose frame ``k`` is this one at time ``t[k]`` (s).

        Poses by :func:`blend_poses`; where ``t`` falls on a frame, its angles and quaternions
        exactly."""
        t = np.asarray(t, dtype=float)
        x = np.clip(t, 0.0, self.duration) * self.fps
        i0, i1, a = sample_points(x, self.n_frames)
        Q, E, R = self.quats, self.euler, self.root_translation
        q, euler, r = blend_poses(
            Q[i0], Q[i1], E[i0], E[i1], R[i0], R[i1], a, self.skeleton.rotation_orders
        )
        exact = np.abs(x - np.rint(x)) < EXACT_FRAMES
        if exact.any():
            near = np.rint(x[exact]).astype(np.int64)
            euler[exact] = self.euler[near]
            q[exact] = self.quats[near]
        return self.replace(
            name=name or self.name,
            fps=self.fps if fps is None else float(fps),
            euler=euler,
            quats=q,
            root_translation=r,
        )

    def resample(self, fps: float) -> Motion:
        """Resample to the frame rate ``fps`` (frame ``k`` at ``k / fps`` s).

        Up to the last frame's time; 120 -> 60 Hz keeps every second frame. LimitError, before
        allocating, for a rate outside :func:`fpdtw.limits.fps_range` or too many frames.

        Paper: FP-DTW Table 1.
        """
        where = self.path or self.name or None
        why = limits.fps_problem(fps)
        if why is not None:
            raise LimitError(where, f"cannot resample to it: {why}")
        fps = float(fps)
        n = int(np.floor(min(self.duration * fps, 2.0**62) + 1e-9)) + 1
        if self.n_frames >= limits.MIN_FRAMES:  # a one-frame motion stays one frame
            what = f"resampling {self.n_frames} frames at {self.fps:g} Hz to {fps:g} Hz"
            limits.check_frames(n, where, what)
        return self.retime(np.arange(n) / fps, fps=fps)
