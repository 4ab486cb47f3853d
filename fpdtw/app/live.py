"""Replay a recorded take as if it were being captured, and align it online.

:func:`replay` feeds the TARGET motion to an online aligner one frame at a time at its own
frame rate (frame ``q`` is due ``q / fps`` seconds after the start), times each ``step`` and
reports the latency against the frame budget ``1 / fps`` (8.33 ms at 120 Hz).

* step time: wall time of the aligner's ``step`` (``time.perf_counter``); the features are
  extracted for the whole target beforehand (each frame's depend only on it and earlier ones).
* a frame is DROPPED when its answer comes after the NEXT frame's due time: a renderer
  showing one frame per capture tick had nothing new to show. Every frame is still
  processed, so a late step delays the next one.
* ``realtime=False`` runs the steps back to back and derives the schedule: frame ``q``
  starts at ``max(due_q, finish_{q-1})`` and ends one measured step time later.

Notebook: 20_align_a_live_performance.ipynb
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from fpdtw.motion.features import MotionFeatures

#: Latency percentiles reported by :meth:`LiveReport.percentiles`.
PERCENTILES = (50, 90, 99)


@dataclass
class LiveReport:
    """What happened during a replay: times in seconds after its start, arrays of shape (n,).

    Attributes
    ----------
    M : ndarray of int64
        Input frame returned for each target frame.
    step_s, due_s, start_s, finish_s : ndarray of float64
        Step time of each frame; its due time, start and end (simulated schedule when
        ``realtime`` is False).
    fps : float
        Target frame rate; the budget is ``1 / fps``.
    realtime : bool
    name : str
        Aligner name.

    Paper: FP-DTW Table 2 (time per frame) and Section 1 (real-time use).
    """

    M: np.ndarray
    step_s: np.ndarray
    due_s: np.ndarray
    start_s: np.ndarray
    finish_s: np.ndarray
    fps: float
    realtime: bool
    name: str = ""

    @property
    def n_frames(self) -> int:
        return int(self.M.size)

    @property
    def budget_s(self) -> float:
        return 1.0 / self.fps

    @property
    def dropped(self) -> np.ndarray:
        """bool (n,): the frame's step ended after the next frame's due time."""
        return self.finish_s > self.due_s + self.budget_s

    @property
    def n_dropped(self) -> int:
        return int(self.dropped.sum())

    @property
    def response_s(self) -> np.ndarray:
        """From each frame's due time to its answer, seconds, shape (n,)."""
        return self.finish_s - self.due_s

    def percentiles(self, of: str = "step") -> dict:
        """``p50, p90, p99, max`` in seconds of the step times (``of="step"``) or of the
        response times (``of="response"``: includes waiting for a late previous frame)."""
        x = self.step_s if of == "step" else self.response_s
        out = {f"p{p}": float(np.percentile(x, p)) for p in PERCENTILES}
        out["max"] = float(x.max())
        return out

    def summary(self) -> dict:
        """Plain numbers (milliseconds) for printing or JSON."""
        pct = {k: v * 1e3 for k, v in self.percentiles().items()}
        return {
            "aligner": self.name,
            "frames": self.n_frames,
            "fps": self.fps,
            "realtime": self.realtime,
            "budget_ms": self.budget_s * 1e3,
            **{f"step_{k}_ms": v for k, v in pct.items()},
            "max_response_ms": float(self.response_s.max() * 1e3),
            "dropped": self.n_dropped,
        }

    def table(self) -> str:
        """A small text table: step-time percentiles against the budget, dropped frames."""
        pct = self.percentiles()
        mode = (
            "real time"
            if self.realtime
            else "as fast as possible (real-time schedule simulated from the step times)"
        )
        head = f"{'':<16}" + "".join(f"{k:>9}" for k in (*pct, "budget"))
        rows = [
            f"{label:<16}"
            + "".join(f"{v * 1e3:>9.3f}" for v in (*self.percentiles(of).values(), self.budget_s))
            for label, of in (("step time (ms)", "step"), ("response (ms)", "response"))
        ]
        pc = 100.0 * self.n_dropped / max(self.n_frames, 1)
        return "\n".join(
            [
                f"aligner: {self.name}; {self.n_frames} target frames at {self.fps:g} Hz; {mode}",
                head,
                *rows,
                f"dropped frames: {self.n_dropped} of {self.n_frames} ({pc:.1f} %) "
                "(answer later than the next frame's due time)",
                "(step time: the aligner's work on a frame; response: from the frame's due "
                "time to its answer)",
            ]
        )


