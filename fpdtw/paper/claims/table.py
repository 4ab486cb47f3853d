"""The papers' claims, each split into parts, checked against our results.

Each claim of :data:`CLAIMS` is a row of data: its id, the claim in words, the paper's value
(from :mod:`fpdtw.paper.numbers`) and an *assessment* that reads our results from a
:class:`ClaimContext` and returns our value in words and the claim's **parts**: atomic
statements, each decided by a check (a number with its 95 % interval against a threshold)
or marked not comparable. The rules that turn parts into verdicts live in one module,
:mod:`fpdtw.paper.claims.rules`; the intervals come from :mod:`fpdtw.paper.claims.bootstrap`.

:func:`build_claims` evaluates every claim on several bodies of evidence and returns one
row per claim (:data:`COLUMNS`):

* ``holds`` and ``reason``: on all pairs, intervals resampling movements and motions;
* ``holds_same_movements``: the same with only the motions resampled (these movements,
  other takes: narrower intervals);
* ``holds_authors_fbx``, ``holds_hdm05``: on one dataset's pairs alone;
* ``holds_paper_shaped``: on the paper-shaped selection (notebook 15: at most 8 takes per
  movement);
* ``robustness``: under how many of the documented readings and silent choices the verdict
  stands (:mod:`fpdtw.paper.claims.robustness`);
* ``ours_literal``, ``holds_literal``: with Method C's literal window;
* ``ours_plugin``, ``holds_plugin``: the OPW poster's claims with OPW read as the authors'
  MotionBuilder plugin does it (:data:`fpdtw.paper.opw_eval.READINGS`; "n/a" for the FP-DTW
  claims).

:func:`part_rows` gives one row per part (``figures/claims_intervals.csv``).

Rows carry ``stable``: False for the claims computed from timings (``make bench``:
measurements that change between runs); all other rows are deterministic.

Paper: FP-DTW Sections 5-7; OPW poster Section 5.
Notebook: 12_claims.ipynb
"""

from __future__ import annotations

import json
from collections.abc import Callable
from dataclasses import dataclass, field, replace

import numpy as np

from fpdtw.paper import numbers as N
from fpdtw.paper.atomic import write_atomic
from fpdtw.paper.claims import open as _open
from fpdtw.paper.claims import rules as R
from fpdtw.paper.claims.evidence import Evidence
from fpdtw.paper.claims.rules import AllOf, Check, Not, Part
from fpdtw.paper.numbers import FPDTW_NAMES, FPDTW_TYPEV_NAMES, TYPE_V, WINDOWS
from fpdtw.paper.runner.results import EQ2_READINGS, STORED_EQ2

#: Name of the Fig. 8 notebook's JSON under ``results/<mode>/figs/``.
FIG8_JSON = "10_fig8_walk_pair.json"
OPW_FIG4_JSON = "13_opw_fig4.json"
OPW_FIG56_JSON = "14_opw_fig5_fig6.json"

#: The bodies of evidence a claim is decided on besides all pairs: column suffix -> label.
DATASETS = ("authors_fbx", "hdm05")
#: Columns of the claims table.
COLUMNS = ("id", "claim", "short", "paper", "ours", "holds", "reason", "interval",
           "holds_same_movements", "holds_authors_fbx", "holds_hdm05", "holds_paper_shaped",
           "robustness", "ours_literal", "holds_literal", "ours_plugin", "holds_plugin",
           "holds_seed2", "eq2_other", "holds_eq2_other", "holds_eq2_other_authors_fbx",
           "holds_eq2_other_hdm05", "holds_eq2_other_paper_shaped", "evidence",
           "stable")  # fmt: skip
#: Columns of the parts table (``claims_intervals.csv``).
PART_COLUMNS = ("claim", "part", "text", "verdict", "formula", "checks", "quantity", "estimate",
                "ci_low", "ci_high", "threshold", "mc_margin", "verdict_seed2",
                "verdict_same_movements", "verdict_authors_fbx", "verdict_hdm05",
                "verdict_paper_shaped", "verdict_literal", "verdict_plugin",
                "verdict_eq2_other")  # fmt: skip
#: Columns of the checks table (``claims_checks.csv``): every check behind every part, on
#: every body of evidence (:data:`BODIES`).
CHECK_COLUMNS = ("body", "claim", "part", "formula", "check", "quantity", "estimate", "low",
                 "high", "low_se", "high_se", "threshold", "relation", "interval",
                 "verdict")  # fmt: skip
#: Every body of evidence a part is decided on: ``"all"`` (the headline), the second seed,
#: the other bodies, Method C's literal window and OPW's plugin reading.
BODIES = ("all", "seed2", "same_movements", "authors_fbx", "hdm05", "paper_shaped", "literal",
          "plugin", "eq2_other", "eq2_other_authors_fbx", "eq2_other_hdm05",
          "eq2_other_paper_shaped")  # fmt: skip
#: The bodies under the other reading of eq. 2 (:func:`other_eq2`), as keys of
#: :func:`claim_contexts`.
EQ2_OTHER = ("eq2_other", "eq2_other_authors_fbx", "eq2_other_hdm05", "eq2_other_paper_shaped")
#: The second bootstrap seed's offset from :data:`fpdtw.paper.claims.bootstrap.SEED`.
SEED2_OFFSET = 1
#: Method C's readings the claims table is evaluated under: column suffix -> reading.
READINGS = {"": "square", "_literal": "literal"}
#: The other bodies of evidence, as column suffixes of ``holds``.
OTHER_EVIDENCE = ("same_movements", "authors_fbx", "hdm05", "paper_shaped")
#: OPW's other reading: the OPW notebooks' facts hold it under ``readings`` -> this name.
OPW_PLUGIN = "plugin"


@dataclass
class Assessment:
    """Our value of a claim in words and its parts."""

    ours: str
    parts: list


@dataclass
class ClaimContext:
    """Everything the claims read: the evidence of the pairs and the notebooks' facts.

    Attributes
    ----------
    mode : str
        ``"full"`` or ``"smoke"``.
    ev : Evidence or None
        Per-pair values, medians and bootstrap intervals (None: no experiment results).
    timing : list of dict or None
        :func:`fpdtw.paper.figures.timing.time_per_frame_rows` of ``make bench``'s report.
    fig8 : dict or None
        The Fig. 8 notebook's JSON.
    opw_fig4, opw_fig56 : dict or None
        The OPW notebooks' JSON (13_opw_fig4, 14_opw_fig5_fig6).
    counts : dict or None
        Our data: ``motions``, ``movements``, ``pairs`` (and per dataset).
    alias : dict
        Method C's reading (:func:`reading_alias`): the timing rows and Fig. 8 deviations of
        that reading stand for the paper's names (:meth:`timing_rows`, :meth:`fig8_devs`).
    open_ev : Evidence or None
        The open run's evidence (:func:`fpdtw.paper.claims.open.open_evidence`), read by the
        questions beyond the papers (Q rows); None: they are "not computed".
    plain : list of dict or None
        ``make bench``'s times of the plain NumPy steps (``results/bench.json`` -> ``plain``:
        rows with ``name``, ``method``, ``w``, ``mean_us``): the paper's implementation
        without further optimisation, for claim 4b.
    bench : dict or None
        ``make bench``'s report (``results/bench.json``) as it is, for what Q3 reads of it
        (:func:`fpdtw.paper.figures.timing.band_cost`); None without one.
    """

    mode: str = "full"
    ev: Evidence | None = None
    timing: list | None = None
    fig8: dict | None = None
    opw_fig4: dict | None = None
    opw_fig56: dict | None = None
    counts: dict | None = None
    alias: dict = field(default_factory=dict)
    open_ev: Evidence | None = None
    plain: list | None = None
    bench: dict | None = None

    def with_evidence(self, ev) -> ClaimContext:
        return replace(self, ev=ev)

    def timing_rows(self) -> list | None:
        """The timing rows under this context's reading (None without timings)."""
        return _alias_timing(self.timing, self.alias) if self.timing else None

    def fig8_devs(self) -> dict | None:
        """The Fig. 8 deviations under this context's reading."""
        return _fig8_deviations(_alias_fig8(self.fig8, self.alias))

    @classmethod
    def from_results(
        cls, results, mode="full", fig8_path=None, reading="square", scheme="movements", **evidence
    ) -> ClaimContext:
        """The context of a run (:func:`fpdtw.paper.runner.run.load_results`).

        ``reading`` chooses Method C's reading of Algorithm 3: with ``"literal"`` every Mc
        name (``"Mc w40"``, ``"Mc w80 + Type V"``, ``"Mc w20@60Hz"``) stands for the
        results of that reading (``"Mc w40 (literal window)"``, ...).
        """
        from fpdtw.paper.claims.open import open_evidence
        from fpdtw.paper.figures.timing import TIMED_NAMES, load_bench, time_per_frame_rows
        from fpdtw.paper.paths import results_dir

        alias = reading_alias(reading)
        ev = Evidence(results, scheme=scheme, alias=alias, **evidence)
        bench = load_bench()
        timing = plain = None
        if bench is not None:
            timing = time_per_frame_rows(bench, names=list(TIMED_NAMES)) or None
            plain = bench.get("plain") or None
        figs = results_dir() / mode / "figs"
        return cls(
            mode=mode,
            ev=ev,
            timing=timing,
            fig8=_read_json(figs / FIG8_JSON if fig8_path is None else fig8_path),
            alias=alias,
            opw_fig4=_read_json(figs / OPW_FIG4_JSON),
            opw_fig56=_read_json(figs / OPW_FIG56_JSON),
            counts=getattr(results, "counts", None) or data_counts(results.pairs),
            open_ev=open_evidence(mode),
            plain=plain,
            bench=bench,
        )

    @classmethod
    def from_facts(cls, mode="full", reading="square", **facts) -> ClaimContext:
        """A context holding only a notebook's own facts (no experiment results).

        For notebooks that check a claim from what they computed themselves: the walk pair
        (``fig8``), the OPW poster's figures (``opw_fig4``, ``opw_fig56``), the data
        (``counts``, as :func:`data_counts`) or the timings (``timing``: rows of
        :func:`fpdtw.paper.figures.timing.time_per_frame_rows`, which may hold Method C's
        other readings too). Claims that need the pairs come out "not computed".

        Paper: FP-DTW Sections 5-7; OPW poster Section 5.
        """
        allowed = {"fig8", "opw_fig4", "opw_fig56", "counts", "timing", "plain"}
        unknown = set(facts) - allowed
        if unknown:
            raise TypeError(f"unknown facts {sorted(unknown)}; allowed: {sorted(allowed)}")
        return cls(mode=mode, alias=reading_alias(reading), **facts)


