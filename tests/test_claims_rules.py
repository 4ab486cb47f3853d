"""The verdict rules (fpdtw.paper.claims.rules) and the cluster bootstrap, on invented data.

Every rule is shown able to give every verdict, on numbers made up for the purpose. When
the rules were chosen, and which results had been seen by then: docs/history.md.
"""

from __future__ import annotations

import numpy as np
import pytest
from reference.fake_run import FakeRun

from fpdtw.paper.claims import bootstrap as bs
from fpdtw.paper.claims import rules as R
from fpdtw.paper.claims.rules import AllOf, AnyOf, Check, Not, Part

H, C, I, NC = R.HOLDS, R.CONTRADICTED, R.INCONCLUSIVE, R.NOT_COMPARABLE


def check(lo, hi, thr=0.0, above=True, est=None, **kw):
    est = (lo + hi) / 2 if est is None else est
    return Check("x", est, lo, hi, thr, above=above, **kw)


# -- checks ---------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("lo", "hi", "above", "want"),
    [
        (0.1, 0.2, True, H),  # whole interval above 0
        (-0.2, -0.1, True, C),  # whole interval below
        (-0.1, 0.1, True, I),  # straddles
        (-0.1, 0.0, True, C),  # at the threshold is not above it
        (0.0, 0.1, True, I),
        (-0.2, -0.1, False, H),  # "below" statements mirror
        (0.1, 0.2, False, C),
        (-0.1, 0.1, False, I),
        (0.0, 0.1, False, C),
    ],
)
def test_a_check_decides_by_its_whole_interval(lo, hi, above, want):
    assert check(lo, hi, above=above).verdict == want


def test_at_least_and_at_most_checks_count_the_threshold_itself():
    assert check(0.0, 0.1, strict=False).verdict == H
    assert check(-0.1, 0.0, strict=False).verdict == I
    assert check(-0.2, -0.1, strict=False).verdict == C
    assert check(-0.1, 0.0, above=False, strict=False).verdict == H
    assert check(0.05, 0.1, above=False, strict=False).verdict == C


def test_a_point_check_ignores_its_interval_and_nan_is_inconclusive():
    assert Check("t", 20.0, threshold=8.0, interval=False).verdict == H
    assert Check("t", 5.0, threshold=8.0, interval=False).verdict == C
    assert Check("t", 5.0, -100.0, 100.0, 8.0, interval=True).verdict == I
    assert Check("t", float("nan"), threshold=8.0, interval=False).verdict == I
    assert check(float("nan"), 0.3).verdict == I


def test_describe_says_what_the_numbers_do():
    assert check(0.1, 0.3, est=0.2).describe() == "x 0.200 [0.100, 0.300] > 0"
    assert check(-0.3, -0.1, est=-0.2).describe() == "x -0.200 [-0.300, -0.100] <= 0"
    assert check(-0.1, 0.3, est=0.1).describe() == "x 0.100 [-0.100, 0.300] straddles 0"
    c = Check("dev", 13.5, 12.1, 14.9, 18.0, above=False, digits=1)
    assert c.describe() == "dev 13.5 [12.1, 14.9] < 18"
    assert Check("dev", 20.0, 19.0, 21.0, 18.0, above=False, digits=1).describe().endswith(">= 18")
    assert Check("t", 12.0, threshold=8, interval=False, digits=1).describe() == "t 12.0 > 8"


# -- formulas: Kleene's three-valued logic ------------------------------------------------------

VALUES = {H: check(0.1, 0.2), C: check(-0.2, -0.1), I: check(-0.1, 0.1)}


@pytest.mark.parametrize("a", [H, C, I])
@pytest.mark.parametrize("b", [H, C, I])
def test_all_any_not_follow_kleene(a, b):
    x, y = VALUES[a], VALUES[b]
    order = {C: 0, I: 1, H: 2}  # false < unknown < true
    back = {v: k for k, v in order.items()}
    assert R.evaluate(AllOf(x, y)) == back[min(order[a], order[b])]
    assert R.evaluate(AnyOf(x, y)) == back[max(order[a], order[b])]
    assert R.evaluate(Not(x)) == {H: C, C: H, I: I}[a]


def test_evidence_names_the_checks_that_decide():
    h, c, i = VALUES[H], VALUES[C], VALUES[I]
    assert R.evidence(AllOf(h, c, i)) == [c]  # contradicted by c alone
    assert R.evidence(AllOf(h, i)) == [i]  # unknown because of i
    assert R.evidence(AllOf(h, h)) == [h]  # holds: every item (dedup)
    assert R.evidence(AnyOf(c, h, i)) == [h]
    assert R.evidence(AnyOf(c, c)) == [c]
    assert R.evidence(Not(AnyOf(c, h))) == [h]  # "none passes" is contradicted by h
    assert R.checks(AllOf(h, Not(AnyOf(c, i)))) == [h, c, i]
    with pytest.raises(TypeError):
        R.evaluate("holds")


