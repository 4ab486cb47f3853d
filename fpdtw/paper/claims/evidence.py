"""What the claims read from the experiment results: per-pair values, medians, intervals,
and the :class:`~fpdtw.paper.claims.rules.Check` objects the claims are made of.

Paper: FP-DTW Sections 4-6 (the medians over pairs, the two benchmarks).
Notebook: 12_claims.ipynb
"""

from __future__ import annotations

import functools
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


def _memo(method):
    """A method whose result is kept per arguments in the evidence's ``_cache``."""

    @functools.wraps(method)
    def cached(self, *args):
        key = (method.__name__, *args)
        if key not in self._cache:
            self._cache[key] = method(self, *args)
        return self._cache[key]

    return cached


def _check(quantity: str, estimate: float, replicates, threshold: float, **kw) -> Check:
    """A check whose interval and Monte Carlo errors come from bootstrap replicates."""
    lo, hi, lo_se, hi_se = bs.interval_error(replicates)
    return Check(quantity, estimate, lo, hi, threshold, low_se=lo_se, high_se=hi_se, **kw)


def missing(ev, names, absent: str = "no experiment results") -> str | None:
    """None when ``ev`` has the results of every name, else why not (``absent``: no ``ev``)."""
    if ev is None:
        return absent
    gone = [n for n in names if not ev.has(n)]
    return f"no results for {', '.join(gone)}" if gone else None