def opw_reading(ctx, reading: str = OPW_PLUGIN):
    """The context with the OPW notebooks' facts of another reading of OPW, or None.

    The OPW notebooks store each other reading's facts under ``readings`` -> name in their
    JSON (``13_opw_fig4.json``, ``14_opw_fig5_fig6.json``); None when neither holds it.

    Paper: OPW poster Section 5; the authors' MotionBuilder plugin.
    """

    def sub(d):
        return ((d or {}).get("readings") or {}).get(reading)

    fig4, fig56 = sub(ctx.opw_fig4), sub(ctx.opw_fig56)
    if fig4 is None and fig56 is None:
        return None
    return replace(ctx, opw_fig4=fig4, opw_fig56=fig56)


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
    return None


def _names(xs) -> str:
    return ", ".join(xs) if xs else "none"


# -- assessments: our value and the parts of each claim ------------------------------------------
# Each returns an Assessment, or a string: why the claim could not be computed.


def _need(ctx, *names):
    """None when the context has every name's results, else why not."""
    if ctx.ev is None:
        return "no experiment results"
    missing = [n for n in names if not ctx.ev.has(n)]
    return f"no results for {', '.join(missing)}" if missing else None


def _point_pass(ev, name, metric) -> bool:
    """Passes by the medians alone (what the paper's figures show), without intervals."""
    c = ev.passes(name, metric)
    return c.estimate > c.threshold if c.above else c.estimate < c.threshold


def _claim1(ctx):
    names = list(FPDTW_NAMES)
    if why := _need(ctx, "UTW", *names):
        return why
    ev = ctx.ev
    by_median = [
        n for n in names if _point_pass(ev, n, "similarity") or _point_pass(ev, n, "deviation")
    ]  # noqa: E501
    named = list(N.PASS_EITHER_UNCONSTRAINED)
    parts = [Part(f"{n} passes a benchmark", ev.passes_either(n)) for n in named]
    others = [n for n in names if n not in named]
    parts.append(
        Part(
            "no other unconstrained FP-DTW algorithm passes one",
            AllOf(*[Not(ev.passes_either(n)) for n in others]),
        )
    )
    return Assessment(f"pass either (by medians): {_names(by_median)}", parts)


def _claim2(ctx):
    names = list(N.PASS_BOTH)
    if why := _need(ctx, "UTW", *names):
        return why
    ev = ctx.ev
    by_median = [n for n in names if _both_by_median(ev, n)]
    parts = [Part(f"{n} passes both benchmarks", ev.passes_both(n)) for n in names]
    return Assessment(f"pass both (by medians): {_names(by_median)}", parts)


def _both_by_median(ev, name) -> bool:
    return _point_pass(ev, name, "similarity") and _point_pass(ev, name, "deviation")


def _claim2b(ctx):
    names = list(FPDTW_NAMES + FPDTW_TYPEV_NAMES)
    if why := _need(ctx, "UTW", *names):
        return why
    ev = ctx.ev
    others = [n for n in names if n not in N.PASS_BOTH]
    by_median = [n for n in others if _both_by_median(ev, n)]
    part = Part(
        "no FP-DTW algorithm other than the three named passes both benchmarks",
        AllOf(*[Not(ev.passes_both(n)) for n in others]),
    )
    return Assessment(f"others passing both (by medians): {_names(by_median)}", [part])


def best_window_test(ev, rate):
    """The paper's best window of Method C at ``rate`` beats every other window: its median
    similarity minus each other's, on the same pairs, above 0 (Table 1).
    """
    best = N.BEST_WINDOW[rate]
    sfx = "" if rate == 120 else "@60Hz"
    others = [w for w in WINDOWS if w != best]
    return AllOf(*[ev.better(f"Mc w{best}{sfx}", f"Mc w{w}{sfx}", "similarity") for w in others])


def _best_part(ev, rate):
    best = N.BEST_WINDOW[rate]
    return Part(f"at {rate} Hz Mc w{best} has the highest median similarity",
                best_window_test(ev, rate))  # fmt: skip


def _claim3(ctx):
    names = [f"Mc w{w}{s}" for w in WINDOWS for s in ("", "@60Hz")]
    if why := _need(ctx, *names):
        return why
    ev = ctx.ev
    best = {}
    for rate, sfx in ((120, ""), (60, "@60Hz")):
        med = {w: ev.median(f"Mc w{w}{sfx}", "similarity") for w in WINDOWS}
        best[rate] = max(WINDOWS, key=lambda w: (med[w], -w))
    ours = f"best w (by medians): {best[120]} at 120 Hz, {best[60]} at 60 Hz"
    return Assessment(ours, [_best_part(ev, 120), _best_part(ev, 60)])


def _timing_by(ctx):
    return {(r["method"], r["w"]): r for r in ctx.timing_rows() if not r["type_v"]}


def _claim4(ctx):
    from fpdtw.paper.figures.timing import growth_ratio

    if not ctx.timing_rows():
        return "no timings"
    by = _timing_by(ctx)
    parts, words = [], []
    for m in ("B", "C"):
        if not all((m, w) in by for w in WINDOWS):
            return f"Method {m} not timed at every w"
        t = [by[(m, w)]["median_us"] for w in WINDOWS]
        steps = [
            Check(
                f"median us of M{m.lower()} w{b} minus w{a}",
                t[i + 1] - t[i],
                threshold=0.0,
                interval=False,
                signed=True,
                digits=1,
            )
            for i, (a, b) in enumerate(zip(WINDOWS, WINDOWS[1:]))
        ]
        ratio = growth_ratio(ctx.timing_rows(), m, key="median_us")
        parts.append(
            Part(f"Method {m}'s median time per frame grows at every window step", AllOf(*steps))
        )
        parts.append(
            Part(
                f"Method {m}'s w80/w10 time ratio is at least 8",
                Check(
                    f"M{m.lower()} w80/w10 median time ratio",
                    ratio,
                    threshold=8.0,
                    interval=False,
                    digits=1,
                    strict=False,
                ),
            )
        )
        mean = growth_ratio(ctx.timing_rows(), m, key="mean_us")
        words.append(f"M{m.lower()} {ratio:.1f}x (means {mean:.1f}x)")
    return Assessment("w80/w10 (medians): " + ", ".join(words), parts)


def _claim4b(ctx):
    plain = {(r["method"], int(r["w"])): r for r in (ctx.plain or [])}
    if ("B", 80) not in plain or ("C", 80) not in plain:
        return "no times of the plain (unoptimised) steps: make bench"
    parts = [
        Part(
            f"without further optimisation, M{m.lower()} w80's mean time per frame is above "
            "the 120 Hz budget",
            Check(
                f"M{m.lower()} w80 plain NumPy step, mean us per frame",
                plain[(m, 80)]["mean_us"],
                threshold=N.BUDGET_120HZ_US,
                interval=False,
                digits=0,
            ),
            note=f"the paper's: {N.TABLE2_US[(m, 80)]:.0f} us on its machine",
        )
        for m in ("B", "C")
    ]
    ours = "unoptimised (plain NumPy): " + ", ".join(
        f"M{m.lower()} w80 {plain[(m, 80)]['mean_us']:.0f} us" for m in "BC"
    )
    by = _timing_by(ctx) if ctx.timing_rows() else {}
    if ("B", 80) in by and ("C", 80) in by:
        ours += "; compiled kernels (our finding, not the claim): " + ", ".join(
            f"M{m.lower()} w80 {by[(m, 80)]['mean_us']:.0f} us" for m in "BC"
        )
    return Assessment(ours + " (this machine; budget 8333 us)", parts)


def _claim4c(ctx):
    cand = [n for n in FPDTW_NAMES if n != "Ma"]
    if why := _need(ctx, *cand):
        return why
    ev = ctx.ev
    counts = {n: ev.exhausted_counts(n) for n in cand}
    share = {n: c[0].sum() / c[1].sum() for n, c in counts.items()}
    top = max(cand, key=lambda n: share[n])
    tests = [
        ev.share_difference(f"exhausted share of Mc w80 minus {n}", counts["Mc w80"], counts[n])
        for n in cand
        if n != "Mc w80"
    ]
    ours = (
        f"Mc w80 {share['Mc w80']:.2f} of frames (Mc w40 {share['Mc w40']:.2f}, "
        f"Mb w80 {share['Mb w80']:.2f}); largest: {top}"
    )
    part = Part(
        "Mc w80 has the largest share of target frames processed with the input "
        "exhausted (unconstrained B and C)",
        AllOf(*tests),
    )
    return Assessment(ours, [part])


def _claim5(ctx):
    names = list(FPDTW_NAMES)
    if why := _need(ctx, *names):
        return why
    ev = ctx.ev
    cut = len(names) - len(names) // 3 + 1  # 9 algorithms: rank 7 or worse
    parts, words = [], []
    for metric in ("similarity", "deviation"):
        c = ev.rank("Ma", names, metric, cut)
        parts.append(Part(f"Ma ranks {cut}-{len(names)} of {len(names)} by median {metric}", c))
        words.append(f"{c.estimate:.0f} of {len(names)} ({metric})")
    return Assessment("Ma ranks " + ", ".join(words), parts)


