"""Deciding the claims: every claim on every body of evidence, part by part (one row per
claim, one per part, one per check).

Paper: FP-DTW Sections 5-7; OPW poster Section 5.
Notebook: 12_claims.ipynb
"""

from __future__ import annotations

import numpy as np

from fpdtw.paper.claims import rules as R
from fpdtw.paper.claims import types as T
from fpdtw.paper.claims.contexts import claim_contexts, load_context, open_evidence, other_eq2
from fpdtw.paper.claims.paper_claims import CLAIMS, SHORT, claims_by_id
from fpdtw.paper.claims.robustness import robustness as claim_robustness
from fpdtw.paper.figures.timing import load_bench
from fpdtw.paper.runner import load_results


def _interval_text(parts, labels) -> str:
    out = []
    for label, p in zip(labels, parts):
        c = p.decisive()
        point = "" if c is None or c.interval else " (no resampling)"
        text = p.verdict if c is None else f"{c.value_text()} vs {c.threshold:g}{point}"
        out.append(f"{label}: {text}")
    return "; ".join(out)


def check_rows(body: str, claim_id: str, label: str, part) -> list[dict]:
    """The rows of :data:`CHECK_COLUMNS` of one part on one body, one per check (numbered from
    1, as in ``formula``; a part that is not comparable: one row, ``check`` 0)."""
    base = dict(body=body, claim=claim_id, part=label)
    if part.test is None:
        empty = dict.fromkeys(T.CHECK_COLUMNS[5:-1], "")
        return [base | dict(formula="", check=0) | empty | dict(verdict=part.verdict)]
    text = R.formula(part.test)
    out = []
    for k, c in enumerate(R.checks(part.test), start=1):
        ci = (c.low, c.high, c.low_se, c.high_se) if c.interval else ("",) * 4
        relation = (">" if c.above else "<") + ("" if c.strict else "=")
        out.append(
            base
            | dict(formula=text, check=k, quantity=c.quantity, estimate=c.estimate)
            | dict(zip(("low", "high", "low_se", "high_se"), ci))
            | dict(threshold=c.threshold, relation=relation, interval=c.interval, verdict=c.verdict)
        )
    return out


def seed_verdict(first: str, second: str | None) -> str:
    """A headline part's verdict with both seeds (``ON_THRESHOLD`` where they disagree)."""
    return first if second in (None, R.NA, first) else R.ON_THRESHOLD


def _applies(claim, key: str) -> bool:
    """Whether a claim is decided on the body ``key`` of :func:`claim_contexts`."""
    if key == "seed2":
        return claim.pairs or claim.question
    if claim.question:
        return False
    if key == "literal":
        return True
    return claim.opw if key == T.OPW_PLUGIN else claim.pairs


