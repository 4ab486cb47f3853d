"""Aggregate heat maps of all alignment paths of an algorithm: Figs. 7 and 10.

Paths on the unit square (x = q / n, y = M_q / m), each weighted equally; mass BELOW the
diagonal means sticking, ABOVE skipping (paper Section 5). One log colour scale per figure.
"""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.colors import LogNorm

from fpdtw import registry
from fpdtw.paper.figures.plotting import new_axes, style_beyond_paper_panel
from fpdtw.paper.figures.timing import pair_maps
from fpdtw.paper.runner.results import aggregate_heatmap
from fpdtw.registry import TYPE_V_SUFFIX


def fig7_names() -> tuple:
    """Fig. 7's panels: the paper's algorithms, then the registry's baselines (read at each
    call).

    Paper: FP-DTW Fig. 7.
    """
    return (
        "DTW", "UTW", "OE-DTW", "Ma", "Mb w10", "Mb w80", "Mc w10", "Mc w20", "Mc w40", "Mc w80",
    ) + registry.baselines()  # fmt: skip


#: The algorithms of the paper's Fig. 10 (each without and with the Type V constraint).
FIG10_NAMES = ("Ma", "Mc w10", "Mc w80")

#: Lowest colour of the log scale, as a fraction of the hottest cell.
LOG_FLOOR = 1e-4


def heatmap(results, name: str, bins: int = 100) -> np.ndarray:
    """One algorithm's aggregate heat map, float64 (bins, bins): ``H[i, j]``, the fraction
    of path mass at input time bin ``i`` and target time bin ``j``.

    Paper: FP-DTW Fig. 7.
    Notebook: 08_fig7_fig10_heatmaps.ipynb
    """
    H = np.asarray(aggregate_heatmap(results, name, bins=bins), dtype=np.float64)
    total = H.sum()
    return H / total if total > 0 else H


def path_balance(results, name: str, band: float = 0.1) -> dict:
    """Where the path mass lies, from the maps: the mean over pairs of the shares of target
    frames with ``M_q / m - q / n`` within ``band`` (``diagonal``), ``below`` and ``above``.

    Paper: FP-DTW Section 5 (reading of Fig. 7).
    Notebook: 08_fig7_fig10_heatmaps.ipynb
    """
    shares = []  # per pair: near the diagonal, below, above
    for M, m in pair_maps(results, name):
        d = M / max(m, 1) - np.arange(M.size) / max(M.size - 1, 1)
        shares.append((np.mean(np.abs(d) <= band), np.mean(d < -band), np.mean(d > band)))
    P = max(len(shares), 1)
    diag, below, above = (sum(s[k] for s in shares) / P for k in range(3))
    return dict(diagonal=diag, below=below, above=above, pairs=len(shares))


def shared_norm(maps):
    """One logarithmic colour scale for several heat maps, from LOG_FLOOR x max to max."""
    vmax = max(float(np.max(H)) for H in maps)
    vmax = vmax if vmax > 0 else 1.0
    return LogNorm(vmin=vmax * LOG_FLOOR, vmax=vmax)


def plot_heatmap(H, ax=None, *, norm=None, title=None):
    """Draw one heat map of :func:`heatmap` with the diagonal on the scale ``norm``.

    Paper: FP-DTW Figs. 7 and 10.
    """
    fig, ax = new_axes(ax, figsize=(3, 3))
    H = np.asarray(H, dtype=np.float64)
    norm = norm if norm is not None else shared_norm([H])
    cm = plt.get_cmap("magma")
    cm = cm.with_extremes(bad=cm(0.0), under=cm(0.0))
    ax.imshow(np.ma.masked_less_equal(H, 0.0), origin="lower", extent=(0, 1, 0, 1), norm=norm,
              cmap=cm, aspect="equal", interpolation="nearest")  # fmt: skip
    ax.plot([0, 1], [0, 1], ls=(0, (2, 3)), color="w", lw=0.6, alpha=0.7)
    if title:
        ax.set_title(title, fontsize=9)
    ax.set(xticks=[0, 0.5, 1], yticks=[0, 0.5, 1])
    ax.tick_params(labelsize=7)
    return fig, ax


def _grid(results, cells, shape, bins, maps, labels, titles=None):
    """Heat maps on one colour scale, each name of ``cells`` at its panel ``(row, column)``
    of a grid of ``shape`` (``maps`` first, the others computed), the other panels hidden;
    tick labels and axis ``labels`` (x, y) on the left and lowest panels only; one colour bar."""
    maps = {**maps, **{n: heatmap(results, n, bins) for n, _ in cells if n not in maps}}
    size = 2.2
    fig, axes = plt.subplots(
        *shape, figsize=(size * shape[1] + 0.8, size * shape[0] + 0.4), squeeze=False
    )
    norm = shared_norm([maps[n] for n, _ in cells])
    for ax in axes.flat:
        ax.set_visible(False)
    for n, at in cells:
        axes[at].set_visible(True)
        plot_heatmap(maps[n], axes[at], norm=norm, title=(titles or {}).get(n, n))
        style_beyond_paper_panel(axes[at], n)
    for (r, c), ax in np.ndenumerate(axes):
        below = any(axes[k, c].get_visible() for k in range(r + 1, shape[0]))
        ax.tick_params(labelleft=c == 0, labelbottom=not below)
        ax.set_xlabel("" if below else labels[0], fontsize=8)
        ax.set_ylabel(labels[1] if c == 0 else "", fontsize=8)
    sm = plt.cm.ScalarMappable(norm=norm, cmap="magma")
    cb = fig.colorbar(sm, ax=axes, shrink=0.6, pad=0.02)
    cb.set_label("fraction of path mass per cell", fontsize=8)
    return fig, axes


def plot_heatmap_grid(results, names=None, ncols=5, bins=100, maps=None, titles=None):
    """Fig. 7: one heat map per algorithm (default :func:`fig7_names`), one colour scale;
    ``maps``: precomputed heat maps by name; ``titles``: panel titles by name.

    Paper: FP-DTW Fig. 7.
    Notebook: 08_fig7_fig10_heatmaps.ipynb
    """
    maps = maps or {}
    names = fig7_names() if names is None else names
    names = [n for n in names if n in maps or n in set(results.algorithms)]
    cells = [(n, divmod(i, ncols)) for i, n in enumerate(names)]
    labels = ("target time q / n", "input time M_q / m")
    return _grid(results, cells, (-(-len(names) // ncols), ncols), bins, maps, labels, titles)


def plot_typev_heatmaps(results, bases=FIG10_NAMES, bins=100, per_row=None, maps=None):
    """Fig. 10: each algorithm's heat map above its "+ Type V" one, ``per_row`` per row pair.

    Paper: FP-DTW Fig. 10.
    Notebook: 08_fig7_fig10_heatmaps.ipynb
    """
    per_row = per_row or len(bases)
    cells = [
        (n, (2 * (i // per_row) + j, i % per_row))
        for i, b in enumerate(bases)
        for j, n in enumerate((b, b + TYPE_V_SUFFIX))
    ]
    shape = (2 * -(-len(bases) // per_row), per_row)
    return _grid(results, cells, shape, bins, maps or {}, ("target q / n", "input M_q / m"))
