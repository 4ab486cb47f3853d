"""FP-DTW Methods A, B and C (Algorithms 1-3): hand-worked cases, invariants, real motions
(the plain versions, fpdtw.plain, against the same cases: tests/test_plain.py).

Hand-worked cases use one-joint motions rotating about X by 18 degrees per "unit": the
geodesic cost (eq. 1) between u and v units is ``(2/pi) arccos|cos(9 (u - v) deg)| =
|u - v| / 10`` (for |u - v| <= 10), so every C and D below is in tenths and was worked
out on paper (the arithmetic is in the comments).
"""

from __future__ import annotations

import math

import numba
import numpy as np
import pytest
from reference.synthetic import (
    features_from_euler,
    method_pairs,
    one_joint_motion,
    random_walk_features,
    synthetic_pair,
)

from fpdtw import plain
from fpdtw.costs import _acos01, geo_distance
from fpdtw.errors import AlignmentError
from fpdtw.io import load_motion
from fpdtw.metrics import hold_share
from fpdtw.motion.features import Frame, MotionFeatures
from fpdtw.motion.joints import OPW_JOINTS
from fpdtw.online.base import run_online, run_together
from fpdtw.online.method_a import MethodA
from fpdtw.online.method_b import MethodB
from fpdtw.online.method_c import MethodC
from fpdtw.online.typev import dtw_python_accepts, is_legal_typev, legal_prefix
from fpdtw.online.window import B_CORNER, WindowCache, run_group
from fpdtw.registry import C_READINGS, make_online, method_c_name

INF = math.inf


def units(u):
    """One-joint motion: frame f is a rotation about X by 18 * u[f] degrees."""
    return one_joint_motion(18.0 * np.asarray(u, dtype=float), "X")


def run_recording(aligner, T):
    """Run an aligner frame by frame; return the map and the snapshot of every step."""
    aligner.reset()
    M, snaps = [], []
    for frame in T.frames():
        M.append(aligner.step(frame))
        snaps.append(aligner.window_snapshot())
    return np.array(M), snaps


def tenths(rows):
    return np.array(rows, dtype=float) / 10.0


def test_unit_motions_cost_tenths():
    A = units([0, 1, 3, 10])
    assert geo_distance(A.quats[0], A.quats[1]) == pytest.approx(0.1, abs=1e-12)
    assert geo_distance(A.quats[1], A.quats[3]) == pytest.approx(0.9, abs=1e-12)
    assert geo_distance(A.quats[0], A.quats[3]) == pytest.approx(1.0, abs=1e-12)


# --- Method A ---------------------------------------------------------------------------


def test_method_a_hand_worked():
    I = units([0, 1, 2, 3, 4, 5])  # m = 5
    T = units([0, 2, 2, 5, 6, 6])
    M, snaps = run_recording(MethodA(I, record=True), T)
    # q=1: rows I0..I2 vs T=2: [.2, .1, 0] -> +2; q=2: I2..I4 vs 2: [0, .1, .2] -> +0;
    # q=3: I2..I4 vs 5: [.3, .2, .1] -> +2; q=4: w_i = min(2, 5-4) = 1, I4..I5 vs 6:
    # [.2, .1] -> +1; q=5: M_n = m, w_i = 0 -> hold.
    np.testing.assert_array_equal(M, [0, 2, 2, 4, 5, 5])
    assert [s.kind for s in snaps] == ["first", "window", "window", "window", "window", "end"]
    np.testing.assert_allclose(snaps[1].C, tenths([[2], [1], [0]]), atol=1e-9)
    np.testing.assert_allclose(snaps[3].C, tenths([[3], [2], [1]]), atol=1e-9)
    s4 = snaps[4]
    assert (s4.start, s4.w_i, s4.offset, s4.M) == (4, 1, 1, 5)
    np.testing.assert_allclose(s4.C, tenths([[2], [1]]), atol=1e-9)
    assert (snaps[5].w_i, snaps[5].offset) == (0, 0)


def test_method_a_ties_take_lowest_offset():
    # I1 and I2 are the same pose: at q=1 rows 1 and 2 tie exactly (cost 0) -> offset 1.
    I = units([0, 1, 1, 2])
    T = units([0, 1, 3, 3])
    M, snaps = run_recording(MethodA(I, record=True), T)
    np.testing.assert_array_equal(M, [0, 1, 3, 3])
    assert snaps[1].C[1, 0] == snaps[1].C[2, 0]
    assert snaps[1].offset == 1


def test_method_a_typev_hand_worked():
    I = units(range(10))
    T = units([0] * 10)
    M_free, _ = run_online(MethodA(I), T)
    np.testing.assert_array_equal(M_free, [0] * 10)
    M, snaps = run_recording(MethodA(I, constraint="typeV", record=True), T)
    # N: no hold -> +1 (A1); hold (H1); hold (N); +1; ... every row costs more than row 0
    np.testing.assert_array_equal(M, [0, 1, 1, 1, 2, 2, 2, 3, 3, 3])
    assert [s.state for s in snaps[1:5]] == ["N", "A1", "H1", "N"]
    np.testing.assert_array_equal(snaps[1].allowed, [False, True, True, True])
    assert is_legal_typev(M)


# --- Method B ---------------------------------------------------------------------------

B_I = [0, 2, 3, 4, 4, 5, 5, 6]  # m = 7
B_T = [0, 1, 2, 4, 5, 7, 7]


