"""Regenerate tests/golden/dtw_squat1Reps_bd001_bd002.json (run explicitly, never by pytest).

Usage (from the repository root)::

    FPDTW_MIRROR=../shared/data .venv/bin/python tests/golden/make_dtw_golden.py

The file pins, for one real HDM05 pair (squat1Reps, actor bd, takes 001 -> 002), the
offline DTW map and distance, the OE-DTW end points and the similarity (eq. 2) of the
DTW and UTW maps. Regenerate only after a deliberate change (e.g. to the readers or the
joint conventions) and review the diff.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

from golden_io import write_golden

OUT = Path(__file__).with_name("dtw_squat1Reps_bd001_bd002.json")
PAIR = (
    "hdm05/HDM05_cut_amc/squat1Reps/HDM_bd_squat1Reps_001_120.amc",
    "hdm05/HDM05_cut_amc/squat1Reps/HDM_bd_squat1Reps_002_120.amc",
)
STEP_PATTERN = "symmetric1"


def make(mirror: Path) -> dict:
    """Compute the golden record from the mirror folder ``mirror``."""
    from fpdtw.dtw import dtw_pair, utw_map
    from fpdtw.io import load_motion
    from fpdtw.metrics import similarity
    from fpdtw.motion.features import MotionFeatures
    from fpdtw.online.base import run_online
    from fpdtw.online.oedtw import OEDTW

    I = MotionFeatures.from_motion(load_motion(mirror / PAIR[0]))
    T = MotionFeatures.from_motion(load_motion(mirror / PAIR[1]))
    r = dtw_pair(I, T, STEP_PATTERN)
    M_oe, _ = run_online(OEDTW(I, STEP_PATTERN), T)
    m, n = I.n_frames - 1, T.n_frames - 1
    return {
        "input": PAIR[0],
        "target": PAIR[1],
        "step_pattern": STEP_PATTERN,
        "m": m,
        "n": n,
        "distance": r.distance,
        "dtw_map": r.map.tolist(),
        "oedtw_end_points": M_oe.tolist(),
        "similarity_dtw": similarity(I.quats, T.quats, r.map),
        "similarity_utw": similarity(I.quats, T.quats, utw_map(m, n)),
    }


def main() -> int:
    mirror = os.environ.get("FPDTW_MIRROR", "").strip()
    if not mirror or not Path(mirror).is_dir():
        print("set FPDTW_MIRROR to the local data mirror folder", file=sys.stderr)
        return 2
    record = make(Path(mirror))
    return write_golden(record, OUT)


if __name__ == "__main__":
    sys.exit(main())
