"""Per-frame latency of the online aligners (FP-DTW Table 2), against the hardware limit,
the peers and the paper, measured in one run on this machine.

``make bench`` runs :func:`main`. On real pairs of the data here it times every online
aligner (Method A, Methods B and C at w = 10, 20, 40, 80, each with and without the Type V
constraint, Method C's literal window, OLTW, OPW and OE-DTW) frame by frame with
:func:`fpdtw.online.base.run_online`, after an untimed warm-up run over the same pairs
(numba compilation, caches), and reports the median and 95th percentile per frame.
Absolute times do not travel between machines (2-3x between two of ours), so the report
puts each median next to:

* the LIMIT: the unavoidable work of the same steps on the same data, timed in the same
  run (:mod:`fpdtw.app.bench_limit`: the window's geodesic evaluations and its
  accumulation), with the gap split into the forecast, the rest of the compiled step and
  the Python call overhead;
* the PEERS, side by side: offline DTW against dtw-python on the same cost matrix; OE-DTW
  per frame against recomputing dtw-python's ``open_end`` per frame (what a dtw-python
  user would do); OLTW per frame against pymatchmaker's OLTW-Dixon on the same features
  (``make bench-peers``, a separate environment: :mod:`fpdtw.app.bench_peers`);
* the PAPER: our median over Table 2's mean, a cross-machine comparison (3.58-3.95 GHz,
  C#/Unity-era implementation).

and the PAPER'S UNOPTIMISED IMPLEMENTATION: Section 5 judges w 80 at 120 Hz "without further
optimization", so :func:`plain_step_times` also times the plain NumPy steps of
:mod:`fpdtw.plain` (Algorithms 2 and 3 line by line, no numba: ``method_b_step`` and
``method_c_step``, stepped by ``fpdtw.plain.run``) for Mb w80 and Mc w80 on the first
:data:`PLAIN_FRAMES` target frames of each pair, next to the 8333 us budget of one frame at
120 Hz; the compiled kernels' times are our own finding beside them.

And the SERVER: the loopback round trip per frame of ``fpdtw serve`` (Method C, w 40) for
the first pair's target played in real time by ``fpdtw stream``, alone and as eight takes at
once (:func:`bench_server`; the two commands run as subprocesses on every core, before the
benchmark pins itself to one).

Everything is written to ``results/bench.json`` with the machine (CPU model, SIMD flags,
clock, LLVM's target CPU, Python, numba and llvmlite versions) and the load average before
and after. The process is pinned to one core (``os.sched_setaffinity``) so that the
numbers are single-core numbers, as in the paper.
"""

from __future__ import annotations

import contextlib
import json
import os
import time

import numpy as np

from fpdtw import registry
from fpdtw.app import bench_limit
from fpdtw.app.stream import round_trip_stats
from fpdtw.paper import provenance
from fpdtw.paper.atomic import write_atomic
from fpdtw.paper.figures.timing import step_s
from fpdtw.paper.numbers import TABLE2_US

#: A step above this many times its limit gets its gap explained in the report.
EXPLAIN_ABOVE = 1.5
#: Target frames at which OE-DTW's peer (dtw-python's open_end, recomputed) is timed:
#: evenly spread, so that their median estimates the median over every frame.
OE_PEER_FRAMES = 25

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

#: The configurations :func:`plain_step_times` times as the paper's unoptimised implementation
#: (Section 5: "a window size of 80 would not be feasible ... at 120 Hz").
PLAIN_NAMES = ("Mb w80", "Mc w80")
#: Target frames timed per pair by :func:`plain_step_times` (the plain steps take
#: milliseconds each: a bounded prefix keeps ``make bench`` within a minute for them).
PLAIN_FRAMES = 240
#: Target frames of each pair run untimed first, per configuration (warm-up).
PLAIN_WARMUP = 20
#: The plain step of each method :func:`plain_step_times` times: the functions of
#: :mod:`fpdtw.plain` that ``tests/test_plain.py`` holds equal to the compiled kernels.
PLAIN_STEPS = {"B": "method_b_step", "C": "method_c_step"}


def bench_names() -> list:
    """The online aligners ``make bench`` times, by name: Method A, Methods B and C (the
    default square window and the literal one) at every w, each with and without Type V,
    and the global band variants of notebook 16 (Q3, :data:`fpdtw.paper.runner.grid.OPEN_Q3`).
    """
    from fpdtw.paper.numbers import FPDTW_NAMES, FPDTW_TYPEV_NAMES
    from fpdtw.paper.runner.grid import BAND_NAMES, MC_LITERAL_NAMES

    return list(FPDTW_NAMES) + list(FPDTW_TYPEV_NAMES) + list(MC_LITERAL_NAMES) + list(BAND_NAMES)


def bench_baselines(pairs, limits=False) -> list:
    """:func:`bench_online` of the registry's online baselines beyond the paper
    (:func:`fpdtw.registry.baselines`: OPW and OLTW as built in; OPW only on pairs with
    joint positions, which it compares). A baseline without a replay of its steps gets no
    limit (None).

    Parameters
    ----------
    pairs : sequence of (MotionFeatures, MotionFeatures)
    limits : bool

    Returns
    -------
    rows : list of dict
        One per baseline timed, as :func:`bench_online`.

    Paper: FP-DTW Table 2 (the baselines beside it).
    Notebook: none (``make bench`` runs it; notebook 09 reads its report)
    """
    positions = all(I.positions is not None and T.positions is not None for I, T in pairs)
    rows = []
    for name in registry.baselines():
        if registry.resolve(name).family == "OPW" and not positions:
            continue
        rows += bench_online(pairs, [name], limits=limits)
    return rows


def _name_key(name: str) -> tuple:
    from fpdtw.errors import AlignmentError
    from fpdtw.registry import resolve

    try:
        a = resolve(name)
    except AlignmentError:  # an aligner outside the registry: its name is its family
        return name, 0, False
    return a.family, a.value or 0, a.typev


