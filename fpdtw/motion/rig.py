"""A pose that means the same on every rig: rotations away from the rest pose, in body axes.

Joint ``j`` with parent ``p``, rest global rotations ``G^0``, local rotation ``L_j(t)``, the
rig's body axes ``W`` in its world (:func:`world_axes`: Y-up or Z-up, any facing or
handedness): ``Delta_j(t) = W^-1 G_p^0 L_j(t) (G_j^0)^-1 W = A_j R_j(t) B_j`` (``A_j = W^-1
G_p^0 pre_j``, ``B_j = post_j (G_j^0)^-1 W``: :class:`RigTransform`). For one rig eq. 1 on
``Delta`` is eq. 1 on the local rotations (conjugation keeps angles), so motions of one rig
are compared by their raw local rotations, others with the input expressed in the target's
rig (:func:`cost_input`). docs/align.md gives the limits and measurements.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.spatial.transform import Rotation

from fpdtw.errors import MotionFormatError
from fpdtw.motion.joints import PAPER_JOINTS
from fpdtw.motion.rotations import quat_conj, quat_mul, quat_normalize, quat_rotate

_IDENTITY = np.array([1.0, 0.0, 0.0, 0.0])

#: Bodies whose sizes differ by less than this factor share a length unit: adults differ by
#: less (1.5 m and 2 m: 1.33), units by more (inch and cm: 2.54; HDM05's ASF unit and cm: 5.6).
POSITION_UNIT_RATIO = 1.5

#: Joints whose rest positions give a rig's body axes (:func:`world_axes`).
FRAME_JOINTS = ("center_hip", "head", "right_hip", "left_hip", "left_ankle", "right_ankle")
#: The world axes ``--up`` and ``--facing`` name.
AXIS_NAMES = {f"{s}{a}": (1.0 if s == "+" else -1.0) * np.eye(3)[i]
              for s in "+-" for i, a in enumerate("xyz")}  # fmt: skip

#: Rules of :func:`position_scale`: ``"auto"`` (default), ``"raw"``, ``"body-size"``.
POSITION_RULES = ("auto", "raw", "body-size")


@dataclass(frozen=True, eq=False)
class RigTransform:
    """The fixed quaternions ``left`` ``A_j`` and ``right`` ``B_j`` (k, 4) per cost joint, and
    the body ``axes`` (3, 3; rows left, up, facing in world coordinates; default identity).

    Paper: FP-DTW eq. 1 (its local rotations, made comparable across rigs).
    """

    left: np.ndarray
    right: np.ndarray
    axes: np.ndarray = field(default_factory=lambda: np.eye(3))

    def __post_init__(self):
        for name in ("left", "right"):
            v = np.ascontiguousarray(getattr(self, name), dtype=np.float64)
            if v.ndim != 2 or v.shape[1] != 4 or not np.isfinite(v).all():
                raise ValueError(f"RigTransform.{name} must be finite (k, 4), got {v.shape}")
            object.__setattr__(self, name, v)
        if self.left.shape != self.right.shape:
            raise ValueError(f"left {self.left.shape} and right {self.right.shape} differ")

    @property
    def n_joints(self) -> int:
        return self.left.shape[0]

    @classmethod
    def identity(cls, k: int) -> RigTransform:
        """The transform of a rig whose local rotations are already the common ones."""
        q = np.tile(_IDENTITY, (k, 1))
        return cls(q, q.copy())

    def same_as(self, other) -> bool:
        """True when ``other`` is exactly the same transform (every quaternion equal)."""
        return other is self or (
            isinstance(other, RigTransform)
            and np.array_equal(self.left, other.left)
            and np.array_equal(self.right, other.right)
            and np.array_equal(self.axes, other.axes)
        )

    def to_common(self, quats) -> np.ndarray:
        """``Delta = A R B`` of animated rotations ``quats`` (F, k, 4)."""
        return quat_normalize(quat_mul(quat_mul(self.left, np.asarray(quats, float)), self.right))

    def expressed_in(self, quats, other: RigTransform) -> np.ndarray:
        """Rotations of this rig as rotations of rig ``other``: ``(A_o^-1 A) R (B B_o^-1)``."""
        P = quat_mul(quat_conj(other.left), self.left)
        S = quat_mul(self.right, quat_conj(other.right))
        return quat_normalize(quat_mul(quat_mul(P, np.asarray(quats, float)), S))

    def positions_in(self, P, other: RigTransform) -> np.ndarray:
        """Positions ``P`` (..., 3) of this rig's world in the world of rig ``other``."""
        return np.asarray(P, float) @ (other.axes.T @ self.axes).T


