"""Every verdict again, from the committed files alone.

``python -m fpdtw.paper.claims verify figures/`` rebuilds every check of
``claims_checks.csv``, decides each check, part and claim by :mod:`fpdtw.paper.claims.rules`
and compares them with ``claims_intervals.csv`` (parts) and ``claims.csv`` (claims); no
results, no bootstrap are read. It exits 1 and names every disagreement.

Paper: FP-DTW Section 5 (the benchmarks); OPW poster Section 5.
Notebook: 12_claims.ipynb
"""

from __future__ import annotations

import argparse
import csv
import sys
from pathlib import Path

from fpdtw.paper.claims import rules as R
from fpdtw.paper.claims.evaluation import seed_verdict
from fpdtw.paper.claims.types import BODIES, PART_COLUMNS

#: claims_intervals.csv's column of each body's part verdict.
PART_COLUMN = {b: f"verdict_{b}" for b in BODIES if f"verdict_{b}" in PART_COLUMNS}
PART_COLUMN["all"] = "verdict"
#: claims.csv's column of each body's claim verdict.
CLAIM_COLUMN = {"all": "holds"} | {b: f"holds_{b}" for b in BODIES if b != "all"}


def _read(path: Path) -> list[dict]:
    with path.open(newline="", encoding="utf-8") as f:
        return list(csv.DictReader(f))


def check_from_row(row: dict) -> R.Check:
    """The :class:`~fpdtw.paper.claims.rules.Check` of one row of ``claims_checks.csv``."""
    rel = row["relation"]
    if rel not in (">", ">=", "<", "<="):
        raise ValueError(f"check {row['part']}#{row['check']}: relation {rel!r}")
    est, lo, hi, t = (float(row[k] or "nan") for k in ("estimate", "low", "high", "threshold"))
    kw = dict(above=rel.startswith(">"), interval=row["interval"] == "True", strict=len(rel) == 1)
    return R.Check(row["quantity"], est, lo, hi, t, **kw)


def part_verdicts(checks: list[dict]) -> tuple[dict, list[str]]:
    """Each (body, claim, part)'s verdict recomputed from its check rows, and the check rows
    whose stored verdict disagrees."""
    groups: dict = {}
    for row in checks:
        groups.setdefault((row["body"], row["claim"], row["part"]), []).append(row)
    out, bad = {}, []
    for key, rows in groups.items():
        if len(rows) == 1 and rows[0]["check"] == "0":
            out[key] = R.NOT_COMPARABLE
            continue
        by_number = {}
        for row in rows:
            c = check_from_row(row)
            if c.verdict != row["verdict"]:
                bad.append(f"{key[0]} {key[2]} check {row['check']}: stored {row['verdict']!r}, "
                           f"recomputed {c.verdict!r}")  # fmt: skip
            by_number[int(row["check"])] = c
        out[key] = R.evaluate(R.parse_formula(rows[0]["formula"], by_number))
    return out, bad


def verify(folder) -> list[str]:
    """Every disagreement between the verdicts stored in ``folder`` and those recomputed."""
    folder = Path(folder)
    claims = _read(folder / "claims.csv")
    parts = _read(folder / "claims_intervals.csv")
    got, problems = part_verdicts(_read(folder / "claims_checks.csv"))
    by_claim: dict = {}
    for p in parts:
        by_claim.setdefault(p["claim"], []).append(p)
    for body in BODIES:
        for claim in claims:
            cid = claim["id"]
            verdicts = []
            for p in by_claim.get(cid, []):
                label = p["part"]
                v = got.get((body, cid, label))
                if body == "all" and v is not None:
                    v = seed_verdict(v, got.get(("seed2", cid, label)))
                if v is None:
                    continue
                verdicts.append(v)
                stored = p.get(PART_COLUMN[body]) if body in PART_COLUMN else None
                if stored is not None and stored != v:
                    problems.append(f"{body} {label}: stored {stored!r}, recomputed {v!r}")
            want = R.claim_verdict(verdicts)
            have = claim.get(CLAIM_COLUMN[body], R.NA)
            if claim["holds"] == R.NA and body == "all" and not verdicts:
                continue
            if have != want:
                problems.append(f"{body} claim {cid}: stored {have!r}, recomputed {want!r}")
    return problems


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m fpdtw.paper.claims", description=__doc__)
    sub = ap.add_subparsers(dest="command", required=True)
    v = sub.add_parser("verify", help="recompute every verdict from the committed files")
    v.add_argument("folder", nargs="?", default="figures")
    a = ap.parse_args(argv)
    folder = Path(a.folder)
    files = ("claims.csv", "claims_intervals.csv", "claims_checks.csv")
    if missing := [n for n in files if not (folder / n).is_file()]:
        print(f"{folder}: no {', '.join(missing)} (make figures writes them)", file=sys.stderr)
        return 2
    if problems := verify(folder):
        print(f"{len(problems)} verdicts do not recompute from {folder}:")
        print("\n".join(f"  {p}" for p in problems))
        return 1
    n_claims, n_parts, n_checks = (len(_read(folder / n)) for n in files)
    print(f"every verdict recomputes from {folder}: {n_checks} checks, {n_parts} parts, "
          f"{n_claims} claims on {len(BODIES)} bodies of evidence")  # fmt: skip
    return 0
