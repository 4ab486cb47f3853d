"""Aggregate heat maps of all alignment paths of an algorithm: Figs. 7 and 10.

Every path (one per pair) is normalised to the unit square, x = q / n (target time),
y = M_q / m (input time), and accumulated into a 2-D histogram with each path weighted
equally (:func:`fpdtw.paper.runner.run.aggregate_heatmap`). The diagonal is the 1:1 alignment;
mass BELOW the diagonal means the aligner sticks on input frames (input time lags), mass
ABOVE it means it skips input frames (paper Section 5).

The colour scale is logarithmic by default: a few hot cells (every path starts at (0, 0)
and many end at (1, 1)) would otherwise hide everything else. All panels of a figure share
one colour scale, so panels can be compared; the colour is the fraction of all path mass
per cell.
"""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.colors import LogNorm, Normalize

from fpdtw import registry
from fpdtw.paper.figures.plotting import new_axes, style_beyond_paper_panel
from fpdtw.paper.figures.timing import last_input_frame
from fpdtw.paper.runner.results import aggregate_heatmap
from fpdtw.registry import TYPE_V_SUFFIX

#: The paper's algorithms of its Fig. 7.
FIG7_PAPER_NAMES = (
    "DTW",
    "UTW",
    "OE-DTW",
    "Ma",
    "Mb w10",
    "Mb w80",
    "Mc w10",
    "Mc w20",
    "Mc w40",
    "Mc w80",
)


def fig7_names() -> tuple:
    """Fig. 7's panels: the paper's algorithms, then the registry's online baselines beyond
    it (:func:`fpdtw.registry.baselines`), read at each call.

    Returns
    -------
    names : tuple of str

    Paper: FP-DTW Fig. 7.
    Notebook: none (the default of :func:`plot_heatmap_grid`)
    """
    return FIG7_PAPER_NAMES + registry.baselines()


#: :func:`fig7_names` with the registry as built in.
FIG7_NAMES = fig7_names()

#: The algorithms of the paper's Fig. 10 (each without and with the Type V constraint).
FIG10_NAMES = ("Ma", "Mc w10", "Mc w80")

#: Lowest colour of the log scale, as a fraction of the hottest cell.
LOG_FLOOR = 1e-4


def heatmap(results, name: str, bins: int = 100) -> np.ndarray:
    """The aggregate heat map of one algorithm, as an image: rows = input time.

    Parameters
    ----------
    results : fpdtw.paper.runner.run.Results
    name : str
    bins : int

    Returns
    -------
    H : ndarray of float64, shape (bins, bins)
        ``H[i, j]``: fraction of all path mass (each path weighted equally) with input
        time in bin ``i`` and target time in bin ``j``; sums to 1. Draw with
        ``origin="lower"``.

    Paper: FP-DTW Fig. 7.
    Notebook: 08_fig7_fig10_heatmaps.ipynb
    """

    # aggregate_heatmap: H[y_bin, x_bin], y = M_q / m (input), x = q / n (target)
    H = np.asarray(aggregate_heatmap(results, name, bins=bins), dtype=np.float64)
    total = H.sum()
    return H / total if total > 0 else H


def path_balance(results, name: str, band: float = 0.1) -> dict:
    """Where the path mass lies: near the diagonal, below it (sticking), above it (skipping).

    Computed from the maps, exactly (no binning): per pair the fraction of target frames
    ``q`` with ``|M_q / m - q / n| <= band``, with ``M_q / m < q / n - band`` (below) and
    with ``M_q / m > q / n + band`` (above); then the mean over pairs (each path weighted
    equally, as in the heat map). Deterministic.

    Parameters
    ----------
    results : fpdtw.paper.runner.run.Results
    name : str
    band : float
        Half width of the diagonal band, in normalised time.

    Returns
    -------
    out : dict
        ``diagonal``, ``below``, ``above`` (sum to 1), ``pairs``.

    Paper: FP-DTW Section 5 (reading of Fig. 7).
    Notebook: 08_fig7_fig10_heatmaps.ipynb
    """

    arr = results.get(name)
    m_of = {k: max(v, 1) for k, v in last_input_frame(results, name).items()}
    offsets = np.asarray(arr["offsets"], dtype=np.int64)
    maps = np.asarray(arr["maps"])
    pid = np.asarray(arr["pair_id"])
    diag = below = above = 0.0
    for k in range(pid.size):
        M = maps[offsets[k] : offsets[k + 1]].astype(np.float64)
        n = max(M.size - 1, 1)
        d = M / m_of[int(pid[k])] - np.arange(M.size) / n
        below += np.mean(d < -band)
        above += np.mean(d > band)
        diag += np.mean(np.abs(d) <= band)
    P = max(pid.size, 1)
    return dict(diagonal=diag / P, below=below / P, above=above / P, pairs=int(pid.size))


