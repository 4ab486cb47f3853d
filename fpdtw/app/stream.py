"""``fpdtw stream``: play a recorded take to ``fpdtw serve`` as if it were being captured.

The client sends the take's BVH header, then one motion line per frame at the take's frame
rate (``--rate``: the take resampled to another capture rate first), and reads the
server's answer to each line. It measures the ROUND TRIP of every line: from just before
the line is written to the socket until its answer has been read (``time.perf_counter``),
and prints its percentiles next to the server's own latency (the fourth field of each
answer).

What is sent:

* a ``.bvh`` take at its own rate: the file's own lines, verbatim (so the server parses
  exactly what ``fpdtw align INPUT TAKE.bvh`` reads); any other take, or ``--rate``: the
  motion as :func:`fpdtw.io.bvh.write_bvh` would write it (6 decimals);
* each motion line prefixed with ``t=<capture time>`` (frame number / rate, printed so
  that it reads back as the same float) unless ``timestamps=False`` (the server then times
  frames by their arrival);
* simulated losses and jitter from one seed (deterministic): frame 0 is always sent, each
  later frame is dropped with probability ``drop``; each line is sent ``U(0, jitter_ms)``
  milliseconds after its capture time (never before the previous line: TCP keeps the
  order). Its ``t=`` stays the capture time, as a capture system stamps it.

``fast=True`` sends each line as soon as the previous answer has arrived (no pacing):
quicker for tests, and the round trip then measures the server and the network alone.

:func:`simulate` feeds the very same lines to a :class:`fpdtw.app.serve.Session` in this
process (no network): the answers are the server's, and every target frame the aligner
stepped on is there (notebook 20's drop-rate table).

Notebook: 20_align_a_live_performance.ipynb
"""

from __future__ import annotations

import asyncio
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

#: Percentiles printed and returned.
PERCENTILES = (50, 90, 99)


@dataclass
class TakeLines:
    """A take as the lines a capture system would send.

    Attributes
    ----------
    name : str
    fps : float
        Capture rate (``1 / Frame Time`` of the header).
    header : list of str
        ``HIERARCHY`` through ``Frame Time:``.
    lines : list of str
        One BVH motion line per frame (no ``t=``).
    """

    name: str
    fps: float
    header: list
    lines: list

    @property
    def n_frames(self) -> int:
        return len(self.lines)


def take_lines(take, rate=None, *, skeleton=None) -> TakeLines:
    """The lines to stream for a take.

    Parameters
    ----------
    take : str, os.PathLike or Motion
        A motion file (``.bvh`` sent verbatim at its own rate) or a motion.
    rate : float, optional
        Capture rate to send at: the take resampled to it (slerp) first.
    skeleton : str, optional
        The ``.asf`` of an ``.amc`` take.

    Returns
    -------
    lines : TakeLines

    Notebook: 20_align_a_live_performance.ipynb
    """
    from fpdtw.io import load_motion
    from fpdtw.io._text import read_lines
    from fpdtw.io.bvh import bvh_lines, parse_bvh_header

    if isinstance(take, str | Path) and Path(take).suffix.lower() == ".bvh":
        path = Path(take)
        text = read_lines(path)
        h = parse_bvh_header(text, path)
        if rate is None or abs(rate - h.fps) <= 1e-9 * max(rate, h.fps):
            body = [s.strip() for s in text[h.end_line :] if s.strip()]
            return TakeLines(path.stem, h.fps, text[: h.end_line], body)
    motion = take
    if isinstance(take, str | Path):
        motion = load_motion(take, **({"skeleton": skeleton} if skeleton else {}))
    if rate is not None and abs(rate - motion.fps) > 1e-9 * max(rate, motion.fps):
        motion = motion.resample(rate)
    header, lines = bvh_lines(motion)
    return TakeLines(motion.name, motion.fps, header, lines)


