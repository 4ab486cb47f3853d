"""Regenerate tests/golden/online_squat1Reps_bd001_bd002.json (run explicitly, never by pytest).

Usage (from the repository root)::

    FPDTW_MIRROR=../shared/data .venv/bin/python tests/golden/make_online_golden.py

The file pins the map of every online algorithm of the paper (OE-DTW, Ma, Mb and Mc
at w 10/20/40/80, each with and without Type V) on one real HDM05 pair (squat1Reps,
actor bd, takes 001 -> 002). Regenerate only after a deliberate change and review the
diff.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

OUT = Path(__file__).with_name("online_squat1Reps_bd001_bd002.json")
PAIR = (
    "HDM05_cut_amc/squat1Reps/HDM_bd_squat1Reps_001_120.amc",
    "HDM05_cut_amc/squat1Reps/HDM_bd_squat1Reps_002_120.amc",
)


def make() -> dict:
    from fpdtw import catalog
    from fpdtw.algorithms import PAPER_NAMES, align
    from fpdtw.features import MotionFeatures

    I, T = (MotionFeatures.from_motion(catalog.load("hdm05", p)) for p in PAIR)
    record = {"input": PAIR[0], "target": PAIR[1]}
    for name in PAPER_NAMES:
        if name not in ("DTW", "UTW"):
            record[name] = align(name, I, T)[0].tolist()
    return record


def main() -> int:
    record = make()
    lines = [f" {json.dumps(k)}: {json.dumps(v)}" for k, v in record.items()]
    OUT.write_text("{\n" + ",\n".join(lines) + "\n}\n")
    print(f"wrote {OUT}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
