"""Per-joint weights of eq. 1 from the recorded motion (an open question, notebook 16).

FP-DTW's conclusion suggests pre-processing the recorded motion to weight its joints. The
rule (committed in 0b05346, before Q2's first results in 97738ec, and unchanged since;
docs/history.md): each joint's weight is proportional to how far it turns over the whole
INPUT, measured with eq. 1's own per-joint angle.
"""

from __future__ import annotations

import numpy as np

from fpdtw.errors import AlignmentError


def joint_weights(I) -> np.ndarray:
    """Weights of eq. 1's joints: each joint's total angular travel in the input motion.

    ``travel_j = sum_{t >= 1} (2/pi) arccos |q_{t,j} . q_{t-1,j}|`` over ``I.quats`` and
    ``w = travel / mean(travel)``; a still input gets 1 for every joint. No floor: a joint
    that never moves gets weight 0.

    Parameters
    ----------
    I : MotionFeatures or ndarray of float, shape (m + 1, k, 4)
        The input (recorded) motion, or its unit quaternions.

    Returns
    -------
    w : ndarray of float64, shape (k,)

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
