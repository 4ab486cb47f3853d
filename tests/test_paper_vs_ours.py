"""The "paper | ours" rows of the companion notebooks, on made-up inputs (no verdict of
their own: the claims decide)."""

from __future__ import annotations

import numpy as np
import pytest

from fpdtw import plain
from fpdtw.online.window import B_CORNER, SMOOTHING
from fpdtw.paper import numbers as N
from fpdtw.paper.claims.rules import Check
from fpdtw.paper.figures import paper_vs_ours as C


def ours(rows) -> dict:
    return {r["quantity"]: r["ours"] for r in rows}


def test_the_papers_constants_are_the_librarys():
    assert N.METHOD_B_CORNER == B_CORNER
    assert N.FORECAST_LEVEL == SMOOTHING
    from fpdtw import PAPER_JOINTS

    # Section 4: "hip, knees, shoulder and elbows", 8 joints
    assert len(PAPER_JOINTS) == 8


def test_format_side_by_side_is_an_aligned_deterministic_table_without_a_verdict():
    rows = [C.side_by_side("a", 1, "x"), C.side_by_side("longer name", "p", 2.5)]
    text = C.format_side_by_side(rows, title="T")
    lines = text.splitlines()
    assert lines[0] == "T"
    assert lines[1].split(" | ") == ["quantity   ", "paper", "ours"]
    assert set(lines[2]) <= {"-", "+"}
    assert lines[3] == "a           | 1     | x" and lines[4] == "longer name | p     | 2.5"
    assert len({x.index("|") for x in lines[1:] if "|" in x}) == 1  # columns aligned
    assert C.side_by_side("q", 1, 2) == dict(quantity="q", paper="1", ours="2")
    assert C.format_side_by_side(rows) == "\n".join(lines[1:])


def test_data_comparison():
    summary = [
        dict(dataset="authors_fbx", movement="Walk", listed=3, available=3),
        dict(dataset="authors_fbx", movement="Jog", listed=3, available=0),
        dict(dataset="hdm05", movement="squat", listed=2, available=2),
        dict(dataset="cmu", movement="shake", listed=1, available=1),  # not FP-DTW data
    ]
    rows = C.data_comparison(summary)
    assert [r["ours"] for r in rows] == ["3 (of 6 listed)", "2 (of 2 listed)", "5", "2"]
    assert [r["paper"] for r in rows] == [
        str(N.DATA_SOURCES["authors_fbx"]),
        str(N.DATA_SOURCES["hdm05"]),
        str(N.DATA["motions"]),
        str(N.DATA["movements"]),
    ]
    assert all(set(r) == {"quantity", "paper", "ours"} for r in rows)


def test_oedtw_comparison():
    jump = dict(jumps=2, n_frames=30, first_jump=dict(q=14, e_q=20, e_q1=17))
    (row,) = C.oedtw_comparison(jump)
    assert row["ours"] == "2 in 29 steps; first at frames 14 -> 15: e 20 -> 17"
    assert f"{N.FIG1_FRAMES[0]} -> {N.FIG1_FRAMES[1]}" in row["paper"]
    (row,) = C.oedtw_comparison(dict(jumps=0, n_frames=30, first_jump=None))
    assert row["ours"] == "none in 29 steps"


def _steps(offset_a=1, offset_b=1, offset_c=2, corner=B_CORNER):
    """Plain steps (fpdtw.plain.Step) with only what windows_comparison reads."""
    a = plain.Step(
        50 + offset_a, "window", 2, np.array([[0.3], [0.1], [0.2]]), M_n=50, q=60
    )  # fmt: skip
    D = np.ones((4, 5))
    D[0, 0] = corner
    b1 = plain.Step(
        3 + offset_b, "window", 3, D=D, M_n=3, q=5,
        path=np.array([[0, 0], [1, 0], [1, 1], [2, 1], [3, 2], [3, 3], [3, 4]]),
    )  # fmt: skip
    b2 = plain.Step(
        7, "window", 3, D=D, M_n=7, q=9,
        path=np.array([[0, 0], [0, 1], [1, 2], [2, 3], [3, 4]]),
    )  # fmt: skip
    Dc = np.array([[3.0, 1.0], [2.0, 1.0], [1.0, 1.0]])
    c = plain.Step(3 + offset_c, "window", 2, D=Dc, M_n=3, q=5)
    return a, [b1, b2], c


