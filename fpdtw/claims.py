"""The FP-DTW paper's claims, checked against our results, one row per claim.

:func:`build_claims` evaluates a list of claim functions (:data:`CLAIMS`; add more with
:func:`register_claim`, e.g. the OPW poster's claims) on a :class:`ClaimContext` built
from the experiment results, and returns rows a reviewer can check: the claim in words,
the paper's number, ours, whether it holds here ("yes", "no", "partly"; "n/a" when it
could not be computed) and the evidence (figure, table or JSON that shows it).
:func:`save_claims` writes them as a table (``claims.csv|md``) and as
``results/<mode>/claims.json``.

The rules deciding "holds" are fixed here and never tuned to make a claim come true:

* A benchmark is passed by an algorithm whose MEDIAN similarity is above UTW's median
  similarity, or whose MEDIAN deviation from DTW is below 18 frames (paper Section 5).
* Set claims ("only Mc w40 passes ..."): "yes" when our set equals the paper's, "partly"
  when they share at least one algorithm, "no" otherwise.
* "Improved by Type V": median similarity higher AND median deviation lower with the
  constraint than without.
* "Among the worst": in the bottom third (rank 7 to 9 of the 9 unconstrained FP-DTW
  algorithms) of a test.
* "Grows steeply with w": the MEDIAN per-frame time increases at every window step and the
  ratio w80 / w10 is at least 8 (the window grows 8-fold; the paper's ratios of means are
  19.8 and 12.9). Medians, because a mean is dragged by rare slow frames (a kernel compiled
  inside the timed loop, a busy machine); the means are shown too.

Rows carry ``stable``: False for the claims computed from timings (measurements that change
between runs); all other rows are deterministic functions of the maps.
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass, field

import numpy as np

from .algorithms import FPDTW_NAMES, FPDTW_TYPEV_NAMES, TYPE_V_SUFFIX, WINDOWS

#: Deviation benchmark: 150 ms = 18 frames at 120 Hz (paper Section 4).
DEVIATION_BENCHMARK = 18.0

#: The paper's data (Section 4).
PAPER_DATA = {"motions": 333, "movements": 44, "pairs": 3248}

#: The paper's Fig. 8 deviations from DTW on its walk pair (Section 5), in frames.
PAPER_FIG8_DEVIATIONS = {"Mb w80": 8.0, "Mc w20": 177.0, "Mc w40": 62.0, "Mc w80": 6.0}

#: Name of the Fig. 8 notebook's JSON under ``results/<mode>/figs/``.
FIG8_JSON = "10_fig8_walk_pair.json"

#: Columns of the claims table: ``ours`` and ``holds`` with Method C's default (square)
#: window, ``ours_literal`` and ``holds_literal`` with its literal ``(w_i + 1) x w``
#: window (notebook 15).
COLUMNS = ("id", "claim", "paper", "ours", "holds", "ours_literal", "holds_literal", "evidence",
           "stable")  # fmt: skip
#: Method C's readings the claims table is evaluated under: column suffix -> reading.
READINGS = {"": "square", "_literal": "literal"}


@dataclass
class ClaimContext:
    """Everything the claim functions read, computed once from the results.

    Attributes
    ----------
    mode : str
        ``"full"`` or ``"smoke"``.
    similarity, deviation : dict of str to float
        Median similarity (eq. 2) and median deviation from DTW (eq. 3) per algorithm.
    utw_median : float
        Median similarity of UTW (the benchmark) at 120 Hz.
    table1 : list of dict or None
        :func:`fpdtw.plots.scores.table1_rows` (None without the 60 Hz runs).
    timing : list of dict or None
        :func:`fpdtw.plots.timing.time_per_frame_rows` of ``make bench``'s report
        (measurements; None when ``results/bench.json`` does not exist).
    exhausted : dict of str to float
        Fraction of target frames processed with the input exhausted, per algorithm.
    oedtw_backward : dict or None
        ``pairs``, ``pairs_backward`` (pairs whose OE-DTW map jumps backwards at least
        once), ``jumps`` (all backward jumps).
    fig8 : dict or None
        The Fig. 8 notebook's JSON, if it exists.
    opw_fig4, opw_fig56 : dict or None
        The OPW notebooks' JSON (13_opw_fig4, 14_opw_fig5_fig6), if they exist.
    counts : dict or None
        Our data: ``motions``, ``movements``, ``pairs`` (and per dataset).
    """

    mode: str = "full"
    similarity: dict = field(default_factory=dict)
    deviation: dict = field(default_factory=dict)
    utw_median: float = float("nan")
    table1: list | None = None
    timing: list | None = None
    exhausted: dict = field(default_factory=dict)
    oedtw_backward: dict | None = None
    fig8: dict | None = None
    opw_fig4: dict | None = None
    opw_fig56: dict | None = None
    counts: dict | None = None

    def passes_similarity(self, name) -> bool:
        return name in self.similarity and self.similarity[name] > self.utw_median

    def passes_deviation(self, name) -> bool:
        return name in self.deviation and self.deviation[name] < DEVIATION_BENCHMARK

    @classmethod
    def from_results(cls, results, mode="full", fig8_path=None, reading="square"):
        """Compute the context from :func:`fpdtw.experiments.load_results` output.

        ``reading`` chooses Method C's reading of Algorithm 3: with ``"literal"`` every Mc
        name (``"Mc w40"``, ``"Mc w80 + Type V"``, ``"Mc w20@60Hz"``) stands for the
        results of that reading (``"Mc w40 (literal window)"``, ...), so the same claims
        are checked under it; Mc names without such results are left out.

        Notebook: 12_claims.ipynb
        """
        from .paths import results_dir
        from .plots.scores import scores, table1_rows, utw_median
        from .plots.timing import TIMED_NAMES, exhausted_fraction, load_bench, time_per_frame_rows

        alias = reading_alias(reading)
        have = set(results.algorithms)
        variants = set(alias.values())
        src = {}  # the name a claim reads -> the results it stands for
        for n in results.algorithms:
            if n in alias:
                if alias[n] in have:
                    src[n] = alias[n]
            elif n not in variants:
                src[n] = n
        sim = {n: float(np.median(scores(results, s, "similarity"))) for n, s in src.items()}
        dev = {n: float(np.median(scores(results, s, "deviation"))) for n, s in src.items()}
        try:
            table1 = table1_rows(results, reading=reading)
        except (KeyError, ValueError, FileNotFoundError):
            table1 = None
        bench = load_bench()
        timing = None
        if bench is not None:
            paper_name = {alias.get(n, n): n for n in TIMED_NAMES if "(" not in n}
            timing = time_per_frame_rows(bench, names=list(paper_name)) or None
            for r in timing or []:  # rows stand for the paper's names
                r["algorithm"] = paper_name[r["algorithm"]]
        exhausted = {
            n: exhausted_fraction(results, s)["fraction"]
            for n, s in src.items()
            if n in FPDTW_NAMES or n in FPDTW_TYPEV_NAMES
        }
        oe = oedtw_backward_jumps(results) if "OE-DTW" in have else None
        fig8_path = results_dir() / mode / "figs" / FIG8_JSON if fig8_path is None else fig8_path
        fig8 = _alias_fig8(_read_json(fig8_path), alias)
        opw_fig4 = _read_json(results_dir() / mode / "figs" / OPW_FIG4_JSON)
        opw_fig56 = _read_json(results_dir() / mode / "figs" / OPW_FIG56_JSON)
        return cls(
            mode=mode,
            similarity=sim,
            deviation=dev,
            utw_median=utw_median(results),
            table1=table1,
            timing=timing,
            exhausted=exhausted,
            oedtw_backward=oe,
            fig8=fig8,
            opw_fig4=opw_fig4,
            opw_fig56=opw_fig56,
            counts=getattr(results, "counts", None) or data_counts(results.pairs),
        )


def reading_alias(reading: str) -> dict:
    """Mc name -> the name of its results under a reading of Algorithm 3 ({} for the default).

    ``reading_alias("literal")["Mc w40 + Type V@60Hz"]`` is
    ``"Mc w40 (literal window) + Type V@60Hz"``.

    Notebook: 12_claims.ipynb
    """
    from .algorithms import method_c_name

    if reading == "square":
        return {}
    out = {}
    for w in WINDOWS:
        for typev in (False, True):
            for rate in ("", "@60Hz"):
                out[method_c_name(w, "square", typev) + rate] = (
                    method_c_name(w, reading, typev) + rate
                )
    return out


def _alias_fig8(fig8, alias):
    """The Fig. 8 notebook's JSON with its deviations keyed by the paper's names."""
    if not alias or fig8 is None:
        return fig8
    devs = _fig8_deviations(fig8)
    if devs is None:
        return fig8
    out = {n: v for n, v in devs.items() if n not in alias}
    out.update({n: devs[s] for n, s in alias.items() if s in devs})
    return {"deviations": out}


def oedtw_backward_jumps(results, name="OE-DTW") -> dict:
    """How often OE-DTW's end point moves backwards (``M_{q+1} < M_q``), over all pairs.

    Returns
    -------
    out : dict
        ``pairs``, ``pairs_backward`` (at least one backward jump), ``fraction``,
        ``jumps`` (total number of backward jumps).

    Paper: FP-DTW Section 2, Fig. 1.
    Notebook: 12_claims.ipynb
    """
    arr = results.get(name)
    offsets = np.asarray(arr["offsets"], dtype=np.int64)
    maps = np.asarray(arr["maps"], dtype=np.int64)
    P = len(offsets) - 1
    back = jumps = 0
    for k in range(P):
        d = np.diff(maps[offsets[k] : offsets[k + 1]])
        j = int(np.count_nonzero(d < 0))
        jumps += j
        back += j > 0
    return dict(pairs=P, pairs_backward=back, fraction=back / P if P else 0.0, jumps=jumps)


def data_counts(pairs) -> dict:
    """Motions, movements and pairs in a pair list (``Results.pairs``), total and per dataset.

    Notebook: 12_claims.ipynb
    """
    out = {}
    for ds in sorted({p["dataset"] for p in pairs}) + [None]:
        pp = [p for p in pairs if ds is None or p["dataset"] == ds]
        motions = {(p["dataset"], p[k]) for p in pp for k in ("input", "target")}
        movements = {(p["dataset"], p["movement"]) for p in pp}
        out[ds or "total"] = dict(motions=len(motions), movements=len(movements), pairs=len(pp))
    return out


# -- helpers -------------------------------------------------------------------------------------

OPW_FIG4_JSON = "13_opw_fig4.json"
OPW_FIG56_JSON = "14_opw_fig5_fig6.json"


def _read_json(path):
    try:
        with open(path) as fh:
            return json.load(fh)
    except FileNotFoundError:
        return None


def _names(xs) -> str:
    return ", ".join(xs) if xs else "none"


def compare_sets(paper, ours) -> str:
    """Compare two sets: "yes" when equal, "partly" when they overlap, "no" otherwise."""
    paper, ours = set(paper), set(ours)
    if paper == ours:
        return "yes"
    return "partly" if paper & ours else "no"


def _order(names):
    rank = {n: i for i, n in enumerate(FPDTW_NAMES + FPDTW_TYPEV_NAMES)}
    return sorted(names, key=lambda n: rank.get(n, len(rank)))


def _row(id, claim, paper, ours, holds, evidence, stable=True):
    return dict(id=id, claim=claim, paper=paper, ours=ours, holds=holds, evidence=evidence,
                stable=bool(stable))  # fmt: skip


def _na(id, claim, paper, why, evidence, stable=True):
    return _row(id, claim, paper, f"not computed ({why})", "n/a", evidence, stable)


# -- the claims ----------------------------------------------------------------------------------


def claim_only_mc_w40_unconstrained(ctx: ClaimContext) -> dict:
    """Claim 1: without a constraint only Mc w40 passes a benchmark.

    Paper: FP-DTW Section 5, Figs. 5 and 6.
    Notebook: 12_claims.ipynb
    """
    claim = (
        "Without a constraint, Mc w40 is the only FP-DTW algorithm whose median passes a "
        "benchmark (similarity above UTW's median or deviation below 18 frames)"
    )
    have = [n for n in FPDTW_NAMES if n in ctx.similarity]
    ours = [n for n in have if ctx.passes_similarity(n) or ctx.passes_deviation(n)]
    return _row(
        "1",
        claim,
        "Mc w40",
        f"pass either: {_names(ours)}",
        compare_sets({"Mc w40"}, ours),
        "Figs. 5, 6; fig5_similarity_summary, fig6_deviation_summary",
    )


def claim_three_pass_both(ctx: ClaimContext) -> dict:
    """Claim 2: Ma + Type V, Mc w40 and Mc w80 + Type V pass both benchmarks.

    Paper: FP-DTW Sections 6 and 7, Figs. 5 and 6.
    Notebook: 12_claims.ipynb
    """
    claim = "Ma + Type V, Mc w40 and Mc w80 + Type V pass both benchmarks"
    paper = ("Ma + Type V", "Mc w40", "Mc w80 + Type V")
    have = [n for n in FPDTW_NAMES + FPDTW_TYPEV_NAMES if n in ctx.similarity]
    ours = [n for n in have if ctx.passes_similarity(n) and ctx.passes_deviation(n)]
    return _row(
        "2",
        claim,
        ", ".join(paper),
        f"pass both: {_names(ours)}",
        compare_sets(paper, ours),
        "Figs. 5, 6; fig5_similarity_summary, fig6_deviation_summary",
    )


def claim_mc_best_window(ctx: ClaimContext) -> dict:
    """Claim 3: Method C's best window is 40 at 120 Hz and 20 at 60 Hz.

    Paper: FP-DTW Table 1.
    Notebook: 12_claims.ipynb
    """
    claim = "Method C's best window (median similarity) moves from 40 at 120 Hz to 20 at 60 Hz"
    paper = "best w: 40 at 120 Hz, 20 at 60 Hz (Table 1)"
    if not ctx.table1:
        return _na("3", claim, paper, "no 60 Hz runs", "Table 1")
    best = {r["rate_hz"]: r["best_w"] for r in ctx.table1 if r["source"].startswith("ours")}
    b120, b60 = best.get(120), best.get(60)
    if b120 is None or b60 is None:
        return _na("3", claim, paper, "a rate is missing", "Table 1")
    hits = (b120 == 40) + (b60 == 20)
    holds = "yes" if hits == 2 else "partly" if (hits == 1 or b60 < b120) else "no"
    return _row(
        "3",
        claim,
        paper,
        f"best w: {b120} at 120 Hz, {b60} at 60 Hz",
        holds,
        "Table 1; table1_method_c_60_120hz",
    )


def claim_cost_grows_with_w(ctx: ClaimContext) -> dict:
    """Claim 4: per-frame cost grows steeply with w (timings: not stable).

    Paper: FP-DTW Table 2.
    Notebook: 12_claims.ipynb
    """
    from .plots.timing import growth_ratio, paper_growth_ratio

    key = "median_us"

    claim = (
        "Per-frame cost grows steeply with the window w (Methods B and C: median time per "
        "frame increasing at every step, w80/w10 ratio >= 8)"
    )
    paper = (
        f"w80/w10: Mb {paper_growth_ratio('B'):.1f}x, Mc {paper_growth_ratio('C'):.1f}x "
        "(Table 2, means)"
    )
    if not ctx.timing:
        return _na("4", claim, paper, "no timings", "Table 2", stable=False)
    parts, means, verdicts = [], [], []
    for method in ("B", "C"):
        ts = {r["w"]: r[key] for r in ctx.timing if r["method"] == method and not r["type_v"]}
        if not all(w in ts for w in WINDOWS):
            return _na("4", claim, paper, f"Method {method} not timed at every w", "Table 2", False)
        seq = [ts[w] for w in WINDOWS]
        increasing = all(b > a for a, b in zip(seq, seq[1:]))
        ratio = growth_ratio(ctx.timing, method, key=key)
        parts.append(f"M{method.lower()} {ratio:.1f}x{'' if increasing else ' (not monotonic)'}")
        mean_ratio = growth_ratio(ctx.timing, method, key="mean_us")
        if mean_ratio is not None:
            means.append(f"M{method.lower()} {mean_ratio:.1f}x")
        verdicts.append("yes" if increasing and ratio >= 8 else "partly" if ratio > 1 else "no")
    holds = (
        "yes"
        if all(v == "yes" for v in verdicts)
        else ("no" if all(v == "no" for v in verdicts) else "partly")
    )
    return _row(
        "4",
        claim,
        paper,
        "w80/w10: "
        + ", ".join(parts)
        + " (medians)"
        + (f"; means: {', '.join(means)}" if means else ""),
        holds,
        "Table 2; table2_time_per_frame, table2_time_vs_w",
        stable=False,
    )


def claim_w80_not_realtime(ctx: ClaimContext) -> dict:
    """Claim 4b: w80 does not fit the 8333 us budget of 120 Hz (timings: not stable).

    Paper: FP-DTW Section 5 (Table 2).
    Notebook: 12_claims.ipynb
    """
    from .bench import PAPER_TABLE2_US

    claim = "A window of 80 is not feasible at 120 Hz (mean per-frame time above 8333 us)"
    budget = 1e6 / 120
    paper = (
        f"Mb w80 {PAPER_TABLE2_US[('B', 80)]:.0f} us, Mc w80 {PAPER_TABLE2_US[('C', 80)]:.0f} us"
    )
    if not ctx.timing:
        return _na("4b", claim, paper, "no timings", "Table 2", stable=False)
    ts = {(r["method"], r["w"]): r["mean_us"] for r in ctx.timing if not r["type_v"]}
    if ("B", 80) not in ts or ("C", 80) not in ts:
        return _na("4b", claim, paper, "w80 not timed", "Table 2", stable=False)
    over = [m for m in ("B", "C") if ts[(m, 80)] > budget]
    holds = "yes" if len(over) == 2 else "partly" if over else "no"
    return _row(
        "4b",
        claim,
        paper,
        f"Mb w80 {ts[('B', 80)]:.0f} us, Mc w80 {ts[('C', 80)]:.0f} us",
        holds,
        "Table 2; table2_time_per_frame",
        stable=False,
    )


def claim_mc_w80_runs_out(ctx: ClaimContext) -> dict:
    """Claim 4c: Mc w80 runs out of input frames early (from the maps).

    Paper: FP-DTW Section 5 (Table 2).
    Notebook: 12_claims.ipynb
    """
    claim = (
        "Mc w80 runs out of input frames early (the reason for its low time): it has the "
        "largest fraction of target frames processed with the input exhausted among the "
        "unconstrained B and C algorithms"
    )
    paper = "Mc w80 runs out of input early (Section 5, no number)"
    cand = [n for n in FPDTW_NAMES if n != "Ma" and n in ctx.exhausted]
    if "Mc w80" not in cand:
        return _na("4c", claim, paper, "no Mc w80 maps", "Table 2")
    top = max(cand, key=lambda n: ctx.exhausted[n])
    holds = "yes" if ctx.exhausted["Mc w80"] >= ctx.exhausted[top] else "no"
    others = ", ".join(f"{n} {ctx.exhausted[n]:.2f}" for n in ("Mc w40", "Mb w80") if n in cand)
    return _row(
        "4c",
        claim,
        paper,
        f"Mc w80 {ctx.exhausted['Mc w80']:.2f} of frames ({others}); largest: {top}",
        holds,
        "table2_time_per_frame (exhausted_fraction)",
    )


def _rank(values: dict, name: str, higher_is_better: bool) -> int:
    v = values[name]
    better = [n for n, x in values.items() if (x > v if higher_is_better else x < v)]
    return 1 + len(better)


def claim_ma_among_worst(ctx: ClaimContext) -> dict:
    """Claim 5: without a constraint Ma is among the worst in both tests.

    Paper: FP-DTW Section 5, Figs. 5 and 6.
    Notebook: 12_claims.ipynb
    """
    claim = (
        "Without a constraint, Ma is among the worst FP-DTW algorithms in both tests "
        "(bottom third: rank 7-9 of 9)"
    )
    have = [n for n in FPDTW_NAMES if n in ctx.similarity and n in ctx.deviation]
    if "Ma" not in have:
        return _na("5", claim, "one of the worst in both tests", "no Ma", "Figs. 5, 6")
    sim = {n: ctx.similarity[n] for n in have}
    dev = {n: ctx.deviation[n] for n in have}
    rs, rd = _rank(sim, "Ma", True), _rank(dev, "Ma", False)
    cut = len(have) - len(have) // 3  # 9 algorithms: ranks 7, 8, 9
    hits = (rs > cut) + (rd > cut)
    return _row(
        "5",
        claim,
        "one of the worst in both tests",
        f"Ma ranks {rs} of {len(have)} (similarity), {rd} of {len(have)} (deviation)",
        "yes" if hits == 2 else "partly" if hits == 1 else "no",
        "Figs. 5, 6; fig5_similarity_summary, fig6_deviation_summary",
    )


def claim_mb_improves_with_w(ctx: ClaimContext) -> dict:
    """Claim 5b: Method B improves as its window grows.

    Paper: FP-DTW Section 5, Figs. 5 and 6.
    Notebook: 12_claims.ipynb
    """
    claim = (
        "Method B improves as the window grows (median similarity up and median deviation "
        "down at every step w10 -> w80)"
    )
    names = [f"Mb w{w}" for w in WINDOWS]
    paper = "Method B improves with w; Method C peaks at w40 (Section 5)"
    if not all(n in ctx.similarity for n in names):
        return _na("5b", claim, paper, "Method B missing", "Figs. 5, 6")
    s = [ctx.similarity[n] for n in names]
    d = [ctx.deviation[n] for n in names]
    up = all(b > a for a, b in zip(s, s[1:]))
    down = all(b < a for a, b in zip(d, d[1:]))
    return _row(
        "5b",
        claim,
        paper,
        "similarity " + " / ".join(f"{x:.3f}" for x in s)
        + "; deviation " + " / ".join(f"{x:.1f}" for x in d),
        "yes" if up and down else "partly" if up or down else "no",
        "Figs. 5, 6; fig5_similarity_summary, fig6_deviation_summary",
    )  # fmt: skip


#: The paper's Section 6: algorithms improved by the Type V constraint.
PAPER_TYPEV_IMPROVED = ("Ma", "Mb w10", "Mb w20", "Mb w40", "Mb w80", "Mc w80")


def claim_typev_improves(ctx: ClaimContext) -> dict:
    """Claim 6: Type V improves every A and B algorithm, of Method C only Mc w80.

    Paper: FP-DTW Section 6, Figs. 5 and 6.
    Notebook: 12_claims.ipynb
    """
    claim = (
        "The Type V constraint improves every Method A and B algorithm but, of Method C, only "
        "Mc w80 (improved: median similarity higher AND median deviation lower)"
    )
    bases = [n for n in FPDTW_NAMES if n in ctx.similarity and n + TYPE_V_SUFFIX in ctx.similarity]
    if not bases:
        return _na("6", claim, _names(PAPER_TYPEV_IMPROVED), "no Type V runs", "Figs. 5, 6")
    both, one = [], []
    for b in bases:
        tv = b + TYPE_V_SUFFIX
        s = ctx.similarity[tv] > ctx.similarity[b]
        d = ctx.deviation[tv] < ctx.deviation[b]
        (both if s and d else one if s or d else []).append(b)
    return _row(
        "6",
        claim,
        "improved: " + _names(PAPER_TYPEV_IMPROVED),
        f"improved: {_names(both)}; in one test only: {_names(one)}",
        compare_sets(PAPER_TYPEV_IMPROVED, both),
        "Figs. 5, 6 (with/without Type V); fig5/fig6 summaries",
    )


def claim_oedtw_backward(ctx: ClaimContext) -> dict:
    """Claim 7: OE-DTW's end points move backwards.

    Paper: FP-DTW Section 2, Fig. 1.
    Notebook: 12_claims.ipynb
    """
    claim = "OE-DTW's end points move backwards between consecutive target frames"
    paper = "yes (Fig. 1: one example, frames 15 -> 16)"
    oe = ctx.oedtw_backward
    if not oe:
        return _na("7", claim, paper, "no OE-DTW maps", "Fig. 1")
    return _row(
        "7",
        claim,
        paper,
        f"{oe['pairs_backward']} of {oe['pairs']} pairs ({oe['fraction']:.0%}) have a backward "
        f"jump; {oe['jumps']} jumps in all",
        "yes" if oe["pairs_backward"] > 0 else "no",
        "Fig. 1 (02_fig1_oedtw); OE-DTW maps",
    )


def _fig8_deviations(d) -> dict | None:
    """Algorithm -> deviation (frames) from the Fig. 8 notebook's JSON, whatever its nesting."""
    if not isinstance(d, dict):
        return None
    for key in ("deviations", "deviation", "deviation_frames"):
        v = d.get(key)
        if isinstance(v, dict) and v and all(isinstance(x, int | float) for x in v.values()):
            return {k: float(x) for k, x in v.items()}
    algos = d.get("algorithms")
    if isinstance(algos, dict):
        out = {k: v.get("deviation") for k, v in algos.items() if isinstance(v, dict)}
        out = {k: float(v) for k, v in out.items() if isinstance(v, int | float)}
        return out or None
    if isinstance(algos, list):
        out = {
            a["name"]: float(a["deviation"])
            for a in algos
            if isinstance(a, dict) and "name" in a and isinstance(a.get("deviation"), int | float)
        }
        return out or None
    return None


