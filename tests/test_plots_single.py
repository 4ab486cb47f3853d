"""Figures drawn from single runs (Figs. 1, 2, 3, 4, 8, 9): rule helpers and plot functions.

The rule helpers (first backward jump, step selection, best level, Type V states) are
checked on tiny hand-worked inputs; each plot function runs on a small real or synthetic
input and must return ``(fig, ax)`` holding the artists the figure promises.

Hand-worked OE-DTW case: one-joint motions rotating about X by 18 degrees per "unit", so
the geodesic cost (eq. 1) between u and v units is ``|u - v| / 10`` (see test_methods.py).
"""

from __future__ import annotations

import json

import matplotlib.pyplot as plt
import numpy as np
import pytest
from reference.synthetic import one_joint_motion, random_walk_features, synthetic_pair

from fpdtw import plain
from fpdtw.motion.features import MotionFeatures
from fpdtw.online import MethodA, MethodB, run_online
from fpdtw.online.window import B_CORNER
from fpdtw.paper import numbers
from fpdtw.paper.figures import facts as pf
from fpdtw.paper.figures import forecast as pfc
from fpdtw.paper.figures import oedtw as po
from fpdtw.paper.figures import typev as pt
from fpdtw.paper.figures import walk_pair as pw
from fpdtw.paper.figures import windows as pwin


def units(u):
    """One-joint motion: frame f is a rotation about X by 18 * u[f] degrees."""
    return one_joint_motion(18.0 * np.asarray(u, dtype=float), "X")


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


@pytest.fixture(scope="module")
def walk_short():
    """The real walk pair, first 0.5 s (61 frames each)."""
    return pw.load_walk_pair(smoke=True, seconds=0.5)


# --- Fig. 1: OE-DTW ---------------------------------------------------------------------


def test_backward_jumps_hand_checked():
    E = [0, 1, 3, 2, 2, 4, 1, 5]  # drops: 3 -> 2 after q = 2, 4 -> 1 after q = 5
    np.testing.assert_array_equal(po.backward_jumps(E), [2, 5])
    assert po.first_backward_jump(E) == (2, 3, 2)
    f = po.oedtw_facts(E)
    assert f == {
        "n_frames": 8,
        "jumps": 2,
        "jump_frames": [2, 5],
        "frames_back": 4,  # (3 - 2) + (4 - 1)
        "first_jump": {"q": 2, "e_q": 3, "e_q1": 2},
    }
    assert po.backward_jumps([0, 0, 1, 1, 2]).size == 0
    assert po.first_backward_jump([0, 0, 1, 1, 2]) is None
    assert po.oedtw_facts([0, 1])["first_jump"] is None
    with pytest.raises(ValueError):
        po.backward_jumps(np.zeros((2, 2)))


def hand_oedtw():
    # I = 0, 1, 3, 6 units; T = 0, 3, 1. Costs |I_i - T_q| / 10 per column:
    #   T0 = 0: .0 .1 .3 .6 -> D[:, 0] = 0, .1, .4, 1.0            e_0 = 0
    #   T1 = 3: .3 .2 .0 .3 -> D[:, 1] = .3, .2, .1, .4             e_1 = 2
    #   T2 = 1: .1 .0 .2 .5 -> D[:, 2] = .4, .2, .3, .6             e_2 = 1 (backwards)
    # path of q = 1 from (2, 1): diagonal to (1, 0) (D .1), then (0, 0);
    # path of q = 2 from (1, 2): to (1, 1) (D .2 < .3, .4), then diagonal to (0, 0).
    return po.run_oedtw(units([0, 1, 3, 6]), units([0, 3, 1]))


def test_oedtw_hand_worked_jump():
    oe = hand_oedtw()
    np.testing.assert_array_equal(oe.end_points, [0, 2, 1])
    np.testing.assert_allclose(
        oe.D, [[0, 0.3, 0.4], [0.1, 0.2, 0.2], [0.4, 0.1, 0.3], [1.0, 0.4, 0.6]], atol=1e-9
    )
    assert po.first_backward_jump(oe.end_points) == (1, 2, 1)
    np.testing.assert_array_equal(oe.path(1), [[0, 0], [1, 0], [2, 1]])
    np.testing.assert_array_equal(oe.path(2), [[0, 0], [1, 1], [1, 2]])


