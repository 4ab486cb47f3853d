"""Run the experiment grid over every pair of a selection, in parallel and resumably.

What runs: the pairs of a mode's selection (:mod:`fpdtw.paper.runner.selection`) and its
algorithms (:mod:`fpdtw.paper.runner.grid`), by the registry's names
(:mod:`fpdtw.registry`). Per pair and algorithm: the map ``M`` (target frame -> input
frame), the similarity (eq. 2) of the warped input and the target and the deviation (eq. 3)
from the DTW map at the same frame rate (in frames of that rate). Methods B and C of a pair
run together in one compiled loop sharing one :class:`fpdtw.online.window.WindowCache` (the
maps are those of separate runs; tested), so the grid does not time frames: per-frame
latency is what ``make bench`` measures (:mod:`fpdtw.paper.bench`).

Files, under ``results_dir()/<mode>/`` (every write atomic: temporary file +
:func:`os.replace`; ``.npz`` files by :func:`fpdtw.paper.runner.results.save_npz`, byte for
byte the same for the same arrays)

``pairs.json``
    ``{"mode", "selection", "counts": {dataset: {motions, movements, pairs}, ...,
    "total": {...}}, "pairs": [{"id", "dataset", "movement", "input", "target",
    "input_path", "target_path", "m", "n", "m60", "n60"}, ...]}``; ``m``, ``n`` are
    the last frame indices of input and target at 120 Hz, ``m60``, ``n60`` at 60 Hz.
``algorithms/<slug>.npz`` (slug: :func:`slug`, e.g. ``"Mc_w40_TypeV"``)
    ``pair_id`` (P,) int32, ``offsets`` (P+1,) int64, ``maps`` int32 (the map of
    pair k is ``maps[offsets[k]:offsets[k+1]]``), ``similarity`` (P,) float64,
    ``deviation`` (P,) float64. Deterministic.
``summary.json``
    ``{"benchmarks": {...}, "algorithms": {name: {...}}}`` (see :func:`summarize`).
    Deterministic.
``run.json``
    The keys, what was computed, start and end time, wall time, n_jobs, and the
    environment (package versions, Python, the package's commit, the CPU:
    :func:`fpdtw.paper.provenance.environment`).
``features/``, ``chunks/``
    Caches: the features of every motion (keyed by the data file's sha256, the crop
    and the library's source) and one file per work unit (one input motion against
    every other take of its movement, every algorithm).

Resuming: a run killed at any point (even by SIGKILL) resumes from the finished chunks and
ends with the same ``algorithms/*.npz``, ``pairs.json`` and ``summary.json`` as an
uninterrupted run. A re-run with nothing changed returns at once. The *config key* (mode,
algorithm list, pair list, data hashes, every source file of the package) decides "nothing
changed"; the *base key* (mode, selection, data hashes, pair list, :data:`CACHE_FORMAT` and
the library's source, :func:`compute_files`) decides whether a chunk is still valid. A
chunk holds the algorithms it was computed for; a run that adds one computes only it. One
run at a time per results folder.

Reading: :func:`load_results` -> :class:`Results` (``.pairs``, ``.algorithms``,
``.get(name)`` with ``.map(k)``, ``.summary``) and :func:`aggregate_heatmap`, defined in
:mod:`fpdtw.paper.runner.results`.

Command line::

    python -m fpdtw.paper.runner.run [--mode full|smoke|study|smoke-study] [--jobs N]
                                     [--algorithms NAME ...] [--quiet]

Paper: FP-DTW Section 4 (pairs), eq. 2 and eq. 3, Figs. 5-7 and 10, Tables 1 and 2.
Notebook: 05_run_experiments.ipynb
"""

from __future__ import annotations

import argparse
import datetime as _dt
import functools
import hashlib
import json
import shutil
import sys
import time
from collections import OrderedDict
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from fpdtw import registry
from fpdtw.errors import AlignmentError, MotionFormatError
from fpdtw.metrics import deviation, joint_trajectories, trajectory_scores
from fpdtw.motion.features import MotionFeatures
from fpdtw.motion.joints import OPW_JOINTS
from fpdtw.online.window import WindowCache, run_group
from fpdtw.paper import catalog, numbers, provenance
from fpdtw.paper.paths import results_dir
from fpdtw.paper.runner.grid import (
    DEFAULT_ALGORITHMS,
    MODE_ALGORITHMS,
    split_rate,
)
from fpdtw.paper.runner.results import (
    BASE_FPS,
    LOW_FPS,
    TMP_SUFFIX,
    Results,
    load_json,
    load_npz,
    load_results,
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
)

