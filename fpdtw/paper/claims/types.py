"""The shapes the claims are made of: a claim, its context, its assessment, the table's columns.

The bottom of the claims package beside the rules (:mod:`~fpdtw.paper.claims.rules`), the
intervals (:mod:`~fpdtw.paper.claims.bootstrap`) and the evidence of the pairs
(:mod:`~fpdtw.paper.claims.evidence`); it imports nothing above them:

* :class:`Claim`: one claim, what the paper says and the function that assesses it;
* :class:`ClaimContext`: everything an assessment reads (the evidence of the pairs, the
  notebooks' facts, the timings), and the other readings of Method C and OPW it can be
  put under (:func:`reading_alias`, :func:`opw_reading`);
* :class:`Assessment`: our value in words and the claim's parts;
* the columns of the claims, parts and checks tables and the bodies of evidence.

Paper: FP-DTW Sections 5-7; OPW poster Section 5.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field, replace

from fpdtw.paper.claims import rules as R
from fpdtw.paper.claims.evidence import Evidence
from fpdtw.paper.numbers import WINDOWS
from fpdtw.registry import method_c_name

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
#: The bodies under the other reading of eq. 2 (:func:`fpdtw.paper.claims.contexts.other_eq2`),
#: as keys of :func:`fpdtw.paper.claims.contexts.claim_contexts`.
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

    Made from a run by :func:`fpdtw.paper.claims.contexts.load_context`, or from a
    notebook's own facts by :meth:`from_facts`.

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
        The open run's evidence (:func:`fpdtw.paper.claims.contexts.open_evidence`), read by the
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


__all__ = [
    "BODIES",
    "CHECK_COLUMNS",
    "COLUMNS",
    "DATASETS",
    "EQ2_OTHER",
    "FIG8_JSON",
    "OPW_FIG4_JSON",
    "OPW_FIG56_JSON",
    "OPW_PLUGIN",
    "OTHER_EVIDENCE",
    "PART_COLUMNS",
    "READINGS",
    "SEED2_OFFSET",
    "Assessment",
    "Claim",
    "ClaimContext",
    "opw_reading",
    "reading_alias",
]
