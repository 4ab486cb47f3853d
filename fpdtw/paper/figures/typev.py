"""Fig. 9: the Type V local continuity constraint, backward, forward and as a state table.

(i) the backward Rabiner-Juang Type V local paths, read from dtw-python's
``rabinerJuangStepPattern(5, "c")``; (ii) their forward form, the advance of the input
frame per target frame (0..3); (iii) the real state table of
:class:`fpdtw.online.TypeV`; (iv) a real constrained path (e.g. Ma + Type V) annotated
with the state in force at each step. Axes: target frames horizontal, input frames
vertical, as in every other figure.
"""

from __future__ import annotations

import matplotlib as mpl
import matplotlib.pyplot as plt
import numpy as np

from fpdtw.online.typev import TYPE_V, TypeV
from fpdtw.paper.figures.plotting import new_axes


def backward_steps(pattern=None) -> list:
    """The local paths of a dtw-python step pattern, as cells relative to the end cell.

    Parameters
    ----------
    pattern : dtw.StepPattern, optional
        Default ``rabinerJuangStepPattern(5, "c")`` (needs the ``dtw-python`` package).

    Returns
    -------
    steps : list of ndarray of int64, shape (L, 2)
        One per local path, cells ``(target, input)`` from the start cell to the end
        cell ``(0, 0)``, e.g. ``[[-3, -1], [-2, 0], [-1, 0], [0, 0]]``. dtw-python's
        ``.mx`` rows are ``(path, d_query, d_reference, weight)``; query = target.

    Paper: FP-DTW Fig. 9 i (Rabiner and Juang 1993, Type V).
    Notebook: 11_fig9_typev.ipynb
    """
    if pattern is None:
        from dtw import rabinerJuangStepPattern

        pattern = rabinerJuangStepPattern(5, "c")
    mx = np.asarray(pattern.mx)
    steps = []
    for p in np.unique(mx[:, 0]):
        rows = mx[mx[:, 0] == p]
        steps.append(-rows[:, 1:3].astype(np.int64))
    return steps


def forward_advances(steps) -> list:
    """Forward reading of each backward local path: input advance per target frame.

    The forward map keeps one input frame per target frame, the highest the path visits
    in that target frame (where the next window starts, see :mod:`fpdtw.online.typev`).

    Parameters
    ----------
    steps : list of ndarray, shape (L, 2)
        From :func:`backward_steps`.

    Returns
    -------
    advances : list of tuple of int
        For Type V: ``(1, 0, 0), (1, 0), (1,), (2,), (3,)``.

    Paper: FP-DTW Fig. 9 ii.
    Notebook: 11_fig9_typev.ipynb
    """
    out = []
    for S in steps:
        S = np.asarray(S)
        t = np.unique(S[:, 0])
        highest = np.array([S[S[:, 0] == k, 1].max() for k in t])
        out.append(tuple(int(a) for a in np.diff(highest)))
    return out


def typev_states(M, tv: TypeV = TYPE_V) -> list:
    """State in force when each target frame is mapped, replayed from a map.

    Parameters
    ----------
    M : array_like of int, shape (n + 1,)
        A legal Type V map (``M_0 = 0``).
    tv : TypeV

    Returns
    -------
    states : list of str, length n + 1
        ``states[0]`` is empty (``M_0 = 0`` is fixed); ``states[q]`` (q >= 1) is the
        state before choosing ``M_q``: the start state for q = 1, then the table's next
        state after each advance.

    Raises
    ------
    ValueError
        An advance the state does not allow.

    Paper: FP-DTW Fig. 9 iii-iv.
    Notebook: 11_fig9_typev.ipynb
    """
    M = np.asarray(M, dtype=np.int64)
    out = [""]
    state = tv.start
    for q in range(1, M.size):
        out.append(tv.states[state])
        nxt = tv.next_state(state, int(M[q] - M[q - 1]))
        if nxt < 0:
            raise ValueError(
                f"advance {int(M[q] - M[q - 1])} at target frame {q} is not allowed in state "
                f"{tv.states[state]}"
            )
        state = nxt
    return out


