"""Figure helpers: one function saves every figure; plot functions take ``ax=None``.

Plot functions return ``(fig, ax)`` and leave showing to the caller. Figures are
written as PDF and PNG with metadata that does not change between runs (no creation
date, no software version), so regenerating an unchanged figure gives the same bytes.

One style rule sets apart the algorithms the FP-DTW paper does not evaluate (OPW, OLTW,
the variants of notebooks 15-16) wherever a figure mixes them with the paper's own:
:func:`beyond_paper` decides, :func:`style_beyond_paper` and :func:`style_beyond_paper_panel`
draw it (grey hatched boxes, grey italic labels, a dashed separator and the words
"beyond the paper").
"""

from __future__ import annotations

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
from fpdtw.paper.numbers import PAPER_NAMES  # noqa: E402
from fpdtw.paper.paths import figures_dir  # noqa: E402
from fpdtw.registry import name as canonical
from fpdtw.registry import resolve

_PDF_META = {"CreationDate": None, "ModDate": None, "Creator": None, "Producer": None}
_PNG_META = {"Software": None}


def new_axes(ax=None, **subplots_kw):
    """Return ``(fig, ax)``: the given axes' figure, or a new figure and axes."""
    if ax is not None:
        return ax.figure, ax
    fig, ax = plt.subplots(**subplots_kw)
    return fig, ax


def save_figure(fig, name: str, folder=None, dpi: int = 150) -> list[Path]:
    """Save a figure as ``<name>.pdf`` and ``<name>.png`` with stable metadata.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
    name : str
        File stem, e.g. ``"fig5_similarity"``.
    folder : path-like, optional
        Default :func:`fpdtw.paper.paths.figures_dir`.
    dpi : int
        Resolution of the PNG.

    Returns
    -------
    paths : list of Path
        The PDF and PNG written.
    """
    folder = Path(folder) if folder is not None else figures_dir()
    folder.mkdir(parents=True, exist_ok=True)
    out = []
    with matplotlib.rc_context({"svg.hashsalt": "fpdtw", "pdf.compression": 6}):
        for ext, meta in (("pdf", _PDF_META), ("png", _PNG_META)):
            path = folder / f"{name}.{ext}"
            tmp = path.with_suffix(f".{ext}.part")
            fig.savefig(tmp, format=ext, dpi=dpi, metadata=meta, bbox_inches="tight")
            os.replace(tmp, path)
            out.append(path)
    return out


#: The words that mark an algorithm the FP-DTW paper does not evaluate.
BEYOND_PAPER_LABEL = "beyond the paper"
#: Boxes and bars of such an algorithm: light grey, hatched, grey edge.
BEYOND_PAPER_PATCH = {"facecolor": "0.9", "hatch": "////", "edgecolor": "0.45"}
#: Tick labels and panel titles of such an algorithm.
BEYOND_PAPER_TEXT = {"color": "0.4", "fontstyle": "italic"}
_RATE_SUFFIX = "@60Hz"


def beyond_paper(name: str) -> bool:
    """True for an algorithm name the FP-DTW paper does not evaluate.

    The paper's names are :data:`fpdtw.paper.numbers.PAPER_NAMES` (DTW, UTW, OE-DTW, Ma,
    Mb/Mc w10-w80, each FP-DTW one with "+ Type V"), also at 60 Hz (``"Mc w40@60Hz"``,
    Table 1), and also under another reading of Algorithm 3's window
    (``"Mc w40 (literal window)"``: the paper's own method read as printed, notebook 15).
    Every other name is beyond the paper: OPW (the poster's, not evaluated in the FP-DTW
    paper), OLTW, ``"Mc auto"``, and any other option (``"Mc w40 (band 1 s)"``,
    ``"OLTW (weighted joints)"``, ``"Mc w40 (derivative)"``); so is a name the registry
    does not know.
    """

    base = name.removesuffix(_RATE_SUFFIX)
    if base in PAPER_NAMES:
        return False
    try:
        a = resolve(base)
    except AlignmentError:
        return True
    if a.derivative or set(a.options) - {"window"}:
        return True
    return canonical(a.entry.key, a.value, a.typev) not in PAPER_NAMES


def beyond_paper_handle(**kw):
    """A legend entry for the style: a grey hatched patch labelled "beyond the paper"."""

    return Patch(**{**BEYOND_PAPER_PATCH, "label": BEYOND_PAPER_LABEL, **kw})


