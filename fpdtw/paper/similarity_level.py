"""Why our eq. 2 scores sit above the paper's: the stored maps rescored under each reading.

Eq. 2 (the similarity of the aligned input and target) leaves several representational
details open. Each reading of :data:`READINGS` changes ONE of them from ours (local
rotations, the unit vector (0, 1, 0), Kendall tau-b, an axis flat in one motion scoring 0,
every target frame); :func:`similarity_level_rows` rescores the maps a finished run stored
(no aligner is run again) and reports the median eq. 2 of UTW, DTW and Mc w40 per dataset,
beside the paper's Table 1 values.

The motions are loaded again from the catalog (resampled to 120 Hz and cropped as the run
did) because the global and root-relative frames and the bone directions need the whole
skeleton, which the run's feature cache does not keep; the local rotations so obtained are
checked equal to the cache's reading (the ``ours`` row reproduces the run's stored scores).

:func:`reading_values` rescores EVERY algorithm of a run (both rates, lazily, cached on
disk) under one reading, as the per-pair ``values`` of
:class:`fpdtw.paper.claims.evidence.Evidence`: the claims can then be read under it.
"""

from __future__ import annotations

import hashlib
import io
import json
from dataclasses import asdict, dataclass

import numpy as np
from tqdm.auto import tqdm

from fpdtw.metrics import similarity
from fpdtw.motion.joints import PAPER_JOINTS
from fpdtw.motion.rig import TRAJECTORY_FRAMES, bone_directions, trajectory_rotations
from fpdtw.online.window import SMOOTHING
from fpdtw.paper import catalog
from fpdtw.paper import numbers as N
from fpdtw.paper.atomic import write_atomic
from fpdtw.paper.figures.paper_vs_ours import side_by_side
from fpdtw.paper.runner.grid import split_transform
from fpdtw.paper.runner.results import EQ2_READINGS, RESCORERS, STORED_EQ2, slug
from fpdtw.paper.runner.run import BASE_FPS
from fpdtw.paper.runner.selection import Selection, pair_selection
from fpdtw.pause import hold_frames, pause_plan, pause_seed

#: Algorithms of the table (the paper's Table 1 gives UTW and Mc w40 at 120 Hz).
LEVEL_ALGORITHMS = ("UTW", "DTW", "Mc w40")

#: Paper Table 1 (120 Hz), median eq. 2 over its data set's pairs (Section 4 names no other
#: selection); DTW is not in the table.
PAPER_TABLE1 = {"UTW": N.TABLE1[120]["UTW"], "DTW": float("nan"), "Mc w40": N.TABLE1[120][40]}

#: Target frames of the online methods' warm-up: ``M_0`` and ``n < s`` (``s = 2``).
WARMUP_FRAMES = SMOOTHING + 1


@dataclass(frozen=True)
class Reading:
    """One reading of eq. 2: the trajectory frame, the axis and the similarity options."""

    name: str
    changes: str
    frame: str = "local"
    axis: str = "y"
    tau: str = "b"
    flat: str = "zero"
    skip: int = 0


#: Ours first, then one change at a time.
READINGS = (
    Reading("ours", "local rotations, (0, 1, 0), tau-b, one-flat axis 0, all frames"),
    Reading("tau-a", "Kendall tau-a instead of tau-b", tau="a"),
    Reading("flat-toolkit", "the authors' toolkit's flat-axis rule", flat="toolkit"),
    Reading("flat-skip", "an axis flat in one motion left out", flat="skip"),
    Reading(
        "skip-warm-up", f"the first {WARMUP_FRAMES} target frames left out", skip=WARMUP_FRAMES
    ),
    Reading("bone-axis", "each joint's bone direction instead of (0, 1, 0)", axis="bone"),
    Reading(
        "transform",
        "local transforms with the pre/post-rotations (FBX; ASF axis frames)",
        frame="transform",
    ),
    Reading("global", "global (world) rotations", frame="global"),
    Reading("root", "rotations relative to the root", frame="root"),
)


def _motion_arrays(record, crop, fps=BASE_FPS, frames=TRAJECTORY_FRAMES) -> dict:
    """Rotations of the paper's joints in some frames, the bone directions and the name of
    one motion, resampled and cropped as the run did (120 Hz, crop, then ``fps``)."""
    motion = catalog.load(record)
    if abs(motion.fps - BASE_FPS) > 1e-6:
        motion = motion.resample(BASE_FPS)
    if crop is not None:
        motion = motion.crop(0.0, crop)
    if fps != BASE_FPS:
        motion = motion.resample(fps)
    out = {f: trajectory_rotations(motion, f, PAPER_JOINTS) for f in frames}
    out["bone"] = bone_directions(motion, PAPER_JOINTS)
    out["name"] = motion.name
    return out


