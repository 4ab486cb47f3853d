"""Per-frame latency of the online aligners (FP-DTW Table 2) and offline DTW throughput.

``make bench`` runs :func:`main`: on real pairs of the data here it times every online
aligner (Method A, Methods B and C at w = 10, 20, 40, 80, each with and without the
Type V constraint, and OE-DTW) frame by frame with
:func:`fpdtw.online.base.run_online`, after an untimed warm-up run over the same pairs
(numba compilation, caches), and reports the median and 95th percentile per frame. It
also times offline DTW (accumulation + path) in cells per second, writes everything to
``results/bench.json`` and prints our medians next to the paper's Table 2 (means on a
3.58-3.95 GHz core, C#/Unity-era implementation; we report medians, and means too).

The process is pinned to one core (``os.sched_setaffinity``) so that the numbers are
single-core numbers, as in the paper.
"""

from __future__ import annotations

import json
import os
import time

import numpy as np

from fpdtw.paper import provenance
from fpdtw.paper.numbers import TABLE2_US

#: Issue targets on one core of this machine (microseconds per frame, median).
TARGETS_US = {("A", 2): 3.0, ("B", 40): 40.0, ("C", 40): 40.0, ("B", 80): 150.0, ("C", 80): 150.0}

#: Real pairs timed by ``make bench``: (dataset, input path, target path).
BENCH_PAIRS = (
    ("authors_fbx", "MoCapData/Walk_01.fbx", "MoCapData/Walk_02.fbx"),
    ("authors_fbx", "MoCapData/Shelf_Stack_02.fbx", "MoCapData/Shelf_Stack_03.fbx"),
    (
        "hdm05",
        "HDM05_cut_amc/jogLeftCircle4StepsRstart/HDM_bd_jogLeftCircle4StepsRstart_001_120.amc",
        "HDM05_cut_amc/jogLeftCircle4StepsRstart/HDM_bk_jogLeftCircle4StepsRstart_003_120.amc",
    ),
)

#: OE-DTW is timed against an input of exactly this many frames (issue target).
OE_INPUT_FRAMES = 1000


def bench_names() -> list:
    """The online aligners ``make bench`` times, by name: Method A, Methods B and C (the
    default square window and the literal one) at every w, each with and without Type V.

    Notebook: 09_table2_timing.ipynb
    """
    from fpdtw.paper.numbers import FPDTW_NAMES, FPDTW_TYPEV_NAMES
    from fpdtw.paper.runner.grid import MC_LITERAL_NAMES

    return list(FPDTW_NAMES) + list(FPDTW_TYPEV_NAMES) + list(MC_LITERAL_NAMES)


def _name_key(name: str) -> tuple:
    from fpdtw.errors import AlignmentError
    from fpdtw.registry import resolve

    try:
        a = resolve(name)
    except AlignmentError:  # an aligner outside the registry: its name is its family
        return name, 0, False
    return a.family, a.value or 0, a.typev


def bench_online(pairs, names=None, make=None):
    """Median, 95th percentile and mean per-frame time of each online aligner.

    Parameters
    ----------
    pairs : sequence of (MotionFeatures, MotionFeatures)
        (input, target) pairs.
    names : sequence of str, optional
        FP-DTW configurations by name (default :func:`bench_names`).
    make : callable, optional
        ``make(I) -> OnlineAligner``, to time one other aligner instead of ``names``.

    Returns
    -------
    rows : list of dict
        Keys ``name``, ``method``, ``w``, ``typev``, ``frames`` (number timed),
        ``median_s``, ``p95_s``, ``mean_s`` (seconds per frame).

    Paper: FP-DTW Table 2.
    Notebook: 09_table2_timing.ipynb
    """
    from fpdtw.online.base import run_online
    from fpdtw.registry import make_online

    pairs = list(pairs)
    if not pairs:
        raise ValueError("no pairs to time")
    if make is not None:
        jobs = [(None, make)]
    else:
        jobs = [(n, lambda I, n=n: make_online(n, I)) for n in (names or bench_names())]
    rows = []
    for name, build in jobs:
        for I0, T0 in pairs:  # warm-up: compile, caches, branch predictors
            run_online(build(I0), T0)
        times = []
        for I, T in pairs:
            aligner = build(I)
            _, dt = run_online(aligner, T)
            times.append(dt)
        dt = np.concatenate(times)
        name = name or aligner.name
        method, w, typev = _name_key(name)
        rows.append(
            dict(
                name=name,
                method=method,
                w=int(w),
                typev=bool(typev),
                frames=int(dt.size),
                median_s=float(np.median(dt)),
                p95_s=float(np.percentile(dt, 95)),
                mean_s=float(dt.mean()),
            )
        )
    return rows