def claim_fig8_walk_pair(ctx: ClaimContext) -> dict:
    """Claim 8: the Fig. 8 walk pair's deviations from DTW.

    Paper: FP-DTW Section 5, Fig. 8.
    Notebook: 12_claims.ipynb
    """
    claim = (
        "On the walk pair of Fig. 8, the deviations from DTW of Mb w80, Mc w20, Mc w40, Mc w80 "
        "are 8, 177, 62, 6 frames: below 18 only for Mb w80 and Mc w80 by these numbers (the "
        "paper's text names Mb w80 and Mc w40, contradicting its own numbers)"
    )
    paper = ", ".join(f"{k} {v:.0f}" for k, v in PAPER_FIG8_DEVIATIONS.items())
    devs = _fig8_deviations(ctx.fig8)
    if ctx.fig8 is None:
        return _na("8", claim, paper, f"{FIG8_JSON} absent", "Fig. 8")
    if not devs or not all(n in devs for n in PAPER_FIG8_DEVIATIONS):
        return _na("8", claim, paper, f"{FIG8_JSON} lacks the deviations", "Fig. 8")
    below_paper = [n for n, v in PAPER_FIG8_DEVIATIONS.items() if v < DEVIATION_BENCHMARK]
    below_ours = [n for n in PAPER_FIG8_DEVIATIONS if devs[n] < DEVIATION_BENCHMARK]
    return _row(
        "8",
        claim,
        paper,
        ", ".join(f"{n} {devs[n]:.1f}" for n in PAPER_FIG8_DEVIATIONS)
        + f" (below 18: {_names(below_ours)}; our walk pair differs from the paper's)",
        compare_sets(below_paper, below_ours),
        f"Fig. 8 (10_fig8_walk_pair); results/{ctx.mode}/figs/{FIG8_JSON}",
    )