def test_plot_oedtw_paths_artists():
    oe = hand_oedtw()
    fig, ax = po.plot_oedtw_paths(oe, 1)
    assert ax.figure is fig
    assert len(ax.images) == 1
    assert ax.images[0].get_array().shape == (4, 3)  # all 4 input rows, target frames 0..2
    p1, p2, ends = ax.lines[:3]
    np.testing.assert_array_equal(p1.get_xydata(), [[0, 0], [0, 1], [1, 2]])  # (t, i)
    np.testing.assert_array_equal(p2.get_xydata(), [[0, 0], [1, 1], [2, 1]])
    np.testing.assert_array_equal(ends.get_ydata(), [0, 2, 1])
    with pytest.raises(ValueError):
        po.plot_oedtw_paths(oe, 2)  # frame q + 1 = 3 not received


def test_plot_end_points_and_fig1():
    E = np.array([0, 1, 3, 2, 2, 4, 1, 5])
    fig, ax = po.plot_end_points(E)
    assert len(ax.lines) == 3  # end points, 1:1, jumps
    np.testing.assert_array_equal(ax.lines[2].get_xdata(), [3, 6])  # marked at q + 1
    np.testing.assert_array_equal(ax.lines[2].get_ydata(), [2, 1])
    assert len(ax.child_axes) == 1  # inset around the first jump
    fig, ax = po.plot_end_points([0, 1, 2, 3])
    assert len(ax.lines) == 2 and not ax.child_axes
    fig, axes = po.plot_fig1(hand_oedtw())
    assert len(axes) == 2 and "1 and 2" in axes[0].get_title()


def test_oedtw_real_walk_prefix(walk_short):
    mI, mT = walk_short
    I, T = MotionFeatures.from_motion(mI), MotionFeatures.from_motion(mT)
    assert I.n_frames == T.n_frames == 61
    oe = po.run_oedtw(I, T)
    E = oe.end_points
    assert E.shape == (61,) and E[0] == 0 and E.max() <= 60
    for q in po.backward_jumps(E):
        assert E[q + 1] < E[q]
    first = po.first_backward_jump(E)
    if first is not None:
        q = first[0]
        assert np.all(np.diff(E[: q + 1]) >= 0)  # nothing backwards before the first jump


# --- Figs. 2 and 4: windows -------------------------------------------------------------


def test_plain_run_keeps_the_steps_of_its_map():
    I, T, _ = synthetic_pair(120, k=4, seed=3)
    steps = []
    M = plain.run(plain.method_b_step, I, T, 10, steps=steps)
    np.testing.assert_array_equal(M, plain.run(plain.method_b_step, I, T, 10))
    M2, _ = run_online(MethodB(I, 10), T)
    np.testing.assert_array_equal(M, M2)  # the plain steps are the compiled aligner's
    assert len(steps) == T.n_frames - 1
    assert [s.M for s in steps] == M[1:].tolist()
    window = [s for s in steps if s.kind == "window"]
    assert window and all(s.q == q for q, s in enumerate(steps, 1) if s.kind == "window")
    assert all(s.M_n == M[s.q - 1] for s in window)
    assert steps[0].kind == "warmup" and steps[0].M_n is None and steps[0].q is None


def bstep(q, kind="window", path=None):
    """A plain Method B step with only what first_leaving reads."""
    if kind != "window":
        return plain.Step(q, kind)
    return plain.Step(0, kind, 3, path=None if path is None else np.array(path), M_n=0, q=q)