def _claim5b(ctx):
    names = [f"Mb w{w}" for w in WINDOWS]
    if why := _need(ctx, *names):
        return why
    ev = ctx.ev
    parts = []
    for metric, verb in (("similarity", "rises"), ("deviation", "falls")):
        tests = [ev.better(b, a, metric) for a, b in zip(names, names[1:])]
        parts.append(
            Part(f"Method B's median {metric} {verb} at every step w10 -> w80", AllOf(*tests))
        )
    s = " / ".join(f"{ev.median(n, 'similarity'):.3f}" for n in names)
    d = " / ".join(f"{ev.median(n, 'deviation'):.1f}" for n in names)
    return Assessment(f"similarity {s}; deviation {d}", parts)


def _improves(ev, base):
    return AllOf(
        ev.better(base + TYPE_V, base, "similarity"), ev.better(base + TYPE_V, base, "deviation")
    )


def _claim6(ctx):
    if why := _need(ctx, *FPDTW_NAMES, *FPDTW_TYPEV_NAMES):
        return why
    ev = ctx.ev
    ab = [n for n in FPDTW_NAMES if not n.startswith("Mc")]
    c_yes = [n for n in N.TYPEV_IMPROVED if n.startswith("Mc")]
    c_no = [n for n in FPDTW_NAMES if n.startswith("Mc") and n not in c_yes]
    parts = [
        Part(
            "Type V improves every Method A and B algorithm (median similarity up and median "
            "deviation down)",
            AllOf(*[_improves(ev, n) for n in ab]),
        ),
        *[Part(f"Type V improves {n}", _improves(ev, n)) for n in c_yes],
        Part(
            f"Type V does not improve {', '.join(c_no)}",
            AllOf(*[Not(_improves(ev, n)) for n in c_no]),
        ),
    ]
    both = [
        n
        for n in FPDTW_NAMES
        if ev.median(n + TYPE_V, "similarity") > ev.median(n, "similarity")
        and ev.median(n + TYPE_V, "deviation") < ev.median(n, "deviation")
    ]
    return Assessment(f"improved (by medians): {_names(both)}", parts)


def _claim7(ctx):
    if why := _need(ctx, "OE-DTW"):
        return why
    ev = ctx.ev
    back = ev.backward_jumps("OE-DTW")
    c = ev.share(
        "share of pairs whose OE-DTW end point moves backwards", back, np.ones_like(back), 0.0
    )
    ours = f"{int(back.sum())} of {back.size} pairs ({c.estimate:.0%}) have a backward jump"
    return Assessment(
        ours,
        [
            Part(
                "OE-DTW's end point moves backwards between consecutive "
                "target frames (in some pairs)",
                c,
            )
        ],
    )


_FIG8_BELOW = [n for n, v in N.FIG8_DEVIATIONS.items() if v < N.DEVIATION_BENCHMARK_FRAMES]
_FIG8_CONTRADICTION = (
    f"The paper's text names {' and '.join(N.FIG8_TEXT_BELOW_BENCHMARK)} as the ones below 18 "
    f"frames, but its own numbers put {' and '.join(_FIG8_BELOW)} below it "
    f"(Mc w40: {N.FIG8_DEVIATIONS['Mc w40']:.0f} frames)"
)


def _claim8(ctx):
    devs = ctx.fig8_devs()
    words = []
    if devs and all(n in devs for n in N.FIG8_DEVIATIONS):
        words.append(
            "our Fig. 8 pair (the authors' Walk_01 -> Walk_02): "
            + ", ".join(f"{n} {devs[n]:.1f}" for n in N.FIG8_DEVIATIONS)
        )
    ev = ctx.ev
    if ev is not None and ev.has(*N.FIG8_DEVIATIONS):
        walk = [
            i
            for i, r in enumerate(ev.rows)
            if ev.results.pairs[r]["dataset"] == "authors_fbx"
            and ev.results.pairs[r]["movement"] == "Walk"
        ]
        if walk:
            w = ev.restrict(np.array(walk), "the authors' walk pairs")
            words.append(
                f"median over our {len(walk)} walk pairs: "
                + ", ".join(f"{n} {w.median(n, 'deviation'):.1f}" for n in N.FIG8_DEVIATIONS)
            )
    if not words:
        return f"{FIG8_JSON} absent and no walk pairs"
    part = Part(
        "on the paper's walk pair the deviations of Mb w80, Mc w20, Mc w40, Mc w80 are "
        "8, 177, 62, 6 frames",
        None,
        note="the paper's pair is HDM05 sample 3239, WalkLeftCircle (so named in the "
        "authors' example videos); HDM05's walking classes are not available here, so "
        "no pair of ours can confirm or contradict its per-pair numbers",
    )
    return Assessment("; ".join(words), [part])


def _claim8b(ctx):
    counts = (ctx.fig8 or {}).get("statements")
    if not counts:
        return f"no walk-pair statements in {FIG8_JSON} (notebook 10)"
    parts, words = [], []
    for statement, c in counts.items():
        n, k = int(c["pairs"]), int(c["holds"])
        parts.append(Part(
            f"{statement}, on most of our walk pairs",
            Check(f"share of walk pairs where '{statement}' holds", k / n if n else float("nan"),
                  threshold=0.5, interval=False, digits=2),
            note="the rule of each statement: fpdtw.paper.figures.walk_pair.FIG8_STATEMENT_RULES",
        ))  # fmt: skip
        words.append(f"{statement}: {k} of {n}")
    return Assessment("walk pairs where it holds: " + ", ".join(words), parts)


def _claim9(ctx):
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
    part = Part(
        f"the evaluation used {N.DATA['motions']} motions of {N.DATA['movements']} "
        f"movements, {N.DATA['pairs']} ordered pairs",
        None,
        note="our data are what can be obtained (15 of the authors' takes and 5 HDM05 "
        "classes are not available; the paper's HDM05 selection is unpublished), so "
        "our counts say nothing about the paper's",
    )
    return Assessment(ours, [part])


_DATA_CONTRADICTION = (
    f"The paper's sources add up to {N.DATA_SOURCES['authors_fbx']} + {N.DATA_SOURCES['hdm05']} "
    f"= {sum(N.DATA_SOURCES.values())} motions, not {N.DATA['motions']}"
)


#: Why the OPW poster's claims are decided on our stand-in clips (all four alike).
STAND_IN = (
    "on stand-in clips (the poster's CMU two-person clips are not available): the poster's "
    "example warp curve is reproduced exactly and the poster says OPW performs consistently "
    "on different motions, so its levels are tested on other motions"
)


def example_base_ms(offset: float | None = None) -> float:
    """The example warp curve's mean ``|t - g(t)|`` in ms: the temporal difference that the
    removed share of :func:`fpdtw.paper.opw_eval.temporal_difference_removed` divides by.

    ``removed = 1 - mean deviation / base``, so a mean deviation fixes the removed share.

    Paper: OPW poster Section 5 (Figs. 4, 5).
    """
    from fpdtw.paper import opw_eval

    g = opw_eval.example_curve(offset=opw_eval.OFFSET if offset is None else offset)
    t = opw_eval.sample_times(g.x[-1], opw_eval.SAMPLE_RATE)
    return float(1000.0 * np.abs(t - g(t)).mean())


def _claim_p1(ctx):
    d = ctx.opw_fig4
    if d is None:
        return f"{OPW_FIG4_JSON} absent"
    (lo, hi), mx, (dlo, dhi) = d["opw_mean_ms_range"], d["opw_max_ms"], d["dtw_mean_ms_range"]
    base = d.get("baseline", "DTW")
    ours = f"mean {lo:.0f}-{hi:.0f} ms, max {mx:.0f} ms ({base} mean {dlo:.0f}-{dhi:.0f} ms)"
    pmin, pmax = N.OPW_MEAN_DEVIATION_MS
    parts = [
        Part(
            f"OPW's mean deviation is {pmin:.0f}-{pmax:.0f} ms on each of the three motions",
            AllOf(
                Check(
                    "smallest OPW mean deviation of a motion, ms",
                    lo,
                    threshold=pmin,
                    interval=False,
                    digits=0,
                    strict=False,
                ),
                Check(
                    "largest OPW mean deviation of a motion, ms",
                    hi,
                    threshold=pmax,
                    above=False,
                    interval=False,
                    digits=0,
                    strict=False,
                ),
            ),
            note=STAND_IN,
        ),  # fmt: skip
        Part(
            "OPW's maximum deviation is below the 150 ms perceptual threshold",
            Check(
                "OPW max deviation, ms",
                mx,
                threshold=N.PERCEPTUAL_THRESHOLD_MS,
                above=False,
                interval=False,
                digits=0,
            ),
            note=STAND_IN,
        ),
    ]
    return Assessment(ours, parts)


def _near(quantity, ours, paper, tol, digits=0, scale=100.0):
    """``|ours - paper| <= tol`` as a check (in percentage points when ``scale`` is 100)."""
    return Check(
        f"|{quantity} - {scale * paper:.0f}|",
        scale * abs(ours - paper),
        threshold=scale * tol,
        above=False,
        interval=False,
        digits=digits,
        strict=False,
    )


