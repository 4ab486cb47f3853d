"""Run every algorithm of the FP-DTW paper over every pair, in parallel and resumably.

Pairs (paper Section 4)
    Every ORDERED pair (input, target) of distinct takes of the same movement: the
    authors' FBX takes available here grouped by movement, and the HDM05 clips grouped
    by class. Pair ids follow (dataset, movement, input, target) in manifest order.
    :data:`SELECTIONS` holds the two modes: ``"full"`` (every take) and ``"smoke"``
    (per movement the first two takes, both directions, cropped to 2 s).

Algorithms
    :data:`DEFAULT_ALGORITHMS`: :data:`fpdtw.algorithms.PAPER_NAMES` at 120 Hz and,
    for Table 1, :data:`TABLE1_60HZ_NAMES` on the motions resampled to 60 Hz (any
    name with the suffix ``"@60Hz"`` runs the named algorithm at 60 Hz). More
    algorithms join with :func:`register_algorithm`; a run that adds one computes
    only it.

Per pair and algorithm: the map ``M`` (target frame -> input frame), the similarity
(eq. 2) of the warped input and the target and the deviation (eq. 3) from the DTW map
at the same frame rate (in frames of that rate). Methods B and C of a pair run in
lockstep sharing one :class:`fpdtw.online.window.WindowCache` (the maps are those of
separate runs; tested), so the grid does not time frames: per-frame latency is what
``make bench`` measures (:mod:`fpdtw.bench`, one core, warmed up, medians).

Files, under ``results_dir()/<mode>/`` (every write atomic: temporary file +
:func:`os.replace`; ``.npz`` files by :func:`fpdtw.resultsio.save_npz`, byte for byte
the same for the same arrays)

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
    Config key, keys of what was computed, start/end time, wall time, n_jobs, CPU,
    and ``history``: the same for every earlier invocation on the same base key
    (a re-run that only re-summarises keeps the record of the run that computed).
``features/``, ``chunks/``
    Caches: the features of every motion (keyed by the data file's sha256, the crop
    and the feature code) and one file per work unit (one input motion against
    every other take of its movement, per algorithm).

Resuming: a run killed at any point (even by SIGKILL) resumes from the finished
chunks and ends with the same ``algorithms/*.npz``, ``pairs.json`` and
``summary.json`` as an uninterrupted run. A re-run with
nothing changed returns at once. Keys: the *config key* (mode, algorithm list, pair
list, hash of every source file of the package) decides "nothing changed"; the
*base key* (mode, selection, data hashes, pair list, hash of the source files the
computation imports, :data:`COMPUTE_ROOTS`; this module itself is covered by
:data:`CACHE_FORMAT`) decides whether a chunk is still valid, and an *algorithm
key* per algorithm whether its entries in a chunk are (built-ins: the name;
registered algorithms: the name and the function's source). One run at a time per
results folder.

Reading: :func:`load_results` -> :class:`Results` (``.pairs``, ``.algorithms``,
``.get(name)`` with ``.map(k)``, ``.summary``) and
:func:`aggregate_heatmap`, defined in :mod:`fpdtw.resultsio` and re-exported here.

Command line::

    python -m fpdtw.experiments [--mode full|smoke|study|smoke-study] [--jobs N]
                                [--algorithms NAME ...] [--quiet]

Paper: FP-DTW Section 4 (pairs), eq. 2 and eq. 3, Figs. 5-7 and 10, Tables 1 and 2.
Notebook: 05_run_experiments.ipynb
"""

from __future__ import annotations

import argparse
import ast
import datetime as _dt
import functools
import hashlib
import inspect
import json
import os
import platform
import shutil
import sys
import time
from collections import OrderedDict
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from . import catalog, data
from .algorithms import (
    C_READINGS,
    MC_LITERAL_NAMES,
    PAPER_NAMES,
    WINDOWS,
    align,
    make_online,
    method_c_name,
    parse_name,
)
from .errors import AlignmentError, MotionFormatError
from .features import MotionFeatures
from .joints import OPW_JOINTS
from .metrics import deviation, joint_trajectories, trajectory_scores
from .online.window import WindowCache, run_group
from .paths import results_dir
from .resultsio import (
    BASE_FPS,
    LOW_FPS,
    RATE_SUFFIX,
    TMP_SUFFIX,
    AlgorithmResult,
    Results,
    aggregate_heatmap,
    load_json,
    load_npz,
    load_results,
    save_json,
    save_npz,
    slug,
)