def test_step_rules_hand_checked():
    steps = [
        bstep(1, "warmup"),
        bstep(2, "warmup"),
        bstep(3, path=[[0, 0], [0, 1], [1, 2]]),  # leaves via (0, 1)
        bstep(4, path=[[0, 0], [1, 1], [2, 2]]),  # diagonal (only possible w/o D[0,0] = 10000)
        bstep(5, path=[[0, 0], [1, 0], [1, 1]]),  # leaves via (1, 0)
        bstep(6, path=[[0, 0], [0, 1], [0, 2]]),
        bstep(7, "end"),
    ]
    assert pwin.first_leaving(steps, pwin.VIA_INPUT).q == 5
    assert pwin.first_leaving(steps, pwin.VIA_TARGET).q == 3
    assert pwin.first_leaving(steps, pwin.VIA_TARGET, q_min=4).q == 6
    assert pwin.first_leaving(steps, (1, 1)).q == 4
    assert pwin.first_leaving(steps, pwin.VIA_INPUT, q_min=6) is None


def test_plot_method_a_window_hand_worked():
    # test_methods.test_method_a_hand_worked: M = 0, 2, 2, 4, 5, 5; at q = 3 the window
    # I2..I4 against T = 5 units costs .3, .2, .1 and the choice is +2 -> 4.
    I, T = units([0, 1, 2, 3, 4, 5]), units([0, 2, 2, 5, 6, 6])
    steps = []
    M = plain.run(plain.method_a_step, I, T, 2, steps=steps)
    np.testing.assert_array_equal(M, [0, 2, 2, 4, 5, 5])
    a = plain.method_a_step(I, T, M[:3], 2)  # the step that maps T_3
    assert (a.q, a.M_n, a.M) == (3, 2, 4) == (steps[2].q, steps[2].M_n, steps[2].M)
    np.testing.assert_array_equal(a.C, steps[2].C)
    fig, ax = pwin.plot_method_a_window(M, a, before=3, after=1)
    assert len(ax.images) == 1
    grid = ax.images[0].get_array()
    # columns target 0..4, rows input r0 = min(M_0..M_2) - 1 -> 0 .. start + w_i + 1 = 5
    assert grid.shape == (6, 5)
    np.testing.assert_allclose(grid[2:5, 3], [0.3, 0.2, 0.1], atol=1e-9)
    assert np.isnan(np.delete(grid.filled(np.nan), 3, axis=1)).all()
    texts = sorted(t.get_text() for t in ax.texts)
    assert texts == ["0.100", "0.200", "0.300"]
    map_line = ax.lines[0]
    np.testing.assert_array_equal(map_line.get_xdata(), [0, 1, 2])
    np.testing.assert_array_equal(map_line.get_ydata(), [0, 2, 2])
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert any("M_{3} = M_{2} + 2 = 4" in s for s in labels)
    fig, ax = pwin.plot_method_a_window(M[:3], a, before=3)  # the map M_0..M_n alone
    np.testing.assert_array_equal(ax.lines[0].get_ydata(), [0, 2, 2])
    with pytest.raises(ValueError):
        pwin.plot_method_a_window(M, steps[4])  # input exhausted: an "end" step


def test_plot_method_b_window_artists():
    I, T, _ = synthetic_pair(150, k=4, seed=5)
    steps = []
    plain.run(plain.method_b_step, I, T, 10, steps=steps)
    s = next(x for x in steps if x.kind == "window")
    fig, ax = pwin.plot_method_b_window(s)
    img = ax.images[0].get_array()
    assert img.shape == (s.w_i + 1, 11)
    assert np.ma.is_masked(img[0, 0]) or np.isnan(img[0, 0])  # D[0,0] = 10000 kept off scale
    assert s.D[0, 0] == B_CORNER
    assert any(t.get_text() == "10000" for t in ax.texts)
    path_line = ax.lines[1]
    np.testing.assert_array_equal(path_line.get_xydata(), s.path[:, ::-1])  # (column, row)
    x = ax.lines[2]
    offset = s.M - s.M_n
    assert (x.get_xdata()[0], x.get_ydata()[0]) == (1, offset)
    assert offset == s.P[1] == min(r for r, c in s.path if c == 1)  # lowest row in T_{n+1}
    labels = [t.get_text() for t in ax.get_xticklabels()]
    assert labels[0].startswith("$F_0$") and "T_n" in labels[0] and "T_{n+1}" in labels[1]
    fig, ax = pwin.plot_method_b_window(s, which="C", annotate=False)
    assert not np.ma.is_masked(ax.images[0].get_array()[0, 0]) and not ax.texts
    with pytest.raises(ValueError):
        pwin.plot_method_b_window(steps[0])  # warm-up step