def _claim_p2(ctx):
    d = ctx.opw_fig56
    if d is None:
        return f"{OPW_FIG56_JSON} absent"
    mean = d["removed_gamma5_mean_over_offsets"]
    lo, hi = d["removed_gamma5_range_over_offsets"]
    ours = (
        f"{100 * mean:.0f} % on average ({100 * lo:.0f}-{100 * hi:.0f} % across offsets; "
        f"{100 * d['removed_gamma5_at_offset']:.0f} % at 0.25 s)"
    )
    per_offset = [r for r in d.get("fig5", []) if r.get("method") == "OPW"]
    target, tol = N.OPW_REMOVED_GAMMA5, 0.10
    base = example_base_ms()
    pmin, pmax = N.OPW_MEAN_DEVIATION_MS
    arithmetic = (
        f"removed = 1 - mean deviation / {base:.1f} ms at 0.25 s, so the poster's own "
        f"{pmin:.0f}-{pmax:.0f} ms (P1) means {100 * (1 - pmax / base):.0f}-"
        f"{100 * (1 - pmin / base):.0f} % removed there"
    )
    parts = [
        Part(
            "with gamma 5 % OPW removes about 70 % of the temporal difference (within 10 "
            "points, mean over offsets)",
            _near("removed share at gamma 5 %, points", mean, target, tol),
            note=STAND_IN,
        ),
        Part(
            "consistently: at every offset of Fig. 5 the removed share is within 10 points of 70 %",
            AllOf(
                *[
                    _near(
                        f"removed share at offset {r['offset_s']:.2f} s, points",
                        r["removed"],
                        target,
                        tol,
                    )
                    for r in per_offset
                ]
            )
            if per_offset
            else None,
            note=arithmetic if per_offset else "no per-offset rows in the facts",
        ),  # fmt: skip
    ]
    return Assessment(ours, parts)


def _claim_p3(ctx):
    d = ctx.opw_fig56
    if d is None:
        return f"{OPW_FIG56_JSON} absent"
    g, r = d["best_gamma"], d["removed_best_gamma"]
    parts = [
        Part(
            "the best gamma is 15 % (within 5 points)",
            _near("best gamma, points", g, N.OPW_BEST_GAMMA, 0.05),
            note=STAND_IN,
        ),
        Part(
            "it removes about 77 % (within 10 points)",
            _near("removed share at the best gamma, points", r, N.OPW_REMOVED_BEST_GAMMA, 0.10),
            note=STAND_IN,
        ),
    ]
    return Assessment(f"gamma {100 * g:.0f} %, {100 * r:.0f} % removed", parts)


def _claim_p4(ctx):
    d = ctx.opw_fig56
    if d is None:
        return f"{OPW_FIG56_JSON} absent"
    mx = d["largest_offset_max_below_150ms_s"]
    mean = d["largest_offset_mean_below_150ms_s"]
    ours = f"{1000 * mx:.0f} ms (max), {1000 * mean:.0f} ms (mean; the largest offset tried)"
    parts = [
        Part(
            f"OPW copes with {1000 * N.OPW_OFFSET_MAX_OK_S:.0f} ms by its maximum deviation",
            Check(
                "largest offset with max deviation below 150 ms, ms",
                1000 * mx,
                threshold=1000 * N.OPW_OFFSET_MAX_OK_S,
                interval=False,
                digits=0,
                strict=False,
            ),
            note=STAND_IN,
        ),
        Part(
            f"OPW copes with {1000 * N.OPW_OFFSET_MEAN_OK_S:.0f} ms by its mean deviation",
            Check(
                "largest offset with mean deviation below 150 ms, ms",
                1000 * mean,
                threshold=1000 * N.OPW_OFFSET_MEAN_OK_S,
                interval=False,
                digits=0,
                strict=False,
            ),
            note=STAND_IN,
        ),
    ]
    return Assessment(ours, parts)


def _claim_b1(ctx):
    have = [n for n in ("OPW", "OLTW") if ctx.ev is not None and ctx.ev.has(n, "UTW")]
    if not have:
        return "not computed"
    ev = ctx.ev
    words = []
    for n in have:
        s, d = ev.passes(n, "similarity"), ev.passes(n, "deviation")
        lo, hi = ev.interval(n, "similarity")
        words.append(
            f"{n}: similarity {ev.median(n, 'similarity'):.3f} [{lo:.3f}, {hi:.3f}] "
            f"({s.verdict} vs UTW), deviation {d.describe().split(', frames ')[-1]} "
            f"({d.verdict})"
        )
    return Assessment("; ".join(words), [])


# -- the table ------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Claim:
    """One claim: what the paper says and how our results decide it, part by part.

    Attributes
    ----------
    id, text, paper, evidence : str
    assess : callable
        ``assess(ctx) -> Assessment`` (our value in words and the parts), or a string: why
        ours is not computed.
    stable : bool
        False for claims read from timings.
    pairs : bool
        Decided on the experiment pairs (so per dataset, per selection and under the
        readings too); False for claims read from timings or a notebook's own facts.
    contradiction : str
        Where the paper's own text contradicts itself, said first in the reason.
    beyond : bool
        Not a claim of the papers (runs beyond them): verdict "n/a".
    question : bool
        Beyond the papers, but with a real verdict: a question the papers leave open,
        answered on the open run (``ctx.open_ev``, :mod:`fpdtw.paper.claims.open`) by the
        same rules; shown on all of the open run's pairs only (no other body of evidence).
    opw : bool
        A claim of the OPW poster, decided from the OPW notebooks' facts (so under the
        plugin reading of OPW too).
    """

    id: str
    text: str
    paper: str
    assess: Callable = field(repr=False)
    evidence: str = ""
    stable: bool = True
    pairs: bool = True
    contradiction: str = ""
    beyond: bool = False
    opw: bool = False
    question: bool = False

    def evaluate(self, ctx) -> dict:
        """``ours``, ``holds``, ``reason`` and the evaluated parts on one context."""
        got = self.assess(ctx)
        if isinstance(got, str):
            return dict(
                ours=f"not computed ({got})", holds=R.NA, reason=f"not computed: {got}", parts=[]
            )
        if self.beyond:
            return dict(
                ours=got.ours,
                holds=R.NA,
                parts=[],
                reason="not a claim of the papers: runs beyond them, shown for reference",
            )
        verdict = R.claim_verdict(p.verdict for p in got.parts)
        return dict(
            ours=got.ours,
            holds=verdict,
            parts=got.parts,
            reason=R.claim_reason(got.parts, self.contradiction),
        )


_SCORES = "Figs. 5, 6; fig5_similarity_summary, fig6_deviation_summary"

