"""Replay a recorded take as if it were being captured, and align it online.

:func:`replay` feeds the TARGET motion to an online aligner one frame at a time at the
target's own frame rate (frame ``q`` is "captured" at ``q / fps`` seconds after the
start), measures how long each ``step`` takes, and reports the latency against the frame
budget ``1 / fps`` (8.33 ms at 120 Hz) and the frames that were answered too late.

Definitions (:class:`LiveReport`):

* step time: wall time of the aligner's ``step`` call for the frame (``time.perf_counter``).
  Feature extraction (local rotations, unwrapped Euler angles, positions) is done for
  the whole target before the replay and is not included; each frame's features depend
  only on that frame and the ones before it.
* due time of frame ``q``: ``q / fps`` after the start.
* a frame is DROPPED when its answer (the end of its step) comes after the NEXT frame's
  due time, ``(q + 1) / fps``: a renderer showing one frame per capture tick would have
  had nothing new to show. Every frame is still processed (the aligners need every
  frame); a late step delays the start of the next one.

``realtime=True`` waits (``time.sleep``, then a short spin) until each frame's due time
on the monotonic ``perf_counter`` clock. ``realtime=False`` (tests, notebooks) runs the
steps back to back as fast as possible and derives start and finish times on the
simulated schedule: frame ``q`` starts at ``max(due_q, finish_{q-1})`` and finishes one
measured step time later, which is what real time would give if the steps took as long.

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
    """What happened during a replay.

    Attributes
    ----------
    M : ndarray of int64, shape (n,)
        Input frame the aligner returned for each target frame.
    step_s : ndarray of float64, shape (n,)
        Step time of each frame, seconds.
    due_s, start_s, finish_s : ndarray of float64, shape (n,)
        Due time, start and end of each frame's step, seconds after the start of the
        replay (simulated schedule when ``realtime`` is False).
    fps : float
        Target frame rate; the budget is ``1 / fps``.
    realtime : bool
        Whether the replay waited for each frame's due time.
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
        """Time between two captured frames, ``1 / fps`` seconds."""
        return 1.0 / self.fps

    @property
    def dropped(self) -> np.ndarray:
        """bool (n,): the frame's step ended after the next frame's due time."""
        next_due = self.due_s + self.budget_s
        return self.finish_s > next_due

    @property
    def n_dropped(self) -> int:
        return int(self.dropped.sum())

    @property
    def response_s(self) -> np.ndarray:
        """Time from each frame's due time to its answer, seconds, shape (n,)."""
        return self.finish_s - self.due_s

    def percentiles(self, of: str = "step") -> dict:
        """Percentiles and maximum, seconds: keys ``p50, p90, p99, max``.

        ``of="step"``: step times; ``of="response"``: due time to answer (includes waiting
        for a late previous frame and, in real time, the operating system's wake-up delay).
        """
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
    """Feed the first target frames once, untimed, then reset the aligner.

    The first ``step`` of a numba-compiled aligner loads (or compiles) its kernels, which
    takes far longer than a frame; a live system would do this before the performance.

    Parameters
    ----------
    aligner : OnlineAligner
    T : MotionFeatures
        Target frames to feed (the first ``frames`` of them).
    frames : int

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
    on_frame=None,
    warmup_frames: int = 8,
) -> LiveReport:
    """Replay the target at its own frame rate and align it online, frame by frame.

    Parameters
    ----------
    I_motion : Motion or MotionFeatures
        The recorded (input) motion.
    T_motion : Motion or MotionFeatures
        The "live" (target) motion, fed one frame at a time at ``T.fps``.
    aligner_factory : callable
        ``aligner_factory(I_features) -> OnlineAligner`` (e.g. ``lambda I: MethodC(I, 40)``).
    realtime : bool
        Wait for each frame's due time (True) or run as fast as possible and simulate the
        schedule (False); see the module docstring.
    position_joints : sequence of str, optional
        Joints whose positions the features carry (OPW needs
        :data:`fpdtw.motion.joints.OPW_JOINTS`).
    clock, sleep : callable
        Monotonic clock (seconds) and sleep function; replaceable for tests.
    on_frame : callable, optional
        ``on_frame(q, M_q)`` after each frame (e.g. to drive a display).
    warmup_frames : int
        Untimed steps over the first target frames before the replay, then a reset
        (:func:`warm_up`: just-in-time compilation happens there, not in frame 0).

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
        if on_frame is not None:
            on_frame(q, int(M[q]))
    return LiveReport(M, step, due, start, finish, fps, bool(realtime), aligner.name)


# -- plots ------------------------------------------------------------------------------


def plot_latency(reports, ax=None, bins=40):
    """Histogram of step times (ms, log scale) with the frame budget as a vertical line.

    Parameters
    ----------
    reports : LiveReport or sequence of LiveReport
        One histogram per report (labelled by aligner name).
    ax : matplotlib.axes.Axes, optional
    bins : int
        Logarithmically spaced bins over the range of all step times and the budget.

    Returns
    -------
    fig, ax

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
    edges = np.geomspace(lo, hi, bins + 1)
    for r in reports:
        ax.hist(r.step_s * 1e3, bins=edges, histtype="step", lw=1.5, label=r.name)
    ax.axvline(budget_ms, color="k", ls="--", lw=1)
    ax.text(budget_ms, ax.get_ylim()[1] * 0.95, f"budget {budget_ms:.2f} ms ", va="top", ha="right")
    ax.set_xscale("log")
    ax.set_xlabel("time to process one target frame (ms)")
    ax.set_ylabel("frames")
    ax.legend(loc="upper center", frameon=False)
    return fig, ax


def plot_map_comparison(maps: dict, M_ref, axes=None, ref_label="offline DTW", fps=None):
    """Online maps against a reference map (e.g. offline DTW), and their deviation.

    Parameters
    ----------
    maps : dict of str to array_like of int, each shape (n,)
        Maps to compare, by label.
    M_ref : array_like of int, shape (n,)
        Reference map.
    axes : sequence of two Axes, optional
        Left: input frame against target frame; right: ``|M - M_ref|`` per target frame
        (symmetric log scale: linear below 1 frame).
    fps : float, optional
        Draw the FP-DTW paper's 150 ms line (18 frames at 120 Hz) on the right panel.

    Returns
    -------
    fig, axes

    Paper: FP-DTW eq. 3 (deviation from DTW).
    Notebook: 20_align_a_live_performance.ipynb
    """
    import matplotlib.pyplot as plt

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
    axes[1].set_yscale("symlog", linthresh=1.0)  # 0..1 linear, then logarithmic
    axes[1].set_ylim(bottom=0)
    axes[1].set_xlabel("target (live) frame")
    axes[1].set_ylabel(f"|map - {ref_label}| (frames)")
    return fig, axes


__all__ = ["LiveReport", "plot_latency", "plot_map_comparison", "replay", "warm_up"]
