"""Long inputs (issue 11): online aligners run in memory proportional to the window.

An online aligner keeps the target frames it has received; Methods A, B, C and OLTW read
only the latest of them, so once their history reaches ``fpdtw.limits.HISTORY_FRAMES``
they keep only those (``OnlineAligner.history``). Checked here: the bounded history
gives exactly the maps of the full one; the peak of traced memory (the aligner and the
target stream, measured with tracemalloc) does not grow with the stream's length (the same
after 12,000 and 24,000 target frames, where a growing history would add about 460 bytes
a frame), and a control shows the measurement sees a history that grows; offline DTW of a
one-hour pair is refused before allocating anything.

``make test-all`` (``pytest -m long``) also runs the synthetic one-hour pair (432,000
frames at 120 Hz each) through Method C w40 and OLTW: a peak of a few MiB, where the full
history alone would take about 240 MiB (about 2.5 minutes on 2 cores; ``make test``
leaves it out).
"""

from __future__ import annotations

import time
import tracemalloc

import numpy as np
import pytest
from reference.synthetic import features_from_euler, random_walk_euler

from fpdtw import limits
from fpdtw.dtw import dtw_pair
from fpdtw.errors import LimitError
from fpdtw.io import load_motion
from fpdtw.motion.features import Frame, MotionFeatures
from fpdtw.motion.joints import OPW_JOINTS
from fpdtw.motion.rotations import euler_to_quat
from fpdtw.online import OEDTW, MethodA, MethodB, MethodC
from fpdtw.online.base import run_online
from fpdtw.online.oltw import OLTW
from fpdtw.online.opw import OPW

HOUR = 432_000  # one hour at 120 Hz
WALK = "mocap_single_person_actions/MoCapData/Walk_0{}.fbx"
#: The synthetic target shows input time s(q) = q + A sin(2 pi q / P): a speed varying by
#: +-16 % around the input's (monotone), with a known truth.
A, P = 60.0, 2400.0
#: Peak traced memory allowed for a one-hour run (the aligner, its history and the
#: target stream generated in chunks; not the input features nor the output map):
#: generous, the full history alone would take about 240 MiB.
PEAK_BOUND = 16 * 2**20
#: The growth check: target frames streamed, and the frame count at which the peak is
#: read first. Both are well past the 4096 rows at which the bounded history is compacted
#: (by 24,000 frames it has been compacted five times), so a bounded aligner's peak is the
#: same at both; each kept frame costs about 460 bytes (rotations, Euler angles, map), so
#: a history that grows would add about 5.5 MiB between them.
GROWTH_FRAMES, GROWTH_CHECKPOINT = 24_000, 12_000
#: The peak may grow by at most this much between the two: under 90 bytes per extra frame.
GROWTH_BOUND = 2**20


@pytest.fixture(scope="module")
def walk(data_path):
    motions = [load_motion(data_path(WALK.format(k))) for k in (1, 2)]
    return [MotionFeatures.from_motion(m, position_joints=OPW_JOINTS) for m in motions]


MAKERS = {
    "Ma": lambda I: MethodA(I),
    "Mb w40": lambda I: MethodB(I, 40),
    "Mc w40": lambda I: MethodC(I, 40),
    "Mc w10 + Type V": lambda I: MethodC(I, 10, constraint="typeV"),
    "OLTW c30": lambda I: OLTW(I, 30),
    "OLTW": lambda I: OLTW(I),
}


@pytest.mark.parametrize("label", list(MAKERS))
def test_bounded_history_gives_the_same_maps(walk, label):
    I, T = walk
    full = MAKERS[label](I)
    M_full, _ = run_online(full, T)
    assert full.history_start == 0 and len(full.T_quats) == T.n_frames  # 637 < 4096
    with limits.override(history_frames=64):
        short = MAKERS[label](I)
        M_short, _ = run_online(short, T)
    np.testing.assert_array_equal(M_short, M_full)
    assert short.history_start > 0  # compacted several times
    kept = T.n_frames - short.history_start
    assert len(short.T_quats) == len(short.T_euler) == len(short.M) == kept < 300
    np.testing.assert_array_equal(short.T_quats, T.quats[short.history_start :])
    np.testing.assert_array_equal(short.M, M_full[short.history_start :])


