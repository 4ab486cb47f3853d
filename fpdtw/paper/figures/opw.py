"""Figures of the OPW poster: warp curves (Fig. 4), deviation vs offset (Fig. 5), vs gamma (Fig. 6).

Each figure carries a footnote (gid ``"opw_note"``) saying what it draws and which clips.
"""

from __future__ import annotations

import textwrap

import matplotlib.pyplot as plt
import numpy as np

from fpdtw.paper.figures.plotting import new_axes
from fpdtw.paper.numbers import OPW_GAMMA, OPW_MAX_DEVIATION_MS, OPW_MEAN_DEVIATION_MS
from fpdtw.paper.numbers import PERCEPTUAL_THRESHOLD_MS as HOYET_MS
from fpdtw.paper.opw_eval import FIG4_MOTIONS, pooled

#: Colours of the curves (example, the baselines, OPW) in every OPW figure.
COLORS = {"example": "black", "DTW": "tab:blue", "best match": "tab:green", "OPW": "tab:orange"}


def clips_note(labels=None) -> str:
    """Which clips an OPW figure shows (labels of ``FIG4_MOTIONS``, default all), in words.

    Paper: OPW poster Section 4 (three CMU two-person clips, cropped to 2.5 s).
    """
    by = {m.label: m for m in FIG4_MOTIONS}
    labels = list(dict.fromkeys(labels)) if labels is not None else list(by)
    where = {"hdm05": "HDM05", "cmu": "CMU", "authors_fbx": "the FP-DTW authors'"}
    parts = []
    for lab in labels:
        m = by.get(lab)
        if m is None:
            parts.append(f"{lab}: not one of the poster's motions")
            continue
        stem = m.path.rsplit("/", 1)[-1].rsplit(".", 1)[0]
        kind = "stand-in" if m.why.startswith("stand-in") else "the poster's own source take"
        parts.append(f"{lab} = {where.get(m.dataset, m.dataset)} {stem} ({kind})")
    return (
        "Clips, chosen by a fixed rule to stand in for the poster's CMU two-person clips "
        "(fpdtw.paper.opw_eval.FIG4_MOTIONS): " + "; ".join(parts) + ". Each cropped to "
        "2.5 s; the live motion B is the clip A replayed through the example warp curve."
    )


def add_note(fig, text: str):
    """Put an OPW figure's footnote, wrapped to the figure's width."""
    width = max(60, int(fig.get_figwidth() * 16))
    wrapped = "\n".join(textwrap.fill(par, width) for par in text.split("\n"))
    fig.text(0.01, 0.0, wrapped, ha="left", va="top", fontsize=7.5, color="0.2", gid="opw_note")


def _labels_of(rows) -> list:
    return list(dict.fromkeys(r["motion"] for r in rows if "motion" in r))


def _threshold(ax):
    ax.axhline(HOYET_MS, color="tab:red", ls="--", lw=1, label=f"{HOYET_MS:.0f} ms")


def plot_warp_curves(result: dict, ax):
    """Example, baseline and OPW warp curves of one motion on ``ax``, keys marked.

    Paper: OPW poster Fig. 4 (top row).
    """
    D = result["duration"]
    t = np.linspace(0.0, D, 501)
    ax.plot([0, D], [0, D], color="0.7", lw=0.8, ls=":", label="identity")
    for name in ("example", result["baseline"], "OPW"):
        c = result["curves"][name]
        ax.plot(t, c(t), color=COLORS[name], lw=1.6 if name == "example" else 1.2, label=name)
        if name != "example":
            k = c.keys
            k = k[k[:, 0] <= D]
            ax.plot(k[:, 0], k[:, 1], "o" if name == "OPW" else "x", color=COLORS[name], ms=2.5)
    ax.set(xlim=(0, D), ylim=(0, D), aspect="equal", xlabel="live time t (s), motion B")
    ax.set_ylabel("warped time t' (s), motion A")