def shared_norm(maps, log=True):
    """One colour scale for several heat maps (log: from LOG_FLOOR x max to max)."""
    vmax = max(float(np.max(H)) for H in maps)
    vmax = vmax if vmax > 0 else 1.0
    if log:
        return LogNorm(vmin=vmax * LOG_FLOOR, vmax=vmax)
    return Normalize(vmin=0.0, vmax=vmax)


def plot_heatmap(H, ax=None, *, norm=None, log=True, title=None, cmap="magma", diagonal=True):
    """Draw one aggregate heat map (x: target time, y: input time, both normalised).

    Parameters
    ----------
    H : ndarray of float, shape (bins, bins)
        From :func:`heatmap` (rows = input time).
    ax : matplotlib.axes.Axes, optional
    norm : matplotlib.colors.Normalize, optional
        Colour scale (default: this map's own, log if ``log``).
    title : str, optional
    diagonal : bool
        Draw the 1:1 diagonal as a thin dashed line.

    Returns
    -------
    fig, ax
        ``ax.images[0]`` is the heat map.

    Paper: FP-DTW Figs. 7 and 10.
    """

    fig, ax = new_axes(ax, figsize=(3, 3))
    H = np.asarray(H, dtype=np.float64)
    norm = norm if norm is not None else shared_norm([H], log=log)
    cm = plt.get_cmap(cmap)
    cm = cm.with_extremes(bad=cm(0.0), under=cm(0.0))
    img = np.ma.masked_less_equal(H, 0.0) if isinstance(norm, LogNorm) else H
    ax.imshow(
        img,
        origin="lower",
        extent=(0, 1, 0, 1),
        norm=norm,
        cmap=cm,
        aspect="equal",
        interpolation="nearest",
    )
    if diagonal:
        ax.plot([0, 1], [0, 1], ls=(0, (2, 3)), color="w", lw=0.6, alpha=0.7)
    if title:
        ax.set_title(title, fontsize=9)
    ax.set_xticks([0, 0.5, 1])
    ax.set_yticks([0, 0.5, 1])
    ax.tick_params(labelsize=7)
    return fig, ax


def _grid(n_rows, n_cols, size=2.2):
    fig, axes = plt.subplots(
        n_rows, n_cols, figsize=(size * n_cols + 0.8, size * n_rows + 0.4), squeeze=False
    )
    return fig, axes


def _tidy_ticks(axes):
    """Tick labels only on the left column and on the lowest visible panel of each column."""
    n_rows, n_cols = axes.shape
    for r in range(n_rows):
        for c in range(n_cols):
            ax = axes[r, c]
            below = [axes[k, c].get_visible() for k in range(r + 1, n_rows)]
            ax.tick_params(labelleft=c == 0, labelbottom=not any(below))
            if c != 0:
                ax.set_ylabel("")
            if any(below):
                ax.set_xlabel("")


def _colourbar(fig, axes, norm, cmap="magma"):
    sm = plt.cm.ScalarMappable(norm=norm, cmap=cmap)
    cb = fig.colorbar(sm, ax=axes, shrink=0.6, pad=0.02)
    cb.set_label("fraction of path mass per cell", fontsize=8)
    return cb


