"""Figs. 2 and 4: the search windows of Methods A, B and C, each drawn from one
:class:`fpdtw.plain.Step` (Fig. 4's picked by :func:`first_leaving`).
"""

from __future__ import annotations

import matplotlib as mpl
import numpy as np
from matplotlib.lines import Line2D
from matplotlib.patches import Patch, Rectangle

from fpdtw.online.window import B_CORNER
from fpdtw.paper.figures.plotting import image, new_axes

#: Offsets of the second path cell when Method B's path leaves (0, 0): (row, column).
VIA_INPUT = (1, 0)  # advance one input frame within F_0 = T_n
VIA_TARGET = (0, 1)  # hold the input frame into F_1 = T_{n+1}


def _window_step(step, what: str):
    """``step`` if it is a plain window step (it has a window), else ValueError."""
    if step is None or step.kind != "window" or step.M_n is None:
        kind = None if step is None else step.kind
        raise ValueError(f"a {what} window step is needed, not a {kind!r} step")
    return step


def first_leaving(steps, via, q_min: int = 0):
    """The first Method B window step at or after target frame ``q_min`` whose path leaves
    (0, 0) via ``via`` (:data:`VIA_INPUT` or :data:`VIA_TARGET`), or None.

    Paper: FP-DTW Fig. 4 (two example steps).
    Notebook: 03_fig2_fig4_windows.ipynb
    """
    via = tuple(int(v) for v in via)
    drawn = (s for s in steps if s.kind == "window" and s.q >= q_min and s.path is not None)
    return next((s for s in drawn if len(s.path) > 1 and tuple(map(int, s.path[1])) == via), None)


def step_facts(step) -> dict:
    """What a drawn plain step did: ``q``, ``M_n``, ``w_i``, ``M`` (and ``leaves_via``).

    Paper: FP-DTW Figs. 2 and 4.
    Notebook: 03_fig2_fig4_windows.ipynb
    """
    out = {k: getattr(step, k) for k in ("q", "M_n", "w_i", "M")}
    return out if step.path is None else out | {"leaves_via": step.path[1]}


