"""A pose that means the same on every rig: rotations away from the rest pose, in world axes.

Eq. 1 compares the LOCAL rotations of 8 joints, and what a local rotation means depends on
the rig: an AMC value ``M`` turns the bone in its ASF axis frame ``C`` (relative to the
parent it is ``C M C^-1``); an FBX local rotation sits between the node's pre- and
post-rotations (``pre R post``); a BVH channel turns the joint in axes aligned with the
world at the rest pose (zero rotations, the offsets). The same pose on two rigs whose bones
are oriented differently at rest has different local rotations.

The common representation. For joint ``j`` with parent ``p``, rest-pose global rotations
``G_p^0``, ``G_j^0`` and local rotation ``L_j(t)`` (FBX ``pre_j R_j(t) post_j``, ASF
``C_j M_j(t) C_j^-1``, BVH ``R_j(t)``)::

    Delta_j(t) = G_p^0 L_j(t) (G_j^0)^-1 = W_p(t)^-1 W_j(t),   W_j(t) = G_j(t) (G_j^0)^-1

the rotation of the bone away from its rest orientation, in world-aligned axes, relative to
its parent's. ``W_j(t)`` is the world rotation that takes bone ``j`` from its rest
orientation to its orientation at ``t``; a rig that orients the bone's own axes otherwise
(``G_j -> G_j X_j`` at rest and in motion) has the same ``W_j``, so two rigs whose rest poses
have the same SHAPE (both in a T-pose, facing the same way, the same up axis) give the same
``Delta`` for the same pose. With ``R_j(t)`` the animated rotation
(:attr:`fpdtw.motion.Motion.quats`), ``Delta_j(t) = A_j R_j(t) B_j`` with two fixed
quaternions per joint, ``A_j = G_p^0 pre_j`` and ``B_j = post_j (G_j^0)^-1``
(:class:`RigTransform`).

Same rig, same eq. 1. Two motions of one rig (the same ``A`` and ``B``) have
``Delta_I^-1 Delta_T = B^-1 (R_I^-1 R_T) B``: conjugation keeps angles, so eq. 1 on
``Delta`` is eq. 1 on the local rotations, exactly in exact arithmetic. The aligners compare
the raw local rotations whenever both motions carry the same transform (every cost joint's
``A`` and ``B`` exactly equal: every pair of the papers, whose maps stay bit for bit those of
eq. 1 on local rotations) and the common representation otherwise. Computing it: multiplying
two quaternions on the same side by one unit quaternion keeps their 4-D dot product, so
``|Delta_I . Delta_T| = |(A_T^-1 A_I R_I B_I B_T^-1) . R_T|``: the INPUT's rotations are
expressed once in the target's rig (:func:`cost_input`) and the target's frames, and the
forecasts dead-reckoned from its own Euler angles in its own rotation orders (Algorithms 2
and 3 extrapolate Euler angles, which conjugation does not preserve), are used as received.

Rest pose. By default the rig's own: zero animated rotations (BVH: the offsets; ASF: zero
AMC values in the axis frames; FBX: the pre/post rotations with zero ``Lcl Rotation``,
the T-pose of the authors' MotionBuilder rig; a bind pose stored in FBX ``Pose`` nodes is
not read). ``rest_frame=k`` takes frame ``k`` of the motion instead, e.g. a calibration
T-pose of a motion whose rig rests in an A-pose. Limits: rest poses of different shapes (an
A-pose against a T-pose) compare the arms off by the angle between them, unless a rest
frame is given; the world axes must agree (the same up axis and facing at rest); a joint
is compared relative to its own parent, so rigs whose hierarchies differ above a cost joint
(a clavicle in one, none in the other) compare different relative rotations.

Positions (OPW's eq. 5) are compared in each motion's units; :func:`position_scale`
rescales the target's when two bodies differ in size by more than a unit mismatch could
not explain (:data:`POSITION_UNIT_RATIO`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fpdtw.errors import MotionFormatError
from fpdtw.motion.joints import PAPER_JOINTS
from fpdtw.motion.rotations import quat_conj, quat_mul, quat_normalize

_IDENTITY = np.array([1.0, 0.0, 0.0, 0.0])

#: Bodies whose sizes (:func:`body_size`) differ by less than this factor are taken to be
#: measured in one length unit: their positions are compared as they are (the poster's
#: eq. 5). Adults differ by less (1.5 m and 2 m: 1.33); different units by more (inch and
#: cm: 2.54, cm and m: 100, the ASF unit of HDM05, 1/0.45 inch, and cm: 5.6).
POSITION_UNIT_RATIO = 1.5

#: Rules of :func:`position_scale`: ``"auto"`` (default), ``"raw"``, ``"body-size"``.
POSITION_RULES = ("auto", "raw", "body-size")


@dataclass(frozen=True, eq=False)
class RigTransform:
    """The two fixed quaternions per cost joint that map its animated rotation into the
    common representation: ``Delta_j(t) = A_j R_j(t) B_j``.

    Attributes
    ----------
    left : ndarray of float64, shape (k, 4)
        ``A_j = G_p^0 pre_j`` (unit quaternions ``(w, x, y, z)``).
    right : ndarray of float64, shape (k, 4)
        ``B_j = post_j (G_j^0)^-1``.

    Paper: FP-DTW eq. 1 (its local rotations, made comparable across rigs).
    """

    left: np.ndarray
    right: np.ndarray

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
        """The transform of a rig whose local rotations already are the common
        representation (a BVH rig resting with zero rotations in world-aligned axes)."""
        q = np.tile(_IDENTITY, (k, 1))
        return cls(q, q.copy())

    def same_as(self, other) -> bool:
        """True when ``other`` is exactly the same transform (every quaternion equal)."""
        return other is self or (
            isinstance(other, RigTransform)
            and np.array_equal(self.left, other.left)
            and np.array_equal(self.right, other.right)
        )

    def to_common(self, quats) -> np.ndarray:
        """``Delta = A R B`` of animated rotations ``quats`` (F, k, 4), unit quaternions."""
        return quat_normalize(quat_mul(quat_mul(self.left, np.asarray(quats, float)), self.right))

    def expressed_in(self, quats, other: RigTransform) -> np.ndarray:
        """Rotations ``quats`` (F, k, 4) of this rig as rotations of rig ``other`` with the
        same common representation: ``(A_o^-1 A) R (B B_o^-1)``."""
        P = quat_mul(quat_conj(other.left), self.left)
        S = quat_mul(self.right, quat_conj(other.right))
        return quat_normalize(quat_mul(quat_mul(P, np.asarray(quats, float)), S))


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
    """Global rotations of every joint from its animated rotations.

    ``G_j = G_p pre_j R_j post_j`` (the root: ``pre R post``), as
    :meth:`fpdtw.motion.Motion.forward_kinematics` composes them.

    Parameters
    ----------
    skeleton : Skeleton
    quats : ndarray of float, shape (..., J, 4)
        Animated rotations ``R`` of every joint.

    Returns
    -------
    G : ndarray of float64, shape (..., J, 4)
    """
    quats = np.asarray(quats, dtype=float)
    G = np.empty(quats.shape)
    sk = skeleton
    for j in range(sk.n_joints):
        local = quat_mul(quat_mul(sk.pre_rotations[j], quats[..., j, :]), sk.post_rotations[j])
        p = sk.parents[j]
        G[..., j, :] = local if p < 0 else quat_mul(G[..., p, :], local)
    return quat_normalize(G)


def rest_rotations(motion, rest_frame=None) -> np.ndarray:
    """Global rotations of every joint at the rest pose, ``G^0``.

    Parameters
    ----------
    motion : Motion
    rest_frame : int, optional
        Frame of the motion to take as its rest pose (default: the rig's own rest, zero
        animated rotations).

    Returns
    -------
    G0 : ndarray of float64, shape (J, 4)

    Raises
    ------
    MotionFormatError
        ``rest_frame`` is not a frame of the motion (naming its file).
    """
    k = _check_rest_frame(motion, rest_frame)
    J = motion.skeleton.n_joints
    R = np.tile(_IDENTITY, (J, 1)) if k is None else motion.quats[k]
    return global_rotations(motion.skeleton, R)


def rig_transform(motion, joints=PAPER_JOINTS, rest_frame=None) -> RigTransform:
    """The :class:`RigTransform` of the cost joints of a motion's rig.

    ``A_j = G_p^0 pre_j`` and ``B_j = post_j (G_j^0)^-1``, with ``G^0`` from
    :func:`rest_rotations` (the root's parent: the identity).

    Parameters
    ----------
    motion : Motion
    joints : sequence of str
        Cost joints (canonical or own names), default the paper's 8.
    rest_frame : int, optional
        See :func:`rest_rotations`.

    Returns
    -------
    rig : RigTransform

    Raises
    ------
    MotionFormatError
        A joint the skeleton does not have, or a rest frame outside the motion.
    """
    idx = motion.joint_indices(joints)
    return skeleton_rig(motion.skeleton, idx, rest_rotations(motion, rest_frame))


def skeleton_rig(skeleton, joints, rest=None) -> RigTransform:
    """The :class:`RigTransform` of some joints of a skeleton.

    Parameters
    ----------
    skeleton : Skeleton
    joints : ndarray of int, shape (k,)
        Skeleton indices of the cost joints.
    rest : ndarray of float, shape (J, 4), optional
        Global rest rotations ``G^0`` (default: those of zero animated rotations).

    Returns
    -------
    rig : RigTransform
    """
    sk = skeleton
    G0 = global_rotations(sk, np.tile(_IDENTITY, (sk.n_joints, 1))) if rest is None else rest
    left, right = [], []
    for j in np.asarray(joints, dtype=np.int64):
        p = sk.parents[j]
        parent = _IDENTITY if p < 0 else G0[p]
        left.append(quat_mul(parent, sk.pre_rotations[j]))
        right.append(quat_mul(sk.post_rotations[j], quat_conj(G0[j])))
    return RigTransform(quat_normalize(np.array(left)), quat_normalize(np.array(right)))


def common_rotations(motion, joints=PAPER_JOINTS, rest_frame=None) -> np.ndarray:
    """The rig-independent rotations ``Delta_j(t)`` of the chosen joints.

    Parameters
    ----------
    motion : Motion
    joints : sequence of str
    rest_frame : int, optional
        See :func:`rest_rotations`.

    Returns
    -------
    Delta : ndarray of float64, shape (F, k, 4)

    Paper: FP-DTW eq. 1 (its local rotations, made comparable across rigs).
    """
    return rig_transform(motion, joints, rest_frame).to_common(motion.rotations(joints))


def cost_input(I_quats, rig_I, rig_T) -> np.ndarray:
    """The input's rotations as eq. 1 compares them with a target of rig ``rig_T``.

    ``I_quats`` itself when either rig is unknown (None) or both are the same
    (:meth:`RigTransform.same_as`): eq. 1 on the raw local rotations, as the papers
    compute it. Otherwise the input's rotations expressed in the target's rig,
    ``(A_T^-1 A_I) R_I (B_I B_T^-1)``, whose eq. 1 distance to the target's raw rotations
    is that of the two motions' common representations (module docstring).

    Parameters
    ----------
    I_quats : ndarray of float64, shape (m + 1, k, 4)
    rig_I, rig_T : RigTransform or None

    Returns
    -------
    quats : ndarray of float64, shape (m + 1, k, 4), C-contiguous

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
    """``(I_quats, T_quats)`` of two :class:`~fpdtw.motion.MotionFeatures` as eq. 1
    compares them (:func:`cost_input`): what the offline algorithms (DTW) use."""
    return cost_input(I.quats, I.rig, T.rig), T.quats


def _chain_length(skeleton, j: int) -> float:
    """Length of the bones from the root to joint ``j`` (sum of the offsets' norms)."""
    total = 0.0
    while skeleton.parents[j] >= 0:
        total += float(np.linalg.norm(skeleton.offsets[j]))
        j = int(skeleton.parents[j])
    return total


def skeleton_body_size(skeleton, head: int, left_ankle: int, right_ankle: int) -> float:
    """:func:`body_size` of a skeleton, given the indices of its head and ankles."""
    size = _chain_length(skeleton, head) + 0.5 * (
        _chain_length(skeleton, left_ankle) + _chain_length(skeleton, right_ankle)
    )
    return float(size)


def body_size(motion) -> float:
    """The length of a body along its skeleton: root to head plus root to ankle (the
    mean of both legs), summed over the bone offsets, whatever the pose.

    Parameters
    ----------
    motion : Motion

    Returns
    -------
    size : float
        In the motion's length unit (0 for a skeleton without length).

    Raises
    ------
    MotionFormatError
        The skeleton lacks the head or an ankle (see the joint maps).
    """
    idx = motion.require_joints(("head", "left_ankle", "right_ankle"), "a body's size")
    return skeleton_body_size(motion.skeleton, *idx)


def position_scale(input_size, target_size, rule: str = "auto") -> float:
    """The factor the target's positions are multiplied by before OPW compares them
    with the input's (eq. 5 of the poster).

    * ``"auto"`` (default): 1 when the two bodies' sizes (:func:`body_size`) differ by
      less than a factor :data:`POSITION_UNIT_RATIO`, or either is unknown (the poster's
      raw positions, in what is then taken to be one length unit), else
      ``input_size / target_size`` (different length units: the target rescaled to the
      input's body size);
    * ``"raw"``: always 1;
    * ``"body-size"``: ``input_size / target_size`` (1 if either is unknown).

    Parameters
    ----------
    input_size, target_size : float or None
        :func:`body_size` of each motion (:attr:`MotionFeatures.body_size`).
    rule : str

    Returns
    -------
    scale : float

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
    """Rotations whose joint trajectories eq. 2 compares, in one of three frames.

    ``"local"``: the animated local rotations ``R_j`` (:meth:`fpdtw.motion.Motion.rotations`,
    what eq. 2 reads by default); ``"transform"``: the joint's whole local transform
    ``pre_j R_j post_j`` (FBX: with the node's pre/post-rotations, what the FBX SDK's local
    transform evaluation returns; ASF: ``C M C^-1`` in the parent's axes; BVH: ``R``, the
    same as ``"local"``); ``"global"``: each joint's world rotation ``G_j``
    (:func:`global_rotations`: pre/post rotations and every ancestor included);
    ``"root"``: relative to the root joint's world rotation, ``G_root^-1 G_j`` (the
    body's turning and leaning removed).

    Parameters
    ----------
    motion : Motion
    frame : {"local", "transform", "global", "root"}
    joints : sequence of str

    Returns
    -------
    Q : ndarray of float64, shape (F, k, 4)

    Raises
    ------
    MotionFormatError
        An unknown frame (naming the motion's file) or a missing joint.

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
    """Each joint's bone direction: the unit offset to its child, in the joint's own axes.

    A joint with several children takes the one with the longest offset (the limb, not
    a twist or end-site helper).

    Parameters
    ----------
    motion : Motion
    joints : sequence of str

    Returns
    -------
    v : ndarray of float64, shape (k, 3)

    Raises
    ------
    MotionFormatError
        A joint without a child at a non-zero offset (naming the motion's file).

    Paper: FP-DTW eq. 2 ("a one unit length vector along the joint's orientation",
    read as the bone).
    """
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


__all__ = [
    "POSITION_RULES",
    "POSITION_UNIT_RATIO",
    "RigTransform",
    "TRAJECTORY_FRAMES",
    "body_size",
    "bone_directions",
    "common_rotations",
    "cost_input",
    "global_rotations",
    "pair_rotations",
    "position_scale",
    "rest_rotations",
    "rig_transform",
    "skeleton_body_size",
    "skeleton_rig",
    "trajectory_rotations",
]