def format_bench(rows) -> str:
    """The rows of :func:`bench_online` as a text table in microseconds."""
    lines = [f"{'aligner':<20} {'median us':>10} {'p95 us':>10} {'mean us':>10} {'frames':>8}"]
    for r in rows:
        lines.append(
            f"{r['name']:<20} {r['median_s'] * 1e6:10.2f} {r['p95_s'] * 1e6:10.2f} "
            f"{r['mean_s'] * 1e6:10.2f} {r['frames']:8d}"
        )
    return "\n".join(lines)


def dtw_throughput(C, repeats=5):
    """Offline DTW speed: accumulated cost + path, cells per second (median of runs).

    Parameters
    ----------
    C : ndarray of float, shape (m, n)
        A cost matrix.
    repeats : int
        Timed runs after one warm-up run.

    Returns
    -------
    row : dict
        ``cells``, ``median_s``, ``cells_per_s``.
    """
    from fpdtw.dtw import dtw

    dtw(C)  # warm-up
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        dtw(C)
        times.append(time.perf_counter() - t0)
    med = float(np.median(times))
    return {"cells": int(C.size), "median_s": med, "cells_per_s": C.size / med}


def load_bench_pairs(seconds=None):
    """The real (input, target) feature pairs of :data:`BENCH_PAIRS` (fetched, verified).

    Parameters
    ----------
    seconds : float, optional
        Crop every motion to its first seconds (a quick run, e.g. the smoke notebooks).

    Notebook: 09_table2_timing.ipynb
    """
    from fpdtw.motion.features import MotionFeatures
    from fpdtw.motion.joints import OPW_JOINTS
    from fpdtw.paper.catalog import load

    pairs = []
    for ds, a, b in BENCH_PAIRS:
        motions = [load(ds, p) for p in (a, b)]
        if seconds is not None:
            motions = [m.crop(0.0, seconds) for m in motions]
        pairs.append(
            tuple(MotionFeatures.from_motion(m, position_joints=OPW_JOINTS) for m in motions)
        )
    return pairs


def _us(row, key="median_s") -> str:
    return "-" if row is None else f"{row[key] * 1e6:.1f}"


def paper_comparison(rows) -> str:
    """Our median (and mean) per-frame time next to the paper's Table 2, as text.

    Method C's literal window (notebook 15) gets its own column.
    """
    by = {(r["method"], r["w"], r["typev"]): r for r in rows if "(" not in r["name"]}
    literal = {r["w"]: r for r in rows if "(literal window)" in r["name"] and not r["typev"]}
    head = ("", "w", "paper", "ours med", "ours mean", "+TypeV med", "literal med", "target")
    lines = [
        "Per-frame time, microseconds (paper: mean, Table 2; ours: median / mean, one core)",
        "{:<10}{:>5}{:>10}{:>10}{:>11}{:>12}{:>13}{:>8}".format(*head),
    ]
    labels = (
        ("A", "Method A"),
        ("B", "Method B"),
        ("C", "Method C"),
        ("OE", "OE-DTW"),
        ("OLTW", "OLTW"),
        ("OPW", "OPW"),
    )
    single = {"A": 2, "OE": 0, "OLTW": 0, "OPW": 0}
    for method, label in labels:
        for w in (single[method],) if method in single else (10, 20, 40, 80):
            r = by.get((method, w, False))
            if r is None:
                continue
            paper = TABLE2_US.get((method, w))
            target = TARGETS_US.get((method, w), 10.0 if method == "OE" else None)
            cells = (
                label,
                "-" if method in single else str(w),
                "-" if paper is None else f"{paper:.0f}",
                _us(r),
                _us(r, "mean_s"),
                _us(by.get((method, w, True))),
                _us(literal.get(w)) if method == "C" else "-",
                "-" if target is None else f"{target:g}",
            )
            lines.append("{:<10}{:>5}{:>10}{:>10}{:>11}{:>12}{:>13}{:>8}".format(*cells))
    return "\n".join(lines)