def bench_online(pairs, names=None, make=None, limits=False):
    """Median, 95th percentile and mean per-frame time of each online aligner, and (with
    ``limits``) how far each is from the limit of its steps.

    Parameters
    ----------
    pairs : sequence of (MotionFeatures, MotionFeatures)
        (input, target) pairs.
    names : sequence of str, optional
        FP-DTW configurations by name (default :func:`bench_names`).
    make : callable, optional
        ``make(I) -> OnlineAligner``, to time one other aligner instead of ``names``.
    limits : bool
        Also replay every timed run with :func:`fpdtw.app.bench_limit.replay` and add
        the keys of :func:`limit_stats` (aligners without a replay get None there).

    Returns
    -------
    rows : list of dict
        Keys ``name``, ``method``, ``w``, ``typev``, ``frames`` (number timed),
        ``median_s``, ``p95_s``, ``mean_s`` (seconds per frame), and with ``limits``
        those of :func:`limit_stats`.

    Paper: FP-DTW Table 2.
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
    for name, build in _progress(jobs, "online aligners"):
        for I0, T0 in pairs:  # warm-up: compile, caches, branch predictors
            run_online(build(I0), T0)
        times, recs = [], []
        for I, T in pairs:
            aligner = build(I)
            M, dt = run_online(aligner, T)
            times.append(dt)
            if limits:
                recs.append(bench_limit.replay(aligner, T, M))
        dt = np.concatenate(times)
        name = name or aligner.name
        method, w, typev = _name_key(name)
        row = dict(
            name=name,
            method=method,
            w=int(w),
            typev=bool(typev),
            frames=int(dt.size),
            median_s=float(np.median(dt)),
            p95_s=float(np.percentile(dt, 95)),
            mean_s=float(dt.mean()),
        )
        if limits:
            ok = all(r is not None for r in recs)
            row.update(limit_stats(dt, np.concatenate(recs) if ok else None))
        rows.append(row)
    return rows


#: Keys :func:`limit_stats` adds to a row (None where not measured).
LIMIT_KEYS = (
    "window_frames", "step_median_s", "limit_median_s", "limit_p95_s", "step_over_limit",
    "compiled_median_s", "forecast_median_s", "other_median_s", "python_median_s",
    "evals_median", "ns_per_eval", "same_costs",
)  # fmt: skip


def limit_stats(dt, rec) -> dict:
    """One aligner's step against its limit, from its streamed times and its replay.

    Parameters
    ----------
    dt : ndarray of float, shape (n,)
        Streamed time of each frame (seconds), as :func:`fpdtw.online.base.run_online`.
    rec : ndarray of int64, shape (n, N_REC), or None
        :func:`fpdtw.app.bench_limit.replay` of the same frames (None: no replay).

    Returns
    -------
    stats : dict
        Over the frames with a window (``window_frames``; warm-up and end-of-input steps
        have none): medians (seconds) of the streamed ``step``, the ``limit``, the
        ``compiled`` step, the ``forecast``, the ``other`` compiled work
        (compiled - forecast - limit) and the ``python`` call overhead (step - compiled),
        each the median of per-frame values; ``step_over_limit`` (median step / median
        limit); ``evals_median`` (geodesic evaluations per step) and ``ns_per_eval``;
        ``same_costs`` (the limit computed the step's own costs, bit for bit; None: not
        checked).

    Paper: FP-DTW Table 2.
    """
    out = dict.fromkeys(LIMIT_KEYS)
    if rec is None:
        return out
    B = bench_limit
    win = rec[:, B.R_KIND] == B.KIND_WINDOW
    out["window_frames"] = int(win.sum())
    if not win.any():
        return out
    tps = B.ticks_per_second()
    r = rec[win]
    step = np.asarray(dt, dtype=float)[win]
    compiled = r[:, B.R_COMPILED] / tps
    limit = r[:, B.R_LIMIT] / tps
    forecast = r[:, B.R_FORECAST] / tps
    med = lambda x: float(np.median(x))  # noqa: E731
    out.update(
        step_median_s=med(step),
        limit_median_s=med(limit),
        limit_p95_s=float(np.percentile(limit, 95)),
        compiled_median_s=med(compiled),
        forecast_median_s=med(forecast),
        other_median_s=med(compiled - forecast - limit),
        python_median_s=med(step - compiled),
        evals_median=int(np.median(r[:, B.R_EVALS])),
    )
    out["step_over_limit"] = out["step_median_s"] / out["limit_median_s"]
    out["ns_per_eval"] = out["limit_median_s"] / max(out["evals_median"], 1) * 1e9
    same = r[:, B.R_SAME]
    out["same_costs"] = None if (same < 0).all() else bool((same[same >= 0] == 1).all())
    return out


def _progress(items, what):
    """``items`` with a tqdm progress bar on a terminal (plain otherwise)."""
    import sys

    items = list(items)
    if not sys.stderr.isatty():
        return items
    try:
        from tqdm.auto import tqdm
    except ImportError:
        return items
    return tqdm(items, desc=what, leave=False)


def _us(x, digits=1) -> str:
    return "-" if x is None else f"{x * 1e6:.{digits}f}"


def _ratio(x) -> str:
    return "-" if x is None else (f"{x:.2f}" if x < 10 else f"{x:.0f}")


def explain_gap(row) -> str:
    """What a step above :data:`EXPLAIN_ABOVE` times its limit spends the rest on, from the
    measured medians: the largest of forecast, Python call overhead and other compiled work.

    Returns
    -------
    text : str
        E.g. ``"python 1.5 us, forecast 2.3 us"``; ``""`` when the step is within
        :data:`EXPLAIN_ABOVE` of its limit or nothing was measured.
    """
    ratio = row.get("step_over_limit")
    if ratio is None or ratio <= EXPLAIN_ABOVE:
        return ""
    parts = [
        ("forecast (Euler->quaternion, libm sin/cos)", row.get("forecast_median_s")),
        ("Python call", row.get("python_median_s")),
        ("other compiled", row.get("other_median_s")),
    ]
    parts = sorted((p for p in parts if p[1] is not None and p[1] > 0.05e-6), key=lambda p: -p[1])
    return ", ".join(f"{label} {v * 1e6:.1f} us" for label, v in parts[:2])


def format_bench(rows, peers=None) -> str:
    """The rows of :func:`bench_online` as a text table in microseconds: the step, its
    limit, the ratio, where the gap goes (when the rows carry :func:`limit_stats`), and the
    ratios to the paper (Table 2 mean / our step) and to the peers (peer / our step).

    Parameters
    ----------
    rows : list of dict
        Rows of :func:`bench_online`.
    peers : dict, optional
        The ``peers`` of :func:`run_benchmark` (OE-DTW's and OLTW's peer ratios).

    Returns
    -------
    text : str

    Paper: FP-DTW Table 2.
    """
    head = (
        f"{'aligner':<34}{'step us':>9}{'p95 us':>9}{'limit us':>10}{'step/lim':>9}"
        f"{'fcast':>7}{'python':>7}{'other':>7}{'ns/eval':>8}"
        f"{'paper/ours':>11}{'peer/ours':>10}"
    )
    paper = paper_ratios(rows)
    peer = peer_ratios(peers or {})
    lines = [head]
    for r in rows:
        lines.append(
            f"{r['name']:<34}{step_s(r) * 1e6:9.2f}{r['p95_s'] * 1e6:9.2f}"
            f"{_us(r.get('limit_median_s'), 2):>10}{_ratio(r.get('step_over_limit')):>9}"
            f"{_us(r.get('forecast_median_s')):>7}{_us(r.get('python_median_s')):>7}"
            f"{_us(r.get('other_median_s')):>7}"
            f"{'-' if r.get('ns_per_eval') is None else format(r['ns_per_eval'], '.2f'):>8}"
            f"{_times(paper.get(r['name'])):>11}{_times(peer.get(r['name'])):>10}"
        )
    notes = [
        f"  {r['name']}: {r['step_over_limit']:.1f}x its limit: {explain_gap(r)}"
        for r in rows
        if explain_gap(r)
    ]
    if notes:
        lines += ["", f"Steps above {EXPLAIN_ABOVE}x their limit, the largest parts of the gap:"]
        lines += notes
    return "\n".join(lines)


def _times(x) -> str:
    return "-" if x is None else f"{_ratio(x)}x"


def peer_ratios(peers) -> dict:
    """``{"OE-DTW": peer / ours, "OLTW": peer / ours}`` from the ``peers`` of a report
    (the aligners with a per-frame peer; missing peers are left out)."""
    out = {}
    for key, name in (("open_end", "OE-DTW"), ("oltw", "OLTW")):
        p = peers.get(key) or {}
        if p.get("peer_over_ours") is not None:
            out[name] = p["peer_over_ours"]
    return out


def paper_comparison(rows) -> str:
    """Our median per-frame time over the paper's Table 2 mean, per method and w (a
    CROSS-MACHINE comparison: the paper's 3.58-3.95 GHz core and implementation), as text.

    Method C's literal window (notebook 15) gets its own column.
    """
    by = {(r["method"], r["w"], r["typev"]): r for r in rows if "(" not in r["name"]}
    literal = {r["w"]: r for r in rows if "(literal window)" in r["name"] and not r["typev"]}
    head = ("", "w", "paper us", "ours us", "paper/ours", "+TypeV us", "literal us")
    us = lambda r: _us(None if r is None else step_s(r))  # noqa: E731
    fmt = "{:<10}{:>5}{:>10}{:>10}{:>12}{:>11}{:>12}"
    lines = [
        "Against the paper (CROSS-MACHINE: Table 2 means on the paper's 3.58-3.95 GHz core and"
        " implementation; ours: median window step, this machine): paper/ours > 1, we are faster",
        fmt.format(*head),
    ]
    for method, label in (("B", "Method B"), ("C", "Method C")):
        for w in (10, 20, 40, 80):
            r = by.get((method, w, False))
            if r is None:
                continue
            paper = TABLE2_US.get((method, w))
            cells = (
                label,
                str(w),
                "-" if paper is None else f"{paper:.0f}",
                us(r),
                "-" if paper is None else f"{paper / (step_s(r) * 1e6):.0f}x",
                us(by.get((method, w, True))),
                us(literal.get(w)) if method == "C" else "-",
            )
            lines.append(fmt.format(*cells))
    return "\n".join(lines)


def paper_ratios(rows) -> dict:
    """``{"Mb w10": paper mean / our median, ...}`` for Table 2's configurations."""
    out = {}
    for r in rows:
        paper = TABLE2_US.get((r["method"], r["w"]))
        if paper is not None and not r["typev"] and "(" not in r["name"]:
            out[r["name"]] = paper / (step_s(r) * 1e6)
    return out


