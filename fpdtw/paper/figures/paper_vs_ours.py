"""Paper | ours: the paper's values (from :mod:`fpdtw.paper.numbers`) next to ours, printed
after the notebooks' figures; rows of :data:`COLUMNS` with no verdict of their own (a verdict
quoted in ``ours`` is the claims').
"""

from __future__ import annotations

import numpy as np

from fpdtw.paper import numbers as N
from fpdtw.paper.figures.forecast import best_level

#: Keys of every row.
COLUMNS = ("quantity", "paper", "ours")


def side_by_side(quantity: str, paper, ours) -> dict:
    """One row: ``quantity``, ``paper``, ``ours``, each shown with ``str``."""
    return dict(quantity=str(quantity), paper=str(paper), ours=str(ours))


def _rows(*triples) -> list[dict]:
    return [side_by_side(*t) for t in triples]


def format_side_by_side(rows, title: str | None = None) -> str:
    """The rows as a fixed-width text table.

    Notebook: 07_table1_60hz.ipynb
    """
    table = [dict(zip(COLUMNS, COLUMNS))] + [{c: str(r[c]) for c in COLUMNS} for r in rows]
    widths = {c: max(len(r[c]) for r in table) for c in COLUMNS}
    lines = [" | ".join(r[c].ljust(widths[c]) for c in COLUMNS).rstrip() for r in table]
    lines.insert(1, "-+-".join("-" * widths[c] for c in COLUMNS))
    return "\n".join(([title] if title else []) + lines)


def _yes_no(x: bool) -> str:
    return "yes" if x else "no"


def _side(ok: bool) -> str:
    return "below" if ok else "above"


def data_comparison(summary_rows) -> list[dict]:
    """Section 4's data beside ours (:func:`fpdtw.paper.catalog.summary_rows`).

    Paper: FP-DTW Section 4.
    Notebook: 01_data_and_motions.ipynb
    """
    rows = [r for r in summary_rows if r["dataset"] in N.DATA_SOURCES]

    def total(key, ds=None):
        return sum(int(r[key]) for r in rows if ds in (None, r["dataset"]))

    out = [
        side_by_side(f"motions from {ds}", paper,
                     f"{total('available', ds)} (of {total('listed', ds)} listed)")
        for ds, paper in N.DATA_SOURCES.items()
    ]  # fmt: skip
    movements = sum(int(r["available"]) > 0 for r in rows)
    return out + _rows(
        ("motions in all", N.DATA["motions"], total("available")),
        ("movements", N.DATA["movements"], movements),
    )


def oedtw_comparison(facts: dict, label: str = "OE-DTW") -> list[dict]:
    """Fig. 1: do OE-DTW's end points move backwards (:func:`.oedtw.oedtw_facts`)?

    Paper: FP-DTW Section 2, Fig. 1.
    Notebook: 02_fig1_oedtw.ipynb
    """
    a, b = N.FIG1_FRAMES
    steps = facts["n_frames"] - 1
    if j := facts.get("first_jump"):
        ours = (f"{facts['jumps']} in {steps} steps; first at frames {j['q']} -> {j['q'] + 1}: "
                f"e {j['e_q']} -> {j['e_q1']}")  # fmt: skip
    else:
        ours = f"none in {steps} steps"
    return _rows((f"{label}: end point moves backwards", f"yes, e.g. frames {a} -> {b}", ours))