def plot_method_a_window(M, step, ax=None, before: int = 6, after: int = 1):
    """Fig. 2: one plain Method A step: the map so far (``before`` and ``after`` target
    frames around it), the window's costs (eq. 1) and the chosen cell.

    Paper: FP-DTW Fig. 2 (search window of the frame matching algorithm).
    Notebook: 03_fig2_fig4_windows.ipynb
    """
    s = _window_step(step, "Method A")
    q, start, w_i = int(s.q), int(s.M_n), int(s.w_i)
    fig, ax = new_axes(ax, figsize=(5.5, 6))
    t0 = max(0, q - before)
    t1 = q + after
    M = np.asarray(M, dtype=np.int64)[t0:q]
    r0 = max(0, int(M.min()) - 1) if M.size else max(0, start - 1)
    r1 = start + w_i + 1
    costs = np.asarray(s.C)[:, 0]
    grid = np.full((r1 - r0 + 1, t1 - t0 + 1), np.nan)
    grid[start - r0 : start - r0 + w_i + 1, q - t0] = costs
    span = max(float(costs.max() - costs.min()), 1e-6)
    im = ax.imshow(
        grid, origin="lower", cmap="YlOrRd", interpolation="nearest",
        extent=(t0 - 0.5, t1 + 0.5, r0 - 0.5, r1 + 0.5), aspect="equal",
        vmin=costs.min() - 0.3 * span, vmax=costs.max() + 0.1 * span, zorder=0,
    )  # fmt: skip
    fig.colorbar(im, ax=ax, label=f"geoDistance($I_i$, $T_{{{q}}}$) (eq. 1)", shrink=0.7)
    ax.set_xticks(np.arange(t1 - t0 + 2) + t0 - 0.5, minor=True)  # cell borders
    ax.set_yticks(np.arange(r1 - r0 + 2) + r0 - 0.5, minor=True)
    ax.grid(which="minor", color="0.8", lw=0.5)
    ax.tick_params(which="minor", length=0)
    ax.set_axisbelow(True)
    if M.size:
        ax.plot(np.arange(t0, q), M, "o-", color="0.3", ms=6, lw=1.2, zorder=3)
        ax.plot([q - 1, q], [M[-1], s.M], "--", color="tab:red", lw=1.2, zorder=3)
    ax.add_patch(_rect(q, start - 0.5, w_i + 1, color="tab:blue", lw=2.5))
    ax.add_patch(_rect(q, s.M - 0.5, 1, color="tab:red", lw=2.0, inset=0.08))
    for r, c in enumerate(costs):
        ax.text(q, start + r, f"{c:.3f}", ha="center", va="center", fontsize=6.5, zorder=4)
    handles = [
        Line2D([], [], marker="o", color="0.3", ms=6, label="map so far $M_t$"),
        Patch(fill=False, ec="tab:blue", lw=2,
              label=f"window $I_{{{start}}}..I_{{{start + w_i}}}$ ($w$ = {w_i})"),
        Patch(fill=False, ec="tab:red", lw=2,
              label=f"chosen $M_{{{q}}} = M_{{{q - 1}}} + {s.M - start} = {s.M}$"),
    ]  # fmt: skip
    ax.set(xlim=(t0 - 0.5, t1 + 0.5), ylim=(r0 - 0.5, r1 + 0.5), xticks=np.arange(t0, t1 + 1))
    ax.set_yticks(np.arange(r0, r1 + 1))
    ax.tick_params(labelsize=7)
    ax.set(xlabel="target frame (T)", ylabel="input frame (I)")
    ax.legend(handles=handles, loc="upper left", fontsize=7, framealpha=0.95)
    ax.set_title(f"Method A ($w$ = 2), target frame {q}", fontsize=9)
    return fig, ax


def _rect(x, y0, height, color, lw, inset=0.0):
    """Frame of the cells ``y0 .. y0 + height`` of column ``x``, ``inset`` inside."""
    return Rectangle((x - 0.5 + inset, y0 + inset), 1 - 2 * inset, height - 2 * inset,
                     fill=False, ec=color, lw=lw, zorder=5)  # fmt: skip


