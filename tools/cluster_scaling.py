"""Measure how the experiment grid scales: joblib and a Dask cluster, 1 and 2 workers.

Usage (from the checkout, with the project's environment)::

    .venv/bin/python tools/cluster_scaling.py [--mode smoke|full] [--out FILE]

Each configuration runs the whole grid of the mode from scratch into its own temporary
results folder (features and work units; nothing reused between configurations):

* ``joblib-1``, ``joblib-2``: joblib worker processes on this machine;
* ``dask-1``, ``dask-2``: a ``distributed.LocalCluster`` of that many worker processes
  (one thread each) on the loopback address, the run given its scheduler address.

For each it prints and records the wall time, the wall time of the units phase, pairs
per second (pair runs of every algorithm / units-phase seconds), the summed seconds the
units took inside their workers and the longest unit; and it checks that every run's
deterministic result files are byte-identical to the first run's. From the 2-worker Dask
run it estimates a 100-worker cluster: the units phase cannot be shorter than the longest
unit, nor than the summed unit time / 100, and each unit pays the per-unit overhead seen
here (units-phase wall x workers - summed unit seconds, divided by the units).

Writes a JSON record (default ``build/cluster_scaling_<mode>.json``).
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
import time
from pathlib import Path

from fpdtw.paper import provenance
from fpdtw.paper.runner import run as E


def result_bytes(folder: Path) -> dict:
    out = {p.name: p.read_bytes() for p in sorted((folder / "algorithms").glob("*.npz"))}
    for name in ("pairs.json", "summary.json"):
        out[name] = (folder / name).read_bytes()
    return out


def one_run(mode: str, config: str, root: Path) -> dict:
    kind, workers = config.split("-")
    workers = int(workers)
    t0 = time.perf_counter()
    if kind == "joblib":
        E.run_experiments(mode, n_jobs=workers, progress=True, results=root, scheduler="local")
    else:
        from distributed import LocalCluster

        with LocalCluster(
            n_workers=workers,
            threads_per_worker=1,
            processes=True,
            host="127.0.0.1",
            dashboard_address=None,
        ) as cluster:
            E.run_experiments(
                mode, progress=True, results=root, scheduler=cluster.scheduler_address
            )
    total = time.perf_counter() - t0
    run = json.loads((root / mode / "run.json").read_text())
    computed = run["computed"]
    units_s = run["phase_seconds"]["units"]
    return {
        "config": config,
        "workers": workers,
        "seconds_with_cluster_start": round(total, 1),
        "wall_seconds": run["wall_seconds"],
        "phase_seconds": run["phase_seconds"],
        "units": computed["units"],
        "pair_runs": computed["pair_runs"],
        "pairs_per_second": round(computed["pair_runs"] / units_s, 1),
        "unit_seconds_total": computed["unit_seconds"]["total"],
        "unit_seconds_max": computed["unit_seconds"]["max"],
    }


def estimate(row: dict, workers: int) -> dict:
    """The units phase on ``workers`` workers, from one measured run."""
    busy = row["phase_seconds"]["units"] * row["workers"]
    overhead = max(0.0, busy - row["unit_seconds_total"]) / row["units"]
    per_unit = row["unit_seconds_total"] / row["units"]
    bound = max(row["unit_seconds_max"], row["unit_seconds_total"] / workers)
    return {
        "workers": workers,
        "mean_unit_seconds": round(per_unit, 3),
        "overhead_seconds_per_unit": round(overhead, 3),
        "units_phase_seconds": round(bound + overhead * row["units"] / workers, 1),
        "note": "lower bound: the longest unit, or the summed unit time shared by the workers",
    }


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--mode", default="smoke", choices=("smoke", "full"))
    ap.add_argument("--configs", nargs="+", default=["joblib-1", "joblib-2", "dask-1", "dask-2"])
    ap.add_argument("--out", type=Path)
    args = ap.parse_args(argv)
    out = args.out or Path("build") / f"cluster_scaling_{args.mode}.json"
    rows, reference = [], None
    with tempfile.TemporaryDirectory(prefix="fpdtw-scaling-") as tmp:
        for config in args.configs:
            print(f"== {config}", file=sys.stderr, flush=True)
            root = Path(tmp) / config
            row = one_run(args.mode, config, root)
            got = result_bytes(root / args.mode)
            reference = reference or got
            row["same_bytes_as_first"] = got == reference
            rows.append(row)
            print(json.dumps(row), flush=True)
    record = {
        "mode": args.mode,
        "load_average_after": os.getloadavg(),
        "runs": rows,
        "environment": provenance.environment(),
    }
    dask2 = [r for r in rows if r["config"] == "dask-2"]
    if dask2:
        record["estimate_100_workers"] = estimate(dask2[0], 100)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps(record, indent=1) + "\n")
    print(f"{'config':10} {'wall s':>8} {'units s':>8} {'pairs/s':>8} {'same bytes':>10}")
    for r in rows:
        print(
            f"{r['config']:10} {r['wall_seconds']:8.1f} {r['phase_seconds']['units']:8.1f} "
            f"{r['pairs_per_second']:8.1f} {str(r['same_bytes_as_first']):>10}"
        )
    if dask2:
        print("100 workers (estimate):", json.dumps(record["estimate_100_workers"]))
    print(f"wrote {out}")
    return 0 if all(r["same_bytes_as_first"] for r in rows) else 1


if __name__ == "__main__":
    raise SystemExit(main())