#: Datasets of the experiments (paper Section 4).
DATASETS = ("authors_fbx", "hdm05")
#: The algorithms of Table 1 at 60 Hz (DTW for the deviation, UTW for the benchmark).
TABLE1_60HZ_NAMES = (
    "DTW@60Hz",
    "UTW@60Hz",
    "Mc w10@60Hz",
    "Mc w20@60Hz",
    "Mc w40@60Hz",
    "Mc w80@60Hz",
)
#: Method C's literal ``(w_i + 1) x w`` window, at 120 Hz (with and without Type V) and,
#: for Table 1, at 60 Hz: the claims table shows its verdicts next to the default's.
LITERAL_NAMES = MC_LITERAL_NAMES + tuple(method_c_name(w, "literal") + "@60Hz" for w in WINDOWS)
#: Online baselines beyond the FP-DTW paper, run on its pairs: the OPW poster's method
#: and Dixon's on-line time warping (the paper's ref. 3); registered at the end of
#: this module.
EXTRA_ALGORITHMS = ("OPW", "OLTW")
#: What a run computes by default (modes "full" and "smoke").
DEFAULT_ALGORITHMS = tuple(PAPER_NAMES) + TABLE1_60HZ_NAMES + EXTRA_ALGORITHMS + LITERAL_NAMES


def _study_algorithms() -> tuple:
    """The algorithms of notebook 15 (modes "study" and "smoke-study").

    * DTW and UTW at 120 and 60 Hz (the references of deviation and similarity);
    * every reading of Algorithm 3 (:data:`fpdtw.algorithms.C_READINGS`) at every w,
      with and without Type V, at 120 and 60 Hz;
    * Methods A and B as in the paper (the headline medians on this selection);
    * the paper's silent choices (:data:`SILENT_CHOICES`), each on the algorithms it
      touches among the headline ones (:data:`CHOICE_TARGETS`).
    """
    names = ["DTW", "UTW", "DTW@60Hz", "UTW@60Hz"]
    for rate in ("", "@60Hz"):
        for reading in C_READINGS:
            for typev in (False, True):
                names += [method_c_name(w, reading, typev) + rate for w in WINDOWS]
    names += [n for n in PAPER_NAMES if n.startswith(("Ma", "Mb"))]
    for choice in SILENT_CHOICES.values():
        if choice["option"] is not None:
            names += [choice_variant(n, choice) for n in choice_targets(choice)]
    out = []
    for n in names:  # keep the first of any duplicate
        if n not in out:
            out.append(n)
    return tuple(out)


#: The paper's silent choices (notebook 15: how much does each move a result?). Per
#: choice: ``ours`` and ``alternative`` in words; ``option`` (the aligner option and its
#: alternative value, for choices that change the maps) or None (choices of the
#: metrics, recomputed from the stored maps); ``methods`` it touches.
SILENT_CHOICES = {
    "ties": {
        "ours": "ties go to the lowest offset (Methods A, C)",
        "alternative": "ties go to the highest offset",
        "option": ("ties", "high"),
        "methods": "AC",
    },
    "backtrack": {
        "ours": "Method B's back-track prefers the diagonal, then the target step",
        "alternative": "the diagonal, then the input step",
        "option": ("backtrack", "input-first"),
        "methods": "B",
    },
    "forecast": {
        "ours": "dead reckoning in Euler angles (the paper)",
        "alternative": "zero-order hold: every forecast frame is T_{n+1}",
        "option": ("forecast", "hold"),
        "methods": "BC",
    },
    "forecast_start": {
        "ours": "Method C's forecast window starts with T_{n+1} itself",
        "alternative": "it starts with the first prediction T^_{n+2}",
        "option": ("forecast_start", "next"),
        "methods": "C",
    },
    "start": {
        "ours": "M_0 = 0 (both motions start together)",
        "alternative": "M_0 = the best match of T_0 among I_0..I_w",
        "option": ("start", "best"),
        "methods": "ABC",
    },
    "deviation_frames": {
        "ours": "eq. 3 averages over all n + 1 target frames",
        "alternative": "over the n frames q = 1..n, as printed",
        "option": None,
        "methods": "ABC",
    },
    "flat_axis": {
        "ours": "eq. 2: an axis flat in only one motion scores 0",
        "alternative": "such an axis is left out of the average",
        "option": None,
        "methods": "ABC",
    },
    "after_input": {
        "ours": "once the input is exhausted the map holds at m (forced, even under "
        "Type V), and those frames are scored",
        "alternative": "frames after the first frame mapped to m are not scored",
        "option": None,
        "methods": "ABC",
    },
}

#: Per method, the headline algorithms a silent choice is measured on (those of the
#: paper's claims, at both ends of the window range).
CHOICE_TARGETS = {
    "A": ("Ma", "Ma + Type V"),
    "B": ("Mb w10", "Mb w40", "Mb w80", "Mb w80 + Type V"),
    "C": ("Mc w10", "Mc w40", "Mc w80", "Mc w80 + Type V"),
}