def check_b_step(s, C, D, path, P, offset_M):
    """A recorded Method B step against hand-worked C and D (in tenths of a unit, D
    before its corner is set to 10000), back-tracked path, P (None: not checked) and
    (offset, M_{n+1})."""
    np.testing.assert_allclose(s.C, tenths(C), atol=1e-9)
    D = tenths(D)
    D[0, 0] = B_CORNER
    np.testing.assert_allclose(s.D, D, atol=1e-9)
    np.testing.assert_array_equal(s.path, path)
    if P is not None:
        np.testing.assert_array_equal(s.P, P)
    assert (s.offset, s.M) == offset_M


def test_method_b_hand_worked():
    M, snaps = run_recording(MethodB(units(B_I), 3, record=True), units(B_T))
    np.testing.assert_array_equal(M, [0, 1, 2, 2, 5, 7, 7])
    assert [s.kind for s in snaps] == [
        "first", "warmup", "warmup", "window", "window", "window", "end"
    ]  # fmt: skip

    # q=3: M_2 = 2, w_i = 3, rows I2..I5 = [3, 4, 4, 5] units; F = [T2, T3, T3+d, T3+2d]
    # = [2, 4, 6, 8] (d = 2).
    s = snaps[3]
    assert (s.start, s.w_i) == (2, 3)
    C = [[1, 1, 3, 5], [2, 0, 2, 4], [2, 0, 2, 4], [3, 1, 1, 3]]
    # D row 0: 1, 2, 5, 10; row 1: 3, 0+min(1,2,3)=1, 2+min(2,5,1)=3, 4+min(5,10,3)=7;
    # row 2: 5, 0+min(3,1,5)=1, 2+min(1,3,1)=3, 4+min(3,7,3)=7; row 3: 8, 1+min(5,1,8)=2,
    # 1+min(1,3,2)=2, 3+min(3,7,2)=5; then D[0,0] = 10000.
    D = [[1, 2, 5, 10], [3, 1, 3, 7], [5, 1, 3, 7], [8, 2, 2, 5]]
    # back-track: (3,3) -> (3,2) [2 < 3 diag, 7 input] -> (2,1) [diag 1] -> (1,1) [input
    # 1 < diag 3, target 5: overwrite col 1] -> (0,1) [input 2 < target 3 < 10000:
    # overwrite again] -> (0,0)
    path = [[0, 0], [0, 1], [1, 1], [2, 1], [3, 2], [3, 3]]
    check_b_step(s, C, D, path, P=[0, 0, 3, 3], offset_M=(0, 2))  # P_1 = 0: hold
    # without the overwrite rule column 1 would keep row 2 (M = 4); without D[0,0] =
    # 10000, (1,1) would step diagonally to (0,0) (D[0,0] = 0.1 < 0.2) and P_1 = 1.

    # q=4: F = [4, 5, 6, 7] (d = 1); the path enters column 1 at row 3 from (2,0).
    C = [[1, 2, 3, 4], [0, 1, 2, 3], [0, 1, 2, 3], [1, 0, 1, 2]]
    D = [[1, 3, 6, 10], [1, 2, 4, 7], [1, 2, 4, 7], [2, 1, 2, 4]]
    path = [[0, 0], [1, 0], [2, 0], [3, 1], [3, 2], [3, 3]]
    check_b_step(snaps[4], C, D, path, P=[0, 3, 3, 3], offset_M=(3, 5))

    # q=5: the window shrinks, w_i = min(3, 7 - 5) = 2; rows [5, 5, 6]; F = [5, 7, 9, 11].
    s = snaps[5]
    assert (s.start, s.w_i) == (5, 2)
    C = [[0, 2, 4, 6], [0, 2, 4, 6], [1, 1, 3, 5]]
    D = [[0, 2, 6, 12], [0, 2, 6, 12], [1, 1, 4, 9]]
    check_b_step(s, C, D, [[0, 0], [1, 0], [2, 1], [2, 2], [2, 3]], P=None, offset_M=(2, 7))
    # q=6: M_n = m -> M = m without a window
    assert (snaps[6].kind, snaps[6].M) == ("end", 7)


def test_method_b_typev_hand_worked():
    I = units([0, 3, 4, 5, 8, 8, 10, 11])
    T = units([0, 1, 2, 2, 2, 2])
    M_free, _ = run_online(MethodB(I, 3), T)
    np.testing.assert_array_equal(M_free, [0, 1, 2, 2, 2, 2])  # three holds
    M, snaps = run_recording(MethodB(I, 3, constraint="typeV", record=True), T)
    np.testing.assert_array_equal(M, [0, 1, 2, 2, 2, 3])
    assert [s.state for s in snaps[3:]] == ["A1", "H1", "N"]
    # q=5, state N: no hold, C[0, 1] = inf; rows [4, 5, 8, 8] vs F = [2, 2, 2, 2].
    s = snaps[5]
    C = tenths([[2, 2, 2, 2], [3, 3, 3, 3], [6, 6, 6, 6], [6, 6, 6, 6]])
    C[0, 1] = INF
    np.testing.assert_allclose(s.C, C, atol=1e-9)
    # D row 0: 2, inf, inf, inf; row 1: 5, 3+2=5, 3+5=8, 3+8=11; row 2: 11, 11, 11,
    # 6+8=14; row 3: 17, 17, 17, 6+11=17. Back-track (3,3)->(2,2)->(1,1)->(1,0)->(0,0).
    D = tenths([[2, INF, INF, INF], [5, 5, 8, 11], [11, 11, 11, 14], [17, 17, 17, 17]])
    D[0, 0] = B_CORNER
    np.testing.assert_allclose(s.D, D, atol=1e-9)
    np.testing.assert_array_equal(s.P, [0, 1, 2, 3])
    assert (s.offset, s.M) == (1, 3)