# -- parts and claims -----------------------------------------------------------------------------


def test_part_verdicts_and_explanations():
    p = Part("A passes", AllOf(VALUES[H], VALUES[C]))
    assert p.verdict == C and p.decisive() is VALUES[C]
    assert p.explain() == "A passes: contradicted (x -0.150 [-0.200, -0.100] <= 0)"
    q = Part("on the paper's pair", None, note="another pair")
    assert q.verdict == NC and q.explain() == "on the paper's pair: not comparable (another pair)"
    many = Part("all pass", AllOf(*[Check(f"c{k}", -1.0, -2.0, -0.5) for k in range(5)]))
    assert many.explain().endswith("; +2 more)")


@pytest.mark.parametrize(
    ("verdicts", "want"),
    [
        ([H, H], "yes"),
        ([H, C], "partly"),
        ([H, I], "partly"),
        ([H, NC], "partly"),
        ([C, C], "no"),
        ([C, I], "no"),
        ([I, I], "inconclusive"),
        ([I, NC], "inconclusive"),
        ([NC, NC], "not comparable"),
        ([], "n/a"),
    ],
)
def test_a_claims_verdict_follows_from_its_parts(verdicts, want):
    assert R.claim_verdict(verdicts) == want


def test_a_reason_names_the_parts_that_fail_and_why():
    ok = Part("Mc w40 passes a benchmark", VALUES[H])
    bad = Part("no other passes one", Not(Check("Mc w20 dev", 13.5, 12.0, 15.0, 18.0, above=False,
                                                digits=1)))  # fmt: skip
    text = R.claim_reason([ok, bad])
    assert text.startswith("No other passes one: contradicted (Mc w20 dev 13.5 [12.0, 15.0] < 18)")
    assert text.endswith("Holds: Mc w40 passes a benchmark")
    assert R.claim_reason([ok]).startswith("Mc w40 passes a benchmark: holds (x 0.150")
    both = R.claim_reason([ok, ok], contradiction="The text says otherwise.")
    assert both.startswith("The text says otherwise. All 2 parts hold (")
    assert len(R.claim_reason([bad])) >= 25  # never a bare "partly"


# -- the bootstrap --------------------------------------------------------------------------------


def test_weighted_medians_are_medians_of_the_repeated_values():
    rng = np.random.default_rng(1)
    for P in (1, 2, 5, 10, 11):
        v = rng.normal(size=P)
        v[rng.random(P) < 0.15] = np.nan
        W = rng.integers(0, 4, size=(6, P)).astype(np.int32)
        W[0] = 1
        got = bs.weighted_medians(v, W)
        for b in range(W.shape[0]):
            ok = np.isfinite(v)
            rep = np.repeat(v[ok], W[b][ok])
            if rep.size:
                assert got[b] == pytest.approx(np.median(rep))
            else:
                assert np.isnan(got[b])
    v = np.array([3.0, 1.0, 2.0, 10.0])
    assert bs.weighted_medians(v, np.ones((1, 4), np.int32))[0] == 2.5
    # a subset of the columns of a larger weight matrix
    W = np.array([[1, 5, 1, 1, 1, 9]], np.int32)
    assert bs.weighted_medians(v, W, cols=[0, 2, 3, 4])[0] == 2.5


def _design(run):
    return bs.PairDesign.from_pairs(run.pairs)


def test_the_compiled_weight_accumulation_counts_each_pair_as_its_motions_draws():
    rng = np.random.default_rng(5)
    k, B = 5, 7
    li, lt = np.nonzero(~np.eye(k, dtype=bool))
    rows = np.arange(li.size) + 3
    C = rng.multinomial(k, np.full(k, 1 / k), size=B)
    live = rng.random(B) < 0.7
    W = np.ones((B, rows.size + 6), np.int32)
    bs._add_pair_weights(W, rows, li, lt, C, live)
    for b in range(B):
        # a pair (a, b) of a live resample counts c_a * c_b more; a dead one adds nothing
        want = np.array([C[b, i] * C[b, t] for i, t in zip(li, lt)]) * live[b] + 1
        assert np.array_equal(W[b, rows], want)
    assert np.all(W[:, :3] == 1) and np.all(W[:, rows[-1] + 1 :] == 1)