def choice_targets(choice: dict) -> list:
    """The algorithms of :data:`CHOICE_TARGETS` a silent choice touches.

    Notebook: 15_readings_of_algorithm_3.ipynb
    """
    return [n for method in choice["methods"] for n in CHOICE_TARGETS[method]]


def choice_variant(name: str, choice: dict) -> str:
    """``name`` with the choice's alternative option: ``"Mc w40"`` -> ``"Mc w40 (ties high)"``.

    Notebook: 15_readings_of_algorithm_3.ipynb
    """
    from .algorithms import _method_class

    method, w, typev, options = parse_name(name)
    key, value = choice["option"]
    return _method_class(method).name_for(w, typev, **{**options, key: value})


#: What notebook 15 computes by default (modes "study" and "smoke-study").
STUDY_ALGORITHMS = _study_algorithms()
#: The default algorithm list of each mode.
MODE_ALGORITHMS = {
    "full": DEFAULT_ALGORITHMS,
    "smoke": DEFAULT_ALGORITHMS,
    "study": STUDY_ALGORITHMS,
    "smoke-study": STUDY_ALGORITHMS,
}
#: The paper's data (Section 4): 333 motions of 44 movements, 3248 ordered pairs.
PAPER_COUNTS = {"motions": 333, "movements": 44, "pairs": 3248}
#: Deviation benchmark: 150 ms, i.e. 18 frames at 120 Hz (paper Section 4).
DEVIATION_BENCHMARK_MS = 150.0
DEVIATION_BENCHMARK_FRAMES = 18
#: Bump when the feature cache or chunk layout, or what this module computes, changes.
CACHE_FORMAT = 2

_PKG_ROOT = Path(__file__).resolve().parent
_META = "__meta__"


# -- selection and pairs -----------------------------------------------------------------------


@dataclass(frozen=True)
class Selection:
    """Which motions take part in an experiment run.

    Attributes
    ----------
    datasets : tuple of str
        Manifest names, in this order.
    movements : tuple of str or None
        Keep only these movements (authors' names or HDM05 classes); None keeps all.
    takes_per_movement : int or None
        Keep at most this many takes of each movement; None keeps all.
    sample_seed : int or None
        None keeps the FIRST takes in manifest order; an int draws the takes at random
        (without replacement, then in manifest order) with a generator seeded by this
        number, the dataset and the movement, so a movement's draw does not depend on
        the others.
    crop_seconds : float or None
        Crop every motion to its first seconds (``Motion.crop(0, s)``) before
        features are built; None keeps whole motions.

    Notebook: 05_run_experiments.ipynb
    """

    datasets: tuple = DATASETS
    movements: tuple | None = None
    takes_per_movement: int | None = None
    crop_seconds: float | None = None
    sample_seed: int | None = None

    def as_dict(self) -> dict:
        d = asdict(self)
        d["datasets"] = list(self.datasets)
        d["movements"] = None if self.movements is None else list(self.movements)
        return d


#: Takes per movement of the "paper-shaped" selection: the paper's 333 motions over 44
#: movements are 7.6 takes per movement on average (Section 4); we cap at 8.
PAPER_SHAPED_TAKES = 8
#: Seed of the paper-shaped draw (fixed: the draw is part of the documented selection).
PAPER_SHAPED_SEED = 2023

#: The selection of each mode: ``"full"`` every take (whole classes); ``"smoke"`` the
#: first two takes of every movement, both directions (2 pairs per movement), cropped to
#: 2 s; ``"study"`` (notebook 15) the paper-shaped selection, at most 8 takes per movement
#: drawn with a fixed seed (the authors' movements have 3 takes, so all of them stay);
#: ``"smoke-study"`` the smoke selection.
SELECTIONS = {
    "full": Selection(),
    "smoke": Selection(takes_per_movement=2, crop_seconds=2.0),
    "study": Selection(takes_per_movement=PAPER_SHAPED_TAKES, sample_seed=PAPER_SHAPED_SEED),
    "smoke-study": Selection(takes_per_movement=2, crop_seconds=2.0),
}


