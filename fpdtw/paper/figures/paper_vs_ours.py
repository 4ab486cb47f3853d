"""Paper | ours: the paper's values next to ours, printed after the notebooks' figures.

The notebooks read as companions to the papers: after a figure, a cell prints, for the
quantities the figure shows, the paper's value (always read from :mod:`fpdtw.paper.numbers`,
never retyped) and ours, side by side. These tables carry no verdict of their own: whether
a claim of the papers holds is decided by the claims (:mod:`fpdtw.paper.claims`, one set of
rules), which the notebooks print beside these tables (:func:`fpdtw.paper.claims.format_parts`)
for the claims a section is about. Where ``ours`` quotes a verdict (a median passing a
benchmark, a Table 1 cell), it is the claims' check of it (:mod:`fpdtw.paper.claims.rules`).

Every function returns rows with the keys :data:`COLUMNS`. The printed values are rounded
so that a SMOKE run prints the same text every time.
"""

from __future__ import annotations

import numpy as np

from fpdtw.paper import numbers as N
from fpdtw.paper.figures.forecast import best_level
from fpdtw.registry import resolve

#: Keys of every row.
COLUMNS = ("quantity", "paper", "ours")


def side_by_side(quantity: str, paper, ours) -> dict:
    """One row: ``quantity``, ``paper``, ``ours``, as text.

    Parameters
    ----------
    quantity : str
    paper, ours : object
        Shown with ``str``.

    Returns
    -------
    row : dict
        Keys :data:`COLUMNS`.

    Paper: the values of :mod:`fpdtw.paper.numbers`.
    """
    return dict(quantity=str(quantity), paper=str(paper), ours=str(ours))


def format_side_by_side(rows, title: str | None = None) -> str:
    """The rows as a fixed-width text table with the header ``quantity | paper | ours``.

    Parameters
    ----------
    rows : list of dict
        Rows with the keys :data:`COLUMNS`.
    title : str, optional
        A line printed above the table.

    Returns
    -------
    text : str
        Deterministic for deterministic rows (a notebook can check it with nbval).

    Paper: the values of :mod:`fpdtw.paper.numbers`.
    Notebook: 07_table1_60hz.ipynb
    """
    header = dict(quantity="quantity", paper="paper", ours="ours")
    table = [header] + [{c: str(r[c]) for c in COLUMNS} for r in rows]
    widths = {c: max(len(r[c]) for r in table) for c in COLUMNS}

    def line(r):
        return " | ".join(r[c].ljust(widths[c]) for c in COLUMNS).rstrip()

    out = [title] if title else []
    out += [line(header), "-+-".join("-" * widths[c] for c in COLUMNS)]
    out += [line(r) for r in table[1:]]
    return "\n".join(out)


def _yes_no(x: bool) -> str:
    return "yes" if x else "no"


# -- 01: the data ---------------------------------------------------------------------------


def data_comparison(summary_rows, datasets=("authors_fbx", "hdm05")) -> list[dict]:
    """The data of Section 4 next to the data available here.

    Parameters
    ----------
    summary_rows : list of dict
        :func:`fpdtw.paper.catalog.summary_rows` (keys ``dataset``, ``movement``,
        ``listed``, ``available``).
    datasets : tuple of str
        The datasets of the FP-DTW evaluation.

    Returns
    -------
    rows : list of dict
        Motions per dataset and in total, and movements (the claim on them: claim 9,
        notebook 05).

    Paper: FP-DTW Section 4 ("333 recorded motions of 44 different movements ... Fifty
    seven from Reference 8 and 267 from ... HDM05").
    Notebook: 01_data_and_motions.ipynb
    """
    rows = [r for r in summary_rows if r["dataset"] in datasets]
    out = []
    for ds in datasets:
        have = sum(int(r["available"]) for r in rows if r["dataset"] == ds)
        listed = sum(int(r["listed"]) for r in rows if r["dataset"] == ds)
        paper = N.DATA_SOURCES.get(ds)
        out.append(
            side_by_side(
                f"motions from {ds}",
                paper,
                f"{have} (of {listed} listed)",
            )
        )
    motions = sum(int(r["available"]) for r in rows)
    movements = sum(int(r["available"]) > 0 for r in rows)
    out.append(side_by_side("motions in all", N.DATA["motions"], motions))
    out.append(side_by_side("movements", N.DATA["movements"], movements))
    return out