def _check_rest_frame(motion, rest_frame):
    if rest_frame is None:
        return None
    F = motion.n_frames
    if isinstance(rest_frame, bool) or not isinstance(rest_frame, int | np.integer):
        raise MotionFormatError(
            motion.path or motion.name, f"rest frame must be a frame number, got {rest_frame!r}"
        )
    if not 0 <= int(rest_frame) < F:
        raise MotionFormatError(
            motion.path or motion.name,
            f"rest frame {rest_frame} is not a frame of the motion (0..{F - 1})",
        )
    return int(rest_frame)


def global_rotations(skeleton, quats) -> np.ndarray:
    """Global rotations (..., J, 4) from animated ones: ``G_j = G_p pre_j R_j post_j``."""
    quats = np.asarray(quats, dtype=float)
    G = np.empty(quats.shape)
    sk = skeleton
    for j in range(sk.n_joints):
        local = quat_mul(quat_mul(sk.pre_rotations[j], quats[..., j, :]), sk.post_rotations[j])
        p = sk.parents[j]
        G[..., j, :] = local if p < 0 else quat_mul(G[..., p, :], local)
    return quat_normalize(G)


def rest_rotations(motion, rest_frame=None) -> np.ndarray:
    """Global rotations ``G^0`` (J, 4) at the rest pose: the rig's own, or frame ``rest_frame``."""
    k = _check_rest_frame(motion, rest_frame)
    J = motion.skeleton.n_joints
    R = np.tile(_IDENTITY, (J, 1)) if k is None else motion.quats[k]
    return global_rotations(motion.skeleton, R)


def _axis(v) -> np.ndarray:
    """The signed world axis nearest ``v`` (3,)."""
    i = int(np.argmax(np.abs(v)))
    return np.where(np.arange(3) == i, np.copysign(1.0, v[i]), 0.0)


def world_axes(skeleton, rest, ends=None, up=None, facing=None) -> np.ndarray:
    """A rig's body axes in its world, rows left, up, facing (3, 3), each a signed world axis.

    At rest (global rotations ``rest`` (J, 4)): up from the hips to the head, left from the
    right hip to the left (``ends``: indices of :data:`FRAME_JOINTS`), both snapped to the
    nearest world axis; facing is ``left x up``, or its opposite (a left-handed world,
    determinant -1) when the feet (ankle to child bone) point that way. ``up``, ``facing``
    (3,): world vectors that override (left is then ``up x facing`` unless the hips agree);
    without ``ends`` Y is up and Z facing.
    """
    sk, z = skeleton, np.eye(3)[2]
    P = np.zeros((sk.n_joints, 3))
    for j in range(1, sk.n_joints if ends is not None else 0):
        P[j] = P[sk.parents[j]] + quat_rotate(rest[sk.parents[j]], sk.offsets[j])
    hips, head, right, left_hip, *feet = (0, 0, 0, 0, 0, 0) if ends is None else ends
    u = _axis(np.eye(3)[1] if up is None and ends is None else P[head] - P[hips] if up is None
              else up)  # fmt: skip
    side = P[left_hip] - P[right] if ends is not None else np.cross(u, z - (z @ u) * u)
    left = _axis(side - (side @ u) * u)
    kids = [np.flatnonzero(np.asarray(sk.parents) == a)[:1] for a in feet if ends is not None]
    toes = sum(
        (quat_rotate(rest[a], sk.offsets[c]) for a, k in zip(feet, kids) for c in k),
        z if ends is None else np.zeros(3),
    )
    f = np.cross(left, u) * (-1.0 if toes @ np.cross(left, u) < 0 else 1.0)
    if facing is not None:
        f = _axis(facing - (facing @ u) * u)
        left = left if abs(left @ np.cross(u, f)) > 0.5 else np.cross(u, f)
    return np.array([left, u, f])


