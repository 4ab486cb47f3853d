"""The plain NumPy versions (fpdtw.plain) against the fast kernels: the same maps.

fpdtw.plain holds the papers' algorithms only; what neither paper describes (OLTW, the
global band, the bootstrap, tau-a, Method C's other windows, the OPW plugin's options)
is tested on its own in the tests of its module.

* every FP-DTW configuration of the papers on synthetic pairs and on the hand-worked cases of
  tests/test_methods.py, step by step: the same choice, window, costs and accumulation
  (to 1e-9: the plain arccos, sin and cos are NumPy's, the kernels' a polynomial and
  libm's), path and Type V state;
* the offline parts (eq. 1, DTW, OE-DTW, eqs. 2 and 3, the forecast, Type V, OPW);
* one frame's Euler angles to quaternions and forward kinematics, against the live
  server's compiled kernels (:mod:`fpdtw.motion.kinematics`), bit for bit;
* the smoke grid of the experiment runner (``make test`` computes it before the suite):
  every stored map of the papers' FP-DTW configurations, DTW, UTW and OE-DTW reproduced by
  the plain functions, and every stored similarity and deviation. Plain Python takes about
  30 minutes for the whole grid (54 pairs, 40 algorithms), so the default suite checks a
  fixed subset (:data:`SUBSET_PAIRS`, windows up to 20) and the whole grid is the ``slow``
  test (``.venv/bin/pytest -m slow tests/test_plain.py``);
* that every module of compiled kernels of the papers' algorithms names its plain versions.
"""

from __future__ import annotations

import ast
import math
import re

import numpy as np
import pytest
from reference.synthetic import (
    method_pairs,
    one_joint_motion,
    random_walk_features,
    synthetic_pair,
)

from fpdtw import plain
from fpdtw.costs import geo_distance, geodesic_cost_matrix
from fpdtw.dtw import accumulate, backtrack, dtw, path_to_map, utw_map
from fpdtw.forecast import euler_to_quat_fast
from fpdtw.io import load_motion
from fpdtw.metrics import deviation, kendall_tau_b, similarity
from fpdtw.motion.features import MotionFeatures
from fpdtw.motion.kinematics import frame_positions, frame_quats, order_codes
from fpdtw.motion.rotations import ORDERS
from fpdtw.online.base import run_online
from fpdtw.online.method_a import MethodA
from fpdtw.online.method_b import MethodB
from fpdtw.online.method_c import MethodC
from fpdtw.online.oedtw import OEDTW
from fpdtw.online.opw import OPW
from fpdtw.online.typev import TYPE_V
from fpdtw.online.window import B_CORNER
from fpdtw.paper.paths import REPO_ROOT
from fpdtw.registry import resolve
from fpdtw.warpcurve import WarpCurve

STEPS = {"A": plain.method_a_step, "B": plain.method_b_step, "C": plain.method_c_step}


#: The settings of the fast aligners that the papers' text fixes (plain has no others).
PAPER_SETTINGS = {"window": "square", "ties": "low", "band": "none"}


def plain_of(aligner):
    """The plain step of a fast aligner (its settings must be the papers')."""
    family = type(aligner).__name__[-1]
    for k, v in PAPER_SETTINGS.items():
        assert aligner.settings.get(k, v) == v, (k, aligner.settings.get(k))
    return STEPS[family]


def fast_and_plain_steps(aligner, T):
    """Both versions over a whole target: the fast snapshots and the plain steps with the
    Type V state before each (None without the constraint)."""
    aligner.reset()
    snaps = []
    for frame in T.frames():
        aligner.step(frame)
        snaps.append(aligner.window_snapshot())
    step = plain_of(aligner)
    typev = aligner.constraint is not None
    M, state, steps = [0], plain.TYPE_V_START, [None]
    for _ in range(T.n_frames - 1):
        allowed = plain.type_v_allowed(state) if typev else None
        s = step(aligner.I, T, M, aligner.w, allowed)
        steps.append((s, state if typev else None, allowed))
        M.append(s.M)
        state = plain.type_v_next(state, M[-1] - M[-2]) or state
    return snaps, steps