# -- 02: Fig. 1 ----------------------------------------------------------------------------


def oedtw_comparison(facts: dict, label: str = "OE-DTW") -> list[dict]:
    """Fig. 1: do OE-DTW's end points move backwards between consecutive target frames?

    Parameters
    ----------
    facts : dict
        :func:`fpdtw.paper.figures.oedtw.oedtw_facts` of one run (keys ``jumps``,
        ``n_frames``, ``first_jump``).
    label : str
        Which OE-DTW (e.g. ``"OE-DTW, normalised symmetric2"``).

    Returns
    -------
    rows : list of dict
        One row: the backward jumps of the run and the first one (the claim on all pairs:
        claim 7, notebook 12).

    Paper: FP-DTW Section 2, Fig. 1 (frames 15 -> 16).
    Notebook: 02_fig1_oedtw.ipynb
    """
    a, b = N.FIG1_FRAMES
    j = facts.get("first_jump")
    if j:
        ours = (
            f"{facts['jumps']} in {facts['n_frames'] - 1} steps; first at frames "
            f"{j['q']} -> {j['q'] + 1}: e {j['e_q']} -> {j['e_q1']}"
        )
    else:
        ours = f"none in {facts['n_frames'] - 1} steps"
    return [
        side_by_side(
            f"{label}: end point moves backwards",
            f"yes, e.g. frames {a} -> {b}",
            ours,
        )
    ]


# -- 03: Figs. 2 and 4 -----------------------------------------------------------------------


def windows_comparison(step_a, steps_b, step_c) -> list[dict]:
    """Figs. 2 and 4: what Algorithms 1-3 prescribe, next to the real steps drawn.

    One row per prescription: Method A searches ``w + 1`` frames from ``M_n`` (``w`` = 2, or
    fewer at the end of the input) and takes the argmin of eq. 1; Method B sets
    ``D[0, 0]`` to 10,000, its path leaves (0, 0) through (1, 0) in one drawn step and
    through (0, 1) in the other, and it maps ``T_{n+1}`` to the lowest input frame its
    path visits in column ``T_{n+1}`` (``M_{n+1} = M_n + P_1``); Method C maps it to the
    argmin of its reverse-accumulated ``D`` over the column of ``T_{n+1}``.

    Parameters
    ----------
    step_a : fpdtw.plain.Step
        A plain Method A window step (:func:`fpdtw.plain.method_a_step`).
    steps_b : sequence of fpdtw.plain.Step or None
        The plain Method B steps of Fig. 4 (None where no such step was found).
    step_c : fpdtw.plain.Step
        A plain Method C window step.

    Returns
    -------
    rows : list of dict

    Paper: FP-DTW Algorithms 1-3, Figs. 2 and 4.
    Notebook: 03_fig2_fig4_windows.ipynb
    """
    rows = []
    w = N.METHOD_A_WINDOW
    n_a = int(step_a.C.shape[0])
    rows.append(
        side_by_side(
            "Ma: frames searched (Fig. 2)",
            f"w + 1 = {w + 1}: I_Mn .. I_Mn+{w}",
            f"{n_a}: I_{step_a.M_n} .. I_{step_a.M_n + n_a - 1}",
        )
    )
    best_a = int(np.argmin(step_a.C[:, 0]))
    rows.append(
        side_by_side(
            "Ma: M_n+1 = M_n + argmin of eq. 1",
            "Algorithm 1",
            f"offset {step_a.M - step_a.M_n}, argmin {best_a}",
        )
    )
    found = [s for s in steps_b if s is not None]
    if found:
        corner = float(found[0].D[0, 0])
        rows.append(
            side_by_side(
                "Mb: D[0, 0] before back-tracking",
                f"{N.METHOD_B_CORNER:,.0f}",
                f"{corner:,.0f}",
            )
        )
    vias = sorted({tuple(int(v) for v in s.path[1]) for s in found})
    rows.append(
        side_by_side(
            "Mb: path leaves (0, 0) via",
            "(1, 0) or (0, 1) (Fig. 4)",
            ", ".join(f"({r}, {c})" for r, c in vias) or "no window step",
        )
    )
    hits = 0
    for s in found:
        lowest = int(min(r for r, c in s.path if c == 1))
        hits += s.M - s.M_n == lowest
    rows.append(
        side_by_side(
            "Mb: X = lowest input row of the path in column T_n+1",
            "M_n+1 = M_n + P_1 (Fig. 4)",
            f"{hits} of {len(found)} steps drawn",
        )
    )
    score = step_c.score if step_c.score is not None else step_c.D[:, 0]
    best_c = int(np.argmin(score))
    rows.append(
        side_by_side(
            "Mc: M_n+1 = M_n + argmin of D over column T_n+1",
            "Algorithm 3",
            f"offset {step_c.M - step_c.M_n}, argmin {best_c}",
        )
    )
    return rows