def plot_deviation(result: dict, ax=None):
    """Deviation (ms) of the baseline and OPW curves from the example curve (Fig. 4 middle).

    Paper: OPW poster Fig. 4 (middle row).
    """
    fig, ax = new_axes(ax)
    for name in (result["baseline"], "OPW"):
        d = result["deviation"][name]
        ax.plot(d["t"], d["ms"], color=COLORS[name], lw=1.2, label=f"{name} (mean {d['mean']:.0f})")
    _threshold(ax)
    ax.set_xlim(0, result["duration"])
    ax.set_ylim(0, max(HOYET_MS * 1.15, ax.get_ylim()[1]))
    ax.set(xlabel="live time t (s)", ylabel="deviation from example (ms)")
    return fig, ax


def plot_slope_change(result: dict, ax):
    """Change of slope between 50 Hz samples on ``ax``, % of 90 degrees.

    Paper: OPW poster Fig. 4 (bottom row).
    """
    for name in ("example", result["baseline"], "OPW"):
        s = result["slope"][name]
        ax.plot(
            s["t"], s["pct"], color=COLORS[name], lw=0.8 if name == "example" else 1.2,
            alpha=0.5 if name == "example" else 1.0, label=name,
        )  # fmt: skip
    ax.set_xlim(0, result["duration"])
    ax.set_ylim(bottom=0)
    ax.set(xlabel="live time t (s)", ylabel="slope change (%)")


def plot_fig4(results: list, labels: list):
    """Poster Fig. 4: one column per motion: warp curves, deviation, slope change.

    Paper: OPW poster Fig. 4.
    Notebook: 13_opw_fig4.ipynb
    """
    n = len(results)
    fig, axes = plt.subplots(3, n, figsize=(4.2 * n, 11), squeeze=False)
    for c, (res, lab) in enumerate(zip(results, labels)):
        for r, plot in enumerate((plot_warp_curves, plot_deviation, plot_slope_change)):
            plot(res, axes[r, c])
            if c:
                axes[r, c].set_ylabel("")
        axes[0, c].set_title(f"{lab}\n({res['name']})", fontsize=10)
    for row in axes[1:]:
        top = max(a.get_ylim()[1] for a in row)
        for a in row:
            a.set_ylim(0, top)
    for a in axes[1]:
        a.legend(fontsize=7, loc="upper right")
    axes[0, 0].legend(fontsize=7, loc="upper left")
    axes[2, 0].legend(fontsize=7, loc="upper right")
    fig.tight_layout()
    add_note(
        fig,
        "Top: warp curves t' = f(t), live time t of B against the time t' of A it shows "
        f"(black: the example curve g that made B; {results[0]['baseline']} and OPW: the curves "
        "they recover, marks at their keys; dotted: no warp). Middle: deviation |f(t) - g(t)| of "
        "each curve at 50 Hz, in ms (legend: its mean); dashed red: 150 ms (Hoyet et al.). "
        "Bottom: change of slope between 50 Hz samples, % of 90 degrees. "
        "One motion per column, no pooling, no whiskers.\n" + clips_note(labels),
    )
    return fig, axes


def _pooled_axes(ax, ticks, ticklabels, xlabel):
    """The 150 ms line, the x ticks and the labels of a figure of pooled boxes."""
    _threshold(ax)
    ax.set(xticks=ticks, xticklabels=ticklabels, xlabel=xlabel)
    ax.set_ylabel("deviation from example (ms)")
    ax.set_ylim(bottom=0)
    ax.legend(fontsize=8, loc="upper left")


