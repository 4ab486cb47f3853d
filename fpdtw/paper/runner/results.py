"""The result files of the experiments: deterministic atomic writers, and the reader.

:func:`save_npz` writes the same bytes for the same arrays (:func:`numpy.savez` stamps the
time), :func:`save_json` JSON in the caller's key order, both atomically; :func:`load_results`
reads a run (file formats: :mod:`fpdtw.paper.runner.run`) into a :class:`Results`.
"""

from __future__ import annotations

import io
import json
import os
import re
import zipfile
from pathlib import Path

import numpy as np

from fpdtw.paper.atomic import write_atomic
from fpdtw.paper.paths import results_dir

#: Date of every zip entry (the earliest a zip file can hold).
ZIP_DATE = (1980, 1, 1, 0, 0, 0)
#: Unix permissions of every zip entry (rw-r--r--).
_ZIP_MODE = 0o100644 << 16


def npz_bytes(arrays: dict) -> bytes:
    """The bytes of a deterministic ``.npz`` of ``{entry name: array}`` (no object arrays):
    entries in the order given, uncompressed, dated 1980-01-01, fixed permissions."""
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", compression=zipfile.ZIP_STORED) as zf:
        for name, value in arrays.items():
            a = np.asarray(value)
            if a.dtype.hasobject:
                raise TypeError(f"{name}: object arrays cannot be saved (got dtype {a.dtype})")
            member = io.BytesIO()
            np.lib.format.write_array(member, a, allow_pickle=False)
            info = zipfile.ZipInfo(f"{name}.npy", date_time=ZIP_DATE)
            info.compress_type = zipfile.ZIP_STORED
            info.external_attr = _ZIP_MODE
            info.create_system = 3
            zf.writestr(info, member.getvalue())
    return buf.getvalue()


def save_npz(path, **arrays) -> Path:
    """Write arrays to ``path`` as a deterministic ``.npz`` (:func:`npz_bytes`), atomically."""
    return write_atomic(path, npz_bytes(arrays))


def load_npz(path, keys=None) -> dict:
    """The arrays of a ``.npz`` (no pickles), all of them or only ``keys``, in that order."""
    with np.load(path, allow_pickle=False) as z:
        names = list(z.files) if keys is None else list(keys)
        return {k: z[k] for k in names}


