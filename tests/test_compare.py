"""The "paper | ours | holds?" rows of the companion notebooks, on made-up inputs."""

from __future__ import annotations

import numpy as np
import pytest

from fpdtw.online.window import B_CORNER, SMOOTHING, WindowSnapshot
from fpdtw.paper import compare as C
from fpdtw.paper import numbers as N


def holds(rows) -> dict:
    return {r["quantity"]: r["holds"] for r in rows}


def test_the_papers_constants_are_the_librarys():
    assert N.METHOD_B_CORNER == B_CORNER
    assert N.FORECAST_LEVEL == SMOOTHING
    from fpdtw import PAPER_JOINTS

    assert len(PAPER_JOINTS) == N.N_JOINTS


def test_format_comparison_is_an_aligned_deterministic_table():
    rows = [C.comparison_row("a", 1, "x", True), C.comparison_row("longer name", "p", 2.5)]
    text = C.format_comparison(rows, title="T")
    lines = text.splitlines()
    assert lines[0] == "T"
    assert lines[1].split(" | ") == ["quantity   ", "paper", "ours", "holds?"]
    assert set(lines[2]) <= {"-", "+"}
    assert lines[3].split(" | ")[-1] == "yes" and lines[4].endswith("| -")
    assert len({x.index("|") for x in lines[1:] if "|" in x}) == 1  # columns aligned
    assert C.comparison_row("q", 1, 2, False)["holds"] == "no"
    assert C.comparison_row("q", 1, 2, np.bool_(True))["holds"] == "yes"
    assert C.comparison_row("q", 1, 2, "partly")["holds"] == "partly"


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
    assert {r["holds"] for r in rows} == {"no"}


def test_oedtw_comparison():
    jump = dict(jumps=2, n_frames=30, first_jump=dict(q=14, e_q=20, e_q1=17))
    (row,) = C.oedtw_comparison(jump)
    assert (
        row["holds"] == "yes"
        and row["ours"] == "2 in 29 steps; first at frames 14 -> 15: e 20 -> 17"
    )
    assert f"{N.FIG1_FRAMES[0]} -> {N.FIG1_FRAMES[1]}" in row["paper"]
    (row,) = C.oedtw_comparison(dict(jumps=0, n_frames=30, first_jump=None))
    assert row["holds"] == "no" and row["ours"] == "none in 29 steps"


def _steps(offset_a=1, offset_b=1, offset_c=2, corner=B_CORNER):
    a = WindowSnapshot(
        q=60, kind="window", start=50, w_i=2, offset=offset_a, M=50 + offset_a,
        C=np.array([[0.3], [0.1], [0.2]]),
    )  # fmt: skip
    D = np.ones((4, 5))
    D[0, 0] = corner
    b1 = WindowSnapshot(
        q=5, kind="window", start=3, w_i=3, offset=offset_b, M=3 + offset_b, D=D,
        path=np.array([[0, 0], [1, 0], [1, 1], [2, 1], [3, 2], [3, 3], [3, 4]]),
    )  # fmt: skip
    b2 = WindowSnapshot(
        q=9, kind="window", start=7, w_i=3, offset=0, M=7, D=D,
        path=np.array([[0, 0], [0, 1], [1, 2], [2, 3], [3, 4]]),
    )  # fmt: skip
    Dc = np.array([[3.0, 1.0], [2.0, 1.0], [1.0, 1.0]])
    c = WindowSnapshot(q=5, kind="window", start=3, w_i=3, offset=offset_c, M=3, D=Dc)
    return a, [b1, b2], c


def test_windows_comparison_checks_the_steps_against_the_algorithms():
    a, bs, c = _steps()
    assert set(holds(C.windows_comparison(a, bs, c)).values()) == {"yes"}
    got = holds(C.windows_comparison(*_steps(offset_a=0, offset_b=2, offset_c=0, corner=1.0)))
    assert got["Ma: M_n+1 = M_n + argmin of eq. 1"] == "no"
    assert got["Mb: D[0, 0] before back-tracking"] == "no"
    assert got["Mb: X = lowest input row of the path in column T_n+1"] == "partly"
    assert got["Mc: M_n+1 = M_n + argmin of D over column T_n+1"] == "no"
    a, bs, c = _steps()
    got = holds(C.windows_comparison(a, [bs[0], None], c))
    assert got["Mb: path leaves (0, 0) via"] == "partly"  # (1, 0) only


