"""Fig. 3: forecast error (:mod:`fpdtw.forecast`) of smoothing levels ``s`` against frames
ahead ``i``, for dead reckoning, exponential smoothing and Holt's method.
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


def forecast_curves(features, levels, H: int) -> dict:
    """Mean forecast error per forecaster at ``1..H`` frames ahead: ndarray (len(levels), H),
    ``[l, i - 1]`` (:func:`fpdtw.forecast.forecast_error_curve`).

    Paper: FP-DTW Fig. 3.
    Notebook: 04_fig3_forecast.ipynb
    """
    features = list(features)
    return {m: forecast_error_curve(features, m, levels, H) for m, _ in FORECAST_PANELS}


def best_level(err, levels, i: int) -> int:
    """Smoothing level with the lowest error ``err`` (len(levels), H) at ``i`` frames ahead.

    Paper: FP-DTW Fig. 3 (s = 2 optimal per the paper's pilot study).
    Notebook: 04_fig3_forecast.ipynb
    """
    err = np.asarray(err, dtype=float)
    i = int(i)
    if not 1 <= i <= err.shape[1]:
        raise ValueError(f"frames ahead i must be in 1..{err.shape[1]}, got {i}")
    return int(list(levels)[int(np.argmin(err[:, i - 1]))])


def plot_forecast_error(err, levels, ax=None, title=None, logy=False):
    """Error ``err`` (len(levels), H) against frames ahead, one line per smoothing level.

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
    ax.set(xlim=(1, err.shape[1]), xlabel="frames ahead i")
    ax.set_ylabel("mean geodesic error (eq. 1, 8 joints)")
    if title:
        ax.set_title(title, fontsize=9)
    ax.legend(fontsize=8, title="level", title_fontsize=8)
    ax.grid(alpha=0.3)
    return fig, ax


def plot_forecast_panels(curves: dict, levels):
    """Fig. 3: one panel per forecaster of :func:`forecast_curves`, log error axis.

    Paper: FP-DTW Fig. 3.
    Notebook: 04_fig3_forecast.ipynb
    """
    titles = dict(FORECAST_PANELS)
    fig, axes = plt.subplots(1, len(curves), figsize=(4.6 * len(curves), 4), sharey=True)
    axes = list(np.ravel(axes))
    for ax, (method, err) in zip(axes, curves.items()):
        plot_forecast_error(err, levels, ax=ax, title=titles.get(method, method), logy=True)
    for ax in axes[1:]:
        ax.set_ylabel("")
    return fig, axes