def table_rows(tv: TypeV = TYPE_V) -> list:
    """The state table as rows of dicts (for :func:`fpdtw.paper.figures.tables.save_table`).

    Returns
    -------
    rows : list of dict
        Keys ``state``, ``advance 0`` .. ``advance 3`` (next state or ``-``), ``meaning``.

    Paper: FP-DTW Fig. 9 iv.
    Notebook: 11_fig9_typev.ipynb
    """
    header, *body = tv.as_table()
    rows = []
    for r, meaning in zip(body, tv.meanings):
        row = {"state": r[0]}
        row.update({f"advance {a}": c for a, c in zip(header[1:], r[1:])})
        row["meaning"] = meaning
        rows.append(row)
    return rows


def _unit_grid(ax, xs, ys):
    ax.set_xticks(xs)
    ax.set_yticks(ys)
    ax.grid(color="0.85", lw=0.6)
    ax.set_aspect("equal")
    ax.tick_params(labelsize=7)


def _draw_local_paths(ax, paths, labels, ticks, title, legend):
    """Local paths (target, input) as coloured lines, slightly apart so that shared
    segments stay visible, on a unit grid with (0, 0) marked by a black square;
    ``legend``: the legend's title and location."""

    cmap = mpl.colormaps["tab10"]
    for k, (P, label) in enumerate(zip(paths, labels, strict=True)):
        jitter = 0.06 * (k - 2)
        ax.plot(P[:, 0] + jitter, P[:, 1] + jitter, "o-", color=cmap(k), ms=4, lw=1.5, label=label)
    ax.plot([0], [0], "s", color="black", ms=8)
    _unit_grid(ax, ticks, ticks)
    ax.set_xlabel("target frame (relative)")
    ax.set_ylabel("input frame (relative)")
    ax.set_title(title, fontsize=9)
    ax.legend(fontsize=7, title=legend[0], title_fontsize=7, loc=legend[1])


def plot_backward_steps(steps=None, ax=None):
    """Fig. 9 i: the backward Type V local paths ending at (0, 0).

    Returns
    -------
    fig, ax
        One line per local path.

    Paper: FP-DTW Fig. 9 i.
    """
    fig, ax = new_axes(ax, figsize=(4, 4))
    steps = [np.asarray(S) for S in (backward_steps() if steps is None else steps)]
    labels = [f"({-S[0, 0]}, {-S[0, 1]})" for S in steps]
    title = '(i) backward Type V\nrabinerJuangStepPattern(5, "c")'
    legend = ("step (target, input)", "lower left")
    _draw_local_paths(ax, steps, labels, np.arange(-3, 1), title, legend)
    return fig, ax


def plot_forward_steps(advances=None, ax=None):
    """Fig. 9 ii: the forward form: per target frame the input advances by 0..3.

    Each backward local path becomes a sequence of advances (:func:`forward_advances`),
    drawn from (0, 0) forwards; holds (advance 0) only follow an advance of exactly 1,
    at most two in a row.

    Returns the figure and axes: one line per local path, its advances in the legend.

    Paper: FP-DTW Fig. 9 ii.
    """
    fig, ax = new_axes(ax, figsize=(4, 4))
    advances = forward_advances(backward_steps()) if advances is None else advances
    paths = []
    for adv in advances:
        y = np.concatenate([[0], np.cumsum(adv)])
        paths.append(np.column_stack([np.arange(y.size), y]))
    labels = [", ".join(str(a) for a in adv) for adv in advances]
    title = "(ii) forward form: advances\nper target frame"
    _draw_local_paths(ax, paths, labels, np.arange(0, 4), title, ("advances", "upper left"))
    return fig, ax