def claim_data(ctx: ClaimContext) -> dict:
    """Claim 9: the data (motions, movements, pairs).

    Paper: FP-DTW Section 4.
    Notebook: 12_claims.ipynb
    """
    claim = "The data: the paper's motions, movements and ordered pairs"
    p = PAPER_DATA
    paper = f"{p['motions']} motions, {p['movements']} movements, {p['pairs']} pairs"
    if not ctx.counts:
        return _na("9", claim, paper, "no pair list", "pairs.json")
    t = ctx.counts["total"]
    per = "; ".join(
        f"{ds}: {c['motions']}/{c['movements']}/{c['pairs']}"
        for ds, c in ctx.counts.items()
        if ds != "total"
    )
    same = (t["motions"], t["movements"], t["pairs"]) == (p["motions"], p["movements"], p["pairs"])
    return _row(
        "9",
        claim,
        paper,
        f"{t['motions']} motions, {t['movements']} movements, {t['pairs']} pairs ({per}, as "
        f"motions/movements/pairs{'; SMOKE subset' if ctx.mode == 'smoke' else ''})",
        "yes" if same else "no",
        f"results/{ctx.mode}/pairs.json; 05_run_experiments",
    )


# -- the OPW poster (its Figs. 4-6, notebooks 13 and 14) ------------------------------------------