#: Bump when the feature cache or chunk layout, or what this module computes, changes.
CACHE_FORMAT = 3

_PKG_ROOT = Path(__file__).resolve().parents[2]
_META = "__meta__"


# -- algorithms --------------------------------------------------------------------------------


@dataclass(frozen=True)
class AlgorithmSpec:
    """How one named algorithm of a run runs.

    Attributes
    ----------
    name : str
        Name in results (e.g. ``"Mc w40@60Hz"``).
    algorithm : fpdtw.registry.Algorithm
        The registry's algorithm of the name without its rate suffix.
    fps : float
        Frame rate of the features it gets (120 or 60).
    """

    name: str
    algorithm: registry.Algorithm
    fps: float

    @property
    def slug(self) -> str:
        return slug(self.name)


def resolve_algorithm(name: str) -> AlgorithmSpec:
    """The :class:`AlgorithmSpec` of a name (any registry name, ``"@60Hz"`` for 60 Hz).

    Raises
    ------
    AlignmentError
        Unknown name.
    """
    base, fps = split_rate(name)
    return AlgorithmSpec(name, registry.resolve(base), fps)


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


# -- keys ----------------------------------------------------------------------------------------


def _hash(obj) -> str:
    return hashlib.sha256(json.dumps(obj, sort_keys=True, default=str).encode()).hexdigest()


def source_hash(files=None) -> str:
    """sha256 of fpdtw source files: all of them, or the ones given (relative paths).

    Notebook: 05_run_experiments.ipynb
    """
    if files is None:
        files = sorted(str(p.relative_to(_PKG_ROOT)) for p in _PKG_ROOT.rglob("*.py"))
    h = hashlib.sha256()
    for f in files:
        h.update(f.encode() + b"\0" + (_PKG_ROOT / f).read_bytes() + b"\0")
    return h.hexdigest()


def compute_files() -> list:
    """The source files whose code decides the features, maps and scores of a run.

    The library (every module outside ``fpdtw/paper`` and ``fpdtw/app``: readers,
    features, costs, aligners, metrics, the registry) and the catalogue that loads the
    motions. The rest of the paper layer (figures, claims, this runner's bookkeeping) does
    not change what is computed: editing it keeps a finished run's chunks. A change to
    what this module computes bumps :data:`CACHE_FORMAT`.
    """
    out = []
    for p in sorted(_PKG_ROOT.rglob("*.py")):
        rel = p.relative_to(_PKG_ROOT)
        if rel.parts[0] not in ("paper", "app") or rel == Path("paper/catalog.py"):
            out.append(str(rel))
    return out


# -- features ----------------------------------------------------------------------------------


def _feature_file(folder: Path, record, digest: str, crop, src: str) -> Path:
    key = _hash([CACHE_FORMAT, digest, crop, src])[:16]
    return folder / f"{record.name}_{key}.npz"


def _features_of(motion) -> dict:
    try:
        f = MotionFeatures.from_motion(motion, position_joints=OPW_JOINTS)
    except MotionFormatError:  # a skeleton without every OPW joint: no positions
        f = MotionFeatures.from_motion(motion)
    return f


def _build_feature_file(record, path: Path, crop) -> tuple:
    """Load one motion, build its 120 Hz and 60 Hz features and save them (worker)."""
    motion = catalog.load(record)
    if abs(motion.fps - BASE_FPS) > 1e-6:
        motion = motion.resample(BASE_FPS)
    if crop is not None:
        motion = motion.crop(0.0, crop)
    arrays = {}
    for tag, mo in (("120", motion), ("60", motion.resample(LOW_FPS))):
        f = _features_of(mo)
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
    """Features of one motion from the feature cache, at 120 or 60 Hz.

    Returns
    -------
    MotionFeatures
        Quaternions (F, 8, 4), unwrapped Euler angles (F, 8, 3), positions (F, 16, 3)
        of the OPW joints where the skeleton has them.

    Notebook: 05_run_experiments.ipynb
    """
    a = _load_features_file(str(path))
    tag = "120" if fps == BASE_FPS else "60"
    return MotionFeatures(
        a[f"quats{tag}"],
        a[f"euler{tag}"],
        tuple(str(o) for o in a["orders"]),
        float(a[f"fps{tag}"]),
        a.get(f"positions{tag}"),
        str(a["name"]),
    )


