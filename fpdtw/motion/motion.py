"""One motion type for every source format.

A :class:`Motion` holds per-frame *local* joint rotations as unit quaternions and
the Euler angles they came from (with each joint's rotation order), the root
translation, and a :class:`Skeleton` (parents, offsets, fixed pre/post rotations)
from which forward kinematics gives joint positions.

Forward kinematics, for joint ``j`` with parent ``p``::

    G_j = G_p * T(offset_j) * pre_j * R_j(t) * post_j

where ``R_j(t)`` is the local rotation of frame ``t``. The root's translation is
``offset_root + root_translation[t]``. ASF ``axis`` rotations and FBX pre/post
rotations live in ``pre``/``post``; BVH has identity there.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np

from fpdtw import limits
from fpdtw.errors import LimitError, MotionFormatError
from fpdtw.motion.joints import (
    OPW_JOINTS,
    PAPER_JOINTS,
    find_joint_map,
    missing_joints_message,
)
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
    """Euler angles of ``q`` (N, 4) in ``order``, on the branch nearest ``ref`` (N, 3).

    A Tait-Bryan rotation has two angle triples (a, b, c) and (a + 180, 180 - b,
    c + 180) (angles listed in the order's axis sequence), each defined up to
    multiples of 360 degrees; pick the triple and multiples closest to ``ref``.
    """
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
    """Local rotations from Euler angles, each joint in its own rotation order.

    Parameters
    ----------
    euler : ndarray of float, shape (F, J, 3)
        Degrees, (x, y, z) columns.
    orders : sequence of str, length J
        Rotation order of each joint.

    Returns
    -------
    quats : ndarray of float64, shape (F, J, 4)
        Unit quaternions ``(w, x, y, z)`` with ``w >= 0``, the same for any number of
        frames ``F`` (every :class:`Motion` and every streamed frame computes them here).
    """
    euler = np.asarray(euler, dtype=float)
    q = np.empty(euler.shape[:2] + (4,))
    by_order = np.array(orders)
    for order in set(orders):
        cols = np.flatnonzero(by_order == order)
        q[:, cols] = euler_to_quat(euler[:, cols], order)
    return q


def blend_poses(q0, q1, e0, e1, r0, r1, a, orders, joints=None):
    """Poses a fraction ``a`` of the way from one pose to another, as :meth:`Motion.retime`
    makes them (and the live target, :mod:`fpdtw.motion.stream`, between two frames).

    Rotations by slerp (shortest arc), root translation linearly, Euler angles recomputed
    from the slerped quaternions in each joint's order, on the branch nearest the linear
    interpolation of the two poses' own angles (so that they stay continuous). Every row
    is computed on its own: the result does not depend on which rows are computed together.

    Parameters
    ----------
    q0, q1 : ndarray of float, shape (N, J, 4)
    e0, e1 : ndarray of float, shape (N, J, 3)
        Euler angles (degrees) of the same poses.
    r0, r1 : ndarray of float, shape (N, 3)
        Root translations.
    a : ndarray of float, shape (N,)
        Fractions in [0, 1].
    orders : sequence of str, length J
    joints : ndarray of int, optional
        The joints whose Euler angles to compute (default: all).

    Returns
    -------
    q : ndarray of float64, shape (N, J, 4)
    euler : ndarray of float64, shape (N, len(joints), 3)
    r : ndarray of float64, shape (N, 3)
    """
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
    """Where frame positions ``x`` fall between the frames of an ``n``-frame motion.

    Parameters
    ----------
    x : ndarray of float, shape (N,)
        Positions in frames (time times frame rate), within ``[0, n - 1]``.
    n : int

    Returns
    -------
    i0, i1 : ndarray of int64, shape (N,)
        The frames on either side (``i1 = i0 + 1`` except at the last frame); a position
        within 1e-9 below a frame counts as that frame.
    a : ndarray of float64, shape (N,)
        The fraction of the way from ``i0`` to ``i1``, in [0, 1].
    """
    i0 = np.minimum(np.floor(x + 1e-9).astype(np.int64), n - 1)
    i1 = np.minimum(i0 + 1, n - 1)
    a = np.clip(x - i0, 0.0, 1.0)
    return i0, i1, a


#: A resampled frame within this many frames of a source frame IS that source frame
#: (its rotations and Euler angles copied exactly; :meth:`Motion.retime`).
EXACT_FRAMES = 1e-6


@dataclass(frozen=True, eq=False)
class Skeleton:
    """Joint hierarchy with rest offsets.

    Parameters
    ----------
    joint_names : tuple of str, length J
        Joint names, parents before children.
    parents : ndarray of int, shape (J,)
        Parent index of each joint, -1 for the root (exactly one root).
    offsets : ndarray of float, shape (J, 3)
        Translation of each joint from its parent, in the parent's frame.
    rotation_orders : tuple of str, length J
        Euler rotation order of each joint (see :mod:`fpdtw.motion.rotations`).
    pre_rotations, post_rotations : ndarray of float, shape (J, 4)
        Fixed rotations before/after the animated local rotation (identity if
        omitted).
    units : str
        Length unit of offsets and translations, for information.
    """

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

    Parameters
    ----------
    name : str
        Clip name (file stem).
    fps : float
        Frame rate in Hz.
    skeleton : Skeleton
        Hierarchy, offsets, rotation orders.
    euler : ndarray of float, shape (F, J, 3)
        Local Euler angles in degrees, columns (x, y, z), in each joint's order.
    root_translation : ndarray of float, shape (F, 3)
        Root position per frame (added to the root's offset).
    quats : ndarray of float, shape (F, J, 4), optional
        Local rotations as unit quaternions ``(w, x, y, z)``; computed from
        ``euler`` when omitted.
    source : str
        ``"fbx"``, ``"asf"`` or ``"bvh"``: which naming the joint map uses.
    path : str
        File it was read from (for error messages).
    joint_map : dict of str to str, optional
        Canonical joint name -> skeleton joint name; when omitted, the first built-in
        joint map the skeleton fits (:func:`fpdtw.motion.joints.find_joint_map`, the
        maps of ``source``'s format first).

    Raises
    ------
    MotionFormatError
        Shapes that do not fit, no frames, a frame rate that is not positive, a
        non-finite value, or an angle, translation or offset larger in magnitude
        than :data:`fpdtw.limits.MAX_ABS_VALUE` (the message names ``path``).
    """

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

    # ------------------------------------------------------------------ basics
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

    # -------------------------------------------------------------- selection
    def joint_indices(self, joints=PAPER_JOINTS) -> np.ndarray:
        """Skeleton indices of joints given by canonical or own names.

        Raises
        ------
        MotionFormatError
            If a joint is not in this skeleton (the message lists what is).
        """
        return self.require_joints(joints)

    def require_joints(self, joints=PAPER_JOINTS, what: str = "") -> np.ndarray:
        """Skeleton indices of joints, or an error naming every joint missing.

        Parameters
        ----------
        joints : sequence of str
            Canonical or own names.
        what : str
            What the joints are for, in the message (e.g. "the 8 joints FP-DTW compares").

        Returns
        -------
        idx : ndarray of int64, shape (len(joints),)

        Raises
        ------
        MotionFormatError
            Naming the file, the joints not found, the joints the skeleton has and the
            way out (a joint map, ``--joint-map``).
        """
        names = self.skeleton.joint_names
        own = [self.joint_map.get(name, name) for name in joints]
        missing = [j for j, o in zip(joints, own) if o not in names]
        if missing:
            raise MotionFormatError(
                self.path or self.name, missing_joints_message(missing, names, what)
            )
        return np.asarray([names.index(o) for o in own], dtype=np.int64)

    def with_joint_map(self, *maps) -> Motion:
        """This motion with the first of ``maps`` its skeleton fits as its joint map.

        Parameters
        ----------
        *maps : dict of str to str
            Joint maps (our joint -> the rig's name, e.g. from
            :func:`fpdtw.motion.joints.read_joint_map`), tried first; then the built-in
            maps (:func:`fpdtw.motion.joints.find_joint_map`).

        Returns
        -------
        motion : Motion
        """
        jm, _ = find_joint_map(self.skeleton.joint_names, self.source or "fbx", maps)
        return self.replace(joint_map=jm)

    def rotations(self, joints=PAPER_JOINTS) -> np.ndarray:
        """Local rotations of the chosen joints.

        Returns
        -------
        q : ndarray of float, shape (F, k, 4)
            Unit quaternions ``(w, x, y, z)``.

        Paper: FP-DTW Section 4 (8 joints); the input of eq. 1.
        """
        return self.quats[:, self.joint_indices(joints)]

    def eulers(self, joints=PAPER_JOINTS) -> np.ndarray:
        """Local Euler angles (degrees) of the chosen joints, shape (F, k, 3)."""
        return self.euler[:, self.joint_indices(joints)]

    def rotation_orders(self, joints=PAPER_JOINTS) -> tuple:
        """Rotation orders of the chosen joints."""
        return tuple(self.skeleton.rotation_orders[i] for i in self.joint_indices(joints))

    # --------------------------------------------------------------- kinematics
    def forward_kinematics(self):
        """Global joint positions and orientations.

        Returns
        -------
        positions : ndarray of float, shape (F, J, 3)
        orientations : ndarray of float, shape (F, J, 4)
            Global rotation of each joint's frame (after its post rotation).
        """
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
        """Global positions of the chosen joints by forward kinematics.

        Parameters
        ----------
        joints : sequence of str
            Canonical or own joint names.
        root_relative : bool
            Subtract the root position of each frame (the poster's eq. 5 compares
            poses relative to the root).

        Returns
        -------
        P : ndarray of float, shape (F, k, 3)

        Paper: OPW poster eq. 5.
        """
        pos, _ = self.forward_kinematics()
        out = pos[:, self.joint_indices(joints)]
        if root_relative:
            out = out - pos[:, :1]
        return out

    # ------------------------------------------------------------ time changes
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
        """Local rotations and root translation at arbitrary times.

        Parameters
        ----------
        t : array_like of float, shape (N,)
            Times in seconds, clipped to ``[0, duration]``.

        Returns
        -------
        quats : ndarray of float, shape (N, J, 4)
            Slerp between neighbouring frames.
        root_translation : ndarray of float, shape (N, 3)
            Linear interpolation.
        """
        t = np.clip(np.asarray(t, dtype=float), 0.0, self.duration)
        i0, i1, a = sample_points(t * self.fps, self.n_frames)
        q = quat_slerp(self.quats[i0], self.quats[i1], a[:, None] * np.ones(self.quats.shape[1]))
        r = (1 - a)[:, None] * self.root_translation[i0] + a[:, None] * self.root_translation[i1]
        return q, r

    def retime(self, t, fps=None, name=None) -> Motion:
        """A new motion whose frame ``k`` is this motion at time ``t[k]``.

        Rotations by slerp, translation linearly; Euler angles recomputed from
        the quaternions in each joint's order, on the branch nearest the linear
        interpolation of the input's own angles, so that they stay continuous;
        where ``t`` falls on an input frame, angles and quaternions are the input's.

        Parameters
        ----------
        t : array_like of float, shape (N,)
            Source times in seconds.
        fps : float, optional
            Frame rate of the result (default: this motion's).
        """
        t = np.asarray(t, dtype=float)
        x = np.clip(t, 0.0, self.duration) * self.fps
        i0, i1, a = sample_points(x, self.n_frames)
        Q, E, R = self.quats, self.euler, self.root_translation
        q, euler, r = blend_poses(
            Q[i0], Q[i1], E[i0], E[i1], R[i0], R[i1], a, self.skeleton.rotation_orders
        )
        exact = np.abs(x - np.rint(x)) < EXACT_FRAMES
        if exact.any():
            # frames that fall on an input frame keep its angles and rotation exactly
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
        """Resample to another frame rate (slerp for rotations).

        Frame ``k`` of the result is this motion at ``k / fps`` seconds, up to the
        last frame time. Table 1 of the FP-DTW paper resamples 120 Hz to 60 Hz,
        which keeps every second frame exactly.

        Parameters
        ----------
        fps : float
            New frame rate in Hz, within :func:`fpdtw.limits.fps_range`.

        Returns
        -------
        motion : Motion
            ``floor(duration * fps) + 1`` frames.

        Raises
        ------
        LimitError
            ``fps`` outside the plausible range, or a result of more than
            :data:`fpdtw.limits.MAX_FRAMES` frames, or of one frame from a motion of
            two or more (checked before anything is allocated; the message names the
            motion's file).

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
