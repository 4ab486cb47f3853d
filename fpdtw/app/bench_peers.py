"""OLTW per frame against pymatchmaker's OLTW-Dixon, in a separate environment
(``make bench-peers``; read back by ``make bench``).

pymatchmaker needs numpy < 2, which the project's environment does not allow, so the
comparison runs in two halves and never installs pymatchmaker next to fpdtw:

1. ``export`` (the project's ``.venv``): the bench pairs of :mod:`fpdtw.app.bench`
   as flat per-frame feature vectors (each frame's joint quaternions, ``k * 4`` numbers),
   OLTW's parameters, and our OLTW streamed over the same pairs (warm-up run first):
   its map and its time per frame. Written to one ``.npz`` file.
2. ``peer`` (``build/peers-venv``: numpy < 2 and pymatchmaker, built by
   ``make bench-peers``): pymatchmaker's ``OnlineTimeWarpingDixonFrame`` fed the same
   frames one call at a time (what a pymatchmaker user does), timed per call after an
   untimed warm-up; writes ``results/bench_peers.json``. This half imports numpy and
   pymatchmaker only (never fpdtw), and refuses to run in the project's environment.

What is compared. The same input (pymatchmaker's "reference") and target ("live")
frames, the same band (``c`` frames: pymatchmaker's ``window_size * frame_rate`` with
``frame_rate = 1``) and run-count limit. The local cost differs: pymatchmaker computes
scipy's Euclidean distance between the feature vectors, one ``cdist`` call per cell (its
only string metrics; a geodesic distance cannot be passed in), fpdtw the geodesic
distance of eq. 1 (more arithmetic per cell). So the maps differ a little; the report
gives their median difference in frames. The ratio ``peer / ours`` is over the target
frames both timed (pymatchmaker stops when it runs out of reference).

Paper: Dixon (2005), OLTW; FP-DTW Table 2 (per-frame time).
"""

from __future__ import annotations

import json
import os
import sys
import time
from pathlib import Path

import numpy as np

#: The separate environment of the peers (``make bench-peers`` builds it).
PEERS_VENV = Path(__file__).resolve().parents[2] / "build" / "peers-venv"
#: What ``make bench-peers`` installs there (pymatchmaker pins numpy < 2 itself).
PEERS_REQUIREMENTS = ("numpy<2", "pymatchmaker==0.3.0")
#: The pymatchmaker class timed.
PEER_CLASS = "matchmaker.dp.oltw_dixon.OnlineTimeWarpingDixonFrame"
#: Untimed warm-up frames of the peer (its first pair).
PEER_WARMUP_FRAMES = 200


class SameEnvironmentError(RuntimeError):
    """The peers' half was started in the project's environment."""


def check_separate_environment(own_prefix, project_prefix) -> None:
    """Refuse to run the peers in the project's environment.

    Parameters
    ----------
    own_prefix, project_prefix : str or Path
        ``sys.prefix`` of this interpreter and of the one that ran ``export``.

    Raises
    ------
    SameEnvironmentError
        Both are the same environment (pymatchmaker's numpy < 2 would replace the
        project's numpy).
    """
    a, b = Path(own_prefix).resolve(), Path(project_prefix).resolve()
    if a == b:
        raise SameEnvironmentError(
            f"the peers must run in their own environment (make bench-peers builds "
            f"{PEERS_VENV}), not in the project's ({b})"
        )


def pin_one_core() -> None:
    """Pin the process to its first allowed core (single-core numbers, as ``make bench``)."""
    if hasattr(os, "sched_setaffinity"):
        os.sched_setaffinity(0, {sorted(os.sched_getaffinity(0))[0]})


# --- half 1: the project's environment ---------------------------------------------