def pair_features(results, fps: float = BASE_FPS):
    """A function ``features(k) -> (I, T)``: the features of pair k of a finished run.

    Read from the run's feature cache (nothing is recomputed when the cache is there;
    missing files are built).

    Parameters
    ----------
    results : Results
    fps : float
        120 or 60.

    Returns
    -------
    features : callable

    Notebook: 15_readings_of_algorithm_3.ipynb
    """
    selection = Selection(
        **{k: tuple(v) if isinstance(v, list) else v for k, v in results.selection.items()}
    )
    plan = pair_selection(selection)
    files = build_features(plan, results.folder / "features", n_jobs=1, progress=False)
    by_id = {p["id"]: (p["input_index"], p["target_index"]) for p in plan.pairs}
    ids = [int(p["id"]) for p in results.pairs]

    def features(k: int):
        i, t = by_id[ids[k]]
        return load_features(files[i], fps), load_features(files[t], fps)

    return features


# -- parallel helper ---------------------------------------------------------------------------


def _parallel(fn, tasks, n_jobs, progress, desc):
    """Run ``fn(*task)`` over tasks with joblib, yielding results as they finish."""
    from joblib import Parallel, delayed
    from tqdm import tqdm

    gen = Parallel(n_jobs=n_jobs, return_as="generator_unordered", batch_size=1)(
        delayed(fn)(*t) for t in tasks
    )
    bar = tqdm(
        total=len(tasks),
        desc=desc,
        disable=not progress,
        file=sys.stderr,
        mininterval=1.0,
        smoothing=0.05,
    )
    try:
        for r in gen:
            bar.update(1)
            yield r
    finally:
        bar.close()


def build_features(plan: PairSelection, folder: Path, n_jobs=2, progress=True) -> list:
    """Feature cache files of every motion of a plan (built where missing).

    Returns
    -------
    paths : list of Path
        One per motion of ``plan.motions``.

    Notebook: 05_run_experiments.ipynb
    """
    folder.mkdir(parents=True, exist_ok=True)
    crop = plan.selection.crop_seconds
    src = source_hash(compute_files())
    files = [_feature_file(folder, r, d, crop, src) for r, d in zip(plan.motions, plan.sha256)]
    todo = [(r, p, crop) for r, p in zip(plan.motions, files) if not p.is_file()]
    if todo:
        for _ in _parallel(_build_feature_file, todo, n_jobs, progress, "features"):
            pass
    keep = {p.name for p in files}
    for p in folder.glob("*.npz"):  # features of another crop or older code
        if p.name not in keep:
            p.unlink()
    return files


# -- work units --------------------------------------------------------------------------------


def _unit_id(index: int, record) -> str:
    return f"{index:04d}_{record.name}"


def _chunk_meta(path: Path, base_key: str) -> dict:
    """The metadata of a chunk, {} if missing, unreadable or stale."""
    if not path.is_file():
        return {}
    try:
        meta = json.loads(bytes(load_npz(path, [_META])[_META]).decode())
    except Exception:  # a chunk we cannot read is recomputed
        return {}
    return meta if meta.get("base_key") == base_key else {}


def _chunk_algorithms(path: Path, base_key: str) -> set:
    """Names of the algorithms a chunk holds; empty if missing, unreadable or stale."""
    return set(_chunk_meta(path, base_key).get("algorithms", []))


def _pair_maps(specs: list, I: MotionFeatures, T: MotionFeatures, info: dict) -> dict:
    """``{name: M}`` of every spec on one pair at one rate.

    Methods B and C run together in one compiled loop (:func:`fpdtw.online.window.run_group`)
    sharing one :class:`WindowCache` (each forecast and cost cell computed once per target
    frame; the maps are those of separate runs); every other algorithm runs on its own.
    """
    out = {}
    shared = [s for s in specs if s.algorithm.shares_window]
    if shared:
        cache = WindowCache(I, max(s.algorithm.w for s in shared))
        aligners = [s.algorithm.make(I, cache=cache) for s in shared]
        for s, M in zip(shared, run_group(aligners, T)):
            out[s.name] = M
    for s in specs:
        if s.name not in out:
            out[s.name] = s.algorithm.run(I, T)[0]
    return {name: _check_map(s, out[s.name], I, T, info) for s in specs for name in [s.name]}