def test_windows_comparison_shows_the_steps_beside_the_algorithms():
    a, bs, c = _steps()
    got = ours(C.windows_comparison(a, bs, c))
    assert got["Ma: frames searched (Fig. 2)"] == "3: I_50 .. I_52"
    assert got["Ma: M_n+1 = M_n + argmin of eq. 1"] == "offset 1, argmin 1"
    assert got["Mb: D[0, 0] before back-tracking"] == f"{B_CORNER:,.0f}"
    assert got["Mb: path leaves (0, 0) via"] == "(0, 1), (1, 0)"
    assert got["Mb: X = lowest input row of the path in column T_n+1"] == "2 of 2 steps drawn"
    assert got["Mc: M_n+1 = M_n + argmin of D over column T_n+1"] == "offset 2, argmin 2"
    got = ours(C.windows_comparison(*_steps(offset_a=0, offset_b=2, offset_c=0, corner=1.0)))
    assert got["Ma: M_n+1 = M_n + argmin of eq. 1"] == "offset 0, argmin 1"
    assert got["Mb: D[0, 0] before back-tracking"] == "1"
    assert got["Mb: X = lowest input row of the path in column T_n+1"] == "1 of 2 steps drawn"
    assert got["Mc: M_n+1 = M_n + argmin of D over column T_n+1"] == "offset 0, argmin 2"
    a, bs, c = _steps()
    got = ours(C.windows_comparison(a, [bs[0], None], c))
    assert got["Mb: path leaves (0, 0) via"] == "(1, 0)"


def test_forecast_comparison():
    levels = [2, 3, 4]
    dr = np.array([[1.0, 2.0, 9.0], [2.0, 3.0, 3.0], [3.0, 4.0, 5.0]])  # s = 2 best at 1, 2
    curves = {"dead_reckoning": dr, "holt": dr + 0.5, "exponential": dr - 0.1 * np.eye(3)}
    rows = C.forecast_comparison(curves, levels, ahead=(1, 3), short=(1, 2))
    got = ours(rows)
    assert got["best level s, dead reckoning, 1 frame ahead"] == "s = 2"
    assert got["best level s, dead reckoning, 3 frames ahead"] == "s = 3"
    assert rows[1]["ours"] == "s = 3" and rows[0]["paper"] == f"s = {N.FORECAST_LEVEL}"
    # exponential's best (0.9) is below dead reckoning's 1.0 at i = 1, not at i = 2
    assert got["dead reckoning (s = 2) vs the others' best, 1 ahead"] == (
        "1.000 vs holt 1.500, exponential 0.900"
    )
    assert rows[-1]["ours"] == "2.000 vs holt 2.500, exponential 2.000"


def test_paper_passes_reads_sections_5_and_7():
    assert C.paper_passes("Mc w40", "similarity") and C.paper_passes("Mc w40", "deviation")
    assert C.paper_passes("Ma + Type V", "deviation") is True
    assert C.paper_passes("Mb w80", "similarity") is False
    assert C.paper_passes("Mb w80 + Type V", "similarity") is None
    assert C.paper_passes("OLTW", "similarity") is None
    with pytest.raises(ValueError):
        C.paper_passes("Ma", "speed")


def _summary(medians, metric, bench, spread=0.01):
    """Summary rows as score_summary gives them, the verdict from a made-up interval."""

    def verdict(v):
        thr = bench if metric == "similarity" else 18.0
        return Check("x", v, v - spread, v + spread, thr, above=metric == "similarity").verdict

    return [
        dict(algorithm=n, median=v, ci_low=v - spread, ci_high=v + spread, benchmark=bench,
             passes_benchmark=(v > bench) if metric == "similarity" else (v < 18),
             verdict=verdict(v))
        for n, v in medians.items()
    ]  # fmt: skip


def test_benchmark_comparison():
    sim = {"UTW": 0.24, "Ma": 0.1, "Mc w40": 0.3, "Mb w80": 0.3, "Mb w80 + Type V": 0.5}
    rows = C.benchmark_comparison(_summary(sim, "similarity", 0.24), "similarity")
    assert rows[0]["paper"] == f"{N.TABLE1[120]['UTW']:.3f}" and rows[0]["ours"] == "0.240"
    got = ours(rows)
    paper = {r["quantity"]: r["paper"] for r in rows}
    # ours: the claims' check of the pass, with the interval
    assert got["Ma: median above UTW?"] == "contradicted (0.100 [0.090, 0.110])"
    assert got["Mc w40: median above UTW?"] == "holds (0.300 [0.290, 0.310])"
    assert (
        paper["Mc w40: median above UTW?"] == "yes" and paper["Mb w80: median above UTW?"] == "no"
    )
    assert paper["Mb w80 + Type V: median above UTW?"] == "not stated (not both)"
    assert "UTW: median above UTW?" not in got  # offline baselines are left out
    assert all("holds" not in r for r in rows)  # no verdict of the table's own
    rows = C.benchmark_comparison(_summary({"Mc w80": 30.0}, "deviation", 18), "deviation")
    assert rows[0]["paper"] == "18 frames"
    assert rows[1]["ours"] == "contradicted (30.0 [30.0, 30.0])"
    # an interval across the benchmark: inconclusive, never a pass
    rows = C.benchmark_comparison(_summary({"Mc w40": 17.0}, "deviation", 18, 2.0), "deviation")
    assert rows[1]["ours"] == "inconclusive (17.0 [15.0, 19.0])"