def _boxes(ax, rows, key, values, positions, name, width, label):
    """Per value of ``key`` a box at ``positions`` over the samples ``ms`` of ``name``'s rows
    pooled, whiskers from minimum to maximum, black medians; a line through the means.
    Returns the pooled samples."""
    groups = [
        np.concatenate([r["ms"] for r in rows if r["method"] == name and r[key] == v])
        for v in values
    ]
    ax.boxplot(
        groups, positions=positions, widths=width, whis=(0, 100), patch_artist=True,
        showfliers=False, manage_ticks=False, boxprops=dict(facecolor=COLORS[name], alpha=0.55),
        medianprops=dict(color="black"),
    )  # fmt: skip
    ax.plot(positions, [g.mean() for g in groups], "-o", color=COLORS[name], ms=3, label=label)
    return groups


def plot_deviation_vs_offset(rows: list, *, baseline: str = "DTW", note=True):
    """Poster Fig. 5: deviation of ``baseline`` and OPW against the example's offset, one box
    per offset over every motion's 50 Hz samples pooled, a line through the means.

    Paper: OPW poster Fig. 5.
    Notebook: 14_opw_fig5_fig6.ipynb
    """
    fig, ax = plt.subplots(figsize=(8, 4.5))
    offsets = sorted({r["offset_s"] for r in rows})
    step = min(np.diff(offsets)) if len(offsets) > 1 else 0.1
    w = 0.35 * step
    for k, name in enumerate((baseline, "OPW")):
        pos = np.asarray(offsets) + (k - 0.5) * w * 1.1
        _boxes(ax, rows, "offset_s", offsets, pos, name, w, name)
    _pooled_axes(
        ax, offsets, [f"{o:.2f}" for o in offsets], "offset of the example curve's middle key (s)"
    )
    if note:
        add_note(
            fig,
            "Per offset and method one box over the 50 Hz deviation samples |f(t) - g(t)| of "
            "every motion pooled: box = quartiles, black line = median, whiskers = minimum to "
            "maximum of the pooled samples (no outliers left out); the line with dots joins "
            "the means of the pooled samples; dashed red: 150 ms.\n" + clips_note(_labels_of(rows)),
        )
    return fig, ax