def _as_features(motion, position_joints):
    if isinstance(motion, MotionFeatures):
        return motion
    return MotionFeatures.from_motion(motion, position_joints=position_joints)


def warm_up(aligner, T: MotionFeatures, frames: int = 8) -> None:
    """Feed the first ``frames`` target frames once, untimed, then reset the aligner: the
    first ``step`` of a numba aligner loads or compiles its kernels, as a live system would
    before the performance.

    Paper: FP-DTW Table 2 (per-frame times exclude start-up).
    """
    aligner.reset()
    for q in range(min(frames, T.n_frames)):
        aligner.step(T.frame(q))
    aligner.reset()


def _wait_until(deadline, clock, sleep):
    """Sleep until ``deadline`` (clock seconds): coarse sleep, then spin the last 0.5 ms."""
    while True:
        left = deadline - clock()
        if left <= 0:
            return
        if left > 5e-4:
            sleep(left - 5e-4)


def replay(
    I_motion,
    T_motion,
    aligner_factory,
    realtime: bool = True,
    *,
    position_joints=None,
    clock=time.perf_counter,
    sleep=time.sleep,
    warmup_frames: int = 8,
) -> LiveReport:
    """Replay the target at its own frame rate and align it online, frame by frame.

    Parameters
    ----------
    I_motion, T_motion : Motion or MotionFeatures
        The recorded (input) motion and the "live" (target) one, fed at ``T.fps``.
    aligner_factory : callable
        ``aligner_factory(I_features) -> OnlineAligner`` (e.g. ``lambda I: MethodC(I, 40)``).
    realtime : bool
        Wait for each frame's due time, or run as fast as possible and simulate the
        schedule (see the module docstring).
    position_joints : sequence of str, optional
        Joints whose positions the features carry (OPW needs
        :data:`fpdtw.motion.joints.OPW_JOINTS`).
    clock, sleep : callable
        Monotonic clock (seconds) and sleep function; replaceable for tests.
    warmup_frames : int
        Untimed steps before the replay (:func:`warm_up`).

    Returns
    -------
    report : LiveReport

    Paper: FP-DTW Section 1 and Table 2 (per-frame cost against the frame budget).
    Notebook: 20_align_a_live_performance.ipynb
    """
    I = _as_features(I_motion, position_joints)
    T = _as_features(T_motion, position_joints)
    aligner = aligner_factory(I)
    if warmup_frames:
        warm_up(aligner, T, warmup_frames)
    aligner.reset()
    n = T.n_frames
    fps = float(T.fps)
    M = np.empty(n, dtype=np.int64)
    step = np.empty(n)
    due = np.arange(n) / fps
    start = np.empty(n)
    finish = np.empty(n)
    frames = [T.frame(q) for q in range(n)]
    t0 = clock()
    prev_finish = 0.0
    for q in range(n):
        if realtime:
            _wait_until(t0 + due[q], clock, sleep)
        s0 = clock()
        M[q] = aligner.step(frames[q])
        s1 = clock()
        step[q] = s1 - s0
        if realtime:
            start[q] = s0 - t0
            finish[q] = s1 - t0
        else:
            start[q] = max(due[q], prev_finish)
            finish[q] = start[q] + step[q]
        prev_finish = finish[q]
    return LiveReport(M, step, due, start, finish, fps, bool(realtime), aligner.name)