def rig_transform(motion, joints=PAPER_JOINTS, rest_frame=None, up=None, facing=None):
    """The :class:`RigTransform` of a motion's cost ``joints`` (rest: :func:`rest_rotations`;
    body axes: :func:`world_axes`, from :data:`FRAME_JOINTS` if the motion has them)."""
    idx = motion.joint_indices(joints)
    try:
        ends = motion.joint_indices(FRAME_JOINTS)
    except MotionFormatError:
        ends = None
    return skeleton_rig(motion.skeleton, idx, rest_rotations(motion, rest_frame), ends, up, facing)


def skeleton_rig(skeleton, joints, rest=None, ends=None, up=None, facing=None) -> RigTransform:
    """The :class:`RigTransform` of ``joints`` (indices) of a skeleton at rest ``rest`` (J, 4)
    (default its zero rotations); ``ends``, ``up``, ``facing``: of :func:`world_axes`."""
    sk = skeleton
    G0 = global_rotations(sk, np.tile(_IDENTITY, (sk.n_joints, 1))) if rest is None else rest
    axes = world_axes(sk, G0, ends, up, facing)
    B = axes.T * np.sign(np.linalg.det(axes))  # a proper rotation: -W turns as W does
    w = Rotation.from_matrix(B).as_quat()[[3, 0, 1, 2]]
    left, right = [], []
    for j in np.asarray(joints, dtype=np.int64):
        p = sk.parents[j]
        parent = _IDENTITY if p < 0 else G0[p]
        left.append(quat_mul(quat_conj(w), quat_mul(parent, sk.pre_rotations[j])))
        right.append(quat_mul(quat_mul(sk.post_rotations[j], quat_conj(G0[j])), w))
    return RigTransform(quat_normalize(np.array(left)), quat_normalize(np.array(right)), axes)


def common_rotations(motion, joints=PAPER_JOINTS, rest_frame=None) -> np.ndarray:
    """The rig-independent rotations ``Delta_j(t)`` (F, k, 4) of the chosen joints.

    Paper: FP-DTW eq. 1 (its local rotations, made comparable across rigs).
    """
    return rig_transform(motion, joints, rest_frame).to_common(motion.rotations(joints))


def cost_input(I_quats, rig_I, rig_T) -> np.ndarray:
    """The input's rotations (m + 1, k, 4) as eq. 1 compares them with a target of rig ``rig_T``.

    ``I_quats`` itself when a rig is unknown (None) or both are the same (eq. 1 on the raw
    local rotations, as the papers), else expressed in the target's rig.

    Paper: FP-DTW eq. 1.
    """
    if rig_I is None or rig_T is None or rig_I.same_as(rig_T):
        return I_quats
    k = np.shape(I_quats)[1]
    if rig_I.n_joints != k or rig_T.n_joints != k:
        raise ValueError(
            f"rig transforms of {rig_I.n_joints} and {rig_T.n_joints} joints for {k} joints"
        )
    return np.ascontiguousarray(rig_I.expressed_in(I_quats, rig_T))


def pair_rotations(I, T) -> tuple:
    """``(I_quats, T_quats)`` of two MotionFeatures as eq. 1 compares them (:func:`cost_input`)."""
    return cost_input(I.quats, I.rig, T.rig), T.quats


def _chain_length(skeleton, j: int) -> float:
    """Length of the bones from the root to joint ``j``."""
    total = 0.0
    while skeleton.parents[j] >= 0:
        total += float(np.linalg.norm(skeleton.offsets[j]))
        j = int(skeleton.parents[j])
    return total


def skeleton_body_size(skeleton, head: int, left_ankle: int, right_ankle: int) -> float:
    """:func:`body_size` of a skeleton, given its head's and ankles' indices."""
    size = _chain_length(skeleton, head) + 0.5 * (
        _chain_length(skeleton, left_ankle) + _chain_length(skeleton, right_ankle)
    )
    return float(size)