def _compute_unit(unit: dict, specs: list, feature_files: list, base_key: str) -> dict:
    """Compute the algorithms ``specs`` on every pair of one unit and write its chunk (worker).

    The chunk keeps the algorithms it already held (same base key) that are not
    recomputed. Returns ``{"unit", "pairs", "runs", "seconds"}``.
    """
    t0 = time.perf_counter()
    path = Path(unit["chunk"])
    pairs = unit["pairs"]
    keep = _chunk_algorithms(path, base_key) - {s.name for s in specs}
    arrays = {}
    if keep:
        stored = load_npz(path)
        for n in keep:
            pre = slug(n) + "."
            arrays.update({k: v for k, v in stored.items() if k.startswith(pre)})

    per = {s.name: {"maps": [], "sim": [], "dev": []} for s in specs}
    runs = 0
    for p in pairs:
        info = {key: v for key, v in p.items() if key not in ("input_index", "target_index")}
        for fps in sorted({s.fps for s in specs}, reverse=True):
            group = [s for s in specs if s.fps == fps]
            I = load_features(feature_files[p["input_index"]], fps)
            T = load_features(feature_files[p["target_index"]], fps)
            maps = _pair_maps(group, I, T, {**info, "fps": fps})
            dtw_spec = next((s for s in group if s.algorithm.family == "DTW"), None)
            if dtw_spec is None:
                dtw = registry.align("DTW", I, T)[0]
            else:
                dtw = maps[dtw_spec.name]
            XI, XT = joint_trajectories(I.quats), joint_trajectories(T.quats)
            for s in group:
                M = maps[s.name]
                per[s.name]["maps"].append(M)
                # = similarity(I.quats, T.quats, M), each motion's trajectories once
                per[s.name]["sim"].append(float(np.mean(trajectory_scores(XI[M], XT))))
                per[s.name]["dev"].append(deviation(dtw, M))
                runs += 1
    ids = np.array([p["id"] for p in pairs], dtype=np.int32)
    for s in specs:
        pre = s.slug + "."
        maps = per[s.name]["maps"]
        arrays[pre + "pair_id"] = ids
        arrays[pre + "offsets"] = np.concatenate([[0], np.cumsum([len(M) for M in maps])]).astype(
            np.int64
        )
        arrays[pre + "maps"] = np.concatenate(maps).astype(np.int32)
        arrays[pre + "similarity"] = np.array(per[s.name]["sim"], dtype=np.float64)
        arrays[pre + "deviation"] = np.array(per[s.name]["dev"], dtype=np.float64)
    meta = {
        "unit": unit["id"],
        "base_key": base_key,
        "pair_ids": [p["id"] for p in pairs],
        "algorithms": sorted(keep | {s.name for s in specs}),
    }
    arrays[_META] = np.frombuffer(json.dumps(meta).encode(), dtype=np.uint8)
    save_npz(path, **arrays)
    return {
        "unit": unit["id"],
        "pairs": len(pairs),
        "runs": runs,
        "seconds": time.perf_counter() - t0,
    }


# -- assembling and summarising ----------------------------------------------------------------