def _close(ours: float, paper: float, tol: float) -> str:
    return "yes" if abs(ours - paper) <= tol else "no"


def claim_opw_mean_deviation(ctx: ClaimContext) -> dict:
    """Poster claim: OPW's mean deviation is 69-79 ms, its maximum 121 ms (< 150 ms).

    Paper: OPW poster, Section 5 and Fig. 4.
    Notebook: 12_claims.ipynb
    """
    claim = (
        "OPW poster: over the three motions (offset 0.25 s, gamma 5 %), OPW's mean deviation "
        "from the example warp curve is 69-79 ms and its maximum 121 ms, below the 150 ms "
        "perceptual threshold"
    )
    paper = "mean 69-79 ms, max 121 ms"
    d = ctx.opw_fig4
    if d is None:
        return _na("P1", claim, paper, f"{OPW_FIG4_JSON} absent", "poster Fig. 4")
    lo, hi = d["opw_mean_ms_range"]
    mx = d["opw_max_ms"]
    dlo, dhi = d["dtw_mean_ms_range"]
    numbers = "yes" if (69 <= lo and hi <= 79) else "no"
    holds = "yes" if numbers == "yes" and mx < 150 else ("partly" if mx < 150 else "no")
    return _row(
        "P1",
        claim,
        paper,
        f"mean {lo:.0f}-{hi:.0f} ms, max {mx:.0f} ms (DTW mean {dlo:.0f}-{dhi:.0f} ms); "
        "below 150 ms, but not the poster's numbers: our stand-in clips differ",
        holds,
        f"poster Fig. 4 (13_opw_fig4); results/{ctx.mode}/figs/{OPW_FIG4_JSON}",
    )


