"""Figure helpers: one function saves every figure; plot functions take ``ax=None``.

Plot functions return ``(fig, ax)`` and leave showing to the caller. Figures are
written as PDF and PNG with metadata that does not change between runs (no creation
date, no software version), so regenerating an unchanged figure gives the same bytes.
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

from fpdtw.paper.paths import figures_dir  # noqa: E402

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