def windows_comparison(step_a, steps_b, step_c) -> list[dict]:
    """Figs. 2 and 4: what Algorithms 1-3 prescribe, beside the plain steps drawn.

    Paper: FP-DTW Algorithms 1-3, Figs. 2 and 4.
    Notebook: 03_fig2_fig4_windows.ipynb
    """
    w, n_a = N.METHOD_A_WINDOW, int(step_a.C.shape[0])
    rows = _rows(
        ("Ma: frames searched (Fig. 2)", f"w + 1 = {w + 1}: I_Mn .. I_Mn+{w}",
         f"{n_a}: I_{step_a.M_n} .. I_{step_a.M_n + n_a - 1}"),
        ("Ma: M_n+1 = M_n + argmin of eq. 1", "Algorithm 1",
         f"offset {step_a.M - step_a.M_n}, argmin {int(np.argmin(step_a.C[:, 0]))}"),
    )  # fmt: skip
    found = [s for s in steps_b if s is not None]
    if found:
        paper, corner = N.METHOD_B_CORNER, float(found[0].D[0, 0])
        rows += _rows(("Mb: D[0, 0] before back-tracking", f"{paper:,.0f}", f"{corner:,.0f}"))
    vias = sorted({tuple(int(v) for v in s.path[1]) for s in found})
    hits = sum(s.M - s.M_n == int(min(r for r, c in s.path if c == 1)) for s in found)
    score = step_c.score if step_c.score is not None else step_c.D[:, 0]
    return rows + _rows(
        ("Mb: path leaves (0, 0) via", "(1, 0) or (0, 1) (Fig. 4)",
         ", ".join(f"({r}, {c})" for r, c in vias) or "no window step"),
        ("Mb: X = lowest input row of the path in column T_n+1", "M_n+1 = M_n + P_1 (Fig. 4)",
         f"{hits} of {len(found)} steps drawn"),
        ("Mc: M_n+1 = M_n + argmin of D over column T_n+1", "Algorithm 3",
         f"offset {step_c.M - step_c.M_n}, argmin {int(np.argmin(score))}"),
    )  # fmt: skip


def forecast_comparison(curves: dict, levels, ahead=(1, 10), short=(1, 10)) -> list[dict]:
    """Fig. 3: dead reckoning's best level per horizon of ``ahead``; per horizon of ``short``
    its error at s = 2 beside the other forecasters' best.

    Paper: FP-DTW Section 3.2 and Fig. 3.
    Notebook: 04_fig3_forecast.ipynb
    """
    levels, s = list(levels), N.FORECAST_LEVEL
    dr = np.asarray(curves["dead_reckoning"], dtype=float)
    rows = [
        side_by_side(f"best level s, dead reckoning, {i} frame{'s' if i > 1 else ''} ahead",
                     f"s = {s}", f"s = {best_level(dr, levels, i)}")
        for i in ahead
    ]  # fmt: skip
    others = [m for m in curves if m != "dead_reckoning"]
    if others and s in levels:
        for i in short:
            theirs = ", ".join(f"{m} {float(np.min(np.asarray(curves[m])[:, i - 1])):.3f}"
                               for m in others)  # fmt: skip
            rows += _rows((f"dead reckoning (s = {s}) vs the others' best, {i} ahead",
                           "as good (short term)",
                           f"{float(dr[levels.index(s), i - 1]):.3f} vs {theirs}"))  # fmt: skip
    return rows


def paper_passes(name: str, metric: str):
    """Whether the paper says an FP-DTW algorithm's median passes a benchmark (None: unsaid).

    Paper: FP-DTW Sections 5 and 7.
    """
    if metric not in ("similarity", "deviation"):
        raise ValueError(f"metric must be 'similarity' or 'deviation', got {metric!r}")
    if name in N.PASS_BOTH:
        return True
    if name in N.FPDTW_NAMES:
        return name in N.PASS_EITHER_UNCONSTRAINED
    return None


def benchmark_comparison(summary_rows, metric: str) -> list[dict]:
    """Figs. 5 / 6: the benchmark, then per FP-DTW algorithm of :func:`.scores.score_summary`
    the claims' verdict on its median beside :func:`paper_passes`.

    Paper: FP-DTW Figs. 5 and 6, Sections 5-7.
    Notebook: 06_fig5_fig6_scores.ipynb
    """
    if metric == "similarity":
        paper, ours = N.TABLE1[N.SAMPLE_RATE_HZ]["UTW"], summary_rows[0]["benchmark"]
        rows = _rows(("UTW median similarity (the benchmark)", f"{paper:.3f}", f"{ours:.3f}"))
        word, fmt = "above UTW", ".3f"
    else:
        paper, ours = N.DEVIATION_BENCHMARK_FRAMES, N.deviation_benchmark_frames(N.SAMPLE_RATE_HZ)
        rows = _rows(("deviation benchmark (150 ms)", f"{paper} frames", f"{ours:g} frames"))
        word, fmt = "below 18", ".1f"
    for r in summary_rows:
        name = r["algorithm"]
        if name not in N.FPDTW_NAMES and name not in N.FPDTW_TYPEV_NAMES:
            continue
        paper = paper_passes(name, metric)
        iv = f"{r['median']:{fmt}} [{r['ci_low']:{fmt}}, {r['ci_high']:{fmt}}]"
        rows += _rows((f"{name}: median {word}?",
                       "not stated (not both)" if paper is None else _yes_no(paper),
                       f"{r['verdict']} ({iv})"))  # fmt: skip
    return rows


