"""Live replay (fpdtw.app.live), its plots, and the side-by-side animation (fpdtw.app.animate).

Latency and dropped frames are checked with a fake clock (deterministic step times), never
against the real one.
"""

from __future__ import annotations

import numpy as np
import pytest
from PIL import Image
from reference.synthetic import synthetic_pair

from fpdtw.app import animate
from fpdtw.app.animate import WriterUnavailable, animate_alignment, check_writer
from fpdtw.app.live import LiveReport, plot_latency, plot_map_comparison, replay, warm_up
from fpdtw.io import load_motion
from fpdtw.motion.features import MotionFeatures
from fpdtw.motion.joints import OPW_JOINTS
from fpdtw.online import MethodC
from fpdtw.online.base import OnlineAligner, run_online
from fpdtw.online.oltw import OLTW

SQUAT = "hdm05/HDM05_cut_amc/squat1Reps/HDM_bd_squat1Reps_001_120.amc"
SQUAT2 = "hdm05/HDM05_cut_amc/squat1Reps/HDM_bd_squat1Reps_002_120.amc"
WALK = "mocap_single_person_actions/MoCapData/Walk_01.fbx"


class FakeClock:
    """A clock that only moves when told to (and by ``tick`` per reading)."""

    def __init__(self, tick=0.0):
        self.t = 1000.0
        self.tick = tick
        self.sleeps = []

    def __call__(self):
        self.t += self.tick
        return self.t

    def sleep(self, s):
        assert s > 0
        self.sleeps.append(s)
        self.t += s


class Scripted(OnlineAligner):
    """Maps target frame q to min(q, m); step q takes durations[q] seconds on the fake clock."""

    name = "scripted"

    def __init__(self, I, clock, durations):
        self.clock, self.durations = clock, durations
        super().__init__(I)

    def _step(self, q):
        self.clock.t += self.durations[q]
        return min(q, self.m)


# fps 100: budget 10 ms. Frame 1 overruns (15 ms): it ends at 25 ms > 20 ms (frame 2 due):
# dropped; frame 2 starts late at 25 ms, ends at 26 ms < 30 ms: kept. Frame 3 takes 25 ms:
# 30 -> 55 ms > 40: dropped; frame 4 starts at 55, ends 56 ms > 50 (frame 5 due): dropped;
# frame 5 starts late (56 ms) but ends at 57 < 60; frame 6 starts on time, ends at 69.5 < 70.
DURATIONS_MS = [1, 15, 1, 25, 1, 1, 9.5, 1]
DROPPED = [False, True, False, True, True, False, False, False]


def _features(n, fps=100.0):
    I, _, _ = synthetic_pair(max(n, 20), seed=0)
    return MotionFeatures(I.quats[:n], I.euler[:n], I.orders, fps, None, "fake")


@pytest.mark.parametrize("realtime", [False, True])
def test_dropped_frames_and_latency_on_a_fake_clock(realtime):
    clock = FakeClock(tick=1e-7 if realtime else 0.0)
    T = _features(len(DURATIONS_MS))
    dur = np.array(DURATIONS_MS) / 1e3
    rep = replay(
        T,
        T,
        lambda I: Scripted(I, clock, dur),
        realtime=realtime,
        clock=clock,
        sleep=clock.sleep,
        warmup_frames=0,
    )
    assert isinstance(rep, LiveReport) and rep.realtime == realtime
    np.testing.assert_array_equal(rep.M, np.arange(8))
    np.testing.assert_allclose(rep.step_s, dur, atol=1e-6)
    np.testing.assert_allclose(rep.due_s, np.arange(8) / 100.0)
    assert rep.budget_s == pytest.approx(0.01)
    np.testing.assert_array_equal(rep.dropped, DROPPED)
    assert rep.n_dropped == 3
    # frame 2 waited for frame 1, frame 5 for frame 4; frame 6 started on time
    assert rep.start_s[2] == pytest.approx(0.025, abs=1e-5)
    assert rep.start_s[5] == pytest.approx(0.056, abs=1e-5)
    assert rep.start_s[6] == pytest.approx(0.06, abs=1e-5)
    assert rep.response_s[4] == pytest.approx(0.056 - 0.04, abs=1e-5)
    pct = rep.percentiles()
    assert pct["max"] == pytest.approx(0.025, abs=1e-6)
    assert pct["p50"] == pytest.approx(np.median(dur), abs=1e-6)
    # response: frame 4 answered 16 ms after it was due (it waited 15 ms for frame 3)
    assert rep.percentiles("response")["max"] == pytest.approx(0.025, abs=1e-5)
    assert rep.response_s[4] == pytest.approx(0.016, abs=1e-5)
    if realtime:  # slept until frames 1, 3 and 6 were due (less 0.5 ms of spinning);
        # frames 2, 4, 5 were late, frame 7 was due within 0.5 ms: no sleep
        np.testing.assert_allclose(clock.sleeps, [0.0085, 0.0035, 0.0025], atol=1e-5)
    else:
        assert clock.sleeps == []
    table = rep.table()
    assert "p50" in table and "p99" in table and "budget" in table
    assert "dropped frames: 3 of 8" in table
    s = rep.summary()
    assert s["dropped"] == 3 and s["budget_ms"] == pytest.approx(10.0)