# -- 04: Fig. 3 ----------------------------------------------------------------------------


def forecast_comparison(curves: dict, levels, ahead=(1, 10), short=(1, 10)) -> list[dict]:
    """Fig. 3: the paper's two-frame forecast (s = 2) and dead reckoning against the other
    smoothing functions, next to ours.

    Per horizon ``i`` of ``ahead``: the level with dead reckoning's lowest error. Per
    horizon of ``short``: dead reckoning's error with s = 2 and every other forecaster's
    error at its best level.

    Parameters
    ----------
    curves : dict of str to ndarray, shape (len(levels), H)
        :func:`fpdtw.paper.figures.forecast.forecast_curves`.
    levels : sequence of int
    ahead, short : sequence of int
        Horizons (frames ahead).

    Returns
    -------
    rows : list of dict

    Paper: FP-DTW Section 3.2 and Fig. 3 (s = 2 after a pilot study; dead reckoning "as
    well as other smoothing functions" for short-term forecasting, their ref. 7).
    Notebook: 04_fig3_forecast.ipynb
    """
    levels = list(levels)
    s = N.FORECAST_LEVEL
    dr = np.asarray(curves["dead_reckoning"], dtype=float)
    rows = []
    for i in ahead:
        b = best_level(dr, levels, i)
        rows.append(
            side_by_side(
                f"best level s, dead reckoning, {i} frame{'s' if i > 1 else ''} ahead",
                f"s = {s}",
                f"s = {b}",
            )
        )
    others = [m for m in curves if m != "dead_reckoning"]
    if others and s in levels:
        li = levels.index(s)
        for i in short:
            mine = float(dr[li, i - 1])
            theirs = {m: float(np.min(np.asarray(curves[m])[:, i - 1])) for m in others}
            rows.append(
                side_by_side(
                    f"dead reckoning (s = {s}) vs the others' best, {i} ahead",
                    "as good (short term)",
                    f"{mine:.3f} vs " + ", ".join(f"{m} {v:.3f}" for m, v in theirs.items()),
                )
            )
    return rows


# -- 06: Figs. 5 and 6 ---------------------------------------------------------------------


