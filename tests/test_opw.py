"""OPW (poster Algorithm 1) and the poster's evaluation.

Hand-worked OPW cases use one joint moving along x at a constant speed, 4 frames per
second and ``omega = 0.25`` s, so every time and position is exact in binary floating
point. The recording A moves at 1 unit/s: ``A(t) = t``; the live motion B at ``v``
units/s. The first step is at ``t = 0.25``: ``b_hat = B(0.25) + (B(0.25) - B(0)) = 0.5 v``,
compared with ``A(0.25) = 0.25``, ``A(0.5) = 0.5``, ``A(0.75) = 0.75``.
"""

from __future__ import annotations

import numpy as np
import pytest

from fpdtw.app.bench import bench_online
from fpdtw.motion.features import MotionFeatures
from fpdtw.online.base import run_online
from fpdtw.online.opw import OPW, interpolate_positions
from fpdtw.paper import catalog
from fpdtw.paper.opw_eval import OMEGA as POSTER_OMEGA
from fpdtw.paper.opw_eval import (
    deviation_ms,
    dtw_curve,
    evaluate,
    example_curve,
    fig3_key_points,
    opw_features,
    run_opw,
    slope_change_percent,
    temporal_difference_removed,
    warp_motion,
)
from fpdtw.warpcurve import WarpCurve

FPS = 4.0
OMEGA = 0.25


def linear(speed, duration=4.0, fps=FPS, direction=(1.0, 0.0, 0.0), joints=1):
    """Features of ``joints`` joints all at ``speed * t * direction`` (root-relative)."""
    n = int(round(duration * fps)) + 1
    t = np.arange(n) / fps
    P = np.zeros((n, joints, 3))
    P[:] = (speed * t)[:, None, None] * np.asarray(direction)[None, None, :]
    Q = np.zeros((n, 8, 4))
    Q[..., 0] = 1.0
    return MotionFeatures.from_arrays(Q, fps=fps, positions=P)


def first_step(speed, gamma=0.05, **kw):
    A = linear(1.0, **kw)
    B = linear(speed, **kw)
    opw = OPW(A, omega=OMEGA, gamma=gamma)
    m0 = opw.step(B.frame(0))
    m1 = opw.step(B.frame(1))
    assert m0 == 0 and len(opw.decisions) == 1
    return opw, m1


def test_ahead_speeds_the_recording_up():
    # v = 2: b_hat = 1.0; costs |1 - 0.25|, |1 - 0.5|, |1 - 0.75| = 0.75, 0.5, 0.25 -> s = 2
    opw, m1 = first_step(2.0)
    d = opw.decisions[0]
    assert d.t == 0.25 and d.t_warped == 0.25
    assert d.costs == (0.75, 0.5, 0.25)
    assert d.s == 2
    # key pinned at (0.25, 0.25); last key: 4 - (4 - 0.25) * 0.05 * (2 - 1) = 3.8125
    assert np.allclose(opw.curve.keys, [[0, 0], [0.25, 0.25], [3.8125, 4.0]])
    assert d.x_last == 3.8125
    assert m1 == 1  # round(f(0.25) * 4) = round(1.0)


def test_behind_slows_the_recording_down():
    # v = 1/4: b_hat = 0.125; costs 0.125, 0.375, 0.625 -> s = 0
    opw, _ = first_step(0.25)
    d = opw.decisions[0]
    assert d.costs == (0.125, 0.375, 0.625)
    assert d.s == 0
    # last key: 4 - (4 - 0.25) * 0.05 * (0 - 1) = 4.1875: the recording ends later
    assert np.allclose(opw.curve.keys, [[0, 0], [0.25, 0.25], [4.1875, 4.0]])


def test_in_step_keeps_the_curve_and_ties_keep():
    opw, _ = first_step(1.0)  # b_hat = 0.5: costs 0.25, 0, 0.25
    assert opw.decisions[0].costs == (0.25, 0.0, 0.25) and opw.decisions[0].s == 1
    assert np.allclose(opw.curve.keys, [[0, 0], [4, 4]])
    opw, _ = first_step(0.75)  # b_hat = 0.375: costs 0.125, 0.125, 0.375 -> tie -> keep
    assert opw.decisions[0].costs == (0.125, 0.125, 0.375) and opw.decisions[0].s == 1
    assert opw.curve.n_keys == 2
    opw, _ = first_step(1.25)  # b_hat = 0.625: costs 0.375, 0.125, 0.125 -> tie -> keep
    assert opw.decisions[0].s == 1


def test_cost_is_sum_of_euclidean_joint_distances():
    # two joints moving along (0.6, 0.8, 0): distances are lengths along the line, and the
    # two joints add: v = 2 -> per joint 0.75, 0.5, 0.25, total 1.5, 1.0, 0.5
    opw, _ = first_step(2.0, direction=(0.6, 0.8, 0.0), joints=2)
    assert np.allclose(opw.decisions[0].costs, (1.5, 1.0, 0.5))
    assert opw.decisions[0].s == 2