def table1_comparison(rows, source: str = "ours") -> list[dict]:
    """Table 1 cell by cell (:func:`.scores.table1_rows` of ``source``), and the best window.

    Paper: FP-DTW Table 1.
    Notebook: 07_table1_60hz.ipynb
    """
    out = []
    for rate in sorted({r["rate_hz"] for r in rows}, reverse=True):
        paper = N.TABLE1.get(rate)
        ours = next((r for r in rows if r["rate_hz"] == rate and r["source"] == source), None)
        if paper is None or ours is None:
            continue
        out += _rows((f"{rate} Hz UTW", f"{paper['UTW']:.3f}", f"{ours['UTW']:.3f}"))
        for w in N.WINDOWS:
            v = ours.get(f"verdict_w{w}")
            p_side = "above" if paper[w] > paper["UTW"] else "below"
            o_side = "above" if ours[f"w{w}"] > ours["UTW"] else "below"
            v = "" if v is None else ": " + v
            out += _rows((f"{rate} Hz Mc w{w}", f"{paper[w]:.3f} ({p_side} UTW)",
                          f"{ours[f'w{w}']:.3f} ({o_side} UTW{v})"))  # fmt: skip
        v, best = ours.get("best_verdict"), N.BEST_WINDOW[rate]
        v = "" if v is None else f" (w{best} best: {v})"
        out += _rows((f"{rate} Hz best window", f"w{best}", f"w{ours['best_w']}{v}"))
    return out


def _imbalance(b: dict) -> float:
    return abs(b["below"] - b["above"])


def heatmap_comparison(balance: dict) -> list[dict]:
    """Figs. 7 and 10 in words, from :func:`.heatmaps.path_balance` per algorithm: "sticks",
    "skips" or "balanced" (smallest ``|below - above|`` of its method's windows); Type V's
    share near the diagonal.

    Paper: FP-DTW Section 5 (Fig. 7), Section 6 (Fig. 10).
    Notebook: 08_fig7_fig10_heatmaps.ipynb
    """
    rows = []
    for name, claimed in N.FIG7_TENDENCY.items():
        if name not in balance:
            continue
        b = balance[name]
        if claimed == "balanced":
            base = name.partition(" w")[0]
            peers = [n for n in (f"{base} w{w}" for w in N.WINDOWS) if n in balance]
            best = min(peers, key=lambda n: _imbalance(balance[n])) == name
            verdict = "balanced" if best else "not the most balanced"
        else:
            verdict = "sticks" if b["below"] > b["above"] else "skips"
        rows += _rows((f"Fig. 7 {name}", claimed,
                       f"{verdict} (below {b['below']:.2f}, above {b['above']:.2f})"))  # fmt: skip
    for name, improves in N.FIG10_TYPEV_IMPROVES.items():
        tv = name + N.TYPE_V
        if name in balance and tv in balance:
            d0, d1 = balance[name]["diagonal"], balance[tv]["diagonal"]
            rows += _rows((f"Fig. 10 {name}: Type V improves (near diagonal)", _yes_no(improves),
                           f"{_yes_no(d1 > d0)} ({d0:.2f} -> {d1:.2f})"))  # fmt: skip
    a, b = N.FIG10_BALANCED_LIKE
    if a in balance and b in balance:
        ia, ib = _imbalance(balance[a]), _imbalance(balance[b])
        rows += _rows((f"Fig. 10 {a} balanced like {b}", "yes",
                       f"abs(below - above) {ia:.3f} vs {ib:.3f}"))  # fmt: skip
    return rows


