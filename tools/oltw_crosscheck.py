"""Run pymatchmaker's OLTW-Dixon on a simple case and store its decisions as a golden file.

Run it with a SEPARATE environment that has pymatchmaker (it needs numpy < 2), never the
project's .venv::

    python3 -m venv /tmp/pmm && /tmp/pmm/bin/pip install "numpy<2" pymatchmaker
    /tmp/pmm/bin/python tools/oltw_crosscheck.py

It writes ``tests/golden/oltw_pymatchmaker.json``; ``tests/test_oltw.py`` replays the
same inputs through :class:`fpdtw.online.oltw.OLTW` and compares every decision, without
pymatchmaker. This script does not import fpdtw.

The case. A smooth 1-D reference ``x`` (200 frames) and a live sequence ``y`` that shows
``x`` at known warped times (slope 1, then 0.6, then 1.5, then 1; linear interpolation),
ending at reference frame ~150 so that pymatchmaker never runs out of reference.
pymatchmaker compares frames by scipy's Euclidean distance ``|x_a - y_b|``; fpdtw
compares them by the geodesic distance (eq. 1) of one joint rotated about X by
``pi * x`` radians, which is exactly ``|x_a - y_b|`` while ``|x_a - y_b| <= 1``. So both
accumulate the same local costs (to rounding; pymatchmaker stores its accumulated costs
in float32).

What is compared. pymatchmaker's frame tracker (``OnlineTimeWarpingDixonFrame``) and
fpdtw's OLTW share the band (``w = c`` cells), the DTW recursion (diagonal weight 2), the
normalised argmin over the newest row and column (divided by ``1 + i + j``, ties: first
strict minimum, newest live column first) and the order in which rows and columns are
added. They differ in two rules, so the case is chosen where neither matters and fpdtw
is run with ``warmup=False``:

* Dixon's start rule (BOTH while ``t < c``): pymatchmaker has none.
* The run-count rule: pymatchmaker forces the other direction after ``max_run_count``
  equal increments (``>=``, and BOTH counts as an input step), fpdtw after more than
  ``MaxRunCount`` (``>``, BOTH resets the count as in Dixon's pseudocode). The script
  records whether pymatchmaker forced any decision; in this case it does not, and then
  fpdtw's weaker rule cannot force one either (fpdtw's test checks that too).
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

OUT = Path(__file__).resolve().parent.parent / "tests" / "golden" / "oltw_pymatchmaker.json"

C = 20  # band (pymatchmaker: window_size * frame_rate frames)
MAX_RUN = 3
N_REF = 200


def reference_signal(n):
    i = np.arange(n, dtype=float)
    return 0.3 * np.sin(2 * np.pi * i / 47.0) + 0.12 * np.sin(2 * np.pi * i / 13.0 + 1.0)


def warped_times():
    """Reference time (frames) shown by each live frame: slopes 1, 0.6, 1.5, 1."""
    slopes = [1.0] * 30 + [0.6] * 50 + [1.5] * 40 + [1.0] * 30
    return np.concatenate([[0.0], np.cumsum(slopes)])


def main() -> int:
    import matchmaker
    from matchmaker.dp.oltw_dixon import Direction, OnlineTimeWarpingDixonFrame

    x = reference_signal(N_REF)
    s = warped_times()
    y = np.interp(s, np.arange(N_REF), x)
    code = {Direction.TARGET: 1, Direction.REF: 2, Direction.BOTH: 3}

    class Logged(OnlineTimeWarpingDixonFrame):
        log: list

        def _determine_direction(self):
            suggested = self._get_expand_direction()  # also sets best_ref / best_input
            d = super()._determine_direction()
            self.log.append(
                [
                    int(self.ref_pointer - 1),  # corner: input (reference) frame
                    int(self.input_pointer - 1),  # corner: live (target) frame
                    code[d],
                    int(d != suggested),  # forced by the run-count rule
                    int(self.best_ref),
                    int(self.best_input),
                ]
            )
            return d

    a = Logged(
        x[:, None],
        np.arange(N_REF, dtype=float),
        window_size=C,
        frame_rate=1,
        max_run_count=MAX_RUN,
        ref_frame_to_beat=np.arange(N_REF, dtype=float),
    )
    a.log = []
    positions = []
    for q, v in enumerate(y):
        steps = len(a.log)
        a(np.array([v]), float(q))
        if not a.is_still_following():
            print(f"pymatchmaker ran out of reference at live frame {q}", file=sys.stderr)
            return 1
        positions.append([int(a.best_ref), int(a.best_input), len(a.log) - steps])
    forced = sum(row[3] for row in a.log)
    golden = {
        "what": "pymatchmaker OnlineTimeWarpingDixonFrame decisions on a 1-D warped sequence",
        "made_by": "tools/oltw_crosscheck.py",
        "pymatchmaker": getattr(matchmaker, "__version__", "0.3.0"),
        "numpy": np.__version__,
        "params": {"c": C, "max_run_count": MAX_RUN, "distance": "euclidean"},
        "x": x.tolist(),
        "y": y.tolist(),
        "warp": s.tolist(),
        "decision_columns": ["i", "q", "increment", "forced", "best_i", "best_q"],
        "increment_codes": {"1": "target (new live frame)", "2": "input", "3": "both"},
        "decisions": a.log,
        "forced_decisions": forced,
        "per_frame_argmin": positions,
        "final_corner": [int(a.ref_pointer - 1), int(a.input_pointer - 1)],
    }
    OUT.write_text(json.dumps(golden, indent=None, separators=(",", ":")) + "\n")
    print(
        f"{len(a.log)} decisions over {len(y)} live frames, {forced} forced by the run count; "
        f"final corner {golden['final_corner']}; wrote {OUT}"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