def _plan(results) -> tuple:
    """The run's pair selection, ``(input, target)`` motion indices of each of its pairs
    (``results.pairs`` order) and its crop."""
    selection = Selection(
        **{k: tuple(v) if isinstance(v, list) else v for k, v in results.selection.items()}
    )
    plan = pair_selection(selection)
    by_id = {p["id"]: (p["input_index"], p["target_index"]) for p in plan.pairs}
    return plan, [by_id[int(p["id"])] for p in results.pairs], selection.crop_seconds


def _score(r: Reading, I: dict, T: dict, M) -> float:
    """Eq. 2 of one map under reading ``r`` (``I``, ``T``: :func:`_motion_arrays`)."""
    axis = (I["bone"], T["bone"]) if r.axis == "bone" else "y"
    return similarity(I[r.frame], T[r.frame], M, tau=r.tau, flat=r.flat, skip=r.skip, axis=axis)


def pair_arrays(results, k: int) -> tuple:
    """The rotations (each frame) and bone directions of pair k's input and target.

    Loaded from the catalog as :func:`rescore` does (the run's feature cache is not
    touched).

    Parameters
    ----------
    results : fpdtw.paper.runner.run.Results
    k : int
        Index into ``results.pairs``.

    Returns
    -------
    I, T : dict
        ``"local"``, ``"transform"``, ``"global"``, ``"root"``: ndarray of float64, shape (F, 8, 4);
        ``"bone"``: ndarray of float64, shape (8, 3).

    Notebook: 17_similarity_level.ipynb
    """
    plan, index, crop = _plan(results)
    return tuple(_motion_arrays(plan.motions[i], crop) for i in index[k])


def rescore(results, readings=READINGS, algorithms=LEVEL_ALGORITHMS, progress=True) -> dict:
    """Per-pair eq. 2 of stored maps under each reading.

    Parameters
    ----------
    results : fpdtw.paper.runner.run.Results
        A finished run (read only; its feature cache is not touched).
    readings : sequence of Reading
    algorithms : sequence of str
        Names stored in the run (120 Hz).
    progress : bool
        tqdm bars over the motions and the pairs.

    Returns
    -------
    scores : dict
        ``scores[reading.name][algorithm]``: ndarray of float64, shape (P,), in
        ``results.pairs`` order.

    Raises
    ------
    ValueError
        The ``ours`` reading does not reproduce the run's stored scores (the motions
        loaded again differ from those the run aligned).

    Paper: FP-DTW eq. 2.
    """

    plan, index, crop = _plan(results)
    used = sorted({i for pair in index for i in pair})
    arrays = {
        i: _motion_arrays(plan.motions[i], crop)
        for i in tqdm(used, desc="motions", disable=not progress)
    }
    stored = {a: results.stored(a) for a in algorithms}
    P = len(index)
    scores = {r.name: {a: np.full(P, np.nan) for a in algorithms} for r in readings}
    for k in tqdm(range(P), desc="pairs", disable=not progress):
        I, T = (arrays[i] for i in index[k])
        for a in algorithms:
            M = np.asarray(stored[a].map(k), dtype=np.int64)
            for r in readings:
                scores[r.name][a][k] = _score(r, I, T, M)
    if "ours" in scores:
        for a in algorithms:
            want = np.asarray(stored[a]["similarity"], dtype=np.float64)
            if not np.allclose(scores["ours"][a], want, atol=1e-12, equal_nan=True):
                raise ValueError(
                    f"{results.folder}: eq. 2 of {a} recomputed from the motions differs "
                    "from the run's stored scores (other data or code than the run's)"
                )
    return scores


#: Bump when what :func:`reading_values` stores changes (it is part of every cache key).
RESCORE_FORMAT = 1


def _algorithm_scores(r: Reading, stored, arrays: dict, index: list, pause_fps=None):
    """Eq. 2 of every stored map of one algorithm under reading ``r``.

    ``arrays``: motion index -> :func:`_motion_arrays` at the algorithm's rate; ``index``:
    ``(input, target)`` of each pair; ``pause_fps``: the rate, when the algorithm ran on
    the targets with a pause inserted (the pause of :func:`fpdtw.pause.insert_pause`).
    """
    out = np.empty(len(index))
    for k, (i, t) in enumerate(index):
        T = arrays[t]
        if pause_fps is not None:
            at, length = pause_plan(T[r.frame].shape[0], pause_fps, pause_seed(T["name"]))
            T = {**T, r.frame: hold_frames(T[r.frame], at, length)}
        out[k] = _score(r, arrays[i], T, np.asarray(stored.map(k), dtype=np.int64))
    return out