@dataclass
class PairSelection:
    """Motions and ordered pairs of a :class:`Selection` (from the manifests, nothing loaded).

    Attributes
    ----------
    selection : Selection
    motions : list of MotionRecord
        Every motion that takes part in a pair, in manifest order (dataset, movement).
    sha256 : list of str
        Content hash of each motion file (and of its skeleton file, for HDM05).
    pairs : list of dict
        ``id, dataset, movement, input, target, input_path, target_path`` and the
        motion indices ``input_index``, ``target_index`` (into ``motions``).
    counts : dict
        ``{dataset: {"motions", "movements", "pairs"}, "total": {...}}``.
    rows : list of dict
        One row per dataset and movement: ``dataset, movement, motions, pairs``.
    dropped : list of str
        Movements left out because fewer than two takes are available.
    """

    selection: Selection
    motions: list
    sha256: list
    pairs: list
    counts: dict
    rows: list
    dropped: list = field(default_factory=list)


def _content_hashes(manifest, entries: dict, record) -> str:
    """sha256 of a motion file from its manifest entry (plus its skeleton's, if any)."""
    e = entries[record.path]
    digest = e.sha256 or e.git_blob_sha1
    skel = data.skeleton_file(manifest, e)
    if skel is not None:
        digest += "+" + (skel.sha256 or skel.git_blob_sha1)
    return digest


def _take_subset(recs: list, sel: Selection, dataset: str, movement: str) -> list:
    """At most ``sel.takes_per_movement`` of a movement's takes (see :class:`Selection`)."""
    k = sel.takes_per_movement
    if sel.sample_seed is None or len(recs) <= k:
        return recs[:k]
    seed = int.from_bytes(
        hashlib.sha256(f"{sel.sample_seed}/{dataset}/{movement}".encode()).digest()[:8]
    )
    keep = np.random.default_rng(seed).choice(len(recs), size=k, replace=False)
    return [recs[i] for i in sorted(keep)]


def pair_selection(selection: Selection | None = None) -> PairSelection:
    """Every ordered pair of distinct takes of the same movement.

    Parameters
    ----------
    selection : Selection, optional
        Default: every take of :data:`DATASETS` (the ``"full"`` mode).

    Returns
    -------
    PairSelection
        Pairs in deterministic order: dataset, movement, input, target (manifest order).

    Paper: FP-DTW Section 4 ("every permutation of motions with same movement were
    time warped in both directions").
    Notebook: 05_run_experiments.ipynb
    """
    sel = selection or SELECTIONS["full"]
    motions, sha, pairs, rows, dropped = [], [], [], [], []
    counts = OrderedDict()
    for ds in sel.datasets:
        manifest = data.load_manifest(ds)
        entries = {e.path: e for e in manifest.files}
        groups = OrderedDict()
        for r in catalog.motion_records((ds,), available_only=True):
            if sel.movements is not None and r.movement not in sel.movements:
                continue
            groups.setdefault(r.movement, []).append(r)
        c = {"motions": 0, "movements": 0, "pairs": 0}
        for movement, recs in groups.items():
            if sel.takes_per_movement is not None:
                recs = _take_subset(recs, sel, ds, movement)
            if len(recs) < 2:
                dropped.append(f"{ds}/{movement}")
                continue
            first = len(motions)
            for r in recs:
                motions.append(r)
                sha.append(_content_hashes(manifest, entries, r))
            n_pairs = 0
            for a in range(len(recs)):
                for b in range(len(recs)):
                    if a == b:
                        continue
                    I, T = recs[a], recs[b]
                    pairs.append(
                        {
                            "id": len(pairs),
                            "dataset": ds,
                            "movement": movement,
                            "input": I.name,
                            "target": T.name,
                            "input_path": I.path,
                            "target_path": T.path,
                            "input_index": first + a,
                            "target_index": first + b,
                        }
                    )
                    n_pairs += 1
            rows.append(
                {"dataset": ds, "movement": movement, "motions": len(recs), "pairs": n_pairs}
            )
            c["motions"] += len(recs)
            c["movements"] += 1
            c["pairs"] += n_pairs
        counts[ds] = c
    counts["total"] = {
        k: sum(counts[ds][k] for ds in sel.datasets) for k in ("motions", "movements", "pairs")
    }
    return PairSelection(sel, motions, sha, pairs, dict(counts), rows, dropped)


def format_counts(counts: dict) -> str:
    """One line per dataset and the total, with the paper's counts for comparison.

    Notebook: 05_run_experiments.ipynb
    """
    lines = []
    for ds, c in counts.items():
        lines.append(
            f"{ds:12s} {c['motions']:4d} motions {c['movements']:3d} movements "
            f"{c['pairs']:6d} pairs"
        )
    p = PAPER_COUNTS
    lines.append(
        f"{'paper':12s} {p['motions']:4d} motions {p['movements']:3d} movements "
        f"{p['pairs']:6d} pairs"
    )
    return "\n".join(lines)


# -- algorithms --------------------------------------------------------------------------------

_REGISTRY: dict = {}