def plot_state_table(tv: TypeV = TYPE_V, ax=None):
    """Fig. 9 iii-iv: the real state table as a table figure.

    Rows: states; columns: advance 0..3; cells: next state or ``-`` (not allowed).

    Returns
    -------
    fig, ax
        ``ax.tables[0]`` holds the table (``len(states) + 1`` rows x 5 columns).

    Paper: FP-DTW Fig. 9 iv.
    """
    fig, ax = new_axes(ax, figsize=(4, 2))
    header, *body = tv.as_table()
    cols = ["state"] + [f"adv. {a}" for a in header[1:]]
    tab = ax.table(cellText=body, colLabels=cols, loc="center", cellLoc="center")
    tab.auto_set_font_size(False)
    tab.set_fontsize(9)
    tab.scale(1.0, 1.6)
    for (r, c), cell in tab.get_celld().items():
        if r == 0 or c == 0:
            cell.set_text_props(fontweight="bold")
            cell.set_facecolor("0.9")
        elif cell.get_text().get_text() == "-":
            cell.set_facecolor("#f4cccc")
    ax.axis("off")
    start = tv.states[tv.start]
    ax.set_title(
        f"(iii-iv) state table: next state after each advance\n(start {start}; "
        "'-' = not allowed; advances > 3 never)",
        fontsize=9,
    )
    return fig, ax


def plot_constrained_path(M, ax=None, M_free=None, label="Ma + Type V", free_label="Ma"):
    """Fig. 9 (path): a real constrained map, each step annotated with its state.

    Parameters
    ----------
    M : array_like of int, shape (n + 1,)
        A legal Type V map (e.g. the first 30 target frames of Ma + Type V).
    ax : Axes, optional
    M_free : array_like of int, shape (n + 1,), optional
        The unconstrained map of the same method, drawn for comparison.
    label, free_label : str

    Returns
    -------
    fig, ax
        Lines: the constrained map (and the free one if given).

    Paper: FP-DTW Fig. 9 (the constraint applied to forward plotting).
    """
    fig, ax = new_axes(ax, figsize=(7, 4.5))
    M = np.asarray(M, dtype=np.int64)
    q = np.arange(M.size)
    states = typev_states(M)
    ax.plot(q, M, "o-", color="tab:purple", ms=4, lw=1.5, label=label, zorder=3)
    if M_free is not None:
        ax.plot(q, np.asarray(M_free), "s--", color="0.55", ms=3, lw=1, label=free_label, zorder=2)
    for t in range(1, M.size):
        ax.annotate(
            states[t],
            (t, M[t]),
            xytext=(0, 7),
            textcoords="offset points",
            ha="center",
            fontsize=6,
            color="tab:purple",
        )
    ax.set_xlabel("target frame")
    ax.set_ylabel("input frame")
    ax.set_title(
        "(path) state in force when each target frame is mapped (N: no hold allowed, "
        "A1: just advanced by 1, H1: held once)",
        fontsize=9,
    )
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="upper left")
    return fig, ax


def plot_fig9(M, M_free=None, axes=None):
    """Fig. 9: the four panels (backward, forward, table, constrained path).

    Returns
    -------
    fig, axes
        ``axes`` = [backward, forward, table, path].

    Paper: FP-DTW Fig. 9.
    Notebook: 11_fig9_typev.ipynb
    """

    if axes is None:
        fig = plt.figure(figsize=(12, 8.5), layout="constrained")
        gs = fig.add_gridspec(2, 3, height_ratios=[1, 1.05])
        axes = [
            fig.add_subplot(gs[0, 0]),
            fig.add_subplot(gs[0, 1]),
            fig.add_subplot(gs[0, 2]),
            fig.add_subplot(gs[1, :]),
        ]
    fig = axes[0].figure
    plot_backward_steps(ax=axes[0])
    plot_forward_steps(ax=axes[1])
    plot_state_table(ax=axes[2])
    plot_constrained_path(M, ax=axes[3], M_free=M_free)
    return fig, axes


__all__ = [
    "backward_steps",
    "forward_advances",
    "plot_backward_steps",
    "plot_constrained_path",
    "plot_fig9",
    "plot_forward_steps",
    "plot_state_table",
    "table_rows",
    "typev_states",
]