def claim_opw_removed(ctx: ClaimContext) -> dict:
    """Poster claim: OPW removes about 70 % of the temporal difference (gamma 5 %).

    Paper: OPW poster, Section 5 and Fig. 5.
    Notebook: 12_claims.ipynb
    """
    claim = (
        "OPW poster: with gamma 5 %, OPW consistently removes about 70 % of the temporal "
        "difference between the motions, over the offsets of Fig. 5 (ours: within 10 "
        "percentage points, mean over offsets)"
    )
    paper = "about 70 %"
    d = ctx.opw_fig56
    if d is None:
        return _na("P2", claim, paper, f"{OPW_FIG56_JSON} absent", "poster Fig. 5")
    mean = d["removed_gamma5_mean_over_offsets"]
    lo, hi = d["removed_gamma5_range_over_offsets"]
    return _row(
        "P2",
        claim,
        paper,
        f"{100 * mean:.0f} % on average ({100 * lo:.0f}-{100 * hi:.0f} % across offsets; "
        f"{100 * d['removed_gamma5_at_offset']:.0f} % at 0.25 s)",
        _close(mean, 0.70, 0.10),
        f"poster Fig. 5 (14_opw_fig5_fig6); results/{ctx.mode}/figs/{OPW_FIG56_JSON}",
    )