def test_forecast_comparison():
    levels = [2, 3, 4]
    dr = np.array([[1.0, 2.0, 9.0], [2.0, 3.0, 3.0], [3.0, 4.0, 5.0]])  # s = 2 best at 1, 2
    curves = {"dead_reckoning": dr, "holt": dr + 0.5, "exponential": dr - 0.1 * np.eye(3)}
    rows = C.forecast_comparison(curves, levels, ahead=(1, 3), short=(1, 2))
    got = holds(rows)
    assert got["best level s, dead reckoning, 1 frame ahead"] == "yes"
    assert got["best level s, dead reckoning, 3 frames ahead"] == "no"  # s = 3 at i = 3
    assert rows[1]["ours"] == "s = 3" and rows[0]["paper"] == f"s = {N.FORECAST_LEVEL}"
    # exponential's best (0.9) beats dead reckoning's 1.0 at i = 1, not at i = 2
    assert got["dead reckoning (s = 2) vs the others' best, 1 ahead"] == "no"
    assert got["dead reckoning (s = 2) vs the others' best, 2 ahead"] == "yes"
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
    from fpdtw.paper.claims.rules import Check

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
    got = holds(rows)
    assert got["Ma: median above UTW?"] == "yes"  # both fail
    assert got["Mc w40: median above UTW?"] == "yes"  # both pass
    assert got["Mb w80: median above UTW?"] == "no"  # ours passes, the paper's does not
    assert got["Mb w80 + Type V: median above UTW?"] == "-"  # the paper does not say
    assert "UTW: median above UTW?" not in got  # offline baselines are left out
    rows = C.benchmark_comparison(_summary({"Mc w80": 30.0}, "deviation", 18), "deviation")
    assert rows[0]["paper"] == "18 frames" and rows[1]["ours"] == "no (30.0 [30.0, 30.0])"
    assert rows[1]["holds"] == "yes"
    # an interval across the benchmark: the comparison is inconclusive, never a pass
    rows = C.benchmark_comparison(_summary({"Mc w40": 17.0}, "deviation", 18, 2.0), "deviation")
    assert rows[1]["ours"] == "inconclusive (17.0 [15.0, 19.0])"
    assert rows[1]["holds"] == "inconclusive"


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
    assert {r["holds"] for r in rows} == {"yes", "-"}
    assert rows[0]["quantity"] == "120 Hz UTW" and rows[0]["holds"] == "-"
    flipped = {rate: {**med, "UTW": 0.0} for rate, med in N.TABLE1.items()}  # all above UTW
    flipped[120][10] = 0.9  # best window 10
    got = holds(C.table1_comparison(_table1(flipped)))
    assert got["120 Hz Mc w10"] == "no" and got["120 Hz Mc w40"] == "yes"
    assert got["120 Hz best window"] == "no" and got["60 Hz best window"] == "yes"
    assert C.table1_comparison(_table1(N.TABLE1), source="ours (literal window)") == []
    # with the claims' verdicts (table1_rows gives them): an inconclusive best window
    rows = _table1(N.TABLE1)
    rows[0].update({f"verdict_w{w}": "holds" for w in N.WINDOWS}, best_verdict="inconclusive")
    got = holds(C.table1_comparison(rows))
    assert got["60 Hz best window"] == "inconclusive"
    assert got["60 Hz Mc w80"] == "no"  # ours holds above UTW, the paper's is below


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
    assert len(rows) == 9 and {r["holds"] for r in rows} == {"yes"}
    opposite = {**paper_like, "Mc w10": _bal(0.4, 0.1, 0.5), "Mc w20": _bal(0.6, 0.2, 0.2)}
    opposite["Mc w10 + Type V"] = _bal(0.9, 0.05, 0.05)
    got = holds(C.heatmap_comparison(opposite))
    assert got["Fig. 7 Mc w10"] == "no"  # skips, the paper says sticks
    assert got["Fig. 7 Mc w40"] == "no"  # Mc w20 (tied at 0) is the more balanced
    assert got["Fig. 10 Mc w10: Type V improves (near diagonal)"] == "no"
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
    assert row["paper"] == f"{N.TABLE2_US[('B', 10)]:.0f} us" and row["holds"] == "-"
    assert f"{N.TABLE2_US[('B', 10)] / 10:.0f}x faster" in row["ours"]


def test_walk_pair_comparison():
    rows = [dict(algorithm="DTW", deviation=0.0)]
    rows += [dict(algorithm=n, deviation=v) for n, v in N.FIG8_DEVIATIONS.items()]
    rows += [dict(algorithm="Mc w80 (literal window)", deviation=100.0)]
    out = C.walk_pair_comparison(rows)
    got = holds(out)
    assert "DTW" not in got
    # another pair than the paper's: never a yes or a no, whatever the numbers
    assert set(got.values()) == {"not comparable"}
    ours = {r["quantity"]: r["ours"] for r in out}
    assert all(ours[n].endswith("same side as the paper's)") for n in N.FIG8_DEVIATIONS)
    # the paper's 6 is below 18, our 100 above
    assert ours["Mc w80 (literal window)"] == "100.0 (above 18: not the paper's side)"


def test_typev_comparison():
    assert set(holds(C.typev_comparison(True, True, False, 3)).values()) == {"yes", "-"}
    got = holds(C.typev_comparison(True, False, True, 1))
    assert got["Ma + Type V map is a legal Type V path"] == "partly"
    assert got["Type V carried between target frames by states"] == "no"


def test_opw_fig4_comparison():
    poster = dict(
        opw_mean_ms_range=list(N.OPW_MEAN_DEVIATION_MS),
        opw_max_ms=N.OPW_MAX_DEVIATION_MS,
        dtw_mean_ms_range=[20.0, 30.0],
        dtw_better_everywhere=N.OPW_DTW_BETTER,
        opw_smoother_everywhere=N.OPW_SMOOTHER,
    )
    assert {r["holds"] for r in C.opw_fig4_comparison(poster)} == {"yes"}
    worse = {**poster, "opw_mean_ms_range": [20.0, 30.0], "opw_max_ms": 200.0,
             "opw_smoother_everywhere": False}  # fmt: skip
    assert [r["holds"] for r in C.opw_fig4_comparison(worse)] == ["no", "no", "yes", "no"]


def test_live_comparison():
    rows = C.live_comparison({"Mc w40": 3.0, "Ma + Type V": 30.0, "OLTW": 1.0})
    assert [r["holds"] for r in rows] == ["yes", "no", "-"]
    assert rows[2]["paper"] == "not in the paper"


def test_live_timing_comparison():
    rows = C.live_timing_comparison(
        {"Mc w40": [1e-5, 2e-5, 3e-5], "Ma + Type V": [1e-6], "OLTW": [5e-6]}, fps=120.0
    )
    assert rows[0]["paper"] == f"{N.TABLE2_US[('C', 40)]:.0f} us (mean)"
    assert rows[0]["ours"] == "20 us (median; budget 8333 us)"
    assert [r["paper"] for r in rows[1:]] == ["not in Table 2"] * 2
    assert {r["holds"] for r in rows} == {"-"}