def assert_same_steps(aligner, T):
    snaps, steps = fast_and_plain_steps(aligner, T)
    for f, (s, state, allowed) in zip(snaps[1:], steps[1:]):
        assert (f.M, f.kind) == (s.M, s.kind), (aligner.name, f.q)
        assert (f.w_i, f.first) == (s.w_i, 0), (aligner.name, f.q)
        assert f.state == state
        if allowed is not None:
            np.testing.assert_array_equal(f.allowed, allowed)
        for name in ("C", "D", "score"):
            a, b = getattr(f, name), getattr(s, name)
            assert (a is None) == (b is None), name
            if a is not None:
                assert a.shape == b.shape, name
                np.testing.assert_array_equal(np.isinf(a), np.isinf(b))
                fin = np.isfinite(b)
                np.testing.assert_allclose(a[fin], b[fin], rtol=0, atol=1e-9, err_msg=name)
        for name in ("path", "P"):
            a, b = getattr(f, name), getattr(s, name)
            assert (a is None) == (b is None), name
            if a is not None:
                np.testing.assert_array_equal(a, b, err_msg=name)
    return [f.M for f in snaps]


# --- Methods A, B and C step by step ------------------------------------------------------

ALL = [("A", 2)] + [(m, w) for m in ("B", "C") for w in (10, 20, 40, 80)]


def make(method, I, w, typev):
    cls = {"A": MethodA, "B": MethodB, "C": MethodC}[method]
    return cls(I, w, constraint="typeV" if typev else None, record=True)


@pytest.fixture(scope="module")
def pairs():
    return method_pairs()


@pytest.mark.parametrize("typev", [False, True])
@pytest.mark.parametrize("method,w", ALL)
def test_plain_steps_equal_the_fast_ones(pairs, method, w, typev):
    for I, T in pairs[::2]:
        assert_same_steps(make(method, I, w, typev), T)


def units(u):
    """One-joint motion: frame f is a rotation about X by 18 * u[f] degrees (the costs of
    tests/test_methods.py's hand-worked cases are tenths of a unit)."""
    return one_joint_motion(18.0 * np.asarray(u, dtype=float), "X")


#: The hand-worked cases of tests/test_methods.py: (method, w, options, input, target).
HAND_WORKED = [
    ("A", 2, {}, [0, 1, 2, 3, 4, 5], [0, 2, 2, 5, 6, 6]),
    ("A", 2, {}, [0, 1, 1, 2], [0, 1, 3, 3]),
    ("A", 2, {"typev": True}, list(range(10)), [0] * 10),
    ("B", 3, {}, [0, 2, 3, 4, 4, 5, 5, 6], [0, 1, 2, 4, 5, 7, 7]),
    ("B", 3, {"typev": True}, [0, 3, 4, 5, 8, 8, 10, 11], [0, 1, 2, 2, 2, 2]),
    ("C", 3, {}, list(range(10)), [0, 1, 2, 2, 2, 3, 4, 6]),
    ("C", 3, {}, [0, 1, 2, 3], [0, 1, 2, 3, 4, 5]),
]  # fmt: skip


@pytest.mark.parametrize("case", HAND_WORKED, ids=lambda c: f"{c[0]}-w{c[1]}-{c[2]}")
def test_plain_steps_equal_the_fast_ones_on_the_hand_worked_cases(case):
    method, w, options, I, T = case
    options = dict(options)
    typev = options.pop("typev", False)
    assert_same_steps(make(method, units(I), w, typev), units(T))


def test_plain_method_b_hand_worked_step():
    """tests/test_methods.py's first Method B window, by hand (tenths of a unit)."""
    I, T = units([0, 2, 3, 4, 4, 5, 5, 6]), units([0, 1, 2, 4, 5, 7, 7])
    s = plain.method_b_step(I, T, [0, 1, 2], 3)
    np.testing.assert_allclose(
        s.C, np.array([[1, 1, 3, 5], [2, 0, 2, 4], [2, 0, 2, 4], [3, 1, 1, 3]]) / 10, atol=1e-12
    )
    assert s.D[0, 0] == B_CORNER
    np.testing.assert_array_equal(s.path, [[0, 0], [0, 1], [1, 1], [2, 1], [3, 2], [3, 3]])
    np.testing.assert_array_equal(s.P, [0, 0, 3, 3])
    assert (s.M, s.kind, s.w_i) == (2, "window", 3)
    # the warm-up and the end of the input
    assert plain.method_b_step(I, T, [0, 1], 3) == plain.Step(2, "warmup")
    assert plain.method_b_step(I, T, [0, 1, 2, 7], 3) == plain.Step(7, "end")


