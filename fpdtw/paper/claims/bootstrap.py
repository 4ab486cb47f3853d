"""Intervals for medians over pairs that share motions: a two-stage cluster bootstrap.

Pairs sharing a motion are not independent. Scheme ``"movements"`` draws, within each
dataset, movements and, within each drawn movement, motions, with replacement; a pair
``(a, b)`` counts ``c_a * c_b`` times (``c``: how often each motion was drawn). Every statistic
is computed on every resample from the same weights (paired comparisons); intervals are
percentile intervals, byte-identical on reruns.

Paper: FP-DTW Section 4 (medians over pairs of takes of the same movement).
Notebook: 12_claims.ipynb
"""

from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np

#: The resampling schemes and the question each answers.
SCHEMES = {
    "movements": "other movements like these, recorded again (movements resampled within "
    "each dataset, then motions within each movement)",
    "motions": "these movements, other takes of them (motions resampled within each "
    "movement; the movements fixed)",
}
#: Resamples per interval: :func:`seed_stability` on the full run (notebook 12) keeps interval
#: ends within :data:`STABILITY` from 16000 on (1000 to 32000 measured).
N_RESAMPLES = 16000
#: Seed of every interval (FP-DTW's article number, e2166).
SEED = 2166
#: Interval ends must move less than this between seeds (similarity units).
STABILITY = 0.002
#: Two-sided level of every interval.
LEVEL = 0.95
#: Batches of the batch-means Monte Carlo error of an interval end.
MC_BATCHES = 16


@dataclass(frozen=True)
class PairDesign:
    """Codes (dense, from 0) of each pair's dataset, movement, input and target motion (unique
    across datasets and movements): int64 arrays of shape (P,)."""

    dataset: np.ndarray
    movement: np.ndarray
    input: np.ndarray
    target: np.ndarray

    @property
    def n_pairs(self) -> int:
        return int(self.dataset.size)

    @classmethod
    def from_pairs(cls, pairs) -> PairDesign:
        """The design of ``Results.pairs`` rows, codes in sorted order of the labels."""
        mv = [(p["dataset"], p["movement"]) for p in pairs]
        mo = {k: [(*x, p[k]) for x, p in zip(mv, pairs)] for k in ("input", "target")}
        motions = mo["input"] + mo["target"]
        return cls(_codes([x[0] for x in mv]), _codes(mv), *(_codes(mo[k], motions) for k in mo))


def _codes(labels, universe=None) -> np.ndarray:
    """Each label's position among the sorted distinct ``universe`` (default: the labels)."""
    code = {x: i for i, x in enumerate(sorted(set(labels if universe is None else universe)))}
    return np.array([code[x] for x in labels], dtype=np.int64)


def resample_weights(
    design: PairDesign, scheme: str = "movements", n: int = N_RESAMPLES, seed: int = SEED
) -> np.ndarray:
    """How often each pair counts in each of ``n`` resamples of the two-stage bootstrap.

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
                _add_pair_weights(W, rows, li, lt, C, copies[:, gi] > c)  # live: still drawn
    return W


@numba.njit(cache=True)
def _add_pair_weights(W, rows, li, lt, C, live):  # pragma: no cover - compiled
    """``W[b, rows[p]] += C[b, li[p]] * C[b, lt[p]]`` for the resamples ``b`` with ``live[b]``."""
    for b in range(W.shape[0]):
        if live[b]:
            for p in range(rows.size):
                W[b, rows[p]] += C[b, li[p]] * C[b, lt[p]]


def weighted_medians(values, W, cols=None) -> np.ndarray:
    """Per row of the integer weights ``W`` (B, P_all), ``np.median`` of ``values`` (P,)
    repeated by their weights in the columns ``cols`` (default: all): float64 (B,).
    Non-finite values get no weight; a resample with no weight left gives NaN."""
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
    """Per row of ``W``: the median of the sorted values ``vs`` (pairs ``order``), weighted."""
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
    """``sum(w * numerator) / sum(w * denominator)`` under each row of weights ``W`` (B, P):
    shares counted over frames; shape (B,), NaN where the denominator sums to 0."""
    W = np.atleast_2d(W)
    W = (W if cols is None else W[:, np.asarray(cols)]).astype(np.float64)
    num = W @ np.asarray(numerator, dtype=np.float64)
    den = W @ np.asarray(denominator, dtype=np.float64)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(den > 0, num / np.where(den > 0, den, 1.0), np.nan)


def interval(replicates) -> tuple[float, float]:
    """Percentile interval (:data:`LEVEL`) of bootstrap replicates, NaN ones left out (NaN
    ends when none is finite)."""
    r = np.asarray(replicates, dtype=np.float64)
    r = r[np.isfinite(r)]
    if r.size == 0:
        return float("nan"), float("nan")
    a = 100 * (1 - LEVEL) / 2
    lo, hi = np.percentile(r, [a, 100 - a])
    return float(lo), float(hi)


def interval_error(replicates):
    """``(low, high, low_se, high_se)``: the interval and each end's Monte Carlo standard error
    by batch means (NaN with fewer than 50 finite replicates per batch)."""
    lo, hi = interval(replicates)
    r = np.asarray(replicates, dtype=np.float64)
    r = r[np.isfinite(r)]
    if r.size < 50 * MC_BATCHES:
        return lo, hi, float("nan"), float("nan")
    ends = np.array([interval(b) for b in np.array_split(r, MC_BATCHES)])
    se = ends.std(axis=0, ddof=1) / np.sqrt(MC_BATCHES)
    return lo, hi, float(se[0]), float(se[1])


def seed_stability(values_by_name: dict, design: PairDesign, n: int = N_RESAMPLES) -> dict:
    """How far interval ends move between the seeds :data:`SEED` and ``SEED + 1``.

    Returns
    -------
    out : dict
        ``n``, ``max_shift`` (largest change of an interval end over the names), ``worst``
        (its name) and ``per_name`` (name -> shift).

    Notebook: 12_claims.ipynb
    """
    ends = []
    for s in (SEED, SEED + 1):
        W = resample_weights(design, "movements", n, s)
        ends.append({k: interval(weighted_medians(v, W)) for k, v in values_by_name.items()})
    per = {k: max(abs(ends[0][k][i] - ends[1][k][i]) for i in (0, 1)) for k in values_by_name}
    worst = max(per, key=per.get) if per else None
    return dict(n=n, max_shift=per[worst] if worst else 0.0, worst=worst, per_name=per)
