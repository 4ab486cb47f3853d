"""What the claims read from the experiment results: per-pair values, medians, intervals.

:class:`Evidence` is one body of data a verdict can be made on: some (or all) pairs of a
run, one bootstrap scheme (:mod:`fpdtw.paper.claims.bootstrap`), one reading of the
algorithms' names (Method C's window, a silent choice) and, for the readings of the
metrics, per-pair values computed another way. It gives each algorithm's median and its
bootstrap replicates, and builds the :class:`~fpdtw.paper.claims.rules.Check` objects the
claims are made of:

* :meth:`Evidence.passes` -- an algorithm passes a benchmark: its median similarity minus
  UTW's median (paired: the same resampled pairs) above 0, or its median deviation below
  150 ms (18 frames at 120 Hz, 9 at 60 Hz);
* :meth:`Evidence.better` -- one algorithm's median above (similarity) or below
  (deviation) another's, on the same pairs;
* :meth:`Evidence.rank` -- an algorithm's rank among several, per resample;
* :meth:`Evidence.share` -- a share counted over frames or pairs (a ratio of sums).

Paper: FP-DTW Sections 4-6 (the medians over pairs, the two benchmarks).
Notebook: 12_claims.ipynb
"""

from __future__ import annotations

import hashlib
import io

import numpy as np

from fpdtw.online.band import band_cells
from fpdtw.paper import numbers as N
from fpdtw.paper.atomic import write_atomic
from fpdtw.paper.claims import bootstrap as bs
from fpdtw.paper.claims.rules import AllOf, AnyOf, Check
from fpdtw.registry import resolve

METRICS = ("similarity", "deviation")
#: Bump when what a cached bootstrap replicate holds changes.
_CACHE_VERSION = 1


def _digest(*parts: bytes) -> str:
    h = hashlib.sha256()
    for p in parts:
        h.update(len(p).to_bytes(8, "little") + p)
    return h.hexdigest()[:32]


def _cached(folder, key: str, compute) -> np.ndarray:
    """``compute()`` once per key: read from ``folder/<key>.npy`` when there, else computed
    and written (atomically). ``folder`` None: no disk cache."""
    if folder is None:
        return compute()
    path = folder / f"{key}.npy"
    try:
        return np.load(path, allow_pickle=False)
    except (FileNotFoundError, ValueError, OSError):
        pass
    out = compute()

    buf = io.BytesIO()
    np.save(buf, out, allow_pickle=False)
    folder.mkdir(parents=True, exist_ok=True)
    write_atomic(path, buf.getvalue())
    return out


_UNIT = {"similarity": "", "deviation": " frames"}


def _ci(replicates) -> tuple[float, float, float, float]:
    """Interval ends and their Monte Carlo errors (:func:`bootstrap.interval_error`)."""
    return bs.interval_error(replicates)


def rate_of(name: str) -> int:
    """120, or 60 for a name ending in ``"@60Hz"``."""
    return 60 if name.endswith("@60Hz") else 120


def utw_of(name: str) -> str:
    """UTW at the rate of ``name``: ``"UTW"`` or ``"UTW@60Hz"``."""
    return "UTW@60Hz" if rate_of(name) == 60 else "UTW"


