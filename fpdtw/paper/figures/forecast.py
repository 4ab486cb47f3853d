"""Fig. 3: forecast error of smoothing levels ``s`` vs frames ahead ``i``.

The paper forecasts the live motion by dead reckoning from its last two frames
(``s = 2``) after "a pilot study", and its Fig. 3 shows the error of several smoothing
levels at predicting ``i`` frames ahead. We draw that for dead reckoning (velocity from
the ``s`` latest frames) and, with the same levels mapped to ``alpha = 2 / (s + 1)``,
for exponential smoothing and Holt's method (:mod:`fpdtw.forecast`). The error is the
mean geodesic distance (eq. 1, summed over the 8 joints) between forecast and actual
frame, over every start frame of every motion.
"""

from __future__ import annotations

import matplotlib as mpl
import matplotlib.pyplot as plt
import numpy as np

from fpdtw.forecast import forecast_error_curve
from fpdtw.paper.figures.plotting import new_axes

#: Forecasters of Fig. 3, with the titles of their panels.
FORECAST_PANELS = (
    ("dead_reckoning", "dead reckoning (velocity from the s latest frames)"),
    ("exponential", "exponential smoothing, alpha = 2/(s+1)"),
    ("holt", "Holt (level + trend), alpha = beta = 2/(s+1)"),
)
#: Smoothing levels drawn (the paper's choice, s = 2, first).
LEVELS = (2, 3, 4, 5, 6)
#: Largest number of frames ahead.
HORIZON = 40


def forecast_curves(features, levels=LEVELS, H: int = HORIZON, methods=None) -> dict:
    """Mean forecast error vs frames ahead for each forecaster and level.

    Parameters
    ----------
    features : sequence of MotionFeatures
    levels : sequence of int
    H : int
    methods : sequence of str, optional
        Default: every forecaster of :data:`FORECAST_PANELS`.

    Returns
    -------
    curves : dict of str to ndarray of float64, shape (len(levels), H)
        ``curves[method][l, i - 1]`` (:func:`fpdtw.forecast.forecast_error_curve`).

    Paper: FP-DTW Fig. 3.
    Notebook: 04_fig3_forecast.ipynb
    """
    methods = [m for m, _ in FORECAST_PANELS] if methods is None else list(methods)
    features = list(features)
    return {m: forecast_error_curve(features, m, levels, H) for m in methods}


def best_level(err, levels, i: int) -> int:
    """Smoothing level with the lowest error at ``i`` frames ahead (lowest level on ties).

    Parameters
    ----------
    err : ndarray of float, shape (len(levels), H)
    levels : sequence of int
    i : int
        Frames ahead, ``1..H``.

    Paper: FP-DTW Fig. 3 (s = 2 optimal per the paper's pilot study).
    Notebook: 04_fig3_forecast.ipynb
    """
    err = np.asarray(err, dtype=float)
    i = int(i)
    if not 1 <= i <= err.shape[1]:
        raise ValueError(f"frames ahead i must be in 1..{err.shape[1]}, got {i}")
    return int(list(levels)[int(np.argmin(err[:, i - 1]))])


def plot_forecast_error(err, levels, ax=None, title=None, logy=False):
    """Error vs frames ahead, one line per smoothing level.

    Parameters
    ----------
    err : ndarray of float, shape (len(levels), H)
    levels : sequence of int
    ax : Axes, optional
    title : str, optional
    logy : bool
        Logarithmic error axis.

    Returns
    -------
    fig, ax
        ``len(levels)`` lines.

    Paper: FP-DTW Fig. 3.
    """

    fig, ax = new_axes(ax, figsize=(5, 4))
    err = np.asarray(err, dtype=float)
    levels = list(levels)
    i = np.arange(1, err.shape[1] + 1)
    cmap = mpl.colormaps["plasma"]
    for li, s in enumerate(levels):
        color = cmap(0.85 * li / max(1, len(levels) - 1))
        ax.plot(i, err[li], color=color, lw=2.0 if li == 0 else 1.2, label=f"s = {s}")
    if logy:
        ax.set_yscale("log")
    ax.set_xlim(1, err.shape[1])
    ax.set_xlabel("frames ahead i")
    ax.set_ylabel("mean geodesic error (eq. 1, 8 joints)")
    if title:
        ax.set_title(title, fontsize=9)
    ax.legend(fontsize=8, title="level", title_fontsize=8)
    ax.grid(alpha=0.3)
    return fig, ax


def plot_forecast_panels(curves: dict, levels, axes=None, logy=True):
    """Fig. 3: one panel per forecaster (dead reckoning, exponential, Holt).

    Parameters
    ----------
    curves : dict of str to ndarray, shape (len(levels), H)
        From :func:`forecast_curves`.
    levels : sequence of int
    axes : sequence of Axes, optional
        One per entry of ``curves``.
    logy : bool

    Returns
    -------
    fig, axes

    Paper: FP-DTW Fig. 3.
    Notebook: 04_fig3_forecast.ipynb
    """

    titles = dict(FORECAST_PANELS)
    if axes is None:
        fig, axes = plt.subplots(1, len(curves), figsize=(4.6 * len(curves), 4), sharey=True)
    axes = list(np.ravel(axes))
    fig = axes[0].figure
    for ax, (method, err) in zip(axes, curves.items()):
        plot_forecast_error(err, levels, ax=ax, title=titles.get(method, method), logy=logy)
    for ax in axes[1:]:
        ax.set_ylabel("")
    return fig, axes


__all__ = [
    "FORECAST_PANELS",
    "HORIZON",
    "LEVELS",
    "best_level",
    "forecast_curves",
    "plot_forecast_error",
    "plot_forecast_panels",
]