def plot_deviation_vs_gamma(rows: list):
    """Poster Fig. 6: OPW's deviation against gamma, boxes as :func:`plot_deviation_vs_offset`.

    Paper: OPW poster Fig. 6.
    Notebook: 14_opw_fig5_fig6.ipynb
    """
    fig, ax = plt.subplots(figsize=(8, 4.5))
    rows = [r for r in rows if r["method"] == "OPW"]
    gammas = sorted({r["gamma"] for r in rows})
    pct = 100 * np.asarray(gammas)
    step = min(np.diff(pct)) if len(pct) > 1 else 1.0
    groups = _boxes(ax, rows, "gamma", gammas, pct, "OPW", 0.6 * step, "OPW mean")
    ax.plot(pct, [g.max() for g in groups], "--", color=COLORS["OPW"], lw=1, label="OPW max")
    every = max(1, len(pct) // 15)
    _pooled_axes(ax, pct[::every], [f"{p:.0f}" for p in pct[::every]], "warp parameter gamma (%)")
    add_note(
        fig,
        "Per gamma one box over OPW's 50 Hz deviation samples |f(t) - g(t)| of every "
        "motion pooled: box = quartiles, black line = median, whiskers = minimum to "
        "maximum of the pooled samples; solid line with dots: their mean; dashed: their "
        "maximum; dashed red: 150 ms.\n" + clips_note(_labels_of(rows)),
    )
    return fig, ax


def plot_readings(sweeps):
    """OPW's pooled deviation against gamma under each reading (``(OPWReading, sweep rows)``
    pairs), beside the poster's numbers; log axis.

    Paper: OPW poster Figs. 4 and 6; the authors' MotionBuilder plugin.
    Notebook: 14_opw_fig5_fig6.ipynb
    """
    fig, ax = plt.subplots(figsize=(8, 4.8))
    cmap = plt.get_cmap("tab10")
    for k, (rd, rows) in enumerate(sweeps):
        gs = sorted({r["gamma"] for r in rows})
        stats = [pooled(rows, "OPW", gamma=g) for g in gs]
        pct = 100 * np.asarray(gs)
        c = cmap(k % 10)
        ax.plot(pct, [s["mean_ms"] for s in stats], "-o", color=c, ms=2.5, lw=1.3, label=rd.name)
        ax.plot(pct, [s["max_ms"] for s in stats], "--", color=c, lw=0.9)
    lo, hi = OPW_MEAN_DEVIATION_MS
    g5 = 100 * OPW_GAMMA
    ax.plot([g5, g5], [lo, hi], "-", color="black", lw=4, alpha=0.6,
            label=f"poster: mean {lo:.0f}-{hi:.0f} ms")  # fmt: skip
    ax.plot([g5], [OPW_MAX_DEVIATION_MS], "kx", ms=8,
            label=f"poster: max {OPW_MAX_DEVIATION_MS:.0f} ms")  # fmt: skip
    ax.axhline(HOYET_MS, color="tab:red", ls=":", lw=1, label=f"{HOYET_MS:.0f} ms")
    ax.set(yscale="log", xlabel="warp parameter gamma (%)")
    ax.set_ylabel("deviation from example (ms): mean solid, max dashed")
    ax.legend(fontsize=7, loc="upper left", ncol=2)
    add_note(
        fig,
        "One colour per reading of OPW: solid = mean, dashed = maximum of the 50 Hz "
        "deviation samples |f(t) - g(t)| of every motion pooled, per gamma (no whiskers). "
        "Black bar: the poster's mean range at gamma 5 %; cross: its maximum; dotted red: "
        "150 ms.\n" + clips_note([lab for _, rows in sweeps for lab in _labels_of(rows)]),
    )
    return fig, ax


def plot_curve_construction(curve, *, window=None, relative=False, label=None):
    """A warp curve with its keys and Bezier control polygons (poster Fig. 2, Table 1).

    ``window``: the live-time range shown; ``relative``: plot ``t' - t``; ``label``: the
    motion, whose clip the footnote names.

    Paper: OPW poster Fig. 2 and Table 1.
    Notebook: 13_opw_fig4.ipynb
    """
    fig, ax = plt.subplots()
    lo, hi = window if window is not None else (curve.x[0], curve.x[-1])
    t = np.linspace(lo, hi, 400)
    sh = 1.0 if relative else 0.0
    ax.plot(t, curve(t) - sh * t, color=COLORS["OPW"], lw=1.5, label="warp curve")
    shown = [P.copy() for P in curve.control_points() if P[3, 0] >= lo and P[0, 0] <= hi]
    for i, P in enumerate(shown):
        P[:, 1] -= sh * P[:, 0]
        ax.plot(P[:2, 0], P[:2, 1], "-", color="0.5", lw=0.8)
        ax.plot(P[2:, 0], P[2:, 1], "-", color="0.5", lw=0.8)
        ax.plot(
            P[1:3, 0], P[1:3, 1], "s", color="0.5", ms=3,
            label="control points P1, P2" if i == 0 else None,
        )  # fmt: skip
    k = curve.keys
    k = k[(k[:, 0] >= lo) & (k[:, 0] <= hi)]
    ax.plot(k[:, 0], k[:, 1] - sh * k[:, 0], "o", color="black", ms=4, label="keys P0, P3")
    ax.set(xlim=(lo, hi), xlabel="live time t (s)")
    ax.set_ylabel("t' - t (s)" if relative else "warped time t' (s)")
    ax.legend(fontsize=8)
    add_note(
        fig,
        "Orange: the warp curve"
        + (" minus the identity (a shear)" if relative else "")
        + "; black dots: its keys (P0, P3 of each Bezier segment); grey squares joined "
        "to the keys: the control points P1, P2 (handles), collinear through each key."
        + ("\n" + clips_note([label]) if label is not None else ""),
    )
    return fig, ax