def test_plain_method_c_window_is_the_declared_square():
    """Algorithm 3's line 6 (w_i = w) and its declared w_i x w size: w rows in the middle
    of the input; where line 8 clips the range I_{M_n}..I_{M_n+w_i}, all its w_i + 1."""
    I, T = units(range(10)), units([0, 1, 2, 2, 2, 3, 4, 6])
    square = plain.method_c_step(I, T, [0, 1, 2], 3)
    assert (square.w_i, square.C.shape) == (2, (3, 3))
    # M_n = 8, m = 9: line 8 sets w_i = 1, the range I_8..I_9 has 2 rows (< w = 3)
    end = plain.method_c_step(I, T, [0, 1, 8], 3)
    assert (end.w_i, end.C.shape) == (1, (2, 3))
    # the square window's reverse accumulation, by hand: D[:, 0] = [.3, .4, .6] -> hold
    np.testing.assert_allclose(square.D, np.array([[3, 3, 3], [4, 3, 3], [6, 4, 2]]) / 10)
    assert square.M == 2


def test_backtrack_prefers_diagonal_then_target_step():
    D = np.array([[B_CORNER, 1.0], [1.0, 5.0]])  # (1,1): (0,1) and (1,0) tie
    path = plain.backtrack(D)
    np.testing.assert_array_equal(path, [[0, 0], [1, 0], [1, 1]])
    np.testing.assert_array_equal(plain.path_to_map(path, 1), [0, 1])
    D = np.array([[0.0, 1.0, 9.0], [1.0, 2.0, 9.0], [9.0, 2.0, 3.0]])  # (2,2): all tie
    assert [tuple(c) for c in plain.backtrack(D)][-2:] == [(1, 1), (2, 2)]


# --- the offline parts ------------------------------------------------------------------


def test_geo_distance_and_cost_matrix():
    I, T, _ = synthetic_pair(50, seed=3)
    C = plain.cost_matrix(I.quats, T.quats)
    np.testing.assert_allclose(C, geodesic_cost_matrix(I.quats, T.quats), rtol=0, atol=1e-12)
    assert plain.geo_distance(I.quats[4], T.quats[9]) == pytest.approx(
        geo_distance(I.quats[4], T.quats[9]), abs=1e-12
    )
    A = units([0, 1, 3, 10])
    assert plain.geo_distance(A.quats[1], A.quats[2]) == pytest.approx(0.2, abs=1e-12)


def test_dtw_accumulation_back_track_and_open_end():
    I, T, _ = synthetic_pair(90, seed=6)
    C = geodesic_cost_matrix(I.quats, T.quats)
    D = plain.accumulate(C)
    np.testing.assert_array_equal(D, accumulate(C))  # the same operations: bit for bit
    path = plain.backtrack(D, C)
    np.testing.assert_array_equal(path, backtrack(D, C))
    np.testing.assert_array_equal(plain.backtrack(D), backtrack(D))
    np.testing.assert_array_equal(plain.path_to_map(path, T.n_frames - 1), dtw(C).map)
    np.testing.assert_array_equal(path_to_map(path, T.n_frames - 1), dtw(C).map)
    M, _ = run_online(OEDTW(I), T)
    np.testing.assert_array_equal(plain.oe_dtw_end_points(C), M)


def test_reverse_accumulation_is_dtw_with_both_axes_reversed():
    rng = np.random.default_rng(2)
    C = rng.uniform(0, 1, (7, 5))
    backwards = accumulate(C[::-1, ::-1])[::-1, ::-1]
    np.testing.assert_array_equal(plain.reverse_accumulate(C), backwards)


