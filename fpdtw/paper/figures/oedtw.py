"""Fig. 1: open-end DTW's end points jump backwards between consecutive target frames."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.ticker import MaxNLocator

from fpdtw.online import OEDTW, run_online
from fpdtw.paper.figures.plotting import image, new_axes


def backward_jumps(E) -> np.ndarray:
    """Target frames ``q`` (int64) with ``E[q + 1] < E[q]``, in the end points ``E`` (n + 1,).

    Paper: FP-DTW Fig. 1.
    """
    E = np.asarray(E, dtype=np.int64)
    if E.ndim != 1:
        raise ValueError(f"expected a 1-d sequence of end points, got shape {E.shape}")
    return np.flatnonzero(np.diff(E) < 0).astype(np.int64)


def first_backward_jump(E):
    """The first backward jump ``(q, e_q, e_{q+1})``, or None.

    Paper: FP-DTW Fig. 1 (the paper's example is q = 15 -> 16).
    """
    E = np.asarray(E, dtype=np.int64)
    jumps = backward_jumps(E)
    if jumps.size == 0:
        return None
    q = int(jumps[0])
    return q, int(E[q]), int(E[q + 1])


def run_oedtw(I, T, **kwargs) -> OEDTW:
    """Run OE-DTW (``kwargs``: ``step_pattern``, ``normalize``) over a whole target.

    Notebook: 02_fig1_oedtw.ipynb
    """
    oe = OEDTW(I, **kwargs)
    run_online(oe, T)
    return oe


def oedtw_facts(E) -> dict:
    """Fig. 1's facts: frames, the jumps, the frames gone back and the first jump."""
    E = np.asarray(E, dtype=np.int64)
    jumps = backward_jumps(E)
    first = first_backward_jump(E)
    return {
        "n_frames": int(E.size),
        "jumps": int(jumps.size),
        "jump_frames": [int(q) for q in jumps],
        "frames_back": int((E[jumps] - E[jumps + 1]).sum()),
        "first_jump": None if first is None else dict(zip(("q", "e_q", "e_q1"), first)),
    }


def plot_oedtw_paths(oe: OEDTW, q: int, ax=None):
    """Fig. 1 (a): the paths of target frames q and q + 1 over OE-DTW's ``D``, end points marked.

    Paper: FP-DTW Fig. 1 (paths of frames 15 and 16).
    """
    fig, ax = new_axes(ax, figsize=(5, 5))
    q = int(q)
    E = np.asarray(oe.end_points)
    if q + 1 >= E.size:
        raise ValueError(f"OE-DTW has {E.size} target frames; frame q + 1 = {q + 1} is missing")
    D = oe.D[:, : q + 2]
    rows = min(max(q + 2, int(E[: q + 2].max()) + 1) + 8, D.shape[0])
    image(ax, D[:rows], "accumulated cost D")
    for t, color, style in ((q, "white", "-"), (q + 1, "tab:red", "--")):
        P = oe.path(t)
        label = f"path of frame {t}, ends at e = {int(E[t])}"
        ax.plot(P[:, 1], P[:, 0], style, color=color, lw=2, label=label)
    ax.plot(np.arange(q + 2), E[: q + 2], "o", color="orange", ms=3.5, mec="black", mew=0.4,
            label="end point $e_t$ of each frame")  # fmt: skip
    for t, xytext, color in ((q, (-60, 14), "white"), (q + 1, (-40, -34), "tab:red")):
        ax.annotate(f"$e_{{{t}}} = {int(E[t])}$", (t, E[t]), xytext=xytext,
                    textcoords="offset points", color=color, fontsize=9,
                    arrowprops={"arrowstyle": "-", "color": color})  # fmt: skip
    ax.set(xlim=(-0.5, q + 1.5), ylim=(-0.5, rows - 0.5))
    ax.xaxis.set_major_locator(MaxNLocator(integer=True))
    ax.yaxis.set_major_locator(MaxNLocator(integer=True))
    ax.set(xlabel="target frame t", ylabel="input frame i")
    ax.legend(loc="upper left", fontsize=7, facecolor="0.75", framealpha=0.9)
    return fig, ax


def plot_end_points(E, ax=None):
    """Fig. 1 (b): every target frame's end point, jumps marked, an inset at the first.

    Paper: FP-DTW Fig. 1 (lack of continuity between consecutive frames).
    """
    fig, ax = new_axes(ax, figsize=(5, 4))
    E = np.asarray(E, dtype=np.int64)
    jumps = backward_jumps(E)

    def draw(a, lo, hi, marker_size):
        q = np.arange(lo, hi)
        a.plot(q, E[lo:hi], ".-", color="tab:blue", lw=1.0, ms=marker_size, label="end point $e_q$")
        a.plot([lo, hi - 1], [lo, hi - 1], ":", color="gray", lw=0.8, label="1:1")
        sel = jumps[(jumps + 1 >= lo) & (jumps + 1 < hi)]
        if sel.size:
            a.plot(sel + 1, E[sel + 1], "v", color="tab:red", ms=7, ls="none",
                   label=f"backward jump, $e_{{q+1}} < e_q$ ({jumps.size} in all)")  # fmt: skip

    draw(ax, 0, E.size, 0)
    ax.set(xlim=(0, E.size - 1), ylim=(0, max(int(E.max()), E.size - 1)), xlabel="target frame q")
    ax.set_ylabel("input frame (end point $e_q$)")
    ax.legend(loc="upper left", fontsize=8)
    if jumps.size:
        j, zoom = int(jumps[0]), 6
        lo, hi = max(0, j - zoom), min(E.size, j + zoom + 2)
        ins = ax.inset_axes([0.55, 0.08, 0.42, 0.42])
        draw(ins, lo, hi, 5)
        ins.set_xlim(lo - 0.5, hi - 0.5)
        ys = E[lo:hi]
        ins.set_ylim(min(ys.min(), lo) - 1, max(ys.max(), hi - 1) + 1)
        ins.xaxis.set_major_locator(MaxNLocator(integer=True))
        ins.yaxis.set_major_locator(MaxNLocator(integer=True))
        ins.tick_params(labelsize=7)
        ins.grid(alpha=0.3)
        ins.set_title(
            f"first jump: $e_{{{j}}} = {int(E[j])}$, $e_{{{j + 1}}} = {int(E[j + 1])}$", fontsize=8
        )
        ax.indicate_inset_zoom(ins, edgecolor="0.4")
    return fig, ax


def plot_fig1(oe: OEDTW):
    """Fig. 1: (a) the paths at the first backward jump (or the middle), (b) all end points.

    Paper: FP-DTW Fig. 1.
    Notebook: 02_fig1_oedtw.ipynb
    """
    E = np.asarray(oe.end_points)
    first = first_backward_jump(E)
    q = first[0] if first is not None else max(0, E.size // 2 - 1)
    fig, axes = plt.subplots(1, 2, figsize=(11.5, 5), layout="constrained")
    plot_oedtw_paths(oe, q, ax=axes[0])
    axes[0].set_title(f"(a) OE-DTW paths of target frames {q} and {q + 1}", fontsize=10)
    plot_end_points(E, ax=axes[1])
    axes[1].set_title("(b) end point of every target frame", fontsize=10)
    return fig, axes
