"""Derivative motions: any online aligner run on frame-to-frame differences (beyond the papers).

The OPW poster's conclusion suggests Keogh and Pazzani's derivative DTW (DDTW, SDM 2001):
the cost on the frame-to-frame differences of the two series instead of their values. DDTW
runs DTW UNCHANGED on the derivative estimates of both series. The reading here (committed
in d1a2385, 2026-11-23, before Q5's first results in 97738ec; docs/history.md):
``"<method> (derivative)"`` runs the method unchanged on the derivative motions of both the
input and the target stream.

Rotations
    per cost joint, the backward difference ``q'_t = q_t conj(q_{t-1})``: the rotation that
    takes frame ``t - 1`` to frame ``t`` (expressed in the joint's parent frame), its sign
    canonicalised (``w >= 0``).
Positions
    ``p'_t = p_t - p_{t-1}`` (the root-relative positions OPW compares).
First frame
    ``q'_0 = (1, 0, 0, 0)`` (the identity) and ``p'_0 = 0``: no motion before the first frame.
Causal
    the live target's derivative at frame ``n`` uses frames ``n - 1`` and ``n`` only.
    Keogh and Pazzani's estimate, ``((x_t - x_{t-1}) + (x_{t+1} - x_{t-1}) / 2) / 2``, needs
    frame ``n + 1``, which a live stream does not have when it must answer frame ``n``; the
    alternative, their estimate with a lag of one frame, is not implemented.
Euler angles
    the Euler angles of ``q'_t`` in the joint's rotation order, unwrapped along time. Methods
    B and C forecast by dead reckoning on the target's Euler angles
    (:mod:`fpdtw.forecast`), so their forecast becomes dead reckoning of the DERIVATIVE
    motion (the rotation per frame is extrapolated linearly in its Euler angles).
Rig
    eq. 1 compares the two motions' local rotations, mapped into a common representation
    ``Delta(t) = A R(t) B`` when their rigs differ (:mod:`fpdtw.motion.rig`). The derivative
    is taken AFTER that mapping: ``Delta(t) Delta(t-1)^-1 = A (R(t) R(t-1)^-1) A^-1 =
    A q'_t A^-1``. So the derivative of the raw local rotations carries the rig transform
    ``(A, A^-1)`` (:func:`derivative_rig`), and :func:`fpdtw.motion.rig.cost_input` then
    compares the two derivatives exactly as the derivatives of the two common
    representations, with no change to the aligners. (Differencing the raw rotations and
    comparing them without the mapping would compare rotations about differently oriented
    axes across rigs; with the same rig, or an unknown one, both readings coincide.)

Scoring is unchanged: a derivative aligner's map (one input frame per target frame) is scored
like every other algorithm's, similarity (eq. 2) on the ORIGINAL pair and deviation from DTW
of the original (pose) pair. Only the aligner sees derivatives.

Paper: OPW poster Section 6 (conclusion: derivative DTW); Keogh and Pazzani, SDM 2001.
Notebook: 16_open_questions.ipynb
"""

from __future__ import annotations

import dataclasses

import numpy as np

from fpdtw.errors import AlignmentError
from fpdtw.motion.features import Frame, MotionFeatures
from fpdtw.motion.rig import RigTransform
from fpdtw.motion.rotations import (
    UnwrapDegrees,
    quat_conj,
    quat_mul,
    quat_to_euler,
    unwrap_degrees,
)
from fpdtw.online.base import OnlineAligner

#: The identity rotation, ``q'_0``.
IDENTITY = np.array([1.0, 0.0, 0.0, 0.0])


def _canonical(q: np.ndarray) -> np.ndarray:
    """Quaternions (..., 4) with ``w >= 0`` (the same rotations)."""
    return np.where(q[..., :1] < 0.0, -q, q)


def derivative_quats(quats) -> np.ndarray:
    """The backward differences of rotations: ``q'_t = q_t conj(q_{t-1})``, ``q'_0 = 1``.

    Parameters
    ----------
    quats : array_like of float64, shape (F, k, 4)
        Unit quaternions ``(w, x, y, z)`` of k joints over F frames.

    Returns
    -------
    dq : ndarray of float64, shape (F, k, 4), C-contiguous
        The rotation from frame ``t - 1`` to frame ``t`` of each joint, ``w >= 0``; the
        identity at ``t = 0``.

    Paper: OPW poster Section 6 (derivative DTW, Keogh and Pazzani).
    """
    q = np.asarray(quats, dtype=np.float64)
    out = np.empty_like(q)
    if q.shape[0]:
        out[0] = IDENTITY
        out[1:] = _canonical(quat_mul(q[1:], quat_conj(q[:-1])))
    return np.ascontiguousarray(out)


def derivative_rig(rig: RigTransform | None) -> RigTransform | None:
    """The rig transform of a motion's derivative: ``(A, A^-1)`` of the motion's ``(A, B)``.

    ``A q'_t A^-1`` is the derivative of the common representation ``A R(t) B`` (module
    docstring). None (unknown rig) stays None.
    """
    if rig is None:
        return None
    return RigTransform(rig.left, quat_conj(rig.left))


def _euler(dq: np.ndarray, orders) -> np.ndarray:
    """Euler angles (..., k, 3) in degrees of rotations ``dq`` (..., k, 4), joint by joint."""
    return np.stack([quat_to_euler(dq[..., j, :], o) for j, o in enumerate(orders)], axis=-2)