def _table1(values):
    rows = []
    for rate, med in values.items():
        row = {"rate_hz": rate, "source": "ours", "UTW": med["UTW"]}
        row.update({f"w{w}": med[w] for w in N.WINDOWS})
        row["best_w"] = max(N.WINDOWS, key=lambda w: med[w])
        rows.append(row)
    return rows


def test_table1_comparison():
    rows = C.table1_comparison(_table1(N.TABLE1))
    assert rows[0]["quantity"] == "120 Hz UTW"
    assert rows[0]["paper"] == rows[0]["ours"] == f"{N.TABLE1[120]['UTW']:.3f}"
    # the paper's own values: each window on the paper's side of UTW
    assert all(r["paper"] == r["ours"] for r in rows if "Mc w" in r["quantity"])
    flipped = {rate: {**med, "UTW": 0.0} for rate, med in N.TABLE1.items()}  # all above UTW
    flipped[120][10] = 0.9  # best window 10
    got = ours(C.table1_comparison(_table1(flipped)))
    assert got["120 Hz Mc w10"] == "0.900 (above UTW)"
    assert got["120 Hz best window"] == "w10"
    assert got["60 Hz best window"] == f"w{N.BEST_WINDOW[60]}"
    assert C.table1_comparison(_table1(N.TABLE1), source="ours (literal window)") == []
    # with the claims' verdicts (table1_rows gives them), quoted beside ours
    rows = _table1(N.TABLE1)
    rows[0].update({f"verdict_w{w}": "holds" for w in N.WINDOWS}, best_verdict="inconclusive")
    got = ours(C.table1_comparison(rows))
    rate = rows[0]["rate_hz"]
    assert got[f"{rate} Hz best window"].endswith(f"(w{N.BEST_WINDOW[rate]} best: inconclusive)")
    assert got[f"{rate} Hz Mc w80"].endswith("UTW: holds)")


def _bal(diag, below, above):
    return dict(diagonal=diag, below=below, above=above)


def test_heatmap_comparison():
    paper_like = {
        "Mb w10": _bal(0.4, 0.5, 0.1),
        "Mb w80": _bal(0.5, 0.4, 0.1),
        "Mc w10": _bal(0.4, 0.5, 0.1),
        "Mc w20": _bal(0.5, 0.3, 0.2),
        "Mc w40": _bal(0.6, 0.2, 0.2),
        "Mc w80": _bal(0.4, 0.1, 0.5),
        "Ma": _bal(0.3, 0.6, 0.1),
        "Ma + Type V": _bal(0.6, 0.3, 0.1),
        "Mc w10 + Type V": _bal(0.3, 0.6, 0.1),
        "Mc w80 + Type V": _bal(0.6, 0.2, 0.2),
    }
    rows = C.heatmap_comparison(paper_like)
    assert len(rows) == 9
    # the paper-like balances read as the paper's words
    assert all(r["ours"].startswith(r["paper"]) for r in rows if r["quantity"].startswith("Fig. 7"))
    opposite = {**paper_like, "Mc w10": _bal(0.4, 0.1, 0.5), "Mc w20": _bal(0.6, 0.2, 0.2)}
    opposite["Mc w10 + Type V"] = _bal(0.9, 0.05, 0.05)
    rows = C.heatmap_comparison(opposite)
    got, paper = ours(rows), {r["quantity"]: r["paper"] for r in rows}
    assert paper["Fig. 7 Mc w10"] == "sticks"
    assert got["Fig. 7 Mc w10"] == "skips (below 0.10, above 0.50)"
    # Mc w20 (tied at 0) is the more balanced
    assert got["Fig. 7 Mc w40"] == "not the most balanced (below 0.20, above 0.20)"
    assert paper["Fig. 10 Mc w10: Type V improves (near diagonal)"] == "no"
    assert got["Fig. 10 Mc w10: Type V improves (near diagonal)"] == "yes (0.40 -> 0.90)"
    assert C.heatmap_comparison({}) == []