def time_plain_run(name, I, T, frames=PLAIN_FRAMES):
    """The plain steps of one configuration over the first target frames of a pair, each
    step timed.

    The map is :func:`fpdtw.plain.run`'s on ``T``'s first ``frames + 1`` frames (``M_0 = 0``,
    no Type V unless the name has it), with the method's plain step (:data:`PLAIN_STEPS`)
    wrapped by a timer: each call of the step is timed with :func:`time.perf_counter`,
    nothing else (the loop of ``run`` is not counted).

    Parameters
    ----------
    name : str
        A Method B or C configuration of the registry (``"Mb w80"``).
    I, T : MotionFeatures
        Input and target.
    frames : int
        Target frames stepped and timed, ``q = 1..frames`` (fewer if the target is shorter).

    Returns
    -------
    M : ndarray of int64, shape (min(frames, T.n_frames - 1) + 1,)
        The map of target frames ``0..frames``.
    dt : ndarray of float64, shape (len(M) - 1,)
        Seconds of the step of each target frame ``q = 1..``.

    Paper: FP-DTW Table 2 and Section 5 (Algorithms 2 and 3 without further optimization).
    """
    from fpdtw import plain
    from fpdtw.registry import resolve

    a = resolve(name)
    if a.family not in PLAIN_STEPS or a.derivative:
        raise ValueError(f"{name!r}: only Methods B and C have a plain step to time")
    step = getattr(plain, PLAIN_STEPS[a.family])
    times = []

    def timed(*args, **kwargs):
        t0 = time.perf_counter()
        out = step(*args, **kwargs)
        times.append(time.perf_counter() - t0)
        return out

    n = max(1, min(int(frames) + 1, T.n_frames))
    M = plain.run(timed, I, T.slice(0, n), a.w, a.typev, **a.options)
    return M, np.array(times, dtype=float)


