"""Intervals for medians over pairs that share motions: a two-stage cluster bootstrap.

The pairs of the evaluation are not independent samples: every motion of a movement with
``k`` takes is the input of ``k - 1`` pairs and the target of ``k - 1`` more, so a median
over pairs is a statistic of motions and movements. Resampling pairs as if independent
would give intervals far too narrow. The bootstrap here resamples what was sampled:

* scheme ``"movements"`` (the default, the verdicts' scheme): within each dataset, draw
  its movements with replacement; within each drawn movement, draw its motions with
  replacement. A pair ``(a, b)`` of two distinct motions of a drawn movement then counts
  ``c_a * c_b`` times, ``c`` being how often each motion was drawn (pairs of a motion with
  itself do not exist and get no weight). This answers: *would the result hold for other
  movements like these, recorded again?*
* scheme ``"motions"``: the movements stay as they are; only the motions within each are
  drawn again. This answers: *given these movements, how sure is the result, given which
  takes happened to be recorded?* Its intervals are narrower.

Datasets are strata (never mixed), so the share of each dataset's pairs stays what the
evaluation made it. Every statistic of a claim (a median, a difference of two medians of
the same pairs, a rank, a ratio of sums) is computed on every resample from the same
weights, so comparisons between algorithms are paired: the same resampled pairs enter
both sides. Intervals are percentile intervals (2.5 % and 97.5 %).

Deterministic: the weights depend only on the pairs, the scheme, the number of resamples
and the seed (:data:`SEED`), so reruns give byte-identical intervals. The number of
resamples, :data:`N_RESAMPLES`, was chosen so that interval ends move by less than
:data:`STABILITY` when only the seed changes (:func:`seed_stability` measures it; notebook
12 prints it).

Paper: FP-DTW Section 4 (medians over pairs of takes of the same movement).
Notebook: 12_claims.ipynb
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numba
import numpy as np

#: The resampling schemes and the question each answers.
SCHEMES = {
    "movements": "other movements like these, recorded again (movements resampled within "
    "each dataset, then motions within each movement)",
    "motions": "these movements, other takes of them (motions resampled within each "
    "movement; the movements fixed)",
}
#: Resamples per interval: chosen by :func:`seed_stability` on the full run (notebook 12), where
#: the similarity intervals' ends of six algorithms moved by at most 0.0057, 0.0044, 0.0020,
#: 0.0021, 0.0014 and 0.0008 between two seeds at 1000, 2000, 4000, 8000, 16000 and 32000
#: resamples: 16000 keeps them within :data:`STABILITY`.
N_RESAMPLES = 16000
#: Seed of every interval (FP-DTW's article number, e2166).
SEED = 2166
#: Interval ends must move less than this between seeds (similarity units).
STABILITY = 0.002
#: Two-sided level of every interval.
LEVEL = 0.95
#: Resamples per block when medians are computed (memory: block x pairs int64).
_BLOCK = 256


@dataclass(frozen=True)
class PairDesign:
    """Who shares what among the pairs: each pair's dataset, movement, input and target.

    Attributes
    ----------
    dataset, movement, input, target : ndarray of int64, shape (P,)
        Codes (dense, from 0) of each pair's dataset, movement (unique across datasets),
        input motion and target motion (unique across movements).
    names : dict
        The labels behind the codes: ``"dataset"``, ``"movement"``, ``"motion"`` lists.
    """

    dataset: np.ndarray
    movement: np.ndarray
    input: np.ndarray
    target: np.ndarray
    names: dict = field(default_factory=dict, compare=False)

    @property
    def n_pairs(self) -> int:
        return int(self.dataset.size)

    @classmethod
    def from_pairs(cls, pairs) -> PairDesign:
        """The design of a list of pairs (``Results.pairs`` rows: ``dataset``, ``movement``,
        ``input``, ``target``), codes in sorted order of the labels.
        """
        ds = [p["dataset"] for p in pairs]
        mv = [(p["dataset"], p["movement"]) for p in pairs]
        mo = sorted(
            {(p["dataset"], p["movement"], p[k]) for p in pairs for k in ("input", "target")}
        )
        d_names, m_names = sorted(set(ds)), sorted(set(mv))
        d_code = {x: i for i, x in enumerate(d_names)}
        m_code = {x: i for i, x in enumerate(m_names)}
        o_code = {x: i for i, x in enumerate(mo)}
        return cls(
            dataset=np.array([d_code[x] for x in ds], dtype=np.int64),
            movement=np.array([m_code[x] for x in mv], dtype=np.int64),
            input=np.array([o_code[(*x, p["input"])] for x, p in zip(mv, pairs)], np.int64),
            target=np.array([o_code[(*x, p["target"])] for x, p in zip(mv, pairs)], np.int64),
            names={"dataset": d_names, "movement": m_names, "motion": mo},
        )

    def subset(self, rows) -> PairDesign:
        """The design of some pairs (codes kept: a dataset's pairs stay one stratum)."""
        rows = np.asarray(rows, dtype=np.int64)
        return PairDesign(
            self.dataset[rows],
            self.movement[rows],
            self.input[rows],
            self.target[rows],
            self.names,
        )


def resample_weights(
    design: PairDesign, scheme: str = "movements", n: int = N_RESAMPLES, seed: int = SEED
) -> np.ndarray:
    """How often each pair counts in each resample of the two-stage cluster bootstrap.

    Parameters
    ----------
    design : PairDesign
    scheme : {"movements", "motions"}
        See :data:`SCHEMES`.
    n : int
        Resamples.
    seed : int

    Returns
    -------
    W : ndarray of int32, shape (n, P)
        ``W[b, p]``: the weight of pair ``p`` in resample ``b`` (0 where it is not drawn).
    """
    if scheme not in SCHEMES:
        raise ValueError(f"scheme must be one of {sorted(SCHEMES)}, got {scheme!r}")
    if n < 1:
        raise ValueError(f"need at least one resample, got {n}")
    rng = np.random.default_rng(np.random.SeedSequence([seed, list(SCHEMES).index(scheme)]))
    W = np.zeros((n, design.n_pairs), dtype=np.int32)
    for d in np.unique(design.dataset):
        movements = np.unique(design.movement[design.dataset == d])
        G = movements.size
        if scheme == "movements":
            copies = rng.multinomial(G, np.full(G, 1.0 / G), size=n)
        else:
            copies = np.ones((n, G), dtype=np.int64)
        for gi, g in enumerate(movements):
            rows = np.flatnonzero(design.movement == g)
            motions, local = np.unique(
                np.concatenate([design.input[rows], design.target[rows]]), return_inverse=True
            )
            li, lt = local[: rows.size], local[rows.size :]
            k = motions.size
            for c in range(int(copies[:, gi].max())):
                C = rng.multinomial(k, np.full(k, 1.0 / k), size=n)
                live = copies[:, gi] > c
                _add_pair_weights(W, rows, li, lt, C, live)
    return W


@numba.njit(cache=True)
def _add_pair_weights(W, rows, li, lt, C, live):  # pragma: no cover - compiled
    """``W[b, rows[p]] += C[b, li[p]] * C[b, lt[p]]`` for the resamples ``b`` with ``live[b]``.

    Tested by tests/test_claims_rules.py (``c_a c_b`` per pair, written out there).
    """
    for b in range(W.shape[0]):
        if live[b]:
            for p in range(rows.size):
                W[b, rows[p]] += C[b, li[p]] * C[b, lt[p]]


def weighted_medians(values, W, cols=None) -> np.ndarray:
    """The median of ``values`` under each row of weights, as if each pair were repeated.

    With integer weights this is ``np.median`` of the values repeated by their weights
    (the mean of the two middle values when the total weight is even), so unit weights give
    ``np.median(values)``. Non-finite values get no weight; a resample with no weight left
    gives NaN.

    Parameters
    ----------
    values : ndarray of float, shape (P,)
    W : ndarray of int, shape (B, P) or (B, P_all)
    cols : ndarray of int, shape (P,), optional
        The columns of ``W`` that hold the weights of ``values`` (a subset of the pairs
        ``W`` was drawn for); default: all of them, in order.

    Returns
    -------
    medians : ndarray of float64, shape (B,)
    """
    values = np.asarray(values, dtype=np.float64)
    W = np.atleast_2d(W)
    cols = np.arange(W.shape[1]) if cols is None else np.asarray(cols, dtype=np.int64)
    if cols.size != values.size:
        raise ValueError(f"{values.size} values but weights for {cols.size} pairs")
    ok = np.flatnonzero(np.isfinite(values))
    order = ok[np.argsort(values[ok], kind="stable")]
    return _weighted_medians(values[order], np.ascontiguousarray(W), cols[order])


@numba.njit(cache=True)
def _weighted_medians(vs, W, order):  # pragma: no cover - compiled
    """Per row of ``W``: the median of the sorted values ``vs`` (pairs ``order``) repeated by
    their weights.

    Tested by tests/test_claims_rules.py (the median of the repeated values).
    """
    B = W.shape[0]
    out = np.full(B, np.nan)
    for b in range(B):
        tot = 0
        for i in range(order.size):
            tot += W[b, order[i]]
        if tot == 0 or order.size == 0:
            continue
        lo_pos, hi_pos = (tot + 1) // 2, tot // 2 + 1  # 1-based positions of the middle
        acc = 0
        lo = -1
        for i in range(order.size):
            acc += W[b, order[i]]
            if lo < 0 and acc >= lo_pos:
                lo = i
            if acc >= hi_pos:
                out[b] = 0.5 * (vs[lo] + vs[i])
                break
    return out


def weighted_ratios(numerator, denominator, W, cols=None) -> np.ndarray:
    """``sum(w * numerator) / sum(w * denominator)`` under each row of weights.

    For shares counted over frames (e.g. frames processed with the input exhausted, out of
    all frames): every pair contributes its counts as often as it is drawn.

    Parameters
    ----------
    numerator, denominator : ndarray, shape (P,)
    W : ndarray of int, shape (B, P)

    Returns
    -------
    ratios : ndarray of float64, shape (B,)
        NaN where the denominator sums to 0.
    """
    W = np.atleast_2d(W)
    W = (W if cols is None else W[:, np.asarray(cols)]).astype(np.float64)
    num = W @ np.asarray(numerator, dtype=np.float64)
    den = W @ np.asarray(denominator, dtype=np.float64)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(den > 0, num / np.where(den > 0, den, 1.0), np.nan)


def interval(replicates, level: float = LEVEL) -> tuple[float, float]:
    """Percentile interval of bootstrap replicates (NaN replicates left out).

    Returns
    -------
    low, high : float
        NaN when no replicate is finite.
    """
    r = np.asarray(replicates, dtype=np.float64)
    r = r[np.isfinite(r)]
    if r.size == 0:
        return float("nan"), float("nan")
    a = 100 * (1 - level) / 2
    lo, hi = np.percentile(r, [a, 100 - a])
    return float(lo), float(hi)


#: Batches of the batch-means estimate of an interval end's Monte Carlo error.
MC_BATCHES = 16


def interval_error(replicates, level: float = LEVEL, batches: int = MC_BATCHES):
    """The percentile interval and the Monte Carlo standard error of each end.

    The replicates are cut into ``batches`` consecutive batches (the resamples are
    independent draws, so each batch is a bootstrap of its own); each batch's interval ends
    vary as ``1 / sqrt(batch size)``, so the standard error of the ends from all replicates
    is the standard deviation over the batches divided by ``sqrt(batches)``.

    Returns
    -------
    low, high, low_se, high_se : float
        NaN where no replicate is finite; the errors NaN with fewer than 2 batches of at
        least 50 finite replicates.
    """
    lo, hi = interval(replicates, level)
    r = np.asarray(replicates, dtype=np.float64)
    r = r[np.isfinite(r)]
    if batches < 2 or r.size < 50 * batches:
        return lo, hi, float("nan"), float("nan")
    ends = np.array([interval(b, level) for b in np.array_split(r, batches)])
    se = ends.std(axis=0, ddof=1) / np.sqrt(batches)
    return lo, hi, float(se[0]), float(se[1])


def seed_stability(
    values_by_name: dict,
    design: PairDesign,
    n: int = N_RESAMPLES,
    seeds=(SEED, SEED + 1),
    scheme: str = "movements",
) -> dict:
    """How far interval ends move when only the seed changes.

    Parameters
    ----------
    values_by_name : dict of str to ndarray, shape (P,)
        Per-pair values (e.g. each algorithm's similarity).
    design : PairDesign
    n : int
        Resamples.
    seeds : pair of int
    scheme : str

    Returns
    -------
    out : dict
        ``n``, ``max_shift`` (largest change of an interval end over the names),
        ``worst`` (its name) and ``per_name`` (name -> shift).

    Notebook: 12_claims.ipynb
    """
    ends = []
    for s in seeds:
        W = resample_weights(design, scheme, n, s)
        ends.append({k: interval(weighted_medians(v, W)) for k, v in values_by_name.items()})
    per = {k: max(abs(ends[0][k][i] - ends[1][k][i]) for i in (0, 1)) for k in values_by_name}
    worst = max(per, key=per.get) if per else None
    return dict(n=n, max_shift=per[worst] if worst else 0.0, worst=worst, per_name=per)


__all__ = [
    "LEVEL",
    "N_RESAMPLES",
    "SCHEMES",
    "SEED",
    "STABILITY",
    "PairDesign",
    "MC_BATCHES",
    "interval",
    "interval_error",
    "resample_weights",
    "seed_stability",
    "weighted_medians",
    "weighted_ratios",
]
