"""Run the experiment grid over every pair of a selection, in parallel and resumably.

Per pair of a mode's selection (:mod:`.selection`) and algorithm of its grid (:mod:`.grid`):
the map ``M`` (target frame -> input frame), the similarity (eq. 2) and the deviation (eq. 3)
from DTW's map at the same rate, in frames. Under ``results_dir()/<mode>/``, written atomically:

``pairs.json``
    ``{"mode", "selection", "counts", "pairs": [{"id", "dataset", "movement", "input",
    "target", "input_path", "target_path", "m", "n", "m60", "n60"}, ...]}``: ``m``, ``n``
    the last frame indices of input and target at 120 Hz, ``m60``, ``n60`` at 60 Hz.
``algorithms/<slug>.npz``
    ``pair_id`` (P,) int32, ``offsets`` (P+1,) int64, ``maps`` int32 (pair k's map is
    ``maps[offsets[k]:offsets[k+1]]``), ``similarity``, ``deviation`` (P,) float64.
``summary.json`` (:func:`summarize`); ``run.json`` (keys, what was computed where, times,
the environment: not deterministic); caches ``features/`` (per motion) and ``chunks/`` (per
work unit: an input motion against every other take of its movement, every algorithm).

A killed run resumes from its finished chunks to the same files. The *config key* (mode,
algorithms, pairs, data hashes, every source file) decides "nothing changed"; the *base key*
(mode, selection, data hashes, pairs, :data:`CACHE_FORMAT`, :func:`compute_files`' source)
whether a chunk is valid; an added algorithm is computed alone. One run at a time per
results folder. Command line: ``fpdtw experiments run``; on Dask: :mod:`.parallel`.

Paper: FP-DTW Section 4 (pairs), eq. 2 and eq. 3, Figs. 5-7 and 10, Tables 1 and 2.
Notebook: 05_run_experiments.ipynb
"""

from __future__ import annotations

import datetime as _dt
import functools
import hashlib
import itertools
import json
import os
import shutil
import socket
import time
from collections import Counter
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from fpdtw import registry
from fpdtw.errors import AlignmentError, ClusterError, MotionFormatError
from fpdtw.metrics import deviation, joint_trajectories, trajectory_scores
from fpdtw.motion.features import MotionFeatures
from fpdtw.motion.joints import OPW_JOINTS
from fpdtw.online.window import WindowCache, run_group
from fpdtw.paper import catalog, numbers, provenance
from fpdtw.paper.atomic import TMP_SUFFIX, write_atomic
from fpdtw.paper.edits import EDITS, edit_target, fits
from fpdtw.paper.paths import results_dir
from fpdtw.paper.pause import insert_pause
from fpdtw.paper.runner.grid import mode_algorithms, split_rate, split_transform
from fpdtw.paper.runner.parallel import CONNECT_TIMEOUT, Executor, make_executor, scheduler_from_env
from fpdtw.paper.runner.results import (
    BASE_FPS,
    LOW_FPS,
    Results,
    load_json,
    load_npz,
    load_results,  # noqa: F401 - re-exported (fpdtw.paper.runner.run.load_results)
    save_json,
    save_npz,
    slug,
)
from fpdtw.paper.runner.selection import (
    SELECTIONS,
    PairSelection,
    Selection,
    format_counts,
    pair_selection,
    run_plan,
)

#: Bump when the feature cache or chunk layout, or what this module computes, changes.
CACHE_FORMAT = 3

_PKG_ROOT = Path(__file__).resolve().parents[2]
#: The reproduction's modules that decide numbers: the catalogue, the pause and the edits in
#: targets.
_PAPER_COMPUTE = ("paper/catalog.py", "paper/pause.py", "paper/edits.py")
_META = "__meta__"


@dataclass(frozen=True)
class AlgorithmSpec:
    """How one named algorithm of a run runs: its name in results (``"Mc w40@60Hz"``), the
    registry's algorithm, the frame rate of its features and its target ``transform``
    (``"pause"``: a held pose inserted, or an edit of :data:`~fpdtw.paper.edits.EDITS`; the
    deviation from DTW of the modified pair)."""

    name: str
    algorithm: registry.Algorithm
    fps: float
    transform: str | None = None

    @property
    def slug(self) -> str:
        return slug(self.name)


