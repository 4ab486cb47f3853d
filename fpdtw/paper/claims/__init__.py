"""The papers' claims, checked against our results: parts, intervals, verdicts.

Bottom to top (a module imports only those before it): rules, bootstrap, evidence, types,
open (the Q rows), paper_claims, contexts, robustness, evaluation, report and verify.
"""

from fpdtw.paper.claims.contexts import claim_contexts, data_counts, load_context, open_evidence
from fpdtw.paper.claims.evaluation import build_claims, claim_rows, evaluate_claims, open_claim_rows
from fpdtw.paper.claims.open import QUESTION_IDS, open_mode
from fpdtw.paper.claims.paper_claims import CLAIMS, claims_by_id
from fpdtw.paper.claims.report import (
    SHORT_COLUMNS,
    claims_summary,
    format_claims,
    format_parts,
    movement_count,
    power_rows,
    save_claims,
    short_rows,
)
from fpdtw.paper.claims.rules import RULE
from fpdtw.paper.claims.types import COLUMNS, PART_COLUMNS, Claim, ClaimContext

__all__ = [
    "CLAIMS", "COLUMNS", "PART_COLUMNS", "QUESTION_IDS", "RULE", "SHORT_COLUMNS", "Claim",
    "ClaimContext", "build_claims", "claim_contexts", "claim_rows", "claims_by_id",
    "claims_summary", "data_counts", "evaluate_claims", "format_claims", "format_parts",
    "load_context", "movement_count", "open_claim_rows", "open_evidence", "open_mode",
    "power_rows", "save_claims", "short_rows"
]  # fmt: skip
