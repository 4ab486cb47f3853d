"""Which motions and which ordered pairs an experiment run takes (paper Section 4).

Every ORDERED pair (input, target) of distinct takes of the same movement: the authors'
FBX takes available here grouped by movement, and the HDM05 clips grouped by class. Pair ids
follow (dataset, movement, input, target) in manifest order. :data:`SELECTIONS` holds the
selection of each mode.

Notebook: 05_run_experiments.ipynb
"""

from __future__ import annotations

import hashlib
from collections import OrderedDict
from dataclasses import asdict, dataclass, field

import numpy as np

from fpdtw.paper import catalog, numbers
from fpdtw.paper import datasets as data

#: Datasets of the experiments (paper Section 4).
DATASETS = ("authors_fbx", "hdm05")


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
    subsample_takes : int or None
        After the draw above, keep at most this many of each movement's drawn takes, drawn
        again (without replacement, then in manifest order) with the generator seeded by
        ``sample_seed + 1``, the dataset and the movement: a seeded subsample of the
        selection without it. None: no second draw.
    crop_seconds : float or None
        Crop every motion to its first seconds (``Motion.crop(0, s)``) before
        features are built; None keeps whole motions.
    max_movements : int or None
        Keep at most this many movements of each dataset, the first ones (in the order of
        the catalogue) that keep two takes; None keeps all. Only the smoke runs of notebooks
        15 and 16 use it (to keep ``make test`` short): it is a test of the code path, not a
        selection of results.
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

#: The selection of each mode: ``"full"`` every take (whole classes); ``"smoke"`` the
#: first two takes of every movement, both directions (2 pairs per movement), cropped to
#: 2 s; ``"study"`` (notebook 15) the paper-shaped selection, at most 8 takes per movement
#: drawn with a fixed seed (the authors' movements have 3 takes, so all of them stay);
#: ``"smoke-study"`` the smoke selection on its first :data:`SMOKE_MOVEMENTS` movements of
#: each dataset; ``"open"`` (notebook 16) a subsample of the paper-shaped selection: of its
#: takes of each movement, :data:`OPEN_TAKES` drawn with seed ``PAPER_SHAPED_SEED + 1``;
#: ``"smoke-open"`` as ``"smoke-study"``.
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


def _subsample(recs: list, sel: Selection, dataset: str, movement: str) -> list:
    """At most ``sel.subsample_takes`` of the takes drawn (see :class:`Selection`)."""
    k = sel.subsample_takes
    if k is None or len(recs) <= k:
        return recs
    seed = int.from_bytes(
        hashlib.sha256(f"{(sel.sample_seed or 0) + 1}/{dataset}/{movement}".encode()).digest()[:8]
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
            recs = _subsample(recs, sel, ds, movement)
            if len(recs) < 2:
                dropped.append(f"{ds}/{movement}")
                continue
            if sel.max_movements is not None and c["movements"] >= sel.max_movements:
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
    p = numbers.DATA
    lines.append(
        f"{'paper':12s} {p['motions']:4d} motions {p['movements']:3d} movements "
        f"{p['pairs']:6d} pairs"
    )
    return "\n".join(lines)


__all__ = [
    "DATASETS",
    "OPEN_TAKES",
    "PAPER_SHAPED_SEED",
    "PAPER_SHAPED_TAKES",
    "SELECTIONS",
    "PairSelection",
    "Selection",
    "format_counts",
    "pair_selection",
]