# --- Method C ---------------------------------------------------------------------------


def test_method_c_literal_window_hand_worked():
    I = units([0, 0, 2, 2, 3, 4, 6, 7])  # m = 7
    T = units([0, 1, 2, 3, 5, 7, 9])
    M, snaps = run_recording(MethodC(I, 3, window="literal", record=True), T)
    np.testing.assert_array_equal(M, [0, 1, 2, 4, 6, 7, 7])
    assert [s.kind for s in snaps] == [
        "first", "warmup", "warmup", "window", "window", "window", "end"
    ]  # fmt: skip
    # q=3: rows I2..I5 = [2, 2, 3, 4]; F = [T3, T3+d, T3+2d] = [3, 4, 5] (d = 1).
    s = snaps[3]
    np.testing.assert_allclose(s.C, tenths([[1, 2, 3], [1, 2, 3], [0, 1, 2], [1, 0, 1]]), atol=1e-9)
    # reverse: row 3: 1+1=2, 0+1=1, 1; row 2: 0+min(1,2,2)=1, 1+min(1,1,3)=2, 2+1=3;
    # row 1: 1+min(2,1,4)=2, 2+min(3,2,6)=4, 3+3=6; row 0: 1+min(4,2,6)=3, 2+min(6,4,9)=6, 9
    np.testing.assert_allclose(s.D, tenths([[3, 6, 9], [2, 4, 6], [1, 2, 3], [2, 1, 1]]), atol=1e-9)
    assert (s.offset, s.M) == (2, 4)
    # q=4: rows [3, 4, 6, 7]; F = [5, 7, 9] (d = 2). C's column 0 alone would pick row 1
    # (first of two 0.1s); the accumulated D picks row 2.
    s = snaps[4]
    np.testing.assert_allclose(s.C, tenths([[2, 4, 6], [1, 3, 5], [1, 1, 3], [2, 0, 2]]), atol=1e-9)
    np.testing.assert_allclose(
        s.D, tenths([[6, 10, 16], [4, 6, 10], [3, 3, 5], [4, 2, 2]]), atol=1e-9
    )
    assert (s.offset, s.M) == (2, 6)
    # q=5: the window shrinks to w_i = 1: rows [6, 7]; F = [7, 9, 11].
    s = snaps[5]
    assert (s.start, s.w_i) == (6, 1)
    np.testing.assert_allclose(s.C, tenths([[1, 3, 5], [0, 2, 4]]), atol=1e-9)
    np.testing.assert_allclose(s.D, tenths([[7, 7, 9], [6, 6, 4]]), atol=1e-9)
    assert (s.offset, s.M) == (1, 7)
    assert (snaps[6].kind, snaps[6].M) == ("end", 7)


def test_method_c_ties_take_lowest_row():
    # literal window, w = 2, T constant (delta = 0): F = [T_{n+1}, T_{n+1}] (units 0). At
    # q = 3 (M_n = 2) the rows I_2..I_4 are units [0, 1, 2]: C = [[0, 0], [c1, c1],
    # [c2, c2]] (c1 = .1, c2 = .2). Reverse accumulation: D[1, 1] = c1 + c2, D[1, 0] =
    # c1 + min(c2, 2 c2, c1 + c2) = c1 + c2, D[0, 1] = D[1, 1], D[0, 0] = 0 + min(D[1, 1],
    # D[1, 0], D[0, 1]) = c1 + c2: rows 0 and 1 tie exactly (the same sum), row 2 = 2 c2.
    I = units([0, 0, 0, 1, 2])
    T = units([0, 0, 0, 0])
    M, snaps = run_recording(MethodC(I, 2, window="literal", record=True), T)
    D = snaps[3].D
    assert D[0, 0] == D[1, 0] and D[2, 0] > D[1, 0]
    np.testing.assert_allclose(D[:, 0], [0.3, 0.3, 0.4], atol=1e-12)
    np.testing.assert_array_equal(M, [0, 1, 2, 2])
    M, snaps = run_recording(MethodC(I, 2, window="literal", ties="high", record=True), T)
    np.testing.assert_array_equal(M, [0, 1, 2, 3])


def test_method_c_refuses_w_below_2():
    """w = 1 would freeze the square window on one row (the map stuck at M_2)."""
    I = units([0, 1, 2, 3])
    for window in ("square", "literal"):
        with pytest.raises(AlignmentError, match=r"MethodC: window w must be an int >= 2"):
            MethodC(I, 1, window=window)
    assert MethodC(I, 2).w == 2