def plain_step_times(pairs, names=PLAIN_NAMES, frames=PLAIN_FRAMES, warmup=PLAIN_WARMUP):
    """Per-frame time of the paper's algorithms as written, without the compiled kernels.

    Times :func:`fpdtw.plain.method_b_step` (Algorithm 2) and
    :func:`fpdtw.plain.method_c_step` (Algorithm 3), plain NumPy and Python loops, no numba,
    stepped through each pair by :func:`fpdtw.plain.run` (:func:`time_plain_run`): the same
    functions ``tests/test_plain.py`` holds equal to the compiled aligners, so the maps are
    the aligners' maps. Per configuration, the first ``warmup`` target frames of every pair
    are run untimed first (allocation, caches); then target frames ``q = 1..frames`` of
    every pair are timed (every step: the method's two warm-up steps and any step with the
    input exhausted count too, as in the compiled rows' means).

    Parameters
    ----------
    pairs : sequence of (MotionFeatures, MotionFeatures)
        (input, target) pairs (:func:`load_bench_pairs`).
    names : sequence of str
        Method B and C configurations (default :data:`PLAIN_NAMES`).
    frames : int
        Target frames timed per pair (default :data:`PLAIN_FRAMES`).
    warmup : int
        Target frames run untimed per pair first.

    Returns
    -------
    rows : list of dict
        ``name``, ``method`` (``"B"`` or ``"C"``), ``w``, ``mean_us`` and ``median_us``
        (microseconds per target frame, float), ``frames`` (steps timed, all pairs),
        ``pairs``.

    Paper: FP-DTW Table 2 and Section 5 ("Without further optimization ... a window size of
    80 would not be feasible for use with a sample rate of 120 Hz").
    """
    from fpdtw.registry import resolve

    pairs = list(pairs)
    if not pairs:
        raise ValueError("no pairs to time")
    rows = []
    for name in _progress(names, "plain steps"):
        for I, T in pairs:
            time_plain_run(name, I, T, max(1, int(warmup)))
        dt = np.concatenate([time_plain_run(name, I, T, frames)[1] for I, T in pairs])
        a = resolve(name)
        rows.append(
            dict(name=name, method=a.family, w=int(a.w), mean_us=float(dt.mean() * 1e6),
                 median_us=float(np.median(dt) * 1e6), frames=int(dt.size), pairs=len(pairs))
        )  # fmt: skip
    return rows


