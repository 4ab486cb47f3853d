"""Measure what an optimisation of fpdtw/online/window.py pays: run in two checkouts.

Usage (from each checkout, e.g. one with the optimisation and one without, alternately)::

    taskset -c 1 .venv/bin/python tools/window_costs.py step > step.json
    .venv/bin/python tools/window_costs.py grid /tmp/grid-x > grid.json

``step``: make bench's median step time and step/limit (:func:`fpdtw.app.bench.bench_online`
with limits) of Methods A, B and C at w = 10, 40, 80 on make bench's pairs.
The same file runs in a checkout from before the redesign (693a34e): copy it there.
``grid``: the experiment grid's compute time (the sum of its work units' seconds, two
workers) for every default algorithm on 316 pairs (five takes per movement of the full
selection, the paper-shaped seed), in a fresh results folder.
"""

from __future__ import annotations

import json
import os
import sys


def step() -> dict:
    try:
        from fpdtw.app.bench import bench_online, load_bench_pairs
    except ImportError:  # a checkout from before the tools moved to fpdtw/app (693a34e)
        from fpdtw.paper.bench import bench_online, load_bench_pairs

    names = ["Ma", "Mb w10", "Mb w40", "Mb w80", "Mc w10", "Mc w40", "Mc w80", "Mc w80 + Type V"]
    rows = bench_online(load_bench_pairs(), names, limits=True)
    return {
        r["name"]: {
            "step_us": 1e6 * (r.get("step_median_s") or r["median_s"]),
            "step_over_limit": r.get("step_over_limit"),
        }
        for r in rows
    }


def grid(folder: str) -> dict:
    os.environ["FPDTW_RESULTS_DIR"] = folder
    from fpdtw.paper.runner import run as E

    try:
        from fpdtw.paper.runner.grid import default_algorithms
    except ImportError:  # before the registry fed the grid (693a34e)
        from fpdtw.paper.runner.grid import DEFAULT_ALGORITHMS

        def default_algorithms():
            return DEFAULT_ALGORITHMS

    from fpdtw.paper.runner.selection import PAPER_SHAPED_SEED, Selection

    sel = Selection(subsample_takes=5, sample_seed=PAPER_SHAPED_SEED)
    res = E.run_experiments("grid", list(default_algorithms()), n_jobs=2, selection=sel)
    run = json.loads((res.folder / "run.json").read_text())
    return {"pairs": len(res.pairs), "unit_seconds": run["computed"]["unit_seconds"]}


if __name__ == "__main__":
    what = sys.argv[1] if len(sys.argv) > 1 else "step"
    print(json.dumps(step() if what == "step" else grid(sys.argv[2])))