def _npy_bytes(a: np.ndarray) -> bytes:
    buf = io.BytesIO()
    np.lib.format.write_array(buf, a, allow_pickle=False)
    return buf.getvalue()


def reading_values(results, reading: str = "transform", progress: bool = True):
    """Per-pair eq. 2 of every algorithm of a run under one reading, for :class:`Evidence`.

    The maps the run stored are rescored (no aligner runs again) on the motions loaded from
    the catalog as the run loaded them (resampled to 120 Hz, cropped, then resampled to
    60 Hz for the ``"@60Hz"`` names; a ``"@pause"`` name's targets get their pause). Each
    motion is loaded once per rate, each algorithm rescored on its first request, and its
    scores kept in ``results.folder / "rescored" / reading / f"{slug(name)}.{key}.npy"``,
    where ``key`` (16 hex digits) is a sha256 of :data:`RESCORE_FORMAT`, the reading's
    options, the name, the crop, the pair ids, the motions' data hashes and the stored
    ``offsets`` and ``maps``: a changed run writes a new file (the old ones of that name
    are removed) and never reads a stale one. Changes to the code that reads the motions
    or computes eq. 2 are not in the key: bump :data:`RESCORE_FORMAT`.

    Parameters
    ----------
    results : fpdtw.paper.runner.run.Results
        A finished run (its result files are read; only ``rescored/`` is written).
    reading : str
        A name of :data:`READINGS` (``"ours"`` reproduces the stored scores).
    progress : bool
        tqdm bar over the motions loaded for each rate.

    Returns
    -------
    values : callable
        ``values(name, metric) -> ndarray of float64, shape (P,) or None``:
        ``"similarity"``: eq. 2 of each pair of ``name`` in ``results.pairs`` order;
        any other metric (``"deviation"``: eq. 3 does not depend on the reading): None.

    Raises
    ------
    KeyError
        An unknown reading, or (from ``values``) a name without results.
    ValueError
        (from ``values``) The stored pairs are not ``results.pairs`` in order.

    Paper: FP-DTW eq. 2.
    """

    by_name = {r.name: r for r in READINGS}
    if reading not in by_name:
        raise KeyError(f"unknown reading {reading!r}; have: {', '.join(by_name)}")
    r = by_name[reading]
    plan, index, crop = _plan(results)
    used = sorted({i for pair in index for i in pair})
    ids = np.array([int(p["id"]) for p in results.pairs], dtype=np.int64)
    base = hashlib.sha256(
        json.dumps(
            [RESCORE_FORMAT, asdict(r), crop, [[plan.sha256[i] for i in p] for p in index]]
        ).encode()
        + ids.tobytes()
    )
    folder = results.folder / "rescored" / reading
    motions, scores = {}, {}

    def arrays(fps: float) -> dict:
        if fps not in motions:
            motions[fps] = {
                i: _motion_arrays(plan.motions[i], crop, fps, frames=(r.frame,))
                for i in tqdm(used, desc=f"motions at {fps:g} Hz", disable=not progress)
            }
        return motions[fps]

    def compute(name: str) -> np.ndarray:
        stored, fps = results.stored(name), results.fps(name)
        if not np.array_equal(np.asarray(stored["pair_id"], dtype=np.int64), ids):
            raise ValueError(f"{results.folder}: the pairs of {name} are not the run's pairs")
        h = base.copy()
        for part in (name.encode(), stored["offsets"].tobytes(), stored["maps"].tobytes()):
            h.update(part)
        path = folder / f"{slug(name)}.{h.hexdigest()[:16]}.npy"
        if path.is_file():
            return np.load(path)
        pause = fps if split_transform(name)[1] == "pause" else None
        v = _algorithm_scores(r, stored, arrays(fps), index, pause)
        for old in folder.glob(f"{slug(name)}.*.npy"):
            old.unlink()
        write_atomic(path, _npy_bytes(v))
        return v

    def values(name: str, metric: str):
        if metric != "similarity":
            return None
        if name not in scores:
            scores[name] = compute(name)
        return scores[name]

    return values


