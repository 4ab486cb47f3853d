"""Fig. 9: the Type V local continuity constraint, backward, forward and as a state table."""

from __future__ import annotations

import matplotlib as mpl
import matplotlib.pyplot as plt
import numpy as np

from fpdtw.online.typev import TYPE_V
from fpdtw.paper.figures.plotting import new_axes


def backward_steps(pattern=None) -> list:
    """The local paths of a dtw-python step pattern (default Type V), as int64 cells
    ``(target, input)`` (L, 2) from the start cell to the end cell ``(0, 0)``.

    Paper: FP-DTW Fig. 9 i (Rabiner and Juang 1993, Type V).
    Notebook: 11_fig9_typev.ipynb
    """
    if pattern is None:
        from dtw import rabinerJuangStepPattern

        pattern = rabinerJuangStepPattern(5, "c")
    mx = np.asarray(pattern.mx)
    return [-mx[mx[:, 0] == p][:, 1:3].astype(np.int64) for p in np.unique(mx[:, 0])]


def forward_advances(steps) -> list:
    """Each backward local path read forwards: the input's advance per target frame (to the
    highest input frame visited). For Type V: ``(1, 0, 0), (1, 0), (1,), (2,), (3,)``.

    Paper: FP-DTW Fig. 9 ii.
    Notebook: 11_fig9_typev.ipynb
    """
    out = []
    for S in steps:
        S = np.asarray(S)
        highest = np.array([S[S[:, 0] == k, 1].max() for k in np.unique(S[:, 0])])
        out.append(tuple(int(a) for a in np.diff(highest)))
    return out


def typev_states(M) -> list:
    """The state in force when each target frame of a legal Type V map is mapped (``""``
    for ``M_0``); ValueError on an advance the state does not allow.

    Paper: FP-DTW Fig. 9 iii-iv.
    Notebook: 11_fig9_typev.ipynb
    """
    M = np.asarray(M, dtype=np.int64)
    out = [""]
    state = TYPE_V.start
    for q in range(1, M.size):
        out.append(TYPE_V.states[state])
        adv = int(M[q] - M[q - 1])
        state = TYPE_V.next_state(state, adv)
        if state < 0:
            raise ValueError(f"advance {adv} at target frame {q} is not allowed in state {out[-1]}")
    return out


def table_rows() -> list:
    """The state table as rows: ``state``, ``advance 0`` .. ``advance 3``, ``meaning``.

    Paper: FP-DTW Fig. 9 iv.
    Notebook: 11_fig9_typev.ipynb
    """
    header, *body = TYPE_V.as_table()
    return [
        {"state": r[0], **{f"advance {a}": c for a, c in zip(header[1:], r[1:])}, "meaning": m}
        for r, m in zip(body, TYPE_V.meanings)
    ]


def _draw_local_paths(ax, paths, labels, ticks, title, legend):
    """Local paths as coloured lines, slightly apart, on a unit grid with (0, 0) marked."""
    cmap = mpl.colormaps["tab10"]
    for k, (P, label) in enumerate(zip(paths, labels, strict=True)):
        jitter = 0.06 * (k - 2)
        ax.plot(P[:, 0] + jitter, P[:, 1] + jitter, "o-", color=cmap(k), ms=4, lw=1.5, label=label)
    ax.plot([0], [0], "s", color="black", ms=8)
    ax.set(xticks=ticks, yticks=ticks)
    ax.grid(color="0.85", lw=0.6)
    ax.set_aspect("equal")
    ax.tick_params(labelsize=7)
    ax.set(xlabel="target frame (relative)", ylabel="input frame (relative)")
    ax.set_title(title, fontsize=9)
    ax.legend(fontsize=7, title=legend[0], title_fontsize=7, loc=legend[1])


def plot_state_table(ax=None):
    """Fig. 9 iii-iv: the state table as a table figure (``ax.tables[0]``).

    Paper: FP-DTW Fig. 9 iv.
    """
    fig, ax = new_axes(ax, figsize=(4, 2))
    header, *body = TYPE_V.as_table()
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
    start = TYPE_V.states[TYPE_V.start]
    ax.set_title(
        f"(iii-iv) state table: next state after each advance\n(start {start}; "
        "'-' = not allowed; advances > 3 never)",
        fontsize=9,
    )
    return fig, ax


def plot_constrained_path(M, ax=None, M_free=None):
    """Fig. 9 (path): an Ma + Type V map annotated with its states, beside ``M_free``.

    Paper: FP-DTW Fig. 9 (the constraint applied to forward plotting).
    """
    fig, ax = new_axes(ax, figsize=(7, 4.5))
    M = np.asarray(M, dtype=np.int64)
    q = np.arange(M.size)
    states = typev_states(M)
    ax.plot(q, M, "o-", color="tab:purple", ms=4, lw=1.5, label="Ma + Type V", zorder=3)
    if M_free is not None:
        ax.plot(q, np.asarray(M_free), "s--", color="0.55", ms=3, lw=1, label="Ma", zorder=2)
    for t in range(1, M.size):
        ax.annotate(states[t], (t, M[t]), xytext=(0, 7), textcoords="offset points",
                    ha="center", fontsize=6, color="tab:purple")  # fmt: skip
    ax.set(xlabel="target frame", ylabel="input frame")
    ax.set_title(
        "(path) state in force when each target frame is mapped (N: no hold allowed, "
        "A1: just advanced by 1, H1: held once)",
        fontsize=9,
    )
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="upper left")
    return fig, ax


def plot_fig9(M, M_free=None):
    """Fig. 9: the four panels (backward, forward, table, constrained path).

    Paper: FP-DTW Fig. 9.
    Notebook: 11_fig9_typev.ipynb
    """
    fig = plt.figure(figsize=(12, 8.5), layout="constrained")
    gs = fig.add_gridspec(2, 3, height_ratios=[1, 1.05])
    axes = [fig.add_subplot(gs[0, k]) for k in range(3)] + [fig.add_subplot(gs[1, :])]
    steps = backward_steps()  # (i) backward, ending at (0, 0)
    labels = [f"({-S[0, 0]}, {-S[0, 1]})" for S in steps]
    title = '(i) backward Type V\nrabinerJuangStepPattern(5, "c")'
    _draw_local_paths(
        axes[0], steps, labels, np.arange(-3, 1), title, ("step (target, input)", "lower left")
    )
    advances = forward_advances(steps)  # (ii) forward: the input's advance per target frame
    paths = [
        np.column_stack([np.arange(len(a) + 1), np.concatenate([[0], np.cumsum(a)])])
        for a in advances
    ]
    labels = [", ".join(str(a) for a in adv) for adv in advances]
    title = "(ii) forward form: advances\nper target frame"
    _draw_local_paths(axes[1], paths, labels, np.arange(0, 4), title, ("advances", "upper left"))
    plot_state_table(ax=axes[2])
    plot_constrained_path(M, ax=axes[3], M_free=M_free)
    return fig, axes
