"""Reporting the claims: as text, as the short table, as files, with the power estimates.

Paper: FP-DTW Sections 5-7; OPW poster Section 5.
Notebook: 12_claims.ipynb
"""

from __future__ import annotations

import json
import textwrap

import numpy as np

from fpdtw.paper.atomic import write_atomic
from fpdtw.paper.claims import bootstrap as bs
from fpdtw.paper.claims import rules as R
from fpdtw.paper.claims import types as T
from fpdtw.paper.claims.paper_claims import SHORT
from fpdtw.paper.figures.tables import save_table, to_markdown
from fpdtw.paper.paths import figures_dir, results_dir
from fpdtw.paper.provenance import versions_line

#: Claims whose pooled intervals get a power estimate (:func:`power_rows`).
POWER_CLAIMS = ("1", "3")
POWER_COLUMNS = ("claim", "part", "check", "quantity", "estimate", "low", "high", "threshold",
                 "relation", "movements", "movements_needed", "to")  # fmt: skip


def movement_count(ev) -> int:
    """Movements (dataset, movement) among an evidence's pairs."""
    return len({(ev.results.pairs[r]["dataset"], ev.results.pairs[r]["movement"]) for r in ev.rows})


def power_rows(checks, movements: int) -> list[dict]:
    """How many movements like ours (``movements`` today) the pooled intervals would need to
    decide each inconclusive check of :data:`POWER_CLAIMS` (rows of :data:`POWER_COLUMNS`).

    An interval narrows about as ``1 / sqrt(K)``: with the estimate fixed, the end on the
    threshold's side clears it at ``K' = K * (h / |estimate - threshold|) ** 2``, ``h`` that
    end's distance from the estimate. A rough guide, not a power analysis.

    Notebook: 12_claims.ipynb
    """
    out = []
    for c in checks:
        if c["body"] != "all" or c["claim"] not in POWER_CLAIMS or c["verdict"] != R.INCONCLUSIVE:
            continue
        if c["low"] == "":  # a point check (a part not comparable is never inconclusive)
            continue
        est, lo, hi, t = (float(c[k]) for k in ("estimate", "low", "high", "threshold"))
        above = c["relation"].startswith(">")
        gap = est - t
        if gap == 0 or not np.isfinite(gap):
            need, to = float("inf"), "neither (the estimate is on the threshold)"
        else:
            h = (est - lo) if gap > 0 else (hi - est)  # the end between estimate and threshold
            need = movements * (h / abs(gap)) ** 2
            to = "hold" if (gap > 0) == above else "be contradicted"
        out.append(
            {k: c[k] for k in POWER_COLUMNS[:9]}
            | dict(movements=movements,
                   movements_needed=int(np.ceil(need - 1e-9)) if np.isfinite(need) else "never",
                   to=to)
        )  # fmt: skip
    return out


#: The other readings :func:`format_claims` shows where they change ours or the verdict.
_READINGS = (("literal", "with Method C's literal window: "),
             ("plugin", "with OPW read as the authors' plugin does it: "))  # fmt: skip


def format_claims(rows, stable=None) -> str:
    """The claims as text (``stable``: True only the deterministic rows, False only the
    timing rows, None all).

    Notebook: 06_fig5_fig6_scores.ipynb
    """

    def fill(text, label):
        return textwrap.fill(str(text), 96, initial_indent="    " + label,
                             subsequent_indent=" " * 12)  # fmt: skip

    out = []
    for r in rows:
        if stable is not None and bool(r.get("stable", True)) != stable:
            continue
        lines = [textwrap.fill(f"[{r['id']}] {r['claim']}", 96, subsequent_indent="    ")]
        lines.append(fill(r["paper"], "paper:  "))
        lines.append(fill(r["ours"], "ours:   "))
        lines.append(fill(f"{r['holds']}: {r['reason']}", "holds?  "))
        if r.get("interval"):
            lines.append(fill(r["interval"], "95 %:   "))
        bodies = [
            f"{k.replace('_', ' ')} {r[f'holds_{k}']}"
            for k in T.OTHER_EVIDENCE
            if r.get(f"holds_{k}", R.NA) != R.NA
        ]
        if bodies:
            lines.append(fill("; ".join(bodies), "also:   "))
        if r.get("robustness") and not str(r["robustness"]).startswith(("n/a", "not computed")):
            lines.append(fill(r["robustness"], "robust: "))
        for key, label in _READINGS:
            ours = r.get(f"ours_{key}", R.NA)
            if ours != R.NA and (ours, r[f"holds_{key}"]) != (r["ours"], r["holds"]):
                lines.append(fill(f"{ours}; holds? {r[f'holds_{key}']}", label))
        out.append("\n".join(lines))
    return "\n".join(out) if out else "(no claims)"