def test_plot_method_c_window_artists():
    I, T, _ = synthetic_pair(150, k=4, seed=6)
    steps = []
    plain.run(plain.method_c_step, I, T, 10, steps=steps)
    s = next(x for x in steps if x.kind == "window")
    fig, ax = pwin.plot_method_c_window(s)
    assert ax.images[0].get_array().shape == s.D.shape == (s.w_i + 1, 10) == (10, 10)  # square
    x = ax.lines[0]
    assert (x.get_xdata()[0], x.get_ydata()[0]) == (0, s.M - s.M_n)
    assert s.M - s.M_n == int(np.argmin(s.D[:, 0]))
    assert "T_{n+1}" in ax.get_xticklabels()[0].get_text()
    with pytest.raises(ValueError):
        pwin.plot_method_c_window(steps[0])  # warm-up step


def test_forecast_labels():
    assert pwin.forecast_labels(3, True) == ["$F_0$\n$=T_n$", "$F_1$\n$=T_{n+1}$", "$F_{2}$"]
    assert pwin.forecast_labels(2, False) == ["$F_0$\n$=T_{n+1}$", "$F_{1}$"]


# --- Fig. 3: forecast error -------------------------------------------------------------


def test_best_level_hand_checked():
    err = np.array([[0.3, 0.1], [0.2, 0.2], [0.2, 0.05]])
    assert pfc.best_level(err, [2, 3, 4], 1) == 3  # tie 0.2 / 0.2: the lower level
    assert pfc.best_level(err, [2, 3, 4], 2) == 4
    for bad in (0, 3):
        with pytest.raises(ValueError):
            pfc.best_level(err, [2, 3, 4], bad)


def test_forecast_curves_and_panels():
    feats = [random_walk_features(80, k=3, seed=s) for s in (1, 2)]
    curves = pfc.forecast_curves(feats, levels=(2, 3, 4), H=6)
    assert list(curves) == ["dead_reckoning", "exponential", "holt"]
    for err in curves.values():
        assert err.shape == (3, 6) and np.all(err >= 0) and np.all(np.isfinite(err))
        assert np.all(np.diff(err[0]) > 0)  # error grows with frames ahead on smooth walks
    fig, axes = pfc.plot_forecast_panels(curves, (2, 3, 4))
    assert len(axes) == 3
    for ax, err in zip(axes, curves.values()):
        assert len(ax.lines) == 3
        np.testing.assert_allclose(ax.lines[0].get_ydata(), err[0])
        np.testing.assert_array_equal(ax.lines[0].get_xdata(), np.arange(1, 7))
    fig, ax = pfc.plot_forecast_error(curves["holt"], (2, 3, 4), logy=False)
    assert [ln.get_label() for ln in ax.lines] == ["s = 2", "s = 3", "s = 4"]


# --- Fig. 8: walk pair ------------------------------------------------------------------


def test_walk_pair_loads_the_authors_walks(walk_short):
    mI, mT = walk_short
    assert (mI.name, mT.name) == ("Walk_01", "Walk_02")
    assert pw.WALK_PAIR[0][1].endswith("Walk_01.fbx") and pw.WALK_PAIR[1][1].endswith("Walk_02.fbx")
    assert mI.fps == mT.fps == 120


def test_pose_frames():
    np.testing.assert_array_equal(pw.pose_frames(241, 5), [0, 60, 120, 180, 240])
    np.testing.assert_array_equal(pw.pose_frames(3, 5), [0, 1, 2])