def derivative_features(F: MotionFeatures) -> MotionFeatures:
    """The derivative motion of ``F``: frame-to-frame rotations and position differences.

    Parameters
    ----------
    F : MotionFeatures
        A motion's features (F frames, k cost joints, optionally p position joints).

    Returns
    -------
    D : MotionFeatures
        ``quats`` (F, k, 4): ``q'_t = q_t conj(q_{t-1})``, ``w >= 0``, the identity at
        ``t = 0``; ``euler`` (F, k, 3): their Euler angles in each joint's order, degrees,
        unwrapped along time; ``positions`` (F, p, 3) or None: ``p'_t = p_t - p_{t-1}``,
        0 at ``t = 0``; ``rig``: :func:`derivative_rig`; orders, frame rate and body size
        those of ``F``; name ``F.name + " (derivative)"``.

    Raises
    ------
    AlignmentError
        ``F`` is not MotionFeatures.

    Paper: OPW poster Section 6 (derivative DTW, Keogh and Pazzani).
    Notebook: 16_open_questions.ipynb
    """
    if not isinstance(F, MotionFeatures):
        raise AlignmentError(
            f"derivative_features: expected MotionFeatures, got {type(F).__name__}"
        )
    dq = derivative_quats(F.quats)
    euler = np.ascontiguousarray(unwrap_degrees(_euler(dq, F.orders), axis=0))
    pos = None
    if F.positions is not None:
        p = np.asarray(F.positions, dtype=np.float64)
        pos = np.zeros_like(p)
        pos[1:] = p[1:] - p[:-1]
    return dataclasses.replace(
        F,
        quats=dq,
        euler=euler,
        positions=pos,
        name=f"{F.name} (derivative)",
        rig=derivative_rig(F.rig),
    )


class DerivativeFrames:
    """The derivative of a live stream, one frame at a time (causal: frames n - 1 and n).

    Calling it with the frames of a motion in order returns the frames of
    :func:`derivative_features` of that motion, bit for bit (stream == batch).
    """

    def __init__(self):
        self.reset()

    def reset(self) -> None:
        """Forget the stream; the next frame is a first frame."""
        self._prev = None
        self._unwrap = UnwrapDegrees()
        self._rig = None

    def __call__(self, frame: Frame, orders) -> Frame:
        """The derivative frame of ``frame`` (its rotation ``orders``: the take's)."""
        q = np.asarray(frame.quats, dtype=np.float64)
        p = None if frame.positions is None else np.asarray(frame.positions, dtype=np.float64)
        if self._prev is None:
            self._rig = derivative_rig(frame.rig)
            dq = np.broadcast_to(IDENTITY, q.shape).copy()
            dp = None if p is None else np.zeros_like(p)
        else:
            pq, pp = self._prev
            dq = _canonical(quat_mul(q, quat_conj(pq)))
            dp = None if p is None or pp is None else p - pp
        self._prev = (q.copy(), None if p is None else p.copy())
        euler = self._unwrap(_euler(dq, orders))
        return Frame(dq, euler, dp, frame.orders, self._rig)


class DerivativeAligner(OnlineAligner):
    """Any online aligner run on derivative motions (``"<method> (derivative)"``).

    The inner aligner is built on :func:`derivative_features` of the input; each incoming
    target frame is differenced with the previous one (:class:`DerivativeFrames`) and fed
    to it. The map is the inner aligner's (input frame of each target frame, the same
    frame numbers as the original motions).

    Parameters
    ----------
    I : MotionFeatures
        The input (recorded) motion, its poses.
    inner : OnlineAligner
        An aligner built on ``derivative_features(I)``.

    Paper: OPW poster Section 6 (derivative DTW, Keogh and Pazzani).
    """

    #: Reads the previous target frame (its own copy), so nothing earlier is kept here.
    history = 1

    def __init__(self, I: MotionFeatures, inner: OnlineAligner):
        if not isinstance(inner, OnlineAligner):
            raise AlignmentError(
                f"DerivativeAligner: the inner aligner must be an OnlineAligner, "
                f"got {type(inner).__name__}"
            )
        if inner.I.n_frames != I.n_frames:
            raise AlignmentError(
                f"DerivativeAligner: the inner aligner's input has {inner.I.n_frames} frames, "
                f"the input {I.n_frames}"
            )
        self.inner = inner
        self._diff = DerivativeFrames()
        self.name = f"{inner.name} (derivative)"
        super().__init__(I)

    def reset(self) -> None:
        super().reset()
        self.inner.reset()
        self._diff.reset()

    def _begin_take(self, frame: Frame) -> None:
        """The take's rotation orders (the rig is the inner aligner's business)."""
        self.T_orders = self.I.orders if frame.orders is None else tuple(frame.orders)

    def step(self, frame: Frame) -> int:
        """Receive target frame ``T_{n+1}`` (a pose), return ``M_{n+1}`` (inner aligner)."""
        if self.n_received == 0:
            self._diff.reset()
        self._frame = frame
        try:
            return super().step(frame)
        finally:
            self._frame = None

    def _step(self, q: int) -> int:
        orders = self.T_orders
        if len(orders) != np.shape(self._frame.quats)[0]:
            raise AlignmentError(
                f"target frame {self.n_received - 1}: {len(orders)} rotation orders for "
                f"{np.shape(self._frame.quats)[0]} joints"
            )
        return self.inner.step(self._diff(self._frame, orders))


__all__ = [
    "IDENTITY",
    "DerivativeAligner",
    "DerivativeFrames",
    "derivative_features",
    "derivative_quats",
    "derivative_rig",
]