def body_size(motion) -> float:
    """A body's length along its skeleton, in the motion's unit, whatever the pose.

    Root to head plus root to ankle (both legs' mean), summed over the bone offsets;
    MotionFormatError without a head or an ankle."""
    idx = motion.require_joints(("head", "left_ankle", "right_ankle"), "a body's size")
    return skeleton_body_size(motion.skeleton, *idx)


def position_scale(input_size, target_size, rule: str = "auto") -> float:
    """The factor the target's positions are multiplied by before OPW's eq. 5.

    ``"auto"``: 1 when the body sizes differ by less than :data:`POSITION_UNIT_RATIO` or one
    is unknown (the poster's raw positions), else ``input_size / target_size`` (other length
    units); ``"raw"``: 1; ``"body-size"``: ``input_size / target_size`` (1 if unknown).

    Paper: OPW poster eq. 5 (root-relative joint positions).
    """
    if rule not in POSITION_RULES:
        raise ValueError(f"rule must be one of {POSITION_RULES}, got {rule!r}")
    if rule == "raw" or not input_size or not target_size:
        return 1.0
    ratio = float(input_size) / float(target_size)
    if rule == "auto" and 1.0 / POSITION_UNIT_RATIO < ratio < POSITION_UNIT_RATIO:
        return 1.0
    return ratio


#: Frames of the joint trajectories of eq. 2 (:func:`trajectory_rotations`).
TRAJECTORY_FRAMES = ("local", "transform", "global", "root")


def trajectory_rotations(motion, frame: str = "local", joints=PAPER_JOINTS) -> np.ndarray:
    """Rotations (F, k, 4) whose joint trajectories eq. 2 compares, in one of four frames.

    ``"local"`` (the default reading): the animated rotations ``R_j``; ``"transform"``:
    ``pre_j R_j post_j``; ``"global"``: the world rotation ``G_j``; ``"root"``:
    ``G_root^-1 G_j``. MotionFormatError for another frame or a missing joint.

    Paper: FP-DTW eq. 2 ("joint trajectories"; the frame is not stated).
    """
    if frame not in TRAJECTORY_FRAMES:
        raise MotionFormatError(
            motion.path or motion.name, f"frame {frame!r} is not one of {TRAJECTORY_FRAMES}"
        )
    idx = motion.joint_indices(joints)
    if frame == "local":
        return np.ascontiguousarray(motion.quats[:, idx], dtype=np.float64)
    sk = motion.skeleton
    if frame == "transform":
        pre, post = np.asarray(sk.pre_rotations)[idx], np.asarray(sk.post_rotations)[idx]
        Q = quat_mul(quat_mul(pre[None], motion.quats[:, idx]), post[None])
        return np.ascontiguousarray(quat_normalize(Q))
    G = global_rotations(sk, motion.quats)
    Q = G[:, idx]
    if frame == "root":
        root = int(np.flatnonzero(np.asarray(sk.parents) < 0)[0])
        Q = quat_mul(quat_conj(G[:, root : root + 1]), Q)
    return np.ascontiguousarray(quat_normalize(Q))


def bone_directions(motion, joints=PAPER_JOINTS) -> np.ndarray:
    """Each joint's bone direction (k, 3) in its own axes: the unit offset to its child with
    the longest offset (MotionFormatError without one).

    Paper: FP-DTW eq. 2 ("a one unit length vector along the joint's orientation",
    read as the bone)."""
    sk = motion.skeleton
    parents = np.asarray(sk.parents)
    out = np.empty((len(joints), 3))
    for i, j in enumerate(motion.joint_indices(joints)):
        kids = np.flatnonzero(parents == j)
        lengths = np.linalg.norm(sk.offsets[kids], axis=1) if kids.size else np.zeros(0)
        if kids.size == 0 or lengths.max() < 1e-9:
            raise MotionFormatError(
                motion.path or motion.name,
                f"joint {sk.joint_names[j]!r} has no child bone to give its direction",
            )
        c = kids[int(np.argmax(lengths))]
        out[i] = sk.offsets[c] / lengths.max()
    return out
