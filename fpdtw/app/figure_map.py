"""The one map from notebook to the figures and tables it makes, and what it reproduces.

The Makefile's per-figure rules and notebook order come from it (``python
fpdtw/app/figure_map.py makefile > build/figure_map.mk``; standard library only, so make
can run it before the environment exists); docs/notebooks.md's table and each notebook's
"Makes:" line are checked against it. Adding a figure: one notebook, one module in
:mod:`fpdtw.paper.figures`, one row here.
"""

from __future__ import annotations

import sys
from dataclasses import dataclass


@dataclass(frozen=True)
class Notebook:
    """One notebook (``stem``: file name without ``.ipynb``): the stems it writes to
    ``figures/`` (figures as PDF + PNG, tables as CSV + Markdown), what it reproduces in
    words, and the notebooks whose results it reads (run first)."""

    stem: str
    makes: tuple
    paper: str
    needs: tuple = ()


_RUN = ("05_run_experiments",)

#: Every notebook, in order.
NOTEBOOKS = (
    Notebook("01_data_and_motions", ("data_summary", "data_poses"), "data (Section 4)"),
    Notebook("02_fig1_oedtw", ("fig1_oedtw_endpoints",),
             "Fig. 1: OE-DTW end points jump backwards (real walk pair)"),
    Notebook("03_fig2_fig4_windows",
             ("fig2_method_a_window", "fig4_method_b_window", "fig4_method_c_window"),
             "Figs. 2 and 4, drawn from real steps"),
    Notebook("04_fig3_forecast", ("fig3_forecast_error",),
             "Fig. 3: forecast error vs frames ahead per smoothing level"),
    Notebook("05_run_experiments", ("experiment_pairs",), "the evaluation of Section 4"),
    Notebook("06_fig5_fig6_scores",
             ("fig5_similarity", "fig5_similarity_summary", "fig6_deviation",
              "fig6_deviation_summary", "fig5_fig6_summary_by_dataset"),
             "Figs. 5 and 6", _RUN),
    Notebook("07_table1_60hz", ("table1_method_c_60_120hz",), "Table 1", _RUN),
    Notebook("08_fig7_fig10_heatmaps",
             ("fig7_heatmaps", "fig10_typev_heatmaps", "fig10_typev_heatmaps_all",
              "fig7_path_balance"),
             "Figs. 7 and 10", _RUN),
    Notebook("09_table2_timing", ("table2_time_per_frame", "table2_time_vs_w"),
             "Table 2 (`make bench`: one core, warmed up)", _RUN),
    Notebook("10_fig8_walk_pair",
             ("fig8_paths", "fig8_right_hip", "fig8_poses", "fig8_walk_pair_scores",
              "fig8_statements"),
             "Fig. 8; its statements (Mc w20 fails, Mc w80 skips a cycle, Mb w80 stays close) "
             "on our six walk pairs"),
    Notebook("11_fig9_typev", ("fig9_typev", "fig9_typev_table"),
             "Fig. 9: the Type V state table as used"),
    Notebook("13_opw_fig4",
             ("opw_fig4_curves", "opw_fig4_curves_plugin", "opw_fig4_summary", "opw_curve_keys"),
             "OPW poster Fig. 4, as the poster reads and as the authors' plugin runs it"),
    Notebook("14_opw_fig5_fig6",
             ("opw_fig5_offset", "opw_fig6_gamma", "opw_fig5_offset_plugin", "opw_readings"),
             "OPW poster Figs. 5 and 6; OPW read as the poster and as the authors' plugin, "
             "mechanism by mechanism"),
    Notebook("15_readings_of_algorithm_3",
             ("readings_table", "readings_signature", "readings_overview", "readings_mechanism",
              "readings_heatmaps", "silent_choices", "silent_choices_detail",
              "selection_paper_shaped"),
             "Algorithm 3's window read five ways, side by side; every other silent choice; "
             "a paper-shaped data selection", _RUN),
    Notebook("12_claims", ("claims", "claims_intervals", "claims_checks", "claims_power"),
             "every claim of both papers split into parts: verdict and reason, 95 % intervals, "
             "per dataset and selection, robustness to the paper's open readings",
             ("02_fig1_oedtw", "06_fig5_fig6_scores", "07_table1_60hz", "08_fig7_fig10_heatmaps",
              "09_table2_timing", "10_fig8_walk_pair", "13_opw_fig4", "14_opw_fig5_fig6",
              "15_readings_of_algorithm_3", "16_open_questions")),
    Notebook("16_open_questions",
             ("open_q1_period", "open_q1_windows", "open_q1_movements", "open_q2_weights",
              "open_q3_band", "open_q3_cost",
              "open_q4_gamma", "open_q5_derivative", "open_q6_pause_example", "open_q6_pause",
              "open_q7_edit_example", "open_q7_edits"),
             "beyond the papers: the questions they leave open, answered on the same pairs "
             "(the window from the period; joint weights; a global band and its per-frame cost; "
             "adaptive gamma; derivative costs; standing still; a skip, a repeat or a restart)"),
    Notebook("17_similarity_level", ("similarity_level",),
             "eq. 2 read six other ways (tau, flat axes, warm-up frames, bone axis, world and "
             "root-relative frames): the median similarity level next to Table 1's", _RUN),
    Notebook("20_align_a_live_performance",
             ("live_latency", "live_maps", "live_walk_Mc_w40", "live_walk_OLTW",
              "live_network_latency", "live_source_latency", "live_drop_rate", "live_ms"),
             "for people: align a recorded take to a live one, also over the network "
             "(`fpdtw serve`, and from each capture system's stream)"),
)  # fmt: skip


def by_stem() -> dict:
    """``{stem: Notebook}``."""
    return {nb.stem: nb for nb in NOTEBOOKS}


def readme_table() -> str:
    """The notebook table of docs/notebooks.md (Markdown; a generated block there)."""
    lines = ["| notebook | makes | paper |", "|---|---|---|"]
    for nb in sorted(NOTEBOOKS, key=lambda n: n.stem):
        makes = ", ".join(f"`{m}`" for m in nb.makes)
        lines.append(f"| `{nb.stem}` | {makes} | {nb.paper} |")
    return "\n".join(lines) + "\n"


def makefile() -> str:
    """Make rules: one target per figure or table, and the order between notebooks."""
    out = ["# generated from fpdtw/app/figure_map.py: do not edit"]
    for nb in NOTEBOOKS:
        for stem in nb.makes:
            out.append(f"$(eval $(call FIGURE_RULE,{stem},{nb.stem}))")
        if nb.needs:
            needs = " ".join(f"%DIR%/{n}.ipynb" for n in nb.needs)
            for d in ("build/notebooks", "$(SMOKE_DIR)"):
                out.append(f"{d}/{nb.stem}.ipynb: {needs.replace('%DIR%', d)}")
    return "\n".join(out) + "\n"


if __name__ == "__main__":
    what = sys.argv[1] if len(sys.argv) > 1 else "readme"
    sys.stdout.write(makefile() if what == "makefile" else readme_table())