def claim_opw_best_gamma(ctx: ClaimContext) -> dict:
    """Poster claim: the best gamma is 15 %, removing about 77 %.

    Paper: OPW poster, Section 5 and Fig. 6.
    Notebook: 12_claims.ipynb
    """
    claim = (
        "OPW poster: OPW does best with gamma = 15 %, removing about 77 % of the temporal "
        "difference (ours: best gamma within 5 points, removed share within 10 points)"
    )
    paper = "gamma 15 %, about 77 %"
    d = ctx.opw_fig56
    if d is None:
        return _na("P3", claim, paper, f"{OPW_FIG56_JSON} absent", "poster Fig. 6")
    g, r = d["best_gamma"], d["removed_best_gamma"]
    ok_g = abs(g - 0.15) <= 0.05
    ok_r = abs(r - 0.77) <= 0.10
    holds = "yes" if ok_g and ok_r else ("partly" if ok_g or ok_r else "no")
    return _row(
        "P3",
        claim,
        paper,
        f"gamma {100 * g:.0f} %, {100 * r:.0f} % removed",
        holds,
        f"poster Fig. 6 (14_opw_fig5_fig6); results/{ctx.mode}/figs/{OPW_FIG56_JSON}",
    )


def claim_opw_offset_limit(ctx: ClaimContext) -> dict:
    """Poster claim: OPW copes with a 300 ms offset (maximum deviation below 150 ms).

    Paper: OPW poster, Section 5 and Fig. 5.
    Notebook: 12_claims.ipynb
    """
    claim = (
        "OPW poster: OPW copes with a temporal difference of 300 ms in 2500 ms motions "
        "(maximum deviation below 150 ms), and up to 500 ms judged by the mean"
    )
    paper = "300 ms (max), 500 ms (mean)"
    d = ctx.opw_fig56
    if d is None:
        return _na("P4", claim, paper, f"{OPW_FIG56_JSON} absent", "poster Fig. 5")
    mx = d["largest_offset_max_below_150ms_s"]
    mean = d["largest_offset_mean_below_150ms_s"]
    holds = "yes" if mx >= 0.3 and mean >= 0.5 else ("partly" if mx >= 0.3 or mean >= 0.5 else "no")
    return _row(
        "P4",
        claim,
        paper,
        f"{1000 * mx:.0f} ms (max), {1000 * mean:.0f} ms (mean; the largest offset tried)",
        holds,
        f"poster Fig. 5 (14_opw_fig5_fig6); results/{ctx.mode}/figs/{OPW_FIG56_JSON}",
    )