def paper_passes(name: str, metric: str):
    """Whether the paper says an FP-DTW algorithm's median passes a benchmark.

    Known for every unconstrained algorithm (Section 5: only Mc w40 passes either, and it
    passes both) and for the three that pass both (Section 7); for the other "+ Type V"
    algorithms the paper says only that they do not pass both.

    Parameters
    ----------
    name : str
        E.g. ``"Mb w20"``, ``"Ma + Type V"``.
    metric : {"similarity", "deviation"}

    Returns
    -------
    passes : bool or None
        None where the paper does not say.

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
    """Figs. 5 / 6: per FP-DTW algorithm, does its median pass the benchmark, ours vs paper?

    Our side is the claims' check of the pass (:meth:`fpdtw.paper.claims.evidence.Evidence.passes`,
    decided by :mod:`fpdtw.paper.claims.rules`, as in the claims table): "holds" when the
    median's 95 % interval clears the benchmark (for similarity: the interval of its
    difference from UTW's median), "contradicted" when it fails it, "inconclusive" when it
    straddles it. The paper's side is :func:`paper_passes`. The first row shows the
    benchmark itself. Claims 1, 2, 2b, 5, 5b and 6 decide what the paper says of them.

    Parameters
    ----------
    summary_rows : list of dict
        :func:`fpdtw.paper.figures.scores.score_summary` for ``metric``.
    metric : {"similarity", "deviation"}

    Returns
    -------
    rows : list of dict

    Paper: FP-DTW Figs. 5 and 6, Sections 5-7.
    Notebook: 06_fig5_fig6_scores.ipynb
    """
    rows = []
    if metric == "similarity":
        bench = summary_rows[0]["benchmark"]
        rows.append(
            side_by_side(
                "UTW median similarity (the benchmark)",
                f"{N.TABLE1[N.SAMPLE_RATE_HZ]['UTW']:.3f}",
                f"{bench:.3f}",
            )
        )
    else:
        rows.append(
            side_by_side(
                "deviation benchmark (150 ms)",
                f"{N.DEVIATION_BENCHMARK_FRAMES} frames",
                f"{N.deviation_benchmark_frames(N.SAMPLE_RATE_HZ):g} frames",
            )
        )
    word = "above UTW" if metric == "similarity" else "below 18"
    fmt = ".3f" if metric == "similarity" else ".1f"
    for r in summary_rows:
        name = r["algorithm"]
        if name not in N.FPDTW_NAMES and name not in N.FPDTW_TYPEV_NAMES:
            continue
        paper = paper_passes(name, metric)
        v = r["verdict"]
        iv = f"{r['median']:{fmt}} [{r['ci_low']:{fmt}}, {r['ci_high']:{fmt}}]"
        rows.append(
            side_by_side(
                f"{name}: median {word}?",
                "not stated (not both)" if paper is None else _yes_no(paper),
                f"{v} ({iv})",
            )
        )
    return rows


# -- 07: Table 1 ---------------------------------------------------------------------------


def table1_comparison(rows, source: str = "ours") -> list[dict]:
    """Table 1 cell by cell: the paper's median similarity of Method C next to ours.

    Each window's median, on which side of UTW's median it lies and, where the rows carry
    it, the claims' check that it lies above (:func:`fpdtw.paper.figures.scores.table1_rows`:
    the interval of the difference from UTW's median); the best window and the check that
    the paper's best window beats every other one (claim 3 decides the paper's claim).

    Parameters
    ----------
    rows : list of dict
        :func:`fpdtw.paper.figures.scores.table1_rows` (the paper's rows and ours).
    source : str
        Which of our rows: ``"ours"`` or ``"ours (literal window)"``.

    Returns
    -------
    rows : list of dict

    Paper: FP-DTW Table 1.
    Notebook: 07_table1_60hz.ipynb
    """
    out = []
    rates = sorted({r["rate_hz"] for r in rows}, reverse=True)
    for rate in rates:
        paper = N.TABLE1.get(rate)
        ours = next((r for r in rows if r["rate_hz"] == rate and r["source"] == source), None)
        if paper is None or ours is None:
            continue
        out.append(side_by_side(f"{rate} Hz UTW", f"{paper['UTW']:.3f}", f"{ours['UTW']:.3f}"))
        for w in N.WINDOWS:
            p_above = paper[w] > paper["UTW"]
            o_above = ours[f"w{w}"] > ours["UTW"]
            v = ours.get(f"verdict_w{w}")
            side = "above" if o_above else "below"
            out.append(
                side_by_side(
                    f"{rate} Hz Mc w{w}",
                    f"{paper[w]:.3f} ({'above' if p_above else 'below'} UTW)",
                    f"{ours[f'w{w}']:.3f} ({side} UTW{'' if v is None else ': ' + v})",
                )
            )
        v = ours.get("best_verdict")
        out.append(
            side_by_side(
                f"{rate} Hz best window",
                f"w{N.BEST_WINDOW[rate]}",
                f"w{ours['best_w']}"
                + ("" if v is None else f" (w{N.BEST_WINDOW[rate]} best: {v})"),
            )
        )
    return out


# -- 08: Figs. 7 and 10 ----------------------------------------------------------------------


def _imbalance(b: dict) -> float:
    return abs(b["below"] - b["above"])


def _method_windows(name: str) -> list[str]:
    base, _, _ = name.partition(" w")
    return [f"{base} w{w}" for w in N.WINDOWS]


def heatmap_comparison(balance: dict) -> list[dict]:
    """Figs. 7 and 10 in numbers: where each named algorithm's path mass lies.

    ``balance`` gives, per algorithm, the share of path frames near the diagonal, below it
    and above it (:func:`fpdtw.paper.figures.heatmaps.path_balance`). Ours, in words:

    * "sticks": more mass below the diagonal band than above it; "skips": more above;
      "balanced": the smallest ``|below - above|`` of its method's four windows;
    * Fig. 10: whether the share near the diagonal is higher with Type V;
    * "Mc w80 + Type V balanced like Mc w40": both ``|below - above|``.

    Parameters
    ----------
    balance : dict of str to dict
        Algorithm -> ``{"diagonal", "below", "above"}``.

    Returns
    -------
    rows : list of dict
        Algorithms missing from ``balance`` are left out.

    Paper: FP-DTW Section 5 (Fig. 7), Section 6 (Fig. 10).
    Notebook: 08_fig7_fig10_heatmaps.ipynb
    """
    rows = []
    for name, claimed in N.FIG7_TENDENCY.items():
        if name not in balance:
            continue
        b = balance[name]
        if claimed == "balanced":
            peers = [n for n in _method_windows(name) if n in balance]
            ours = min(peers, key=lambda n: _imbalance(balance[n])) == name
            verdict = "balanced" if ours else "not the most balanced"
        else:
            verdict = "sticks" if b["below"] > b["above"] else "skips"
        rows.append(
            side_by_side(
                f"Fig. 7 {name}",
                claimed,
                f"{verdict} (below {b['below']:.2f}, above {b['above']:.2f})",
            )
        )
    for name, improves in N.FIG10_TYPEV_IMPROVES.items():
        tv = name + N.TYPE_V
        if name not in balance or tv not in balance:
            continue
        d0, d1 = balance[name]["diagonal"], balance[tv]["diagonal"]
        rows.append(
            side_by_side(
                f"Fig. 10 {name}: Type V improves (near diagonal)",
                _yes_no(improves),
                f"{_yes_no(d1 > d0)} ({d0:.2f} -> {d1:.2f})",
            )
        )
    a, b = N.FIG10_BALANCED_LIKE
    if a in balance and b in balance:
        ia, ib = _imbalance(balance[a]), _imbalance(balance[b])
        rows.append(
            side_by_side(
                f"Fig. 10 {a} balanced like {b}",
                "yes",
                f"abs(below - above) {ia:.3f} vs {ib:.3f}",
            )
        )
    return rows


# -- 09: Table 2 ---------------------------------------------------------------------------


def timing_comparison(rows) -> list[dict]:
    """Table 2 cell by cell: the paper's mean time per frame next to ours (measurements).

    Values only: our times come from another implementation on another machine; the
    claims about them (growth with w, w80 over budget) are claims 4 and 4b.

    Parameters
    ----------
    rows : list of dict
        :func:`fpdtw.paper.figures.timing.time_per_frame_rows`.

    Returns
    -------
    rows : list of dict
        One per Method B and C window the bench timed.

    Paper: FP-DTW Table 2.
    Notebook: 09_table2_timing.ipynb
    """
    out = []
    for r in rows:
        if r["method"] not in ("B", "C") or r["type_v"] or r.get("paper_mean_us") is None:
            continue
        if "(" in r["algorithm"]:
            continue
        out.append(
            side_by_side(
                f"{r['algorithm']}: mean time per frame",
                f"{r['paper_mean_us']:.0f} us",
                f"{r['mean_us']:.0f} us (median {r['median_us']:.0f}; "
                f"{r['paper_mean_us'] / r['mean_us']:.0f}x faster)",
            )
        )
    return out


# -- 10: Fig. 8 ----------------------------------------------------------------------------


def walk_pair_comparison(rows) -> list[dict]:
    """Fig. 8: deviation from DTW (eq. 3) on the walk pair, per algorithm, ours vs paper's.

    Our walk pair is not the paper's (the paper's is HDM05 sample 3239, WalkLeftCircle, a
    class we do not have), so no row can confirm or contradict the paper's number (claim 8
    decides it: not comparable); ``ours`` says whether our number lies on the same side of
    the 18-frame benchmark as the paper's printed one (the algorithm's behaviour on a walk
    pair). Method C's literal-window rows are set beside the
    paper's number of the same window.

    Parameters
    ----------
    rows : list of dict
        :func:`fpdtw.paper.figures.walk_pair.pair_scores` (keys ``algorithm``,
        ``deviation``).

    Returns
    -------
    rows : list of dict

    Paper: FP-DTW Section 5 (Fig. 8: 8, 177, 62 and 6 frames).
    Notebook: 10_fig8_walk_pair.ipynb
    """
    out = []
    for r in rows:
        base = r["algorithm"].replace(" (literal window)", "")
        paper = N.FIG8_DEVIATIONS.get(base)
        if paper is None:
            continue
        p_ok, o_ok = N.passes_deviation(paper), N.passes_deviation(r["deviation"])
        side = "same side as the paper's" if p_ok == o_ok else "not the paper's side"
        out.append(
            side_by_side(
                r["algorithm"],
                f"{paper:.0f} ({'below' if p_ok else 'above'} 18)",
                f"{r['deviation']:.1f} ({'below' if o_ok else 'above'} 18: {side})",
            )
        )
    return out


# -- 11: Fig. 9 ----------------------------------------------------------------------------


def typev_comparison(legal: bool, accepted: bool, free_legal: bool, n_states: int) -> list[dict]:
    """Fig. 9: the forward Type V constraint as a state table, and the paths it yields.

    Ours: the states of the table (more than one carries the constraint from one target
    frame to the next), whether the constrained path is a legal Type V path by our state
    table and by dtw-python's backward Type V pattern, and whether unconstrained Method A's
    is.

    Parameters
    ----------
    legal, accepted : bool
        The Ma + Type V map is legal by the state table; dtw-python accepts it.
    free_legal : bool
        Unconstrained Ma's map is legal Type V.
    n_states : int
        States of the table.

    Returns
    -------
    rows : list of dict

    Paper: FP-DTW Section 6, Fig. 9.
    Notebook: 11_fig9_typev.ipynb
    """
    return [
        side_by_side(
            "Type V carried between target frames by states",
            "yes, a state table (Fig. 9 iii-iv)",
            f"{n_states} states",
        ),
        side_by_side(
            "Ma + Type V map is a legal Type V path",
            "yes (by construction)",
            f"state table {_yes_no(legal)}, dtw-python {_yes_no(accepted)}",
        ),
        side_by_side("unconstrained Ma is a legal Type V path", "not stated", _yes_no(free_legal)),
    ]


# -- 13: OPW poster Fig. 4 -------------------------------------------------------------------


def opw_fig4_comparison(facts: dict) -> list[dict]:
    """Poster Fig. 4: OPW's deviation from the example warp, DTW, smoothness.

    The range of OPW's mean deviations, its maximum, whether DTW deviates less than OPW on
    every motion and whether OPW's largest slope change is below DTW's on every motion
    (claim P1 decides the poster's claim). Under the plugin reading the poster's DTW is the
    plugin's baseline (``facts["baseline"]``).

    Parameters
    ----------
    facts : dict
        :func:`fpdtw.paper.opw_eval.fig4_facts`.

    Returns
    -------
    rows : list of dict

    Paper: OPW poster Section 5, Fig. 4.
    Notebook: 13_opw_fig4.ipynb
    """
    plo, phi = N.OPW_MEAN_DEVIATION_MS
    lo, hi = facts["opw_mean_ms_range"]
    dlo, dhi = facts["dtw_mean_ms_range"]
    base = facts.get("baseline", "DTW")
    thr = N.PERCEPTUAL_THRESHOLD_MS
    return [
        side_by_side(
            "OPW mean deviation over the motions",
            f"{plo:.0f}-{phi:.0f} ms",
            f"{lo:.0f}-{hi:.0f} ms",
        ),
        side_by_side(
            f"OPW max deviation below {thr:.0f} ms",
            f"{N.OPW_MAX_DEVIATION_MS:.0f} ms",
            f"{facts['opw_max_ms']:.0f} ms",
        ),
        side_by_side(
            f"{base} deviates less than OPW on every motion",
            _yes_no(N.OPW_DTW_BETTER),
            f"{_yes_no(facts['dtw_better_everywhere'])} ({base} {dlo:.0f}-{dhi:.0f} ms)",
        ),
        side_by_side(
            f"OPW smoother than {base} on every motion",
            _yes_no(N.OPW_SMOOTHER),
            _yes_no(facts["opw_smoother_everywhere"]),
        ),
    ]


# -- 20: a live performance ------------------------------------------------------------------


def live_timing_comparison(step_seconds: dict, fps: float) -> list[dict]:
    """A live replay's median time per frame next to the paper's Table 2 mean (values only).

    Parameters
    ----------
    step_seconds : dict of str to ndarray of float
        Aligner name -> seconds each frame's step took (measurements: they vary).
    fps : float
        The live take's frame rate (the frame budget is ``1 / fps``).

    Returns
    -------
    rows : list of dict
        Values only: another implementation on another machine (claims 4, 4b decide the
        growth with w and the budget).

    Paper: FP-DTW Table 2 and its text (the 120 Hz budget of 8333 us).
    Notebook: 20_align_a_live_performance.ipynb
    """
    out = []
    for name, steps in step_seconds.items():
        a = resolve(name)
        paper = None if (a.typev or a.options) else N.TABLE2_US.get((a.family, a.w))
        med = float(np.median(np.asarray(steps, dtype=float))) * 1e6
        out.append(
            side_by_side(
                f"{name}: time per frame",
                "not in Table 2" if paper is None else f"{paper:.0f} us (mean)",
                f"{med:.0f} us (median; budget {1e6 / fps:.0f} us)",
            )
        )
    return out


def live_comparison(deviations: dict) -> list[dict]:
    """A live replay: each aligner's deviation from DTW on this one pair, against 18 frames.

    Values only: one pair says nothing of a median over all pairs. The paper's column says
    whether the paper recommends the configuration (it passes both benchmarks, Section 7;
    claim 2 decides that on our pairs).

    Parameters
    ----------
    deviations : dict of str to float
        Aligner name -> deviation from DTW (eq. 3), frames.

    Returns
    -------
    rows : list of dict

    Paper: FP-DTW Section 7, eq. 3.
    Notebook: 20_align_a_live_performance.ipynb
    """
    out = []
    for name, dev in deviations.items():
        ok = N.passes_deviation(dev)
        recommended = name in N.PASS_BOTH
        out.append(
            side_by_side(
                f"{name}: deviation from DTW",
                "passes both benchmarks (all pairs)" if recommended else "not in the paper",
                f"{dev:.1f} frames ({'below' if ok else 'above'} 18, this pair)",
            )
        )
    return out


__all__ = [
    "COLUMNS",
    "benchmark_comparison",
    "data_comparison",
    "forecast_comparison",
    "format_side_by_side",
    "heatmap_comparison",
    "live_comparison",
    "live_timing_comparison",
    "oedtw_comparison",
    "opw_fig4_comparison",
    "paper_passes",
    "side_by_side",
    "table1_comparison",
    "timing_comparison",
    "typev_comparison",
    "walk_pair_comparison",
]
