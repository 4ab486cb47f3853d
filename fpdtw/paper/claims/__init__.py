"""The papers' claims, checked against our results: parts, intervals, verdicts.

* :mod:`~fpdtw.paper.claims.rules`: the one set of rules (checks, parts, claim verdicts);
* :mod:`~fpdtw.paper.claims.bootstrap`: intervals for medians over pairs that share motions;
* :mod:`~fpdtw.paper.claims.evidence`: per-pair values, medians and checks of a run;
* :mod:`~fpdtw.paper.claims.table`: the claims, split into parts, and the table;
* :mod:`~fpdtw.paper.claims.robustness`: each verdict under the documented readings.
"""

from fpdtw.paper.claims.open import QUESTION_IDS
from fpdtw.paper.claims.rules import LEGEND
from fpdtw.paper.claims.table import (
    CLAIMS,
    COLUMNS,
    FIG8_JSON,
    OPW_FIG4_JSON,
    OPW_FIG56_JSON,
    PART_COLUMNS,
    READINGS,
    Assessment,
    Claim,
    ClaimContext,
    build_claims,
    claim_contexts,
    claim_rows,
    claims_by_id,
    claims_summary,
    data_counts,
    evaluate_claims,
    format_claims,
    format_parts,
    oedtw_backward_jumps,
    opw_reading,
    paper_shaped_rows,
    reading_alias,
    save_claims,
)

__all__ = [
    "CLAIMS",
    "COLUMNS",
    "FIG8_JSON",
    "LEGEND",
    "OPW_FIG4_JSON",
    "OPW_FIG56_JSON",
    "PART_COLUMNS",
    "QUESTION_IDS",
    "READINGS",
    "Assessment",
    "Claim",
    "ClaimContext",
    "build_claims",
    "claim_contexts",
    "claim_rows",
    "claims_by_id",
    "claims_summary",
    "data_counts",
    "evaluate_claims",
    "format_claims",
    "format_parts",
    "oedtw_backward_jumps",
    "opw_reading",
    "paper_shaped_rows",
    "reading_alias",
    "save_claims",
]