def export(path, pairs=None, c=None, max_run_count=3) -> dict:
    """Write the peers' input: the bench pairs as feature vectors, and our OLTW on them.

    Parameters
    ----------
    path : str or Path
        The ``.npz`` file to write.
    pairs : sequence of (MotionFeatures, MotionFeatures), optional
        Default :func:`fpdtw.app.bench.load_bench_pairs`.
    c : int, optional
        OLTW's band (default: the registry's, 120).
    max_run_count : int
        OLTW's run-count limit (pymatchmaker's default, 3).

    Returns
    -------
    meta : dict
        What was written besides the arrays (``c``, ``max_run_count``, ``names``,
        ``project_prefix``, ``out``: where the peers' report goes).
    """
    import inspect

    from fpdtw.app.bench import load_bench_pairs
    from fpdtw.online.base import run_online
    from fpdtw.online.oltw import OLTW
    from fpdtw.paper.paths import results_dir

    pairs = load_bench_pairs() if pairs is None else list(pairs)
    c = inspect.signature(OLTW).parameters["c"].default if c is None else int(c)
    arrays = {}
    for p, (I, T) in enumerate(pairs):
        run_online(OLTW(I, c, max_run_count=max_run_count), T)  # warm-up
        M, dt = run_online(OLTW(I, c, max_run_count=max_run_count), T)
        arrays[f"ref{p}"] = I.quats.reshape(I.n_frames, -1)
        arrays[f"live{p}"] = T.quats.reshape(T.n_frames, -1)
        arrays[f"ours_map{p}"] = M
        arrays[f"ours_s{p}"] = dt
    meta = {
        "c": c,
        "max_run_count": int(max_run_count),
        "names": [f"{I.name} -> {T.name}" for I, T in pairs],
        "project_prefix": sys.prefix,
        "out": str(results_dir() / "bench_peers.json"),
    }
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    np.savez(path, meta=np.array(json.dumps(meta)), **arrays)
    return meta


# --- half 2: the peers' environment ------------------------------------------------


def read_export(path) -> tuple:
    """``(meta, pairs)`` of an :func:`export` file; ``pairs``: a list of dicts with
    ``ref``, ``live`` (feature vectors), ``ours_map``, ``ours_s``."""
    with np.load(path) as z:
        meta = json.loads(str(z["meta"]))
        pairs = [
            {key: z[f"{key}{p}"] for key in ("ref", "live", "ours_map", "ours_s")}
            for p in range(len(meta["names"]))
        ]
    return meta, pairs


def time_peer(make, live, warmup=0) -> tuple:
    """Feed ``live`` frames one call at a time to a fresh ``make()``, timing each call.

    Parameters
    ----------
    make : callable
        ``make() -> tracker`` with pymatchmaker's interface: ``tracker(frame, t)``,
        ``tracker.best_ref``, ``tracker.is_still_following()``.
    live : ndarray, shape (n, d)
    warmup : int
        First run this many frames through another fresh tracker, untimed.

    Returns
    -------
    positions : ndarray of int64, shape (n_timed,)
        The tracker's reference frame after each call.
    seconds : ndarray of float, shape (n_timed,)
        Time of each call; stops where the tracker ran out of reference.
    """
    if warmup:
        w = make()
        for q in range(min(warmup, len(live))):
            w(live[q], float(q))
            if not w.is_still_following():
                break
    a = make()
    positions, seconds = [], []
    clock = time.perf_counter
    for q in range(len(live)):
        t0 = clock()
        a(live[q], float(q))
        t1 = clock()
        if not a.is_still_following():
            break
        seconds.append(t1 - t0)
        positions.append(int(a.best_ref))
    return np.array(positions, dtype=np.int64), np.array(seconds)


