"""The papers' claims, checked against our results: parts, intervals, verdicts.

* :mod:`~fpdtw.paper.claims.rules`: the one set of rules (checks, parts, claim verdicts);
* :mod:`~fpdtw.paper.claims.bootstrap`: intervals for medians over pairs that share motions;
* :mod:`~fpdtw.paper.claims.evidence`: per-pair values, medians and checks of a run;
* :mod:`~fpdtw.paper.claims.table`: the claims, split into parts, and the table;
* :mod:`~fpdtw.paper.claims.robustness`: each verdict under the documented readings;
* :mod:`~fpdtw.paper.claims.verify`: every verdict again from the committed files
  (``python -m fpdtw.paper.claims verify figures/``).
"""

from fpdtw.paper.claims.open import QUESTION_IDS
from fpdtw.paper.claims.rules import LEGEND, RULE
from fpdtw.paper.claims.table import (
    BODIES,
    CHECK_COLUMNS,
    CLAIMS,
    COLUMNS,
    FIG8_JSON,
    OPW_FIG4_JSON,
    OPW_FIG56_JSON,
    PART_COLUMNS,
    POWER_COLUMNS,
    READINGS,
    SHORT,
    SHORT_COLUMNS,
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
    movement_count,
    oedtw_backward_jumps,
    opw_reading,
    paper_shaped_rows,
    power_rows,
    reading_alias,
    save_claims,
    short_rows,
)

__all__ = [
    "BODIES",
    "CHECK_COLUMNS",
    "CLAIMS",
    "COLUMNS",
    "FIG8_JSON",
    "LEGEND",
    "OPW_FIG4_JSON",
    "OPW_FIG56_JSON",
    "PART_COLUMNS",
    "POWER_COLUMNS",
    "QUESTION_IDS",
    "READINGS",
    "RULE",
    "SHORT",
    "SHORT_COLUMNS",
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
    "movement_count",
    "oedtw_backward_jumps",
    "opw_reading",
    "paper_shaped_rows",
    "power_rows",
    "reading_alias",
    "save_claims",
    "short_rows",
]