def plan(n: int, fps: float, drop: float = 0.0, jitter_ms: float = 0.0, seed: int = 0):
    """Which frames are sent, and when.

    Parameters
    ----------
    n : int
        Frames of the take.
    fps : float
    drop : float
        Probability that a frame (not frame 0) is lost, in [0, 1).
    jitter_ms : float
        Each line leaves ``U(0, jitter_ms)`` ms after its capture time.
    seed : int
        One seed for both (drops and jitter come from separate streams of it, so the
        frames dropped do not depend on the jitter).

    Returns
    -------
    sent : ndarray of bool, shape (n,)
    capture_s : ndarray of float64, shape (n,)
        Capture time of each frame, ``q / fps``.
    send_s : ndarray of float64, shape (n,)
        When each line leaves (seconds after the start; non-decreasing).
    """
    if not 0.0 <= drop < 1.0:
        raise ValueError(f"drop must be a probability in [0, 1), got {drop!r}")
    if not 0.0 <= jitter_ms < 1e6:
        raise ValueError(f"jitter must be a number of milliseconds >= 0, got {jitter_ms!r}")
    ss_drop, ss_jitter = np.random.SeedSequence(seed).spawn(2)
    sent = np.random.default_rng(ss_drop).random(n) >= drop
    sent[0] = True
    capture = np.arange(n) / float(fps)
    delay = np.random.default_rng(ss_jitter).uniform(0.0, jitter_ms / 1e3, n)
    send = np.maximum.accumulate(capture + delay)
    return sent, capture, send


def stamp(line: str, t: float) -> str:
    """``t=<t> <line>``, with ``t`` printed so that it reads back as the same float."""
    return f"t={float(t)!r} {line}"


@dataclass
class StreamReport:
    """What a streamed take got back.

    Attributes
    ----------
    name : str
    fps : float
        Capture rate sent at.
    frames : int
        Frames of the take.
    sent : ndarray of int64, shape (s,)
        Take frame number of each line sent.
    index, input_frame : ndarray of int64, shape (a,)
        The answers (``a <= s``: fewer when the take ended in an error).
    input_time_s : ndarray of float64, shape (a,)
    server_us : ndarray of float64, shape (a,)
        The server's latency of each answer.
    round_trip_s : ndarray of float64, shape (a,)
        Line written -> answer read, on this side.
    error : str or None
        The server's error line, if any.
    fast : bool
        Sent without pacing.
    """

    name: str
    fps: float
    frames: int
    sent: np.ndarray
    index: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    input_frame: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    input_time_s: np.ndarray = field(default_factory=lambda: np.zeros(0))
    server_us: np.ndarray = field(default_factory=lambda: np.zeros(0))
    round_trip_s: np.ndarray = field(default_factory=lambda: np.zeros(0))
    error: str | None = None
    fast: bool = False

    def percentiles(self, of: str = "round_trip") -> dict:
        """``{"p50": .., "p90": .., "p99": .., "max": ..}`` in seconds: ``of="round_trip"``
        or ``"server"``; empty without answers."""
        x = self.round_trip_s if of == "round_trip" else self.server_us / 1e6
        if not x.size:
            return {}
        out = {f"p{p}": float(np.percentile(x, p)) for p in PERCENTILES}
        out["max"] = float(x.max())
        return out

    def table(self) -> str:
        """Frames, losses, answers and latency percentiles (ms) as text."""
        lost = self.frames - self.sent.size
        mode = "as fast as answered" if self.fast else "in real time"
        head = f"{'':<20}" + "".join(f"{k:>9}" for k in (*(f"p{p}" for p in PERCENTILES), "max"))
        rows = []
        for label, of in (("round trip (ms)", "round_trip"), ("server (ms)", "server")):
            pct = self.percentiles(of)
            if pct:
                rows.append(f"{label:<20}" + "".join(f"{v * 1e3:>9.3f}" for v in pct.values()))
        last = (
            f"last answer: frame {self.index[-1]} -> input frame {self.input_frame[-1]} "
            f"({self.input_time_s[-1]:.3f} s)"
            if self.index.size
            else "no answer"
        )
        return "\n".join(
            [
                f"take {self.name}: {self.frames} frames at {self.fps:g} Hz, {mode}; "
                f"{self.sent.size} sent, {lost} dropped on purpose; "
                f"{self.index.size} answers",
                head,
                *rows,
                last,
                "(round trip: line written -> its answer read, here; server: the server's own "
                "time per line)",
            ]
        )


def _frame_lines(take: TakeLines, sent, capture, timestamps: bool):
    frames = np.flatnonzero(sent)
    if timestamps:
        lines = [stamp(take.lines[q], capture[q]) for q in frames]
    else:
        lines = [take.lines[q] for q in frames]
    return frames, lines


