"""Derivative motions: any online aligner run on frame-to-frame differences (beyond the papers).

The OPW poster's conclusion suggests Keogh and Pazzani's derivative DTW (DDTW, SDM 2001).
The reading (committed in d1a2385, before Q5's first results in 97738ec; docs/history.md):
``"<method> (derivative)"`` runs the method unchanged on the derivative motions of both the
input and the target stream:

* rotations ``q'_t = q_t conj(q_{t-1})`` per cost joint (``w >= 0``), positions ``p'_t =
  p_t - p_{t-1}``; at frame 0 the identity and 0;
* causal: frame ``n`` uses frames ``n - 1`` and ``n`` (Keogh and Pazzani's estimate needs
  frame ``n + 1``; a lagged version of it is not implemented);
* Euler angles: those of ``q'_t``, unwrapped, so Methods B and C dead-reckon the derivative;
* rigs: the derivative of the common representation ``A R(t) B`` is ``A q'_t A^-1``, so the
  raw derivative carries the rig transform ``(A, A^-1)`` (:func:`derivative_rig`).

Scoring is unchanged: the map is scored on the original pair.

Paper: OPW poster Section 6 (conclusion: derivative DTW); Keogh and Pazzani, SDM 2001.
Notebook: 16_open_questions.ipynb
"""

from __future__ import annotations

import dataclasses

import numpy as np

from fpdtw.errors import AlignmentError
from fpdtw.motion.features import Frame, MotionFeatures
from fpdtw.motion.rig import RigTransform
from fpdtw.motion.rotations import UnwrapDegrees, quat_conj, quat_mul, quat_to_euler, unwrap_degrees
from fpdtw.online.base import FrameWrapper, OnlineAligner

#: The identity rotation, ``q'_0``.
IDENTITY = np.array([1.0, 0.0, 0.0, 0.0])


def _canonical(q: np.ndarray) -> np.ndarray:
    """Quaternions (..., 4) with ``w >= 0`` (the same rotations)."""
    return np.where(q[..., :1] < 0.0, -q, q)


def derivative_quats(quats) -> np.ndarray:
    """Backward differences ``q'_t = q_t conj(q_{t-1})`` (``w >= 0``; ``q'_0 = 1``) of unit
    quaternions of shape (F, k, 4); float64, C-contiguous, the same shape.

    Paper: OPW poster Section 6 (derivative DTW, Keogh and Pazzani).
    """
    q = np.asarray(quats, dtype=np.float64)
    out = np.empty_like(q)
    if q.shape[0]:
        out[0] = IDENTITY
        out[1:] = _canonical(quat_mul(q[1:], quat_conj(q[:-1])))
    return np.ascontiguousarray(out)


def derivative_rig(rig: RigTransform | None) -> RigTransform | None:
    """The rig transform of a motion's derivative: ``(A, A^-1)`` of its ``(A, B)``; None: None."""
    if rig is None:
        return None
    return RigTransform(rig.left, quat_conj(rig.left))


def _euler(dq: np.ndarray, orders) -> np.ndarray:
    """Euler angles (..., k, 3) in degrees of rotations ``dq`` (..., k, 4), joint by joint."""
    return np.stack([quat_to_euler(dq[..., j, :], o) for j, o in enumerate(orders)], axis=-2)


def derivative_features(F: MotionFeatures) -> MotionFeatures:
    """The derivative motion of ``F`` (module docstring), named ``F.name + " (derivative)"``.

    Parameters
    ----------
    F : MotionFeatures

    Returns
    -------
    D : MotionFeatures

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
    """The derivative of a live stream, one frame at a time: bit for bit the frames of
    :func:`derivative_features` of the whole motion."""

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


class DerivativeAligner(FrameWrapper):
    """Any online aligner run on derivative motions (``"<method> (derivative)"``): each
    target frame is differenced (:class:`DerivativeFrames`) and fed to ``inner``.

    Parameters
    ----------
    I : MotionFeatures
        The input motion (poses).
    inner : OnlineAligner
        An aligner built on ``derivative_features(I)``.

    Paper: OPW poster Section 6 (derivative DTW, Keogh and Pazzani).
    """

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

    def step(self, frame: Frame) -> int:
        """Receive target frame ``T_{n+1}`` (a pose), return ``M_{n+1}`` (inner aligner)."""
        if self.n_received == 0:
            self._diff.reset()
        return super().step(frame)

    def _step(self, q: int) -> int:
        orders = self.T_orders
        if len(orders) != np.shape(self._frame.quats)[0]:
            raise AlignmentError(
                f"target frame {self.n_received - 1}: {len(orders)} rotation orders for "
                f"{np.shape(self._frame.quats)[0]} joints"
            )
        return self.inner.step(self._diff(self._frame, orders))