def _assemble(out: Path, specs: list, units: list, n_pairs: int) -> dict:
    """Write ``algorithms/<slug>.npz`` of ``specs`` from the chunks, in pair order.

    Returns ``{name: online}``.
    """
    parts = {s.name: {"maps": [], "sim": [], "dev": [], "ids": [], "len": []} for s in specs}
    for unit in units:
        keys = [
            s.slug + "." + k
            for s in specs
            for k in ("pair_id", "offsets", "maps", "similarity", "deviation")
        ]
        stored = load_npz(unit["chunk"], keys)
        for s in specs:
            pre = s.slug + "."
            acc = parts[s.name]
            acc["ids"].append(stored[pre + "pair_id"])
            acc["maps"].append(stored[pre + "maps"])
            acc["len"].append(np.diff(stored[pre + "offsets"]))
            acc["sim"].append(stored[pre + "similarity"])
            acc["dev"].append(stored[pre + "deviation"])
        del stored
    for s in specs:
        acc = parts.pop(s.name)
        ids = np.concatenate(acc["ids"]).astype(np.int32)
        if not np.array_equal(ids, np.arange(n_pairs)):
            raise RuntimeError(f"{s.name}: chunks do not cover pairs 0..{n_pairs - 1} in order")
        offsets = np.concatenate([[0], np.cumsum(np.concatenate(acc["len"]))]).astype(np.int64)
        save_npz(
            out / "algorithms" / f"{s.slug}.npz",
            pair_id=ids,
            offsets=offsets,
            maps=np.concatenate(acc["maps"]).astype(np.int32),
            similarity=np.concatenate(acc["sim"]).astype(np.float64),
            deviation=np.concatenate(acc["dev"]).astype(np.float64),
        )
    return {s.name: s.algorithm.online for s in specs}


def _stats(x) -> dict:
    x = np.asarray(x, dtype=np.float64)
    q1, med, q3 = np.percentile(x, [25, 50, 75])
    return {"median": float(med), "mean": float(np.mean(x)), "q1": float(q1), "q3": float(q3)}


def summarize(results: Results) -> dict:
    """The summary of every algorithm of a results folder (the content of ``summary.json``).

    Returns
    -------
    summary : dict
        ``"benchmarks"``: ``utw_median_similarity_120hz`` / ``_60hz`` (median
        similarity of UTW at that rate, None if UTW was not run),
        ``deviation_frames`` (18), ``deviation_ms`` (150).
        ``"algorithms"``: per algorithm ``fps, online, n_pairs, similarity_median,
        similarity_mean, similarity_q1, similarity_q3, deviation_median,
        deviation_mean, frac_above_utw_median`` (pairs whose similarity is above the
        UTW median at the same rate), ``frac_deviation_below_18`` (below 18 frames
        of the algorithm's own rate), ``frac_deviation_below_150ms``,
        ``passes_similarity_benchmark`` (median similarity above the UTW median),
        ``passes_deviation_benchmark`` (median deviation below 150 ms, i.e. 18
        frames at 120 Hz, 9 at 60 Hz). Deterministic, like the whole summary (the
        time per frame is measured by ``make bench``, :mod:`fpdtw.paper.bench`).

    Paper: FP-DTW Section 5 (benchmarks), Figs. 5-6, Tables 1-2.
    Notebook: 05_run_experiments.ipynb
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
        sim, dev = r["similarity"], r["deviation"]
        s, d = _stats(sim), _stats(dev)
        u = utw.get(fps)
        dev_ms = dev * 1000.0 / fps
        algos[name] = {
            "fps": fps,
            "online": results.is_online(name),
            "n_pairs": int(sim.shape[0]),
            "similarity_median": s["median"],
            "similarity_mean": s["mean"],
            "similarity_q1": s["q1"],
            "similarity_q3": s["q3"],
            "deviation_median": d["median"],
            "deviation_mean": d["mean"],
            "frac_above_utw_median": None if u is None else float(np.mean(sim > u)),
            "frac_deviation_below_18": float(np.mean(dev < numbers.DEVIATION_BENCHMARK_FRAMES)),
            "frac_deviation_below_150ms": float(np.mean(dev_ms < numbers.DEVIATION_BENCHMARK_MS)),
            "passes_similarity_benchmark": None
            if u is None
            else numbers.passes_similarity(s["median"], u),
            "passes_deviation_benchmark": numbers.passes_deviation(d["median"], fps),
        }
    return {"benchmarks": bench, "algorithms": algos}


# -- the run -----------------------------------------------------------------------------------


def _now() -> str:
    return _dt.datetime.now(_dt.UTC).isoformat(timespec="seconds")


def _outputs_exist(out: Path, run: dict) -> bool:
    files = [out / "pairs.json", out / "summary.json"]
    for a in run.get("algorithms", []):
        files.append(out / "algorithms" / f"{a['slug']}.npz")
    return all(f.is_file() for f in files)


def _remove_temporaries(out: Path) -> None:
    """Temporary files a killed run left in the runner's own files and folders."""
    for name in ("pairs.json", "summary.json", "run.json"):
        for p in out.glob(f".{name}.*{TMP_SUFFIX}"):
            p.unlink(missing_ok=True)
    for sub in ("features", "chunks", "algorithms"):
        for p in (out / sub).glob(f".*{TMP_SUFFIX}"):
            p.unlink(missing_ok=True)