async def stream_take(
    take: TakeLines,
    host: str,
    port: int,
    *,
    drop: float = 0.0,
    jitter_ms: float = 0.0,
    seed: int = 0,
    fast: bool = False,
    timestamps: bool = True,
    timeout: float = 30.0,
) -> StreamReport:
    """Stream one take to a server and collect its answers (a coroutine).

    Parameters
    ----------
    take : TakeLines
    host, port : str, int
        The server.
    drop, jitter_ms, seed : float, float, int
        Simulated losses and jitter (:func:`plan`).
    fast : bool
        No pacing: each line right after the previous answer.
    timestamps : bool
        Prefix every line with ``t=<capture time>``.
    timeout : float
        Seconds to wait for any one answer.

    Returns
    -------
    report : StreamReport

    Raises
    ------
    OSError
        No server at ``host:port``.
    """
    if fast and jitter_ms:
        raise ValueError("jitter needs real-time pacing (not fast)")
    sent, capture, send_at = plan(take.n_frames, take.fps, drop, jitter_ms, seed)
    frames, lines = _frame_lines(take, sent, capture, timestamps)
    send_at = send_at[frames]
    report = StreamReport(take.name, take.fps, take.n_frames, frames, fast=fast)
    reader, writer = await asyncio.open_connection(host, port, limit=2**20)
    clock = time.perf_counter
    written = np.empty(len(lines))
    got = []  # (index, input frame, input time, server us, read at)
    try:
        writer.write(("\n".join(take.header) + "\n").encode("latin-1"))
        await writer.drain()

        async def read_one():
            raw = await asyncio.wait_for(reader.readline(), timeout)
            at = clock()
            text = raw.decode("latin-1").strip()
            if not text or text.startswith("error:"):
                report.error = text or "error: the server closed the connection"
                return False
            f = text.split()
            got.append((int(f[0]), int(f[1]), float(f[2]), float(f[3]), at))
            return True

        if fast:
            for i, line in enumerate(lines):
                written[i] = clock()
                writer.write((line + "\n").encode("latin-1"))
                await writer.drain()
                if not await read_one():
                    break
        else:
            loop = asyncio.get_running_loop()
            t0 = loop.time() + 0.05

            async def sender():
                for i, line in enumerate(lines):
                    wait = t0 + send_at[i] - loop.time()
                    if wait > 0:
                        await asyncio.sleep(wait)
                    if report.error:
                        return
                    written[i] = clock()
                    writer.write((line + "\n").encode("latin-1"))
                    await writer.drain()

            task = asyncio.create_task(sender())
            try:
                for _ in lines:
                    if not await read_one():
                        break
            finally:
                task.cancel()
                await asyncio.gather(task, return_exceptions=True)
        if report.error is None:
            writer.write_eof()
    finally:
        writer.close()
        try:
            await asyncio.wait_for(writer.wait_closed(), 1.0)
        except (OSError, TimeoutError):
            pass
    if got:
        a = np.array(got)
        report.index = a[:, 0].astype(np.int64)
        report.input_frame = a[:, 1].astype(np.int64)
        report.input_time_s = a[:, 2]
        report.server_us = a[:, 3]
        report.round_trip_s = a[:, 4] - written[: len(got)]
    return report


def play(take, to: str, *, rate=None, skeleton=None, **kwargs) -> StreamReport:
    """Stream a take to ``to`` (``"HOST:PORT"``) and return the report (blocking).

    ``kwargs`` as :func:`stream_take`.
    """
    from fpdtw.app.serve import parse_address

    host, port = parse_address(to)
    lines = take if isinstance(take, TakeLines) else take_lines(take, rate, skeleton=skeleton)
    return _run(stream_take(lines, host, port, **kwargs))


def play_many(take, to: str, streams: int, *, rate=None, **kwargs) -> list:
    """Stream the same take ``streams`` times at once (one connection each, seeds
    ``seed, seed + 1, ...``); return their reports.
    """
    from fpdtw.app.serve import parse_address

    host, port = parse_address(to)
    lines = take if isinstance(take, TakeLines) else take_lines(take, rate)
    seed = kwargs.pop("seed", 0)

    async def main():
        jobs = [stream_take(lines, host, port, seed=seed + i, **kwargs) for i in range(streams)]
        return await asyncio.gather(*jobs)

    return list(_run(main()))


