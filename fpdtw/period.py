"""The dominant period of a motion, and Method C's window from it (an open question).

FP-DTW's conclusion suggests "restricting the size of the forecast window to less than half
the period of the movement cycle"; the input is known in advance, so its period can be
estimated first. The rule (committed in cbb3316, before Q1's first results in cfc7b1d, and
unchanged since; docs/history.md):

* ``r[k]``: the biased autocorrelations of the input's joint trajectories (24 series, means
  removed), summed and divided by their total energy, i.e. weighted by variance (with equal
  weights a bone swinging with period P cancels to about 0 at P / 2; tested);
* the period: the lag of the first local maximum of ``r`` after its first zero crossing,
  within :data:`MIN_PERIOD_S`-:data:`MAX_PERIOD_S`, if at least :data:`MIN_PEAK`; else none;
* the window: ``ceil(P / 2) - 1`` frames clamped to ``[2, 4 s]``; without a period,
  :data:`FALLBACK_W` (the paper's 40 at 120 Hz) scaled by the rate.

Paper: FP-DTW Section 7 (conclusion: the window below half the movement's period).
Notebook: 16_open_questions.ipynb
"""

from __future__ import annotations

import math

import numpy as np

from fpdtw.errors import AlignmentError
from fpdtw.metrics import joint_trajectories

#: Shortest and longest period searched, in seconds.
MIN_PERIOD_S, MAX_PERIOD_S = 0.25, 4.0
#: Smallest autocorrelation of the peak for a motion to count as cyclic.
MIN_PEAK = 0.2
#: The paper's recommended window at 120 Hz (the fallback; scaled by the rate).
FALLBACK_W = 40
#: Smallest window.
MIN_W = 2


def autocorrelation(quats) -> np.ndarray:
    """Mean autocorrelation of a motion's joint trajectories (the module's rule).

    Parameters
    ----------
    quats : ndarray of float, shape (F, k, 4)
        Local rotations of the cost joints.

    Returns
    -------
    r : ndarray of float64, shape (F,)
        By lag in frames, ``r[0] = 1``; all zeros when nothing moves.

    Paper: FP-DTW Section 7.
    Notebook: 16_open_questions.ipynb
    """
    X = joint_trajectories(quats)
    F = X.shape[0]
    X = X.reshape(F, -1)
    X = X - X.mean(axis=0)
    energy = float(np.sum(X * X))
    if F == 0 or not energy > 0:
        return np.zeros(F)
    n = 1 << int(math.ceil(math.log2(2 * F)))
    spec = np.fft.rfft(X, n=n, axis=0)
    acf = np.fft.irfft(spec * np.conj(spec), n=n, axis=0)[:F]
    return np.sum(acf, axis=1) / energy


def dominant_period(quats, fps: float):
    """The dominant period of a motion in frames, or None when it is acyclic.

    Parameters
    ----------
    quats : ndarray of float, shape (F, k, 4)
    fps : float
        Frame rate (Hz).

    Returns
    -------
    period : int or None
        In frames (the module's rule).

    Paper: FP-DTW Section 7.
    Notebook: 16_open_questions.ipynb
    """
    if not fps > 0:
        raise AlignmentError(f"frame rate must be positive, got {fps!r}")
    r = autocorrelation(quats)
    below = np.flatnonzero(r <= 0)
    if below.size == 0:
        return None
    lo = max(int(below[0]), int(math.ceil(MIN_PERIOD_S * fps)), 1)
    hi = min(int(math.floor(MAX_PERIOD_S * fps)), r.size - 2)
    for k in range(lo, hi + 1):
        if r[k - 1] < r[k] >= r[k + 1]:
            return k if r[k] >= MIN_PEAK else None
    return None


def window_from_period(period, fps: float) -> int:
    """Method C's window (int) from a period in frames (None: the fallback) at ``fps``.

    Paper: FP-DTW Section 7.
    """
    if period is None:
        return max(MIN_W, int(round(FALLBACK_W * fps / 120.0)))
    w = int(math.ceil(period / 2.0)) - 1
    return int(min(max(w, MIN_W), int(math.floor(MAX_PERIOD_S * fps))))


def auto_window(I) -> int:
    """The window (int) of "Mc auto" for the input motion ``I`` (a MotionFeatures).

    Paper: FP-DTW Section 7.
    Notebook: 16_open_questions.ipynb
    """
    return window_from_period(dominant_period(I.quats, I.fps), I.fps)
