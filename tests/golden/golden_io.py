"""Write a golden record the way both golden scripts do (one key per line, lists on one
line: small, reviewable diffs)."""

from __future__ import annotations

import json
from pathlib import Path


def write_golden(record: dict, out: Path) -> int:
    """Write ``record`` to ``out`` as JSON, one key per line; print the path; return 0."""
    lines = [f" {json.dumps(k)}: {json.dumps(v)}" for k, v in record.items()]
    out.write_text("{\n" + ",\n".join(lines) + "\n}\n")
    print(f"wrote {out}")
    return 0