def resolve_algorithm(name: str) -> AlgorithmSpec:
    """The :class:`AlgorithmSpec` of a registry name, ``"@60Hz"`` for 60 Hz, ``"@pause"``
    for the targets with a pause inserted (AlignmentError: an unknown name)."""
    base, transform = split_transform(name)
    base, fps = split_rate(base)
    return AlgorithmSpec(name, registry.resolve(base), fps, transform)


def transform_target(transform, T: MotionFeatures) -> MotionFeatures:
    """The target an algorithm of ``transform`` runs on (None: ``T`` itself)."""
    if transform is None:
        return T
    if transform == "pause":
        return insert_pause(T)
    if transform in EDITS:
        return edit_target(T, transform)[0]
    raise AlignmentError(f"unknown target transform {transform!r}")


def _check_map(spec: AlgorithmSpec, M, I: MotionFeatures, T: MotionFeatures, info: dict):
    """The map as int64 (n+1,), or an error naming the algorithm and the pair."""
    M = np.asarray(M)
    n1, m = T.n_frames, I.n_frames - 1
    if M.shape != (n1,) or not np.issubdtype(M.dtype, np.integer):
        raise AlignmentError(
            f"{spec.name} on pair {info['id']}: the map must be an int array "
            f"of shape ({n1},), got {M.dtype} {M.shape}"
        )
    if M.min() < 0 or M.max() > m:
        raise AlignmentError(f"{spec.name} on pair {info['id']}: map entries outside 0..{m}")
    return M.astype(np.int64)


def _hash(obj) -> str:
    return hashlib.sha256(json.dumps(obj, sort_keys=True, default=str).encode()).hexdigest()


def source_hash(files=None) -> str:
    """sha256 of fpdtw source files: all of them, or the ones given (relative paths)."""
    if files is None:
        files = sorted(str(p.relative_to(_PKG_ROOT)) for p in _PKG_ROOT.rglob("*.py"))
    h = hashlib.sha256()
    for f in files:
        h.update(f.encode() + b"\0" + (_PKG_ROOT / f).read_bytes() + b"\0")
    return h.hexdigest()


def compute_files() -> list:
    """The source files that decide a run's features, maps and scores: the library (outside
    ``fpdtw/paper`` and ``fpdtw/app``), the catalogue and the pause inserted into targets;
    editing the rest keeps a run's chunks (a change to what this module computes bumps
    :data:`CACHE_FORMAT`)."""
    rels = [p.relative_to(_PKG_ROOT) for p in sorted(_PKG_ROOT.rglob("*.py"))]
    return [str(r) for r in rels if r.parts[0] not in ("paper", "app") or str(r) in _PAPER_COMPUTE]


def load_motion(record, crop, fps: float = BASE_FPS):
    """A motion of a run as its features are built from it: at 120 Hz, cropped to its first
    ``crop`` seconds (None: whole), then at ``fps``."""
    motion = catalog.load(record)
    if abs(motion.fps - BASE_FPS) > 1e-6:
        motion = motion.resample(BASE_FPS)
    if crop is not None:
        motion = motion.crop(0.0, crop)
    return motion if fps == BASE_FPS else motion.resample(fps)


def _build_feature_file(record, path: Path, crop, code: str) -> Path:
    """Load one motion, build its 120 Hz and 60 Hz features and save them (worker; ``code``:
    the run's :func:`_code_key`)."""
    _check_code(code)
    motion = load_motion(record, crop)
    arrays = {}
    for tag, mo in (("120", motion), ("60", motion.resample(LOW_FPS))):
        try:
            f = MotionFeatures.from_motion(mo, position_joints=OPW_JOINTS)
        except MotionFormatError:  # a skeleton without every OPW joint: no positions
            f = MotionFeatures.from_motion(mo)
        arrays[f"quats{tag}"] = f.quats
        arrays[f"euler{tag}"] = f.euler
        if f.positions is not None:
            arrays[f"positions{tag}"] = f.positions
        arrays[f"fps{tag}"] = np.float64(f.fps)
    arrays["orders"] = np.array(motion.rotation_orders(), dtype="U8")
    arrays["name"] = np.array(motion.name)
    save_npz(path, **arrays)
    return path