@dataclass(frozen=True)
class AlgorithmSpec:
    """How one named algorithm runs.

    Attributes
    ----------
    name : str
        Name in results (e.g. ``"Mc w40@60Hz"``).
    base : str
        The algorithm at its own rate (``"Mc w40"``).
    fps : float
        Frame rate of the features it gets (120 or 60).
    fn : callable or None
        A registered function, or None for a built-in (:func:`fpdtw.algorithms.align`).
    key : str
        Identity of the computation (see module docstring).
    """

    name: str
    base: str
    fps: float
    fn: object = None
    key: str = ""

    @property
    def slug(self) -> str:
        return slug(self.name)


def register_algorithm(name: str, fn, fps: float = BASE_FPS, version: str | None = None):
    """Add an algorithm that :func:`run_experiments` can run by name.

    Parameters
    ----------
    name : str
        Its name in results (no ``"@"``); ``name + "@60Hz"`` then runs it at 60 Hz.
    fn : callable
        ``fn(I_features, T_features, pair_info) -> (M, seconds)``: ``I_features``,
        ``T_features`` are :class:`~fpdtw.features.MotionFeatures` at the algorithm's
        rate (with root-relative positions of :data:`fpdtw.joints.OPW_JOINTS` where
        the skeleton has them); ``pair_info`` is the pair's entry of ``pairs.json``
        plus ``"fps"``; ``M`` an int array of shape (n + 1,) with entries in
        ``0..m``; ``seconds`` the per-frame processing times (shape (n + 1,)) of an
        online algorithm, else None. Must be deterministic; it is pickled to the
        worker processes, so define it in an importable module for ``n_jobs > 1``.
    fps : float
        Frame rate of the features it gets (120 by default).
    version : str, optional
        Identity of the computation; by default the function's source text. Chunks
        computed under another version are recomputed.

    Notebook: 05_run_experiments.ipynb
    """
    if "@" in name or not name.strip():
        raise AlignmentError(f"bad algorithm name {name!r} (no '@'; add '@60Hz' when running)")
    if _is_builtin(name):
        raise AlignmentError(f"{name!r} is a built-in algorithm")
    if not callable(fn):
        raise TypeError("fn must be callable")
    _REGISTRY[name] = (fn, float(fps), version)


def unregister_algorithm(name: str) -> None:
    """Remove a registered algorithm (tests)."""
    _REGISTRY.pop(name, None)


def _fn_identity(fn, version) -> str:
    if version is not None:
        return str(version)
    parts = [getattr(fn, "__module__", ""), getattr(fn, "__qualname__", repr(fn))]
    try:
        parts.append(inspect.getsource(fn))
    except (OSError, TypeError):
        pass
    mod = getattr(fn, "__module__", "") or ""
    if mod == "fpdtw" or mod.startswith("fpdtw."):
        parts.append(source_hash([mod]))
    return _hash(parts)


def _is_builtin(name: str) -> bool:
    """DTW, UTW, OE-DTW and every FP-DTW configuration (options included)."""
    if name in ("DTW", "UTW", "OE-DTW"):
        return True
    try:
        parse_name(name)
    except AlignmentError:
        return False
    return True


def resolve_algorithm(name: str) -> AlgorithmSpec:
    """The :class:`AlgorithmSpec` of a name (built-in, ``@60Hz`` variant or registered).

    Raises
    ------
    AlignmentError
        Unknown name.
    """
    base, fps = name, BASE_FPS
    if name.endswith(RATE_SUFFIX):
        base, fps = name[: -len(RATE_SUFFIX)], LOW_FPS
    if base in _REGISTRY:
        fn, reg_fps, version = _REGISTRY[base]
        if fps == BASE_FPS:
            fps = reg_fps
        return AlgorithmSpec(name, base, fps, fn, _hash([name, fps, _fn_identity(fn, version)]))
    if _is_builtin(base):
        return AlgorithmSpec(name, base, fps, None, name)
    known = ", ".join(list(DEFAULT_ALGORITHMS) + sorted(_REGISTRY))
    raise AlignmentError(f"unknown algorithm {name!r}; known: {known}")


def _align_pair(spec: AlgorithmSpec, I: MotionFeatures, T: MotionFeatures, info: dict):
    """Map of one pair by one algorithm: ``(M int64 (n+1,), seconds or None)``."""
    if spec.fn is None:
        M, seconds = align(spec.base, I, T)
    else:
        M, seconds = spec.fn(I, T, info)
    M = _check_map(spec, M, I, T, info)
    n1 = T.n_frames
    if seconds is not None:
        seconds = np.asarray(seconds, dtype=np.float32)
        if seconds.shape != (n1,):
            raise AlignmentError(f"{spec.name}: seconds must have shape ({n1},)")
    return M, seconds


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