@pytest.mark.parametrize("history", [None, 64])
def test_full_buffers_do_not_leave_the_compiled_step(walk, monkeypatch, history):
    """Method C's one compiled call takes every streamed frame, also those that find its
    buffers full (grown at 256 and 512 rows, or compacted at a 64-row history): the general
    path (a live server's first call of its kernel took 37 ms, at frame 256 of a take) takes
    only the first frame, which allocates the buffer of the positions these features carry;
    the map is the general path's (a recording aligner's)."""
    I, T = walk
    M_general, _ = run_online(MethodC(I, 40, record=True), T)
    general, step = [], MethodC._step
    monkeypatch.setattr(MethodC, "_step", lambda self, q: general.append(q) or step(self, q))
    with limits.override(**({} if history is None else {"history_frames": history})):
        lean = MethodC(I, 40)
        M_lean, _ = run_online(lean, T)
    assert general == [0] and T.n_frames > 512
    assert (lean.history_start > 0) == (history is not None)
    np.testing.assert_array_equal(M_lean, M_general)


def test_aligners_that_read_every_frame_keep_every_frame(walk):
    I, T = walk
    with limits.override(history_frames=64):
        for aligner in (OEDTW(I), OPW(I), MethodC(I, 40, record=True), OLTW(I, record=True)):
            run_online(aligner, T)
            assert aligner.history_start == 0 and len(aligner.T_quats) == T.n_frames
            assert len(aligner.M) == T.n_frames


# ------------------------------------------------------------ long streams, one hour
@pytest.fixture(scope="module")
def hour_input():
    """One hour of a smooth 8-joint random walk at 120 Hz (about 190 MiB of features)."""
    return features_from_euler(random_walk_euler(HOUR, 8, seed=11), name="hour_I")


@pytest.fixture(scope="module")
def growth_input():
    """The first 200 s of the same kind of walk (24,000 frames at 120 Hz)."""
    return features_from_euler(random_walk_euler(GROWTH_FRAMES, 8, seed=11), name="walk_I")


def target_stream(I: MotionFeatures, n: int, chunk: int = 4096):
    """Frames of the target, generated a chunk at a time (never held whole), and the truth.

    Target frame q is the input at time ``s(q) = q + A sin(2 pi q / P)`` frames (Euler
    angles interpolated, then converted in each joint's order).

    Yields
    ------
    frame : Frame
    s : float
    """
    k = I.euler.shape[1]
    for start in range(0, n, chunk):
        q = np.arange(start, min(start + chunk, n), dtype=float)
        s = np.clip(q + A * np.sin(2 * np.pi * q / P), 0, I.n_frames - 1)
        lo = np.floor(s).astype(np.int64)
        hi = np.minimum(lo + 1, I.n_frames - 1)
        a = (s - lo)[:, None, None]
        E = (1 - a) * I.euler[lo] + a * I.euler[hi]
        Q = np.stack([euler_to_quat(E[:, j], I.orders[j]) for j in range(k)], axis=1)
        for i in range(len(q)):
            yield Frame(Q[i], E[i]), s[i]


def run_stream(aligner, I, n, checkpoints=()):
    """Feed n target frames; return the map, the truth and the peak traced bytes above
    the baseline (aligner built and warmed up, output arrays allocated).

    The warm-up (a few frames, then ``reset``) loads the numba kernels and the modules
    the stream uses, one-off costs that are not the aligner's memory. With
    ``checkpoints`` (frame counts), the peak is a list: the peak up to each checkpoint,
    then up to the end.
    """
    for _, (frame, _s) in zip(range(8), target_stream(I, 8), strict=True):
        aligner.step(frame)
    aligner.reset()
    M = np.empty(n, dtype=np.int64)
    truth = np.empty(n)
    marks, peaks = set(checkpoints), []
    tracemalloc.start()
    try:
        base = tracemalloc.get_traced_memory()[0]
        tracemalloc.reset_peak()
        for q, (frame, s) in enumerate(target_stream(I, n)):
            M[q] = aligner.step(frame)
            truth[q] = s
            if q + 1 in marks:
                peaks.append(tracemalloc.get_traced_memory()[1] - base)
        peak = tracemalloc.get_traced_memory()[1] - base
    finally:
        tracemalloc.stop()
    return M, truth, (peaks + [peak] if checkpoints else peak)