def compare(meta, pairs, peer_runs, peer_name, environment) -> dict:
    """The report of ``make bench-peers`` from our streamed times and the peer's.

    Parameters
    ----------
    meta, pairs
        :func:`read_export`.
    peer_runs : list of (positions, seconds)
        :func:`time_peer` per pair.
    peer_name : str
    environment : dict
        The peers' environment (Python, numpy, pymatchmaker, prefix).

    Returns
    -------
    report : dict
        ``{"oltw": {...}, "environment": ..., "pairs": ...}``; ``oltw`` has ``peer``,
        ``frames`` (timed by both), ``ours_median_s``, ``peer_median_s``,
        ``peer_over_ours``, ``map_median_abs_diff`` (frames), ``c``, ``max_run_count``,
        ``distance``, ``measured`` (UTC date).
    """
    ours, theirs, diff = [], [], []
    for pair, (pos, sec) in zip(pairs, peer_runs):
        n = len(sec)
        ours.append(np.asarray(pair["ours_s"])[:n])
        theirs.append(sec)
        diff.append(np.abs(np.asarray(pair["ours_map"])[:n] - pos))
    ours, theirs, diff = (np.concatenate(x) if x else np.empty(0) for x in (ours, theirs, diff))
    if ours.size == 0:
        raise ValueError("the peer timed no frame")
    o, p = float(np.median(ours)), float(np.median(theirs))
    return {
        "oltw": {
            "peer": peer_name,
            "frames": int(ours.size),
            "ours_median_s": o,
            "peer_median_s": p,
            "peer_over_ours": p / o,
            "map_median_abs_diff": float(np.median(diff)),
            "c": meta["c"],
            "max_run_count": meta["max_run_count"],
            "distance": "peer: Euclidean between the flat quaternion vectors (scipy cdist per "
            "cell); ours: geodesic (eq. 1)",
            "measured": time.strftime("%Y-%m-%d", time.gmtime()),
        },
        "environment": environment,
        "pairs": meta["names"],
    }


def write_report(report, path) -> Path:
    """Write ``report`` as JSON to ``path`` (atomically); returns the path."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(".json.part")
    tmp.write_text(json.dumps(report, indent=1) + "\n")
    os.replace(tmp, path)
    return path


def run_peer(path, out=None) -> dict:
    """Time pymatchmaker's OLTW-Dixon on an :func:`export` file, in the peers' environment,
    and write ``results/bench_peers.json`` (or ``out``).
    """
    meta, pairs = read_export(path)
    check_separate_environment(sys.prefix, meta["project_prefix"])
    import platform

    import matchmaker
    from matchmaker.dp.oltw_dixon import OnlineTimeWarpingDixonFrame

    try:
        from importlib.metadata import version

        pm_version = version("pymatchmaker")
    except Exception:  # noqa: BLE001 - a version string only
        pm_version = getattr(matchmaker, "__version__", "unknown")

    def maker(ref):
        beats = np.arange(len(ref), dtype=float)

        def make():
            return OnlineTimeWarpingDixonFrame(
                ref,
                beats,
                window_size=meta["c"],
                frame_rate=1,
                max_run_count=meta["max_run_count"],
                ref_frame_to_beat=beats,
            )

        return make

    runs = [
        time_peer(maker(p["ref"]), p["live"], warmup=PEER_WARMUP_FRAMES if i == 0 else 0)
        for i, p in enumerate(pairs)
    ]
    environment = {
        "python": platform.python_version(),
        "numpy": np.__version__,
        "pymatchmaker": pm_version,
        "prefix": sys.prefix,
    }
    report = compare(meta, pairs, runs, f"pymatchmaker {pm_version} OLTW-Dixon", environment)
    write_report(report, out or meta["out"])
    return report


def main(argv=None) -> int:
    """``export FILE`` (project's environment) or ``peer FILE [--out JSON]`` (the peers')."""
    import argparse

    ap = argparse.ArgumentParser(description=main.__doc__)
    sub = ap.add_subparsers(dest="cmd", required=True)
    e = sub.add_parser("export", help="write the pairs and our OLTW times (project env)")
    e.add_argument("file")
    r = sub.add_parser("peer", help="time pymatchmaker on an export (peers' env)")
    r.add_argument("file")
    r.add_argument("--out", default=None)
    args = ap.parse_args(argv)
    pin_one_core()
    if args.cmd == "export":
        meta = export(args.file)
        print(f"wrote {args.file}: {len(meta['names'])} pairs, OLTW c={meta['c']}")
        return 0
    report = run_peer(args.file, args.out)
    o = report["oltw"]
    print(
        f"OLTW per frame over {o['frames']} frames: ours {o['ours_median_s'] * 1e6:.1f} us, "
        f"{o['peer']} {o['peer_median_s'] * 1e6:.1f} us: peer/ours {o['peer_over_ours']:.0f}x "
        f"(maps differ by {o['map_median_abs_diff']:.0f} frames, median)"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())


__all__ = [
    "PEERS_VENV",
    "SameEnvironmentError",
    "check_separate_environment",
    "compare",
    "export",
    "read_export",
    "run_peer",
    "time_peer",
    "write_report",
]
