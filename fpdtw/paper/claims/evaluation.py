"""Deciding the claims: every claim on every body of evidence, part by part.

:func:`build_claims` evaluates every claim of :data:`~fpdtw.paper.claims.paper_claims.CLAIMS`
on the bodies of :func:`~fpdtw.paper.claims.contexts.claim_contexts` and returns one row per
claim (:data:`~fpdtw.paper.claims.types.COLUMNS`):

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

With ``with_parts`` it also gives one row per part (``figures/claims_intervals.csv``), with
``with_checks`` one row per check (``figures/claims_checks.csv``). :func:`claim_rows` picks
the rows a notebook is evidence for; :func:`open_claim_rows` decides the Q rows on the open
run alone.

Rows carry ``stable``: False for the claims computed from timings (``make bench``:
measurements that change between runs); all other rows are deterministic.

Paper: FP-DTW Sections 5-7; OPW poster Section 5.
Notebook: 12_claims.ipynb
"""

from __future__ import annotations

import numpy as np

from fpdtw.paper.claims import rules as R
from fpdtw.paper.claims.contexts import claim_contexts, load_context, open_evidence, other_eq2
from fpdtw.paper.claims.paper_claims import CLAIMS, SHORT, claims_by_id
from fpdtw.paper.claims.robustness import robustness as claim_robustness
from fpdtw.paper.claims.rules import Check
from fpdtw.paper.claims.types import (
    BODIES,
    CHECK_COLUMNS,
    COLUMNS,
    EQ2_OTHER,
    OPW_PLUGIN,
    OTHER_EVIDENCE,
    PART_COLUMNS,
    ClaimContext,
)
from fpdtw.paper.figures.timing import load_bench
from fpdtw.paper.runner import load_results


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
            results = load_results(mode)
        context = load_context(results, mode)
    contexts = claim_contexts(context, results, mode)
    rob = None
    if robustness and results is not None:
        rob = claim_robustness(claims, mode)
    checks = []
    rows, parts = evaluate_claims(claims, contexts, rob, checks=checks)
    if with_checks:
        return rows, parts, checks
    return (rows, parts) if with_parts else rows


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
        ctx = ClaimContext.from_facts(mode, **dict(facts))
        out, parts = evaluate_claims(subset, claim_contexts(ctx))
    else:
        out, parts = build_claims(mode, results, claims=subset, robustness=False, with_parts=True)
    return (out, parts) if with_parts else out


def open_claim_rows(ids, mode: str = "full"):
    """The rows and parts of the Q claims ``ids`` on the open run alone (no other run read).

    Parameters
    ----------
    ids : sequence of str
        Ids of the questions beyond the papers (:data:`~fpdtw.paper.claims.open.QUESTION_IDS`).
    mode : {"full", "smoke"}
        The open run read is :func:`~fpdtw.paper.claims.open.open_mode` of it.

    Returns
    -------
    rows, parts : list of dict
        As :func:`claim_rows` with ``with_parts=True``.

    Paper: FP-DTW Section 7; OPW poster Section 6 (the questions their conclusions leave open).
    Notebook: 16_open_questions.ipynb
    """
    ctx = ClaimContext(mode=mode, open_ev=open_evidence(mode), bench=load_bench())
    return evaluate_claims(claims_by_id([str(i) for i in ids]), claim_contexts(ctx))


__all__ = [
    "build_claims",
    "check_rows",
    "claim_rows",
    "evaluate_claims",
    "open_claim_rows",
    "seed_verdict",
]