def test_method_c_typev_hand_worked():
    I = units([0, 3, 4, 4, 5, 6, 9, 11])
    T = units([0, 1, 2, 6, 6, 6, 6])
    M_free, _ = run_online(MethodC(I, 3, window="literal"), T)
    np.testing.assert_array_equal(M_free, [0, 1, 2, 5, 5, 5, 5])  # hold after +3
    M, snaps = run_recording(MethodC(I, 3, window="literal", constraint="typeV", record=True), T)
    np.testing.assert_array_equal(M, [0, 1, 2, 5, 6, 6, 6])
    # q=3 (A1): rows [4, 4, 5, 6] vs F = [6, 10, 14]; D[:, 0] = [1.7, 1.5, 1.3, 1.2] -> +3.
    s = snaps[3]
    np.testing.assert_allclose(
        s.C, tenths([[2, 6, 10], [2, 6, 10], [1, 5, 9], [0, 4, 8]]), atol=1e-9
    )
    np.testing.assert_allclose(
        s.D, tenths([[17, 25, 37], [15, 19, 27], [13, 13, 17], [12, 12, 8]]), atol=1e-9
    )
    # q=4 (N, no hold): rows [6, 9, 11] vs F = [6, 6, 6]; C[0, 0] = inf; D[:, 0] =
    # [inf, 1.1, 1.5] -> +1 (unconstrained: D[0, 0] = 0 + min(.8, 1.1, .8) = .8 -> hold).
    s = snaps[4]
    assert s.state == "N"
    np.testing.assert_allclose(s.C, tenths([[INF, 0, 0], [3, 3, 3], [5, 5, 5]]), atol=1e-9)
    np.testing.assert_allclose(s.D, tenths([[INF, 8, 8], [11, 8, 8], [15, 10, 5]]), atol=1e-9)
    assert (s.offset, s.M) == (1, 6)
    assert [s.state for s in snaps[5:]] == ["A1", "H1"]


def test_method_c_square_window_hand_worked():
    # The default, Algorithm 3's declared w_i x w window. I = 0..9 units (m = 9), w = 3.
    I = units(range(10))
    T = units([0, 1, 2, 2, 2, 3, 4, 6])  # the target pauses at 2, then speeds up
    M, snaps = run_recording(MethodC(I, 3, record=True), T)
    # q=3: M_n = 2, w_i = min(3 - 1, 9 - 2) = 2: 3 rows I2..I4 = [2, 3, 4]; d = 0, F = [2, 2, 2].
    s = snaps[3]
    assert (s.start, s.w_i) == (2, 2)
    np.testing.assert_allclose(s.C, tenths([[0, 0, 0], [1, 1, 1], [2, 2, 2]]), atol=1e-9)
    # reverse: row 2: 2+2+2=6, 2+2=4, 2; row 1: 1+min(4,6,3)=4, 1+min(2,4,3)=3, 1+2=3;
    # row 0: 0+min(3,4,3)=3, 0+min(3,3,3)=3, 0+3=3. D[:, 0] = [.3, .4, .6]: hold.
    np.testing.assert_allclose(s.D, tenths([[3, 3, 3], [4, 3, 3], [6, 4, 2]]), atol=1e-9)
    assert (s.offset, s.M) == (0, 2)
    np.testing.assert_allclose(s.score, s.D[:, 0])
    # q=4: the same window: hold again. q=5: T = 3, d = 1, F = [3, 4, 5]; rows [2, 3, 4]:
    # C = [[1,2,3],[0,1,2],[1,0,1]]; row 2: 2, 1, 1; row 1: 0+min(1,2,2)=1, 1+min(1,1,3)=2,
    # 2+1=3; row 0: 1+min(2,1,4)=2, 2+min(3,2,6)=4, 3+3=6 -> D[:, 0] = [.2, .1, .2]: +1.
    np.testing.assert_allclose(snaps[5].D, tenths([[2, 4, 6], [1, 2, 3], [2, 1, 1]]), atol=1e-9)
    # q=7: M_n = 4, T = 6, d = 2, F = [6, 8, 10]; rows [4, 5, 6]: C = [[2,4,6],[1,3,5],
    # [0,2,4]]; row 2: 6, 6, 4; row 1: 1+min(6,6,7)=7, 3+min(4,6,9)=7, 5+4=9; row 0:
    # 2+min(7,7,11)=9, 4+min(9,7,15)=11, 6+9=15 -> D[:, 0] = [.9, .7, .6]: +2.
    np.testing.assert_allclose(snaps[7].D, tenths([[9, 11, 15], [7, 7, 9], [6, 6, 4]]), atol=1e-9)
    np.testing.assert_array_equal(M, [0, 1, 2, 2, 2, 3, 4, 6])  # = T: exact


def test_method_c_square_window_reaches_the_end_of_the_input():
    # m = 3, w = 3. q=3: M_n = 2, w_i = min(3 - 1, 3 - 2) = 1: 2 rows I2..I3 = [2, 3] (the
    # last row is I_m: read as written, m - M_n = 1 row, the map would stop at
    # m - 1); F = [3, 4, 5]: C = [[1,2,3],[0,1,2]]; row 1: 3, 3, 2; row 0: 1+min(3,3,4)=4,
    # 2+min(2,3,5)=4, 3+2=5 -> D[:, 0] = [.4, .3]: +1 = m. Then the input is exhausted.
    I = units([0, 1, 2, 3])
    T = units([0, 1, 2, 3, 4, 5])
    M, snaps = run_recording(MethodC(I, 3, record=True), T)
    s = snaps[3]
    assert (s.start, s.w_i, s.C.shape) == (2, 1, (2, 3))
    np.testing.assert_allclose(s.D, tenths([[4, 4, 5], [3, 3, 2]]), atol=1e-9)
    np.testing.assert_array_equal(M, [0, 1, 2, 3, 3, 3])
    assert [x.kind for x in snaps[4:]] == ["end", "end"]