class Evidence:
    """Per-pair values of some pairs of a run, with medians and bootstrap replicates.

    Parameters
    ----------
    results : fpdtw.paper.runner.run.Results
    rows : sequence of int, optional
        Indices into ``results.pairs`` (default: every pair).
    scheme : {"movements", "motions"}
        Bootstrap scheme (:data:`fpdtw.paper.claims.bootstrap.SCHEMES`).
    n_resamples, seed : int
    alias : dict, optional
        A claim's name -> the results it stands for under a reading (e.g. ``"Mc w40"`` ->
        ``"Mc w40 (literal window)"``).
    values : callable, optional
        ``values(result_name, metric) -> ndarray (P,) or None``: per-pair values of a metric
        computed another way (a reading of eq. 2 or 3), in ``results.pairs`` order; None
        keeps the stored ones.
    label : str
        What this body of data is, in words (``"all pairs"``, ``"hdm05"``...).

    :meth:`restrict` and :meth:`reading` derive evidence that shares these bootstrap weights
    (a dataset's pairs are a stratum of the resampling, so the weights of its columns are a
    bootstrap of that dataset alone).

    Notebook: 12_claims.ipynb
    """

    def __init__(
        self,
        results,
        rows=None,
        scheme="movements",
        n_resamples=bs.N_RESAMPLES,
        seed=bs.SEED,
        alias=None,
        values=None,
        label="all pairs",
    ):
        self.results = results
        P = len(results.pairs)
        self.rows = np.arange(P) if rows is None else np.asarray(rows, dtype=np.int64)
        if self.rows.size == 0:
            raise ValueError(f"{label}: no pairs")
        self.scheme, self.n_resamples, self.seed = scheme, n_resamples, seed
        self.alias = dict(alias or {})
        self._values = values
        self.label = label
        self._design = None
        self._W = None
        self._owner = None  # the evidence whose weights these pairs use (None: its own)
        self._cols = None  # columns of the owner's weights holding these pairs (None: all)
        self._key = None
        self._cache = {}
        ids = np.array([int(p["id"]) for p in results.pairs], dtype=np.int64)
        self._pair_ids = ids[self.rows]

    def restrict(self, keep, label: str) -> Evidence:
        """The same evidence on some of its pairs (``keep``: bool mask or indices into
        :attr:`rows`), sharing its bootstrap weights. Only valid for subsets that are whole
        strata (datasets) of the resampling."""
        keep = np.asarray(keep)
        idx = np.flatnonzero(keep) if keep.dtype == bool else keep.astype(np.int64)
        out = self._derived(rows=self.rows[idx], label=label)
        out._owner = self._owner or self
        base = np.arange(self.n_pairs) if self._cols is None else self._cols
        out._cols = base[idx]
        out._key = _digest(self.weights_key.encode(), out._cols.tobytes())
        return out

    def reading(self, alias=None, values=None, label=None) -> Evidence:
        """The same pairs and weights under another reading of the names or the metrics."""
        out = self._derived(rows=self.rows, label=label or self.label, alias=alias, values=values)
        out._owner, out._cols, out._key = self._owner or self, self._cols, self.weights_key
        return out

    def _derived(self, rows, label, alias=None, values=None) -> Evidence:
        return Evidence(
            self.results,
            rows,
            self.scheme,
            self.n_resamples,
            self.seed,
            alias=self.alias if alias is None else alias,
            values=self._values if values is None else values,
            label=label,
        )

    # -- data ---------------------------------------------------------------------------------

    @property
    def design(self) -> bs.PairDesign:
        if self._design is None:
            self._design = bs.PairDesign.from_pairs([self.results.pairs[i] for i in self.rows])
        return self._design

    @property
    def weights_key(self) -> str:
        """What decides the bootstrap weights of these pairs (design, scheme, resamples,
        seed), as a hex digest: the key of the on-disk cache of replicates."""
        if self._key is None:
            d = self.design
            parts = [a.tobytes() for a in (d.dataset, d.movement, d.input, d.target)]
            spec = f"{_CACHE_VERSION}:{self.scheme}:{self.n_resamples}:{self.seed}"
            self._key = _digest(spec.encode(), *parts)
        return self._key

    @property
    def weights(self) -> np.ndarray:
        """Bootstrap weights, shape (n_resamples, P_all) (computed once, on first need;
        :attr:`cols` are this evidence's columns)."""
        if self._owner is not None:
            return self._owner.weights
        if self._W is None:
            self._W = bs.resample_weights(self.design, self.scheme, self.n_resamples, self.seed)
        return self._W

    @property
    def cols(self) -> np.ndarray:
        """Columns of :attr:`weights` that hold this evidence's pairs, in order."""
        if self._cols is not None:
            return self._cols
        return np.arange((self._owner or self).n_pairs)

    @property
    def n_pairs(self) -> int:
        return int(self.rows.size)

    def source(self, name: str) -> str:
        """The results a claim's name reads under this evidence's reading."""
        return self.alias.get(name, name)

    def has(self, *names) -> bool:
        """Whether every name has results (under the reading)."""
        have = set(self.results.algorithms)
        return all(self.source(n) in have for n in names)

    def values(self, name: str, metric: str) -> np.ndarray:
        """Per-pair values of a metric for ``name``, in the order of :attr:`rows`."""
        if metric not in METRICS:
            raise ValueError(f"metric must be one of {METRICS}, got {metric!r}")
        key = ("values", name, metric)
        if key not in self._cache:
            src = self.source(name)
            v = self._values(src, metric) if self._values is not None else None
            if v is None:
                arr = self.results.get(src)
                pos = np.empty(int(np.max(arr["pair_id"])) + 1, dtype=np.int64)
                pos[np.asarray(arr["pair_id"], dtype=np.int64)] = np.arange(arr["pair_id"].size)
                v = np.asarray(arr[metric], dtype=np.float64)[pos[self._pair_ids]]
            else:
                v = np.asarray(v, dtype=np.float64)[self.rows]
            self._cache[key] = v
        return self._cache[key]

    def median(self, name: str, metric: str) -> float:
        """Median over this evidence's pairs (finite values), as the paper's figures."""
        v = self.values(name, metric)
        v = v[np.isfinite(v)]
        return float(np.median(v)) if v.size else float("nan")

    def replicates(self, name: str, metric: str) -> np.ndarray:
        """The median on every bootstrap resample, shape (n_resamples,).

        Kept on disk beside the results (``<results folder>/bootstrap/``), keyed by the
        weights and the values, so that every notebook reading the same run reuses them.
        """
        key = ("reps", name, metric)
        if key not in self._cache:
            v = self.values(name, metric)
            self._cache[key] = _cached(
                self._cache_dir(),
                _digest(self.weights_key.encode(), v.tobytes()),
                lambda: bs.weighted_medians(v, self.weights, self.cols),
            )
        return self._cache[key]

    def ratio_replicates(self, numerator, denominator) -> np.ndarray:
        """``sum(w * numerator) / sum(w * denominator)`` on every resample (cached on disk as
        :meth:`replicates`)."""
        num = np.asarray(numerator, dtype=np.float64)
        den = np.asarray(denominator, dtype=np.float64)
        key = _digest(self.weights_key.encode(), b"ratio", num.tobytes(), den.tobytes())
        return _cached(
            self._cache_dir(), key, lambda: bs.weighted_ratios(num, den, self.weights, self.cols)
        )

    def _cache_dir(self):
        folder = getattr(self.results, "folder", None)
        return None if folder is None else folder / "bootstrap"

    def interval(self, name: str, metric: str) -> tuple[float, float]:
        """95 % interval of the median of ``name``."""
        return bs.interval(self.replicates(name, metric))

    # -- checks -------------------------------------------------------------------------------

    def passes(self, name: str, metric: str) -> Check:
        """``name`` passes the benchmark of ``metric`` (paper Section 5).

        Similarity: median minus UTW's median (same pairs, same resamples) above 0.
        Deviation: median below 150 ms in frames of the algorithm's rate.
        """
        if metric == "similarity":
            u = utw_of(name)
            est = self.median(name, metric) - self.median(u, metric)
            ci = _ci(self.replicates(name, metric) - self.replicates(u, metric))
            return Check(
                f"{name} median similarity minus UTW's", est, *ci[:2], 0.0, above=True,
                signed=True, low_se=ci[2], high_se=ci[3],
            )  # fmt: skip
        thr = N.deviation_benchmark_frames(rate_of(name))
        ci = _ci(self.replicates(name, metric))
        return Check(
            f"{name} median deviation, frames",
            self.median(name, metric),
            *ci[:2],
            thr,
            above=False,
            digits=1,
            low_se=ci[2],
            high_se=ci[3],
        )

    def passes_either(self, name: str):
        """``name`` passes at least one of the two benchmarks."""

        return AnyOf(self.passes(name, "similarity"), self.passes(name, "deviation"))

    def passes_both(self, name: str):
        """``name`` passes both benchmarks."""

        return AllOf(self.passes(name, "similarity"), self.passes(name, "deviation"))

    def better(self, a: str, b: str, metric: str) -> Check:
        """``a`` is better than ``b`` on the same pairs: higher median similarity, or lower
        median deviation (difference of the two medians, paired resamples)."""
        est = self.median(a, metric) - self.median(b, metric)
        ci = _ci(self.replicates(a, metric) - self.replicates(b, metric))
        return Check(
            f"median {metric} of {a} minus {b}",
            est,
            *ci[:2],
            0.0,
            above=metric == "similarity",
            signed=True,
            digits=3 if metric == "similarity" else 1,
            low_se=ci[2],
            high_se=ci[3],
        )

    def ranks(self, names, metric: str) -> tuple[np.ndarray, np.ndarray]:
        """Rank (1 = best) of each name by median, on the data and on every resample.

        Returns
        -------
        rank : ndarray of int, shape (len(names),)
        rank_reps : ndarray of int, shape (len(names), n_resamples)
        """
        sign = -1.0 if metric == "similarity" else 1.0  # rank 1: highest similarity
        est = sign * np.array([self.median(n, metric) for n in names])
        reps = sign * np.stack([self.replicates(n, metric) for n in names])
        rank = 1 + np.sum(est[None, :] < est[:, None], axis=1)
        rank_reps = 1 + np.sum(reps[None, :, :] < reps[:, None, :], axis=1)
        return rank, rank_reps

    def rank(self, name: str, names, metric: str, worst_from: int) -> Check:
        """``name`` ranks ``worst_from`` or worse among ``names`` by median ``metric``."""
        names = list(names)
        rank, reps = self.ranks(names, metric)
        i = names.index(name)
        ci = _ci(reps[i])
        return Check(
            f"rank of {name} (of {len(names)}) by median {metric}",
            float(rank[i]),
            *ci[:2],
            worst_from - 0.5,
            above=True,
            digits=0,
            low_se=ci[2],
            high_se=ci[3],
        )

    def share(
        self, quantity: str, numerator, denominator, threshold: float, above: bool = True
    ) -> Check:
        """A share summed over pairs (e.g. frames with the input exhausted / all frames)."""
        num = np.asarray(numerator, dtype=np.float64)
        den = np.asarray(denominator, dtype=np.float64)
        est = float(num.sum() / den.sum()) if den.sum() > 0 else float("nan")
        lo, hi, lo_se, hi_se = _ci(self.ratio_replicates(num, den))
        return Check(quantity, est, lo, hi, threshold, above=above, low_se=lo_se, high_se=hi_se)

    def share_difference(self, quantity: str, a, b, threshold: float = 0.0) -> Check:
        """Difference of two shares of the same pairs: ``a`` and ``b`` are
        ``(numerator, denominator)`` per pair; paired resamples."""
        (na, da), (nb, db) = ((np.asarray(x, dtype=np.float64) for x in y) for y in (a, b))
        est = float(na.sum() / da.sum() - nb.sum() / db.sum())
        reps = self.ratio_replicates(na, da) - self.ratio_replicates(nb, db)
        lo, hi, lo_se, hi_se = _ci(reps)
        return Check(
            quantity, est, lo, hi, threshold, above=True, signed=True, low_se=lo_se, high_se=hi_se
        )

    # -- per pair, from the maps ---------------------------------------------------------------

    def exhausted_counts(self, name: str) -> tuple[np.ndarray, np.ndarray]:
        """Per pair: target frames processed with the input exhausted, and all frames q >= 1.

        A frame ``q >= 1`` counts when ``M_{q-1} >= m`` (as
        :func:`fpdtw.paper.figures.timing.exhausted_fraction`).
        """
        key = ("exhausted", name)
        if key not in self._cache:
            src = self.source(name)
            arr = self.results.get(src)
            m_all, _ = self.results.frames(src)
            m_of = {int(p["id"]): int(m_all[i]) for i, p in enumerate(self.results.pairs)}
            pos = {int(pid): k for k, pid in enumerate(arr["pair_id"])}
            ex = np.zeros(self.n_pairs)
            fr = np.zeros(self.n_pairs)
            for j, pid in enumerate(self._pair_ids):
                M = arr.map(pos[int(pid)])
                ex[j] = np.count_nonzero(M[:-1] >= m_of[int(pid)])
                fr[j] = M.size - 1
            self._cache[key] = (ex, fr)
        return self._cache[key]

    def band_cells(self, name: str) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Per pair, the cells of eq. 1 a band variant's windows compute, from its maps
        (:func:`fpdtw.online.band.band_cells`): its window steps, the cells of those steps without
        the band and with it, and the sum over the steps of the share of the window's cells
        the band removes (``1 - with / without``).

        Parameters
        ----------
        name : str
            A Method B or C name with a band option (``"Mc w40 (band w/2)"``).

        Returns
        -------
        steps, full, banded, removed : ndarray of float64, shape (P,)

        Paper: FP-DTW Section 7 (conclusion: a global constraint).
        """

        key = ("band_cells", name)
        if key not in self._cache:
            src = self.source(name)
            a = resolve(src.partition("@")[0])
            band = a.options.get("band", "none")
            if a.family not in ("B", "C") or band == "none" or "window" in a.options:
                raise ValueError(f"{name!r}: not a band variant of Method B or C (square window)")
            arr = self.results.get(src)
            m_all, _ = self.results.frames(src)
            m_of = {int(p["id"]): int(m_all[i]) for i, p in enumerate(self.results.pairs)}
            pos = {int(pid): k for k, pid in enumerate(arr["pair_id"])}
            out = np.zeros((4, self.n_pairs))
            for j, pid in enumerate(self._pair_ids):
                M = arr.map(pos[int(pid)])
                _, full, banded = band_cells(M, m_of[int(pid)], a.w, a.family, band)
                out[:, j] = (full.size, full.sum(), banded.sum(), np.sum(1.0 - banded / full))
            self._cache[key] = tuple(out)
        return self._cache[key]

    def backward_jumps(self, name: str = "OE-DTW") -> np.ndarray:
        """Per pair: 1 when the map moves backwards at least once (``M_{q+1} < M_q``)."""
        src = self.source(name)
        arr = self.results.get(src)
        pos = {int(pid): k for k, pid in enumerate(arr["pair_id"])}
        return np.array(
            [
                float(np.any(np.diff(arr.map(pos[int(p)]).astype(np.int64)) < 0))
                for p in self._pair_ids
            ]
        )


_SHARED: dict = {}


def shared_evidence(results, dataset=None, scheme: str = "movements") -> Evidence:
    """The evidence of a run's pairs (or one dataset's), made once per run and reused.

    Figures, tables and claims of one notebook then read the same medians and the same
    bootstrap replicates, so they cannot disagree.

    Parameters
    ----------
    results : fpdtw.paper.runner.run.Results
    dataset : str, optional
        Only this dataset's pairs (a stratum of the resampling: the weights are shared).
    scheme : {"movements", "motions"}
    """
    key = (id(results), scheme)
    hit = _SHARED.get(key)
    if hit is None or hit[0] is not results:
        if len(_SHARED) > 8:  # a long session: forget older runs
            _SHARED.clear()
        hit = (results, Evidence(results, scheme=scheme), {})
        _SHARED[key] = hit
    _, ev, subsets = hit
    if dataset is None:
        return ev
    if dataset not in subsets:
        ds = np.array([p["dataset"] for p in results.pairs])
        if not np.any(ds == dataset):
            raise ValueError(f"no pairs of dataset {dataset!r} in the results")
        subsets[dataset] = ev.restrict(ds == dataset, dataset)
    return subsets[dataset]


__all__ = ["METRICS", "Evidence", "rate_of", "shared_evidence", "utw_of"]