def test_pair_scores_and_paths_plot():
    I, T, _ = synthetic_pair(100, k=4, seed=8)
    maps = pw.align_all(I, T, ("DTW", "UTW", "Mc w10"))
    assert list(maps) == ["DTW", "UTW", "Mc w10"]
    rows = pw.pair_scores(I, T, maps)
    assert rows[0]["algorithm"] == "DTW" and rows[0]["deviation"] == 0.0
    dev = np.mean(np.abs(maps["DTW"] - maps["UTW"])[1:])  # eq. 3: q = 1..n, as printed
    assert rows[1]["deviation"] == pytest.approx(dev)
    assert rows[1]["paper_deviation"] is None
    assert all(-1 <= r["similarity"] <= 1 for r in rows)
    assert numbers.FIG8_DEVIATIONS == {"Mb w80": 8, "Mc w20": 177, "Mc w40": 62, "Mc w80": 6}
    from fpdtw.dtw import dtw_pair

    D = dtw_pair(I, T).D
    fig, ax = pw.plot_paths_over_cost(D, maps)
    assert ax.images[0].get_array().shape == D.shape
    assert len(ax.lines) == len(maps)
    for ln, (name, M) in zip(ax.lines, maps.items()):
        assert ln.get_label() == name
        np.testing.assert_array_equal(ln.get_ydata(), M)


def test_joint_curves_warp_the_input():
    I, T, _ = synthetic_pair(90, k=4, seed=9)
    maps = pw.align_all(I, T, ("DTW", "UTW"))
    fig, axes = pw.plot_joint_curves(I, T, maps, joint=1)
    assert len(axes) == 3
    assert all(len(ax.lines) == 3 for ax in axes)
    np.testing.assert_allclose(axes[0].lines[0].get_ydata(), T.euler[:, 1, 0])
    np.testing.assert_allclose(axes[2].lines[2].get_ydata(), I.euler[maps["UTW"], 1, 2])


def test_aligned_poses_grid(walk_short):
    mI, mT = walk_short
    n = mT.n_frames
    maps = {"DTW": np.arange(n), "Mc w20": np.minimum(np.arange(n) * 2, mI.n_frames - 1)}
    frames = pw.pose_frames(n, 3)
    fig, axes = pw.plot_aligned_poses(mI, mT, maps, frames)
    assert axes.shape == (3, 3)
    assert [ax.get_title() for ax in axes[0]] == ["T 0", "T 30", "T 60"]
    assert [ax.get_title() for ax in axes[2]] == ["I 0", "I 60", "I 60"]
    n_bones = int((mT.skeleton.parents >= 0).sum())
    assert len(axes[0, 0].lines) == n_bones + 1  # one line per bone, plus the joint dots
    # side elevation: vertical = y (up), the head above the feet
    head = axes[0, 0].lines[-1].get_ydata().max()
    assert head > 100


def _statement_case(**maps):
    """A hand-made walk pair: n = 40 target frames, m = 80 input frames, DTW's map 2q,
    gait cycles of 25 input and 10 target frames; ``maps`` replace the defaults (DTW's)."""
    q = np.arange(41)
    P = 2 * q
    base = {"DTW": P, "Mb w80": P, "Mc w20": P, "Mc w80": P}
    return dict(pair="in -> tg", maps={**base, **maps}, input_cycle=25, target_cycle=10, m=80)


def test_fig8_statements_hand_checked():
    q = np.arange(41)
    P = 2 * q
    stuck = np.minimum(P, 4)  # input frame 4 held from target frame 2 to 40: 39 frames
    ahead = np.where(q >= 10, np.minimum(P + 25, 80), P)  # 25 input frames ahead at q = 10..27
    close = np.minimum(P + 1, 80)  # 1 frame off on q = 1..39, 0 at q = 40
    rows = pw.fig8_statements([_statement_case(**{"Mc w20": stuck, "Mc w80": ahead,
                                                  "Mb w80": close})])  # fmt: skip
    by = {r["statement"]: r for r in rows}
    assert list(by) == ["Mc w20 fails", "Mc w20 sticks early", "Mc w80 skips a walk cycle",
                        "Mb w80 stays close to DTW"]  # fmt: skip
    # eq. 3: sum over q = 3..40 of (2q - 4), over 40 = 1482 / 40
    assert by["Mc w20 fails"]["value"] == pytest.approx(1482 / 40)
    assert by["Mc w20 fails"]["holds"] and by["Mc w20 fails"]["threshold"] == 18
    assert by["Mc w20 sticks early"]["value"] == 39 and by["Mc w20 sticks early"]["holds"]
    assert by["Mc w20 sticks early"]["threshold"] == 10  # one target gait cycle
    assert by["Mc w80 skips a walk cycle"]["value"] == 25  # exactly one input cycle: holds
    assert by["Mc w80 skips a walk cycle"]["holds"]
    assert by["Mb w80 stays close to DTW"]["value"] == pytest.approx(39 / 40)
    assert by["Mb w80 stays close to DTW"]["holds"]
    assert {r["pair"] for r in rows} == {"in -> tg"}