def test_forecast_and_quaternions():
    X = random_walk_features(20, seed=8)
    E = plain.forecast_joints(X.euler[4], X.euler[5], 6)
    np.testing.assert_allclose(E[0], X.euler[5])
    np.testing.assert_allclose(E[3], X.euler[5] + 3 * (X.euler[5] - X.euler[4]))
    Q = plain.euler_to_quat(E, X.orders)
    F = euler_to_quat_fast(E, X.orders)
    np.testing.assert_allclose(np.abs(np.sum(Q * F, axis=-1)), 1.0, atol=1e-12)
    np.testing.assert_allclose(np.abs(plain.euler_to_quat(X.euler, X.orders)[..., 0]),
                               np.abs(X.quats[..., 0]), atol=1e-9)  # fmt: skip


def test_type_v_table_is_the_aligners_table():
    assert tuple(plain.TYPE_V_TABLE) == TYPE_V.states
    assert plain.TYPE_V_START == TYPE_V.states[TYPE_V.start]
    for s, name in enumerate(TYPE_V.states):
        np.testing.assert_array_equal(plain.type_v_allowed(name), TYPE_V.allowed(s))
        for a in range(-1, 6):
            nxt = TYPE_V.next_state(s, a)
            assert plain.type_v_next(name, a) == (None if nxt < 0 else TYPE_V.states[nxt])
    np.testing.assert_array_equal(plain.allowed_rows(plain.type_v_allowed("N"), 6),
                                  [False, True, True, True, False, False])  # fmt: skip
    assert plain.allowed_rows(None, 3).all()


def test_similarity_and_deviation_equal_the_metrics():
    I, T, _ = synthetic_pair(120, seed=9)
    for M in (utw_map(I.n_frames - 1, T.n_frames - 1), run_online(MethodC(I, 20), T)[0]):
        assert plain.similarity(I.quats, T.quats, M) == similarity(I.quats, T.quats, M)
        assert plain.deviation(utw_map(I.n_frames - 1, T.n_frames - 1), M) == deviation(
            utw_map(I.n_frames - 1, T.n_frames - 1), M
        )
    rng = np.random.default_rng(4)
    x, y = rng.integers(0, 5, 40).astype(float), rng.normal(size=40)
    assert plain.kendall_tau_b(x, y) == kendall_tau_b(x, y)
    assert math.isnan(plain.kendall_tau_b(np.ones(5), y[:5]))
    # a still axis in both motions scores 1, in one of them 0
    still = np.zeros((30, 1, 4))
    still[..., 0] = 1.0
    assert plain.similarity(still, still, np.arange(30)) == 1.0


def test_opw_runs_the_plain_step():
    """OPW's step is plain.opw_step: a loop of it over the same positions builds the same
    curve and the same decisions."""
    rng = np.random.default_rng(1)
    PA = np.cumsum(rng.normal(size=(90, 16, 3)), axis=0)
    PB = PA[np.clip(np.round(np.arange(100) * 0.85).astype(int), 0, 89)]
    I = MotionFeatures(np.tile([1.0, 0, 0, 0], (90, 1, 1)), np.zeros((90, 1, 3)), ("XYZ",),
                       30.0, PA)  # fmt: skip
    T = MotionFeatures(np.tile([1.0, 0, 0, 0], (100, 1, 1)), np.zeros((100, 1, 3)), ("XYZ",),
                       30.0, PB)  # fmt: skip
    opw = OPW(I, omega=0.04, gamma=0.1)
    run_online(opw, T)
    f = WarpCurve.identity((I.n_frames - 1) / 30.0)
    decisions = []
    k = 1
    while k * 0.04 <= (T.n_frames - 1) / 30.0 + 1e-9:
        t = k * 0.04
        k += 1
        if t >= f.x[-1]:
            continue
        q = math.ceil((t - 1e-9) * 30.0)  # the frames received when OPW takes the step
        decisions.append(plain.opw_step(f, t, PA, PB[: q + 1], 0.04, 0.1, 30.0, 30.0))
    assert [s for s, _ in decisions] == [d.s for d in opw.decisions]
    assert {0, 2} <= {s for s, _ in decisions}
    np.testing.assert_array_equal([p for _, p in decisions], [d.costs for d in opw.decisions])
    np.testing.assert_array_equal(f.keys, opw.curve.keys)


# --- one frame's rotations and forward kinematics (the live server's kernels) ------------


