"""Figures of notebook 15: the readings of Algorithm 3 side by side, and their mechanism.

Notebook: 15_readings_of_algorithm_3.ipynb
"""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
import seaborn as sns

from fpdtw.paper.figures.plotting import new_axes


def plot_mechanism(profile: dict, ax=None, w=None):
    """Mean rest-of-path cost ``f(r) = D[r, 0] - C[r, 0]`` against the row offset r, one
    line per reading of :func:`fpdtw.paper.readings.mechanism_profile`; ``w`` for the title.

    Paper: FP-DTW Algorithm 3 (the window's declared size).
    Notebook: 15_readings_of_algorithm_3.ipynb
    """
    fig, ax = new_axes(ax, figsize=(6, 3.8))
    for reading, p in profile.items():
        if p["steps"] == 0:
            continue
        label = f"{reading}: f(0) - f(1) = {p['excess']:.2f} (median), holds {p['hold']:.1%}"
        ax.plot(p["r"], p["mean_f"], marker="o", ms=3, label=label)
    ax.set(xlabel="row offset r (input frame $M_n + r$)", ylabel="mean rest-of-path cost f(r)")
    title = "Method C: cost of the path after the first cell, per row"
    ax.set_title(title + (f" (w = {w})" if w else ""), fontsize=9)
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3)
    return fig, ax


def plot_readings_overview(rows, dataset: str, utw=None):
    """Per reading: median similarity against w at 120 and 60 Hz (``utw``: ``{rate_hz:
    median}``) and the stick/skip index, from :func:`fpdtw.paper.readings.readings_table`.

    Paper: FP-DTW Table 1, Section 5 (Fig. 7's sticking and skipping).
    Notebook: 15_readings_of_algorithm_3.ipynb
    """
    df = pd.DataFrame([r for r in rows if r["dataset"] == dataset and r["reading"] != "DTW"])
    if df.empty:
        raise ValueError(f"no reading rows for dataset {dataset!r}")
    df["constraint"] = np.where(df["type_v"], "+ Type V", "none")
    fig, axes = plt.subplots(1, 3, figsize=(13, 3.8), layout="constrained")
    panels = [
        (120, "similarity", "median similarity, 120 Hz"),
        (60, "similarity", "median similarity, 60 Hz"),
        (120, "stick_skip", "stick (< 0) / skip (> 0) index, 120 Hz"),
    ]
    for ax, (rate, col, title) in zip(axes, panels):
        sub = df[df["rate_hz"] == rate]
        sns.lineplot(data=sub, x="w", y=col, hue="reading", style="constraint", markers=True,
                     ax=ax, legend=ax is axes[-1])  # fmt: skip
        ax.set_xscale("log", base=2)
        ax.set_xticks(sorted(sub["w"].unique()), [str(int(w)) for w in sorted(sub["w"].unique())])
        ax.set_title(title, fontsize=9)
        ax.set_ylabel("stick/skip index" if col == "stick_skip" else "median similarity")
        ax.grid(alpha=0.3)
        if col == "stick_skip":
            ax.axhline(0.0, color="k", lw=0.8)
        elif utw and rate in utw:
            ax.axhline(utw[rate], color="tab:red", lw=1, ls="--", label="UTW median")
    if axes[-1].get_legend() is not None:
        sns.move_legend(axes[-1], "upper left", bbox_to_anchor=(1.02, 1), fontsize=7)
    return fig, axes