def plain_table(report) -> str:
    """The plain steps (:func:`plain_step_times`, the paper's algorithms without further
    optimisation) beside our compiled kernels and the 120 Hz budget, as text; ``""`` when
    the report has no plain rows.

    Paper: FP-DTW Table 2 and Section 5.
    """
    rows = report.get("plain") or []
    if not rows:
        return ""
    compiled = {r["name"]: r for r in report.get("online", [])}
    budget = 1e6 / 120
    per_pair = max(r["frames"] // max(r["pairs"], 1) for r in rows)
    fmt = "{:<10}{:>15}{:>17}{:>8}{:>18}{:>16}{:>11}"
    lines = [
        "Without further optimization (Section 5): PLAIN = fpdtw.plain's line-by-line NumPy "
        f"steps (method_b_step, method_c_step; no numba), up to {per_pair} target frames per "
        f"pair; COMPILED = our numba kernels (our finding, not the paper's implementation); "
        f"budget at 120 Hz: {budget:.0f} us per frame",
        fmt.format("", "plain mean us", "plain median us", "frames", "compiled mean us",
                   "plain/compiled", "in budget"),
    ]  # fmt: skip
    for r in rows:
        c = compiled.get(r["name"])
        c_us = None if c is None else c["mean_s"] * 1e6
        lines.append(
            fmt.format(
                r["name"], f"{r['mean_us']:.0f}", f"{r['median_us']:.0f}", r["frames"],
                "-" if c_us is None else f"{c_us:.1f}",
                "-" if c_us is None else f"{r['mean_us'] / c_us:.0f}x",
                "yes" if r["mean_us"] <= budget else "no",
            )
        )  # fmt: skip
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

    med = _median_time(lambda: dtw(C), repeats)
    return {"cells": int(C.size), "median_s": med, "cells_per_s": C.size / med}


def _median_time(fn, repeats):
    fn()  # warm-up (compilation; the first large allocations fault their pages in)
    fn()
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return float(np.median(times))


def peer_dtw(C, repeats=5, ours_median_s=None) -> dict:
    """Offline DTW (accumulated cost + path, symmetric1) against dtw-python on the same
    cost matrix.

    Parameters
    ----------
    C : ndarray of float, shape (m, n)
    repeats : int
        Timed runs of each, after warm-up runs.
    ours_median_s : float, optional
        Our median on ``C`` measured already (:func:`dtw_throughput`), so that the report
        shows one number for it; timed here otherwise.

    Returns
    -------
    row : dict
        ``peer`` (name and version), ``cells``, ``ours_median_s``, ``peer_median_s``,
        ``peer_over_ours`` (how many times longer the peer takes), ``same_distance``.
        Empty dict when dtw-python is not installed.
    """
    try:
        import dtw as dtwpy
    except ImportError:
        return {}
    from fpdtw.dtw import dtw

    ours = _median_time(lambda: dtw(C), repeats) if ours_median_s is None else ours_median_s
    peer = _median_time(lambda: dtwpy.dtw(C, step_pattern=dtwpy.symmetric1), repeats)
    same = dtw(C).distance == dtwpy.dtw(C, step_pattern=dtwpy.symmetric1).distance
    return dict(
        peer=f"dtw-python {provenance.package_versions(('dtw-python',))['dtw-python']}",
        cells=int(C.size),
        ours_median_s=ours,
        peer_median_s=peer,
        peer_over_ours=peer / ours,
        same_distance=bool(same),
    )


def peer_open_end(I, T, ours_median_s, frames=OE_PEER_FRAMES) -> dict:
    """OE-DTW per frame against what a dtw-python user would do at each new target frame:
    recompute ``dtw(C[:, :q+1], open_end=True)`` (symmetric1, distance only) and read its
    end point.

    The peer is timed at ``frames`` target frames spread evenly over the target (its time
    grows with q; the median of evenly spread frames estimates the median over all), on a
    cost matrix computed beforehand (its cost is not counted: in the peer's favour). Every
    end point is checked against ours.

    Parameters
    ----------
    I, T : MotionFeatures
        The OE-DTW pair of :func:`run_benchmark`.
    ours_median_s : float
        Our OE-DTW median per frame on the same pair.

    Returns
    -------
    row : dict
        ``peer``, ``frames``, ``ours_median_s``, ``peer_median_s``, ``peer_over_ours``,
        ``same_end_points``; empty when dtw-python is not installed.
    """
    try:
        import dtw as dtwpy
    except ImportError:
        return {}
    from fpdtw.costs import geodesic_cost_matrix
    from fpdtw.online.base import run_online
    from fpdtw.online.oedtw import OEDTW

    C = geodesic_cost_matrix(I.quats, T.quats)
    M, _ = run_online(OEDTW(I), T)
    # dtw-python refuses open_end for "symmetric1" (not normalisable); with hint "N" it
    # divides by the query length, the same for every candidate end: argmin unchanged
    pattern = dtwpy.StepPattern(dtwpy.symmetric1.mx, hint="N")
    n = T.n_frames
    qs = sorted({min(n - 1, int((2 * i + 1) * n / (2 * frames))) for i in range(frames)})

    def end(q):
        return dtwpy.dtw(C[:, : q + 1].T, step_pattern=pattern, open_end=True, distance_only=True)

    end(qs[0])  # warm-up
    times, same = [], True
    for q in qs:
        t0 = time.perf_counter()
        e = end(q).jmin
        times.append(time.perf_counter() - t0)
        same &= int(e) == int(M[q])
    peer = float(np.median(times))
    return dict(
        peer=f"dtw-python {provenance.package_versions(('dtw-python',))['dtw-python']} open_end",
        frames=len(qs),
        ours_median_s=float(ours_median_s),
        peer_median_s=peer,
        peer_over_ours=peer / ours_median_s,
        same_end_points=bool(same),
    )


def load_peers(path=None) -> dict | None:
    """The report of ``make bench-peers`` (``results/bench_peers.json``), or None."""
    from fpdtw.paper.paths import results_dir

    path = results_dir() / "bench_peers.json" if path is None else path
    try:
        return json.loads(path.read_text())
    except FileNotFoundError:
        return None


def peers_table(report) -> str:
    """Our per-frame (or per-matrix) medians next to the peers', as text: ratios > 1 mean
    the peer takes that many times longer."""
    fmt = "{:<26}{:<40}{:>11}{:>11}{:>11}  {}"
    lines = [
        "Against the peers (same data, same run; peer/ours > 1: the peer is slower)",
        fmt.format("ours", "peer", "ours us", "peer us", "peer/ours", "check"),
    ]
    d = report.get("peers", {}).get("dtw") or {}
    if d:
        lines.append(
            fmt.format(
                f"DTW, {d['cells']} cells", d["peer"], _us(d["ours_median_s"]),
                _us(d["peer_median_s"]), _ratio(d["peer_over_ours"]),
                "same distance" if d["same_distance"] else "DISTANCES DIFFER",
            )
        )  # fmt: skip
    o = report.get("peers", {}).get("open_end") or {}
    if o:
        lines.append(
            fmt.format(
                "OE-DTW per frame", o["peer"] + " per frame", _us(o["ours_median_s"]),
                _us(o["peer_median_s"]), _ratio(o["peer_over_ours"]),
                "same end points" if o["same_end_points"] else "END POINTS DIFFER",
            )
        )  # fmt: skip
    p = report.get("peers", {}).get("oltw") or {}
    if p:
        lines.append(
            fmt.format(
                "OLTW per frame", p["peer"], _us(p["ours_median_s"]), _us(p["peer_median_s"]),
                _ratio(p["peer_over_ours"]), f"make bench-peers, {p.get('measured', '')}",
            )
        )  # fmt: skip
    else:
        lines.append(
            fmt.format("OLTW per frame", "pymatchmaker OLTW-Dixon", "-", "-", "-",
                       "run make bench-peers (optional, separate environment)")
        )  # fmt: skip
    return "\n".join(lines)


def machine_header(report) -> str:
    """The machine, versions, pinning and load of a report, as text lines."""
    env = report["environment"]
    cpu = env.get("cpu") or {}
    pk = env["packages"]
    mhz = f", {cpu['mhz']:.0f} MHz now" if cpu.get("mhz") else ""
    tsc = report.get("cycle_counter_hz")
    tsc = (
        f"; cycle counter {tsc / 1e9:.3f} GHz"
        if tsc
        else "; no cycle counter (limits not measured)"
    )
    load = report.get("loadavg") or {}
    return "\n".join(
        [
            f"machine: {cpu.get('model')} ({cpu.get('cores')} logical cores{mhz}); "
            f"SIMD: {', '.join(cpu.get('simd') or []) or 'none'}; "
            f"LLVM target: {cpu.get('llvm_cpu')}{tsc}",
            f"versions: Python {env['python']}, numpy {pk.get('numpy')}, numba {pk.get('numba')}, "
            f"llvmlite {pk.get('llvmlite')}, dtw-python {pk.get('dtw-python')}; fpdtw commit "
            f"{(env['fpdtw'].get('commit') or 'unknown')[:10]}"
            f"{' (uncommitted changes)' if env['fpdtw'].get('dirty') else ''}",
            f"run: {'one pinned core' if report['single_core'] else 'all cores'}; load average "
            f"(1 min) before {_load(load.get('before'))}, after {_load(load.get('after'))} "
            f"(above 1: other work shared the machine, times are noisier)",
        ]
    )


def _load(x):
    return "-" if x is None else f"{x[0]:.2f}"


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


def oe_pair(pairs):
    """OE-DTW's pair: the longest input repeated and cropped to :data:`OE_INPUT_FRAMES`
    frames, against that pair's target."""
    I_long, T_long = max(pairs, key=lambda p: p[0].n_frames)
    reps = -(-OE_INPUT_FRAMES // I_long.n_frames)
    I_oe = I_long if reps == 1 else _concat([I_long] * reps)
    return I_oe.slice(0, OE_INPUT_FRAMES), T_long


#: ``make bench``'s server round trip: the method's ``fpdtw serve`` options and the numbers
#: of takes played at once.
SERVER_OPTIONS = ("-m", "c", "-w", "40")
SERVER_STREAMS = (1, 8)


def bench_server(pair=BENCH_PAIRS[0], streams=SERVER_STREAMS, timeout=300.0, view=False) -> dict:
    """Loopback round trip of ``fpdtw serve`` (:data:`SERVER_OPTIONS`) against the pair's
    input, the pair's target played in real time by ``fpdtw stream --streams N``.

    Both run as commands in subprocesses (the paper layer imports no app); the server gets
    an untimed warm-up take (as fast as answered) first. Bounded: every command has
    ``timeout`` seconds, the server is stopped with SIGTERM at the end. ``view``: the server
    runs with ``--view`` and its page is open in headless Chromium while the takes play.

    Returns
    -------
    result : dict
        ``method`` (the options), ``pair``, ``fps`` and, per number of takes at once,
        ``streams[n]`` = ``answers``, ``round_trip_p50_ms``, ``round_trip_p99_ms``,
        ``round_trip_max_ms``, ``server_p50_ms``, ``server_p99_ms``.
    """
    import signal
    import subprocess
    import sys
    import tempfile
    from pathlib import Path

    from fpdtw.paper.datasets import fetch

    ds, a, b = pair
    inp, take = fetch(ds, a, progress=False), fetch(ds, b, progress=False)
    cli = [sys.executable, "-m", "fpdtw.app.cli"]
    extra = ["--view", "127.0.0.1:0"] if view else []
    server = subprocess.Popen(
        [*cli, "serve", str(inp), *SERVER_OPTIONS, "--listen", "127.0.0.1:0", *extra],
        stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True,
    )  # fmt: skip
    out = {"method": " ".join(SERVER_OPTIONS), "pair": f"{Path(a).stem} -> {Path(b).stem}"}
    page = contextlib.nullcontext()
    try:
        if view:
            from fpdtw.app.browser import chromium

            url = server.stdout.readline().split()[-1]
            page = chromium()
            page.__enter__().get(url)
        line = server.stdout.readline().split()
        if line[:2] != ["listening", "on"]:
            raise RuntimeError(f"fpdtw serve did not start: {line}")
        to = ["--to", line[2]]
        with tempfile.TemporaryDirectory() as tmp:
            run = lambda *args: subprocess.run(  # noqa: E731
                [*cli, "stream", str(take), *to, *args], check=True, timeout=timeout,
                stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
            )  # fmt: skip
            run("--fast")  # warm-up
            out["streams"] = {}
            for n in streams:
                csv = Path(tmp) / f"answers_{n}.csv"
                run("--streams", str(n), "--out", str(csv))
                rows = np.loadtxt(csv, delimiter=",", skiprows=1, ndmin=2)
                rt, sv = rows[:, 6] / 1e3, rows[:, 5] / 1e3  # round_trip_us, server_us
                out["streams"][int(n)] = round_trip_stats(rt, sv)
    finally:
        page.__exit__(None, None, None)
        server.send_signal(signal.SIGTERM)
        try:
            server.wait(30)
        except subprocess.TimeoutExpired:
            server.kill()
            server.wait()
        server.stdout.close()
    return out


#: The online methods timed with and without ``(relocate)`` (:func:`bench_relocate`).
RELOCATE_NAMES = ("Ma + Type V", "Mc w40", "OPW", "OLTW")
#: The authors' longest take we have (frames at 120 Hz): the input the search is timed on.
LONGEST_TAKE = ("authors_fbx", "MoCapData/Two_Handed_Pickup_03.fbx")


def bench_relocate(pairs, names=RELOCATE_NAMES) -> dict:
    """Per-frame time of each online method with and without ``(relocate)`` on ``pairs``
    (:func:`bench_online`), and of the relocating search alone (one
    :func:`fpdtw.online.relocate._search_step`) against :data:`LONGEST_TAKE` as the input.

    Returns
    -------
    dict
        ``rows``: per name, ``median_us`` without and ``relocate_median_us`` with, and
        ``p95_us`` of both; ``search``: ``frames`` (the input's), ``median_us``, ``p95_us``;
        ``budget_us`` (one frame at 120 Hz).
    """
    from fpdtw.motion.features import MotionFeatures
    from fpdtw.online.relocate import _search_step
    from fpdtw.paper.catalog import load
    from fpdtw.registry import with_option

    pairs = list(pairs)
    rows = []
    for name in names:
        plain_row, reloc_row = bench_online(pairs, [name, with_option(name, "relocate")])
        rows.append(dict(name=name, median_us=plain_row["median_s"] * 1e6,
                         p95_us=plain_row["p95_s"] * 1e6,
                         relocate_median_us=reloc_row["median_s"] * 1e6,
                         relocate_p95_us=reloc_row["p95_s"] * 1e6))  # fmt: skip
    I = MotionFeatures.from_motion(load(*LONGEST_TAKE))
    N = I.n_frames
    Isoa, G = np.ascontiguousarray(I.quats.transpose(1, 2, 0)), np.zeros(N)
    acc, c = np.empty(N), np.empty(N)
    times = []
    for n in range(I.n_frames + 200):  # the take against itself; the first 200 untimed
        q = np.ascontiguousarray(I.quats[n % I.n_frames])
        t0 = time.perf_counter()
        _search_step(q, Isoa, G, 0.99, acc, c)
        if n >= 200:
            times.append(time.perf_counter() - t0)
    t = np.array(times) * 1e6
    search = dict(frames=I.n_frames, median_us=float(np.median(t)),
                  p95_us=float(np.percentile(t, 95)))  # fmt: skip
    return dict(rows=rows, search=search, budget_us=1e6 / 120)


def relocate_table(result) -> str:
    """:func:`bench_relocate`'s result as text lines (microseconds per frame)."""
    lines = [
        "Relocating search (fpdtw.online.relocate), per frame, us: each method without and "
        "with (relocate)",
        f"{'method':<14}{'median':>9}{'p95':>9}{'relocate median':>17}{'relocate p95':>14}",
    ]
    for r in result["rows"]:
        lines.append(f"{r['name']:<14}{r['median_us']:>9.1f}{r['p95_us']:>9.1f}"
                     f"{r['relocate_median_us']:>17.1f}{r['relocate_p95_us']:>14.1f}")  # fmt: skip
    s = result["search"]
    lines.append(f"the search alone against the authors' longest take ({s['frames']} frames): "
                 f"median {s['median_us']:.1f} us, p95 {s['p95_us']:.1f} us; budget at 120 Hz "
                 f"{result['budget_us']:.0f} us")  # fmt: skip
    return "\n".join(lines)


def bench_view(pair=BENCH_PAIRS[0], rounds=3) -> list:
    """:func:`bench_server` for one take, without ``--view`` and with its page open in
    headless Chromium, alternately, ``rounds`` times each: rows ``round``, ``view``, and the
    round trip and server percentiles (ms). Needs Chromium (:mod:`fpdtw.app.browser`)."""
    rows = []
    for r in _progress(range(rounds), "view"):
        for view in (False, True):
            got = bench_server(pair, streams=(1,), view=view)["streams"][1]
            rows.append(dict(round=r + 1, view=view, **got))
    return rows


def view_table(rows) -> str:
    """:func:`bench_view`'s rows as text lines (ms), with the medians over the rounds."""
    lines = [
        "fpdtw serve round trip, one take, without --view and with its page open (headless "
        "Chromium); ms",
        f"{'round':<7}{'view':<7}{'p50':>9}{'p99':>9}{'server p50':>12}{'server p99':>12}",
    ]
    for r in rows:
        lines.append(f"{r['round']:<7}{'open' if r['view'] else 'off':<7}"
                     f"{r['round_trip_p50_ms']:>9.3f}{r['round_trip_p99_ms']:>9.3f}"
                     f"{r['server_p50_ms']:>12.3f}{r['server_p99_ms']:>12.3f}")  # fmt: skip
    for view in (False, True):
        got = [r for r in rows if r["view"] == view]
        keys = ("round_trip_p50_ms", "round_trip_p99_ms", "server_p50_ms", "server_p99_ms")
        med = {k: float(np.median([r[k] for r in got])) for k in keys}
        lines.append(f"{'median':<7}{'open' if view else 'off':<7}"
                     f"{med['round_trip_p50_ms']:>9.3f}{med['round_trip_p99_ms']:>9.3f}"
                     f"{med['server_p50_ms']:>12.3f}{med['server_p99_ms']:>12.3f}")  # fmt: skip
    return "\n".join(lines)


def bench_sources(pair=BENCH_PAIRS[0], performers=(1, 4, 1, 1)) -> list:
    """Wire-to-answer latency of every capture source (:func:`fpdtw.app.source_latency.measure`,
    ``fpdtw serve`` :data:`SERVER_OPTIONS`): the pair's target played by each system's emulator,
    for 1 and for N performers at once (one performer three times: the bar's runs)."""
    from fpdtw.app.source_latency import WIRES, measure
    from fpdtw.io import load_motion
    from fpdtw.paper.datasets import fetch

    ds, a, b = pair
    inp, take = fetch(ds, a, progress=False), load_motion(fetch(ds, b, progress=False))
    return [measure(s, inp, take, n) for s in _progress(WIRES, "sources") for n in performers]


def sources_table(rows) -> str:
    """:func:`bench_sources`'s rows as text lines (ms)."""
    lines = [
        "Capture sources (fpdtw serve -m c -w 40 --source, each system's emulator, loopback, "
        "real time; wire -> answer, ms; server: its own time per frame)",
        f"{'source':<10}{'performers':>11}{'answers':>9}{'p50':>9}{'p99':>9}{'max':>9}"
        f"{'server p50':>12}{'server p99':>12}",
    ]
    for r in rows:
        lines.append(
            f"{r['source']:<10}{r['performers']:>11}{r['answers']:>9}{r['p50_ms']:>9.3f}"
            f"{r['p99_ms']:>9.3f}{r['max_ms']:>9.3f}{r['server_p50_ms']:>12.3f}"
            f"{r['server_p99_ms']:>12.3f}"
        )
    from fpdtw.app.source_latency import bar_rows

    lines.append("The bar, one performer: p99 below 2 ms in every run")
    lines += [f"{b['source']:<10}p99 {b['p99_ms']} ms: {b['verdict']}" for b in bar_rows(rows)]
    return "\n".join(lines)


def server_table(result) -> str:
    """:func:`bench_server`'s result as text lines (ms)."""
    if not result:
        return "server round trip: not measured"
    lines = [
        f"Server round trip (fpdtw serve {result['method']}, {result['pair']}, loopback, real "
        "time; line written -> answer read, ms; server: its own time per line)",
        f"{'takes at once':<16}{'answers':>9}{'p50':>9}{'p99':>9}{'max':>9}"
        f"{'server p50':>12}{'server p99':>12}",
    ]
    for n, r in result["streams"].items():
        lines.append(
            f"{n:<16}{r['answers']:>9}{r['round_trip_p50_ms']:>9.3f}{r['round_trip_p99_ms']:>9.3f}"
            f"{r['round_trip_max_ms']:>9.3f}{r['server_p50_ms']:>12.3f}{r['server_p99_ms']:>12.3f}"
        )
    return "\n".join(lines)


def run_benchmark(
    pairs=None, out=None, single_core=True, limits=True, peers=True, server=False, plain=False
):
    """Time everything ``make bench`` reports and write ``results/bench.json``.

    Parameters
    ----------
    pairs : sequence of (MotionFeatures, MotionFeatures), optional
        Default :func:`load_bench_pairs`.
    out : Path, optional
        Default ``results/bench.json``.
    single_core : bool
        Pin the process to one core first.
    limits : bool
        Measure every aligner's limit (:func:`limit_stats`).
    peers : bool
        Time dtw-python side by side (:func:`peer_dtw`, :func:`peer_open_end`); the OLTW
        peer is read from ``results/bench_peers.json`` when ``make bench-peers`` wrote it.
    server : bool
        Measure ``fpdtw serve``'s round trip first (:func:`bench_server`, on every core).
    plain : bool
        Time the plain steps of :data:`PLAIN_NAMES` (:func:`plain_step_times`, about half a
        minute on one core; ``make bench`` does, :func:`main` without ``--no-plain``).

    Returns
    -------
    report : dict
        ``environment`` (:func:`fpdtw.paper.provenance.environment`), ``single_core``,
        ``loadavg`` (``before``, ``after``: :func:`os.getloadavg`), ``cycle_counter_hz``,
        ``pairs``, ``online`` (rows of :func:`bench_online`), ``oe_dtw`` (OE-DTW against a
        1000-frame input), ``dtw`` (offline throughput), ``peers`` (``dtw``, ``open_end``,
        ``oltw``), ``paper_table2_us`` and ``paper_over_ours`` (:func:`paper_ratios`),
        ``plain`` (rows of :func:`plain_step_times`; empty without ``plain``).

    Paper: FP-DTW Table 2.
    Notebook: 09_table2_timing.ipynb
    """
    from fpdtw.costs import geodesic_cost_matrix
    from fpdtw.paper.paths import results_dir

    load_before = list(os.getloadavg()) if hasattr(os, "getloadavg") else None
    served = bench_server() if server else None
    sources = bench_sources() if server else None
    viewed = None
    if server:
        from fpdtw.app.browser import missing_browser

        viewed = None if missing_browser() else bench_view()
    if single_core and hasattr(os, "sched_setaffinity"):
        os.sched_setaffinity(0, {sorted(os.sched_getaffinity(0))[0]})
    pairs = load_bench_pairs() if pairs is None else pairs
    limits = limits and bench_limit.HAVE_CYCLES
    tps = bench_limit.ticks_per_second() if limits else None

    online = bench_online(pairs, limits=limits) + bench_baselines(pairs, limits=limits)
    plain_rows = plain_step_times(pairs) if plain else []
    relocating = bench_relocate(pairs)
    I_oe, T_oe = oe_pair(pairs)
    oe = bench_online([(I_oe, T_oe)], ["OE-DTW"], limits=limits)
    # offline DTW on the largest real cost matrix
    I_big, T_big = max(pairs, key=lambda p: p[0].n_frames * p[1].n_frames)
    C = geodesic_cost_matrix(I_big.quats, T_big.quats)
    offline = dtw_throughput(C, repeats=9)
    peer = {}
    if peers:
        peer["dtw"] = peer_dtw(C, ours_median_s=offline["median_s"])
        peer["open_end"] = peer_open_end(I_oe, T_oe, step_s(oe[0]))
        pm = load_peers()
        if pm and pm.get("oltw"):
            peer["oltw"] = pm["oltw"]
    report = {
        "environment": provenance.environment(),
        "single_core": bool(single_core),
        "loadavg": {
            "before": load_before,
            "after": list(os.getloadavg()) if hasattr(os, "getloadavg") else None,
        },
        "cycle_counter_hz": tps,
        "pairs": [f"{I.name} -> {T.name} ({I.n_frames} x {T.n_frames})" for I, T in pairs],
        "online": online,
        "oe_dtw": oe,
        "dtw": offline,
        "peers": peer,
        "paper_table2_us": {f"{m} w{w}": v for (m, w), v in TABLE2_US.items()},
        "paper_over_ours": paper_ratios(online),
        "plain": plain_rows,
        "server": served,
        "sources": sources,
        "view": viewed,
        "relocate": relocating,
    }
    out = results_dir() / "bench.json" if out is None else out
    write_atomic(out, (json.dumps(report, indent=1) + "\n").encode())
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


def format_report(report) -> str:
    """Everything ``make bench`` prints: the machine, the limit table, the peers, the paper,
    the plain steps (the paper's algorithms without further optimisation) beside the compiled
    ones."""
    rows = report["online"] + report["oe_dtw"]
    d = report["dtw"]
    parts = [
        machine_header(report),
        "pairs: " + "; ".join(report["pairs"]),
        "",
        "Against the hardware limit (medians over the frames with a window; limit: the "
        "window's geodesic evaluations + accumulation, same data, same run; fcast/python/"
        "other: the gap, us)",
        format_bench(rows, report.get("peers")),
        "",
        peers_table(report),
        "",
        paper_comparison(rows),
        "",
        f"offline DTW (accumulate + path) on {d['cells']} cells: {d['median_s'] * 1e3:.1f} ms, "
        f"{d['cells_per_s'] / 1e6:.0f} million cells/s",
    ]
    if report.get("plain"):
        parts += ["", plain_table(report)]
    if report.get("server"):
        parts += ["", server_table(report["server"])]
    if report.get("sources"):
        parts += ["", sources_table(report["sources"])]
    if report.get("view"):
        parts += ["", view_table(report["view"])]
    if report.get("relocate"):
        parts += ["", relocate_table(report["relocate"])]
    return "\n".join(parts)


def main(argv=None) -> None:
    """``python -m fpdtw.app.bench``: time every aligner on real pairs against its limit,
    the peers and the paper; write ``results/bench.json``; print the tables."""
    import argparse

    ap = argparse.ArgumentParser(description=main.__doc__)
    ap.add_argument("--all-cores", action="store_true", help="do not pin to one core")
    ap.add_argument("--no-limits", action="store_true", help="skip the limit replays")
    ap.add_argument("--no-peers", action="store_true", help="skip dtw-python")
    ap.add_argument("--no-server", action="store_true", help="skip fpdtw serve's round trip")
    ap.add_argument("--no-plain", action="store_true", help="skip the plain (unoptimised) steps")
    args = ap.parse_args(argv)
    report = run_benchmark(
        single_core=not args.all_cores,
        limits=not args.no_limits,
        peers=not args.no_peers,
        server=not args.no_server,
        plain=not args.no_plain,
    )
    print(format_report(report))


if __name__ == "__main__":
    main()


__all__ = [
    "bench_baselines",
    "bench_online",
    "bench_server",
    "bench_relocate",
    "bench_view",
    "dtw_throughput",
    "explain_gap",
    "format_bench",
    "format_report",
    "limit_stats",
    "paper_comparison",
    "paper_ratios",
    "peer_dtw",
    "peer_open_end",
    "peer_ratios",
    "peers_table",
    "plain_step_times",
    "plain_table",
    "time_plain_run",
    "round_trip_stats",
    "run_benchmark",
    "server_table",
    "sources_table",
    "relocate_table",
    "view_table",
    "bench_sources",
]