def plot_heatmap_grid(results, names=None, ncols=5, bins=100, log=True, maps=None, titles=None):
    """Fig. 7: the aggregate heat map of each algorithm, one panel each, one colour scale.

    Parameters
    ----------
    results : fpdtw.paper.runner.run.Results
    names : sequence of str, optional
        Default: :func:`fig7_names`.
    ncols : int
    bins : int
    log : bool
        Logarithmic colour scale (default; see module docstring).
    maps : dict, optional
        Precomputed ``{name: heatmap(results, name, bins)}``.
    titles : dict, optional
        ``{name: panel title}`` (default: the name).

    Returns
    -------
    fig, axes
        ``axes`` is a 2-D array; panels past ``len(names)`` are hidden. A panel of an
        algorithm beyond the paper (OPW, OLTW) is set apart by
        :func:`fpdtw.paper.figures.plotting.style_beyond_paper_panel` (its title says so, its
        frame is grey and dashed).

    Paper: FP-DTW Fig. 7.
    Notebook: 08_fig7_fig10_heatmaps.ipynb
    """
    maps = dict(maps or {})
    names = fig7_names() if names is None else names
    names = [n for n in names if n in maps or n in set(results.algorithms)]
    for n in names:
        if n not in maps:
            maps[n] = heatmap(results, n, bins)
    nrows = -(-len(names) // ncols)
    fig, axes = _grid(nrows, ncols)
    norm = shared_norm([maps[n] for n in names], log=log)
    for ax, n in zip(axes.flat, names):
        plot_heatmap(maps[n], ax, norm=norm, title=(titles or {}).get(n, n))
        style_beyond_paper_panel(ax, n)  # OPW, OLTW: titled "beyond the paper", dashed frame
    for ax in axes.flat[len(names) :]:
        ax.set_visible(False)
    for ax in axes.flat:
        ax.set_xlabel("target time q / n", fontsize=8)
        ax.set_ylabel("input time M_q / m", fontsize=8)
    _tidy_ticks(axes)
    _colourbar(fig, axes, norm)
    return fig, axes


def plot_typev_heatmaps(results, bases=FIG10_NAMES, bins=100, log=True, per_row=None, maps=None):
    """Fig. 10: heat maps without and with the Type V constraint, side by side.

    Each algorithm gets a column pair of rows: the top row without constraint, the row
    below "+ Type V". With ``per_row`` the algorithms wrap onto further row pairs.

    Parameters
    ----------
    results : fpdtw.paper.runner.run.Results
    bases : sequence of str
        Unconstrained FP-DTW names (the paper's Fig. 10: Ma, Mc w10, Mc w80).
    per_row : int, optional
        Algorithms per row pair (default: all in one).
    maps : dict, optional
        Precomputed heat maps by name.

    Returns
    -------
    fig, axes
        ``axes`` shape ``(2 * row_pairs, per_row)``.

    Paper: FP-DTW Fig. 10.
    Notebook: 08_fig7_fig10_heatmaps.ipynb
    """
    per_row = per_row or len(bases)
    names = [n for b in bases for n in (b, b + TYPE_V_SUFFIX)]
    maps = dict(maps or {})
    for n in names:
        if n not in maps:
            maps[n] = heatmap(results, n, bins)
    blocks = -(-len(bases) // per_row)
    fig, axes = _grid(2 * blocks, per_row)
    norm = shared_norm([maps[n] for n in names], log=log)
    for ax in axes.flat:
        ax.set_visible(False)
    for i, b in enumerate(bases):
        r, c = divmod(i, per_row)
        for j, n in enumerate((b, b + TYPE_V_SUFFIX)):
            ax = axes[2 * r + j, c]
            ax.set_visible(True)
            plot_heatmap(maps[n], ax, norm=norm, title=n)
            ax.set_ylabel("input M_q / m", fontsize=8)
            ax.set_xlabel("target q / n", fontsize=8)
    _tidy_ticks(axes)
    _colourbar(fig, axes, norm)
    return fig, axes


__all__ = [
    "FIG10_NAMES",
    "FIG7_NAMES",
    "FIG7_PAPER_NAMES",
    "fig7_names",
    "heatmap",
    "path_balance",
    "plot_heatmap",
    "plot_heatmap_grid",
    "plot_typev_heatmaps",
    "shared_norm",
]