def _run(coro):
    """Run a coroutine to its end: here, or, where an event loop already runs (a Jupyter
    kernel), on a loop of its own in a worker thread."""
    try:
        asyncio.get_running_loop()
    except RuntimeError:
        return asyncio.run(coro)
    from concurrent.futures import ThreadPoolExecutor

    with ThreadPoolExecutor(1) as pool:
        return pool.submit(asyncio.run, coro).result()


def simulate(
    I, take: TakeLines, algorithm: str, *, drop=0.0, seed=0, gap="slerp", jitter_ms=0.0,
    timestamps=True,
):  # fmt: skip
    """Feed a take's lines to a server session in this process (no network).

    The same lines as :func:`stream_take` sends (same drops for the same seed); without
    timestamps each line counts at its simulated send time (capture time + jitter).

    Parameters
    ----------
    I : Motion or MotionFeatures
        The recorded input (features with positions for OPW).
    take : TakeLines
    algorithm : str
        A registry name (``"Mc w40"``, ``"OLTW"``, ``"OPW"``).
    drop, seed, gap, jitter_ms, timestamps
        As :func:`stream_take` and :class:`fpdtw.app.serve.Session`.

    Returns
    -------
    session : Session
        With ``ticks`` (every target frame stepped on) and ``answers``.

    Notebook: 20_align_a_live_performance.ipynb
    """
    from fpdtw.app.serve import Session
    from fpdtw.motion.features import MotionFeatures
    from fpdtw.motion.joints import OPW_JOINTS
    from fpdtw.registry import resolve

    a = resolve(algorithm)
    pj = OPW_JOINTS if a.family == "OPW" else None
    if not isinstance(I, MotionFeatures):
        I = MotionFeatures.from_motion(I, position_joints=pj)
    session = Session(I, a.make, position_joints=pj, gap=gap, record=True)
    for line in take.header:
        session.feed(line.encode("latin-1"), 0.0)
    sent, capture, send_at = plan(take.n_frames, take.fps, drop, jitter_ms, seed)
    frames, lines = _frame_lines(take, sent, capture, timestamps)
    for line, q in zip(lines, frames, strict=True):
        session.feed(line.encode("latin-1"), time.perf_counter(), when=send_at[q])
    return session


#: Columns of :func:`write_answers_csv`.
ANSWER_COLUMNS = (
    "stream", "sent_frame", "frame_index", "input_frame", "input_time_s", "server_us",
    "round_trip_us",
)  # fmt: skip


def write_answers_csv(path, reports) -> Path:
    """The answers of one or more reports as CSV, one row per answer, columns
    :data:`ANSWER_COLUMNS` (``stream`` numbers the reports from 1); written whole or not
    at all.
    """
    import io

    from fpdtw.paper.atomic import write_atomic

    if isinstance(reports, StreamReport):
        reports = [reports]
    buf = io.StringIO()
    buf.write(",".join(ANSWER_COLUMNS) + "\n")
    for n, r in enumerate(reports, 1):
        for i in range(r.index.size):
            buf.write(
                f"{n},{r.sent[i]},{r.index[i]},{r.input_frame[i]},{r.input_time_s[i]:.6f},"
                f"{r.server_us[i]:.0f},{r.round_trip_s[i] * 1e6:.1f}\n"
            )
    return write_atomic(Path(path), buf.getvalue().encode())


def pooled_table(reports) -> str:
    """:meth:`StreamReport.table` of several streams played at once, their answers
    pooled (one line per stream first)."""
    if len(reports) == 1:
        return reports[0].table()
    r0 = reports[0]
    pooled = StreamReport(
        f"{r0.name} x {len(reports)} streams at once",
        r0.fps,
        sum(r.frames for r in reports),
        np.concatenate([r.sent for r in reports]),
        np.concatenate([r.index for r in reports]),
        np.concatenate([r.input_frame for r in reports]),
        np.concatenate([r.input_time_s for r in reports]),
        np.concatenate([r.server_us for r in reports]),
        np.concatenate([r.round_trip_s for r in reports]),
        next((r.error for r in reports if r.error), None),
        r0.fast,
    )
    return pooled.table()