@functools.lru_cache(maxsize=96)
def _load_features_file(path: str) -> dict:
    return load_npz(path)


def load_features(path, fps: float = BASE_FPS) -> MotionFeatures:
    """Features of one motion from the feature cache, at 120 or 60 Hz: quaternions (F, 8, 4),
    unwrapped Euler angles (F, 8, 3) and, where the skeleton has them, the positions
    (F, 16, 3) of the OPW joints."""
    a = _load_features_file(str(path))
    tag = "120" if fps == BASE_FPS else "60"
    q, e, p = (a.get(f"{k}{tag}") for k in ("quats", "euler", "positions"))
    orders = tuple(str(o) for o in a["orders"])
    return MotionFeatures(q, e, orders, float(a[f"fps{tag}"]), p, str(a["name"]))


def pair_features(results, fps: float = BASE_FPS):
    """``features(k) -> (I, T)``: the features at ``fps`` (120 or 60) of pair k of a finished
    run, from its feature cache (missing files are built).

    Notebook: 15_readings_of_algorithm_3.ipynb
    """
    plan, index = run_plan(results)
    files = build_features(plan, results.folder / "features", n_jobs=1, progress=False)

    def features(k: int):
        i, t = index[k]
        return load_features(files[i], fps), load_features(files[t], fps)

    return features


def _worker_name() -> str:
    return f"{socket.gethostname()}:{os.getpid()}"


def _code_key() -> str:
    """What decides the computed numbers in this process: CACHE_FORMAT and the library source."""
    return f"{CACHE_FORMAT}:{source_hash(compute_files())}"


_worker_code_key = functools.lru_cache(maxsize=1)(_code_key)


def _check_code(expected: str) -> None:
    """ClusterError when this process's :func:`_code_key` (taken at its first task) is not
    the run's: a cluster worker with another fpdtw."""
    have = _worker_code_key()
    if have != expected:
        raise ClusterError(
            f"worker {_worker_name()} runs other fpdtw code than the run it works for "
            f"(CACHE_FORMAT:library source {have[:20]} from {_PKG_ROOT}, the run's "
            f"{expected[:20]}): install the same fpdtw commit on every worker and restart them"
        )


def _reuse_features(folder: Path, files: list) -> None:
    """Copy into ``folder`` the missing feature files another mode of the same results folder
    built (a name holds the hash of everything that decides the bytes), whole or not at all."""
    siblings = [d / "features" for d in folder.parent.parent.iterdir() if d.is_dir()]
    siblings = [d for d in siblings if d.is_dir() and d.resolve() != folder.resolve()]
    for p in files:
        if not p.is_file():
            src = next((d / p.name for d in siblings if (d / p.name).is_file()), None)
            if src is not None:
                write_atomic(p, src.read_bytes())


def build_features(
    plan: PairSelection, folder: Path, n_jobs=2, progress=True, executor: Executor | None = None
) -> list:
    """The feature cache file in ``folder`` of each motion of a plan, copied from another mode
    or built where missing (on ``executor``, else ``n_jobs`` joblib processes)."""
    folder.mkdir(parents=True, exist_ok=True)
    crop = plan.selection.crop_seconds
    src = source_hash(compute_files())
    files = [
        folder / f"{r.name}_{_hash([CACHE_FORMAT, d, crop, src])[:16]}.npz"
        for r, d in zip(plan.motions, plan.sha256)
    ]
    code = _code_key()
    _reuse_features(folder, files)
    todo = [(r, p, crop, code) for r, p in zip(plan.motions, files) if not p.is_file()]
    if todo:
        ex = executor if executor is not None else Executor(n_jobs)
        keys = [f"fpdtw-features-{p.stem}" for _, p, _, _ in todo]
        list(ex.map(_build_feature_file, todo, desc="features", progress=progress, keys=keys))
        ex.settle([p for _, p, _, _ in todo], Path.is_file, "feature files", folder)
    _prune(folder, {p.name for p in files})  # features of another crop or older code
    return files


