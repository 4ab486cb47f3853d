"""Figure helpers: one function saves every figure; one style marks what is beyond the paper."""

from __future__ import annotations

import io
import os
import sys
from pathlib import Path

import matplotlib

# headless by default; inside Jupyter the kernel's inline backend is kept
if os.environ.get("MPLBACKEND") is None and "ipykernel" not in sys.modules:
    matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.patches import Patch

from fpdtw.errors import AlignmentError
from fpdtw.paper.atomic import write_atomic
from fpdtw.paper.numbers import PAPER_NAMES  # noqa: E402
from fpdtw.paper.paths import figures_dir  # noqa: E402
from fpdtw.registry import name as canonical
from fpdtw.registry import resolve

_PDF_META = {"CreationDate": None, "ModDate": None, "Creator": None, "Producer": None}
_PNG_META = {"Software": None}


def new_axes(ax=None, **subplots_kw):
    """``(fig, ax)``: the given axes' figure, or a new figure and axes."""
    return (ax.figure, ax) if ax is not None else plt.subplots(**subplots_kw)


def image(ax, A, label: str, cmap="viridis"):
    """A matrix as an image (rows upwards) with its colour bar beside the axes."""
    im = ax.imshow(A, origin="lower", aspect="auto", cmap=cmap, interpolation="nearest")
    ax.figure.colorbar(im, ax=ax, label=label, fraction=0.046, pad=0.04)


def save_figure(fig, name: str) -> list[Path]:
    """Save a figure as ``<name>.pdf`` and ``<name>.png`` in
    :func:`fpdtw.paper.paths.figures_dir` with stable metadata; returns both paths."""
    out = []
    with matplotlib.rc_context({"svg.hashsalt": "fpdtw", "pdf.compression": 6}):
        for ext, meta in (("pdf", _PDF_META), ("png", _PNG_META)):
            buf = io.BytesIO()
            fig.savefig(buf, format=ext, dpi=150, metadata=meta, bbox_inches="tight")
            out.append(write_atomic(figures_dir() / f"{name}.{ext}", buf.getvalue()))
    return out


#: The words that mark an algorithm the FP-DTW paper does not evaluate.
BEYOND_PAPER_LABEL = "beyond the paper"
#: Boxes and bars of such an algorithm: light grey, hatched, grey edge.
BEYOND_PAPER_PATCH = {"facecolor": "0.9", "hatch": "////", "edgecolor": "0.45"}
#: Tick labels and panel titles of such an algorithm.
BEYOND_PAPER_TEXT = {"color": "0.4", "fontstyle": "italic"}


def beyond_paper(name: str) -> bool:
    """True for an algorithm name the FP-DTW paper does not evaluate: all but
    :data:`fpdtw.paper.numbers.PAPER_NAMES`, also at 60 Hz and under the literal window."""
    base = name.removesuffix("@60Hz")
    if base in PAPER_NAMES:
        return False
    try:
        a = resolve(base)
    except AlignmentError:
        return True
    if a.derivative or set(a.options) - {"window"}:
        return True
    return canonical(a.entry.key, a.value, a.typev) not in PAPER_NAMES


def style_beyond_paper(ax, names, patches) -> list:
    """Set apart the algorithms beyond the paper on an axes with one algorithm per x tick
    (``patches[name]``: their boxes): grey, hatched, a dashed line before each run of them.
    Returns the style's legend entry if any name is beyond the paper, else ``[]``.
    """
    flags = [beyond_paper(n) for n in names]
    for n in [n for n, b in zip(names, flags) if b]:
        for patch in patches.get(n, []):
            patch.set(**BEYOND_PAPER_PATCH)
    for t in ax.get_xticklabels():
        if beyond_paper(t.get_text()):
            t.set(**BEYOND_PAPER_TEXT)
    runs = [k for k in range(1, len(flags)) if flags[k] != flags[k - 1]]  # where a run starts
    for k in runs:
        ax.axvline(k - 0.5, color="0.4", ls="--", lw=0.9, gid="beyond_paper_separator")
    if (k := next((k for k in runs if flags[k]), None)) is not None:  # the first beyond run
        ax.text(k - 0.5, 0.98, f" {BEYOND_PAPER_LABEL} →", transform=ax.get_xaxis_transform(),
                ha="left", va="top", fontsize=8, zorder=7, gid="beyond_paper_label",
                **BEYOND_PAPER_TEXT)  # fmt: skip
    return [Patch(**BEYOND_PAPER_PATCH, label=BEYOND_PAPER_LABEL)] if any(flags) else []


def style_beyond_paper_panel(ax, name: str) -> bool:
    """The same rule on a panel of one algorithm (a heat map): when it is beyond the paper,
    its title says so in grey italic and its frame is grey and dashed."""
    if not beyond_paper(name):
        return False
    ax.set_title(f"{name}\n({BEYOND_PAPER_LABEL})", fontsize=9, **BEYOND_PAPER_TEXT)
    for spine in ax.spines.values():
        spine.set(edgecolor="0.45", linestyle="--", linewidth=1.2)
    ax.set_gid("beyond_paper_panel")
    return True


def plot_skeleton(positions, parents, ax=None, *, view=(0, 1), color="k", lw=1.5):
    """Draw one pose, ``positions`` (J, 3), as a stick figure in the 2-D projection ``view``.

    Notebook: 01_data_and_motions.ipynb
    """
    fig, ax = new_axes(ax)
    P = np.asarray(positions, dtype=float)
    a, b = view
    for j, p in enumerate(parents):
        if p >= 0:
            ax.plot([P[p, a], P[j, a]], [P[p, b], P[j, b]], color=color, lw=lw)
    ax.plot(P[:, a], P[:, b], "o", color=color, ms=2)
    ax.set_aspect("equal")
    return fig, ax