def test_gamma_scales_the_move_and_second_step_uses_the_new_curve():
    A = linear(1.0)
    B = linear(2.0)
    opw = OPW(A, omega=OMEGA, gamma=0.2)
    for q in range(3):
        opw.step(B.frame(q))
    d0, d1 = opw.decisions
    assert d0.x_last == 4 - 3.75 * 0.2  # 3.25
    # second step at t = 0.5 reads the curve built by the first step
    ref = WarpCurve([0, 0.25, 3.25], [0, 0.25, 4.0])
    tw = ref(0.5)
    assert d1.t == 0.5 and d1.t_warped == pytest.approx(tw)
    b_hat = 2 * 1.0 - 0.5  # B(0.5) + (B(0.5) - B(0.25)) = 1.5
    assert np.allclose(d1.costs, [abs(b_hat - (tw + i * 0.25)) for i in range(3)])
    assert d1.s == 2  # b_hat = 1.5 is beyond A(tw + 0.5) < 1.2
    assert d1.x_last == pytest.approx(3.25 - (3.25 - 0.5) * 0.2)
    assert np.allclose(opw.curve.x, [0, 0.25, 0.5, d1.x_last])


def test_steps_follow_omega_not_frames_and_interpolate_between_frames():
    # 10 frames per second, omega 0.25: steps at 0.25 (needs frame 3, t = 0.3), 0.5 (frame 5)
    A = linear(1.0, fps=10.0)
    B = linear(2.0, fps=10.0)
    opw = OPW(A, omega=0.25, gamma=0.05)
    done = []
    for q in range(6):
        opw.step(B.frame(q))
        done.append(len(opw.decisions))
    assert done == [0, 0, 0, 1, 1, 2]
    d = opw.decisions[0]
    # B(0.25) = 0.5 interpolated between frames 2 and 3; b_hat = 1.0 as at 4 fps
    assert np.allclose(d.costs, (0.75, 0.5, 0.25))
    P = np.arange(5.0)[:, None, None] * np.ones((1, 1, 3))
    assert np.allclose(interpolate_positions(P, 2.0, 0.75), 1.5)
    assert np.allclose(interpolate_positions(P, 2.0, 9.0), 4.0)  # clamped
    assert np.allclose(interpolate_positions(P, 2.0, 9.0, last=2), 2.0)


def test_map_follows_the_curve_and_stops_at_the_end():
    A = linear(1.0)
    B = linear(2.0, duration=8.0)
    opw = OPW(A, omega=OMEGA, gamma=0.1)
    M, _ = run_online(opw, B)
    assert M[0] == 0 and M[-1] == A.n_frames - 1
    assert np.all(np.diff(M) >= 0) and M.max() <= A.n_frames - 1
    t = np.arange(B.n_frames) / FPS
    assert np.array_equal(M, np.clip(np.rint(opw.curve(t) * FPS), 0, A.n_frames - 1))
    # no decision after the curve's end (the recording has been played out)
    assert all(d.t < d.x_last for d in opw.decisions)
    assert opw.decisions[-1].t < opw.curve.x[-1] <= opw.decisions[-1].t + OMEGA * 4


def test_identity_pair_keeps_the_identity_curve():
    A = linear(1.0)
    opw = OPW(A, omega=OMEGA)
    run_online(opw, A)
    assert all(d.s == 1 for d in opw.decisions) and len(opw.decisions) == 15
    assert np.allclose(opw.curve.keys, [[0, 0], [4, 4]])


def test_reset_and_bad_arguments():
    A = linear(1.0)
    opw = OPW(A, omega=OMEGA)
    run_online(opw, linear(2.0))
    assert opw.curve.n_keys > 2
    opw.reset()
    assert opw.curve.n_keys == 2 and opw.decisions == [] and opw.n_received == 0
    with pytest.raises(ValueError):
        OPW(MotionFeatures(A.quats, A.euler, A.orders, A.fps))  # no positions
    with pytest.raises(ValueError):
        OPW(A, gamma=1.0)
    with pytest.raises(ValueError):
        OPW(A, omega=0.0)


# -- real motions ----------------------------------------------------------------------------


@pytest.fixture(scope="module")
def handshake():
    return catalog.load("cmu", "18_01.bvh").crop(0.0, 2.5)


@pytest.fixture(scope="module")
def hdm():
    path = "HDM05_cut_amc/throwBasketball/HDM_bd_throwBasketball_002_120.amc"
    return catalog.load("hdm05", path).crop(0.0, 2.5)