def _window_heatmap(ax, A, start, col_labels, label, hide_corner=False, annotate=True):
    """Heat map of a window matrix (rows input offsets, columns forecast frames), the
    non-finite cells and, with ``hide_corner``, ``A[0, 0]`` left blank."""
    A = np.asarray(A, dtype=float)
    shown = np.where(np.isfinite(A), A, np.nan)
    if hide_corner:
        shown[0, 0] = np.nan
    image(ax, shown, label, mpl.colormaps["viridis"].with_extremes(bad="0.92"))
    nr, nc = A.shape
    ax.set_xticks(np.arange(nc), col_labels, fontsize=7)
    rows = np.arange(0, nr, max(1, nr // 12))
    ax.set_yticks(rows, [f"{start + r}" for r in rows], fontsize=7)
    ax.set_xlabel("forecast window F (target frames)")
    ax.set_ylabel(f"input frame ($I_{{M_n + r}}$, $M_n$ = {start})")
    if annotate:
        vals = shown[np.isfinite(shown)]
        mid = 0.5 * (vals.min() + vals.max()) if vals.size else 0.0
        for r in range(nr):
            for c in range(nc):
                if np.isfinite(shown[r, c]):
                    colour = "white" if shown[r, c] < mid else "black"
                    ax.text(c, r, f"{A[r, c]:.2f}", ha="center", va="center", fontsize=5,
                            color=colour)  # fmt: skip


def _mark_x(ax, col, row, label):
    """The chosen cell of a window step as a large red X (in the legend as ``label``)."""
    ax.plot([col], [row], "x", color="tab:red", ms=12, mew=2.5, label=label)


def forecast_labels(n_cols: int, with_prev: bool) -> list:
    """Column labels of a forecast window, from ``T_n`` (``with_prev``, Method B) or ``T_{n+1}``."""
    first = ["$F_0$\n$=T_n$", "$F_1$\n$=T_{n+1}$"] if with_prev else ["$F_0$\n$=T_{n+1}$"]
    return (first + [f"$F_{{{c}}}$" for c in range(len(first), n_cols)])[:n_cols]


def plot_method_b_window(step, ax=None, which: str = "D", annotate=True):
    """Fig. 4: one plain Method B step: the window's D (or C, ``which``), its path and X
    (``D[0, 0]`` off the colour scale); ``annotate``: write every cell's value.

    Paper: FP-DTW Fig. 4 and Algorithm 2.
    Notebook: 03_fig2_fig4_windows.ipynb
    """
    s = _window_step(step, "Method B")
    if s.path is None:
        raise ValueError("a Method B window step (with a path) is needed")
    fig, ax = new_axes(ax, figsize=(6, 5))
    A = s.D if which == "D" else s.C
    label = "accumulated cost D" if which == "D" else "cost C (eq. 1)"
    _window_heatmap(ax, A, s.M_n, forecast_labels(A.shape[1], True), label, which == "D", annotate)
    extra = []
    if which == "D":
        ax.text(0, 0, f"{B_CORNER:.0f}", ha="center", va="center", fontsize=6, color="tab:red",
                fontweight="bold")  # fmt: skip
        extra = [
            Patch(fc="0.92", ec="tab:red", label="$D[0,0]$ = 10000 (set before back-tracking)")
        ]
    P = np.asarray(s.path)
    ax.plot(P[:, 1], P[:, 0], "-", color="white", lw=3.2)
    ax.plot(P[:, 1], P[:, 0], ".-", color="tab:red", lw=1.4, ms=5, label="back-tracked path")
    off = s.M - s.M_n
    _mark_x(ax, 1, off, f"X: $M_{{n+1}} = M_n + P_1 = {s.M_n} + {off} = {s.M}$")
    via = tuple(int(v) for v in P[1])
    ax.set_title(
        f"Method B ($w$ = {s.D.shape[1] - 1}), target frame {s.q}: path leaves (0,0) via "
        f"(r, c) = {via}",
        fontsize=9,
    )
    handles, _ = ax.get_legend_handles_labels()
    ax.legend(handles=handles + extra, fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.13))
    return fig, ax


def plot_method_c_window(step, ax=None):
    """One plain Method C step: the reverse-accumulated ``D`` and X, the argmin of column 0.

    Paper: FP-DTW Algorithm 3 (getReverseTotalCostMatrix, argmin of column 0).
    Notebook: 03_fig2_fig4_windows.ipynb
    """
    s = _window_step(step, "Method C")
    fig, ax = new_axes(ax, figsize=(6, 5))
    D = np.asarray(s.D)
    _window_heatmap(ax, D, s.M_n, forecast_labels(D.shape[1], False), "reverse-accumulated cost D")
    nr, nc = D.shape
    off = s.M - s.M_n
    _mark_x(ax, 0, off, f"X: argmin of column 0, $M_{{n+1}} = {s.M_n} + {off} = {s.M}$")
    ax.annotate(
        "accumulation\nstarts here", (nc - 1, nr - 1), xytext=(-95, -40),
        textcoords="offset points", fontsize=7, color="tab:red",
        bbox={"fc": "white", "ec": "none", "alpha": 0.8, "pad": 1},
        arrowprops={"arrowstyle": "->", "color": "tab:red"},
    )  # fmt: skip
    ax.set_title(
        f"Method C ($w$ = {D.shape[1]}), target frame {s.q}: reverse accumulation, argmin of $F_0$",
        fontsize=9,
    )
    ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.13))
    return fig, ax