def lines_motion(take: TakeLines):
    """The motion a take's lines hold, read by the BVH reader's own parser (what the
    server receives, before any loss)."""
    from fpdtw.io.bvh import parse_bvh_header

    h = parse_bvh_header(take.header)
    rows = [h.parse_line(s, h.end_line + 1 + k, k) for k, s in enumerate(take.lines)]
    return h.motion(np.stack(rows), take.name)


def session_map(session) -> np.ndarray:
    """Every target frame's input frame, ``M[k]`` for tick ``k = 0, 1, ...``, from a
    session's ticks (int64, shape (ticks,))."""
    return np.array([m for _, m, _ in session.ticks], dtype=np.int64)


# -- measurements (notebook 20) -------------------------------------------------------------


def round_trip_stats(round_trip_ms, server_ms) -> dict:
    """``answers``, ``round_trip_p50_ms``, ``round_trip_p99_ms``, ``round_trip_max_ms``,
    ``server_p50_ms``, ``server_p99_ms`` of the answers' round trips and server latencies
    (milliseconds, arrays of the same length)."""
    rt, sv = np.asarray(round_trip_ms, dtype=float), np.asarray(server_ms, dtype=float)
    return dict(
        answers=int(rt.size),
        round_trip_p50_ms=float(np.percentile(rt, 50)),
        round_trip_p99_ms=float(np.percentile(rt, 99)),
        round_trip_max_ms=float(rt.max()),
        server_p50_ms=float(np.percentile(sv, 50)),
        server_p99_ms=float(np.percentile(sv, 99)),
    )


def round_trip_rows(addresses: dict, take: TakeLines, streams=(1, 8), *, fast=False, seed=0):
    """Loopback round trip per frame for servers already running, with 1 and N streams.

    Each server first gets an untimed warm-up take (its first 60 frames, fast). Then the
    take is played ``n`` times at once for each ``n`` of ``streams`` (in real time unless
    ``fast``), and the round trips of all answers pooled.

    Parameters
    ----------
    addresses : dict of str to str
        Label (e.g. ``"Mc w40"``) -> ``"HOST:PORT"`` of its ``fpdtw serve``.
    take : TakeLines
    streams : sequence of int
    fast : bool
    seed : int

    Returns
    -------
    rows : list of dict
        ``method``, ``streams``, ``answers``, ``round_trip_p50_ms``, ``round_trip_p99_ms``,
        ``round_trip_max_ms``, ``server_p50_ms``, ``server_p99_ms``, ``budget_ms``
        (``1000 / fps``), ``mode``.

    Raises
    ------
    RuntimeError
        A server answered with an error line.

    Notebook: 20_align_a_live_performance.ipynb
    """
    warm = TakeLines(take.name, take.fps, take.header, take.lines[:60])
    rows = []
    for label, address in addresses.items():
        play(warm, address, fast=True)
        for n in streams:
            reports = play_many(take, address, n, fast=fast, seed=seed)
            bad = [r.error for r in reports if r.error]
            if bad:
                raise RuntimeError(f"{label} at {address}: {bad[0]}")
            rt = np.concatenate([r.round_trip_s for r in reports]) * 1e3
            sv = np.concatenate([r.server_us for r in reports]) / 1e3
            rows.append(
                dict(
                    method=label,
                    streams=int(n),
                    **round_trip_stats(rt, sv),
                    budget_ms=1e3 / take.fps,
                    mode="as fast as answered" if fast else "real time",
                )
            )
    return rows


