"""OPW read as the authors' MotionBuilder plugin does it, and the plugin's baseline.

Hand-worked cases as in ``test_opw.py``: one joint moving along x, the recording A at
1 unit/s (``A(t) = t``), 4 frames per second, ``omega = 0.25`` s, so every time and
position is exact in binary floating point.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from test_opw import FPS, OMEGA, linear

from fpdtw import plain
from fpdtw.online.base import run_online
from fpdtw.online.opw import OPW, opw_step
from fpdtw.paper import catalog
from fpdtw.paper import opw_eval as oe
from fpdtw.warpcurve import WarpCurve

# -- one step: where the recording is read, and which way a change goes ----------------------


def _bent_curve():
    """A curve whose value at t = 0.5 (0.375) is not t * D_A / x_last (= 2 t = 1.0)."""
    return WarpCurve([0.0, 1.0, 2.0], [0.0, 1.0, 4.0])


def test_ratio_reference_reads_the_recording_at_t_times_the_global_ratio():
    A = linear(1.0).positions  # A(t) = t, 4 s
    # live = recording: B(0.5) = 0.5, B(0.25) = 0.25, b_hat = 0.75
    f = _bent_curve()
    assert f(0.5) == pytest.approx(0.375)
    # the poster: A at f(0.5) + (0, 1, 2) 0.25 = 0.375, 0.625, 0.875 -> costs 0.375, 0.125,
    # 0.125: p_1 and p_2 tie for the smallest -> keep (strict inequalities)
    s, p = plain.opw_step(f, 0.5, A, A, OMEGA, 0.25, FPS, FPS)
    assert s == 1 and p == pytest.approx([0.375, 0.125, 0.125])
    assert f.n_keys == 3
    # the plugin: r = D_A / x_last = 4 / 2 = 2, A at (0.5 + (0, 1, 2) 0.25) * 2 = 1, 1.5, 2
    # -> costs 0.25, 0.75, 1.25 -> s = 0 (the current sample closest): slow A down
    s, p = opw_step(f, 0.5, A, A, OMEGA, 0.25, FPS, FPS, reference="ratio")
    assert s == 0 and p == [0.25, 0.75, 1.25]
    # a key pinned at (0.5, f(0.5)), the last key moved later by 0.25 of the time left:
    # 2 + (2 - 0.5) * 0.25 = 2.375; its value (D_A) never moves
    assert np.allclose(f.keys, [[0, 0], [0.5, 0.375], [1, 1], [2.375, 4]])


def test_readme_direction_is_the_opposite_sign():
    A = linear(1.0).positions
    f = _bent_curve()
    s, _ = opw_step(f, 0.5, A, A, OMEGA, 0.25, FPS, FPS, "ratio", "readme")
    assert s == 0  # the same decision ...
    assert f.x[-1] == 2 - 1.5 * 0.25  # ... but the recording speeds up: 1.625
    with pytest.raises(ValueError, match="direction"):
        opw_step(_bent_curve(), 0.5, A, A, OMEGA, 0.25, FPS, FPS, direction="up")
    with pytest.raises(ValueError, match="reference"):
        opw_step(_bent_curve(), 0.5, A, A, OMEGA, 0.25, FPS, FPS, reference="warp")


def test_ratio_reference_agrees_with_the_curve_until_the_last_key_moves():
    # first step (t = 0.25): x_last = D_A, r = 1, so (t + i omega) r = f(t) + i omega; the
    # step moves the last key (v = 2: s = 2), and from the second step on they differ
    A, B = linear(1.0), linear(2.0)
    poster = OPW(A, omega=OMEGA, gamma=0.05)
    ratio = OPW(A, omega=OMEGA, gamma=0.05, reference="ratio")
    run_online(poster, B)
    run_online(ratio, B)
    assert poster.decisions[0] == ratio.decisions[0]
    assert poster.decisions[0].s == 2
    d = ratio.decisions[1]  # t = 0.5: A at (0.5 + i 0.25) * 4 / 3.8125
    r = 4 / 3.8125
    assert d.costs == pytest.approx(tuple(abs(1.5 - (0.5 + i * 0.25) * r) for i in range(3)))
    assert d.costs != poster.decisions[1].costs


def test_frame_clock_steps_at_the_first_frame_strictly_after_the_previous_step_plus_omega():
    # 4 fps, omega 0.25: frame 1 (t = 0.25) is not STRICTLY later than 0 + 0.25, so the
    # plugin steps at every second frame: 0.5, 1.0, 1.5, ...
    A, B = linear(1.0), linear(1.0)
    opw = OPW(A, omega=OMEGA, gamma=0.05, clock="frames")
    run_online(opw, B)
    assert [d.t for d in opw.decisions] == [0.5 * k for k in range(1, 8)]
    # 10 fps: steps at 0.3 (> 0.25), 0.6 (> 0.55), 0.9 (> 0.85), ...
    A, B = linear(1.0, fps=10.0), linear(2.0, fps=10.0)
    opw = OPW(A, omega=OMEGA, gamma=0.05, reading="plugin")
    done = []
    for q in range(10):
        opw.step(B.frame(q))
        done.append(len(opw.decisions))
    assert done == [0, 0, 0, 1, 1, 1, 2, 2, 2, 3]
    t = [d.t for d in opw.decisions]
    assert t == pytest.approx([0.3, 0.6, 0.9])
    # first step: b_hat = B(0.3) + (B(0.3) - B(0.05)) = 0.6 + 0.5 = 1.1 (B(0.05) between
    # frames 0 and 1); r = 1: costs |1.1 - 0.3|, |1.1 - 0.55|, |1.1 - 0.8| -> s = 2
    d = opw.decisions[0]
    assert d.costs == pytest.approx((0.8, 0.55, 0.3)) and d.s == 2
    assert d.x_last == pytest.approx(4 - 3.7 * 0.05)
    # the second step reads A at (0.6 + i 0.25) * 4 / x_last
    r = 4 / d.x_last
    b_hat = 1.2 + (1.2 - 0.7)
    assert opw.decisions[1].costs == pytest.approx(
        tuple(abs(b_hat - (0.6 + i * 0.25) * r) for i in range(3))
    )


def test_plugin_aligner_is_a_loop_of_the_plain_step():
    rng = np.random.default_rng(3)
    PA = np.cumsum(rng.normal(size=(90, 16, 3)), axis=0)
    PB = PA[np.clip(np.round(np.arange(100) * 0.85).astype(int), 0, 89)]
    Q = np.tile([1.0, 0, 0, 0], (100, 8, 1))
    from fpdtw.motion.features import MotionFeatures

    I = MotionFeatures.from_arrays(Q[:90], fps=30.0, positions=PA)
    T = MotionFeatures.from_arrays(Q, fps=30.0, positions=PB)
    opw = OPW(I, omega=0.04, gamma=0.1, reading="plugin")
    run_online(opw, T)
    f = WarpCurve.identity(89 / 30.0)
    prev, got = 0.0, []
    for q in range(T.n_frames):
        t = q / 30.0
        if t > prev + 0.04 + 1e-9:  # the plugin's clock
            prev = t
            if t < f.x[-1]:
                got.append(opw_step(f, t, PA, PB[: q + 1], 0.04, 0.1, 30.0, 30.0, "ratio"))
    assert [s for s, _ in got] == [d.s for d in opw.decisions] and {0, 2} <= {s for s, _ in got}
    np.testing.assert_array_equal(f.keys, opw.curve.keys)
    assert np.diff([d.t for d in opw.decisions]) == pytest.approx(2 / 30.0)  # every 2nd frame


def test_bad_options():
    A = linear(1.0)
    for kw in ({"reading": "authors"}, {"reference": "warp"}, {"clock": "ticks"},
               {"direction": "up"}):  # fmt: skip
        with pytest.raises(ValueError):
            OPW(A, **kw)
    opw = OPW(A, reading="plugin", clock="exact")  # one option overridden
    assert (opw.reference, opw.clock, opw.direction) == ("ratio", "exact", "code")


# -- the plugin's "standard DTW" baseline ---------------------------------------------------


def test_best_match_map_is_monotone_and_steps_at_most_two():
    best = [1, 0, 3, 7, 8, 8, 5]
    C = np.ones((len(best), 10))
    C[np.arange(len(best)), best] = 0.0
    C[2, 9] = 0.0  # a tie: the first minimum (3) wins
    # 1; 0 < 1 -> 1; 3; 7 > 3 + 2 -> 5; 8 -> 7; 8; 5 < 8 -> 8
    assert oe.best_match_map(C).tolist() == [1, 1, 3, 5, 7, 8, 8]


def test_best_match_keys_and_curve():
    # non-sequential steps into 1, 2, 3, 4; 5 is sequential; 6 is the last
    assert oe.best_match_keys([1, 1, 3, 5, 7, 8, 8]).tolist() == [1, 2, 3, 4, 6]
    # a repeat followed by a repeat gets no key (2, 6); the last is kept although sequential
    assert oe.best_match_keys([0, 1, 1, 1, 2, 3, 5, 5, 6]).tolist() == [3, 7, 8]
    assert oe.best_match_keys([0, 1, 2]).tolist() == [2]
    # keys (M_i P, i P); sample 1 matched live 0: its key replaces (0, 0)
    f = oe.best_match_warp([0, 0, 1, 2], 1.0)
    assert f.keys.tolist() == [[0.0, 1.0], [2.0, 3.0]]
    f = oe.best_match_warp([1, 1, 3, 5, 7, 8, 8], 0.5)
    want = [[0, 0], [0.5, 0.5], [1.5, 1.0], [2.5, 1.5], [3.5, 2.0], [4.0, 3.0]]
    assert f.keys.tolist() == want
    f = oe.best_match_warp([0, 0, 0], 0.5, span=2.0)  # everything matched live 0
    assert f.keys.tolist() == [[0.0, 1.0], [2.0, 1.0]]


def test_plugin_period_is_whole_milliseconds():
    assert [oe.plugin_period(f) for f in (120.0, 30.0, 25.0, 60.0)] == [0.008, 0.033, 0.04, 0.016]


@pytest.fixture(scope="module")
def handshake():
    return catalog.load("cmu", "18_01.bvh").crop(0.0, 2.5)


def test_best_match_curve_on_real_motions(handshake):
    A = handshake
    P = oe.plugin_period(A.fps)
    # A against itself: every sample matches itself, so the map is sequential and the curve
    # is the identity up to the last sample before the end (times < D_A, as the plugin)
    f = oe.best_match_curve(A, A)
    last = (math.ceil(2.5 / P) - 1) * P
    assert np.allclose(f.keys, [[0, 0], [last, last]])
    g = oe.example_curve(2.5, 0.25)
    f = oe.best_match_curve(A, oe.warp_motion(A, g))
    dev = oe.deviation_ms(f, g)
    assert dev["max"] < 2 * 1000 * P  # within two samples of the example everywhere
    assert np.all(np.diff(f(np.linspace(0, 2.5, 200))) >= -1e-12)


# -- the readings of the whole protocol -------------------------------------------------------


def test_evaluate_under_both_readings(handshake):
    res = oe.evaluate(handshake, reading="plugin")
    assert res["reading"] == "plugin" and res["baseline"] == "best match"
    assert set(res["curves"]) == {"example", "DTW", "best match", "OPW"}
    ref = oe.run_opw(handshake, oe.warp_motion(handshake, res["curves"]["example"]),
                     reading="plugin")  # fmt: skip
    np.testing.assert_array_equal(ref.curve.keys, res["curves"]["OPW"].keys)
    assert (ref.reference, ref.clock) == ("ratio", "frames")
    poster = oe.evaluate(handshake)
    lag = oe.reference_lag(poster)
    np.testing.assert_array_equal(lag["reference_ms"], lag["curve_ms"])  # read through f
    lag = oe.reference_lag(res)
    assert lag["reference_mean_abs_ms"] != lag["curve_mean_abs_ms"]
    with pytest.raises(ValueError, match="unknown OPW reading"):
        oe.evaluate(handshake, reading="authors")


def test_reference_lag_by_hand():
    res = {
        "decisions": {"t": np.array([0.5, 1.0]), "t_warped": np.array([0.5, 0.9]),
                      "x_last": np.array([2.0, 2.5])},
        "curves": {"example": WarpCurve.identity(2.5)},
        "duration": 2.5,
        "reference": "ratio",
    }  # fmt: skip
    lag = oe.reference_lag(res)
    # step 1: x_last before it is D_A: 0.5; step 2: 1.0 * 2.5 / 2.0 = 1.25
    assert lag["reference_ms"] == pytest.approx([0.0, 250.0])
    assert lag["curve_ms"] == pytest.approx([0.0, -100.0])
    assert lag["reference_mean_abs_ms"] == pytest.approx(125.0)


def _row(motion, method, gamma, ms, removed):
    return dict(motion=motion, method=method, gamma=gamma, offset_s=0.25,
                ms=np.asarray(ms, dtype=float), removed=removed)  # fmt: skip


def test_readings_table_by_hand():
    rows = [
        _row("a", "OPW", 0.05, [10, 30], 0.5), _row("a", "OPW", 0.1, [5, 5], 0.9),
        _row("b", "OPW", 0.05, [20, 20], 0.6), _row("b", "OPW", 0.1, [40, 40], 0.1),
        _row("a", "DTW", 0.05, [1, 3], 0.95), _row("b", "DTW", 0.05, [2, 2], 0.9),
        _row("a", "DTW", 0.1, [1, 3], 0.95), _row("b", "DTW", 0.1, [2, 2], 0.9),
    ]  # fmt: skip
    got = {r["motion"]: r for r in oe.readings_table([("poster", rows)], 0.05)}
    assert list(got) == ["a", "b", "all"]
    a, b, both = got["a"], got["b"], got["all"]
    assert (a["opw_mean_ms"], a["opw_max_ms"], a["opw_removed"]) == (20.0, 30.0, 0.5)
    assert (a["best_gamma"], a["best_gamma_mean_ms"], a["best_gamma_removed"]) == (0.1, 5.0, 0.9)
    assert (b["best_gamma"], b["best_gamma_mean_ms"]) == (0.05, 20.0)
    # pooled: gamma 5 %: mean of 10, 30, 20, 20 = 20; gamma 10 %: 22.5 -> best 5 %
    assert (both["opw_mean_ms"], both["best_gamma"], both["opw_removed"]) == (20.0, 0.05, 0.55)
    assert (both["baseline"], both["baseline_mean_ms"], both["baseline_max_ms"]) == (
        "DTW",
        2.0,
        3.0,
    )
    assert list(a) == list(oe.READINGS_COLUMNS)
    with pytest.raises(ValueError, match="not among"):
        oe.readings_table([("poster", rows)], 0.2)


def test_fig4_facts_take_the_readings_baseline():
    methods = (("DTW", 20.0, 5.0), ("best match", 4.0, 0.5), ("OPW", 60.0, 1.0))
    rows = [dict(motion="a", method=m, mean_ms=v, max_ms=2 * v, slope_mean_pct=1.0,
                 slope_max_pct=s, removed=0.5) for m, v, s in methods]  # fmt: skip
    motions = {"a": oe.FIG4_MOTIONS[0]}
    poster = oe.fig4_facts(rows, motions)
    plugin = oe.fig4_facts(rows, motions, "best match")
    assert poster["dtw_mean_ms_range"] == [20.0, 20.0] and poster["opw_smoother_everywhere"]
    assert plugin["baseline"] == "best match" and plugin["dtw_mean_ms_range"] == [4.0, 4.0]
    assert not plugin["opw_smoother_everywhere"]
    with pytest.raises(ValueError, match="one OPW"):
        oe.fig4_facts(rows[:1], motions)


def test_reading_steps_change_one_thing_at_a_time():
    steps = oe.READING_STEPS
    poster, plugin = oe.READINGS["poster"], oe.READINGS["plugin"]
    assert steps[0] == poster and plugin in steps
    fields = ("reference", "clock", "root_relative")
    for rd in steps[1:4]:
        changed = [k for k in fields if getattr(rd, k) != getattr(poster, k)]
        assert len(changed) == 1 and getattr(rd, changed[0]) == getattr(plugin, changed[0])
    assert steps[-1].direction == "readme" and steps[-1].reference == plugin.reference


def test_plot_readings_and_plugin_fig4(handshake):
    import matplotlib

    matplotlib.use("Agg")
    from fpdtw.paper.figures.opw import plot_deviation, plot_readings

    rows = oe.sweep({"hs": handshake}, gammas=(0.05, 0.1), reading="plugin")
    fig, ax = plot_readings([(oe.READINGS["plugin"], rows)])
    labels = [ln.get_label() for ln in ax.get_lines()]
    assert "plugin" in labels and ax.get_yscale() == "log"
    fig, ax = plot_deviation(oe.evaluate(handshake, reading="plugin"))
    assert [ln.get_label().split(" (")[0] for ln in ax.get_lines()[:2]] == ["best match", "OPW"]


def test_opw_figures_say_what_their_lines_and_whiskers_are_and_whose_clips(handshake):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from fpdtw.paper.figures.opw import (
        clips_note,
        plot_curve_construction,
        plot_deviation_vs_gamma,
        plot_deviation_vs_offset,
        plot_fig4,
        plot_readings,
    )

    def note(fig):
        texts = [t.get_text().replace("\n", " ") for t in fig.texts if t.get_gid() == "opw_note"]
        assert len(texts) == 1
        return texts[0]

    # the clips: the hand shake is the poster's own source take, the other two stand-ins
    everything = clips_note()
    assert "hand gestures = HDM05 HDM_bd_throwBasketball_002_120 (stand-in)" in everything
    assert "arm wrestle = the FP-DTW authors' Shelf_Stack_01 (stand-in)" in everything
    assert "hand shake = CMU 18_01 (the poster's own source take)" in everything
    assert "FIG4_MOTIONS" in everything
    rows = oe.sweep({"hand shake": handshake}, offsets=(0.1, 0.25), gammas=(0.05, 0.15))
    fig, ax = plot_deviation_vs_offset([r for r in rows if r["gamma"] == 0.05])
    text = note(fig)
    assert "whiskers = minimum to maximum of the pooled samples" in text
    assert "the line with dots joins the means" in text and "CMU 18_01" in text
    assert "stand in for the poster's CMU two-person clips" in text
    assert "arm wrestle" not in text  # only the clips the figure shows
    # what the note says is what is drawn: OPW's whiskers at 0.1 s span its samples
    ms = np.concatenate([r["ms"] for r in rows if r["method"] == "OPW" and r["offset_s"] == 0.1
                         and r["gamma"] == 0.05])  # fmt: skip
    vertical = [ln.get_ydata() for ln in ax.lines if len(ln.get_ydata()) == 2]
    ends = [float(y) for ys in vertical if ys[0] != ys[1] for y in ys]
    assert ms.min() in ends and ms.max() in ends
    plt.close(fig)
    fig, ax = plot_deviation_vs_gamma([r for r in rows if r["offset_s"] == 0.25])
    assert "dashed: their maximum" in note(fig) and "whiskers = minimum to maximum" in note(fig)
    plt.close(fig)
    fig, ax = plot_readings([(oe.READINGS["poster"], rows)])
    assert "solid = mean, dashed = maximum" in note(fig) and "hand shake" in note(fig)
    plt.close(fig)
    res = oe.evaluate(handshake)
    fig, axes = plot_fig4([res], labels=["hand shake"])
    assert "Top: warp curves" in note(fig) and "no whiskers" in note(fig)
    assert "hand shake = CMU 18_01" in note(fig)
    plt.close(fig)
    fig, ax = plot_curve_construction(res["curves"]["OPW"], label="hand shake")
    assert "black dots: its keys" in note(fig) and "CMU 18_01" in note(fig)
    plt.close(fig)
    fig, ax = plot_deviation_vs_offset(rows, note=False)
    assert not fig.texts
    plt.close(fig)