def test_example_curve_and_warp(hdm):
    g = example_curve(2.5, 0.25)
    assert np.allclose(g.keys, [[0, 0], [1.25, 1.5], [2.5, 2.5]])
    B = warp_motion(hdm, g)
    assert B.n_frames == hdm.n_frames == 301 and B.fps == 120.0 and B.duration == 2.5
    # live 1.25 s (frame 150) shows recording 1.5 s (frame 180), exactly
    assert np.array_equal(B.quats[150], hdm.quats[180])
    assert np.array_equal(B.quats[0], hdm.quats[0]) and np.array_equal(B.quats[300], hdm.quats[300])
    # elsewhere B(t) = A(g(t)) (slerp between A's frames)
    for k in (17, 99, 211, 280):
        q, r = hdm.sample([g(k / 120.0)])
        dots = np.abs((B.quats[k] * q[0]).sum(axis=-1))
        assert np.allclose(dots, 1.0, atol=1e-12)
        assert np.allclose(B.root_translation[k], r[0])
    with pytest.raises(ValueError):
        example_curve(2.5, 1.3)


def test_streaming_never_reads_future_frames(handshake):
    A = handshake
    B = warp_motion(A, example_curve(A.duration, 0.25))
    I, T = opw_features(A), opw_features(B)
    M_ref, _ = run_online(OPW(I), T)
    rng = np.random.default_rng(0)
    for q in (5, 30, 60):
        P = T.positions.copy()
        P[q + 1 :] = rng.normal(scale=50.0, size=P[q + 1 :].shape)
        Tg = MotionFeatures(T.quats, T.euler, T.orders, T.fps, P)
        opw = OPW(I)
        M, _ = run_online(opw, Tg)
        assert np.array_equal(M[: q + 1], M_ref[: q + 1])
    assert np.all(np.diff(M_ref) >= 0) and M_ref[0] == 0


def test_real_identity_pair_stays_near_identity(handshake):
    opw = run_opw(handshake, handshake)
    dev = deviation_ms(opw.curve, WarpCurve.identity(2.5))
    assert dev["max"] < 10.0


def test_dtw_curve_identity_and_fig3_rule(handshake):
    c = dtw_curve(handshake, handshake)
    assert np.allclose(c.keys, [[0, 0], [2.5, 2.5]])
    # steps: diag, del, diag, ins, ins, diag, del, del, del, diag, diag
    path = np.array([(0, 0), (1, 1), (2, 1), (3, 2), (3, 3), (3, 4), (4, 5), (5, 5), (6, 5),
                     (7, 5), (8, 6), (9, 7)])  # fmt: skip
    assert fig3_key_points(path).tolist() == [0, 2, 5, 11]  # the run of 3 gets no key
    assert fig3_key_points(path, max_run=None).tolist() == [0, 2, 5, 9, 11]
    assert fig3_key_points(np.array([(0, 0), (1, 1), (2, 2)])).tolist() == [0, 2]


def test_dtw_curve_of_the_example_warp(handshake):
    A = handshake
    g = example_curve(2.5, 0.25)
    c = dtw_curve(A, warp_motion(A, g))
    assert c.keys[0].tolist() == [0, 0] and c.keys[-1].tolist() == [2.5, 2.5]
    inner = c.keys[1:-1] / 0.04
    assert np.allclose(inner, np.rint(inner))  # keys on the 25 Hz grid
    assert np.all(np.diff(c(np.linspace(0, 2.5, 500))) >= -1e-12)


def test_measures_on_hand_curves():
    g = example_curve(2.5, 0.25)
    ident = WarpCurve.identity(2.5)
    # the identity deviates by g(t) - t, largest (250 ms) at the middle key; at 40 Hz
    # t = 1.25 is a sample
    d = deviation_ms(ident, g, rate=40)
    assert d["t"].size == 101 and d["max"] == pytest.approx(250.0)
    assert d["ms"][50] == pytest.approx(250.0) and d["ms"][0] == 0 and d["ms"][-1] == 0
    shifted = WarpCurve([0, 2.5], [0.1, 2.6])
    d = deviation_ms(shifted, ident)
    assert d["mean"] == pytest.approx(100.0) and d["max"] == pytest.approx(100.0)
    assert d["t"].size == 126  # 50 Hz over [0, 2.5]
    # removed: identity 0, the example itself 1, the half-way curve (keys and slopes the
    # average of identity and example, so the curve is their average) exactly 1/2
    assert temporal_difference_removed(ident, g) == pytest.approx(0.0)
    assert temporal_difference_removed(g, g) == pytest.approx(1.0)
    half = WarpCurve([0, 1.25, 2.5], [0, 1.375, 2.5])
    assert temporal_difference_removed(half, g) == pytest.approx(0.5)
    assert np.isnan(temporal_difference_removed(ident, ident))
    # slope change: a straight line has none; a 45-degree line that holds flat after
    # t = 1 changes by 45 degrees = 50 % at the sample t = 1
    s = slope_change_percent(ident)
    assert np.allclose(s["pct"], 0.0, atol=1e-9)
    s = slope_change_percent(WarpCurve([0, 1], [0, 1]), duration=2.0)
    k = np.flatnonzero(s["pct"] > 1e-9)
    assert k.size == 1 and s["t"][k[0]] == pytest.approx(1.0)
    assert s["pct"][k[0]] == pytest.approx(50.0)