def _prune(folder: Path, keep: set) -> None:
    """Remove the ``.npz`` files of ``folder`` not named in ``keep``."""
    for p in folder.glob("*.npz"):
        if p.name not in keep:
            p.unlink()


def _chunk_algorithms(path: Path, base_key: str) -> set:
    """Names of the algorithms a chunk holds; empty if missing, unreadable or stale."""
    if not path.is_file():
        return set()
    try:
        meta = json.loads(bytes(load_npz(path, [_META])[_META]).decode())
    except Exception:  # a chunk we cannot read is recomputed
        return set()
    return set(meta.get("algorithms", [])) if meta.get("base_key") == base_key else set()


def _pair_maps(specs: list, I: MotionFeatures, T: MotionFeatures, info: dict) -> dict:
    """``{name: M}`` of every spec on one pair at one rate: Methods B and C in one compiled
    loop sharing one :class:`WindowCache` (:func:`~fpdtw.online.window.run_group`)."""
    out = {}
    shared = [s for s in specs if s.algorithm.shares_window]
    if shared:
        cache = WindowCache(I, max(s.algorithm.w for s in shared))
        aligners = [s.algorithm.make(I, cache=cache) for s in shared]
        out = dict(zip([s.name for s in shared], run_group(aligners, T)))
    for s in specs:
        if s.name not in out:
            out[s.name] = s.algorithm.run(I, T)[0]
    return {s.name: _check_map(s, out[s.name], I, T, info) for s in specs}


def _compute_unit(unit: dict, specs: list, feature_files, base_key: str, code: str) -> dict:
    """Compute ``specs`` on every pair of one unit and write its chunk, keeping the
    algorithms it held that are not recomputed (worker). ``feature_files``: motion index ->
    feature file. Returns ``{"unit", "pairs", "runs", "seconds", "worker"}``."""
    t0 = time.perf_counter()
    _check_code(code)
    path = Path(unit["chunk"])
    pairs = unit["pairs"]
    keep = _chunk_algorithms(path, base_key) - {s.name for s in specs}
    arrays = {}
    if keep:
        stored = load_npz(path)
        for n in keep:
            pre = slug(n) + "."
            arrays.update({k: v for k, v in stored.items() if k.startswith(pre)})

    per = {s.name: [] for s in specs}  # per pair (map, similarity, deviation)
    for p in pairs:
        info = {key: v for key, v in p.items() if key not in ("input_index", "target_index")}
        for fps, transform in sorted(
            {(s.fps, s.transform) for s in specs}, key=lambda g: (-g[0], g[1] or "")
        ):
            group = [s for s in specs if s.fps == fps and s.transform == transform]
            I = load_features(feature_files[p["input_index"]], fps)
            T = load_features(feature_files[p["target_index"]], fps)
            if transform in EDITS and not fits(T.n_frames, T.fps, transform):
                for s in group:  # no result: an empty map, NaN scores
                    per[s.name].append((np.zeros(0, np.int64), np.nan, np.nan))
                continue
            T = transform_target(transform, T)
            maps = _pair_maps(group, I, T, {**info, "fps": fps})
            dtw_spec = next((s for s in group if s.algorithm.family == "DTW"), None)
            dtw = registry.align("DTW", I, T)[0] if dtw_spec is None else maps[dtw_spec.name]
            XI, XT = joint_trajectories(I.quats), joint_trajectories(T.quats)
            for s in group:
                M = maps[s.name]
                # = similarity(I.quats, T.quats, M), each motion's trajectories once
                sim = float(np.mean(trajectory_scores(XI[M], XT)))
                per[s.name].append((M, sim, deviation(dtw, M)))
    ids = [p["id"] for p in pairs]
    for s in specs:
        maps, sim, dev = zip(*per[s.name])
        fields = _fields(ids, [len(M) for M in maps], maps, sim, dev)
        arrays.update({f"{s.slug}.{k}": v for k, v in fields.items()})
    meta = {
        "unit": unit["id"],
        "base_key": base_key,
        "pair_ids": ids,
        "algorithms": sorted(keep | {s.name for s in specs}),
    }
    arrays[_META] = np.frombuffer(json.dumps(meta).encode(), dtype=np.uint8)
    save_npz(path, **arrays)
    took = time.perf_counter() - t0
    runs = len(pairs) * len(specs)  # every algorithm on every pair
    return dict(unit=unit["id"], pairs=len(pairs), runs=runs, seconds=took, worker=_worker_name())


