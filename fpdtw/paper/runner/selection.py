"""Which motions and which ordered pairs an experiment run takes (paper Section 4): the
authors' FBX takes available here grouped by movement, the HDM05 clips grouped by class.

Notebook: 05_run_experiments.ipynb
"""

from __future__ import annotations

import hashlib
import itertools
from collections import OrderedDict
from dataclasses import asdict, dataclass, field

import numpy as np

from fpdtw.paper import catalog, numbers
from fpdtw.paper import datasets as data

#: Datasets of the experiments (paper Section 4).
DATASETS = ("authors_fbx", "hdm05")


@dataclass(frozen=True)
class Selection:
    """Which motions take part in an experiment run (None: no limit).

    ``datasets``: manifest names, in order; ``movements``: only these; ``takes_per_movement``:
    at most this many takes of each, the first in manifest order or, with a ``sample_seed``,
    drawn without replacement (kept in manifest order) seeded by it, the dataset and the
    movement; ``subsample_takes``: then at most this many, drawn with ``sample_seed + 1``;
    ``crop_seconds``: each motion cropped to its first seconds; ``max_movements``: the first
    this many movements with two takes per dataset (smoke runs of notebooks 15 and 16).
    """

    datasets: tuple = DATASETS
    movements: tuple | None = None
    takes_per_movement: int | None = None
    crop_seconds: float | None = None
    sample_seed: int | None = None
    subsample_takes: int | None = None
    max_movements: int | None = None

    def as_dict(self) -> dict:
        d = asdict(self)
        for key in ("subsample_takes", "max_movements"):  # selections made before keep keys
            if d[key] is None:
                del d[key]
        d["datasets"] = list(self.datasets)
        d["movements"] = None if self.movements is None else list(self.movements)
        return d


#: Takes per movement of the "paper-shaped" selection: the paper's 333 motions over 44
#: movements are 7.6 takes per movement on average (Section 4); we cap at 8.
PAPER_SHAPED_TAKES = 8
#: Seed of the paper-shaped draw (fixed: the draw is part of the documented selection).
PAPER_SHAPED_SEED = 2023

#: Takes per movement of the "open" mode (notebook 16): a seeded subsample of the
#: paper-shaped selection small enough for its grid to stay within the time budget.
OPEN_TAKES = 2
#: Movements per dataset of the smoke runs of notebooks 15 and 16 (``make test`` time).
SMOKE_MOVEMENTS = 8

#: The selection of each mode: ``"full"`` every take (whole classes); ``"smoke"`` 2 pairs per
#: movement cropped to 2 s; ``"study"`` (notebook 15) paper-shaped (the authors' movements have
#: 3 takes: all stay); ``"open"`` (notebook 16) a subsample of it (drawn with seed + 1).
SELECTIONS = {
    "full": Selection(),
    "smoke": Selection(takes_per_movement=2, crop_seconds=2.0),
    "study": Selection(takes_per_movement=PAPER_SHAPED_TAKES, sample_seed=PAPER_SHAPED_SEED),
    "smoke-study": Selection(takes_per_movement=2, crop_seconds=2.0, max_movements=SMOKE_MOVEMENTS),
    "open": Selection(
        takes_per_movement=PAPER_SHAPED_TAKES,
        sample_seed=PAPER_SHAPED_SEED,
        subsample_takes=OPEN_TAKES,
    ),
    "smoke-open": Selection(takes_per_movement=2, crop_seconds=2.0, max_movements=SMOKE_MOVEMENTS),
}


@dataclass
class PairSelection:
    """Motions and ordered pairs of a :class:`Selection`, from the manifests (nothing loaded):
    ``motions`` in manifest order with ``sha256`` (content hash, plus the skeleton's for HDM05);
    ``pairs`` (``id, dataset, movement, input, target, input_path, target_path, input_index,
    target_index``); ``counts`` per dataset and ``"total"``; ``rows`` one per movement;
    ``dropped``: movements with fewer than two takes."""

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


def _draw(recs: list, k: int, seed: int, dataset: str, movement: str) -> list:
    """``k`` of a movement's takes drawn without replacement, kept in manifest order."""
    seed = int.from_bytes(hashlib.sha256(f"{seed}/{dataset}/{movement}".encode()).digest()[:8])
    keep = np.random.default_rng(seed).choice(len(recs), size=k, replace=False)
    return [recs[i] for i in sorted(keep)]


def pair_selection(selection: Selection | None = None) -> PairSelection:
    """Every ORDERED pair of distinct takes of the same movement (default: the ``"full"``
    mode's selection); ids in order of dataset, movement, input, target (manifest order).

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
            k, seed = sel.takes_per_movement, sel.sample_seed
            if k is not None and len(recs) > k:
                recs = recs[:k] if seed is None else _draw(recs, k, seed, ds, movement)
            k = sel.subsample_takes
            if k is not None and len(recs) > k:
                recs = _draw(recs, k, (sel.sample_seed or 0) + 1, ds, movement)
            if len(recs) < 2:
                dropped.append(f"{ds}/{movement}")
                continue
            if sel.max_movements is not None and c["movements"] >= sel.max_movements:
                continue
            first = len(motions)
            for r in recs:
                motions.append(r)
                sha.append(_content_hashes(manifest, entries, r))
            n_pairs = len(recs) * (len(recs) - 1)
            for (a, I), (b, T) in itertools.permutations(enumerate(recs), 2):
                pairs.append(dict(
                    id=len(pairs), dataset=ds, movement=movement, input=I.name,
                    target=T.name, input_path=I.path, target_path=T.path,
                    input_index=first + a, target_index=first + b,
                ))  # fmt: skip
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


def run_plan(results) -> tuple:
    """The pair selection of a finished run (:class:`~fpdtw.paper.runner.results.Results`)
    and, per pair of ``results.pairs``, its ``(input_index, target_index)``."""
    selection = Selection(
        **{k: tuple(v) if isinstance(v, list) else v for k, v in results.selection.items()}
    )
    plan = pair_selection(selection)
    by_id = {p["id"]: (p["input_index"], p["target_index"]) for p in plan.pairs}
    return plan, [by_id[int(p["id"])] for p in results.pairs]


def format_counts(counts: dict) -> str:
    """One line per dataset and the total, with the paper's counts for comparison.

    Notebook: 05_run_experiments.ipynb
    """
    return "\n".join(
        f"{ds:12s} {c['motions']:4d} motions {c['movements']:3d} movements {c['pairs']:6d} pairs"
        for ds, c in [*counts.items(), ("paper", numbers.DATA)]
    )