def test_plain_euler_to_quat_is_the_compiled_one_in_all_six_orders():
    """``frame_quats`` (scipy's numbers, bit for bit) keeps ``w >= 0``; the plain version
    leaves the sign as it comes. Bit for bit where NumPy's sine and cosine are libm's (the
    kernel's), as here; else to 1e-12."""
    rng = np.random.default_rng(7)
    E = rng.uniform(-720.0, 720.0, (3000, 6, 3))
    E[:100] = np.round(E[:100])
    E[100:200] = 0.0
    E[200:300, :, 1] = 90.0  # gimbal lock
    fast = frame_quats(E.reshape(-1, 3), np.tile(order_codes(ORDERS), len(E))).reshape(
        E.shape[:-1] + (4,)
    )
    Q = plain.euler_to_quat(E, ORDERS)
    Q = np.where(Q[..., :1] < 0, -Q, Q)
    np.testing.assert_allclose(Q, fast, rtol=0, atol=1e-12)
    h = (E * (math.pi / 360.0)).ravel()
    if np.array_equal(np.sin(h), [math.sin(x) for x in h]) and np.array_equal(
        np.cos(h), [math.cos(x) for x in h]
    ):
        np.testing.assert_array_equal(Q, fast)


@pytest.mark.parametrize(
    "rel", ["mocap_single_person_actions/MoCapData/Walk_02.fbx", "cmu/18_01.bvh",
            "hdm05/HDM05_cut_amc/squat1Reps/HDM_bd_squat1Reps_001_120.amc"],
)  # fmt: skip
def test_plain_forward_kinematics_is_the_compiled_one(data_path, rel):
    """FBX (pre- and post-rotations), BVH and ASF/AMC skeletons, bit for bit."""
    m = load_motion(data_path(rel))
    sk = m.skeleton
    for k in range(0, m.n_frames, max(1, m.n_frames // 40)):
        q, r = m.quats[k], m.root_translation[k]
        P = plain.forward_kinematics(q, sk.pre_rotations, sk.post_rotations, sk.offsets,
                                     sk.parents, r)  # fmt: skip
        np.testing.assert_array_equal(P, frame_positions(sk, q, r, root_relative=False))


def test_plain_forward_kinematics_by_hand():
    """A chain of three joints, each 1 along x from its parent, the root turned by 90
    degrees about z and the second joint by 90 about z again: (1, 2, 3) + root, then
    (1, 3, 3), then (0, 3, 3)."""
    turn = [math.cos(math.pi / 4), 0.0, 0.0, math.sin(math.pi / 4)]
    Q = np.array([turn, turn, [1.0, 0, 0, 0]])
    ident = np.tile([1.0, 0, 0, 0], (3, 1))
    offsets = np.array([[0.0, 0, 0], [1, 0, 0], [1, 0, 0]])
    P = plain.forward_kinematics(Q, ident, ident, offsets, np.array([-1, 0, 1]), [1.0, 2, 3])
    np.testing.assert_allclose(P, [[1, 2, 3], [1, 3, 3], [0, 3, 3]], atol=1e-15)


# --- the smoke grid -----------------------------------------------------------------------

SMOKE_RESULTS = REPO_ROOT / "build" / "smoke" / "results"
#: Pairs of the smoke grid the default suite checks: the first of each dataset.
SUBSET_PAIRS = ("authors_fbx", "hdm05")


@pytest.fixture(scope="module")
def smoke():
    from fpdtw.paper.runner.run import Results, pair_features

    folder = SMOKE_RESULTS / "smoke"
    if not (folder / "summary.json").is_file():
        pytest.fail(
            f"no smoke results in {SMOKE_RESULTS}: run `make test` (it computes the smoke grid "
            "before the test suite) or `make build/smoke/grids/smoke.done`"
        )
    results = Results(folder)
    return results, {fps: pair_features(results, fps) for fps in (120.0, 60.0)}


def plain_map(name, I, T):
    """The map of algorithm ``name`` (the registry's names) from the plain functions."""
    a = resolve(name)
    if a.family == "UTW":
        return utw_map(I.n_frames - 1, T.n_frames - 1)
    if a.family in ("DTW", "OE"):
        C = plain.cost_matrix(I.quats, T.quats)
        if a.family == "OE":
            return plain.oe_dtw_end_points(C)
        return plain.path_to_map(plain.backtrack(plain.accumulate(C), C), T.n_frames - 1)
    return plain.run(STEPS[a.family], I, T, a.w, a.typev, **a.options)


def in_plain(a):
    """Whether fpdtw.plain writes the algorithm out: the papers' offline baselines and
    Methods A, B and C as the text reads them (OPW's step is compared on its own,
    test_opw_runs_the_plain_step; OLTW and the other readings are compiled only)."""
    return a.family in ("UTW", "DTW", "OE", "A", "B", "C") and not a.options


def check_smoke_pairs(smoke, pairs, max_w):
    results, features = smoke
    checked = 0
    for name in results.algorithms:
        base, _, rate = name.partition("@")
        a = resolve(base)
        if not in_plain(a) or (a.w or 0) > max_w:
            continue
        fps = results.fps(name)
        stored = results.get(name)
        ref = results.get("DTW@60Hz" if rate else "DTW")
        for k in pairs:
            I, T = features[fps](k)
            M = plain_map(base, I, T)
            np.testing.assert_array_equal(M, stored.map(k), err_msg=f"{name}, pair {k}")
            assert plain.similarity(I.quats, T.quats, M) == stored["similarity"][k], name
            assert plain.deviation(ref.map(k), M) == stored["deviation"][k], name
            checked += 1
    return checked


def test_plain_maps_equal_the_smoke_grid_on_a_subset(smoke):
    results, _ = smoke
    first = {
        d: next(k for k, p in enumerate(results.pairs) if p["dataset"] == d) for d in SUBSET_PAIRS
    }
    pairs = list(first.values())
    assert check_smoke_pairs(smoke, pairs, max_w=20) >= 2 * 13


@pytest.mark.slow
def test_plain_maps_equal_the_whole_smoke_grid(smoke):
    results, _ = smoke
    n = check_smoke_pairs(smoke, range(len(results.pairs)), max_w=80)
    papers = [k for k in results.algorithms if in_plain(resolve(k.partition("@")[0]))]
    assert n == len(results.pairs) * len(papers)


#: numba's entry points that compile a function.
NUMBA_COMPILERS = {"jit", "njit", "generated_jit", "vectorize", "guvectorize", "cfunc",
                   "stencil", "jit_module", "intrinsic", "overload", "overload_method",
                   "overload_attribute", "register_jitable"}  # fmt: skip
#: Modules of compiled kernels of the papers' algorithms: each must name the plain
#: versions of its kernels (eq. 1, DTW and OE-DTW, the forecast, Algorithms 1-3 and Type V,
#: eqs. 2 and 3, and the poses OPW's eq. 5 compares). Other compiled modules (OLTW, the
#: bootstrap, the benchmark's limit kernels) hold what neither paper describes: the
#: compiled function alone, tested on its own.
PAPER_MODULES = {
    "fpdtw/costs.py": "eq. 1",
    "fpdtw/dtw.py": "offline DTW (Section 2)",
    "fpdtw/forecast.py": "forecastJoints of Algorithms 2 and 3",
    "fpdtw/metrics.py": "eqs. 2 and 3",
    "fpdtw/motion/kinematics.py": "the forecast's quaternions and OPW's eq. 5 positions",
    "fpdtw/online/oedtw.py": "OE-DTW (Section 2, Fig. 1)",
    "fpdtw/online/window.py": "Algorithms 1-3 and the Type V constraint",
}


def compiles_with_numba(source: str) -> bool:
    """Whether a module's source uses one of numba's compilers (:data:`NUMBA_COMPILERS`),
    however numba or the compiler was imported (``import numba as nb``, ``from numba
    import njit as jit``, ``from numba.extending import intrinsic``)."""
    tree = ast.parse(source)
    modules, compilers = set(), set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            modules |= {a.asname or a.name.partition(".")[0] for a in node.names
                        if a.name.partition(".")[0] == "numba"}  # fmt: skip
        elif isinstance(node, ast.ImportFrom) and (node.module or "").startswith("numba"):
            compilers |= {a.asname or a.name for a in node.names if a.name in NUMBA_COMPILERS}
            modules |= {a.asname or a.name for a in node.names if a.name not in NUMBA_COMPILERS}
    for node in ast.walk(tree):
        if isinstance(node, ast.Name) and node.id in compilers:
            return True
        if isinstance(node, ast.Attribute) and node.attr in NUMBA_COMPILERS:
            root = node.value
            while isinstance(root, ast.Attribute):
                root = root.value
            if isinstance(root, ast.Name) and root.id in modules:
                return True
    return False


@pytest.mark.parametrize(
    "source,compiles",
    [("import numba\n@numba.njit(cache=True)\ndef f(x):\n    return x", True),
     ("import numba as nb\n@nb.jit\ndef f(x):\n    return x", True),
     ("from numba import njit as fast\nf = fast(cache=True)(lambda x: x)", True),
     ("from numba.extending import intrinsic\n@intrinsic\ndef f(typingctx):\n    pass", True),
     ("import numba.np.ufunc\ng = numba.np.ufunc.vectorize(['f8(f8)'])(abs)", True),
     ("import numba\nprint(numba.config.CPU_NAME)", False),
     ("from numba import prange, types\n", False),
     ("def njit(f):\n    return f\n@njit\ndef g(x):\n    return x", False)],
)  # fmt: skip
def test_compiles_with_numba_finds_the_compiled_modules(source, compiles):
    assert compiles_with_numba(source) is compiles


def test_every_plain_version_line_names_a_plain_function():
    """The "Plain version: fpdtw.plain.xxx" lines name functions of fpdtw.plain, and every
    module of compiled kernels of the papers' algorithms (:data:`PAPER_MODULES`) names at
    least one; a compiled module of anything else need not."""
    named, compiled = {}, set()
    for path in sorted((REPO_ROOT / "fpdtw").rglob("*.py")):
        rel, text = path.relative_to(REPO_ROOT).as_posix(), path.read_text()
        if compiles_with_numba(text):
            compiled.add(rel)
        if path.name == "plain.py":  # its docstring describes the convention
            continue
        for line in text.splitlines():
            if "Plain version:" in line:
                names = re.findall(r"fpdtw\.plain\.(\w+)", line)
                assert names, f"{rel}: {line.strip()}"
                named.setdefault(rel, set()).update(names)
    for rel, names in named.items():
        assert names <= set(plain.__all__), f"{rel}: {sorted(names - set(plain.__all__))}"
    assert "fpdtw/plain.py" not in compiled
    assert set(PAPER_MODULES) <= compiled, sorted(set(PAPER_MODULES) - compiled)
    missing = sorted(set(PAPER_MODULES) - set(named))
    assert not missing, f"compiled, with no 'Plain version: fpdtw.plain.xxx' line: {missing}"


def test_twins_take_the_same_arguments():
    """joint_trajectories (axis "y" or vectors), deviation (frames=) and geo_distance
    (weights) are called alike in both versions and agree."""
    from fpdtw.metrics import joint_trajectories

    I, T, _ = synthetic_pair(40, seed=2)
    bones = np.random.default_rng(3).normal(size=(I.quats.shape[1], 3))
    for axis in ("y", bones, np.array([0.0, 0.0, 2.0])):
        np.testing.assert_allclose(plain.joint_trajectories(I.quats, axis),
                                   joint_trajectories(I.quats, axis), atol=1e-12)  # fmt: skip
    P_a, P_b = utw_map(I.n_frames - 1, T.n_frames - 1), run_online(MethodC(I, 10), T)[0]
    for frames in ("printed", "all"):
        assert plain.deviation(P_a, P_b, frames) == deviation(P_a, P_b, frames)
    # by hand: |0-0| + |1-3| + |2-2| = 2 over q = 1..2 -> 1.0; over q = 0..2 -> 2/3
    assert plain.deviation([0, 1, 2], [0, 3, 2]) == 1.0
    assert plain.deviation([0, 1, 2], [0, 3, 2], frames="all") == pytest.approx(2 / 3)
    w = np.linspace(0.5, 1.5, I.quats.shape[1])
    assert geo_distance(I.quats[3], T.quats[7], w) == pytest.approx(
        plain.geo_distance(I.quats[3], T.quats[7], w), abs=1e-12
    )
    assert geo_distance(I.quats[3], T.quats[7], np.ones(len(w))) == pytest.approx(
        geo_distance(I.quats[3], T.quats[7]), abs=1e-15
    )