def timing_comparison(rows) -> list[dict]:
    """Table 2: the mean time per frame of each unconstrained Method B and C window.

    Paper: FP-DTW Table 2.
    Notebook: 09_table2_timing.ipynb
    """
    return [
        side_by_side(f"{r['algorithm']}: mean time per frame", f"{r['paper_mean_us']:.0f} us",
                     f"{r['mean_us']:.0f} us (median {r['median_us']:.0f}; "
                     f"{r['paper_mean_us'] / r['mean_us']:.0f}x faster)")
        for r in rows
        if r["method"] in ("B", "C") and not r["type_v"] and r.get("paper_mean_us") is not None
        and "(" not in r["algorithm"]
    ]  # fmt: skip


def walk_pair_comparison(rows) -> list[dict]:
    """Fig. 8 (:func:`.walk_pair.pair_scores`): the deviation from DTW and its side of 18
    frames, ours (another pair) beside the paper's.

    Paper: FP-DTW Section 5 (Fig. 8).
    Notebook: 10_fig8_walk_pair.ipynb
    """
    out = []
    for r in rows:
        paper = N.FIG8_DEVIATIONS.get(r["algorithm"].replace(" (literal window)", ""))
        if paper is None:
            continue
        p_ok, o_ok = N.passes_deviation(paper), N.passes_deviation(r["deviation"])
        side = "same side as the paper's" if p_ok == o_ok else "not the paper's side"
        out += _rows((r["algorithm"], f"{paper:.0f} ({_side(p_ok)} 18)",
                      f"{r['deviation']:.1f} ({_side(o_ok)} 18: {side})"))  # fmt: skip
    return out


def typev_comparison(legal: bool, accepted: bool, free_legal: bool, n_states: int) -> list[dict]:
    """Fig. 9: the state table's size; whether the Ma (+ Type V) maps are legal Type V paths.

    Paper: FP-DTW Section 6, Fig. 9.
    Notebook: 11_fig9_typev.ipynb
    """
    return _rows(
        ("Type V carried between target frames by states", "yes, a state table (Fig. 9 iii-iv)",
         f"{n_states} states"),
        ("Ma + Type V map is a legal Type V path", "yes (by construction)",
         f"state table {_yes_no(legal)}, dtw-python {_yes_no(accepted)}"),
        ("unconstrained Ma is a legal Type V path", "not stated", _yes_no(free_legal)),
    )  # fmt: skip


def opw_fig4_comparison(facts: dict) -> list[dict]:
    """Poster Fig. 4 (:func:`fpdtw.paper.opw_eval.fig4_facts`): OPW against the baseline.

    Paper: OPW poster Section 5, Fig. 4.
    Notebook: 13_opw_fig4.ipynb
    """
    (plo, phi), (lo, hi) = N.OPW_MEAN_DEVIATION_MS, facts["opw_mean_ms_range"]
    dlo, dhi = facts["dtw_mean_ms_range"]
    base = facts.get("baseline", "DTW")
    return _rows(
        ("OPW mean deviation over the motions", f"{plo:.0f}-{phi:.0f} ms", f"{lo:.0f}-{hi:.0f} ms"),
        (f"OPW max deviation below {N.PERCEPTUAL_THRESHOLD_MS:.0f} ms",
         f"{N.OPW_MAX_DEVIATION_MS:.0f} ms", f"{facts['opw_max_ms']:.0f} ms"),
        (f"{base} deviates less than OPW on every motion", _yes_no(N.OPW_DTW_BETTER),
         f"{_yes_no(facts['dtw_better_everywhere'])} ({base} {dlo:.0f}-{dhi:.0f} ms)"),
        (f"OPW smoother than {base} on every motion", _yes_no(N.OPW_SMOOTHER),
         _yes_no(facts["opw_smoother_everywhere"])),
    )  # fmt: skip


def live_comparison(deviations: dict) -> list[dict]:
    """A live replay: each aligner's deviation from DTW (eq. 3) on one pair, against 18
    frames, beside whether the paper recommends it.

    Paper: FP-DTW Section 7, eq. 3.
    Notebook: 20_align_a_live_performance.ipynb
    """
    return [
        side_by_side(f"{name}: deviation from DTW",
                     "passes both benchmarks (all pairs)" if name in N.PASS_BOTH
                     else "not in the paper",
                     f"{dev:.1f} frames ({_side(N.passes_deviation(dev))} 18, this pair)")
        for name, dev in deviations.items()
    ]  # fmt: skip
