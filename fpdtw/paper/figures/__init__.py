"""Figure code of the FP-DTW paper's figures, one module per figure (or group).

* :mod:`.oedtw` — Fig. 1 (OE-DTW end points jumping backwards);
* :mod:`.windows` — Figs. 2 and 4 (Method A/B/C windows drawn from plain steps);
* :mod:`.forecast` — Fig. 3 (forecast error of smoothing levels vs frames ahead);
* :mod:`.walk_pair` — Fig. 8 (one walk pair: paths, right-hip curves, poses);
* :mod:`.typev` — Fig. 9 (the Type V constraint and its state table);
* :mod:`.scores` — Figs. 5 and 6 (similarity and deviation box plots) and Table 1;
* :mod:`.heatmaps` — Figs. 7 and 10 (aggregate heat maps of all paths);
* :mod:`.timing` — Table 2 (time per frame);
* :mod:`.opw` — OPW poster Figs. 4-6;
* :mod:`.facts` — the JSON of facts each figure notebook writes.

Plot functions take ``ax=None`` (or ``axes=None``) and return ``(fig, ax)``; figures are
saved with :func:`fpdtw.paper.figures.plotting.save_figure`.
"""

from fpdtw.paper.figures.facts import facts_path, load_facts, save_facts  # noqa: F401
from fpdtw.paper.figures.forecast import best_level, forecast_curves, plot_forecast_panels  # noqa: F401
from fpdtw.paper.figures.heatmaps import (  # noqa: F401
    heatmap,
    path_balance,
    plot_heatmap,
    plot_heatmap_grid,
    plot_typev_heatmaps,
)
from fpdtw.paper.figures.oedtw import backward_jumps, first_backward_jump, plot_fig1  # noqa: F401
from fpdtw.paper.figures.opw import (  # noqa: F401
    plot_curve_construction,
    plot_deviation,
    plot_deviation_vs_gamma,
    plot_deviation_vs_offset,
    plot_fig4,
    plot_slope_change,
    plot_warp_curves,
)
from fpdtw.paper.figures.scores import plot_score_boxes, plot_table1, score_summary, table1_rows  # noqa: F401
from fpdtw.paper.figures.timing import exhausted_fraction, plot_time_vs_w, time_per_frame_rows  # noqa: F401
from fpdtw.paper.figures.typev import plot_fig9, plot_state_table, table_rows, typev_states  # noqa: F401
from fpdtw.paper.figures.walk_pair import (  # noqa: F401
    align_all,
    load_walk_pair,
    pair_scores,
    plot_paths_over_cost,
)
from fpdtw.paper.figures.windows import first_leaving, plot_method_b_window  # noqa: F401