# -- hashes ------------------------------------------------------------------------------------


def _hash(obj) -> str:
    return hashlib.sha256(json.dumps(obj, sort_keys=True, default=str).encode()).hexdigest()


def _module_file(parts) -> Path | None:
    """File of module ``fpdtw.<parts>`` (a package's ``__init__.py``), or None."""
    p = _PKG_ROOT.joinpath(*parts)
    if (p / "__init__.py").is_file():
        return p / "__init__.py"
    if p.with_suffix(".py").is_file():
        return p.with_suffix(".py")
    return None


def _is_package(parts) -> bool:
    return (_PKG_ROOT.joinpath(*parts) / "__init__.py").is_file()


def _from_module(package, node) -> tuple | None:
    """Module (parts relative to fpdtw) an ``ImportFrom`` node imports from, or None."""
    if node.level:
        base = list(package[: len(package) - (node.level - 1)])
        return tuple(base + (node.module.split(".") if node.module else []))
    if node.module and (node.module == "fpdtw" or node.module.startswith("fpdtw.")):
        return tuple(node.module.split(".")[1:])
    return None


def _resolve_name(package: tuple, name: str) -> list:
    """Where ``from <package> import <name>`` gets its code: a sub-module, the module a
    re-export in the package's ``__init__`` points to, or the ``__init__`` itself."""
    if _module_file(package + (name,)) is not None:
        return [package + (name,)]
    init = _module_file(package)
    for node in ast.parse(init.read_text()).body:
        if isinstance(node, ast.ImportFrom) and any(
            a.name in (name, "*") or a.asname == name for a in node.names
        ):
            mod = _from_module(package, node)
            if mod is not None:
                return _resolve_name(mod, name) if _is_package(mod) else [mod]
    return [package + ("__init__",)]


def _imports(parts, file: Path):
    """Modules (parts relative to fpdtw) whose code ``file`` uses, from its imports anywhere.

    A name imported from a package resolves to the module that defines it (a package's
    ``__init__`` counts only where it defines the name itself), so adding a re-export
    to a package does not change what a module depends on.
    """
    package = tuple(parts[:-1])  # a module's package; a package's own ("io", "__init__")
    out = []
    for node in ast.walk(ast.parse(file.read_text())):
        if isinstance(node, ast.Import):
            for a in node.names:
                if a.name.startswith("fpdtw."):
                    mod = tuple(a.name.split(".")[1:])
                    out.append(mod + ("__init__",) if _is_package(mod) else mod)
        elif isinstance(node, ast.ImportFrom):
            mod = _from_module(package, node)
            if mod is None:
                continue
            if _is_package(mod):
                for a in node.names:
                    out.extend(_resolve_name(mod, a.name))
            else:
                out.append(mod)
    return out


@functools.lru_cache(maxsize=64)
def _closure(roots: tuple) -> tuple:
    todo = [tuple(r.split(".")[1:]) for r in roots]
    seen = {}
    while todo:
        parts = todo.pop()
        if parts in seen:
            continue
        if parts and parts[-1] == "__init__":
            f = _PKG_ROOT.joinpath(*parts[:-1]) / "__init__.py"
        else:
            f = _module_file(parts)
            if f is not None and f.name == "__init__.py":
                parts = parts + ("__init__",)
        if f is None or not f.is_file():
            continue
        seen[parts] = f
        todo.extend(_imports(parts, f))
    return tuple(sorted(str(f.relative_to(_PKG_ROOT)) for f in seen.values()))


def source_hash(roots=None) -> str:
    """Hash of fpdtw source files: all of them, or those the modules ``roots`` import.

    Parameters
    ----------
    roots : sequence of str, optional
        Module names (``"fpdtw.algorithms"``); their transitive fpdtw imports (found
        statically, including imports inside functions) and parent packages are
        hashed. None hashes every ``.py`` file of the package.

    Returns
    -------
    hex : str
    """
    if roots is None:
        files = sorted(str(p.relative_to(_PKG_ROOT)) for p in _PKG_ROOT.rglob("*.py"))
    else:
        files = _closure(tuple(roots))
    h = hashlib.sha256()
    for f in files:
        h.update(f.encode() + b"\0" + (_PKG_ROOT / f).read_bytes() + b"\0")
    return h.hexdigest()


