"""The papers' claims, checked against our results: a table of claims, one rule each.

Each claim of :data:`CLAIMS` is a row of data: its id, the claim in words, the paper's value
(from :mod:`fpdtw.paper.numbers`), an *extractor* that reads our value from a
:class:`ClaimContext` (built once from the experiment results and the notebooks' facts) and
a *rule* that decides whether the claim holds here ("yes", "no", "partly"; "n/a" when our
value could not be computed). :func:`build_claims` evaluates the table, once with Method C's
default window and once with its literal window (notebook 15), and :func:`save_claims`
writes ``claims.csv|md`` and ``results/<mode>/claims.json``.

The rules are fixed here and never tuned to make a claim come true:

* A benchmark is passed by an algorithm whose MEDIAN similarity is above UTW's median
  similarity, or whose MEDIAN deviation from DTW is below 18 frames
  (:func:`fpdtw.paper.numbers.passes_similarity`, :func:`~fpdtw.paper.numbers.passes_deviation`).
* Set claims ("only Mc w40 passes ..."): "yes" when our set equals the paper's, "partly"
  when they share at least one algorithm, "no" otherwise (:func:`compare_sets`).
* "Improved by Type V": median similarity higher AND median deviation lower with the
  constraint than without.
* "Among the worst": in the bottom third (rank 7 to 9 of the 9 unconstrained FP-DTW
  algorithms) of a test.
* "Grows steeply with w": the MEDIAN per-frame time increases at every window step and the
  ratio w80 / w10 is at least 8 (the window grows 8-fold; the paper's ratios of means are
  19.8 and 12.9). Medians, because a mean is dragged by rare slow frames; the means are
  shown too.

Rows carry ``stable``: False for the claims computed from timings (``make bench``:
measurements that change between runs); all other rows are deterministic.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from fpdtw.paper import numbers as N
from fpdtw.paper.atomic import write_atomic
from fpdtw.paper.numbers import FPDTW_NAMES, FPDTW_TYPEV_NAMES, TYPE_V, WINDOWS

#: Name of the Fig. 8 notebook's JSON under ``results/<mode>/figs/``.
FIG8_JSON = "10_fig8_walk_pair.json"
OPW_FIG4_JSON = "13_opw_fig4.json"
OPW_FIG56_JSON = "14_opw_fig5_fig6.json"

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
        :func:`fpdtw.paper.figures.scores.table1_rows` (None without the 60 Hz runs).
    timing : list of dict or None
        :func:`fpdtw.paper.figures.timing.time_per_frame_rows` of ``make bench``'s report
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
        return name in self.similarity and N.passes_similarity(
            self.similarity[name], self.utw_median
        )

    def passes_deviation(self, name) -> bool:
        return name in self.deviation and N.passes_deviation(self.deviation[name])

    @classmethod
    def from_results(cls, results, mode="full", fig8_path=None, reading="square"):
        """Compute the context from :func:`fpdtw.paper.runner.run.load_results` output.

        ``reading`` chooses Method C's reading of Algorithm 3: with ``"literal"`` every Mc
        name (``"Mc w40"``, ``"Mc w80 + Type V"``, ``"Mc w20@60Hz"``) stands for the
        results of that reading (``"Mc w40 (literal window)"``, ...), so the same claims
        are checked under it; Mc names without such results are left out.
        """
        from fpdtw.paper.figures.scores import scores, table1_rows, utw_median
        from fpdtw.paper.figures.timing import (
            TIMED_NAMES,
            exhausted_fraction,
            load_bench,
            time_per_frame_rows,
        )
        from fpdtw.paper.paths import results_dir

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

    @classmethod
    def from_facts(cls, mode="full", reading="square", **facts):
        """A context holding only a notebook's own facts (no experiment results).

        For notebooks that check a claim from what they computed themselves, without
        loading the experiment grid: the walk pair (``fig8``: notebook 10's JSON), the OPW
        poster's figures (``opw_fig4``, ``opw_fig56``), the data (``counts``, as
        :func:`data_counts`) or OE-DTW's jumps (``oedtw_backward``, as
        :func:`oedtw_backward_jumps`). Claims that need anything else come out "not
        computed". With ``reading="literal"`` the Fig. 8 deviations of Method C are read
        from its literal-window maps, as :meth:`from_results` does.

        Parameters
        ----------
        mode : {"full", "smoke"}
        reading : str
            Method C's reading (:func:`reading_alias`).
        **facts
            Attributes of :class:`ClaimContext` (``fig8``, ``opw_fig4``, ``opw_fig56``,
            ``counts``, ``oedtw_backward``, ``timing``: rows of
            :func:`fpdtw.paper.figures.timing.time_per_frame_rows`, which may hold Method
            C's other readings too: each reading's rows stand for the paper's names).

        Paper: FP-DTW Sections 5-7; OPW poster Section 5.
        """
        allowed = {"fig8", "opw_fig4", "opw_fig56", "counts", "oedtw_backward", "timing"}
        unknown = set(facts) - allowed
        if unknown:
            raise TypeError(f"unknown facts {sorted(unknown)}; allowed: {sorted(allowed)}")
        alias = reading_alias(reading)
        if facts.get("fig8") is not None:
            facts["fig8"] = _alias_fig8(facts["fig8"], alias)
        if facts.get("timing") is not None:
            facts["timing"] = _alias_timing(facts["timing"], alias)
        return cls(mode=mode, **facts)


def reading_alias(reading: str) -> dict:
    """Mc name -> the name of its results under a reading of Algorithm 3 ({} for the default).

    ``reading_alias("literal")["Mc w40 + Type V@60Hz"]`` is
    ``"Mc w40 (literal window) + Type V@60Hz"``.
    """
    from fpdtw.registry import method_c_name

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


def _alias_timing(rows, alias):
    """Timing rows keyed by the paper's names: a reading's Mc rows stand for "Mc w<w>"."""
    by = {r["algorithm"]: r for r in rows}
    out = []
    for r in rows:
        name = r["algorithm"]
        if "(" in name:  # another reading's row: used below only if the reading asks for it
            continue
        src = by.get(alias.get(name, name))
        if src is not None:
            out.append({**src, "algorithm": name})
    return out


def oedtw_backward_jumps(results, name="OE-DTW") -> dict:
    """How often OE-DTW's end point moves backwards (``M_{q+1} < M_q``), over all pairs.

    Returns
    -------
    out : dict
        ``pairs``, ``pairs_backward`` (at least one backward jump), ``fraction``,
        ``jumps`` (total number of backward jumps).

    Paper: FP-DTW Section 2, Fig. 1.
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
    """Motions, movements and pairs in a pair list (``Results.pairs``), total and per dataset."""
    out = {}
    for ds in sorted({p["dataset"] for p in pairs}) + [None]:
        pp = [p for p in pairs if ds is None or p["dataset"] == ds]
        motions = {(p["dataset"], p[k]) for p in pp for k in ("input", "target")}
        movements = {(p["dataset"], p["movement"]) for p in pp}
        out[ds or "total"] = dict(motions=len(motions), movements=len(movements), pairs=len(pp))
    return out


# -- helpers ----------------------------------------------------------------------------------


def _read_json(path):
    try:
        with open(path) as fh:
            return json.load(fh)
    except FileNotFoundError:
        return None


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


def compare_sets(paper, ours) -> str:
    """Compare two sets: "yes" when equal, "partly" when they overlap, "no" otherwise."""
    paper, ours = set(paper), set(ours)
    if paper == ours:
        return "yes"
    return "partly" if paper & ours else "no"


def _names(xs) -> str:
    return ", ".join(xs) if xs else "none"


def _share(hits: int, of: int) -> str:
    """All of them: "yes"; some: "partly"; none: "no"."""
    return "yes" if hits == of else "partly" if hits else "no"


# -- extractors: our value of a claim, read from the context -------------------------------------
# Each returns ``(ours in words, value)`` for the rule, or a string: why it is not computed.


def _passing(ctx, names, both: bool):
    have = [n for n in names if n in ctx.similarity]
    if both:
        return [n for n in have if ctx.passes_similarity(n) and ctx.passes_deviation(n)]
    return [n for n in have if ctx.passes_similarity(n) or ctx.passes_deviation(n)]


def _pass_either(ctx):
    if not ctx.similarity:
        return "no scores"
    ours = _passing(ctx, FPDTW_NAMES, both=False)
    return f"pass either: {_names(ours)}", ours


def _pass_both(ctx):
    if not ctx.similarity:
        return "no scores"
    ours = _passing(ctx, FPDTW_NAMES + FPDTW_TYPEV_NAMES, both=True)
    return f"pass both: {_names(ours)}", ours


def _best_window(ctx):
    if not ctx.table1:
        return "no 60 Hz runs"
    best = {r["rate_hz"]: r["best_w"] for r in ctx.table1 if r["source"].startswith("ours")}
    if best.get(120) is None or best.get(60) is None:
        return "a rate is missing"
    return f"best w: {best[120]} at 120 Hz, {best[60]} at 60 Hz", (best[120], best[60])


def _growth(ctx):
    from fpdtw.paper.figures.timing import growth_ratio

    if not ctx.timing:
        return "no timings"
    parts, means, verdicts = [], [], []
    for method in ("B", "C"):
        rows = [r for r in ctx.timing if r["method"] == method and not r["type_v"]]
        ts = {r["w"]: r["median_us"] for r in rows}
        if not all(w in ts for w in WINDOWS):
            return f"Method {method} not timed at every w"
        seq = [ts[w] for w in WINDOWS]
        increasing = all(b > a for a, b in zip(seq, seq[1:]))
        ratio = growth_ratio(ctx.timing, method, key="median_us")
        parts.append(f"M{method.lower()} {ratio:.1f}x{'' if increasing else ' (not monotonic)'}")
        mean_ratio = growth_ratio(ctx.timing, method, key="mean_us")
        if mean_ratio is not None:
            means.append(f"M{method.lower()} {mean_ratio:.1f}x")
        verdicts.append("yes" if increasing and ratio >= 8 else "partly" if ratio > 1 else "no")
    ours = "w80/w10: " + ", ".join(parts) + " (medians)"
    return ours + (f"; means: {', '.join(means)}" if means else ""), verdicts


def _w80_budget(ctx):
    if not ctx.timing:
        return "no timings"
    ts = {(r["method"], r["w"]): r["mean_us"] for r in ctx.timing if not r["type_v"]}
    if ("B", 80) not in ts or ("C", 80) not in ts:
        return "w80 not timed"
    over = [m for m in ("B", "C") if ts[(m, 80)] > N.BUDGET_120HZ_US]
    return f"Mb w80 {ts[('B', 80)]:.0f} us, Mc w80 {ts[('C', 80)]:.0f} us", len(over)


def _runs_out(ctx):
    cand = [n for n in FPDTW_NAMES if n != "Ma" and n in ctx.exhausted]
    if "Mc w80" not in cand:
        return "no Mc w80 maps"
    top = max(cand, key=lambda n: ctx.exhausted[n])
    others = ", ".join(f"{n} {ctx.exhausted[n]:.2f}" for n in ("Mc w40", "Mb w80") if n in cand)
    ours = f"Mc w80 {ctx.exhausted['Mc w80']:.2f} of frames ({others}); largest: {top}"
    return ours, ctx.exhausted["Mc w80"] >= ctx.exhausted[top]


def _rank(values: dict, name: str, higher_is_better: bool) -> int:
    v = values[name]
    return 1 + sum(1 for x in values.values() if (x > v if higher_is_better else x < v))


def _ma_worst(ctx):
    have = [n for n in FPDTW_NAMES if n in ctx.similarity and n in ctx.deviation]
    if "Ma" not in have:
        return "no Ma"
    rs = _rank({n: ctx.similarity[n] for n in have}, "Ma", True)
    rd = _rank({n: ctx.deviation[n] for n in have}, "Ma", False)
    cut = len(have) - len(have) // 3  # 9 algorithms: ranks 7, 8, 9
    ours = f"Ma ranks {rs} of {len(have)} (similarity), {rd} of {len(have)} (deviation)"
    return ours, (rs > cut) + (rd > cut)


def _mb_grows(ctx):
    names = [f"Mb w{w}" for w in WINDOWS]
    if not all(n in ctx.similarity for n in names):
        return "Method B missing"
    s = [ctx.similarity[n] for n in names]
    d = [ctx.deviation[n] for n in names]
    up = all(b > a for a, b in zip(s, s[1:]))
    down = all(b < a for a, b in zip(d, d[1:]))
    ours = "similarity " + " / ".join(f"{x:.3f}" for x in s)
    return ours + "; deviation " + " / ".join(f"{x:.1f}" for x in d), up + down


def _typev_improves(ctx):
    bases = [n for n in FPDTW_NAMES if n in ctx.similarity and n + TYPE_V in ctx.similarity]
    if not bases:
        return "no Type V runs"
    both, one = [], []
    for b in bases:
        s = ctx.similarity[b + TYPE_V] > ctx.similarity[b]
        d = ctx.deviation[b + TYPE_V] < ctx.deviation[b]
        (both if s and d else one if s or d else []).append(b)
    return f"improved: {_names(both)}; in one test only: {_names(one)}", both


def _oedtw_backward(ctx):
    oe = ctx.oedtw_backward
    if not oe:
        return "no OE-DTW maps"
    ours = (
        f"{oe['pairs_backward']} of {oe['pairs']} pairs ({oe['fraction']:.0%}) have a backward "
        f"jump; {oe['jumps']} jumps in all"
    )
    return ours, oe["pairs_backward"] > 0


def _fig8(ctx):
    if ctx.fig8 is None:
        return f"{FIG8_JSON} absent"
    devs = _fig8_deviations(ctx.fig8)
    if not devs or not all(n in devs for n in N.FIG8_DEVIATIONS):
        return f"{FIG8_JSON} lacks the deviations"
    below = [n for n in N.FIG8_DEVIATIONS if N.passes_deviation(devs[n])]
    ours = ", ".join(f"{n} {devs[n]:.1f}" for n in N.FIG8_DEVIATIONS)
    return ours + f" (below 18: {_names(below)}; our walk pair differs from the paper's)", below


def _data(ctx):
    if not ctx.counts:
        return "no pair list"
    t = ctx.counts["total"]
    per = "; ".join(
        f"{ds}: {c['motions']}/{c['movements']}/{c['pairs']}"
        for ds, c in ctx.counts.items()
        if ds != "total"
    )
    smoke = "; SMOKE subset" if ctx.mode == "smoke" else ""
    ours = (
        f"{t['motions']} motions, {t['movements']} movements, {t['pairs']} pairs ({per}, as "
        f"motions/movements/pairs{smoke})"
    )
    return ours, (t["motions"], t["movements"], t["pairs"])


def _opw_mean(ctx):
    d = ctx.opw_fig4
    if d is None:
        return f"{OPW_FIG4_JSON} absent"
    (lo, hi), mx, (dlo, dhi) = d["opw_mean_ms_range"], d["opw_max_ms"], d["dtw_mean_ms_range"]
    ours = (
        f"mean {lo:.0f}-{hi:.0f} ms, max {mx:.0f} ms (DTW mean {dlo:.0f}-{dhi:.0f} ms); "
        "below 150 ms, but not the poster's numbers: our stand-in clips differ"
    )
    pmin, pmax = N.OPW_MEAN_DEVIATION_MS
    return ours, (pmin <= lo and hi <= pmax, mx < N.PERCEPTUAL_THRESHOLD_MS)


def _opw_removed(ctx):
    d = ctx.opw_fig56
    if d is None:
        return f"{OPW_FIG56_JSON} absent"
    mean = d["removed_gamma5_mean_over_offsets"]
    lo, hi = d["removed_gamma5_range_over_offsets"]
    ours = (
        f"{100 * mean:.0f} % on average ({100 * lo:.0f}-{100 * hi:.0f} % across offsets; "
        f"{100 * d['removed_gamma5_at_offset']:.0f} % at 0.25 s)"
    )
    return ours, abs(mean - N.OPW_REMOVED_GAMMA5) <= 0.10


def _opw_best_gamma(ctx):
    d = ctx.opw_fig56
    if d is None:
        return f"{OPW_FIG56_JSON} absent"
    g, r = d["best_gamma"], d["removed_best_gamma"]
    ok = (abs(g - N.OPW_BEST_GAMMA) <= 0.05) + (abs(r - N.OPW_REMOVED_BEST_GAMMA) <= 0.10)
    return f"gamma {100 * g:.0f} %, {100 * r:.0f} % removed", ok


def _opw_offset(ctx):
    d = ctx.opw_fig56
    if d is None:
        return f"{OPW_FIG56_JSON} absent"
    mx = d["largest_offset_max_below_150ms_s"]
    mean = d["largest_offset_mean_below_150ms_s"]
    ours = f"{1000 * mx:.0f} ms (max), {1000 * mean:.0f} ms (mean; the largest offset tried)"
    return ours, (mx >= N.OPW_OFFSET_MAX_OK_S) + (mean >= N.OPW_OFFSET_MEAN_OK_S)


def _beyond(ctx):
    parts = []
    for n in ("OPW", "OLTW"):
        if n in ctx.similarity:
            sim = "passes" if ctx.passes_similarity(n) else "fails"
            dev = "passes" if ctx.passes_deviation(n) else "fails"
            parts.append(
                f"{n}: similarity {ctx.similarity[n]:.3f} ({sim}), deviation "
                f"{ctx.deviation[n]:.1f} frames ({dev})"
            )
    return "; ".join(parts) or "not computed", None


# -- the table ---------------------------------------------------------------------------------


@dataclass(frozen=True)
class Claim:
    """One claim: what the paper says, how we read ours, and the rule deciding "holds".

    Attributes
    ----------
    id, text, paper, evidence : str
    extract : callable
        ``extract(ctx) -> (ours in words, value)``, or a string: why ours is not computed.
    rule : callable
        ``rule(value) -> "yes" | "no" | "partly" | "n/a"``.
    stable : bool
        False for claims read from timings.
    """

    id: str
    text: str
    paper: str
    extract: Callable = field(repr=False)
    rule: Callable = field(repr=False)
    evidence: str
    stable: bool = True

    def row(self, ctx) -> dict:
        got = self.extract(ctx)
        if isinstance(got, str):
            ours, holds = f"not computed ({got})", "n/a"
        else:
            ours, holds = got[0], self.rule(got[1])
        return dict(id=self.id, claim=self.text, paper=self.paper, ours=ours, holds=holds,
                    evidence=self.evidence, stable=self.stable)  # fmt: skip


def _table1_rule(best):
    b120, b60 = best
    hits = (b120 == N.BEST_WINDOW[120]) + (b60 == N.BEST_WINDOW[60])
    return "yes" if hits == 2 else "partly" if (hits == 1 or b60 < b120) else "no"


def _each_of(verdicts):
    if all(v == "yes" for v in verdicts):
        return "yes"
    return "no" if all(v == "no" for v in verdicts) else "partly"


_SCORES = "Figs. 5, 6; fig5_similarity_summary, fig6_deviation_summary"
_FIG8_BELOW = [n for n, v in N.FIG8_DEVIATIONS.items() if v < N.DEVIATION_BENCHMARK_FRAMES]

#: The claims, in table order.
CLAIMS = [
    Claim("1", "Without a constraint, Mc w40 is the only FP-DTW algorithm whose median passes a "
          "benchmark (similarity above UTW's median or deviation below 18 frames)",
          _names(N.PASS_EITHER_UNCONSTRAINED), _pass_either,
          lambda v: compare_sets(N.PASS_EITHER_UNCONSTRAINED, v), _SCORES),
    Claim("2", "Ma + Type V, Mc w40 and Mc w80 + Type V pass both benchmarks",
          ", ".join(N.PASS_BOTH), _pass_both, lambda v: compare_sets(N.PASS_BOTH, v), _SCORES),
    Claim("3", "Method C's best window (median similarity) moves from 40 at 120 Hz to 20 at 60 Hz",
          f"best w: {N.BEST_WINDOW[120]} at 120 Hz, {N.BEST_WINDOW[60]} at 60 Hz (Table 1)",
          _best_window, _table1_rule, "Table 1; table1_method_c_60_120hz"),
    Claim("4", "Per-frame cost grows steeply with the window w (Methods B and C: median time per "
          "frame increasing at every step, w80/w10 ratio >= 8)",
          "w80/w10: " + ", ".join(
              f"M{m.lower()} {N.TABLE2_US[(m, 80)] / N.TABLE2_US[(m, 10)]:.1f}x" for m in "BC"
          ) + " (Table 2, means)",
          _growth, _each_of, "Table 2; table2_time_per_frame, table2_time_vs_w", stable=False),
    Claim("4b", "A window of 80 is not feasible at 120 Hz (mean per-frame time above 8333 us)",
          f"Mb w80 {N.TABLE2_US[('B', 80)]:.0f} us, Mc w80 {N.TABLE2_US[('C', 80)]:.0f} us",
          _w80_budget, lambda over: ("no", "partly", "yes")[over],
          "Table 2; table2_time_per_frame", stable=False),
    Claim("4c", "Mc w80 runs out of input frames early (the reason for its low time): it has the "
          "largest fraction of target frames processed with the input exhausted among the "
          "unconstrained B and C algorithms",
          "Mc w80 runs out of input early (Section 5, no number)", _runs_out,
          lambda top: "yes" if top else "no", "table2_time_per_frame (exhausted_fraction)"),
    Claim("5", "Without a constraint, Ma is among the worst FP-DTW algorithms in both tests "
          "(bottom third: rank 7-9 of 9)", "one of the worst in both tests", _ma_worst,
          lambda hits: _share(hits, 2), _SCORES),
    Claim("5b", "Method B improves as the window grows (median similarity up and median "
          "deviation down at every step w10 -> w80)",
          "Method B improves with w; Method C peaks at w40 (Section 5)", _mb_grows,
          lambda hits: _share(hits, 2), _SCORES),
    Claim("6", "The Type V constraint improves every Method A and B algorithm but, of Method C, "
          "only Mc w80 (improved: median similarity higher AND median deviation lower)",
          "improved: " + _names(N.TYPEV_IMPROVED), _typev_improves,
          lambda v: compare_sets(N.TYPEV_IMPROVED, v),
          "Figs. 5, 6 (with/without Type V); fig5/fig6 summaries"),
    Claim("7", "OE-DTW's end points move backwards between consecutive target frames",
          f"yes (Fig. 1: one example, frames {N.FIG1_FRAMES[0]} -> {N.FIG1_FRAMES[1]})",
          _oedtw_backward, lambda some: "yes" if some else "no",
          "Fig. 1 (02_fig1_oedtw); OE-DTW maps"),
    Claim("8", "On the walk pair of Fig. 8, the deviations from DTW of Mb w80, Mc w20, Mc w40, "
          "Mc w80 are 8, 177, 62, 6 frames: below 18 only for Mb w80 and Mc w80 by these numbers "
          "(the paper's text names Mb w80 and Mc w40, contradicting its own numbers)",
          ", ".join(f"{k} {v:.0f}" for k, v in N.FIG8_DEVIATIONS.items()), _fig8,
          lambda v: compare_sets(_FIG8_BELOW, v), f"Fig. 8 (10_fig8_walk_pair); {FIG8_JSON}"),
    Claim("9", "The data: the paper's motions, movements and ordered pairs",
          f"{N.DATA['motions']} motions, {N.DATA['movements']} movements, {N.DATA['pairs']} pairs",
          _data, lambda t: "yes" if t == tuple(N.DATA.values()) else "no",
          "pairs.json; 05_run_experiments"),
    Claim("P1", "OPW poster: over the three motions (offset 0.25 s, gamma 5 %), OPW's mean "
          "deviation from the example warp curve is 69-79 ms and its maximum 121 ms, below the "
          "150 ms perceptual threshold",
          "mean {:.0f}-{:.0f} ms, max {:.0f} ms".format(*N.OPW_MEAN_DEVIATION_MS,
                                                        N.OPW_MAX_DEVIATION_MS),
          _opw_mean, lambda v: "yes" if all(v) else "partly" if v[1] else "no",
          f"poster Fig. 4 (13_opw_fig4); {OPW_FIG4_JSON}"),
    Claim("P2", "OPW poster: with gamma 5 %, OPW consistently removes about 70 % of the temporal "
          "difference between the motions, over the offsets of Fig. 5 (ours: within 10 "
          "percentage points, mean over offsets)", f"about {100 * N.OPW_REMOVED_GAMMA5:.0f} %",
          _opw_removed, lambda ok: "yes" if ok else "no",
          f"poster Fig. 5 (14_opw_fig5_fig6); {OPW_FIG56_JSON}"),
    Claim("P3", "OPW poster: OPW does best with gamma = 15 %, removing about 77 % of the temporal "
          "difference (ours: best gamma within 5 points, removed share within 10 points)",
          f"gamma {100 * N.OPW_BEST_GAMMA:.0f} %, about {100 * N.OPW_REMOVED_BEST_GAMMA:.0f} %",
          _opw_best_gamma, lambda hits: _share(hits, 2),
          f"poster Fig. 6 (14_opw_fig5_fig6); {OPW_FIG56_JSON}"),
    Claim("P4", "OPW poster: OPW copes with a temporal difference of 300 ms in 2500 ms motions "
          "(maximum deviation below 150 ms), and up to 500 ms judged by the mean",
          f"{1000 * N.OPW_OFFSET_MAX_OK_S:.0f} ms (max), {1000 * N.OPW_OFFSET_MEAN_OK_S:.0f} ms "
          "(mean)", _opw_offset, lambda hits: _share(hits, 2),
          f"poster Fig. 5 (14_opw_fig5_fig6); {OPW_FIG56_JSON}"),
    Claim("B1", "Beyond the papers: the OPW poster's method and Dixon's OLTW (the FP-DTW paper's "
          "ref. 3) run on the FP-DTW pairs, against the same two benchmarks",
          "not in the papers", _beyond, lambda _: "n/a", "Figs. 5, 6, 7; " + _SCORES[12:]),
]  # fmt: skip


def build_claims(mode="full", results=None, claims=None, context=None) -> list[dict]:
    """Check every claim against our results, under Method C's default and literal windows.

    Parameters
    ----------
    mode : {"full", "smoke"}
    results : fpdtw.paper.runner.Results, optional
        Default ``load_results(mode)``.
    claims : sequence of Claim, optional
        Default :data:`CLAIMS`.
    context : ClaimContext, optional
        Precomputed context (then ``results`` is not read; the literal columns repeat it).

    Returns
    -------
    rows : list of dict
        Keys :data:`COLUMNS`: ``id``, ``claim``, ``paper``, ``ours``, ``holds`` ("yes", "no",
        "partly", "n/a"), the same two under Method C's literal window (``ours_literal``,
        ``holds_literal``), ``evidence``, ``stable`` (False: computed from timings).

    Paper: FP-DTW Sections 5-7; OPW poster Section 5.
    Notebook: 12_claims.ipynb
    """
    if context is None:
        if results is None:
            from fpdtw.paper.runner import load_results

            results = load_results(mode)
        contexts = {
            suffix: ClaimContext.from_results(results, mode, reading=reading)
            for suffix, reading in READINGS.items()
        }
    else:
        contexts = {suffix: context for suffix in READINGS}
    return _evaluate(CLAIMS if claims is None else claims, contexts)


def _evaluate(claims, contexts) -> list[dict]:
    """Rows of :data:`COLUMNS` for ``claims``; ``contexts``: column suffix -> context."""
    rows = []
    for claim in claims:
        row = claim.row(contexts[""])
        for suffix, ctx in contexts.items():
            if suffix:
                other = claim.row(ctx)
                row[f"ours{suffix}"] = other["ours"]
                row[f"holds{suffix}"] = other["holds"]
        rows.append({c: row[c] for c in COLUMNS})
    return rows


def claims_by_id(ids, claims=None) -> list:
    """The :class:`Claim` objects of ``ids``, in that order (KeyError names an unknown id)."""
    by = {c.id: c for c in (CLAIMS if claims is None else claims)}
    missing = [i for i in ids if str(i) not in by]
    if missing:
        raise KeyError(f"no claims {missing} in the table (ids: {', '.join(by)})")
    return [by[str(i)] for i in ids]


def claim_rows(ids, mode="full", results=None, *, rows=None, facts=None) -> list[dict]:
    """The rows of the claims table that a notebook is evidence for, in the order of ``ids``.

    The companion notebooks print these right after their figure
    (:func:`format_claims`), so that each figure is followed by what the paper claims
    from it, our value and whether the claim holds here, decided by the same rules as
    ``figures/claims.md`` (notebook 12).

    Parameters
    ----------
    ids : sequence of str
        Claim ids of :data:`CLAIMS`, e.g. ``["1", "2"]`` (KeyError for an unknown id).
    mode : {"full", "smoke"}
    results : fpdtw.paper.runner.Results, optional
        The experiment results to evaluate the claims on (default: ``load_results(mode)``,
        unless ``rows`` or ``facts`` is given).
    rows : list of dict, optional
        A claims table already built (:func:`build_claims`): its rows are picked.
    facts : dict, optional
        A notebook's own facts instead of results (:meth:`ClaimContext.from_facts`): the
        claims are evaluated on them under each reading of :data:`READINGS`.

    Returns
    -------
    rows : list of dict
        Keys :data:`COLUMNS`, one row per id.

    Paper: FP-DTW Sections 5-7; OPW poster Section 5.
    Notebook: 06_fig5_fig6_scores.ipynb (and every notebook that checks a claim)
    """
    ids = [str(i) for i in ids]
    if sum(x is not None for x in (results, rows, facts)) > 1:
        raise ValueError("give at most one of results, rows and facts")
    if rows is not None:
        by = {r["id"]: r for r in rows}
        missing = [i for i in ids if i not in by]
        if missing:
            raise KeyError(f"no rows {missing} in the claims table given")
        return [by[i] for i in ids]
    subset = claims_by_id(ids)
    if facts is not None:
        contexts = {
            suffix: ClaimContext.from_facts(mode, reading, **dict(facts))
            for suffix, reading in READINGS.items()
        }
        return _evaluate(subset, contexts)
    return build_claims(mode, results, claims=subset)


def format_claims(rows, stable=None, width: int = 96) -> str:
    """The claims as text: the claim, then "paper", "ours" and "holds?" on their own lines.

    Under Method C's literal window (``ours_literal``, ``holds_literal``) a line is added
    only where it differs from the default window's. Deterministic for deterministic rows,
    so a notebook cell printing it can be compared by nbval.

    Parameters
    ----------
    rows : list of dict
        From :func:`claim_rows` or :func:`build_claims`.
    stable : bool, optional
        True: only the deterministic rows; False: only the timing rows; None: all.
    width : int
        Line width the claim text is wrapped to.

    Returns
    -------
    text : str

    Notebook: 06_fig5_fig6_scores.ipynb (and every notebook that checks a claim)
    """
    import textwrap

    out = []
    for r in rows:
        if stable is not None and bool(r.get("stable", True)) != stable:
            continue
        head = textwrap.fill(f"[{r['id']}] {r['claim']}", width, subsequent_indent="    ")
        lines = [head]
        for label, key in (("paper: ", "paper"), ("ours:  ", "ours"), ("holds? ", "holds")):
            lines.append(
                textwrap.fill(
                    str(r[key]), width, initial_indent="    " + label, subsequent_indent=" " * 11
                )
            )
        lit = [s for s in READINGS if s]
        for s in lit:
            if f"ours{s}" in r and (r[f"ours{s}"], r[f"holds{s}"]) != (r["ours"], r["holds"]):
                lines.append(
                    textwrap.fill(
                        f"{r[f'ours{s}']}; holds? {r[f'holds{s}']}",
                        width,
                        initial_indent=f"    with Method C's {READINGS[s]} window: ",
                        subsequent_indent=" " * 11,
                    )
                )
        out.append("\n".join(lines))
    return "\n".join(out) if out else "(no claims)"


def claims_summary(rows) -> str:
    """How many claims hold: counts of "yes", "partly", "no", "n/a" per reading of Method C.

    Returns
    -------
    text : str
        One line per reading, e.g. ``"square window: yes 6, partly 5, no 2, n/a 1"``.

    Notebook: 12_claims.ipynb
    """
    lines = []
    for suffix, reading in READINGS.items():
        counts = {v: 0 for v in ("yes", "partly", "no", "n/a")}
        for r in rows:
            counts[r[f"holds{suffix}"]] = counts.get(r[f"holds{suffix}"], 0) + 1
        lines.append(
            f"{reading} window: "
            + ", ".join(f"{k} {v}" for k, v in counts.items())
            + f" (of {len(rows)} claims)"
        )
    return "\n".join(lines)


def save_claims(rows, mode="full"):
    """Write the claims as ``claims.csv|md`` (figures folder) and ``results/<mode>/claims.json``.

    Returns
    -------
    paths : list of Path

    Notebook: 12_claims.ipynb
    """
    from fpdtw.paper.figures.tables import save_table
    from fpdtw.paper.paths import results_dir
    from fpdtw.paper.provenance import versions_line

    note = (
        f"Computed with {versions_line()}. The commit and the machine that made these "
        "figures: ENVIRONMENT.md."
    )
    out = list(save_table(rows, "claims", columns=COLUMNS, note=note))
    text = json.dumps({"mode": mode, "claims": rows}, indent=1) + "\n"
    out.append(write_atomic(results_dir() / mode / "claims.json", text.encode()))
    return out


__all__ = [
    "CLAIMS",
    "COLUMNS",
    "Claim",
    "ClaimContext",
    "build_claims",
    "claim_rows",
    "claims_by_id",
    "claims_summary",
    "compare_sets",
    "data_counts",
    "format_claims",
    "oedtw_backward_jumps",
    "reading_alias",
    "save_claims",
]