def drop_rate_rows(
    pairs, methods, *, drops=(0.0, 0.01, 0.05, 0.10), seeds=(0, 1, 2), slow_rate=30.0,
    gaps=("slerp", "hold"),
):  # fmt: skip
    """Deviation from offline DTW of takes streamed with lost frames, or at a lower rate.

    For each (input, target) pair the target is streamed as BVH lines (through
    :class:`fpdtw.app.serve.Session`, as the server does, without the network): at its own
    rate with each frame but the first lost with probability ``drop`` (every gap rule,
    every seed), and at ``slow_rate`` Hz without loss (resampled online to the input's
    rate). The deviation (FP-DTW eq. 3) of EVERY target frame the aligner stepped on,
    filled ones included, from the DTW map of the complete take at full rate, on the
    frames both cover.

    Parameters
    ----------
    pairs : sequence of (Motion, Motion)
        (input, target), the same frame rate.
    methods : sequence of str
        Registry names.
    drops, seeds, gaps : sequences
    slow_rate : float

    Returns
    -------
    rows : list of dict
        ``method``, ``condition`` (``"drop 5 %"``, ``"30 Hz target"``), ``gap``,
        ``runs``, ``lost_per_run`` (mean frames lost), ``deviation_frames`` (mean over
        pairs and seeds), ``deviation_max_frames`` (largest run).

    Paper: FP-DTW eq. 3 and its conclusion (dropped frames); OPW poster (25-30 Hz
    markerless capture against 120 Hz recordings).
    Notebook: 20_align_a_live_performance.ipynb
    """
    from fpdtw.dtw import dtw_pair
    from fpdtw.metrics import deviation
    from fpdtw.motion.features import MotionFeatures
    from fpdtw.motion.joints import OPW_JOINTS

    runs = {}  # (method, condition, gap) -> [(deviation, lost)]
    for I, T in _progress(list(pairs), "pairs"):
        FI = MotionFeatures.from_motion(I, position_joints=OPW_JOINTS)
        full = take_lines(T)
        M_ref = dtw_pair(
            MotionFeatures.from_motion(I), MotionFeatures.from_motion(lines_motion(full))
        ).map
        slow = take_lines(T, slow_rate)
        for method in methods:
            jobs = [
                (f"drop {100 * d:g} %", d, g, sd)
                for d in drops
                for g in (gaps if d else ("-",))
                for sd in (seeds if d else seeds[:1])
            ]
            jobs.append((f"{slow_rate:g} Hz target", 0.0, "-", seeds[0]))
            for cond, d, g, sd in jobs:
                take = slow if cond.endswith("target") else full
                sess = simulate(FI, take, method, drop=d, seed=sd, gap="slerp" if g == "-" else g)
                M = session_map(sess)
                n = min(M.size, M_ref.size)
                key = (method, cond, g)
                runs.setdefault(key, []).append((deviation(M_ref[:n], M[:n]), sess.target.n_lost))
    rows = []
    for (method, cond, g), vals in runs.items():
        dev = np.array([v[0] for v in vals])
        rows.append(
            dict(
                method=method,
                condition=cond,
                gap=g,
                runs=len(vals),
                lost_per_run=float(np.mean([v[1] for v in vals])),
                deviation_frames=float(dev.mean()),
                deviation_max_frames=float(dev.max()),
            )
        )
    return rows


def drop_rate_pivot(rows) -> list:
    """:func:`drop_rate_rows` as one row per method and gap rule, one column per condition
    (mean deviation, frames); the conditions without gaps (no loss, another rate) repeat
    under both rules.

    Notebook: 20_align_a_live_performance.ipynb
    """
    conds = list(dict.fromkeys(r["condition"] for r in rows))
    rules = list(dict.fromkeys(r["gap"] for r in rows if r["gap"] != "-")) or ["-"]
    out = []
    for method in dict.fromkeys(r["method"] for r in rows):
        for rule in rules:
            row = {"method": method, "gap": rule}
            for c in conds:
                hit = [r for r in rows if r["method"] == method and r["condition"] == c
                       and r["gap"] in (rule, "-")]  # fmt: skip
                row[c] = hit[0]["deviation_frames"] if hit else None
            out.append(row)
    return out


def _progress(items, what):
    """``items`` with a tqdm progress bar on a terminal (plain otherwise: a notebook's
    checked output stays the same)."""
    import sys

    if len(items) < 2 or not sys.stderr.isatty():
        return items
    from tqdm.auto import tqdm

    return tqdm(items, desc=what, leave=False)


__all__ = [
    "ANSWER_COLUMNS",
    "StreamReport",
    "TakeLines",
    "play",
    "drop_rate_pivot",
    "drop_rate_rows",
    "lines_motion",
    "play_many",
    "plan",
    "pooled_table",
    "round_trip_rows",
    "round_trip_stats",
    "session_map",
    "simulate",
    "stamp",
    "stream_take",
    "take_lines",
    "write_answers_csv",
]