def evaluate_claims(claims, contexts, robustness=None, checks=None):
    """``(rows, parts)`` of the claims on the bodies of :func:`claim_contexts` (keys
    :data:`COLUMNS`, :data:`PART_COLUMNS`); ``robustness``: claim id -> text; ``checks``: a
    list the rows of :data:`CHECK_COLUMNS` are appended to."""
    rows, part_out = [], []
    for claim in claims:
        main = claim.evaluate(contexts[""])
        labels = [R.part_label(claim.id, k) for k in range(len(main["parts"]))]
        others = {}
        for key in T.BODIES[1:]:  # every body but the headline ("all")
            c = contexts.get(key)
            others[key] = claim.evaluate(c) if c is not None and _applies(claim, key) else None
        seed2 = others["seed2"]
        verdicts = [
            seed_verdict(p.verdict, _verdict(seed2, k)) for k, p in enumerate(main["parts"])
        ]
        holds, reason = main["holds"], main["reason"]
        if main["parts"] and R.ON_THRESHOLD in verdicts:
            holds = R.claim_verdict(verdicts)
            moved = [f"{lab} ({seed2['parts'][k].verdict} with the second seed)"
                     for k, lab in enumerate(labels) if verdicts[k] == R.ON_THRESHOLD]  # fmt: skip
            reason += ". On the threshold: " + "; ".join(moved)
        row = dict(id=claim.id, claim=claim.text, paper=claim.paper, stable=claim.stable)
        row |= dict(ours=main["ours"], holds=holds, reason=reason, evidence=claim.evidence)
        row["short"] = SHORT.get(claim.id, claim.text)
        row["interval"] = _interval_text(main["parts"], labels)
        row |= {f"holds_{k}": R.NA if o is None else o["holds"] for k, o in others.items()}
        row["eq2_other"] = other_eq2(getattr(contexts[""].ev, "results", None)) or R.NA
        row["ours_literal"] = (others["literal"] or {"ours": "not computed"})["ours"]
        plug = others[T.OPW_PLUGIN] or {"ours": "not computed (no plugin reading)"}
        row["ours_plugin"] = plug["ours"] if claim.opw else R.NA
        rob = (robustness or {}).get(claim.id)
        if not claim.pairs or claim.beyond:
            rob = "n/a (not decided on the pairs)"
        if claim.question:
            rob = "n/a (a question beyond the papers, decided on the open run)"
        row["robustness"] = rob or "not computed here (notebook 12)"
        rows.append({c: row[c] for c in T.COLUMNS})
        for k, (label, p) in enumerate(zip(labels, main["parts"])):
            pr = dict(claim=claim.id, part=label, text=p.text, verdict=verdicts[k], quantity="")
            if (c := p.decisive()) is not None:  # the columns it leaves out are empty
                pr |= dict(quantity=c.quantity, estimate=c.estimate, threshold=c.threshold)
                pr |= dict(ci_low=c.low, ci_high=c.high) if c.interval else {}
            cs = [] if p.test is None else R.checks(p.test)
            pr |= dict(formula="" if p.test is None else R.formula(p.test), checks=len(cs))
            m = min((x.mc_margin() for x in cs), default=float("inf"))  # in Monte Carlo errors
            pr["mc_margin"] = round(float(m), 1) if np.isfinite(m) else None
            pr |= {f"verdict_{key}": _verdict(got, k) for key, got in others.items()}
            part_out.append({col: pr.get(col) for col in T.PART_COLUMNS})
        for body, got in ({"all": main, **others} if checks is not None else {}).items():
            for k, p in enumerate((got or {}).get("parts", [])):
                checks += check_rows(body, claim.id, R.part_label(claim.id, k), p)
    return rows, part_out


def _verdict(got, k: int) -> str:
    """The verdict of part ``k`` of an evaluated claim (n/a where it has none)."""
    return got["parts"][k].verdict if got and k < len(got["parts"]) else R.NA


def build_claims(mode="full", results=None, claims=None, *, robustness=True, with_parts=False,
                 with_checks=False):  # fmt: skip
    """Every claim (default :data:`CLAIMS`) against a run (default ``load_results(mode)``).

    Returns the rows, with ``with_parts`` also the parts, with ``with_checks`` the parts and the
    checks; ``robustness``: also under the readings of the study run (notebook 15).

    Paper: FP-DTW Sections 5-7; OPW poster Section 5.
    Notebook: 12_claims.ipynb
    """
    claims = CLAIMS if claims is None else claims
    results = load_results(mode) if results is None else results
    contexts = claim_contexts(load_context(results, mode), results, mode)
    rob = claim_robustness(claims, mode) if robustness else None
    checks = []
    rows, parts = evaluate_claims(claims, contexts, rob, checks=checks)
    if with_checks:
        return rows, parts, checks
    return (rows, parts) if with_parts else rows


def claim_rows(ids, mode="full", results=None, *, rows=None, facts=None, with_parts=False):
    """The rows of the claims ``ids`` (no robustness), decided on ``results`` (default
    ``load_results(mode)``) or a notebook's ``facts``, or picked from ``rows``, a table built.

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
        if missing := [i for i in ids if i not in by]:
            raise KeyError(f"no rows {missing} in the claims table given")
        return [by[i] for i in ids]
    subset = claims_by_id(ids)
    if facts is not None:
        ctx = T.ClaimContext.from_facts(mode, **dict(facts))
        out, parts = evaluate_claims(subset, claim_contexts(ctx))
    else:
        out, parts = build_claims(mode, results, claims=subset, robustness=False, with_parts=True)
    return (out, parts) if with_parts else out


def open_claim_rows(ids, mode: str = "full"):
    """The rows and parts of the Q claims ``ids`` decided on the open run of ``mode`` alone.

    Paper: FP-DTW Section 7; OPW poster Section 6 (the questions their conclusions leave open).
    Notebook: 16_open_questions.ipynb
    """
    ctx = T.ClaimContext(mode=mode, open_ev=open_evidence(mode), bench=load_bench())
    return evaluate_claims(claims_by_id([str(i) for i in ids]), claim_contexts(ctx))