class Evidence:
    """Per-pair values of some pairs of a run (``rows``: indices into ``results.pairs``,
    default all), with medians and bootstrap replicates.

    ``alias``: a claim's name -> the results it stands for under a reading; ``values(result_name,
    metric)``: per-pair values (P,) in ``results.pairs`` order computed another way, or None
    for the stored ones; ``label``: this body of data in words.

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
        self._owner = self  # the evidence whose weights these pairs use
        #: Columns of :attr:`weights` that hold this evidence's pairs, in order.
        self.cols = np.arange(self.rows.size)
        self._cache = {}
        self._pair_ids = np.array([int(results.pairs[r]["id"]) for r in self.rows], np.int64)

    def restrict(self, keep, label: str) -> Evidence:
        """The same evidence on some of its pairs (``keep``: bool mask or indices into
        :attr:`rows`) sharing its weights: valid for whole strata (datasets) only."""
        keep = np.asarray(keep)
        idx = np.flatnonzero(keep) if keep.dtype == bool else keep.astype(np.int64)
        out = self.again(rows=self.rows[idx], label=label)
        out._owner, out.cols = self._owner, self.cols[idx]
        out.weights_key = _digest(self.weights_key.encode(), out.cols.tobytes())
        return out

    def reading(self, alias=None, values=None, label=None) -> Evidence:
        """The same pairs and weights under another reading of the names or the metrics."""
        out = self.again(label=label, alias=alias, values=values)
        out._owner, out.cols, out.weights_key = self._owner, self.cols, self.weights_key
        return out

    def again(self, **changes) -> Evidence:
        """The same run with some of ``rows``, ``scheme``, ``seed``, ``alias``, ``values`` and
        ``label`` changed (None: unchanged), with weights of its own."""
        names = ("rows", "scheme", "n_resamples", "seed", "alias", "label")
        kw = {k: getattr(self, k) for k in names} | {"values": self._values}
        return Evidence(self.results, **kw | {k: v for k, v in changes.items() if v is not None})

    @functools.cached_property
    def design(self) -> bs.PairDesign:
        return bs.PairDesign.from_pairs([self.results.pairs[i] for i in self.rows])

    @functools.cached_property
    def weights_key(self) -> str:
        """Digest of what decides the bootstrap weights: the key of the replicates' disk cache."""
        d = self.design
        parts = [a.tobytes() for a in (d.dataset, d.movement, d.input, d.target)]
        spec = f"{_CACHE_VERSION}:{self.scheme}:{self.n_resamples}:{self.seed}"
        return _digest(spec.encode(), *parts)

    @functools.cached_property
    def weights(self) -> np.ndarray:
        """Bootstrap weights, shape (n_resamples, P_all), computed on first need."""
        if self._owner is not self:
            return self._owner.weights
        return bs.resample_weights(self.design, self.scheme, self.n_resamples, self.seed)

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

    @_memo
    def values(self, name: str, metric: str) -> np.ndarray:
        """Per-pair values of a metric for ``name``, in the order of :attr:`rows`."""
        if metric not in METRICS:
            raise ValueError(f"metric must be one of {METRICS}, got {metric!r}")
        src = self.source(name)
        v = self._values(src, metric) if self._values is not None else None
        if v is not None:
            return np.asarray(v, dtype=np.float64)[self.rows]
        arr = self.results.get(src)
        pos = np.empty(int(np.max(arr["pair_id"])) + 1, dtype=np.int64)
        pos[np.asarray(arr["pair_id"], dtype=np.int64)] = np.arange(arr["pair_id"].size)
        return np.asarray(arr[metric], dtype=np.float64)[pos[self._pair_ids]]

    def median(self, name: str, metric: str) -> float:
        """Median over this evidence's pairs (finite values)."""
        v = self.values(name, metric)
        v = v[np.isfinite(v)]
        return float(np.median(v)) if v.size else float("nan")

    @_memo
    def replicates(self, name: str, metric: str) -> np.ndarray:
        """The median on every bootstrap resample, shape (n_resamples,), cached on disk."""
        v = self.values(name, metric)
        return self._on_disk(
            (v.tobytes(),), lambda: bs.weighted_medians(v, self.weights, self.cols)
        )

    def ratio_replicates(self, num, den) -> np.ndarray:
        """``sum(w * num) / sum(w * den)`` (float64 arrays) on every resample, cached on disk."""
        parts = (b"ratio", num.tobytes(), den.tobytes())
        return self._on_disk(parts, lambda: bs.weighted_ratios(num, den, self.weights, self.cols))

    def _on_disk(self, parts, compute) -> np.ndarray:
        """``compute()`` once per weights and ``parts``, kept in the run's ``bootstrap/<key>.npy``
        (a run without a folder: no disk cache)."""
        folder = getattr(self.results, "folder", None)
        if folder is None:
            return compute()
        path = folder / "bootstrap" / f"{_digest(self.weights_key.encode(), *parts)}.npy"
        try:
            return np.load(path, allow_pickle=False)
        except (FileNotFoundError, ValueError, OSError):
            pass
        out = compute()
        buf = io.BytesIO()
        np.save(buf, out, allow_pickle=False)
        path.parent.mkdir(parents=True, exist_ok=True)
        write_atomic(path, buf.getvalue())
        return out

    def interval(self, name: str, metric: str) -> tuple[float, float]:
        """95 % interval of the median of ``name``."""
        return bs.interval(self.replicates(name, metric))

    def _difference(self, a: str, b: str, metric: str, quantity: str, **kw) -> Check:
        """The difference of the medians of ``a`` and ``b`` against 0."""
        est = self.median(a, metric) - self.median(b, metric)
        reps = self.replicates(a, metric) - self.replicates(b, metric)
        return _check(quantity, est, reps, 0.0, signed=True, **kw)

    def passes(self, name: str, metric: str) -> Check:
        """``name`` passes the benchmark of ``metric`` (paper Section 5): median similarity
        minus UTW's above 0, or median deviation below 150 ms in frames of its rate."""
        rate = 60 if name.endswith("@60Hz") else 120
        if metric == "similarity":
            u = "UTW@60Hz" if rate == 60 else "UTW"
            return self._difference(name, u, metric, f"{name} median similarity minus UTW's")
        return _check(f"{name} median deviation, frames", self.median(name, metric),
                      self.replicates(name, metric), N.deviation_benchmark_frames(rate),
                      above=False, digits=1)  # fmt: skip

    def passes_either(self, name: str):
        """``name`` passes at least one of the two benchmarks."""
        return AnyOf(self.passes(name, "similarity"), self.passes(name, "deviation"))

    def passes_both(self, name: str):
        """``name`` passes both benchmarks."""
        return AllOf(self.passes(name, "similarity"), self.passes(name, "deviation"))

    def better(self, a: str, b: str, metric: str) -> Check:
        """``a`` is better than ``b``: the difference of their medians above 0 (similarity) or
        below 0 (deviation)."""
        sim = metric == "similarity"
        return self._difference(a, b, metric, f"median {metric} of {a} minus {b}", above=sim,
                                digits=3 if sim else 1)  # fmt: skip

    def improves(self, a: str, b: str):
        """``a`` improves on ``b``: median similarity higher AND median deviation lower."""
        return AllOf(self.better(a, b, "similarity"), self.better(a, b, "deviation"))

    def rank(self, name: str, names, metric: str, worst_from: int) -> Check:
        """``name`` ranks ``worst_from`` or worse (1: best) among ``names`` by ``metric``."""
        names = list(names)
        sign = -1.0 if metric == "similarity" else 1.0  # rank 1: highest similarity
        est = sign * np.array([self.median(n, metric) for n in names])
        reps = sign * np.stack([self.replicates(n, metric) for n in names])
        rank = 1 + np.sum(est[None, :] < est[:, None], axis=1)
        rank_reps = 1 + np.sum(reps[None, :, :] < reps[:, None, :], axis=1)
        i = names.index(name)
        return _check(f"rank of {name} (of {len(names)}) by median {metric}", float(rank[i]),
                      rank_reps[i], worst_from - 0.5, digits=0)  # fmt: skip

    def share(self, quantity: str, numerator, denominator, threshold: float) -> Check:
        """A share summed over pairs above ``threshold``."""
        num, den = (np.asarray(x, dtype=np.float64) for x in (numerator, denominator))
        est = float(num.sum() / den.sum()) if den.sum() > 0 else float("nan")
        return _check(quantity, est, self.ratio_replicates(num, den), threshold)

    def share_difference(self, quantity: str, a, b) -> Check:
        """Shares ``a`` minus ``b`` (each ``(numerator, denominator)`` per pair) above 0."""
        (na, da), (nb, db) = ((np.asarray(x, dtype=np.float64) for x in y) for y in (a, b))
        est = float(na.sum() / da.sum() - nb.sum() / db.sum())
        reps = self.ratio_replicates(na, da) - self.ratio_replicates(nb, db)
        return _check(quantity, est, reps, 0.0, signed=True)

    def _maps(self, name: str):
        """``(M, m)`` of every pair of this evidence: its map and last input frame."""
        src = self.source(name)
        arr = self.results.get(src)
        m_all, _ = self.results.frames(src)
        pos = {int(pid): k for k, pid in enumerate(arr["pair_id"])}
        for pid, r in zip(self._pair_ids, self.rows):
            yield arr.map(pos[int(pid)]), int(m_all[r])

    @_memo
    def exhausted_counts(self, name: str) -> tuple[np.ndarray, np.ndarray]:
        """Per pair: target frames ``q >= 1`` with the input exhausted (``M_{q-1} >= m``), and
        all frames ``q >= 1``."""
        counts = [(np.count_nonzero(M[:-1] >= m), M.size - 1) for M, m in self._maps(name)]
        return tuple(np.array(counts, dtype=np.float64).T.copy())

    @_memo
    def band_cells(self, name: str) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Per pair, from the maps of a band variant of Method B or C: its window steps, their
        cells without and with the band, and the summed share removed; float64 (P,) each.

        Paper: FP-DTW Section 7 (conclusion: a global constraint).
        """
        a = resolve(self.source(name).partition("@")[0])
        band = a.options.get("band", "none")
        if a.family not in ("B", "C") or band == "none" or "window" in a.options:
            raise ValueError(f"{name!r}: not a band variant of Method B or C (square window)")
        out = []
        for M, m in self._maps(name):
            _, full, banded = band_cells(M, m, a.w, a.family, band)
            out.append((full.size, full.sum(), banded.sum(), np.sum(1.0 - banded / full)))
        return tuple(np.array(out, dtype=np.float64).T.copy())

    def backward_jumps(self, name: str) -> np.ndarray:
        """Per pair: 1 when the map moves backwards at least once (``M_{q+1} < M_q``)."""
        return np.array(
            [float(np.any(np.diff(M.astype(np.int64)) < 0)) for M, _ in self._maps(name)]
        )


_SHARED: dict = {}


def shared_evidence(results, dataset=None) -> Evidence:
    """The evidence of a run's pairs (or of one dataset's), made once per run."""
    hit = _SHARED.get(id(results))
    if hit is None or hit[0] is not results:
        if len(_SHARED) > 8:  # a long session: forget older runs
            _SHARED.clear()
        hit = _SHARED[id(results)] = (results, Evidence(results), {})
    _, ev, subsets = hit
    if dataset is None:
        return ev
    if dataset not in subsets:
        ds = np.array([p["dataset"] for p in results.pairs])
        if not np.any(ds == dataset):
            raise ValueError(f"no pairs of dataset {dataset!r} in the results")
        subsets[dataset] = ev.restrict(ds == dataset, dataset)
    return subsets[dataset]