@pytest.mark.parametrize("w", [3, 10, 40])
def test_method_c_hold_pays_one_extra_cell_only_in_the_literal_window(w):
    """The mechanism of notebook 15 on a window of equal costs c: every cell costs the
    same, so D[r, 0] = c x (cells on the shortest path from (r, 0) to the far corner).
    Literal (w + 1 rows, w columns): row 0 needs w + 1 cells, every other row w: the hold
    loses to an advance. Square (w x w): every row needs w cells, an exact tie, and the
    tie rule keeps the hold. Open end: w cells from every row."""
    I = one_joint_motion(np.full(w + 5, 30.0), "X")  # one pose
    T = one_joint_motion(np.full(6, 50.0), "X")  # another pose: c = (2/pi) 10 deg
    c = geo_distance(I.quats[0], T.quats[0])
    for window, cells0, cells1, off in [
        ("literal", w + 1, w, 1),
        ("square", w, w, 0),
        ("open-end", w, w, 0),
        ("square-tn", w + 1, w + 1, 0),
    ]:
        M, snaps = run_recording(MethodC(I, w, window=window, record=True), T)
        s = snaps[3]
        assert s.D[0, 0] == pytest.approx(cells0 * c, rel=1e-12), window
        assert s.D[1, 0] == pytest.approx(cells1 * c, rel=1e-12), window
        assert s.offset == off, window
    # normalised: D / ((rows - r) + cols) with paths of total weight (rows - r) + cols - 1
    s = run_recording(MethodC(I, w, window="normalised", record=True), T)[1][3]
    r = np.arange(w + 1)
    np.testing.assert_allclose(s.score, c * ((w + 1 - r) + w - 1) / ((w + 1 - r) + w))
    assert s.offset == w  # the shortest remaining path has the smallest share of c


def test_method_c_readings_cross_check_dtw_python():
    """Every row's accumulated cost is an ordinary DTW distance of the sub-window from
    that row to the far corner, with both axes reversed: dtw-python, symmetric1 (pinned
    corner), symmetric2 normalised (normalised reading)."""
    dtw_mod = pytest.importorskip("dtw")
    I, T, _ = synthetic_pair(160, seed=21)
    for window, pattern in [("literal", "symmetric1"), ("square", "symmetric1"),
                            ("square-tn", "symmetric1"), ("normalised", "symmetric2")]:  # fmt: skip
        a = MethodC(I, 12, window=window, record=True)
        a.reset()
        checked = 0
        for q, frame in enumerate(T.frames()):
            a.step(frame)
            s = a.window_snapshot()
            if s.kind != "window" or q % 9:
                continue
            for r in range(s.C.shape[0]):
                sub = s.C[r:, :][::-1, ::-1]
                al = dtw_mod.dtw(sub, step_pattern=pattern, distance_only=True)
                want = al.normalizedDistance if window == "normalised" else al.distance
                assert s.score[r] == pytest.approx(want, rel=1e-9, abs=1e-12), (window, q, r)
            checked += 1
        assert checked >= 5


def test_method_c_options_forecast_and_start():
    # forecast="hold": every forecast column is T_{n+1}; forecast_start="next": column 0
    # is the first prediction T_{n+1} + d, not T_{n+1}.
    I = units(range(10))
    T = units([0, 1, 2, 3, 4])
    s = run_recording(MethodC(I, 3, forecast="hold", record=True), T)[1][3]
    np.testing.assert_allclose(s.C, tenths([[1, 1, 1], [0, 0, 0], [1, 1, 1]]), atol=1e-9)
    s = run_recording(MethodC(I, 3, forecast_start="next", record=True), T)[1][3]
    np.testing.assert_allclose(s.C, tenths([[2, 3, 4], [1, 2, 3], [0, 1, 2]]), atol=1e-9)
    # start="best": T_0 = 2 units is matched by I_2 in I_0..I_w; warm-up advances from it
    M, _ = run_online(MethodC(I, 3, start="best"), units([2, 3, 4, 5, 6]))
    np.testing.assert_array_equal(M, [2, 3, 4, 5, 6])
    assert MethodC(I, 3, start="best", ties="high").name == "Mc w3 (ties high, M_0 best match)"
    with pytest.raises(AlignmentError, match="window='wide'"):
        MethodC(I, 3, window="wide")
    with pytest.raises(AlignmentError, match="unknown option"):
        MethodB(I, 3, window="literal")


# --- boundary cases ----------------------------------------------------------------------


@pytest.mark.parametrize("cls", [MethodB, MethodC])
def test_warmup_is_clipped_to_a_short_input(cls):
    I = units([0, 1])  # m = 1
    T = units([0, 1, 2, 3, 4])
    for c in (None, "typeV"):
        M, _ = run_online(cls(I, 10, constraint=c), T)
        np.testing.assert_array_equal(M, [0, 1, 1, 1, 1])


@pytest.mark.parametrize("make", [lambda I: MethodA(I), lambda I: MethodB(I, 4),
                                  lambda I: MethodC(I, 4, constraint="typeV")])  # fmt: skip
def test_one_frame_input_maps_everything_to_frame_0(make):
    M, _ = run_online(make(units([3])), units([0, 1, 2, 3]))
    np.testing.assert_array_equal(M, [0, 0, 0, 0])


def test_names():
    I = units(range(5))
    assert MethodC(I, 40, window="literal").name == "Mc w40 (literal window)"
    assert MethodB(I, 10, forecast="hold", backtrack="input-first").name == (
        "Mb w10 (hold forecast, back-track input first)"
    )
    assert MethodA(I).name == "Ma"
    assert MethodA(I, constraint="typeV").name == "Ma + Type V"
    assert MethodA(I, 3).name == "Ma w3"
    assert MethodB(I, 40).name == "Mb w40"
    assert MethodC(I, 40, constraint="Type V").name == "Mc w40 + Type V"