def claim_beyond_baselines(ctx: ClaimContext) -> dict:
    """Not a paper claim: OPW and OLTW on the FP-DTW pairs, against the same benchmarks.

    Notebook: 12_claims.ipynb
    """
    claim = (
        "Beyond the papers: the OPW poster's method and Dixon's OLTW (the FP-DTW paper's ref. 3) "
        "run on the FP-DTW pairs, against the same two benchmarks"
    )
    parts = []
    for n in ("OPW", "OLTW"):
        if n in ctx.similarity:
            sim = "passes" if ctx.passes_similarity(n) else "fails"
            dev = "passes" if ctx.passes_deviation(n) else "fails"
            parts.append(
                f"{n}: similarity {ctx.similarity[n]:.3f} ({sim}), deviation "
                f"{ctx.deviation[n]:.1f} frames ({dev})"
            )
    return _row(
        "B1",
        claim,
        "not in the papers",
        "; ".join(parts) or "not computed",
        "n/a",
        "Figs. 5, 6, 7; fig5_similarity_summary, fig6_deviation_summary",
    )


#: The claim functions, in table order. Each takes a :class:`ClaimContext` and returns a row.
CLAIMS = [
    claim_only_mc_w40_unconstrained,
    claim_three_pass_both,
    claim_mc_best_window,
    claim_cost_grows_with_w,
    claim_w80_not_realtime,
    claim_mc_w80_runs_out,
    claim_ma_among_worst,
    claim_mb_improves_with_w,
    claim_typev_improves,
    claim_oedtw_backward,
    claim_fig8_walk_pair,
    claim_data,
    claim_opw_mean_deviation,
    claim_opw_removed,
    claim_opw_best_gamma,
    claim_opw_offset_limit,
    claim_beyond_baselines,
]