def test_pairs_of_a_resample_count_as_the_product_of_their_motions_draws():
    run = FakeRun({"hdm05": 3}, takes=4)
    d = _design(run)
    W = bs.resample_weights(d, "motions", n=50, seed=3)
    for b in range(W.shape[0]):
        for g in range(3):
            rows = np.flatnonzero(d.movement == g)
            # counts of each motion, recovered from the weights of its pairs:
            # W[a,b] * W[b,a] = (c_a c_b)^2, and sum_b W[a,b] = c_a (k_drawn - c_a)
            mots = np.unique(d.input[rows])
            M = {(d.input[r], d.target[r]): W[b, r] for r in rows}
            for x in mots:
                for y in mots:
                    if x != y:
                        assert M[(x, y)] == M[(y, x)]  # symmetric: c_x c_y both ways
            total = sum(M.values())
            assert total in {4 * 4 - s for s in range(0, 17)}  # sum_{x != y} c_x c_y
    assert W.dtype == np.int32 and W.shape == (50, run.n_pairs)


def test_the_movement_scheme_draws_movements_within_datasets():
    run = FakeRun({"authors_fbx": 3, "hdm05": 5}, takes=3)
    d = _design(run)
    W = bs.resample_weights(d, "movements", n=400, seed=1)
    for ds in (0, 1):
        cols = d.dataset == ds
        assert np.all(W[:, cols].sum(axis=1) > 0) or ds == 0  # a dataset never vanishes whole
    # one draw of 3 takes gives a movement's pairs sum_{x != y} c_x c_y <= 6 in all; more
    # shows a movement drawn twice or more, 0 one left out (or its takes drawn alike)
    per_mv = np.stack([W[:, d.movement == g].sum(axis=1) for g in range(8)], axis=1)
    assert per_mv.max() > 6 and np.any(per_mv == 0)
    motions_only = bs.resample_weights(d, "motions", n=400, seed=1)
    per_mv = np.stack([motions_only[:, d.movement == g].sum(axis=1) for g in range(8)], axis=1)
    assert per_mv.max() <= 6
    same = bs.resample_weights(d, "movements", n=400, seed=1)
    assert same.tobytes() == W.tobytes()  # deterministic
    assert bs.resample_weights(d, "movements", n=400, seed=2).tobytes() != W.tobytes()
    with pytest.raises(ValueError, match="scheme"):
        bs.resample_weights(d, "pairs")


def test_pairs_sharing_a_motion_move_together():
    """When the spread lies in the motions, a bootstrap of pairs as if independent would be
    far too sure; the cluster bootstrap is not, and resampling movements too widens it more."""
    run = FakeRun({"hdm05": 6}, takes=6, seed=4)
    v = run.scores(0.5, motion_sd=0.1, noise_sd=0.001)
    d = _design(run)
    rng = np.random.default_rng(0)
    naive = rng.multinomial(run.n_pairs, np.full(run.n_pairs, 1 / run.n_pairs), size=2000)
    width = {}
    for k, W in (("naive", naive.astype(np.int32)),
                 ("motions", bs.resample_weights(d, "motions", 2000)),
                 ("movements", bs.resample_weights(d, "movements", 2000))):  # fmt: skip
        lo, hi = bs.interval(bs.weighted_medians(v, W))
        assert lo < np.median(v) < hi
        width[k] = hi - lo
    assert width["motions"] > 2 * width["naive"]
    assert width["movements"] > width["motions"]


def test_interval_of_replicates_and_ratios():
    assert bs.interval([np.nan, np.nan]) != bs.interval([1.0, 1.0])
    assert np.isnan(bs.interval([np.nan])[0])
    assert bs.interval(np.arange(101.0)) == pytest.approx((2.5, 97.5))
    W = np.array([[1, 1], [2, 0], [0, 0]])
    r = bs.weighted_ratios([1.0, 0.0], [2.0, 2.0], W)
    assert r[0] == 0.25 and r[1] == 0.5 and np.isnan(r[2])


def test_seed_stability_measures_how_far_interval_ends_move():
    run = FakeRun({"hdm05": 4}, takes=5, seed=2)
    d = _design(run)
    vals = {"a": run.scores(0.4, motion_sd=0.05), "b": run.scores(0.2, motion_sd=0.01)}
    small = bs.seed_stability(vals, d, n=50)
    large = bs.seed_stability(vals, d, n=3000)
    assert small["n"] == 50 and large["worst"] in vals
    assert large["max_shift"] < small["max_shift"]