def _pairs_json(mode, plan, feature_files) -> dict:
    frames = {}
    for i, f in enumerate(feature_files):
        a = _load_features_file(str(f))
        frames[i] = (a["quats120"].shape[0] - 1, a["quats60"].shape[0] - 1)
    pairs = []
    for p in plan.pairs:
        q = {k: v for k, v in p.items() if k not in ("input_index", "target_index")}
        (m, m60), (n, n60) = frames[p["input_index"]], frames[p["target_index"]]
        q.update(m=int(m), n=int(n), m60=int(m60), n60=int(n60))
        pairs.append(q)
    return {
        "mode": mode,
        "selection": plan.selection.as_dict(),
        "counts": plan.counts,
        "pairs": pairs,
    }


def run_experiments(
    mode: str = "full",
    algorithms=None,
    n_jobs: int = 2,
    progress: bool = True,
    selection: Selection | None = None,
) -> Results:
    """Run the algorithms over every pair of a mode, resumably, and write the result files.

    Parameters
    ----------
    mode : str
        ``"full"`` or ``"smoke"`` (see :data:`SELECTIONS`), or any folder name
        together with ``selection``. Results go to ``results_dir()/<mode>``.
    algorithms : sequence of str, optional
        Registry names (default: the mode's list, :data:`fpdtw.paper.runner.grid.MODE_ALGORITHMS`);
        ``"X@60Hz"`` runs X at 60 Hz. Results of other algorithms already in the folder
        (same pairs and code) are kept.
    n_jobs : int
        Worker processes (joblib); 1 runs everything in this process.
    progress : bool
        Print the selection and show progress bars.
    selection : Selection, optional
        Overrides the mode's selection (tests: a tiny subset).

    Returns
    -------
    Results

    Paper: FP-DTW Sections 4-6.
    Notebook: 05_run_experiments.ipynb
    """
    t_start, start = time.perf_counter(), _now()
    say = print if progress else (lambda *a, **k: None)
    if selection is None:
        if mode not in SELECTIONS:
            raise ValueError(f"mode {mode!r} needs a selection (known modes: {list(SELECTIONS)})")
        selection = SELECTIONS[mode]
    names = list(
        MODE_ALGORITHMS.get(mode, DEFAULT_ALGORITHMS) if algorithms is None else algorithms
    )
    if len(set(names)) != len(names):
        raise ValueError(f"an algorithm is listed twice: {names}")
    specs = [resolve_algorithm(n) for n in names]
    slugs = [s.slug for s in specs]
    if len(set(slugs)) != len(slugs):
        raise ValueError(f"two algorithms share a file name: {slugs}")

    plan = pair_selection(selection)
    if not plan.pairs:
        raise ValueError(f"the selection {selection} has no pairs")
    out = results_dir() / mode
    pair_key = [(p["dataset"], p["input_path"], p["target_path"]) for p in plan.pairs]
    compute_src = source_hash(compute_files())
    base_key = _hash([CACHE_FORMAT, mode, selection.as_dict(), plan.sha256, pair_key, compute_src])
    config_key = _hash([mode, names, pair_key, plan.sha256, source_hash()])

    runf = out / "run.json"
    prev = load_json(runf) if runf.is_file() else {}
    if prev.get("config_key") == config_key and _outputs_exist(out, prev):
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
    say(f"{len(specs)} algorithms, n_jobs={n_jobs}, results in {out}")
    out.mkdir(parents=True, exist_ok=True)
    _remove_temporaries(out)

    feature_files = build_features(plan, out / "features", n_jobs, progress)
    save_json(out / "pairs.json", _pairs_json(mode, plan, feature_files))

    # work units: one input motion against every other take of its movement
    units = OrderedDict()
    for p in plan.pairs:
        i = p["input_index"]
        if i not in units:
            uid = _unit_id(i, plan.motions[i])
            units[i] = {"id": uid, "chunk": str(out / "chunks" / f"{uid}.npz"), "pairs": []}
        units[i]["pairs"].append(p)
    units = list(units.values())
    (out / "chunks").mkdir(exist_ok=True)
    keep = {Path(u["chunk"]).name for u in units}
    for p in (out / "chunks").glob("*.npz"):  # units of another selection
        if p.name not in keep:
            p.unlink()

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
    runs = 0
    if tasks:
        say(f"computing {len(tasks)} of {len(units)} units ({len(recomputed)} algorithms)")
        jobs = [(u, missing, [str(f) for f in feature_files], base_key) for _, u, missing in tasks]
        for r in _parallel(_compute_unit, jobs, n_jobs, progress, "units"):
            runs += r["runs"]
    else:
        say("every unit is already computed")

    # per-algorithm files: (re)written where something changed
    prev_algos = (
        {a["name"]: a for a in prev.get("algorithms", [])}
        if prev.get("base_key") == base_key
        else {}
    )
    assemble = [
        s
        for s in specs
        if s.name in recomputed
        or s.name not in prev_algos
        or not (out / "algorithms" / f"{s.slug}.npz").is_file()
    ]
    if assemble:
        say(f"writing {len(assemble)} algorithm files")
        _assemble(out, assemble, units, len(plan.pairs))
    new = {
        s.name: {"name": s.name, "slug": s.slug, "fps": s.fps, "online": s.algorithm.online}
        for s in specs
    }
    # the algorithms already here (same base key, file present) keep their place, then the
    # requested ones that are new here
    info = []
    for n, a in prev_algos.items():
        if n in new:
            info.append(new.pop(n))
        elif (out / "algorithms" / f"{a['slug']}.npz").is_file():
            info.append(a)
    info += list(new.values())
    listed = {a["slug"] for a in info}
    for p in (out / "algorithms").glob("*.npz"):
        if p.stem not in listed:
            p.unlink()
    shutil.rmtree(out / "timings", ignore_errors=True)  # written by runs before CACHE_FORMAT 2

    results = Results(out, algorithms=info)
    summary = summarize(results)
    save_json(out / "summary.json", summary)

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
        },
        "start": start,
        "end": _now(),
        "wall_seconds": round(time.perf_counter() - t_start, 3),
        "n_jobs": n_jobs,
        "environment": provenance.environment(),
    }
    save_json(runf, run)
    say(f"done in {run['wall_seconds']:.1f} s ({runs} pair x algorithm runs)")
    return Results(out)


