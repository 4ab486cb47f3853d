"""The dominant period of a motion, and Method C's window from it (an open question).

The FP-DTW paper's conclusion suggests "restricting the size of the forecast window to less
than half the period of the movement cycle". The recorded input is known in advance, so its
period can be estimated before the live take starts. The rule (committed in cbb3316,
2026-11-23, before Q1's first results in cfc7b1d, and unchanged since; docs/history.md):

* the joint trajectories of the input (:func:`fpdtw.metrics.joint_trajectories` of its
  cost joints: 8 joints x 3 axes = 24 series), each with its mean removed; the biased
  autocorrelations of the 24 series averaged, each weighted by its variance:
  ``r[k] = sum_axes sum_t x_t x_{t+k} / sum_axes sum_t x_t^2``. The weights: an axis that
  barely moves (noise, or the second harmonic ``cos(theta)`` of a bone swinging by
  ``theta``) must not count as much as one that moves; with equal weights a bone swinging
  with period P gives a local maximum of about 0 at P / 2 (its two axes' autocorrelations
  cancel there) and the rule below would call the motion acyclic (tested);
* the period is the lag of the first local maximum (``r[k-1] < r[k] >= r[k+1]``) after
  the first zero crossing (first lag with ``r <= 0``), searched over lags of
  :data:`MIN_PERIOD_S` to :data:`MAX_PERIOD_S` seconds (0.25-4 s);
* acyclic: no zero crossing, no such maximum, or its autocorrelation below
  :data:`MIN_PEAK` (0.2): no period;
* the window is the largest integer below half the period, ``w = ceil(P / 2) - 1``
  (``P`` in frames), clamped to ``[2, 4 s]`` (480 frames at 120 Hz); without a period,
  the paper's recommended window, :data:`FALLBACK_W` = 40 frames at 120 Hz, scaled by
  the rate (20 at 60 Hz).

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
    """Mean autocorrelation of a motion's joint trajectories (the rule of the module).

    Parameters
    ----------
    quats : ndarray of float, shape (F, k, 4)
        Local rotations of the cost joints.

    Returns
    -------
    r : ndarray of float64, shape (F,)
        ``r[0] = 1``; lag k in frames (the variance-weighted mean of the 24 axes'
        autocorrelations). All zeros when nothing moves.

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
        Lag in frames of the first local maximum of :func:`autocorrelation` after its
        first zero crossing, within 0.25-4 s, if its value is at least 0.2.

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
    """Method C's window from a period in frames (None: the fallback), by the module's rule.

    Parameters
    ----------
    period : int or None
    fps : float

    Returns
    -------
    w : int
        ``ceil(period / 2) - 1`` clamped to ``[2, 4 s]``, or ``round(40 * fps / 120)``.

    Paper: FP-DTW Section 7.
    """
    if period is None:
        return max(MIN_W, int(round(FALLBACK_W * fps / 120.0)))
    w = int(math.ceil(period / 2.0)) - 1
    return int(min(max(w, MIN_W), int(math.floor(MAX_PERIOD_S * fps))))


def auto_window(I) -> int:
    """The window of "Mc auto" for the input motion ``I`` (a MotionFeatures).

    Returns
    -------
    w : int

    Paper: FP-DTW Section 7.
    Notebook: 16_open_questions.ipynb
    """
    return window_from_period(dominant_period(I.quats, I.fps), I.fps)


__all__ = [
    "FALLBACK_W",
    "MAX_PERIOD_S",
    "MIN_PEAK",
    "MIN_PERIOD_S",
    "MIN_W",
    "auto_window",
    "autocorrelation",
    "dominant_period",
    "window_from_period",
]