def test_warm_up_resets_the_aligner():
    I, T, _ = synthetic_pair(200, seed=1)
    a = OLTW(I, 30)
    warm_up(a, T, frames=12)
    assert a.n_received == 0
    M, _ = run_online(a, T, reset=False)
    np.testing.assert_array_equal(M, run_online(OLTW(I, 30), T)[0])


@pytest.fixture(scope="module")
def squat_pair(data_path):
    return load_motion(data_path(SQUAT)), load_motion(data_path(SQUAT2))


def test_replay_gives_the_same_map_as_run_online(squat_pair):
    I, T = squat_pair
    FI, FT = MotionFeatures.from_motion(I), MotionFeatures.from_motion(T)
    rep = replay(I, T, lambda F: MethodC(F, 40), realtime=False)
    np.testing.assert_array_equal(rep.M, run_online(MethodC(FI, 40), FT)[0])
    assert rep.name == "Mc w40" and rep.fps == 120.0 and rep.n_frames == T.n_frames
    assert np.all(rep.step_s > 0)
    assert np.all(rep.finish_s >= rep.start_s) and np.all(rep.start_s >= rep.due_s)


def test_replay_with_positions_for_opw(squat_pair):
    from fpdtw.online.opw import OPW

    I, T = squat_pair
    rep = replay(I, T, OPW, realtime=False, position_joints=OPW_JOINTS)
    FI = MotionFeatures.from_motion(I, position_joints=OPW_JOINTS)
    FT = MotionFeatures.from_motion(T, position_joints=OPW_JOINTS)
    np.testing.assert_array_equal(rep.M, run_online(OPW(FI), FT)[0])


def test_plots_return_fig_and_axes(squat_pair):
    I, T = squat_pair
    rep = replay(I, T, lambda F: OLTW(F), realtime=False)
    fig, ax = plot_latency(rep)
    assert ax.get_xscale() == "log"
    budget_lines = [ln for ln in ax.get_lines() if np.allclose(ln.get_xdata(), 1000 / 120)]
    assert len(budget_lines) == 1
    fig2, axes = plot_map_comparison({"OLTW": rep.M}, np.arange(T.n_frames), fps=120)
    assert len(axes) == 2 and len(axes[1].get_lines()) == 2  # deviation + 150 ms line
    np.testing.assert_array_equal(
        axes[1].get_lines()[0].get_ydata(), np.abs(rep.M - np.arange(T.n_frames))
    )
    import matplotlib.pyplot as plt

    plt.close(fig)
    plt.close(fig2)


# ----------------------------------------------------------------------------- animation
def test_animation_gif(squat_pair, tmp_path):
    I, T = squat_pair
    T = T.slice_frames(0, 100)
    M = np.minimum(np.arange(100) * 2, I.n_frames - 1)
    out = animate_alignment(I, T, M, tmp_path / "a.gif", stride=10)
    im = Image.open(out)
    assert im.format == "GIF" and im.n_frames == 10
    assert im.info["duration"] == pytest.approx(1000 * 10 / 120, abs=10)  # plays in real time
    w, h = im.size
    assert w > h > 100


@pytest.mark.parametrize("which", [0, 1])
def test_side_view_is_upright_and_from_the_side(squat_pair, data_path, which):
    I = squat_pair[0] if which == 0 else load_motion(data_path(WALK))
    P = animate._projected(I)
    j = {n: I.skeleton.index(I.joint_map[n]) for n in ("head", "left_ankle", "left_hip",
                                                       "right_hip", "left_knee")}  # fmt: skip
    assert np.all(P[:, j["head"], 1] > P[:, j["left_ankle"], 1])  # head above the feet
    np.testing.assert_allclose(P[:, 0, 0], 0.0, atol=1e-9)  # root-centred horizontally
    # seen from the side: in the first frame both hips project onto the same spot
    assert abs(P[0, j["left_hip"], 0] - P[0, j["right_hip"], 0]) < 1e-6
    if which == 0:  # squatting, the knees come forward: the figure faces right
        deepest = int(np.argmin(P[:, j["head"], 1]))
        assert P[deepest, j["left_knee"], 0] > P[deepest, j["left_hip"], 0]


def test_animation_writers(monkeypatch, tmp_path):
    assert check_writer("x.gif") == "pillow"
    with pytest.raises(WriterUnavailable, match=r"\.gif or \.mp4"):
        check_writer("x.avi")
    monkeypatch.setattr(animate, "ffmpeg_path", lambda: None)
    with pytest.raises(WriterUnavailable, match="ffmpeg"):
        check_writer(tmp_path / "x.mp4")
    monkeypatch.setattr(animate, "ffmpeg_path", lambda: "/usr/bin/ffmpeg")
    assert check_writer("x.MP4") == "ffmpeg"


def test_animation_rejects_a_bad_map(squat_pair, tmp_path):
    I, T = squat_pair
    with pytest.raises(ValueError, match="frames"):
        animate_alignment(I, T, np.zeros(3, dtype=int), tmp_path / "a.gif")
    with pytest.raises(ValueError, match="outside"):
        animate_alignment(I, T, np.full(T.n_frames, I.n_frames), tmp_path / "a.gif")