def test_bad_arguments():
    I = units(range(5))
    for w in (0, -1, 1.5, "40", True):
        with pytest.raises(AlignmentError, match="window w"):
            MethodB(I, w)
    with pytest.raises(AlignmentError, match="constraint"):
        MethodC(I, 10, constraint="typeI")
    with pytest.raises(AlignmentError, match="MotionFeatures"):
        MethodA(I.quats)
    a = MethodC(I, 10)
    with pytest.raises(AlignmentError, match="target frame 0"):
        a.step(Frame(np.ones((1, 4)) / 2.0, np.zeros((2, 3))))
    with pytest.raises(AlignmentError, match="expected quats"):
        a.step(Frame(np.array([1.0, 0.0, 0.0, 0.0]), np.zeros(3)))  # would broadcast
    bad = MotionFeatures(I.quats, I.euler, ("QQQ",), 120.0)
    with pytest.raises(AlignmentError, match="rotation order"):
        MethodB(bad, 10)
    bad = MotionFeatures(I.quats, I.euler[:-1], ("XYZ",), 120.0)
    with pytest.raises(AlignmentError, match="inconsistent features"):
        MethodA(bad)
    with pytest.raises(AlignmentError, match="no frames"):
        MethodC(I.slice(0, 0), 10)


def test_record_is_off_by_default_and_reset_clears_state():
    I, T, _ = synthetic_pair(80, seed=4)
    a = MethodC(I, 10, constraint="typeV")
    M1, _ = run_online(a, T)
    assert a.window_snapshot() is None
    M2, _ = run_online(a, T)  # run_online resets: the Type V state starts again
    np.testing.assert_array_equal(M1, M2)


# --- invariants and online-ness --------------------------------------------------------

ALL = [("A", 2)] + [(m, w) for m in ("B", "C") for w in (10, 20, 40, 80)]


def make(method, I, w, typev, record=False):
    c = "typeV" if typev else None
    if method == "A":
        return MethodA(I, constraint=c, record=record)
    return {"B": MethodB, "C": MethodC}[method](I, w, constraint=c, record=record)


@pytest.fixture(scope="module")
def pairs():
    return method_pairs()


@pytest.mark.parametrize("typev", [False, True])
@pytest.mark.parametrize("method,w", ALL)
def test_maps_are_monotonic_and_in_range(pairs, method, w, typev):
    for I, T in pairs:
        a = make(method, I, w, typev)
        M, _ = run_online(a, T)
        m = I.n_frames - 1
        assert M.shape == (T.n_frames,) and M.dtype == np.int64
        assert M[0] == 0
        adv = np.diff(M)
        assert adv.min() >= 0 and M.max() <= m
        assert adv.max() <= (3 if typev else w)
        if method != "A":
            np.testing.assert_array_equal(M[:3], [0, 1, 2])  # warm-up
        if I.n_frames < T.n_frames // 2:
            assert M[-1] == m  # the long target exhausts the input, then holds at m


@pytest.mark.parametrize("typev", [False, True])
@pytest.mark.parametrize("method,w", ALL)
def test_online_prefix_does_not_depend_on_future_frames(pairs, method, w, typev):
    I, T = pairs[0]
    M, _ = run_online(make(method, I, w, typev), T)
    rng = np.random.default_rng(5)
    for q in (0, 2, 3, 17, 90):
        for garbage in ("random", "nan"):
            if garbage == "nan":
                Q = np.full_like(T.quats, np.nan)
                E = np.full_like(T.euler, np.nan)
            else:
                Q = rng.normal(size=T.quats.shape)
                Q /= np.linalg.norm(Q, axis=-1, keepdims=True)
                E = rng.uniform(-500, 500, size=T.euler.shape)
            Q[: q + 1] = T.quats[: q + 1]
            E[: q + 1] = T.euler[: q + 1]
            T2 = MotionFeatures(Q, E, T.orders, T.fps)
            a = make(method, I, w, typev)
            if garbage == "nan":  # every method refuses the first NaN frame alike
                M2 = np.array([a.step(T2.frame(i)) for i in range(q + 1)])
                with pytest.raises(AlignmentError, match=f"target frame {q + 1}: joint 0 is not"):
                    a.step(T2.frame(q + 1))
            else:
                M2, _ = run_online(a, T2)
            np.testing.assert_array_equal(M2[: q + 1], M[: q + 1])
            assert M2.min() >= 0 and M2.max() <= I.n_frames - 1


@pytest.mark.parametrize("typev", [False, True])
@pytest.mark.parametrize("method,w", ALL)
def test_input_aligned_to_itself_is_the_identity(method, w, typev):
    """A: row 1 of each window costs 0. B: the path runs down the zero diagonal and, at
    (1,1), (0,1) and (1,0) tie exactly (C is symmetric there), so the target step wins
    and P_1 = 1. C: D[1,0] follows the zero diagonal. Type V allows all advances of 1.
    Checked on a linear-in-Euler motion (exact forecasts) and a random walk."""
    rng = np.random.default_rng(3)
    t = np.arange(120)[:, None, None]
    lin = features_from_euler(
        rng.uniform(-60, 60, (1, 8, 3)) + t * rng.uniform(-1.5, 1.5, (1, 8, 3))
    )
    for X in (lin, random_walk_features(120, seed=5)):
        M, _ = run_online(make(method, X, w, typev), X)
        np.testing.assert_array_equal(M, np.arange(X.n_frames))


