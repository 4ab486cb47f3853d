"""What a claim is made of: :class:`Claim`, the :class:`ClaimContext` it is decided on, its
:class:`Assessment`, and the columns of the claims, parts and checks tables.

Paper: FP-DTW Sections 5-7; OPW poster Section 5.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field, replace

from fpdtw.paper.claims import rules as R
from fpdtw.paper.claims.evidence import Evidence
from fpdtw.paper.numbers import WINDOWS
from fpdtw.registry import method_c_name

#: The notebooks' JSON under ``results/<mode>/figs/``.
FIG8_JSON = "10_fig8_walk_pair.json"
OPW_FIG4_JSON = "13_opw_fig4.json"
OPW_FIG56_JSON = "14_opw_fig5_fig6.json"

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
#: Columns of the checks table (``claims_checks.csv``).
CHECK_COLUMNS = ("body", "claim", "part", "formula", "check", "quantity", "estimate", "low",
                 "high", "low_se", "high_se", "threshold", "relation", "interval",
                 "verdict")  # fmt: skip
#: Every body of evidence a part is decided on (``"all"``: the headline).
BODIES = ("all", "seed2", "same_movements", "authors_fbx", "hdm05", "paper_shaped", "literal",
          "plugin", "eq2_other", "eq2_other_authors_fbx", "eq2_other_hdm05",
          "eq2_other_paper_shaped")  # fmt: skip
#: The bodies under the other reading of eq. 2 (keys of ``claim_contexts``).
EQ2_OTHER = ("eq2_other", "eq2_other_authors_fbx", "eq2_other_hdm05", "eq2_other_paper_shaped")
#: The second bootstrap seed's offset from ``bootstrap.SEED``.
SEED2_OFFSET = 1
#: The other bodies of evidence, as column suffixes of ``holds``.
OTHER_EVIDENCE = ("same_movements", "authors_fbx", "hdm05", "paper_shaped")
#: OPW's other reading (the OPW notebooks' facts: ``readings`` -> this name).
OPW_PLUGIN = "plugin"


@dataclass
class Assessment:
    """Our value of a claim in words and its parts."""

    ours: str
    parts: list


@dataclass
class ClaimContext:
    """Everything the claims read (:func:`~fpdtw.paper.claims.contexts.load_context`).

    ``ev``: the pairs' :class:`Evidence` (None: no results); ``timing``: rows of
    :func:`fpdtw.paper.figures.timing.time_per_frame_rows`; ``alias``: Method C's reading
    (:func:`reading_alias`); ``open_ev``: the open run's (Q rows); ``plain``, ``bench``:
    ``make bench``'s plain NumPy steps (claim 4b) and report.
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

    def timing_rows(self) -> list | None:
        """The timing rows under this context's reading (None without timings); the rows of
        another reading (``"Mc w40 (literal window)"``) stand in for their names."""
        if not self.timing:
            return None
        by = {r["algorithm"]: r for r in self.timing}
        names = [r["algorithm"] for r in self.timing if "(" not in r["algorithm"]]
        return [{**by[src], "algorithm": n} for n in names if (src := self.alias.get(n, n)) in by]

    def fig8_devs(self) -> dict | None:
        """Algorithm -> Fig. 8 deviation (frames) under this context's reading."""
        d = self.fig8.get("deviation") if isinstance(self.fig8, dict) else None
        if not (isinstance(d, dict) and d and all(isinstance(x, int | float) for x in d.values())):
            return None
        devs = {k: float(x) for k, x in d.items()}
        out = {n: v for n, v in devs.items() if n not in self.alias}
        out.update({n: devs[s] for n, s in self.alias.items() if s in devs})
        return out or None

    @classmethod
    def from_facts(cls, mode="full", **facts) -> ClaimContext:
        """A context holding only a notebook's own facts: claims on the pairs are "not computed".

        Paper: FP-DTW Sections 5-7; OPW poster Section 5.
        """
        allowed = {"fig8", "opw_fig4", "opw_fig56", "counts", "timing", "plain"}
        if unknown := set(facts) - allowed:
            raise TypeError(f"unknown facts {sorted(unknown)}; allowed: {sorted(allowed)}")
        return cls(mode=mode, **facts)


def opw_reading(ctx):
    """The context with the OPW notebooks' facts of the authors' plugin reading, or None.

    Paper: OPW poster Section 5; the authors' MotionBuilder plugin.
    """
    fig4, fig56 = (
        ((d or {}).get("readings") or {}).get(OPW_PLUGIN) for d in (ctx.opw_fig4, ctx.opw_fig56)
    )
    if fig4 is None and fig56 is None:
        return None
    return replace(ctx, opw_fig4=fig4, opw_fig56=fig56)


def reading_alias(reading: str) -> dict:
    """Mc name -> its results' name under a reading of Algorithm 3 ({} for ``"square"``)."""
    if reading == "square":
        return {}
    keys = [(w, t, r) for w in WINDOWS for t in (False, True) for r in ("", "@60Hz")]
    return {method_c_name(w, "square", t) + r: method_c_name(w, reading, t) + r for w, t, r in keys}


@dataclass(frozen=True)
class Claim:
    """One claim: what the paper says and how our results decide it, part by part.

    ``assess(ctx)``: an :class:`Assessment`, or why ours is not computed. ``stable``: False
    when read from timings. ``pairs``: decided on the experiment pairs. ``contradiction``:
    where the paper contradicts itself. ``beyond``: not a claim of the papers (n/a).
    ``question``: a Q row, decided on the open run. ``opw``: an OPW poster claim.
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
            why = f"not computed: {got}"
            return dict(ours=f"not computed ({got})", holds=R.NA, reason=why, parts=[])
        if self.beyond:
            why = "not a claim of the papers: runs beyond them, shown for reference"
            return dict(ours=got.ours, holds=R.NA, parts=[], reason=why)
        verdict = R.claim_verdict(p.verdict for p in got.parts)
        reason = R.claim_reason(got.parts, self.contradiction)
        return dict(ours=got.ours, holds=verdict, parts=got.parts, reason=reason)