#: The arrays of an algorithm's results, in file order (chunks and ``algorithms/*.npz``).
_FIELDS = ("pair_id", "offsets", "maps", "similarity", "deviation")


def _fields(ids, lengths, maps, sim, dev) -> dict:
    """:data:`_FIELDS` from per-pair (or per-chunk) parts: ids, map lengths, maps, scores."""
    offsets = np.concatenate([[0], np.cumsum(lengths)]).astype(np.int64)
    ids, maps = np.hstack(ids).astype(np.int32), np.concatenate(maps).astype(np.int32)
    sim, dev = np.hstack(sim).astype(np.float64), np.hstack(dev).astype(np.float64)
    return dict(zip(_FIELDS, (ids, offsets, maps, sim, dev), strict=True))


def _assemble(out: Path, specs: list, units: list, n_pairs: int) -> None:
    """Write ``algorithms/<slug>.npz`` of ``specs`` from the chunks, in pair order."""
    parts = {s.name: {k: [] for k in _FIELDS} for s in specs}
    for unit in units:
        stored = load_npz(unit["chunk"], [f"{s.slug}.{k}" for s in specs for k in _FIELDS])
        for s in specs:
            for k in _FIELDS:
                parts[s.name][k].append(stored[f"{s.slug}.{k}"])
    for s in specs:
        acc = parts.pop(s.name)
        lengths = np.concatenate([np.diff(o) for o in acc["offsets"]])
        fields = _fields(acc["pair_id"], lengths, acc["maps"], acc["similarity"], acc["deviation"])
        if not np.array_equal(fields["pair_id"], np.arange(n_pairs)):
            raise RuntimeError(f"{s.name}: chunks do not cover pairs 0..{n_pairs - 1} in order")
        save_npz(out / "algorithms" / f"{s.slug}.npz", **fields)


def _share(x) -> float | None:
    return float(np.mean(x)) if x.size else None


def _stats(x) -> dict:
    x = np.asarray(x, dtype=np.float64)
    if not x.size:
        return dict.fromkeys(("median", "mean", "q1", "q3"), float("nan"))
    q1, med, q3 = np.percentile(x, [25, 50, 75])
    return {"median": float(med), "mean": float(np.mean(x)), "q1": float(q1), "q3": float(q3)}