def run_benchmark(pairs=None, out=None, single_core=True):
    """Time everything ``make bench`` reports and write ``results/bench.json``.

    Returns
    -------
    report : dict
        ``environment`` (:func:`fpdtw.paper.provenance.environment`), ``single_core``,
        ``pairs``, ``online`` (rows of :func:`bench_online`), ``oe_dtw`` (OE-DTW against
        a 1000-frame input) and ``dtw`` (offline throughput).

    Paper: FP-DTW Table 2.
    Notebook: 09_table2_timing.ipynb
    """
    from fpdtw.costs import geodesic_cost_matrix
    from fpdtw.paper.paths import results_dir

    if single_core and hasattr(os, "sched_setaffinity"):
        os.sched_setaffinity(0, {sorted(os.sched_getaffinity(0))[0]})
    pairs = load_bench_pairs() if pairs is None else pairs

    online = bench_online(pairs)
    online += bench_online(pairs, ["OLTW"])
    if all(I.positions is not None and T.positions is not None for I, T in pairs):
        online += bench_online(pairs, ["OPW"])
    # OE-DTW against an input of exactly OE_INPUT_FRAMES frames (the longest input cropped)
    I_long, T_long = max(pairs, key=lambda p: p[0].n_frames)
    reps = -(-OE_INPUT_FRAMES // I_long.n_frames)
    I_oe = I_long if reps == 1 else _concat([I_long] * reps)
    I_oe = I_oe.slice(0, OE_INPUT_FRAMES)
    oe = bench_online([(I_oe, T_long)], ["OE-DTW"])
    # offline DTW on the largest real cost matrix
    I_big, T_big = max(pairs, key=lambda p: p[0].n_frames * p[1].n_frames)
    C = geodesic_cost_matrix(I_big.quats, T_big.quats)
    offline = dtw_throughput(C)
    report = {
        "environment": provenance.environment(),
        "single_core": bool(single_core),
        "pairs": [f"{I.name} -> {T.name} ({I.n_frames} x {T.n_frames})" for I, T in pairs],
        "online": online,
        "oe_dtw": oe,
        "dtw": offline,
        "paper_table2_us": {f"{m} w{w}": v for (m, w), v in TABLE2_US.items()},
    }
    out = results_dir() / "bench.json" if out is None else out
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = out.with_suffix(".json.part")
    tmp.write_text(json.dumps(report, indent=1) + "\n")
    os.replace(tmp, out)
    return report


def _concat(features):
    from fpdtw.motion.features import MotionFeatures

    f0 = features[0]
    return MotionFeatures(
        np.concatenate([f.quats for f in features]),
        np.concatenate([f.euler for f in features]),
        f0.orders,
        f0.fps,
        None,
        f0.name,
    )


def main(argv=None) -> None:
    """``python -m fpdtw.paper.bench``: time every aligner on real pairs, write
    ``results/bench.json``, print the table next to the paper's Table 2."""
    import argparse

    ap = argparse.ArgumentParser(description=main.__doc__)
    ap.add_argument("--all-cores", action="store_true", help="do not pin to one core")
    args = ap.parse_args(argv)
    report = run_benchmark(single_core=not args.all_cores)
    print("pairs:", *report["pairs"], sep="\n  ")
    cpu = report["environment"]["cpu"]
    print(f"cpu: {cpu['model']} ({', '.join(cpu['simd'])}); {provenance.versions_line()}")
    print()
    print(format_bench(report["online"] + report["oe_dtw"]))
    print()
    print(paper_comparison(report["online"] + report["oe_dtw"]))
    d = report["dtw"]
    print(
        f"\noffline DTW (accumulate + path) on {d['cells']} cells: "
        f"{d['median_s'] * 1e3:.1f} ms, {d['cells_per_s'] / 1e6:.0f} million cells/s "
        "(target >= 500)"
    )


if __name__ == "__main__":
    main()


__all__ = ["bench_online", "dtw_throughput", "format_bench", "paper_comparison", "run_benchmark"]