def live_timing_comparison(step_seconds: dict, fps: float) -> list[dict]:
    """Paper | ours rows (:func:`fpdtw.paper.figures.paper_vs_ours.side_by_side`): each
    aligner's median step time (``step_seconds``: name -> seconds per frame) beside the
    paper's Table 2 mean, and the budget ``1 / fps``. Values only: another implementation
    on another machine (claims 4 and 4b decide).

    Paper: FP-DTW Table 2 and its text (the 120 Hz budget of 8333 us).
    Notebook: 20_align_a_live_performance.ipynb
    """
    from fpdtw.paper.figures.paper_vs_ours import side_by_side
    from fpdtw.paper.numbers import TABLE2_US
    from fpdtw.registry import resolve

    out = []
    for name, steps in step_seconds.items():
        a = resolve(name)
        paper = None if (a.typev or a.options) else TABLE2_US.get((a.family, a.w))
        med = float(np.median(np.asarray(steps, dtype=float))) * 1e6
        out.append(
            side_by_side(
                f"{name}: time per frame",
                "not in Table 2" if paper is None else f"{paper:.0f} us (mean)",
                f"{med:.0f} us (median; budget {1e6 / fps:.0f} us)",
            )
        )
    return out


def plot_latency(reports, ax=None):
    """Histogram of step times (ms, log scale), one per report, with the frame budget.

    Paper: FP-DTW Table 2 (per-frame time).
    Notebook: 20_align_a_live_performance.ipynb
    """
    from fpdtw.paper.figures.plotting import new_axes

    if isinstance(reports, LiveReport):
        reports = [reports]
    fig, ax = new_axes(ax, figsize=(6, 3.2))
    budget_ms = reports[0].budget_s * 1e3
    allms = np.concatenate([r.step_s for r in reports]) * 1e3
    lo = max(allms.min(), 1e-4) / 1.5
    hi = max(allms.max(), budget_ms) * 1.5
    edges = np.geomspace(lo, hi, 40 + 1)
    for r in reports:
        ax.hist(r.step_s * 1e3, bins=edges, histtype="step", lw=1.5, label=r.name)
    ax.axvline(budget_ms, color="k", ls="--", lw=1)
    ax.text(budget_ms, ax.get_ylim()[1] * 0.95, f"budget {budget_ms:.2f} ms ", va="top", ha="right")
    ax.set_xscale("log")
    ax.set_xlabel("time to process one target frame (ms)")
    ax.set_ylabel("frames")
    ax.legend(loc="upper center", frameon=False)
    return fig, ax


def plot_map_comparison(maps: dict, M_ref, axes=None, fps=None):
    """Online ``maps`` against offline DTW's ``M_ref`` (left) and their deviation
    ``|M - M_ref|`` per target frame (right, symmetric log: linear below 1 frame), with the
    FP-DTW paper's 150 ms line when ``fps`` is given.

    Paper: FP-DTW eq. 3 (deviation from DTW).
    Notebook: 20_align_a_live_performance.ipynb
    """
    import matplotlib.pyplot as plt

    ref_label = "offline DTW"
    if axes is None:
        fig, axes = plt.subplots(1, 2, figsize=(9, 3.4), constrained_layout=True)
    else:
        fig = axes[0].figure
    M_ref = np.asarray(M_ref)
    q = np.arange(M_ref.size)
    axes[0].plot(q, M_ref, color="k", lw=2.5, alpha=0.35, label=ref_label)
    for label, M in maps.items():
        M = np.asarray(M)
        axes[0].plot(q, M, lw=1.2, label=label)
        axes[1].plot(q, np.abs(M - M_ref), lw=1.2, label=label)
    if fps:
        axes[1].axhline(0.15 * fps, color="k", ls="--", lw=1)
        axes[1].text(0, 0.15 * fps, " 150 ms", va="bottom")
    axes[0].set_xlabel("target (live) frame")
    axes[0].set_ylabel("input (recorded) frame")
    axes[0].legend(frameon=False)
    axes[1].set_yscale("symlog", linthresh=1.0)
    axes[1].set_ylim(bottom=0)
    axes[1].set_xlabel("target (live) frame")
    axes[1].set_ylabel(f"|map - {ref_label}| (frames)")
    return fig, axes


__all__ = [
    "LiveReport", "live_timing_comparison", "plot_latency", "plot_map_comparison", "replay",
    "warm_up",
]  # fmt: skip