def similarity_level_rows(results, scores=None, progress=True) -> list[dict]:
    """The table: median eq. 2 of UTW, DTW and Mc w40 per dataset under each reading.

    Parameters
    ----------
    results : fpdtw.paper.runner.run.Results
        The study run (paper-shaped selection) or the smoke-study run.
    scores : dict, optional
        :func:`rescore`'s output (computed when missing).
    progress : bool

    Returns
    -------
    rows : list of dict
        One per reading and dataset (``all``, then each dataset): ``reading``,
        ``changes``, ``dataset``, ``pairs``, ``UTW``, ``DTW``, ``Mc w40``,
        ``UTW - Mc w40``, and the paper's ``paper UTW``, ``paper Mc w40``.

    Paper: FP-DTW eq. 2, Table 1.
    Notebook: 17_similarity_level.ipynb
    """
    if scores is None:
        scores = rescore(results, progress=progress)
    datasets = np.array([p["dataset"] for p in results.pairs])
    groups = [("all", np.ones(datasets.size, bool))]
    groups += [(d, datasets == d) for d in sorted(set(datasets.tolist()))]
    rows = []
    for r in READINGS:
        if r.name not in scores:
            continue
        for d, mask in groups:
            med = {a: float(np.nanmedian(scores[r.name][a][mask])) for a in LEVEL_ALGORITHMS}
            rows.append(
                dict(
                    reading=r.name,
                    changes=r.changes,
                    dataset=d,
                    pairs=int(mask.sum()),
                    **{a: round(v, 3) for a, v in med.items()},
                    **{
                        "UTW - Mc w40": round(med["UTW"] - med["Mc w40"], 3),
                        "paper UTW": PAPER_TABLE1["UTW"],
                        "paper Mc w40": PAPER_TABLE1["Mc w40"],
                    },
                )
            )
    return rows


def closest_reading(rows, dataset: str = "all") -> dict:
    """The reading whose UTW median comes closest to the paper's 0.240, and how close.

    Parameters
    ----------
    rows : list of dict
        :func:`similarity_level_rows`.
    dataset : str

    Returns
    -------
    row : dict
        The row, with ``gap`` (our UTW median minus the paper's).

    Notebook: 17_similarity_level.ipynb
    """
    mine = [r for r in rows if r["dataset"] == dataset]
    best = min(mine, key=lambda r: abs(r["UTW"] - PAPER_TABLE1["UTW"]))
    return {**best, "gap": round(best["UTW"] - PAPER_TABLE1["UTW"], 3)}


#: A reading brings a median "near" the paper's when within this of it.
NEAR = 0.05


def level_comparison(rows, dataset: str = "all") -> list[dict]:
    """``paper | ours`` rows: UTW's and Mc w40's median eq. 2 under each reading, beside Table 1.

    Parameters
    ----------
    rows : list of dict
        :func:`similarity_level_rows`.
    dataset : str

    Returns
    -------
    out : list of dict
        :func:`fpdtw.paper.figures.paper_vs_ours.side_by_side` rows, two per reading (UTW and
        Mc w40 median eq. 2); ``ours`` says whether the median is within :data:`NEAR` of the
        paper's (the reading closes the gap). Values only: the claims decide nothing here.

    Paper: FP-DTW Table 1 (120 Hz: UTW and Mc w40), eq. 2.
    Notebook: 17_similarity_level.ipynb
    """
    # in the function: fpdtw.paper.runner imports this module, and the figures package
    # imports the runner

    out = []
    for r in rows:
        if r["dataset"] != dataset:
            continue
        for a in ("UTW", "Mc w40"):
            near = bool(abs(r[a] - PAPER_TABLE1[a]) <= NEAR)
            out.append(
                side_by_side(
                    f"{a} median eq. 2, {r['reading']} ({dataset})",
                    f"{PAPER_TABLE1[a]:.3f}",
                    f"{r[a]:.3f} ({'within' if near else 'not within'} {NEAR:g})",
                )
            )
    return out


# the readings of eq. 2 a Results can be scored with, other than the stored one
RESCORERS.update({r: reading_values for r in EQ2_READINGS if r != STORED_EQ2})

__all__ = [
    "LEVEL_ALGORITHMS",
    "NEAR",
    "PAPER_TABLE1",
    "READINGS",
    "RESCORE_FORMAT",
    "Reading",
    "WARMUP_FRAMES",
    "closest_reading",
    "level_comparison",
    "pair_arrays",
    "reading_values",
    "rescore",
    "similarity_level_rows",
]