def register_claim(fn):
    """Add a claim function (``fn(ctx) -> row dict``) to :data:`CLAIMS`; usable as decorator."""
    if fn not in CLAIMS:
        CLAIMS.append(fn)
    return fn


def build_claims(mode="full", results=None, claims=None, context=None) -> list[dict]:
    """Check every claim against our results.

    Parameters
    ----------
    mode : {"full", "smoke"}
    results : fpdtw.experiments.Results, optional
        Default ``load_results(mode)``.
    claims : sequence of callables, optional
        Default :data:`CLAIMS`.
    context : ClaimContext, optional
        Precomputed context (then ``results`` is not read).

    Returns
    -------
    rows : list of dict
        Keys :data:`COLUMNS`: ``id``, ``claim``, ``paper``, ``ours``, ``holds`` ("yes", "no",
        "partly", "n/a"), the same two under Method C's literal window (``ours_literal``,
        ``holds_literal``; with a given ``context``, copies of ours), ``evidence``,
        ``stable`` (False: computed from timings).

    Paper: FP-DTW Sections 5-7.
    Notebook: 12_claims.ipynb
    """
    if context is None:
        if results is None:
            from .experiments import load_results

            results = load_results(mode)
        contexts = {
            suffix: ClaimContext.from_results(results, mode, reading=reading)
            for suffix, reading in READINGS.items()
        }
    else:
        contexts = {suffix: context for suffix in READINGS}
    rows = []
    for fn in CLAIMS if claims is None else claims:
        row = fn(contexts[""])
        for suffix, ctx in contexts.items():
            if suffix:
                other = fn(ctx)
                row[f"ours{suffix}"] = other.get("ours")
                row[f"holds{suffix}"] = other.get("holds")
        missing = [c for c in COLUMNS if c not in row or row[c] is None]
        if missing:
            raise ValueError(f"claim {fn.__name__} returned a row without {missing}")
        rows.append(row)
    return rows


def save_claims(rows, mode="full"):
    """Write the claims as ``claims.csv|md`` (figures folder) and ``results/<mode>/claims.json``.

    Returns
    -------
    paths : list of Path

    Notebook: 12_claims.ipynb
    """
    from .paths import results_dir
    from .tables import save_table

    out = list(save_table(rows, "claims", columns=COLUMNS))
    path = results_dir() / mode / "claims.json"
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(".json.part")
    tmp.write_text(json.dumps({"mode": mode, "claims": rows}, indent=1) + "\n")
    os.replace(tmp, path)
    out.append(path)
    return out


__all__ = [
    "CLAIMS",
    "COLUMNS",
    "ClaimContext",
    "build_claims",
    "compare_sets",
    "data_counts",
    "oedtw_backward_jumps",
    "register_claim",
    "save_claims",
]