#: Modules whose code decides the computed maps and scores: the algorithms and the
#: metrics, with everything they import (statically). This module itself is left out
#: so that editing it does not void a finished run: bump :data:`CACHE_FORMAT` when a
#: change here alters what is computed.
COMPUTE_ROOTS = (
    "fpdtw.algorithms",
    "fpdtw.metrics",
    "fpdtw.dtw",
    "fpdtw.catalog",
    "fpdtw.features",
)
#: Modules whose code decides the features.
FEATURE_ROOTS = ("fpdtw.catalog", "fpdtw.features", "fpdtw.motion", "fpdtw.joints")


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
    src = source_hash(FEATURE_ROOTS)
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


def _chunk_algorithms(path: Path, base_key: str) -> dict:
    """``{name: key}`` of the algorithms a chunk holds, {} if missing, unreadable or stale."""
    meta = _chunk_meta(path, base_key)
    return meta.get("algorithms", {}) if "online" in meta else {}


def _shares_window(spec: AlgorithmSpec) -> bool:
    """A built-in Method B or C configuration (it can share a :class:`WindowCache`)."""
    return spec.fn is None and spec.base.startswith(("Mb ", "Mc "))


def _pair_maps(specs: list, I: MotionFeatures, T: MotionFeatures, info: dict) -> dict:
    """``{name: (M, online)}`` of every spec on one pair at one rate.

    Methods B and C run together in one compiled loop (:func:`fpdtw.online.window.run_group`)
    sharing one :class:`WindowCache` (each forecast and cost cell computed once per target
    frame; the maps are those of separate runs); every other algorithm runs on its own.
    """
    out = {}
    shared = [s for s in specs if _shares_window(s)]
    if shared:
        cache = WindowCache(I, max(parse_name(s.base)[1] for s in shared))
        aligners = [make_online(s.base, I, cache=cache) for s in shared]
        for s, M in zip(shared, run_group(aligners, T)):
            out[s.name] = (_check_map(s, M, I, T, info), True)
    for s in specs:
        if s.name not in out:
            M, seconds = _align_pair(s, I, T, info)
            out[s.name] = (M, seconds is not None)
    return out