def summarize(results: Results) -> dict:
    """The content of ``summary.json`` (deterministic): ``"eq2"`` (the reading scored with),
    ``"benchmarks"`` (UTW's median similarity at 120 and 60 Hz, None without UTW; the deviation
    benchmark) and per algorithm its medians, means, quartiles, shares of pairs above UTW's
    median and below the deviation benchmark, and whether its medians pass each benchmark.

    Paper: FP-DTW Section 5 (benchmarks), Figs. 5-6, Tables 1-2.
    """
    utw = {}
    for name in results.algorithms:
        if split_rate(name)[0] == "UTW":
            utw[results.fps(name)] = float(np.median(results.get(name)["similarity"]))
    bench = {
        "utw_median_similarity_120hz": utw.get(BASE_FPS),
        "utw_median_similarity_60hz": utw.get(LOW_FPS),
        "deviation_frames": numbers.DEVIATION_BENCHMARK_FRAMES,
        "deviation_ms": numbers.DEVIATION_BENCHMARK_MS,
    }
    algos = {}
    for name in results.algorithms:
        r = results.get(name)
        fps = results.fps(name)
        keep = np.isfinite(r["similarity"])  # a pair without a result (an edit too long)
        sim, dev = r["similarity"][keep], r["deviation"][keep]
        s, d = _stats(sim), _stats(dev)
        u = utw.get(fps)
        dev_ms = dev * 1000.0 / fps
        passes_sim = None if u is None else numbers.passes_similarity(s["median"], u)
        algos[name] = {
            "fps": fps,
            "online": results.is_online(name),
            "n_pairs": int(sim.shape[0]),
            **{f"similarity_{k}": v for k, v in s.items()},  # median, mean, q1, q3
            "deviation_median": d["median"],
            "deviation_mean": d["mean"],
            "frac_above_utw_median": None if u is None or not sim.size else float(np.mean(sim > u)),
            "frac_deviation_below_18": _share(dev < numbers.DEVIATION_BENCHMARK_FRAMES),
            "frac_deviation_below_150ms": _share(dev_ms < numbers.DEVIATION_BENCHMARK_MS),
            "passes_similarity_benchmark": passes_sim,
            "passes_deviation_benchmark": numbers.passes_deviation(d["median"], fps),
        }
    return {"eq2": results.eq2, "benchmarks": bench, "algorithms": algos}


def _now() -> str:
    return _dt.datetime.now(_dt.UTC).isoformat(timespec="seconds")


def _remove_temporaries(out: Path) -> None:
    """Temporary files a killed run left in the runner's own files and folders."""
    for name in ("pairs.json", "summary.json", "run.json"):
        for p in out.glob(f".{name}.*{TMP_SUFFIX}"):
            p.unlink(missing_ok=True)
    for sub in ("features", "chunks", "algorithms"):
        for p in (out / sub).glob(f".*{TMP_SUFFIX}"):
            p.unlink(missing_ok=True)


def _pairs_json(mode, plan, feature_files) -> dict:
    files = [_load_features_file(str(f)) for f in feature_files]
    frames = [(a["quats120"].shape[0] - 1, a["quats60"].shape[0] - 1) for a in files]
    pairs = []
    for p in plan.pairs:
        q = {k: v for k, v in p.items() if k not in ("input_index", "target_index")}
        (m, m60), (n, n60) = frames[p["input_index"]], frames[p["target_index"]]
        q.update(m=int(m), n=int(n), m60=int(m60), n60=int(n60))
        pairs.append(q)
    return dict(mode=mode, selection=plan.selection.as_dict(), counts=plan.counts, pairs=pairs)