#: The claims, in table order.
CLAIMS = [
    Claim("1", "Without a constraint, Mc w40 is the only FP-DTW algorithm whose median passes a "
          "benchmark (similarity above UTW's median or deviation below 18 frames)",
          _names(N.PASS_EITHER_UNCONSTRAINED), _claim1, _SCORES),
    Claim("2", "Ma + Type V, Mc w40 and Mc w80 + Type V pass both benchmarks",
          ", ".join(N.PASS_BOTH), _claim2, _SCORES),
    Claim("2b", "No FP-DTW algorithm other than those three passes both benchmarks (the paper: "
          "'Three of the FP-DTW algorithms ... satisfied both')", "only those three",
          _claim2b, _SCORES),
    Claim("3", "Method C's best window (median similarity) moves from 40 at 120 Hz to 20 at 60 Hz",
          f"best w: {N.BEST_WINDOW[120]} at 120 Hz, {N.BEST_WINDOW[60]} at 60 Hz (Table 1)",
          _claim3, "Table 1; table1_method_c_60_120hz"),
    Claim("4", "Per-frame cost grows steeply with the window w (Methods B and C: median time per "
          "frame increasing at every step, w80/w10 ratio >= 8)",
          "w80/w10: " + ", ".join(
              f"M{m.lower()} {N.TABLE2_US[(m, 80)] / N.TABLE2_US[(m, 10)]:.1f}x" for m in "BC"
          ) + " (Table 2, means)",
          _claim4, "Table 2; table2_time_per_frame, table2_time_vs_w", stable=False, pairs=False),
    Claim("4b", "Without further optimisation, a window of 80 is not feasible at 120 Hz (mean "
          "per-frame time of the unoptimised implementation above 8333 us)",
          f"Mb w80 {N.TABLE2_US[('B', 80)]:.0f} us, Mc w80 {N.TABLE2_US[('C', 80)]:.0f} us",
          _claim4b, "Table 2; table2_time_per_frame", stable=False, pairs=False),
    Claim("4c", "Mc w80 runs out of input frames early (the reason for its low time): it has the "
          "largest fraction of target frames processed with the input exhausted among the "
          "unconstrained B and C algorithms",
          "Mc w80 runs out of input early (Section 5, no number)", _claim4c,
          "table2_time_per_frame (exhausted_fraction)"),
    Claim("5", "Without a constraint, Ma is among the worst FP-DTW algorithms in both tests "
          "(bottom third: rank 7-9 of 9)", "one of the worst in both tests", _claim5, _SCORES),
    Claim("5b", "Method B improves as the window grows (median similarity up and median "
          "deviation down at every step w10 -> w80)",
          "Method B improves with w; Method C peaks at w40 (Section 5)", _claim5b, _SCORES),
    Claim("6", "The Type V constraint improves every Method A and B algorithm but, of Method C, "
          "only Mc w80 (improved: median similarity higher AND median deviation lower)",
          "improved: " + _names(N.TYPEV_IMPROVED), _claim6,
          "Figs. 5, 6 (with/without Type V); fig5/fig6 summaries"),
    Claim("7", "OE-DTW's end points move backwards between consecutive target frames",
          f"yes (Fig. 1: one example, frames {N.FIG1_FRAMES[0]} -> {N.FIG1_FRAMES[1]})",
          _claim7, "Fig. 1 (02_fig1_oedtw); OE-DTW maps"),
    Claim("8", "On the walk pair of Fig. 8, the deviations from DTW of Mb w80, Mc w20, Mc w40, "
          "Mc w80 are 8, 177, 62, 6 frames",
          ", ".join(f"{k} {v:.0f}" for k, v in N.FIG8_DEVIATIONS.items()), _claim8,
          f"Fig. 8 (10_fig8_walk_pair); {FIG8_JSON}", pairs=False,
          contradiction=_FIG8_CONTRADICTION),
    Claim("8b", "On its walk pair (Fig. 8), Mc w20 completely fails, sticking on an input "
          "frame early; Mc w80 skips a walk cycle; Mb w80 stays within the benchmark (ours: "
          "each on more than half of our six walk pairs)",
          "Section 5, on Fig. 8's pair (no number)", _claim8b,
          f"Fig. 8 (10_fig8_walk_pair); fig8_statements; {FIG8_JSON}", pairs=False),
    Claim("9", "The data: the paper's motions, movements and ordered pairs",
          f"{N.DATA['motions']} motions, {N.DATA['movements']} movements, {N.DATA['pairs']} pairs",
          _claim9, "pairs.json; 05_run_experiments", pairs=False,
          contradiction=_DATA_CONTRADICTION),
    Claim("P1", "OPW poster: over the three motions (offset 0.25 s, gamma 5 %), OPW's mean "
          "deviation from the example warp curve is 69-79 ms and its maximum 121 ms, below the "
          "150 ms perceptual threshold",
          "mean {:.0f}-{:.0f} ms, max {:.0f} ms".format(*N.OPW_MEAN_DEVIATION_MS,
                                                        N.OPW_MAX_DEVIATION_MS),
          _claim_p1, f"poster Fig. 4 (13_opw_fig4); {OPW_FIG4_JSON}", pairs=False, opw=True),
    Claim("P2", "OPW poster: with gamma 5 %, OPW consistently removes about 70 % of the temporal "
          "difference between the motions, over the offsets of Fig. 5 (ours: within 10 "
          "percentage points on average and at every offset)",
          f"about {100 * N.OPW_REMOVED_GAMMA5:.0f} %",
          _claim_p2, f"poster Fig. 5 (14_opw_fig5_fig6); {OPW_FIG56_JSON}", pairs=False,
          opw=True),
    Claim("P3", "OPW poster: OPW does best with gamma = 15 %, removing about 77 % of the temporal "
          "difference (ours: best gamma within 5 points, removed share within 10 points)",
          f"gamma {100 * N.OPW_BEST_GAMMA:.0f} %, about {100 * N.OPW_REMOVED_BEST_GAMMA:.0f} %",
          _claim_p3, f"poster Fig. 6 (14_opw_fig5_fig6); {OPW_FIG56_JSON}", pairs=False,
          opw=True),
    Claim("P4", "OPW poster: OPW copes with a temporal difference of 300 ms in 2500 ms motions "
          "(maximum deviation below 150 ms), and up to 500 ms judged by the mean",
          f"{1000 * N.OPW_OFFSET_MAX_OK_S:.0f} ms (max), {1000 * N.OPW_OFFSET_MEAN_OK_S:.0f} ms "
          "(mean)", _claim_p4, f"poster Fig. 5 (14_opw_fig5_fig6); {OPW_FIG56_JSON}", pairs=False,
          opw=True),
    Claim("B1", "Beyond the papers: the OPW poster's method and Dixon's OLTW (the FP-DTW paper's "
          "ref. 3) run on the FP-DTW pairs, against the same two benchmarks",
          "not in the papers", _claim_b1, "Figs. 5, 6, 7; " + _SCORES[12:], beyond=True),
    Claim("Q1", "Beyond the papers (FP-DTW conclusion: the forecast window below half the period "
          "of the movement cycle): Method C with w from the input's dominant period (Mc auto) "
          "passes both benchmarks at 120 and 60 Hz and beats a fixed window",
          "an open question (not tested in the papers)", _open.assess_q1,
          "notebook 16; open_q1_windows, open_q1_movements", question=True),
    Claim("Q2", "Beyond the papers (FP-DTW conclusion: pre-process the recorded motion to weight "
          "joints): weighting eq. 1's joints by how much each moves in the recorded motion lets "
          "Mb w40, Mc w40 and OLTW pass both benchmarks and improves each",
          "an open question (not tested in the papers)", _open.assess_q2,
          "notebook 16; open_q2_weights", question=True),
    Claim("Q3", "Beyond the papers (FP-DTW conclusion: a global constraint, fewer cells to "
          "calculate): a band of half the window (w/2 frames) around the uniform-time diagonal, "
          "its window rows outside the band not computed, lets Mb w40, Mc w40 and Mc w80 pass "
          "both benchmarks, improves each, removes cells from their windows and lowers their "
          "per-frame time (make bench); first reading: a 1 s band",
          "an open question (not tested in the papers)", _open.assess_q3,
          "notebook 16; open_q3_band, open_q3_cost", question=True, stable=False),
    Claim("Q4", "Beyond the papers (OPW conclusion: adjust gamma by a feedback loop): OPW with "
          "gamma adapted from its own recent decisions passes both benchmarks on the FP-DTW "
          "pairs and improves on OPW at gamma 5 %",
          "an open question (not tested in the papers)", _open.assess_q4,
          "notebook 16; open_q4_gamma", question=True),
    Claim("Q5", "Beyond the papers (OPW conclusion: Keogh and Pazzani's derivative DTW): "
          "derivative costs (frame-to-frame rotations and position differences) let Method C "
          "(Mc w40) and OPW pass both benchmarks and improve each",
          "an open question (not tested in the papers)", _open.assess_q5,
          "notebook 16; open_q5_derivative", question=True),
    Claim("Q6", "Beyond the poster's tests (OPW conclusion: OPW 'may not work consistently if "
          "there are periods of standing still'): a pause of 0.5-2 s inserted in the target "
          "raises OPW's median deviation (the other online methods: findings, not parts)",
          "an open question (not tested in the papers)", _open.assess_q6,
          "notebook 16; open_q6_pause", question=True),
]  # fmt: skip


#: Each claim in at most 12 words (the outcome block and ``figures/claims.md``).
SHORT = {
    "1": "Without Type V, only Mc w40 passes a benchmark",
    "2": "Ma+TypeV, Mc w40, Mc w80+TypeV pass both benchmarks",
    "2b": "No other FP-DTW algorithm passes both benchmarks",
    "3": "Method C's best window: 40 at 120 Hz, 20 at 60 Hz",
    "4": "Per-frame cost grows steeply with the window (B, C)",
    "4b": "Unoptimised, a window of 80 is infeasible at 120 Hz",
    "4c": "Mc w80 runs out of input frames early",
    "5": "Without Type V, Ma is among the worst in both tests",
    "5b": "Method B improves at every window step, w10 to w80",
    "6": "Type V improves all A, B algorithms; of C only Mc w80",
    "7": "OE-DTW's end points move backwards between frames",
    "8": "Fig. 8's walk pair deviates 8, 177, 62, 6 frames",
    "8b": "Walk pairs: Mc w20 fails early, Mc w80 skips, Mb w80 close",
    "9": "The data: 333 motions, 44 movements, 3248 pairs",
    "P1": "OPW's mean deviation 69-79 ms; maximum below 150 ms",
    "P2": "At gamma 5 %, OPW consistently removes about 70 %",
    "P3": "The best gamma, 15 %, removes about 77 %",
    "P4": "OPW copes with 300 ms offsets (maximum), 500 ms (mean)",
    "B1": "OPW and OLTW on the FP-DTW pairs (reference)",
    "Q1": "Method C with w from the input's period",
    "Q2": "Eq. 1's joints weighted by their travel",
    "Q3": "A global band around the diagonal",
    "Q4": "OPW with gamma adapted by feedback",
    "Q5": "Derivative costs for Mc w40 and OPW",
    "Q6": "A pause in the target raises OPW's deviation",
}


def claims_by_id(ids, claims=None) -> list:
    """The :class:`Claim` objects of ``ids``, in that order (KeyError names an unknown id)."""
    by = {c.id: c for c in (CLAIMS if claims is None else claims)}
    missing = [i for i in ids if str(i) not in by]
    if missing:
        raise KeyError(f"no claims {missing} in the table (ids: {', '.join(by)})")
    return [by[str(i)] for i in ids]


# -- evaluating the table on every body of evidence ------------------------------------------------


def _reseeded(ev):
    """The same evidence with the second bootstrap seed (None stays None)."""
    if ev is None:
        return None
    seed = ev.seed + SEED2_OFFSET
    return Evidence(ev.results, ev.rows, ev.scheme, ev.n_resamples, seed, alias=ev.alias,
                    values=ev._values, label=f"{ev.label} (second seed)")  # fmt: skip


def _reading_context(ctx, reading):
    """The context under another reading of Method C (same pairs, same bootstrap weights)."""
    alias = reading_alias(reading)
    ev = ctx.ev.reading(alias=alias, label=f"{reading} window") if ctx.ev is not None else None
    return replace(ctx, ev=ev, alias=alias)


def paper_shaped_rows(results, mode: str = "full"):
    """Indices into ``results.pairs`` of the paper-shaped selection's pairs (notebook 15).

    The selection is the study run's (``results/study/pairs.json``, ``smoke-study`` for
    SMOKE): at most 8 takes per movement, drawn with a fixed seed. Returns None when that
    run does not exist.
    """
    from fpdtw.paper.paths import results_dir
    from fpdtw.paper.readings import study_mode
    from fpdtw.paper.runner.results import load_json

    path = results_dir() / study_mode(mode == "smoke") / "pairs.json"
    if not path.is_file():
        return None
    key = {
        (p["dataset"], p["movement"], p["input"], p["target"]): i
        for i, p in enumerate(results.pairs)
    }
    rows = [
        key.get((p["dataset"], p["movement"], p["input"], p["target"]))
        for p in load_json(path)["pairs"]
    ]
    return np.array(sorted(r for r in rows if r is not None), dtype=np.int64)