def style_beyond_paper(ax, names, positions=None, patches=None, axis="x", label=True) -> list:
    """The one style rule, on an axes with one algorithm per tick: set apart those beyond
    the paper.

    Their patches (``patches[name]``: a patch or a list of patches, e.g. boxes) become grey
    and hatched, their tick labels grey italic; a dashed line (``gid``
    ``"beyond_paper_separator"``) separates each run of them from the paper's algorithms,
    and the first run is labelled "beyond the paper" (``gid`` ``"beyond_paper_label"``).

    Parameters
    ----------
    ax : matplotlib.axes.Axes
    names : sequence of str
        The algorithms along the axis, in order.
    positions : sequence of float, optional
        Their tick positions (default ``0, 1, ...``).
    patches : dict of str to Patch or list of Patch, optional
    axis : {"x", "y"}
    label : bool
        Write "beyond the paper" beside the separator.

    Returns
    -------
    names : list of str
        The names styled as beyond the paper.
    """
    names = list(names)
    pos = list(range(len(names))) if positions is None else [float(p) for p in positions]
    out = [n for n in names if beyond_paper(n)]
    for n in out:
        mine = (patches or {}).get(n, [])
        for patch in mine if isinstance(mine, list | tuple) else [mine]:
            patch.set(**BEYOND_PAPER_PATCH)
    ticks = ax.get_xticklabels() if axis == "x" else ax.get_yticklabels()
    for t in ticks:
        if beyond_paper(t.get_text()):
            t.set(**BEYOND_PAPER_TEXT)
    first = True
    for k in range(1, len(names)):
        a, b = beyond_paper(names[k - 1]), beyond_paper(names[k])
        if a == b:
            continue
        at = 0.5 * (pos[k - 1] + pos[k])
        line = (ax.axvline if axis == "x" else ax.axhline)(at, color="0.4", ls="--", lw=0.9)
        line.set_gid("beyond_paper_separator")
        if b and label and first:
            first = False
            xy, va = ((at, 0.98), "top") if axis == "x" else ((0.98, at), "bottom")
            trans = ax.get_xaxis_transform() if axis == "x" else ax.get_yaxis_transform()
            txt = ax.text(
                *xy, f" {BEYOND_PAPER_LABEL} →", transform=trans, ha="left", va=va,
                fontsize=8, zorder=7, **BEYOND_PAPER_TEXT,
            )  # fmt: skip
            txt.set_gid("beyond_paper_label")
    return out


def style_beyond_paper_panel(ax, name: str) -> bool:
    """The same rule on a panel given to one algorithm (a heat map of Fig. 7): when it is
    beyond the paper, its title says so in grey italic and its frame is grey and dashed.

    Returns
    -------
    beyond : bool
    """
    if not beyond_paper(name):
        return False
    ax.set_title(f"{name}\n({BEYOND_PAPER_LABEL})", fontsize=9, **BEYOND_PAPER_TEXT)
    for spine in ax.spines.values():
        spine.set(edgecolor="0.45", linestyle="--", linewidth=1.2)
    ax.set_gid("beyond_paper_panel")
    return True


def plot_skeleton(positions, parents, ax=None, *, view=(0, 1), color="k", lw=1.5, label=None):
    """Draw one pose as a stick figure in a 2-D projection.

    Parameters
    ----------
    positions : ndarray of float, shape (J, 3)
        Joint positions of one frame (from :meth:`Motion.forward_kinematics`).
    parents : ndarray of int, shape (J,)
        Parent of each joint (-1 for the root).
    ax : matplotlib.axes.Axes, optional
    view : tuple of int
        The two coordinates to plot (default x horizontal, y vertical).

    Returns
    -------
    fig, ax

    Notebook: 01_data_and_motions.ipynb
    """
    fig, ax = new_axes(ax)
    P = np.asarray(positions, dtype=float)
    a, b = view
    for j, p in enumerate(parents):
        if p >= 0:
            ax.plot([P[p, a], P[j, a]], [P[p, b], P[j, b]], color=color, lw=lw)
    ax.plot(P[:, a], P[:, b], "o", color=color, ms=2, label=label)
    ax.set_aspect("equal")
    return fig, ax
