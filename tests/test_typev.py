"""Forward Type V constraint: state table, legality checker, dtw-python cross-check."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from dtw import dtw, rabinerJuangStepPattern
from reference.synthetic import random_walk_features, synthetic_pair

from fpdtw.errors import AlignmentError
from fpdtw.online.base import run_online
from fpdtw.online.method_a import MethodA
from fpdtw.online.method_b import MethodB
from fpdtw.online.method_c import MethodC
from fpdtw.online.typev import (
    TYPE_V,
    TypeV,
    dtw_python_accepts,
    is_legal_typev,
    legal_prefix,
    lowest_cells,
    resolve_constraint,
    typev_violation,
)


def test_state_table_hand_checked():
    tv = TypeV()
    assert tv.states == ("N", "A1", "H1")
    assert tv.start == 0
    assert tv.table.shape == (3, 4) and tv.table.dtype == np.int64
    # rows N, A1, H1; columns advance 0..3; -1 = not allowed
    np.testing.assert_array_equal(tv.table, [[-1, 1, 0, 0], [2, 1, 0, 0], [0, 1, 0, 0]])
    assert tv.as_table() == [
        ["state", "0", "1", "2", "3"],
        ["N", "-", "A1", "N", "N"],
        ["A1", "H1", "A1", "N", "N"],
        ["H1", "N", "A1", "N", "N"],
    ]
    text = tv.describe()
    assert "A1" in text and "start state: N" in text and "H1: held once" in text
    with pytest.raises(ValueError):
        tv.table[0, 0] = 1  # read-only


def test_next_state_and_allowed():
    tv = TYPE_V
    np.testing.assert_array_equal(tv.allowed(0), [False, True, True, True])
    np.testing.assert_array_equal(tv.allowed(1), [True, True, True, True])
    assert tv.next_state(0, 1) == 1 and tv.next_state(1, 0) == 2 and tv.next_state(2, 0) == 0
    assert tv.next_state(0, 0) == -1
    assert tv.next_state(1, 4) == -1 and tv.next_state(1, -1) == -1
    # advance 1 is allowed in every state: a window of 2+ frames always has a candidate
    assert all(tv.allowed(s)[1] for s in range(3))


def test_warmup_is_consistent_with_the_table():
    state = TYPE_V.start
    for adv in (1, 1):  # M_1 = 1, M_2 = 2 (Methods B and C)
        state = TYPE_V.next_state(state, adv)
        assert state >= 0


LEGAL = [
    [0],
    [0, 1, 2, 3],
    [0, 1, 1, 1, 2],  # +1, two holds
    [0, 2, 5, 6, 6, 7, 7, 7, 10],
    [0, 1, 1, 2, 2, 3],  # +1 0 +1 0
    [0, 3, 4, 4],
    [1, 2],  # a path starting at M_0 = 1 (start="best"): only the advances count
    [7, 8, 8, 8, 11, 12],
]
ILLEGAL = [
    ([0, 1, 1, 1, 1], 4),  # three holds
    ([0, 2, 2], 2),  # hold after an advance of 2
    ([0, 1, 4, 4], 3),  # hold after an advance of 3
    ([0, 0], 1),  # hold at the start (state N)
    ([0, 4], 1),  # advance of 4
    ([5, 5], 1),  # hold at the start, from M_0 = 5
    ([3, 5, 5], 2),  # hold after an advance of 2, from M_0 = 3
    ([0, 2, 1], 2),  # backwards
]


@pytest.mark.parametrize("M", LEGAL)
def test_legal_maps(M):
    assert is_legal_typev(M)
    assert typev_violation(M) is None
    assert dtw_python_accepts(M)


@pytest.mark.parametrize("M,where", ILLEGAL)
def test_illegal_maps_are_rejected_by_both(M, where):
    assert not is_legal_typev(M)
    assert typev_violation(M) == where
    assert not dtw_python_accepts(M)


def test_legality_stops_at_the_end_of_the_input():
    M = [0, 1, 2, 3, 3, 3, 3, 3]  # reaches m = 3 at frame 3, then forced holds
    assert not is_legal_typev(M)
    assert legal_prefix(M, 3) == 4
    assert is_legal_typev(M, m=3)
    assert legal_prefix(M, None) == 8 and legal_prefix([0, 1], 5) == 2


def test_lowest_cells():
    # advances +1 0 +2 0(illegal but well defined) +3
    np.testing.assert_array_equal(lowest_cells([0, 1, 1, 3, 3, 6]), [0, 1, 1, 2, 3, 4])


def test_dtw_python_check_builds_the_path_it_claims():
    """The check's construction: 0 at each row's lowest cell, path highest cells = M.
    For [0, 2, 3] dtw-python's path goes (0,0) -> (1,1),(1,2) [the (1,2) step] -> (2,3)."""
    M = np.array([0, 2, 3])
    C = np.ones((3, 4))
    C[np.arange(3), lowest_cells(M)] = 0
    al = dtw(C, step_pattern=rabinerJuangStepPattern(5, "c"))
    assert al.distance == 0
    assert list(zip(al.index1.tolist(), al.index2.tolist())) == [(0, 0), (1, 1), (1, 2), (2, 3)]
    # and [0, 2, 2] (hold after +2) has a zero-cost path, but its highest cells are
    # [0, 1, 2], not M: rejected
    assert not dtw_python_accepts([0, 2, 2])