def _compute(executor: Executor, mode, plan, specs, out: Path, base_key, progress, say, phases):
    """The features, ``pairs.json`` and every missing chunk of a run (on ``executor``): every
    unit, the ``(cost, unit, missing specs)`` computed, the names of the algorithms computed,
    each computed unit's result; ``phases`` gets the seconds of features and units."""
    t0 = time.perf_counter()
    feature_files = build_features(plan, out / "features", progress=progress, executor=executor)
    save_json(out / "pairs.json", _pairs_json(mode, plan, feature_files))
    phases["features"] = round(time.perf_counter() - t0, 3)
    t0 = time.perf_counter()

    # work units: one input motion against every other take of its movement (adjacent pairs)
    units = []
    for i, group in itertools.groupby(plan.pairs, key=lambda p: p["input_index"]):
        uid = f"{i:04d}_{plan.motions[i].name}"
        units.append({"id": uid, "chunk": str(out / "chunks" / f"{uid}.npz"), "pairs": list(group)})
    (out / "chunks").mkdir(exist_ok=True)
    _prune(out / "chunks", {Path(u["chunk"]).name for u in units})  # another selection's units

    tasks, recomputed = [], set()
    frames = {i: load_features(f).n_frames for i, f in enumerate(feature_files)}
    for u in units:
        have = _chunk_algorithms(Path(u["chunk"]), base_key)
        missing = [s for s in specs if s.name not in have]
        if missing:
            cost = len(missing) * sum(frames[p["target_index"]] for p in u["pairs"])
            tasks.append((cost, u, missing))
            recomputed.update(s.name for s in missing)
    tasks.sort(key=lambda t: -t[0])
    if not tasks:
        say("every unit is already computed")
        return units, tasks, recomputed, []
    say(f"computing {len(tasks)} of {len(units)} units ({len(recomputed)} algorithms)")
    code = _code_key()
    jobs = []
    for _, u, missing in tasks:
        used = sorted({i for p in u["pairs"] for i in (p["input_index"], p["target_index"])})
        jobs.append((u, missing, {i: str(feature_files[i]) for i in used}, base_key, code))
    keys = [f"fpdtw-unit-{u['id']}" for _, u, _ in tasks]
    work = []
    for r in executor.map(_compute_unit, jobs, desc="units", progress=progress, keys=keys):
        if any(w["unit"] == r["unit"] for w in work):  # a task's result delivered twice
            raise RuntimeError(f"unit {r['unit']} was computed twice in one run")
        work.append(r)
    if len(work) != len(jobs):
        raise RuntimeError(f"{len(jobs) - len(work)} units of {len(jobs)} were never computed")
    names = {u["id"]: {s.name for s in missing} for _, u, missing in tasks}
    executor.settle(
        [Path(u["chunk"]) for _, u, _ in tasks],
        lambda p: names[p.stem] <= _chunk_algorithms(p, base_key),
        "chunk files",
        out / "chunks",
    )
    _remove_temporaries(out)  # those of cluster workers that died while writing
    phases["units"] = round(time.perf_counter() - t0, 3)
    return units, tasks, recomputed, work