def _compute_unit(unit: dict, specs: list, feature_files: list, base_key: str) -> dict:
    """Compute the algorithms ``specs`` on every pair of one unit and write its chunk (worker).

    The chunk keeps the algorithms it already held (same base key) that are not
    recomputed. Returns ``{"unit", "pairs", "runs", "seconds"}``.
    """
    t0 = time.perf_counter()
    path = Path(unit["chunk"])
    pairs = unit["pairs"]
    old = _chunk_algorithms(path, base_key)
    new_names = {s.name for s in specs}
    keep = {n: k for n, k in old.items() if n not in new_names}
    arrays = {}
    if keep:
        stored = load_npz(path)
        for n in keep:
            pre = slug(n) + "."
            arrays.update({k: v for k, v in stored.items() if k.startswith(pre)})
    online = {n: v for n, v in _chunk_meta(path, base_key).get("online", {}).items() if n in keep}

    per = {s.name: {"maps": [], "sim": [], "dev": []} for s in specs}
    runs = 0
    for p in pairs:
        info = {key: v for key, v in p.items() if key not in ("input_index", "target_index")}
        for fps in sorted({s.fps for s in specs}, reverse=True):
            group = [s for s in specs if s.fps == fps]
            I = load_features(feature_files[p["input_index"]], fps)
            T = load_features(feature_files[p["target_index"]], fps)
            maps = _pair_maps(group, I, T, {**info, "fps": fps})
            dtw_spec = next((s for s in group if s.base == "DTW"), None)
            if dtw_spec is None:
                dtw = np.asarray(align("DTW", I, T)[0], dtype=np.int64)
            else:
                dtw = maps[dtw_spec.name][0]
            XI, XT = joint_trajectories(I.quats), joint_trajectories(T.quats)
            for s in group:
                M, is_online = maps[s.name]
                online[s.name] = is_online
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
    algos = dict(keep)
    algos.update({s.name: s.key for s in specs})
    meta = {
        "unit": unit["id"],
        "base_key": base_key,
        "pair_ids": [p["id"] for p in pairs],
        "algorithms": algos,
        "online": online,
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
    online = {}
    for unit in units:
        keys = [
            s.slug + "." + k
            for s in specs
            for k in ("pair_id", "offsets", "maps", "similarity", "deviation")
        ]
        stored = load_npz(unit["chunk"], keys + [_META])
        online.update(json.loads(bytes(stored[_META]).decode()).get("online", {}))
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
    return {s.name: bool(online.get(s.name, False)) for s in specs}


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
        time per frame is measured by ``make bench``, :mod:`fpdtw.bench`).

    Paper: FP-DTW Section 5 (benchmarks), Figs. 5-6, Tables 1-2.
    Notebook: 05_run_experiments.ipynb
    """
    utw = {}
    for name in results.algorithms:
        spec_fps = results.fps(name)
        base = name[: -len(RATE_SUFFIX)] if name.endswith(RATE_SUFFIX) else name
        if base == "UTW":
            utw[spec_fps] = float(np.median(results.get(name)["similarity"]))
    bench = {
        "utw_median_similarity_120hz": utw.get(BASE_FPS),
        "utw_median_similarity_60hz": utw.get(LOW_FPS),
        "deviation_frames": DEVIATION_BENCHMARK_FRAMES,
        "deviation_ms": DEVIATION_BENCHMARK_MS,
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
            "frac_deviation_below_18": float(np.mean(dev < DEVIATION_BENCHMARK_FRAMES)),
            "frac_deviation_below_150ms": float(np.mean(dev_ms < DEVIATION_BENCHMARK_MS)),
            "passes_similarity_benchmark": None if u is None else bool(s["median"] > u),
            "passes_deviation_benchmark": bool(d["median"] * 1000.0 / fps < DEVIATION_BENCHMARK_MS),
        }
    return {"benchmarks": bench, "algorithms": algos}


# -- the run -----------------------------------------------------------------------------------


def _cpu_name() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


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
    for sub in ("features", "chunks", "algorithms", "timings"):
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
        Names (default :data:`DEFAULT_ALGORITHMS`); ``"X@60Hz"`` runs X at 60 Hz;
        registered names (:func:`register_algorithm`) too. Results of other
        algorithms already in the folder (same pairs and code) are kept.
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
    compute_src = source_hash(COMPUTE_ROOTS)
    base_key = _hash([CACHE_FORMAT, mode, selection.as_dict(), plan.sha256, pair_key, compute_src])
    config_key = _hash([mode, names, [s.key for s in specs], pair_key, plan.sha256, source_hash()])

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
        missing = [s for s in specs if have.get(s.name) != s.key]
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
        or prev_algos.get(s.name, {}).get("key") != s.key
        or not (out / "algorithms" / f"{s.slug}.npz").is_file()
    ]
    online = {n: a["online"] for n, a in prev_algos.items()}
    if assemble:
        say(f"writing {len(assemble)} algorithm files")
        online.update(_assemble(out, assemble, units, len(plan.pairs)))
    new = {
        s.name: {
            "name": s.name,
            "slug": s.slug,
            "fps": s.fps,
            "online": online[s.name],
            "key": s.key,
        }
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
    import numba

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
        "computed": {"units": len(tasks), "units_total": len(units), "pair_runs": runs},
        "start": start,
        "end": _now(),
        "wall_seconds": round(time.perf_counter() - t_start, 3),
        "n_jobs": n_jobs,
        "machine": {
            "cpu": _cpu_name(),
            "n_cpus": os.cpu_count(),
            "python": platform.python_version(),
            "numpy": np.__version__,
            "numba": numba.__version__,
        },
    }
    # what every invocation did (the last 50), so that a re-run that only re-summarises
    # does not hide the wall time of the run that computed the results
    this = {k: run[k] for k in ("start", "end", "wall_seconds", "n_jobs", "computed")}
    this["algorithms_computed"] = sorted(recomputed)
    run["history"] = (prev.get("history", []) if prev.get("base_key") == base_key else [])[-49:]
    run["history"].append(this)
    save_json(runf, run)
    say(f"done in {run['wall_seconds']:.1f} s ({runs} pair x algorithm runs)")
    return Results(out)


# -- command line ------------------------------------------------------------------------------


def main(argv=None) -> int:
    """``python -m fpdtw.experiments [--mode MODE | --smoke] [--jobs N] [--algorithms NAME ...]
    [--quiet]``."""
    ap = argparse.ArgumentParser(
        prog="python -m fpdtw.experiments", description=__doc__.split("\n")[0]
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
    "DEFAULT_ALGORITHMS",
    "PAPER_COUNTS",
    "SELECTIONS",
    "TABLE1_60HZ_NAMES",
    "AlgorithmResult",
    "AlgorithmSpec",
    "PairSelection",
    "Results",
    "Selection",
    "aggregate_heatmap",
    "format_counts",
    "load_results",
    "pair_features",
    "pair_selection",
    "register_algorithm",
    "resolve_algorithm",
    "run_experiments",
    "slug",
    "summarize",
]


def _register_extras() -> None:
    from .online.oltw import run_pair as oltw_pair
    from .opw_eval import opw_pair

    register_algorithm("OPW", opw_pair)
    register_algorithm("OLTW", oltw_pair)


_register_extras()


if __name__ == "__main__":
    # run the importable module's main: worker processes must find the functions by name
    from fpdtw.experiments import main as _main

    sys.exit(_main())