def claim_contexts(ctx, results=None, mode="full") -> dict:
    """Every body of evidence of the table: key -> context (None where it cannot be made).

    Keys: ``""`` (all pairs), ``"same_movements"``, ``"authors_fbx"``, ``"hdm05"``,
    ``"paper_shaped"``, ``"literal"``, ``"plugin"`` (OPW's plugin reading: None without its
    facts), ``"seed2"`` (all pairs and the open run, resampled with the second seed).
    """
    out = {
        "": ctx,
        **{k: None for k in OTHER_EVIDENCE},
        "literal": _reading_context(ctx, "literal"),
        OPW_PLUGIN: opw_reading(ctx),
        "seed2": None,
    }
    if ctx.ev is not None or ctx.open_ev is not None:
        out["seed2"] = replace(ctx, ev=_reseeded(ctx.ev), open_ev=_reseeded(ctx.open_ev))
    out |= dict.fromkeys(EQ2_OTHER)
    ev = ctx.ev
    if ev is None:
        return out
    other = _other_eq2_values(ev.results)
    out["same_movements"] = ctx.with_evidence(
        Evidence(
            ev.results,
            ev.rows,
            "motions",
            ev.n_resamples,
            ev.seed,
            alias=ev.alias,
            label="these movements",
        )
    )
    ds = np.array([ev.results.pairs[r]["dataset"] for r in ev.rows])
    if other is not None:
        o = ev.reading(values=other, label=f"eq. 2 {other_eq2(ev.results)}")
        out["eq2_other"] = ctx.with_evidence(o)
    for d in DATASETS:
        if np.any(ds == d):
            out[d] = ctx.with_evidence(ev.restrict(ds == d, d))
            if other is not None:
                out[f"eq2_other_{d}"] = ctx.with_evidence(o.restrict(ds == d, d))
    rows = paper_shaped_rows(ev.results, mode) if results is not None else None
    if rows is not None and rows.size:
        for key, values in (("paper_shaped", None), ("eq2_other_paper_shaped", other)):
            if key != "paper_shaped" and other is None:
                continue
            out[key] = ctx.with_evidence(
                Evidence(ev.results, rows, ev.scheme, ev.n_resamples, ev.seed, alias=ev.alias,
                         values=values, label="paper-shaped selection")
            )  # fmt: skip
    return out


def other_eq2(results) -> str | None:
    """The reading of eq. 2 other than the one ``results`` scores with (None: a run
    without readings, e.g. a test's fake run)."""
    eq2 = getattr(results, "eq2", None)
    if eq2 is None:
        return None
    other = next(r for r in EQ2_READINGS if r != eq2)
    if other != STORED_EQ2 and not getattr(results, "selection", None):
        return None  # a run without its selection cannot be rescored
    return other


def _other_eq2_values(results):
    """``values(name, metric)`` of :class:`Evidence` under the other reading of eq. 2."""
    other = other_eq2(results)
    if other is None:
        return None
    if other == STORED_EQ2:

        def stored(name, metric):  # in results.pairs order, as Evidence expects
            if metric != "similarity":
                return None
            arr = results.stored(name)
            pos = {int(p): k for k, p in enumerate(arr["pair_id"])}
            sim = np.asarray(arr["similarity"], dtype=np.float64)
            return np.array([sim[pos[int(p["id"])]] for p in results.pairs])

        return stored
    from fpdtw.paper.similarity_level import reading_values

    return reading_values(results, other)


def _interval_text(parts, labels) -> str:
    out = []
    for label, p in zip(labels, parts):
        c = p.decisive()
        if c is None:
            out.append(f"{label}: {p.verdict}")
        elif c.interval:
            d = c.digits
            out.append(
                f"{label}: {R._fmt(c.estimate, d, c.signed)} "
                f"[{R._fmt(c.low, d, c.signed)}, {R._fmt(c.high, d, c.signed)}] "
                f"vs {c.threshold:g}"
            )
        else:
            out.append(
                f"{label}: {R._fmt(c.estimate, c.digits, c.signed)} vs {c.threshold:g} "
                "(no resampling)"
            )
    return "; ".join(out)


def _relation(c: Check) -> str:
    if c.above:
        return ">" if c.strict else ">="
    return "<" if c.strict else "<="


def check_rows(body: str, claim_id: str, label: str, part) -> list[dict]:
    """The rows of :data:`CHECK_COLUMNS` of one part on one body: one per check, in the
    order of :func:`fpdtw.paper.claims.rules.checks` (``check`` numbers them from 1, as the
    part's ``formula`` does); a part without a test (not comparable) gets one row with
    ``check`` 0 and its verdict."""
    base = dict(body=body, claim=claim_id, part=label)
    if part.test is None:
        empty = dict.fromkeys(CHECK_COLUMNS[5:-1], "")
        return [base | dict(formula="", check=0) | empty | dict(verdict=part.verdict)]
    text = R.formula(part.test)
    out = []
    for k, c in enumerate(R.checks(part.test), start=1):
        out.append(
            base
            | dict(formula=text, check=k, quantity=c.quantity, estimate=c.estimate,
                   low=c.low if c.interval else "", high=c.high if c.interval else "",
                   low_se=c.low_se if c.interval else "", high_se=c.high_se if c.interval else "",
                   threshold=c.threshold, relation=_relation(c), interval=c.interval,
                   verdict=c.verdict)
        )  # fmt: skip
    return out


def seed_verdict(first: str, second: str | None) -> str:
    """A headline part's verdict from its verdicts with the two seeds: the same verdict, or
    :data:`~fpdtw.paper.claims.rules.ON_THRESHOLD` where the seeds disagree (``second``
    None or n/a: no second seed, the first stands)."""
    if second in (None, R.NA) or second == first:
        return first
    return R.ON_THRESHOLD


def evaluate_claims(claims, contexts, robustness=None, checks=None):
    """The claims table and its parts table on the bodies of :func:`claim_contexts`.

    Parameters
    ----------
    claims : sequence of Claim
    contexts : dict
        From :func:`claim_contexts`.
    robustness : dict, optional
        Claim id -> text (:func:`fpdtw.paper.claims.robustness.robustness`).
    checks : list, optional
        When given, the rows of :data:`CHECK_COLUMNS` (every check of every part on every
        body) are appended to it.

    Returns
    -------
    rows : list of dict
        Keys :data:`COLUMNS`.
    parts : list of dict
        Keys :data:`PART_COLUMNS`, one per part.
    """
    rows, part_out = [], []
    for claim in claims:
        main = claim.evaluate(contexts[""])
        labels = [R.part_label(claim.id, k) for k in range(len(main["parts"]))]
        others = {}
        for key in (*OTHER_EVIDENCE, "literal", OPW_PLUGIN, "seed2", *EQ2_OTHER):
            c = contexts.get(key)
            on_pairs = key in OTHER_EVIDENCE or key in EQ2_OTHER
            if c is None or (on_pairs and not claim.pairs) or (claim.question and on_pairs):
                others[key] = None
            elif key in ("literal", OPW_PLUGIN) and claim.question:
                others[key] = None
            elif key == OPW_PLUGIN and not claim.opw:
                others[key] = None
            elif key == "seed2" and not (claim.pairs or claim.question):
                others[key] = None
            else:
                others[key] = claim.evaluate(c)
        seed2 = others["seed2"]
        verdicts = [
            seed_verdict(p.verdict, seed2["parts"][k].verdict if seed2 and
                         k < len(seed2["parts"]) else None)
            for k, p in enumerate(main["parts"])
        ]  # fmt: skip
        holds, reason = main["holds"], main["reason"]
        if main["parts"] and R.ON_THRESHOLD in verdicts:
            holds = R.claim_verdict(verdicts)
            moved = [f"{lab} ({seed2['parts'][k].verdict} with the second seed)"
                     for k, lab in enumerate(labels) if verdicts[k] == R.ON_THRESHOLD]  # fmt: skip
            reason += ". On the threshold: " + "; ".join(moved)
        row = dict(
            id=claim.id,
            claim=claim.text,
            short=SHORT.get(claim.id, claim.text),
            paper=claim.paper,
            ours=main["ours"],
            holds=holds,
            reason=reason,
            interval=_interval_text(main["parts"], labels),
            evidence=claim.evidence,
            stable=claim.stable,
        )
        for key in OTHER_EVIDENCE:
            row[f"holds_{key}"] = R.NA if others[key] is None else others[key]["holds"]
        row["holds_seed2"] = seed2["holds"] if seed2 else R.NA
        row["eq2_other"] = other_eq2(getattr(contexts[""].ev, "results", None)) or R.NA
        for key in EQ2_OTHER:
            row[f"holds_{key}"] = R.NA if others[key] is None else others[key]["holds"]
        lit = others["literal"]
        row["ours_literal"] = lit["ours"] if lit else "not computed"
        row["holds_literal"] = lit["holds"] if lit else R.NA
        plug = others[OPW_PLUGIN]
        if not claim.opw:
            row["ours_plugin"] = R.NA
        else:
            row["ours_plugin"] = plug["ours"] if plug else "not computed (no plugin reading)"
        row["holds_plugin"] = plug["holds"] if plug else R.NA
        rob = (robustness or {}).get(claim.id)
        if not claim.pairs or claim.beyond:
            rob = "n/a (not decided on the pairs)"
        if claim.question:
            rob = "n/a (a question beyond the papers, decided on the open run)"
        row["robustness"] = rob or "not computed here (notebook 12)"
        rows.append({c: row[c] for c in COLUMNS})
        for k, (label, p) in enumerate(zip(labels, main["parts"])):
            c = p.decisive()
            pr = dict(
                claim=claim.id,
                part=label,
                text=p.text,
                verdict=verdicts[k],
                formula=R.formula(p.test) if p.test is not None else "",
                checks=len(R.checks(p.test)) if p.test is not None else 0,
                quantity=c.quantity if c else "",
                estimate=c.estimate if c else None,
                ci_low=c.low if c is not None and c.interval else None,
                ci_high=c.high if c is not None and c.interval else None,
                threshold=c.threshold if c else None,
                mc_margin=_mc_margin(p),
            )
            for key in (*OTHER_EVIDENCE, "literal", OPW_PLUGIN, "seed2", "eq2_other"):
                o = others[key]
                pr[f"verdict_{key}"] = o["parts"][k].verdict if o and k < len(o["parts"]) else R.NA
            part_out.append({c: pr[c] for c in PART_COLUMNS})
        if checks is not None:
            bodies = {"all": main, **{k: v for k, v in others.items()}}
            for body in BODIES:
                got = bodies.get(OPW_PLUGIN if body == "plugin" else body)
                if not got or not got["parts"]:
                    continue
                for k, p in enumerate(got["parts"]):
                    checks += check_rows(body, claim.id, R.part_label(claim.id, k), p)
    return rows, part_out


