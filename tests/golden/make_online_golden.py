"""Regenerate tests/golden/online_squat1Reps_bd001_bd002.json (run explicitly, never by pytest).

Usage (from the repository root)::

    FPDTW_MIRROR=../shared/data .venv/bin/python tests/golden/make_online_golden.py

The file pins the map of every online algorithm of the paper (OE-DTW, Ma, Mb and Mc
at w 10/20/40/80, each with and without Type V), of Method C's literal window at every
w and of every other reading of Algorithm 3 at w 40 (:data:`GOLDEN_NAMES`) on one real
HDM05 pair (squat1Reps, actor bd, takes 001 -> 002). Regenerate only after a deliberate
change and review the diff.
"""

from __future__ import annotations

import sys
from pathlib import Path

from golden_io import write_golden

OUT = Path(__file__).with_name("online_squat1Reps_bd001_bd002.json")
PAIR = (
    "HDM05_cut_amc/squat1Reps/HDM_bd_squat1Reps_001_120.amc",
    "HDM05_cut_amc/squat1Reps/HDM_bd_squat1Reps_002_120.amc",
)


def golden_names() -> list:
    """Every online algorithm the golden file pins."""
    from fpdtw.paper.numbers import PAPER_NAMES
    from fpdtw.paper.runner.grid import MC_LITERAL_NAMES
    from fpdtw.registry import C_READINGS, method_c_name

    names = [n for n in PAPER_NAMES if n not in ("DTW", "UTW")] + list(MC_LITERAL_NAMES)
    for reading in C_READINGS[2:]:
        names += [method_c_name(40, reading, t) for t in (False, True)]
    return names


def make() -> dict:
    from fpdtw.motion.features import MotionFeatures
    from fpdtw.paper import catalog
    from fpdtw.registry import align

    I, T = (MotionFeatures.from_motion(catalog.load("hdm05", p)) for p in PAIR)
    record = {"input": PAIR[0], "target": PAIR[1]}
    for name in golden_names():
        record[name] = align(name, I, T)[0].tolist()
    return record


def main() -> int:
    record = make()
    return write_golden(record, OUT)


if __name__ == "__main__":
    sys.exit(main())