def format_parts(parts) -> str:
    """The parts table as text: one line per part, its verdicts on other bodies where they differ.

    Notebook: 12_claims.ipynb
    """
    out = []
    for p in parts:
        est, lo, hi = p["estimate"], p["ci_low"], p["ci_high"]
        ci = "" if lo is None else f" [{lo:.4g}, {hi:.4g}]"
        num = "" if est is None else f" | {est:.4g}{ci} vs {p['threshold']:g}"
        other = [f"{k.replace('_', ' ')}: {p[f'verdict_{k}']}"
                 for k in (*T.OTHER_EVIDENCE, "literal", T.OPW_PLUGIN)
                 if p[f"verdict_{k}"] not in (R.NA, p["verdict"])]  # fmt: skip
        line = f"{p['part']:4s} {p['verdict']:14s} {p['text']}{num}"
        if other:
            line += " (" + "; ".join(other) + ")"
        out.append(textwrap.fill(line, 110, subsequent_indent=" " * 20))
    return "\n".join(out) if out else "(no parts)"


def claims_summary(rows) -> str:
    """How many claims get each verdict, one line per body: ``"headline ...: yes 6, ..."``.

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
        counts = ", ".join(f"{v} {got.count(v)}" for v in R.CLAIM_VERDICTS[:-1])
        lines.append(f"{label}: {counts} (of {len(got)} claims decided)")
    return "\n".join(lines)


#: The bodies of the short table's "A / H / S" column.
AHS = ("authors_fbx", "hdm05", "paper_shaped")
#: Columns of ``figures/claims.md``, the short table (``claims.csv`` keeps every column).
SHORT_COLUMNS = ("id", "claim", "paper", "ours", "verdict", "movements fixed", "A / H / S",
                 "other eq. 2", "parts")  # fmt: skip


def short_rows(rows, parts=None) -> list[dict]:
    """The short claims table (:data:`SHORT_COLUMNS`; A: the authors' FBX takes, H: HDM05, S:
    the paper-shaped selection).

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


def save_claims(rows, mode="full", parts=None, meta=None, checks=None, power=None):
    """Write ``claims.csv|md`` and, when given, ``claims_intervals`` (``parts``),
    ``claims_checks`` and ``claims_power``, then ``results/<mode>/claims.json``; returns the
    paths written.

    Notebook: 12_claims.ipynb
    """
    # which question each resampling answers, and the seeds (under every claims table)
    boot = (
        f"Intervals: {bs.N_RESAMPLES} resamples of a two-stage cluster bootstrap (seed "
        f"{bs.SEED}; second seed {bs.SEED + T.SEED2_OFFSET}). The verdict resamples movements "
        "within each dataset, then motions within each movement: it answers 'would this hold "
        "for other movements like these, recorded again?'. 'Movements fixed' resamples the "
        "motions only: 'would it hold for other takes of these movements?'. Monte Carlo "
        f"errors of the interval ends: batch means over {bs.MC_BATCHES} batches."
    )
    note = (
        f"{R.RULE}\n\n{boot}\n\nComputed with {versions_line()}. The commit and the "
        "machine that made these figures: ENVIRONMENT.md. Every column: claims.csv; every "
        "check: claims_checks.csv; `python -m fpdtw.paper.claims verify figures/` recomputes "
        "every verdict from these files."
    )
    out = list(save_table(rows, "claims", columns=T.COLUMNS, note=note))
    md = to_markdown(short_rows(rows, parts), SHORT_COLUMNS) + f"\n{note}\n"
    out[1] = write_atomic(figures_dir() / "claims.md", md.encode())
    if parts is not None:
        out += save_table(parts, "claims_intervals", columns=T.PART_COLUMNS, note=boot,
                          csvfmt=".17g")  # fmt: skip
    if checks is not None:
        out += save_table(checks, "claims_checks", columns=T.CHECK_COLUMNS, csvfmt=".17g",
                          floatfmt=".4g", note=f"{R.RULE}\n\n{boot}")  # fmt: skip
    if power is not None:
        out += save_table(power, "claims_power", columns=POWER_COLUMNS, note=(
            "How many movements like ours the pooled interval of each inconclusive check of "
            "claims 1 and 3 would need to decide it, if its estimate stayed where it is and "
            "the interval narrowed as 1/sqrt(movements) (fpdtw.paper.claims.report.power_rows)."
        ))  # fmt: skip
    boot_meta = dict(resamples=bs.N_RESAMPLES, seed=bs.SEED, seed2=bs.SEED + T.SEED2_OFFSET)
    boot_meta |= dict(level=bs.LEVEL, schemes=bs.SCHEMES)
    doc = dict(mode=mode, claims=rows, parts=parts or [], bootstrap=boot_meta) | (meta or {})
    text = json.dumps(doc, indent=1, default=float) + "\n"
    out.append(write_atomic(results_dir() / mode / "claims.json", text.encode()))
    return out