@numba.njit
def fast_acos(x):
    """The kernels' arccos on [0, 1] (``fpdtw.costs._acos01``) of every value of ``x`` (1-D)."""
    out = np.empty_like(x)
    for i in range(x.shape[0]):
        out[i] = _acos01(x[i])
    return out


def test_fast_acos_matches_libm():
    x = np.concatenate(
        [
            np.linspace(0.0, 1.0, 200001),
            1.0 - np.logspace(-17, -1, 2000),
            [0.5, np.nextafter(0.5, 1)],
        ]
    )
    x = np.clip(x, 0.0, 1.0)
    ref = np.array([math.acos(v) for v in x])
    got = fast_acos(x)
    assert np.max(np.abs(got - ref)) <= 1e-15
    assert fast_acos(np.array([1.0]))[0] == 0.0


# --- real motions --------------------------------------------------------------------------

SQUAT = "hdm05/HDM05_cut_amc/squat1Reps/HDM_bd_squat1Reps_{:03d}_120.amc"


@pytest.fixture(scope="module")
def squat_pair(data_path):
    I = MotionFeatures.from_motion(load_motion(data_path(SQUAT.format(1))))
    T = MotionFeatures.from_motion(load_motion(data_path(SQUAT.format(2))))
    return I, T


@pytest.mark.parametrize("method,w", [("A", 2), ("B", 20), ("B", 40), ("C", 20), ("C", 40)])
def test_real_squat_pair(squat_pair, method, w):
    I, T = squat_pair
    assert (I.n_frames, T.n_frames) == (140, 148)
    for typev in (False, True):
        a = make(method, I, w, typev)
        M, _ = run_online(a, T)
        step = {"A": plain.method_a_step, "B": plain.method_b_step, "C": plain.method_c_step}
        np.testing.assert_array_equal(M, plain.run(step[method], I, T, w, typev))
        assert M[0] == 0 and np.diff(M).min() >= 0 and M.max() <= a.m
        if typev:
            assert is_legal_typev(M, a.m)
            assert dtw_python_accepts(M[: legal_prefix(M, a.m)])


WALK = "mocap_single_person_actions/MoCapData/Walk_01.fbx"
#: Every FP-DTW configuration with w <= 40: the paper restricts the window to less than
#: half the movement's cycle (Section 7), and a walk step lasts about 60 frames here.
BEHAVIOUR = [(m, w) for m, w in ALL if w <= 40]


@pytest.fixture(scope="module")
def walk(data_path):
    X = MotionFeatures.from_motion(load_motion(data_path(WALK)))
    slow = np.repeat(np.arange(X.n_frames), 2)  # the take slowed down 2x: frames repeated
    return X, MotionFeatures(X.quats[slow], X.euler[slow], X.orders, X.fps, None, "slow"), slow


@pytest.mark.parametrize("typev", [False, True])
@pytest.mark.parametrize("method,w", BEHAVIOUR)
def test_real_take_aligns_to_itself_and_to_itself_slowed(walk, method, w, typev):
    """What any aligner should do: a take against itself is (nearly) the identity, and
    against itself slowed down 2x it holds on about half the frames. Tolerances: at most
    the paper's 18-frame benchmark anywhere, at most one frame on average (Method C's
    forecast can lead it a few frames off the diagonal and back)."""
    X, S, truth = walk
    m = X.n_frames - 1
    M, _ = run_online(make(method, X, w, typev), X)
    d = np.abs(M - np.arange(X.n_frames))
    assert d.max() <= 18 and d.mean() <= 1.0
    M, _ = run_online(make(method, X, w, typev), S)
    d = np.abs(M - truth)
    assert d.max() <= 18 and d.mean() <= 1.0
    assert 0.45 <= hold_share(M, m) <= 0.55


@pytest.mark.parametrize("w", [10, 20, 40])
def test_literal_window_runs_ahead_on_a_real_take(walk, w):
    """The literal (w_i + 1) x w window fails both behaviour checks on the same take: the
    hold's extra cell makes it skip ahead and run out of input (notebook 15)."""
    X, S, truth = walk
    m = X.n_frames - 1
    M, _ = run_online(MethodC(X, w, window="literal"), X)
    assert np.abs(M - np.arange(X.n_frames)).max() > 100
    M, _ = run_online(MethodC(X, w, window="literal"), S)
    assert hold_share(M, m) < 0.25
    assert np.abs(M - truth).mean() > 100


SHARED_NAMES = (
    [f"Mb w{w}{t}" for w in (10, 40, 80) for t in ("", " + Type V")]
    + [method_c_name(w, r, t) for r in C_READINGS for w in (10, 40, 80) for t in (False, True)]
    + ["Mb w40 (hold forecast)", "Mc w40 (forecast from T_n+2)", "Mc w20 (ties high)"]
    + ["Mb w40 (band w/2)", "Mc w40 (band w/2)", "Mc w80 (band w/2)", "Mc w40 (band 1 s)"]
)


def _with_cache(name, I, cache):
    return make_online(name, I, cache=cache)


