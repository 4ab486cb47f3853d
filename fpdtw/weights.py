"""Per-joint weights of eq. 1 from the recorded motion (an open question, notebook 16).

FP-DTW's conclusion suggests pre-processing the recorded motion to weight its joints. The
rule here (committed in 0b05346, 2026-11-23, before Q2's first results in 97738ec, and
unchanged since; docs/history.md): each joint's weight is
proportional to how far it turns over the whole INPUT ``I`` (known in advance), measured
with eq. 1's own per-joint angle on the cost features' quaternions ``I.quats``.
"""

from __future__ import annotations

import numpy as np

from fpdtw.errors import AlignmentError


def joint_weights(I) -> np.ndarray:
    """Weights of eq. 1's joints: each joint's total angular travel in the input motion.

    ``travel_j = sum_{t >= 1} (2/pi) arccos |q_{t,j} . q_{t-1,j}|`` over the input's
    frames (the quaternions eq. 1 compares, ``I.quats``), and ``w = travel / mean(travel)``
    (mean 1). A still input (every travel zero) gets ``w = 1`` for every joint. There is
    no floor: a joint that never moves gets weight 0 and no longer counts in the cost.
    Eq. 1 becomes ``d = sum_j w_j (2/pi) arccos |q_{a,j} . q_{b,j}|``.

    Parameters
    ----------
    I : MotionFeatures or ndarray of float, shape (m + 1, k, 4)
        The input (recorded) motion, or its unit quaternions.

    Returns
    -------
    w : ndarray of float64, shape (k,)
        Non-negative, mean 1.

    Raises
    ------
    AlignmentError
        Quaternions not of shape (frames, k, 4), or not finite.

    Paper: FP-DTW Section 7 (conclusion: weighting joints by pre-processing the recording).
    Notebook: 16_open_questions.ipynb
    """
    Q = np.asarray(getattr(I, "quats", I), dtype=np.float64)
    name = getattr(I, "name", "input motion")
    if Q.ndim != 3 or Q.shape[2] != 4 or Q.shape[1] == 0:
        raise AlignmentError(f"{name}: expected quaternions (frames, k, 4), got {Q.shape}")
    if not np.all(np.isfinite(Q)):
        raise AlignmentError(f"{name}: quaternions are not all finite")
    dot = np.abs(np.sum(Q[1:] * Q[:-1], axis=2))  # (m, k)
    travel = (2.0 / np.pi) * np.arccos(np.minimum(dot, 1.0)).sum(axis=0)
    mean = travel.mean()
    if mean == 0.0:
        return np.ones(Q.shape[1])
    return travel / mean


__all__ = ["joint_weights"]