def test_fig8_statements_fail_where_the_words_do_not_fit():
    q = np.arange(41)
    P = 2 * q
    # runs to the last input frame at q = 8 and stays there: the input run out, not a stick
    run_out = np.minimum(10 * q, 80)
    # a long hold that starts late (q = 20 >= 40 / 3) is not "early"
    late = np.where(q >= 20, 40, P)
    far = np.minimum(P + 30, 80)  # Mb w80 30 frames ahead nearly everywhere
    case = _statement_case(**{"Mc w20": run_out, "Mc w80": np.minimum(P + 24, 80), "Mb w80": far})
    by = {r["statement"]: r for r in pw.fig8_statements([case])}
    assert by["Mc w20 sticks early"]["value"] == 1 and not by["Mc w20 sticks early"]["holds"]
    assert by["Mc w20 fails"]["holds"]  # far from DTW all the same
    assert by["Mc w80 skips a walk cycle"]["value"] == 24  # one frame short of a cycle
    assert not by["Mc w80 skips a walk cycle"]["holds"]
    assert not by["Mb w80 stays close to DTW"]["holds"]
    by = {r["statement"]: r for r in pw.fig8_statements([_statement_case(**{"Mc w20": late})])}
    assert by["Mc w20 sticks early"]["value"] == 1 and not by["Mc w20 sticks early"]["holds"]
    assert not by["Mc w20 fails"]["holds"]  # sum of 2q - 40 over q = 21..40 is 420; / 40
    assert by["Mc w20 fails"]["value"] == pytest.approx(10.5)
    # the statement counts over pairs
    rows = pw.fig8_statements([case, _statement_case()])
    counts = pw.statement_counts(rows)
    assert counts["Mc w20 fails"] == {"holds": 1, "pairs": 2}
    assert counts["Mb w80 stays close to DTW"] == {"holds": 1, "pairs": 2}
    assert list(counts) == list(pw.FIG8_STATEMENT_RULES)


def test_walk_pairs_are_the_six_ordered_pairs_of_the_authors_walk_takes():
    pairs = pw.walk_pairs()
    names = [(a.name, b.name) for a, b in pairs]
    takes = ("Walk_01", "Walk_02", "Walk_03")
    assert names == [(a, b) for a in takes for b in takes if a != b]
    assert all(a.movement == b.movement == "Walk" for a, b in pairs)


def test_gait_cycle_from_the_autocorrelation_or_the_papers_gait():
    f = np.arange(600)
    swing = one_joint_motion(30.0 * np.sin(2 * np.pi * f / 50.0), "X")  # a 50-frame cycle
    assert pw.gait_cycle(swing) == (50, "autocorrelation")
    still = one_joint_motion(np.zeros(200), "X")  # nothing moves: no period
    # the middle of the paper's 0.82-0.9 Hz at 120 Hz: 120 / 0.86 = 139.5 -> 140 frames
    assert numbers.WALK_GAIT_HZ == (0.82, 0.9)
    assert pw.gait_cycle(still) == (140, "paper's gait")


# --- Fig. 9: Type V -----------------------------------------------------------------------