def test_timing_comparison_shows_values_only():
    rows = [
        dict(algorithm="Mb w10", method="B", w=10, type_v=False, mean_us=10.0, median_us=8.0,
             paper_mean_us=N.TABLE2_US[("B", 10)]),
        dict(algorithm="Mb w10 + Type V", method="B", w=10, type_v=True, mean_us=1.0,
             median_us=1.0, paper_mean_us=None),
        dict(algorithm="Ma", method="A", w=None, type_v=False, mean_us=1.0, median_us=1.0,
             paper_mean_us=None),
    ]  # fmt: skip
    (row,) = C.timing_comparison(rows)
    assert row["paper"] == f"{N.TABLE2_US[('B', 10)]:.0f} us" and "holds" not in row
    assert f"{N.TABLE2_US[('B', 10)] / 10:.0f}x faster" in row["ours"]


def test_walk_pair_comparison():
    rows = [dict(algorithm="DTW", deviation=0.0)]
    rows += [dict(algorithm=n, deviation=v) for n, v in N.FIG8_DEVIATIONS.items()]
    rows += [dict(algorithm="Mc w80 (literal window)", deviation=100.0)]
    out = C.walk_pair_comparison(rows)
    got = ours(out)
    assert "DTW" not in got
    assert all(got[n].endswith("same side as the paper's)") for n in N.FIG8_DEVIATIONS)
    # the paper's 6 is below 18, our 100 above
    assert got["Mc w80 (literal window)"] == "100.0 (above 18: not the paper's side)"


def test_typev_comparison():
    got = ours(C.typev_comparison(True, True, False, 3))
    assert got["Type V carried between target frames by states"] == "3 states"
    assert got["Ma + Type V map is a legal Type V path"] == "state table yes, dtw-python yes"
    assert got["unconstrained Ma is a legal Type V path"] == "no"
    got = ours(C.typev_comparison(True, False, True, 1))
    assert got["Ma + Type V map is a legal Type V path"] == "state table yes, dtw-python no"
    assert got["Type V carried between target frames by states"] == "1 states"


def test_opw_fig4_comparison():
    poster = dict(
        opw_mean_ms_range=list(N.OPW_MEAN_DEVIATION_MS),
        opw_max_ms=N.OPW_MAX_DEVIATION_MS,
        dtw_mean_ms_range=[20.0, 30.0],
        dtw_better_everywhere=N.OPW_DTW_BETTER,
        opw_smoother_everywhere=N.OPW_SMOOTHER,
    )
    rows = C.opw_fig4_comparison(poster)
    assert [r["paper"] for r in rows[:2]] == [r["ours"] for r in rows[:2]]
    worse = {**poster, "opw_mean_ms_range": [20.0, 30.0], "opw_max_ms": 200.0,
             "opw_smoother_everywhere": False}  # fmt: skip
    assert [r["ours"] for r in C.opw_fig4_comparison(worse)] == [
        "20-30 ms", "200 ms", f"{'yes' if N.OPW_DTW_BETTER else 'no'} (DTW 20-30 ms)", "no",
    ]  # fmt: skip


def test_live_comparison():
    rows = C.live_comparison({"Mc w40": 3.0, "Ma + Type V": 30.0, "OLTW": 1.0})
    assert [r["ours"] for r in rows] == [
        "3.0 frames (below 18, this pair)", "30.0 frames (above 18, this pair)",
        "1.0 frames (below 18, this pair)",
    ]  # fmt: skip
    assert rows[0]["paper"] == "passes both benchmarks (all pairs)"
    assert rows[2]["paper"] == "not in the paper"


def test_live_timing_comparison():
    from fpdtw.app.live import live_timing_comparison

    rows = live_timing_comparison(
        {"Mc w40": [1e-5, 2e-5, 3e-5], "Ma + Type V": [1e-6], "OLTW": [5e-6]}, fps=120.0
    )
    assert rows[0]["paper"] == f"{N.TABLE2_US[('C', 40)]:.0f} us (mean)"
    assert rows[0]["ours"] == "20 us (median; budget 8333 us)"
    assert [r["paper"] for r in rows[1:]] == ["not in Table 2"] * 2
    assert all("holds" not in r for r in rows)