def _mc_margin(part) -> float | None:
    """The smallest distance, in Monte Carlo standard errors, from an interval end of the
    part's checks to its threshold (None without an interval)."""
    if part.test is None:
        return None
    m = min((c.mc_margin() for c in R.checks(part.test)), default=float("inf"))
    return None if not np.isfinite(m) else round(float(m), 1)


def build_claims(
    mode="full",
    results=None,
    claims=None,
    context=None,
    *,
    robustness=True,
    with_parts=False,
    with_checks=False,
):
    """Check every claim against our results, part by part, on every body of evidence.

    Parameters
    ----------
    mode : {"full", "smoke"}
    results : fpdtw.paper.runner.Results, optional
        Default ``load_results(mode)``.
    claims : sequence of Claim, optional
        Default :data:`CLAIMS`.
    context : ClaimContext, optional
        A context already made (then ``results`` is not read).
    robustness : bool
        Also decide the claims under the readings of the study run (notebook 15), if it
        exists (:mod:`fpdtw.paper.claims.robustness`).
    with_parts : bool
        Return the parts table too.
    with_checks : bool
        Return the checks table too (implies ``with_parts``).

    Returns
    -------
    rows : list of dict
        Keys :data:`COLUMNS`.
    parts : list of dict
        Keys :data:`PART_COLUMNS` (only with ``with_parts`` or ``with_checks``).
    checks : list of dict
        Keys :data:`CHECK_COLUMNS` (only with ``with_checks``).

    Paper: FP-DTW Sections 5-7; OPW poster Section 5.
    Notebook: 12_claims.ipynb
    """
    claims = CLAIMS if claims is None else claims
    if context is None:
        if results is None:
            from fpdtw.paper.runner import load_results

            results = load_results(mode)
        context = ClaimContext.from_results(results, mode)
    contexts = claim_contexts(context, results, mode)
    rob = None
    if robustness and results is not None:
        from fpdtw.paper.claims.robustness import robustness as _robustness

        rob = _robustness(claims, mode)
    checks = []
    rows, parts = evaluate_claims(claims, contexts, rob, checks=checks)
    if with_checks:
        return rows, parts, checks
    return (rows, parts) if with_parts else rows


#: Claims whose pooled intervals get a power estimate (:func:`power_rows`).
POWER_CLAIMS = ("1", "3")
POWER_COLUMNS = ("claim", "part", "check", "quantity", "estimate", "low", "high", "threshold",
                 "relation", "movements", "movements_needed", "to")  # fmt: skip


def movement_count(ev) -> int:
    """Movements (dataset, movement) among an evidence's pairs."""
    return len({(ev.results.pairs[r]["dataset"], ev.results.pairs[r]["movement"]) for r in ev.rows})


def power_rows(checks, movements: int, claims=POWER_CLAIMS) -> list[dict]:
    """How many movements like ours the pooled intervals would need to decide each
    inconclusive check of ``claims`` (headline body).

    An interval over ``K`` movements (movements resampled) narrows about as
    ``1 / sqrt(K)``; with the estimate where it is, the end on the threshold's side clears
    the threshold at ``K' = K * (h / |estimate - threshold|) ** 2``, ``h`` being that end's
    distance from the estimate today. ``to`` says which way it would then be decided (the
    estimate's side: "hold" or "be contradicted"). A rough guide from the bootstrap's
    spread, not a power analysis: the estimate itself moves with new movements.

    Parameters
    ----------
    checks : list of dict
        Rows of :data:`CHECK_COLUMNS`.
    movements : int
        Movements of the headline body (:func:`movement_count`).

    Returns
    -------
    rows : list of dict
        Keys :data:`POWER_COLUMNS`.

    Notebook: 12_claims.ipynb
    """
    out = []
    for c in checks:
        if c["body"] != "all" or c["claim"] not in claims or c["verdict"] != R.INCONCLUSIVE:
            continue
        if c["low"] == "" or c["check"] == 0:
            continue
        est, lo, hi, t = (float(c[k]) for k in ("estimate", "low", "high", "threshold"))
        above = c["relation"].startswith(">")
        gap = est - t
        if gap == 0 or not np.isfinite(gap):
            need, to = float("inf"), "neither (the estimate is on the threshold)"
        else:
            # the end between the estimate and the threshold decides
            h = (est - lo) if gap > 0 else (hi - est)
            need = movements * (h / abs(gap)) ** 2
            to = "hold" if (gap > 0) == above else "be contradicted"
        out.append(
            {k: c[k] for k in ("claim", "part", "check", "quantity", "estimate", "low", "high",
                               "threshold", "relation")}
            | dict(movements=movements,
                   movements_needed=int(np.ceil(need - 1e-9)) if np.isfinite(need) else "never",
                   to=to)
        )  # fmt: skip
    return out


def claim_rows(ids, mode="full", results=None, *, rows=None, facts=None, with_parts=False):
    """The rows of the claims table that a notebook is evidence for, in the order of ``ids``.

    The companion notebooks print these right after their figure (:func:`format_claims`),
    decided by the same rules on the same evidence as ``figures/claims.md`` (notebook 12),
    which alone adds the robustness column (it rescores the study run under every reading).

    Parameters
    ----------
    ids : sequence of str
        Claim ids of :data:`CLAIMS`, e.g. ``["1", "2"]`` (KeyError for an unknown id).
    mode : {"full", "smoke"}
    results : fpdtw.paper.runner.Results, optional
        The experiment results (default: ``load_results(mode)``, unless ``rows`` or
        ``facts`` is given).
    rows : list of dict, optional
        A claims table already built (:func:`build_claims`): its rows are picked.
    facts : dict, optional
        A notebook's own facts instead of results (:meth:`ClaimContext.from_facts`).
    with_parts : bool
        Return the claims' parts too (not with ``rows``: a table given has no parts), so
        that a notebook ends with the same parts as ``figures/claims_intervals.csv``.

    Returns
    -------
    rows : list of dict
        Keys :data:`COLUMNS`, one row per id.
    parts : list of dict
        Keys :data:`PART_COLUMNS`, the parts of these claims in order (only with
        ``with_parts``; print them with :func:`format_parts`).

    Paper: FP-DTW Sections 5-7; OPW poster Section 5.
    Notebook: 06_fig5_fig6_scores.ipynb
    """
    ids = [str(i) for i in ids]
    if sum(x is not None for x in (results, rows, facts)) > 1:
        raise ValueError("give at most one of results, rows and facts")
    if rows is not None:
        if with_parts:
            raise ValueError("with_parts needs results or facts, not a table of rows")
        by = {r["id"]: r for r in rows}
        missing = [i for i in ids if i not in by]
        if missing:
            raise KeyError(f"no rows {missing} in the claims table given")
        return [by[i] for i in ids]
    subset = claims_by_id(ids)
    if facts is not None:
        ctx = ClaimContext.from_facts(mode, "square", **dict(facts))
        out, parts = evaluate_claims(subset, claim_contexts(ctx))
    else:
        out, parts = build_claims(mode, results, claims=subset, robustness=False, with_parts=True)
    return (out, parts) if with_parts else out


def format_claims(rows, stable=None, width: int = 96) -> str:
    """The claims as text: the claim, then paper, ours, verdict, reason and the other bodies.

    Deterministic for deterministic rows, so a notebook cell printing it can be compared by
    nbval.

    Parameters
    ----------
    rows : list of dict
        From :func:`claim_rows` or :func:`build_claims`.
    stable : bool, optional
        True: only the deterministic rows; False: only the timing rows; None: all.
    width : int
        Line width the text is wrapped to.

    Returns
    -------
    text : str

    Notebook: 06_fig5_fig6_scores.ipynb
    """
    import textwrap

    def fill(text, label):
        return textwrap.fill(
            str(text), width, initial_indent="    " + label, subsequent_indent=" " * 12
        )

    out = []
    for r in rows:
        if stable is not None and bool(r.get("stable", True)) != stable:
            continue
        lines = [textwrap.fill(f"[{r['id']}] {r['claim']}", width, subsequent_indent="    ")]
        lines.append(fill(r["paper"], "paper:  "))
        lines.append(fill(r["ours"], "ours:   "))
        lines.append(fill(f"{r['holds']}: {r['reason']}", "holds?  "))
        if r.get("interval"):
            lines.append(fill(r["interval"], "95 %:   "))
        bodies = [
            f"{k.replace('_', ' ')} {r[f'holds_{k}']}"
            for k in OTHER_EVIDENCE
            if r.get(f"holds_{k}", R.NA) != R.NA
        ]
        if bodies:
            lines.append(fill("; ".join(bodies), "also:   "))
        if r.get("robustness") and not str(r["robustness"]).startswith(("n/a", "not computed")):
            lines.append(fill(r["robustness"], "robust: "))
        if "ours_literal" in r and (r["ours_literal"], r["holds_literal"]) != (
            r["ours"],
            r["holds"],
        ):
            lines.append(
                fill(
                    f"{r['ours_literal']}; holds? {r['holds_literal']}",
                    "with Method C's literal window: ",
                )
            )
        if r.get("ours_plugin", R.NA) != R.NA and (r["ours_plugin"], r["holds_plugin"]) != (
            r["ours"],
            r["holds"],
        ):
            lines.append(
                fill(
                    f"{r['ours_plugin']}; holds? {r['holds_plugin']}",
                    "with OPW read as the authors' plugin does it: ",
                )
            )
        out.append("\n".join(lines))
    return "\n".join(out) if out else "(no claims)"