def test_shared_window_cache_gives_the_same_maps(squat_pair, walk):
    """B and C aligners sharing a WindowCache in lockstep map exactly as they do alone,
    streamed frame by frame (run_together) or in one compiled loop (run_group)."""
    X, _, _ = walk
    for I, T in (squat_pair, (X.slice(0, 300), X.slice(20, 330))):
        alone = [run_online(make_online(name, I), T)[0] for name in SHARED_NAMES]
        cache = WindowCache(I, 80)
        shared = run_together([_with_cache(n, I, cache) for n in SHARED_NAMES], T)
        grouped = run_group([_with_cache(n, I, WindowCache(I, 80)) for n in SHARED_NAMES][:0], T)
        assert grouped == []
        cache = WindowCache(I, 80)
        grouped = run_group([_with_cache(n, I, cache) for n in SHARED_NAMES], T)
        separate = run_group([make_online(n, I) for n in SHARED_NAMES], T)
        for name, M0, M1, M2, M3 in zip(SHARED_NAMES, alone, shared, grouped, separate):
            for M in (M1, M2, M3):
                np.testing.assert_array_equal(M, M0, err_msg=name)


def test_run_group_refuses_what_it_cannot_run(squat_pair):
    I, T = squat_pair
    with pytest.raises(AlignmentError, match="one input and one cache"):
        run_group([MethodC(I, 10), MethodA(I)], T)
    with pytest.raises(AlignmentError, match="one input and one cache"):
        run_group(
            [MethodC(I, 10, cache=WindowCache(I, 10)), MethodB(I, 10, cache=WindowCache(I, 10))], T
        )
    with pytest.raises(AlignmentError, match="joints"):
        run_group(
            [MethodC(I, 10)], MotionFeatures(T.quats[:, :2], T.euler[:, :2], T.orders[:2], 120.0)
        )


def test_shared_window_cache_is_safe_to_misuse(squat_pair):
    """Fed different targets at the same steps (not lockstep), a cache starts afresh:
    speed is all it can change."""
    I, T = squat_pair
    T2 = MotionFeatures(T.quats[::-1].copy(), T.euler[::-1].copy(), T.orders, T.fps)
    cache = WindowCache(I, 40)
    a, b = _with_cache("Mc w40", I, cache), _with_cache("Mb w40", I, cache)
    a.reset()
    b.reset()
    Ma, Mb = [], []
    for f1, f2 in zip(T.frames(), T2.frames()):
        Ma.append(a.step(f1))
        Mb.append(b.step(f2))
    np.testing.assert_array_equal(Ma, run_online(MethodC(I, 40), T)[0])
    np.testing.assert_array_equal(Mb, run_online(MethodB(I, 40), T2)[0])
    with pytest.raises(AlignmentError, match="another input or smaller windows"):
        MethodC(I, 80, cache=cache)
    with pytest.raises(AlignmentError, match="another input"):
        MethodB(T, 10, cache=cache)
    with pytest.raises(AlignmentError, match="WindowCache"):
        MethodB(I, 10, cache=object())


def test_bench_online_rows():
    from fpdtw.app.bench import bench_online, format_bench, paper_comparison

    I, T, _ = synthetic_pair(60, seed=2)
    names = ["Ma", "Ma + Type V", "Mc w10", "Mc w10 + Type V", "Mc w10 (literal window)"]
    rows = bench_online([(I, T)], names)
    assert [r["name"] for r in rows] == names
    assert [(r["method"], r["w"], r["typev"]) for r in rows[2:]] == [
        ("C", 10, False), ("C", 10, True), ("C", 10, False)
    ]  # fmt: skip
    for r in rows:
        assert r["frames"] == T.n_frames
        assert 0 < r["median_s"] <= r["p95_s"]
    assert "Mc w10 + Type V" in format_bench(rows)
    table = paper_comparison(rows)  # the literal window in its own column, not over Mc w10
    line = next(x for x in table.splitlines() if x.startswith("Method C"))
    assert f"{rows[2]['median_s'] * 1e6:.1f}" in line and f"{rows[4]['median_s'] * 1e6:.1f}" in line
    with pytest.raises(AlignmentError, match="unknown algorithm"):
        bench_online([(I, T)], ["Md w10"])


#: One name of every online family, with and without Type V and beyond the papers.
EVERY_ONLINE = (
    "Ma",
    "Ma + Type V",
    "Mb w10",
    "Mb w10 + Type V",
    "Mc w10",
    "Mc w10 + Type V",
    "Mc w10 (literal window)",
    "OE-DTW",
    "OLTW",
    "OPW",
    "Mc w10 (derivative)",
)


@pytest.mark.parametrize("name", EVERY_ONLINE)
@pytest.mark.parametrize("where", ["quats", "euler"])
def test_a_frame_that_is_not_finite_is_refused_the_same_way_by_every_method(name, where, data_path):
    """Issue "capture sources": a NaN or inf names the frame and the joint, for every method;
    the aligner is left as it was, so leaving the frame out gives the map of a take without it."""
    motions = [load_motion(data_path(SQUAT.format(k))).crop(0.0, 0.5) for k in (1, 2)]
    I, T = (MotionFeatures.from_motion(m, position_joints=OPW_JOINTS) for m in motions)
    a = make_online(name, I)
    frames = list(T.frames())
    M = [a.step(f) for f in frames[:5]]
    bad = {"quats": frames[5].quats.copy(), "euler": frames[5].euler.copy()}
    bad[where][2, 1] = np.nan if where == "quats" else np.inf
    with pytest.raises(AlignmentError, match=r"target frame 5: joint 2 is not finite"):
        a.step(Frame(bad["quats"], bad["euler"], frames[5].positions, frames[5].orders))
    M += [a.step(f) for f in frames[6:]]
    kept = [f for k, f in enumerate(frames) if k != 5]
    b = make_online(name, I)
    assert M == [b.step(f) for f in kept]