def test_evaluate_and_runner_hooks(handshake):
    res = evaluate(handshake, offset=0.25, gamma=0.05)
    assert set(res["curves"]) == {"example", "DTW", "best match", "OPW"}
    for k in ("DTW", "OPW"):
        dev = res["deviation"][k]
        assert dev["t"].size == 126 and dev["max"] >= dev["mean"] >= 0
        # both aligners remove part of the temporal difference of the example warp
        assert 0 < res["removed"][k] <= 1
    dec = res["decisions"]
    assert dec["costs"].shape == (dec["t"].size, 3) and set(dec["s"]) <= {0, 1, 2}
    I = opw_features(handshake)
    T = opw_features(warp_motion(handshake, res["curves"]["example"]))
    M, sec = run_online(OPW(I, omega=POSTER_OMEGA, gamma=0.05, fps=T.fps), T)
    assert np.array_equal(M, res["M"]) and sec.shape == M.shape
    (row,) = bench_online([(I, T)], names=["OPW"])  # the registry builds OPW for the bench
    assert row["name"] == "OPW" and row["frames"] == T.n_frames
    assert row["p95_s"] >= row["median_s"] > 0


def test_eq4_and_listing_read_the_recording_at_other_frames_where_the_slope_is_not_1():
    """eq. 4 reads A at f(t) + i omega; Algorithm 1's lines 2-3 at f(t + i omega)."""
    from fpdtw import plain

    A = linear(1.0).positions  # A(t) = t, 4 s
    # slope 2: f(t) = 2 t. t = 0.5, omega = 0.25: eq. 4 at 1.0 + (0, 0.25, 0.5) = 1.0,
    # 1.25, 1.5; the listing at f(0.5), f(0.75), f(1.0) = 1.0, 1.5, 2.0
    steep = WarpCurve([0.0, 2.0], [0.0, 4.0])
    assert steep(0.75) == pytest.approx(1.5)
    assert plain.opw_times(steep, 0.5, 0.25, "eq4") == pytest.approx([1.0, 1.25, 1.5])
    assert plain.opw_times(steep, 0.5, 0.25, "listing") == pytest.approx([1.0, 1.5, 2.0])
    # B = A: b_hat = B(0.5) + (B(0.5) - B(0.25)) = 0.75, so p_i = |0.75 - A(time_i)|
    _, p4 = plain.opw_step(WarpCurve([0.0, 2.0], [0.0, 4.0]), 0.5, A, A, OMEGA, 0.25, FPS, FPS)
    _, pl = plain.opw_step(
        WarpCurve([0.0, 2.0], [0.0, 4.0]), 0.5, A, A, OMEGA, 0.25, FPS, FPS, read_at="listing"
    )
    assert p4 == pytest.approx([0.25, 0.5, 0.75]) and pl == pytest.approx([0.25, 0.75, 1.25])
    # slope 1 (the identity): both read 0.5, 0.75, 1.0
    same = WarpCurve.identity(4.0)
    assert plain.opw_times(same, 0.5, 0.25, "eq4") == pytest.approx([0.5, 0.75, 1.0])
    assert plain.opw_times(same, 0.5, 0.25, "listing") == pytest.approx([0.5, 0.75, 1.0])
    with pytest.raises(ValueError, match="read_at"):
        plain.opw_times(same, 0.5, 0.25, "poster")


def test_the_aligner_takes_the_read_at_switch_and_defaults_to_eq4():
    from fpdtw import plain
    from fpdtw.online.opw import opw_step

    A = linear(1.0).positions
    for read_at in ("eq4", "listing"):
        f, g = WarpCurve([0.0, 2.0], [0.0, 4.0]), WarpCurve([0.0, 2.0], [0.0, 4.0])
        assert opw_step(f, 0.5, A, A, OMEGA, 0.25, FPS, FPS, read_at=read_at) == (
            plain.opw_step(g, 0.5, A, A, OMEGA, 0.25, FPS, FPS, read_at=read_at)
        )
        np.testing.assert_array_equal(f.keys, g.keys)
    assert OPW(linear(1.0)).read_at == "eq4"
    with pytest.raises(ValueError, match="read_at"):
        OPW(linear(1.0), read_at="poster")