def format_parts(parts, width: int = 110) -> str:
    """The parts table as text: one line per part with its verdict and interval, then the
    verdict on the other bodies of evidence where it differs.

    Parameters
    ----------
    parts : list of dict
        Rows of :data:`PART_COLUMNS` (:func:`build_claims` with ``with_parts=True``).
    width : int

    Returns
    -------
    text : str
        Deterministic for deterministic parts.

    Notebook: 12_claims.ipynb
    """
    import textwrap

    out = []
    for p in parts:
        est, lo, hi = p["estimate"], p["ci_low"], p["ci_high"]
        if est is None:
            num = ""
        elif lo is None:
            num = f" | {est:.4g} vs {p['threshold']:g}"
        else:
            num = f" | {est:.4g} [{lo:.4g}, {hi:.4g}] vs {p['threshold']:g}"
        other = [f"{k.replace('_', ' ')}: {p[f'verdict_{k}']}"
                 for k in (*OTHER_EVIDENCE, "literal", OPW_PLUGIN)
                 if p[f"verdict_{k}"] not in (R.NA, p["verdict"])]  # fmt: skip
        line = f"{p['part']:4s} {p['verdict']:14s} {p['text']}{num}"
        if other:
            line += " (" + "; ".join(other) + ")"
        out.append(textwrap.fill(line, width, subsequent_indent=" " * 20))
    return "\n".join(out) if out else "(no parts)"


def claims_summary(rows) -> str:
    """How many claims get each verdict: the headline (movements resampled), with the
    movements fixed, under the other reading of eq. 2, with Method C's literal window, and
    the OPW poster's claims with OPW's plugin reading.

    Returns
    -------
    text : str
        One line per body, e.g. ``"headline: yes 6, partly 5, no 2, ... (of 17 claims)"``;
        a body no claim was decided on has no line.

    Notebook: 12_claims.ipynb
    """
    lines = []
    other = next((r.get("eq2_other") for r in rows if r.get("eq2_other", R.NA) != R.NA), None)
    bodies = (
        ("holds", "headline (movements resampled)"),
        ("holds_same_movements", "movements fixed"),
        ("holds_eq2_other", f"eq. 2 read as {other}"),
        ("holds_literal", "Method C's literal window"),
        ("holds_plugin", "OPW plugin reading"),
    )
    for col, label in bodies:
        got = [r[col] for r in rows if r.get(col, R.NA) != R.NA]
        if not got:
            continue
        counts = {v: got.count(v) for v in R.CLAIM_VERDICTS[:-1]}
        lines.append(
            f"{label}: " + ", ".join(f"{k} {v}" for k, v in counts.items())
            + f" (of {len(got)} claims decided)"
        )  # fmt: skip
    return "\n".join(lines)


#: The bodies of the short table's "A / H / S" column.
AHS = ("authors_fbx", "hdm05", "paper_shaped")
#: Columns of ``figures/claims.md``, the short table (``claims.csv`` keeps every column).
SHORT_COLUMNS = ("id", "claim", "paper", "ours", "verdict", "movements fixed", "A / H / S",
                 "other eq. 2", "parts")  # fmt: skip


def short_rows(rows, parts=None) -> list[dict]:
    """The short claims table: each claim in at most 12 words, the paper's value, ours, the
    verdict (movements resampled), with the movements fixed, per dataset and selection (A:
    the authors' FBX takes, H: HDM05, S: the paper-shaped selection), under the other
    reading of eq. 2 and each part's verdict.

    Returns
    -------
    rows : list of dict
        Keys :data:`SHORT_COLUMNS`.

    Notebook: 12_claims.ipynb
    """
    by_claim = {}
    for p in parts or []:
        by_claim.setdefault(p["claim"], []).append(f"{p['part'][len(p['claim']) :]} {p['verdict']}")
    out = []
    for r in rows:
        ahs = " / ".join(r.get(f"holds_{k}", R.NA) for k in AHS)
        out.append({
            "id": r["id"], "claim": r.get("short") or SHORT.get(r["id"], r["claim"]),
            "paper": r["paper"], "ours": r["ours"], "verdict": r["holds"],
            "movements fixed": r.get("holds_same_movements", R.NA),
            "A / H / S": ahs if ahs != " / ".join([R.NA] * 3) else R.NA,
            "other eq. 2": r.get("holds_eq2_other", R.NA),
            "parts": "; ".join(by_claim.get(r["id"], [])) or "-",
        })  # fmt: skip
    return out


def bootstrap_note() -> str:
    """Which question each resampling answers, and the seeds (under every claims table)."""
    from fpdtw.paper.claims import bootstrap as bs

    return (
        f"Intervals: {bs.N_RESAMPLES} resamples of a two-stage cluster bootstrap (seed "
        f"{bs.SEED}; second seed {bs.SEED + SEED2_OFFSET}). The verdict resamples movements "
        "within each dataset, then motions within each movement: it answers 'would this hold "
        "for other movements like these, recorded again?'. 'Movements fixed' resamples the "
        "motions only: 'would it hold for other takes of these movements?'. Monte Carlo "
        f"errors of the interval ends: batch means over {bs.MC_BATCHES} batches."
    )


def save_claims(rows, mode="full", parts=None, meta=None, checks=None, power=None):
    """Write ``claims.csv|md``, ``claims_intervals.csv|md`` (parts), ``claims_checks.csv|md``
    (every check of every part on every body, at full precision), ``claims_power.csv|md``
    and ``results/<mode>/claims.json``.

    ``claims.md`` is the short table (:func:`short_rows`); ``claims.csv`` has every column
    (:data:`COLUMNS`). ``python -m fpdtw.paper.claims verify figures/`` recomputes every
    part and claim verdict from the CSV files alone.

    Parameters
    ----------
    rows : list of dict
        :func:`build_claims` rows.
    mode : {"full", "smoke"}
    parts : list of dict, optional
        The parts table (:func:`build_claims` with ``with_parts=True``).
    meta : dict, optional
        Stored in the JSON beside the rows (e.g. the bootstrap's design).
    checks : list of dict, optional
        The checks table (:func:`build_claims` with ``with_checks=True``).
    power : list of dict, optional
        :func:`power_rows`.

    Returns
    -------
    paths : list of Path

    Notebook: 12_claims.ipynb
    """
    from fpdtw.paper.claims import bootstrap as bs
    from fpdtw.paper.figures.tables import save_table, to_markdown
    from fpdtw.paper.paths import figures_dir, results_dir
    from fpdtw.paper.provenance import versions_line

    boot = bootstrap_note()
    note = (
        f"{R.RULE}\n\n{boot}\n\nComputed with {versions_line()}. The commit and the "
        "machine that made these figures: ENVIRONMENT.md. Every column: claims.csv; every "
        "check: claims_checks.csv; `python -m fpdtw.paper.claims verify figures/` recomputes "
        "every verdict from these files."
    )
    out = list(save_table(rows, "claims", columns=COLUMNS, note=note))
    md = to_markdown(short_rows(rows, parts), SHORT_COLUMNS) + f"\n{note}\n"
    out[1] = write_atomic(figures_dir() / "claims.md", md.encode())
    if parts is not None:
        out += save_table(parts, "claims_intervals", columns=PART_COLUMNS, note=boot,
                          csvfmt=".17g")  # fmt: skip
    if checks is not None:
        out += save_table(checks, "claims_checks", columns=CHECK_COLUMNS, csvfmt=".17g",
                          floatfmt=".4g", note=f"{R.RULE}\n\n{boot}")  # fmt: skip
    if power is not None:
        out += save_table(power, "claims_power", columns=POWER_COLUMNS, note=(
            "How many movements like ours the pooled interval of each inconclusive check of "
            "claims 1 and 3 would need to decide it, if its estimate stayed where it is and "
            "the interval narrowed as 1/sqrt(movements) (fpdtw.paper.claims.table.power_rows)."
        ))  # fmt: skip
    doc = {
        "mode": mode,
        "claims": rows,
        "parts": parts or [],
        "bootstrap": {
            "resamples": bs.N_RESAMPLES,
            "seed": bs.SEED,
            "seed2": bs.SEED + SEED2_OFFSET,
            "level": bs.LEVEL,
            "schemes": bs.SCHEMES,
        },
        **(meta or {}),
    }
    text = json.dumps(doc, indent=1, default=float) + "\n"
    out.append(write_atomic(results_dir() / mode / "claims.json", text.encode()))
    return out


__all__ = [
    "BODIES",
    "CHECK_COLUMNS",
    "CLAIMS",
    "COLUMNS",
    "PART_COLUMNS",
    "POWER_COLUMNS",
    "SHORT",
    "SHORT_COLUMNS",
    "Assessment",
    "Claim",
    "ClaimContext",
    "best_window_test",
    "bootstrap_note",
    "build_claims",
    "check_rows",
    "claim_contexts",
    "claim_rows",
    "claims_by_id",
    "claims_summary",
    "data_counts",
    "evaluate_claims",
    "format_claims",
    "format_parts",
    "movement_count",
    "oedtw_backward_jumps",
    "opw_reading",
    "paper_shaped_rows",
    "power_rows",
    "reading_alias",
    "save_claims",
    "short_rows",
]