def test_backward_and_forward_type_v_steps():
    steps = pt.backward_steps()
    assert [S[0].tolist() for S in steps] == [[-3, -1], [-2, -1], [-1, -1], [-1, -2], [-1, -3]]
    np.testing.assert_array_equal(steps[0], [[-3, -1], [-2, 0], [-1, 0], [0, 0]])
    np.testing.assert_array_equal(steps[4], [[-1, -3], [0, -2], [0, -1], [0, 0]])
    assert pt.forward_advances(steps) == [(1, 0, 0), (1, 0), (1,), (2,), (3,)]


def test_forward_advances_of_symmetric1():
    from dtw import symmetric1

    adv = pt.forward_advances(pt.backward_steps(symmetric1))
    assert sorted(adv) == [(), (0,), (1,)]  # input-only step: no new target frame


def test_typev_states_hand_checked():
    M = [0, 1, 1, 1, 3, 4, 4]
    # N -(1)-> A1 -(0)-> H1 -(0)-> N -(2)-> N -(1)-> A1 -(0)-> H1
    assert pt.typev_states(M) == ["", "N", "A1", "H1", "N", "N", "A1"]
    with pytest.raises(ValueError):
        pt.typev_states([0, 0])  # no hold from the start state
    with pytest.raises(ValueError):
        pt.typev_states([0, 1, 1, 1, 1])  # third hold


def test_typev_states_match_the_aligner(walk_short):
    I, T = (MotionFeatures.from_motion(m) for m in walk_short)
    aligner = MethodA(I, constraint="typeV", record=True)
    M, got = [], []
    for q in range(T.n_frames):
        M.append(aligner.step(T.frame(q)))
        got.append(aligner.window_snapshot().state)
    assert got[1:] == pt.typev_states(M)[1:]


def test_table_rows_and_state_table_plot():
    rows = pt.table_rows()
    assert [r["state"] for r in rows] == ["N", "A1", "H1"]
    assert [r["advance 0"] for r in rows] == ["-", "H1", "N"]
    assert all(r["advance 1"] == "A1" and r["advance 2"] == r["advance 3"] == "N" for r in rows)
    fig, ax = pt.plot_state_table()
    cells = ax.tables[0].get_celld()
    assert len(cells) == 4 * 5
    assert cells[(1, 1)].get_text().get_text() == "-"
    assert cells[(2, 1)].get_text().get_text() == "H1"


def test_constrained_path_and_fig9():
    M = np.array([0, 1, 1, 1, 3, 4, 4])
    fig, ax = pt.plot_constrained_path(M, M_free=[0, 0, 0, 0, 2, 4, 4])
    assert len(ax.lines) == 2
    assert [t.get_text() for t in ax.texts] == ["N", "A1", "H1", "N", "N", "A1"]
    fig, axes = pt.plot_fig9(M)
    assert len(axes) == 4
    assert len(axes[0].lines) == 5 + 1 and len(axes[1].lines) == 5 + 1  # steps + end cell
    assert axes[2].tables


# --- facts JSON -------------------------------------------------------------------------


def test_save_facts_roundtrip_and_deterministic(tmp_path, monkeypatch):
    monkeypatch.setenv("FPDTW_RESULTS_DIR", str(tmp_path))
    facts = {
        "b": np.int64(3),
        "a": np.array([0.1234567891, 2.0]),
        "nan": float("nan"),
        "flag": np.bool_(True),
        "nested": {"x": (1, 2)},
    }
    p = pf.save_facts("99_test", facts, smoke=True)
    assert p == tmp_path / "smoke" / "figs" / "99_test.json"
    first = p.read_bytes()
    pf.save_facts("99_test", facts, smoke=True)
    assert p.read_bytes() == first
    assert list(json.loads(first)) == ["a", "b", "environment", "flag", "nan", "nested"]
    loaded = json.loads(p.read_text())
    assert loaded.pop("environment")["packages"]["numpy"] == np.__version__
    assert loaded == {
        "a": [0.123457, 2.0],
        "b": 3,
        "flag": True,
        "nan": None,
        "nested": {"x": [1, 2]},
    }
    assert pf.facts_path("99_test", False) == tmp_path / "full" / "figs" / "99_test.json"
    assert not list(tmp_path.rglob("*.part"))