def _nan_to_none(obj):
    if isinstance(obj, float) and obj != obj:
        return None
    if isinstance(obj, dict):
        return {k: _nan_to_none(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [_nan_to_none(v) for v in obj]
    return obj


def save_json(path, obj) -> Path:
    """Write ``obj`` as indented JSON (NaN as null, a trailing newline), atomically."""
    text = json.dumps(_nan_to_none(obj), indent=1, allow_nan=False) + "\n"
    return write_atomic(path, text.encode())


def load_json(path):
    """Read a JSON file."""
    return json.loads(Path(path).read_text())


#: Suffix of an algorithm name that runs it on the motions resampled to 60 Hz.
RATE_SUFFIX = "@60Hz"
#: Frame rates of the experiments.
BASE_FPS, LOW_FPS = 120.0, 60.0


def slug(name: str) -> str:
    """File name of an algorithm's results: ``"Mc w40 + Type V"`` -> ``"Mc_w40_TypeV"``,
    ``"Mc w40 (band w/2)"`` -> ``"Mc_w40_band_w2"`` (brackets, commas, slashes dropped)."""
    s = name.replace(" + Type V", "_TypeV").replace(RATE_SUFFIX, "_60Hz").replace(" ", "_")
    return re.sub(r"_+", "_", re.sub(r"[(),/]", "", s))


class AlgorithmResult(dict):
    """The arrays of ``algorithms/<slug>.npz`` (``pair_id``, ``offsets``, ``maps``,
    ``similarity``, ``deviation``) plus ``name``, ``fps`` and ``map`` (:meth:`map`)."""

    def __init__(self, arrays: dict, name: str, fps: float):
        super().__init__(arrays, name=name, fps=fps, map=self.map)

    def map(self, k: int) -> np.ndarray:
        """The map of pair ``k``: int32 array of shape (n + 1,), target frame -> input frame."""
        o = self["offsets"]
        return self["maps"][o[k] : o[k + 1]]


#: The reading of eq. 2 the run stores (each paper joint's animated local rotation).
STORED_EQ2 = "local"
#: The readings of eq. 2 a :class:`Results` can score with: each joint's whole local
#: transform (rescored from the stored maps), and the stored one.
EQ2_READINGS = ("transform", "local")
#: Environment variable choosing the reading (default: the first of :data:`EQ2_READINGS`).
EQ2_ENV = "FPDTW_EQ2"
#: Reading of eq. 2 -> ``rescore(results, reading) -> values(name, metric)``, filled by
#: :mod:`fpdtw.paper.similarity_level` (imported with :mod:`fpdtw.paper.runner`).
RESCORERS: dict = {}


def default_eq2() -> str:
    """The reading of eq. 2 the results are scored with: ``$FPDTW_EQ2`` or ``"transform"``
    (each joint's whole local transform, as the authors' toolkit reads it:
    ``docs/eq2_reading.md``), the default since 2026-11-24; ``"local"`` (the raw animated
    rotation, the stored scores) before, one switch away.

    Paper: FP-DTW eq. 2.
    """
    value = os.environ.get(EQ2_ENV, "").strip() or EQ2_READINGS[0]
    if value not in EQ2_READINGS:
        raise ValueError(f"{EQ2_ENV}={value!r}: not a reading of eq. 2 ({', '.join(EQ2_READINGS)})")
    return value


class Results:
    """The results of a run (:func:`load_results`): ``pairs`` (of ``pairs.json``),
    ``counts``, ``algorithms`` (in run order), ``summary`` and ``run`` (``summary.json``,
    ``run.json``; {} before they are written) and ``eq2``, the reading of eq. 2 :meth:`get`
    scores with (:meth:`stored`: the stored scores, :data:`STORED_EQ2`'s)."""

    def __init__(self, folder, algorithms=None, eq2=None):
        self.eq2 = default_eq2() if eq2 is None else eq2
        if self.eq2 not in EQ2_READINGS:
            raise ValueError(f"eq2={self.eq2!r}: not one of {EQ2_READINGS}")
        self._rescore = None
        self.folder = Path(folder)
        meta = load_json(self.folder / "pairs.json")
        self.mode = meta["mode"]
        self.pairs = meta["pairs"]
        self.counts = meta["counts"]
        self.selection = meta.get("selection")
        runf, sumf = self.folder / "run.json", self.folder / "summary.json"
        self.run = load_json(runf) if runf.is_file() else {}
        self.summary = load_json(sumf) if sumf.is_file() else {}
        info = algorithms if algorithms is not None else self.run.get("algorithms", [])
        self._info = {a["name"]: a for a in info}
        self.algorithms = [a["name"] for a in info]
        self._cache = {}

    def __repr__(self):
        return (
            f"Results({self.mode!r}, {len(self.pairs)} pairs, "
            f"{len(self.algorithms)} algorithms, folder={str(self.folder)!r})"
        )

    def _check(self, name) -> dict:
        if name not in self._info:
            raise KeyError(f"no results for {name!r}; have: {', '.join(self.algorithms)}")
        return self._info[name]

    def fps(self, name: str) -> float:
        """Frame rate the algorithm ran at (120 or 60)."""
        return float(self._check(name)["fps"])

    def is_online(self, name: str) -> bool:
        """Whether the algorithm is online (it sees one target frame at a time)."""
        return bool(self._check(name)["online"])

    def stored(self, name: str) -> AlgorithmResult:
        """Maps, similarity and deviation of every pair as the run stored them."""
        self._check(name)
        if name not in self._cache:
            arrays = load_npz(self.folder / "algorithms" / f"{slug(name)}.npz")
            self._cache[name] = AlgorithmResult(arrays, name, self.fps(name))
        return self._cache[name]

    def get(self, name: str) -> AlgorithmResult:
        """Maps, similarity and deviation of every pair, eq. 2 under :attr:`eq2` (the stored
        maps rescored once and cached beside the run)."""
        r = self.stored(name)
        if self.eq2 == STORED_EQ2:
            return r
        key = (name, self.eq2)
        if key not in self._cache:
            if self._rescore is None:
                if self.eq2 not in RESCORERS:
                    raise RuntimeError(
                        f"no rescorer for eq. 2 read as {self.eq2!r}: import fpdtw.paper.runner"
                    )
                self._rescore = RESCORERS[self.eq2](self, self.eq2)
            arrays = {k: v for k, v in r.items() if k not in ("name", "fps", "map")}
            arrays["similarity"] = self._rescore(name, "similarity")
            self._cache[key] = AlgorithmResult(arrays, name, self.fps(name))
        return self._cache[key]

    def frames(self, name: str) -> tuple:
        """Last input and target frame indices ``(m, n)`` of every pair at the algorithm's
        rate: int64 arrays of shape (P,)."""
        tag = "60" if self.fps(name) == LOW_FPS else ""
        return tuple(np.array([p[k + tag] for p in self.pairs], dtype=np.int64) for k in "mn")


def load_results(mode: str = "full", eq2: str | None = None) -> Results:
    """Read the results of a run from ``results_dir()/<mode>``, eq. 2 under ``eq2`` (default
    :func:`default_eq2`); FileNotFoundError says how to make a missing run.

    Notebook: 06_fig5_fig6_scores.ipynb, 07_table1_60hz.ipynb, 08_fig7_fig10_heatmaps.ipynb,
    09_table2_timing.ipynb, 12_claims.ipynb
    """
    folder = results_dir() / mode
    if not (folder / "run.json").is_file():
        flag = " --smoke" if mode == "smoke" else ""
        raise FileNotFoundError(
            f"no finished {mode!r} run in {folder}; run `fpdtw experiments run{flag}` "
            "or notebooks/05_run_experiments.ipynb first"
        )
    return Results(folder, eq2=eq2)


def aggregate_heatmap(results: Results, name: str, bins: int = 100) -> np.ndarray:
    """Every path of an algorithm on the unit square, as a 2-D histogram.

    Each path point ``(q / n, M_q / m)`` counts ``1 / (n + 1)`` in a ``bins x bins`` grid
    (a fraction of 1 in the last bin), so the grid sums to the number of pairs.

    Returns
    -------
    H : ndarray of float64, shape (bins, bins)
        Row: input fraction bin (y); column: target fraction bin (x).

    Paper: FP-DTW Figs. 7 and 10.
    """
    r = results.get(name)
    m, n = results.frames(name)
    offsets = r["offsets"]
    lengths = np.diff(offsets)
    seg = np.repeat(np.arange(lengths.shape[0]), lengths)
    q = np.arange(offsets[-1]) - offsets[seg]
    x = q / np.maximum(n[seg], 1)
    y = r["maps"].astype(np.float64) / np.maximum(m[seg], 1)
    w = 1.0 / lengths[seg]
    xb = np.minimum((x * bins).astype(np.int64), bins - 1)
    yb = np.minimum((y * bins).astype(np.int64), bins - 1)
    H = np.bincount(yb * bins + xb, weights=w, minlength=bins * bins)
    return H.reshape(bins, bins)