def run_experiments(
    mode: str = "full",
    algorithms=None,
    n_jobs: int = 2,
    progress: bool = True,
    selection: Selection | None = None,
    *,
    results=None,
    scheduler=None,
    connect_timeout: float = CONNECT_TIMEOUT,
) -> Results:
    """Run the algorithms over every pair of a mode, resumably, and write the result files.

    ``mode``: a mode of :data:`SELECTIONS` (or any folder name with a ``selection``);
    ``algorithms``: registry names (default :func:`~fpdtw.paper.runner.grid.mode_algorithms`),
    other algorithms' results already in the folder are kept; ``n_jobs``: joblib processes;
    ``progress``: print the selection and show progress bars; ``results``: the results root
    (default :func:`fpdtw.paper.paths.results_dir`; on a cluster, a folder every worker sees
    at the same path); ``scheduler``: a Dask scheduler address or client (default
    ``FPDTW_SCHEDULER`` if set, else joblib; ``"local"``: joblib whatever it says).
    ClusterError: a bad scheduler, a worker with other code, workers dying, files not seen here.

    Paper: FP-DTW Sections 4-6.
    Notebook: 05_run_experiments.ipynb
    """
    t_start, start = time.perf_counter(), _now()
    say = print if progress else (lambda *a, **k: None)
    if selection is None:
        if mode not in SELECTIONS:
            raise ValueError(f"mode {mode!r} needs a selection (known modes: {list(SELECTIONS)})")
        selection = SELECTIONS[mode]
    names = list(mode_algorithms(mode) if algorithms is None else algorithms)
    if len(set(names)) != len(names):
        raise ValueError(f"an algorithm is listed twice: {names}")
    specs = [resolve_algorithm(n) for n in names]
    slugs = [s.slug for s in specs]
    if len(set(slugs)) != len(slugs):
        raise ValueError(f"two algorithms share a file name: {slugs}")

    if scheduler is None:
        scheduler = scheduler_from_env()
    executor = make_executor(n_jobs, scheduler, connect_timeout=connect_timeout, say=say)

    plan = pair_selection(selection)
    if not plan.pairs:
        raise ValueError(f"the selection {selection} has no pairs")
    root = results_dir() if results is None else Path(results).expanduser().resolve()
    out = root / mode
    pair_key = [(p["dataset"], p["input_path"], p["target_path"]) for p in plan.pairs]
    compute_src = source_hash(compute_files())
    base_key = _hash([CACHE_FORMAT, mode, selection.as_dict(), plan.sha256, pair_key, compute_src])
    config_key = _hash([mode, names, pair_key, plan.sha256, source_hash()])

    runf = out / "run.json"
    prev = load_json(runf) if runf.is_file() else {}
    outputs = [out / "pairs.json", out / "summary.json"]
    outputs += [out / "algorithms" / f"{a['slug']}.npz" for a in prev.get("algorithms", [])]
    if prev.get("config_key") == config_key and all(f.is_file() for f in outputs):
        say(f"{mode}: nothing to do (config key {config_key[:12]} matches, all outputs in {out})")
        return Results(out)
    if not prev:
        reason = "no earlier run here"
    elif prev.get("config_key") == config_key:
        reason = "some outputs are missing"
    else:
        reason = "the algorithm list, the pairs or the package source changed since the last run"
    say(f"{mode}: {reason}; only what is not computed yet is computed")

    say(f"mode {mode!r}: {selection}")
    say(format_counts(plan.counts))
    if plan.dropped:
        say("left out (fewer than two takes):", ", ".join(plan.dropped))
    where = (
        f"n_jobs={n_jobs}" if executor.kind == "joblib" else f"Dask scheduler {executor.address}"
    )
    say(f"{len(specs)} algorithms, {where}, results in {out}")
    out.mkdir(parents=True, exist_ok=True)
    _remove_temporaries(out)
    phases = {}
    with executor:
        units, tasks, recomputed, work = _compute(
            executor, mode, plan, specs, out, base_key, progress, say, phases
        )
        backend = executor.describe()
        slots = executor.slots
    runs = sum(r["runs"] for r in work)

    # per-algorithm files: (re)written where something changed
    algo_dir = out / "algorithms"
    same_base = prev.get("base_key") == base_key
    prev_algos = {a["name"]: a for a in prev.get("algorithms", [])} if same_base else {}
    assemble = [
        s
        for s in specs
        if s.name in recomputed
        or s.name not in prev_algos
        or not (algo_dir / f"{s.slug}.npz").is_file()
    ]
    if assemble:
        say(f"writing {len(assemble)} algorithm files")
        _assemble(out, assemble, units, len(plan.pairs))
    new = {
        s.name: {"name": s.name, "slug": s.slug, "fps": s.fps, "online": s.algorithm.online}
        for s in specs
    }
    # the algorithms already here (same base key, file present: every requested one's is by
    # now) keep their place, then the requested ones that are new here
    here = {n: a for n, a in prev_algos.items() if (algo_dir / f"{a['slug']}.npz").is_file()}
    info = list({**here, **new}.values())
    _prune(algo_dir, {f"{a['slug']}.npz" for a in info})
    shutil.rmtree(out / "timings", ignore_errors=True)  # written by runs before CACHE_FORMAT 2

    save_json(out / "summary.json", summarize(Results(out, algorithms=info)))

    run = {
        "config_key": config_key,
        "base_key": base_key,
        "mode": mode,
        "selection": selection.as_dict(),
        "requested": names,
        "algorithms": info,
        "source_hash": source_hash(),
        "compute_source_hash": compute_src,
        "counts": plan.counts,
        "computed": {
            "units": len(tasks),
            "units_total": len(units),
            "pair_runs": runs,
            "algorithms": sorted(recomputed),
            "unit_seconds": {
                "total": round(sum(r["seconds"] for r in work), 3),
                "max": round(max((r["seconds"] for r in work), default=0.0), 3),
            },
            "workers": dict(sorted(Counter(r["worker"] for r in work).items())),
        },
        "start": start,
        "end": _now(),
        "wall_seconds": round(time.perf_counter() - t_start, 3),
        "phase_seconds": phases,
        "n_jobs": slots,
        "backend": backend,
        "environment": provenance.environment(),
    }
    save_json(runf, run)
    say(f"done in {run['wall_seconds']:.1f} s ({runs} pair x algorithm runs)")
    return Results(out)