# -- command line ------------------------------------------------------------------------------


def main(argv=None) -> int:
    """``python -m fpdtw.paper.runner.run [--mode MODE | --smoke] [--jobs N] [--algorithms NAME ...]
    [--quiet]``."""
    ap = argparse.ArgumentParser(
        prog="python -m fpdtw.paper.runner.run", description=__doc__.split("\n")[0]
    )
    ap.add_argument(
        "--mode",
        choices=sorted(SELECTIONS),
        default="full",
        help="which selection and algorithm list (default full; study: notebook 15)",
    )
    ap.add_argument("--smoke", action="store_true", help="the same as --mode smoke")
    ap.add_argument("--jobs", type=int, default=2, help="worker processes (default 2)")
    ap.add_argument(
        "--algorithms",
        nargs="+",
        default=None,
        metavar="NAME",
        help="algorithm names (default: the mode's list)",
    )
    ap.add_argument("--quiet", action="store_true", help="no progress output")
    a = ap.parse_args(argv)
    mode = "smoke" if a.smoke else a.mode
    res = run_experiments(mode, a.algorithms, a.jobs, not a.quiet)
    if not a.quiet:
        for name in res.algorithms:
            s = res.summary["algorithms"][name]
            print(
                f"{name:40s} similarity median {s['similarity_median']:6.3f}  "
                f"deviation median {s['deviation_median']:7.2f} frames"
            )
    return 0


__all__ = [
    "CACHE_FORMAT",
    "AlgorithmSpec",
    "build_features",
    "compute_files",
    "load_features",
    "load_results",
    "main",
    "pair_features",
    "resolve_algorithm",
    "run_experiments",
    "source_hash",
    "summarize",
]


if __name__ == "__main__":
    # run the importable module's main: worker processes must find the functions by name
    from fpdtw.paper.runner.run import main as _main

    sys.exit(_main())