def test_checker_agrees_with_dtw_python_exhaustively():
    """Every map with up to 6 steps of advance 0..4: forward table == dtw-python."""
    n = 0
    for L in range(1, 7):
        for adv in itertools.product(range(5), repeat=L):
            M = np.concatenate([[0], np.cumsum(adv)])
            assert is_legal_typev(M) == dtw_python_accepts(M), M
            n += 1
    assert n == sum(5**L for L in range(1, 7))


def test_resolve_constraint():
    assert resolve_constraint(None) is None
    for c in ("typeV", "TypeV", "type V", TYPE_V):
        assert resolve_constraint(c) is TYPE_V
    for c in ("typeI", 5, True):
        with pytest.raises(AlignmentError):
            resolve_constraint(c)


def _aligners(I):
    yield MethodA(I, constraint="typeV")
    for w in (10, 20, 40, 80):
        yield MethodB(I, w, constraint="typeV")
        yield MethodC(I, w, constraint="typeV")


@pytest.mark.parametrize("seed", [0, 1])
def test_every_constrained_map_is_legal(seed):
    """Every method and window, on warped random walks and on unrelated random walks
    (whose target outlasts the input): legal up to the first frame mapped to m, checked
    by the table and by dtw-python; after that, holds at m."""
    I, T, _ = synthetic_pair(150, seed=seed, warp=0.6)
    cases = [(I, T), (random_walk_features(70, seed=seed + 10), random_walk_features(160))]
    n_bitten = 0
    for I, T in cases:
        for a in _aligners(I):
            M, _ = run_online(a, T)
            n = legal_prefix(M, a.m)
            assert is_legal_typev(M, a.m), a.name
            assert dtw_python_accepts(M[:n]), a.name
            assert np.all(M[n:] == a.m)
            free, _ = run_online(type(a)(I, a.w), T)
            n_bitten += not is_legal_typev(free, a.m)
    assert n_bitten >= 12  # the unconstrained maps do break Type V: the mask is exercised


def test_the_type_v_mask_changes_costs_not_only_the_choice():
    """Method C's rule (fpdtw.plain.method_c_step): C[r, 0] = +inf for the rows the state
    does not allow, before the reverse accumulation. A choice-only reading (accumulate the
    costs as they are, then take the best allowed row) picks another row here.

    State "N" allows rows 1..3. Unmasked, row 3 reaches the corner down column 0:
    (3,0) -> (4,0) -> (5,1) costs 5 + 0 + 0 = 5; row 2: 1 + 5 = 6; row 1: 0 + 6 = 6 ->
    row 3. Masked, (4,0) is closed: row 3 goes (3,0) -> (3,1) or (4,1), then down column
    1 through C[4,1] = 20: 25; row 2: 1 + 20 = 21; row 1: (1,0) -> (2,1) -> (3,1) ->
    (4,1) -> (5,1) = 0 + 0 + 0 + 20 + 0 = 20 -> row 1."""
    from fpdtw import plain

    C = np.array([[9, 9], [0, 9], [1, 0], [5, 0], [0, 20], [0, 0]], dtype=float)
    ok = plain.allowed_rows(plain.type_v_allowed("N"), len(C))
    np.testing.assert_array_equal(ok, [False, True, True, True, False, False])
    free = plain.reverse_accumulate(C)[:, 0]
    np.testing.assert_array_equal(free[1:4], [6, 6, 5])
    masked_C = C.copy()
    masked_C[~ok, 0] = np.inf
    masked = plain.reverse_accumulate(masked_C)[:, 0]
    np.testing.assert_array_equal(masked[1:4], [20, 21, 25])
    assert np.argmin(np.where(ok, free, np.inf)) == 3  # choice only
    assert np.argmin(np.where(ok, masked, np.inf)) == 1  # as implemented