def check_map(M, truth, n_input):
    """The map follows the known warp: monotone, to the end, within a few frames."""
    err = np.abs(M - truth)
    assert np.all(np.diff(M) >= 0) and M[-1] >= n_input - 200
    assert np.median(err) <= 3.0 and np.percentile(err, 99) <= 20.0, (np.median(err), err.max())


@pytest.mark.parametrize("label", ["Mc w40", "OLTW"])
def test_memory_does_not_grow_with_the_stream_length(growth_input, label, capsys):
    I = growth_input
    aligner = MAKERS[label](I)
    M, truth, (early, late) = run_stream(aligner, I, GROWTH_FRAMES, [GROWTH_CHECKPOINT])
    with capsys.disabled():
        print(
            f"\n[long input] {label}: peak traced memory {early / 2**20:.3f} MiB after "
            f"{GROWTH_CHECKPOINT} target frames, {late / 2**20:.3f} MiB after {GROWTH_FRAMES}"
        )
    assert aligner.n_received == GROWTH_FRAMES
    assert aligner.history_start > GROWTH_FRAMES - 4096  # compacted
    assert late - early < GROWTH_BOUND, f"grew {(late - early) / 2**20:.2f} MiB"
    assert late < PEAK_BOUND
    check_map(M, truth, I.n_frames)


def test_the_measurement_sees_a_growing_history(growth_input):
    """Control: with the history unbounded, the same measurement grows by megabytes."""
    I = growth_input
    with limits.override(history_frames=10**7):
        grown = MethodC(I, 40)
        _, _, (early, late) = run_stream(grown, I, GROWTH_FRAMES, [GROWTH_CHECKPOINT])
    assert grown.history_start == 0 and len(grown.T_quats) == GROWTH_FRAMES
    assert late - early > 4 * GROWTH_BOUND, f"grew only {(late - early) / 2**20:.2f} MiB"


@pytest.mark.long
@pytest.mark.parametrize("label", ["Mc w40", "OLTW"])
def test_one_hour_pair_runs_in_memory_proportional_to_the_window(hour_input, label, capsys):
    I = hour_input
    aligner = MAKERS[label](I)
    t0 = time.perf_counter()
    M, truth, peak = run_stream(aligner, I, HOUR)
    seconds = time.perf_counter() - t0
    with capsys.disabled():
        print(
            f"\n[long input] {label}: {HOUR} target frames against {I.n_frames} input frames "
            f"in {seconds:.1f} s, peak traced memory above the input features "
            f"{peak / 2**20:.2f} MiB (history kept: {len(aligner.T_quats)} frames)"
        )
    assert aligner.n_received == HOUR and aligner.history_start > HOUR - 4096
    assert peak < PEAK_BOUND
    check_map(M, truth, I.n_frames)


def test_offline_dtw_of_the_one_hour_pair_is_refused():
    # the refusal reads only the sizes: one hour of still frames (identity rotations)
    q = np.zeros((HOUR, 8, 4))
    q[..., 0] = 1.0
    I = MotionFeatures(q, np.zeros((HOUR, 8, 3)), ("XYZ",) * 8, 120.0, None, "hour_I")
    tracemalloc.start()
    try:
        with pytest.raises(LimitError) as info:
            dtw_pair(I, I)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    msg = str(info.value)
    assert msg.startswith("hour_I, hour_I: offline DTW of 432000 input x 432000 target frames")
    assert "(2.72e+03 GiB)" in msg or "TiB" in msg
    assert "use an online method" in msg and "FPDTW_MAX_MATRIX_BYTES" in msg
    assert peak < 2**20  # refused before allocating
