"""``fpdtw serve``: align takes streamed over the network, frame by frame, as they arrive.

A TCP server (asyncio; loopback unless another interface is asked for). One connection is
one take of the live performance; every connection gets its own online aligner, built from
the one recorded INPUT.

Protocol (text lines, ``\\n`` or ``\\r\\n``; fpdtw's own: the capture side connects and sends
lines. A capture system's own stream is read by ``fpdtw serve --source``,
:mod:`fpdtw.app.sources`):

1. The client sends a BVH header: ``HIERARCHY`` through ``Frame Time:`` (a ``Frames:``
   line may come before ``Frame Time:``; its count is ignored). It is parsed by the BVH
   file reader's own parser (:class:`fpdtw.io.bvh.BVHHeader`): same errors, same limits.
2. Then one BVH motion line per captured frame, optionally beginning with
   ``t=<seconds>``, the frame's capture time on the sender's clock (without it the time
   the line arrived counts; the first frame line decides for the whole take). Blank
   lines are ignored.
3. The server answers each motion line, before it reads the next, with one line::

       <frame index> <input frame> <input time s> <latency us>

   ``frame index``: the target frame the answer is for, on the INPUT's frame rate (the
   row of ``fpdtw align INPUT TAKE``'s map; at equal rates the captured frame's number).
   ``input frame``: the frame of the recording the online method shows for it;
   ``input time s`` = input frame / input rate. ``latency us``: the server's time from the
   line's arrival (when its last byte was received) to writing its answer, microseconds
   (waiting behind other takes' lines included). A line that completes no new
   target frame (a target faster than the input) repeats the previous answer's index.
4. Anything wrong (a malformed header or line, a line or header over its limit, a wrong
   channel count, NaN, a time that goes backwards, a client silent for ``idle_timeout``
   seconds or gone in the middle of a line) gets ONE line ``error: line <n>, frame <k>:
   <what>`` and the connection is closed; the server goes on serving the others. A client
   beyond ``max_clients`` gets ``error: ...`` at once and is closed.

Time, dropped frames and other frame rates follow :class:`fpdtw.motion.stream.LiveTarget`:
a gap of more than 1.5 frame periods is a drop whose frames are filled by slerp between the
frames around it (``--gap hold``: the frame before it, repeated) and keep their own
indices; a target at another rate is resampled online to the input's rate, adding at most
one target period of delay. A take streamed without loss gives the map
``fpdtw align INPUT TAKE`` gives, frame for frame.

Each answer can also be sent to an engine: ``osc.udp://HOST:PORT`` sends the OSC message
``/fpdtw/frame`` with arguments (input frame: int, input time s: float, frame index: int,
take: int) through python-osc; ``udp://HOST:PORT`` sends the text line
``<take> <frame index> <input frame> <input time s> <latency us>`` for tools without OSC
(``take`` numbers the connections from 1).

Notebook: 20_align_a_live_performance.ipynb
"""

from __future__ import annotations

import array
import asyncio
import collections
import contextlib
import signal
import socket
import sys
import time
from pathlib import Path

import numpy as np

from fpdtw import limits
from fpdtw.errors import FpdtwError, MotionFormatError
from fpdtw.io.bvh import check_start, is_header_end, parse_bvh_header
from fpdtw.motion.features import MotionFeatures
from fpdtw.motion.joints import find_joint_map
from fpdtw.motion.stream import GAP_RULES, LiveTarget

#: ``--max-clients`` by default.
MAX_CLIENTS = 8
#: Seconds a client may stay silent (in the middle of a line or between lines) by default.
IDLE_TIMEOUT_S = 10.0
#: The OSC address of each answer.
OSC_ADDRESS = "/fpdtw/frame"
_BOM = b"\xef\xbb\xbf"


def parse_address(text: str, default_host: str = "127.0.0.1") -> tuple[str, int]:
    """``"HOST:PORT"`` (``"[::1]:PORT"`` for IPv6, ``":PORT"`` for the default host) ->
    (host, port); ValueError naming what is wrong.
    """
    host, sep, port = str(text).rpartition(":")
    if not sep:
        raise ValueError(f"{text!r} is not HOST:PORT")
    host = host[1:-1] if host.startswith("[") and host.endswith("]") else host
    try:
        number = int(port)
    except ValueError:
        raise ValueError(f"port {port!r} in {text!r} is not a number") from None
    if not 0 <= number <= 65535:
        raise ValueError(f"port {number} in {text!r} is outside 0..65535")
    return host or default_host, number


# -- one take ---------------------------------------------------------------------------------


class Session:
    """One connection's take: its header, its live target, its aligner, its answers.

    :meth:`feed` takes the connection's lines one at a time (the bytes as received) and
    returns the answer line of each motion line. Everything the server does with a line
    happens here, so a take can be replayed without a network (:func:`fpdtw.app.stream.
    simulate`) and give the same answers.

    Parameters
    ----------
    I : MotionFeatures
        The recorded input's features (shared, read only).
    make_aligner : callable
        ``make_aligner(I) -> OnlineAligner``: a fresh aligner for this take.
    position_joints : sequence of str, optional
        Joints whose positions the target frames carry (OPW).
    gap : str
        :data:`fpdtw.motion.stream.GAP_RULES` (default ``"slerp"``).
    record : bool
        Keep every target frame's and every answer's record (``ticks``, ``answers``; a
        simulation). The server does not: it keeps the latencies only (8 bytes a line, at
        most :data:`fpdtw.limits.MAX_FRAMES` of them).
    joint_maps : sequence of dict
        Joint maps tried before the built-in ones on the streamed skeleton
        (:func:`fpdtw.motion.joints.find_joint_map`; ``--joint-map``).

    Attributes
    ----------
    ticks : list of (int, int, bool)
        With ``record``: every target frame the aligner stepped on: index, input frame,
        filled (in a gap).
    answers : list of (int, int, float)
        With ``record``: every answer: index, input frame, server latency (seconds).
    latencies : array.array of float
        The server latency of every answer (seconds).
    watch : callable or None
        ``watch(row, index, m, latency, frame)`` after every answer (``--view``'s
        :meth:`fpdtw.app.view.Slot.put`).
    """

    watch = None

    def __init__(
        self,
        I: MotionFeatures,
        make_aligner,
        *,
        position_joints=None,
        gap="slerp",
        record=False,
        joint_maps=(),
        axes=(None, None),
    ):
        if gap not in GAP_RULES:
            raise ValueError(f"gap must be one of {GAP_RULES}, got {gap!r}")
        self.I, self.gap, self.position_joints = I, gap, position_joints
        self.up, self.facing = axes
        self.joint_maps = tuple(joint_maps)
        self.aligner = make_aligner(I)
        self.header = None
        self.target = None
        self.line = 0
        self.n_frames = 0
        self.record = bool(record)
        self.ticks = []
        self.answers = []
        self.latencies = array.array("d")
        self._lines = []
        self._header_bytes = 0
        self._blank = 0
        self._max_blank = int(limits.get("max_frames"))
        self._started = False
        self._stamped = None
        self._first = None
        self._last = None

    def feed(self, raw: bytes, arrival: float, when: float | None = None) -> str | None:
        """Take the next line; return its answer (a motion line) or None.

        Parameters
        ----------
        raw : bytes
            The line as received (with or without its newline).
        arrival : float
            When it arrived (``time.perf_counter()`` seconds, its last byte received): the
            latency counts from it, and so does a line without ``t=``.
        when : float, optional
            The time a line without ``t=`` counts at (default ``arrival``; a simulation
            passes its simulated arrival).

        Returns
        -------
        answer : str or None
            ``"<frame index> <input frame> <input time s> <latency us>\\n"``; None for a
            header line or a blank line.

        Raises
        ------
        MotionFormatError, LimitError
            Whatever is wrong with the line, naming its line (and frame) number.
        """
        self.line += 1
        if self.line == 1 and raw.startswith(_BOM):
            raw = raw[len(_BOM) :]
        text = raw.decode("latin-1")
        if self.header is None:
            return self._header_line(raw, text)
        s = text.strip()
        if not s:  # ignored, but counted: a take of blank lines ends too
            self._blank += 1
            if self._blank > self._max_blank:
                raise MotionFormatError(
                    None,
                    f"more than {self._max_blank} blank lines ({limits.env_name('max_frames')})",
                    line=self.line,
                )
            return None
        t, values = self._time(s, arrival if when is None else when)
        return self._row(self.header.parse_line(values, self.line, self.n_frames), t, arrival)

    def feed_row(self, row, t: float, arrival: float) -> str:
        """Take one frame as a capture source has read and checked it: its motion line's
        values ``row`` (n_channels,) float64, at capture time ``t`` s, without a text line to
        write and parse again. As :meth:`feed` otherwise (the header first, through it)."""
        self.line += 1
        if self.header is None or self._stamped is False:
            raise ValueError("feed_row: after a complete header, and never after unstamped lines")
        self._stamped = True
        return self._row(np.asarray(row, dtype=float), float(t), arrival)

    def _row(self, row, t: float, arrival: float) -> str:
        h, k = self.header, self.n_frames
        if self._first is None:
            self._first = row
            skeleton = h.skeleton_for(row)  # the header's, unless it has non-root positions
            if skeleton is not h.skeleton:
                self.target = self._live_target(skeleton)
        else:
            h.check_positions(row[None], self._first, lines=[self.line], frame0=k)
        ticks = self.target.push_channels(
            row, *h.channel_map, t, arrival=not self._stamped, line=self.line, frame=k
        )
        self.n_frames += 1
        for index, frame, filled in ticks:
            m = self.aligner.step(frame)
            if self.record:
                self.ticks.append((index, m, filled))
            self._last = (index, m)
        index, m = self._last
        latency = time.perf_counter() - arrival
        self.latencies.append(latency)
        if self.record:
            self.answers.append((index, m, latency))
        if self.watch is not None:  # --view: the answer stored for the page, nothing more
            self.watch(row, index, m, latency, frame)
        return f"{index} {m} {m / self.I.fps:.6f} {round(latency * 1e6)}\n"

    @property
    def last(self) -> tuple | None:
        """(frame index, input frame) of the latest answer (None before the first)."""
        return self._last

    def _header_line(self, raw, text):
        self._header_bytes += len(raw)
        cap = int(limits.get("max_header_bytes"))
        if self._header_bytes > cap:
            raise MotionFormatError(
                None,
                f"the header passes {cap} bytes ({limits.env_name('max_header_bytes')}) "
                "without a 'Frame Time:' line",
                line=self.line,
            )
        self._lines.append(text)
        words = text.split()
        if words and not self._started:
            self._started = True
            check_start(words[0], None, self.line)  # garbage fails now, not at 1 MiB
        if is_header_end(text):
            self.header = parse_bvh_header(self._lines, None, stream=True)
            self._lines = []
            try:  # the joints are there; the target of a header without non-root positions
                self.target = self._live_target(self.header.skeleton)
            except MotionFormatError as e:
                raise MotionFormatError(None, e.reason, line=self.line) from None
        return None

    def _live_target(self, skeleton):
        h = self.header
        joint_map = h.joint_map
        if self.joint_maps:
            joint_map, _ = find_joint_map(skeleton.joint_names, "bvh", self.joint_maps)
        return LiveTarget(
            skeleton,
            h.fps,
            self.I.fps,
            joint_map=joint_map,
            position_joints=self.position_joints,
            gap=self.gap,
            input_body_size=self.I.body_size,
            input_axes=None if self.I.rig is None else self.I.rig.axes,
            up=self.up,
            facing=self.facing,
        )

    def _time(self, s, arrival):
        stamped = s.startswith("t=")
        if self._stamped is None:
            self._stamped = stamped
        elif stamped != self._stamped:
            first = "has" if self._stamped else "has no"
            raise MotionFormatError(
                None,
                f"the first frame line {first} a 't=' time, this one "
                f"{'has' if stamped else 'has not'}: one clock per take",
                line=self.line,
                frame=self.n_frames,
            )
        if not stamped:
            return arrival, s
        head, rest = (s.split(None, 1) + [""])[:2]
        try:
            t = float(head[2:])
        except ValueError:
            raise MotionFormatError(
                None, f"time {head!r} is not a number", line=self.line, frame=self.n_frames
            ) from None
        if not np.isfinite(t) or abs(t) > limits.get("max_abs_value"):
            raise MotionFormatError(
                None, f"time {head!r} is not a plausible time", line=self.line, frame=self.n_frames
            )
        return t, rest

    def summary(self) -> dict:
        """Frames received, target frames stepped, filled, lost; latency percentiles (us)."""
        lat = np.frombuffer(self.latencies, dtype=np.float64) * 1e6
        lt = self.target
        out = dict(
            lines=self.line,
            frames=self.n_frames,
            ticks=0 if lt is None else lt.n_ticks,
            filled=0 if lt is None else lt.n_filled,
            lost=0 if lt is None else lt.n_lost,
        )
        for p in (50, 99):
            out[f"p{p}_us"] = float(np.percentile(lat, p)) if lat.size else None
        return out


# -- where the answers also go ---------------------------------------------------------------


class _Sender:
    """Sends every answer to one UDP destination (OSC or text); never blocks or raises."""

    def __init__(self, url: str):
        self.url = url
        self.failures = 0
        kind, sep, rest = url.partition("://")
        if not sep or kind not in ("osc.udp", "udp"):
            raise ValueError(f"--send {url!r}: expected osc.udp://HOST:PORT or udp://HOST:PORT")
        host, port = parse_address(rest)
        if port == 0:
            raise ValueError(f"--send {url!r}: port 0 is not a destination")
        self.kind = kind
        if kind == "osc.udp":
            from pythonosc.udp_client import SimpleUDPClient

            self._osc = SimpleUDPClient(host, port)
        else:
            info = socket.getaddrinfo(host, port, type=socket.SOCK_DGRAM)[0]
            self._sock = socket.socket(info[0], socket.SOCK_DGRAM)
            self._sock.setblocking(False)
            self._dest = info[4]

    def send(self, take: int, index: int, m: int, t: float, latency_us: int, performer=()) -> None:
        """``performer``: (index, name) of the performer the answer is for (a ``--source``
        with several), appended to the OSC arguments and to the text line."""
        try:
            if self.kind == "osc.udp":
                args = [int(m), float(t), int(index), int(take), *performer]
                self._osc.send_message(OSC_ADDRESS, args)
            else:
                who = "".join(f" {v}" for v in performer)
                line = f"{take} {index} {m} {t:.6f} {latency_us}{who}\n"
                self._sock.sendto(line.encode(), self._dest)
        except OSError:  # nobody listening, buffer full: the alignment goes on
            self.failures += 1

    def close(self):
        sock = self._osc._sock if self.kind == "osc.udp" else self._sock
        sock.close()


# -- the server -------------------------------------------------------------------------------


class _TimedReader(asyncio.StreamReader):
    """A stream reader that notes when each chunk of bytes arrived, so that a line's
    arrival time is when its last byte was received, not when the server got round to it
    (lines that arrived together while the server was busy arrived together)."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self._fed = 0
        self._consumed = 0
        self._chunks = collections.deque()  # (offset after the chunk, perf_counter time)

    def feed_data(self, data):
        self._fed += len(data)
        self._chunks.append((self._fed, time.perf_counter()))
        super().feed_data(data)

    async def timed_line(self):
        """``(line, arrival)``: the next line (with its newline) and when it arrived."""
        return await self.timed_until(b"\n")

    async def timed_until(self, separator: bytes):
        """``(data, arrival)``: the bytes through the next ``separator`` and when the last
        of them arrived (``readuntil``'s errors: at most the reader's limit is searched)."""
        raw = await self.readuntil(separator)
        self._consumed += len(raw)
        while self._chunks[0][0] < self._consumed:
            self._chunks.popleft()
        return raw, self._chunks[0][1]


#: Seconds a refused client's bytes are read and dropped before its connection is closed.
REFUSE_LINGER_S = 1.0


class Server:
    """The asyncio TCP server of ``fpdtw serve``.

    Parameters
    ----------
    I : MotionFeatures
        The recorded input's features.
    make_aligner : callable
        ``make_aligner(I) -> OnlineAligner`` (a fresh aligner per connection).
    name : str
        The method's name, for the log.
    position_joints : sequence of str, optional
        OPW's joints (the target frames then carry positions).
    gap : str
        Rule for dropped frames (:data:`fpdtw.motion.stream.GAP_RULES`).
    joint_maps : sequence of dict
        Joint maps for the streamed skeletons (see :class:`Session`).
    max_clients : int
        Connections served at once; one more gets an error line and is closed.
    idle_timeout : float
        Seconds a client may stay silent before it gets an error line and is closed.
    send : sequence of str
        ``osc.udp://HOST:PORT`` or ``udp://HOST:PORT`` destinations of every answer.
    log : callable
        ``log(message)`` (default: print to stderr).
    view : fpdtw.app.view.Viewer, optional
        ``--view``: every take's session is watched by its page.
    """

    def __init__(
        self,
        I,
        make_aligner,
        name="",
        *,
        position_joints=None,
        gap="slerp",
        joint_maps=(),
        axes=(None, None),
        max_clients=MAX_CLIENTS,
        idle_timeout=IDLE_TIMEOUT_S,
        send=(),
        log=None,
        view=None,
    ):
        self.I, self.make_aligner, self.name = I, make_aligner, name
        self.view = view
        self.position_joints, self.gap = position_joints, gap
        self.joint_maps, self.axes = tuple(joint_maps), axes
        self.max_clients, self.idle_timeout = int(max_clients), float(idle_timeout)
        self.senders = [_Sender(u) for u in send]
        self.log = log or (lambda msg: print(msg, file=sys.stderr, flush=True))
        self.active = 0
        self.takes = 0
        self.refused = 0
        self.errors = 0
        self._tasks = set()
        self._server = None

    def _session(self):
        return Session(
            self.I,
            self.make_aligner,
            position_joints=self.position_joints,
            gap=self.gap,
            joint_maps=self.joint_maps,
            axes=self.axes,
        )

    def warm_up(self, motion, frames: int = 8) -> None:
        """Stream the first ``frames`` frames of ``motion`` through a session, unanswered:
        every compiled kernel of a take (parsing, rotations, positions, the aligner's step)
        is loaded before the first client, not during its first frame."""
        from fpdtw.io.bvh import bvh_lines

        header, lines = bvh_lines(motion)
        s = self._session()
        for line in header:
            s.feed(f"{line}\n".encode(), 0.0)
        for k, line in enumerate(lines[:frames]):
            s.feed(f"{line}\n".encode(), time.perf_counter(), when=k / motion.fps)

    async def start(self, host: str, port: int):
        """Listen on ``host:port`` (port 0: any free one); return the (host, port) bound.

        The line limit (:data:`fpdtw.limits.MAX_LINE_BYTES`) is read here, once."""
        self.max_line_bytes = int(limits.get("max_line_bytes"))
        loop = asyncio.get_running_loop()

        def protocol():
            reader = _TimedReader(limit=self.max_line_bytes, loop=loop)
            return asyncio.StreamReaderProtocol(reader, self._client, loop=loop)

        self._server = await loop.create_server(protocol, host, port)
        sock = self._server.sockets[0].getsockname()
        return sock[0], sock[1]

    async def stop(self):
        """Stop listening; tell every connected client and close it."""
        if self._server is not None:
            self._server.close()
        for task in list(self._tasks):
            task.cancel()
        await asyncio.gather(*self._tasks, return_exceptions=True)
        if self._server is not None:
            await self._server.wait_closed()
        for s in self.senders:
            s.close()

    async def _client(self, reader, writer):
        task = asyncio.current_task()
        peer = writer.get_extra_info("peername")
        peer = f"{peer[0]}:{peer[1]}" if isinstance(peer, tuple) else str(peer)
        if self.active >= self.max_clients:
            self.refused += 1
            self.log(f"refused {peer}: {self.max_clients} takes already (--max-clients)")
            await self._close(
                writer,
                f"error: the server is full ({self.max_clients} takes at once, "
                "--max-clients); try again later\n",
                reader=reader,
            )
            return
        self.active += 1
        self.takes += 1
        take = self.takes
        self._tasks.add(task)
        session = None
        end = "ended"
        try:
            session = self._session()
            if self.view is not None:
                session.watch = self.view.slot(take, peer, session)
            self.log(f"take {take} from {peer}")
            end = await self._serve(take, session, reader, writer)
        except asyncio.CancelledError:
            end = "stopped: the server is shutting down"
            await self._close(writer, "error: the server is shutting down\n")
        except Exception as exc:  # a bug of ours: tell the client, keep serving the others
            self.errors += 1
            end = f"internal error {type(exc).__name__}: {exc}"
            await self._close(writer, f"error: internal error of the server ({end})\n")
        finally:
            self.active -= 1
            self._tasks.discard(task)
            await self._close(writer)
            stats = "" if session is None else _format_summary(session.summary())
            self.log(f"take {take} from {peer} {end}{stats}")

    async def _serve(self, take, session, reader, writer) -> str:
        """Read, answer, until the client ends the take or something is wrong."""
        timeout = self.idle_timeout
        while True:
            where = f"line {session.line + 1}"
            try:
                async with asyncio.timeout(timeout):  # no task per line, unlike wait_for
                    raw, arrival = await reader.timed_line()
            except asyncio.IncompleteReadError as e:
                if not e.partial.strip():
                    return "ended"
                return await self._fail(
                    writer, f"{where}: the connection ended in the middle of a line"
                )
            except asyncio.LimitOverrunError:
                return await self._fail(
                    writer,
                    f"{where}: the line is longer than {self.max_line_bytes} bytes "
                    f"({limits.env_name('max_line_bytes')})",
                )
            except TimeoutError:
                return await self._fail(
                    writer, f"{where}: nothing received for {timeout:g} s (--idle-timeout)"
                )
            except ConnectionError as e:
                return f"ended: the client disconnected ({type(e).__name__})"
            try:
                answer = session.feed(raw, arrival)
            except (FpdtwError, ValueError) as exc:
                return await self._fail(writer, str(exc))
            if answer is None:
                await asyncio.sleep(0)  # a burst of buffered lines never starves the others
                continue
            try:
                await self._answer(take, session, answer, writer)
                await asyncio.sleep(0)
            except TimeoutError:
                return await self._fail(
                    writer, f"{where}: the answers were not read for {timeout:g} s"
                )
            except ConnectionError as e:
                return f"ended: the client disconnected ({type(e).__name__})"

    async def _answer(self, take, session, answer, writer):
        writer.write(answer.encode())
        async with asyncio.timeout(self.idle_timeout):
            await writer.drain()
        if self.senders:
            (index, m), latency = session.last, session.latencies[-1]
            for s in self.senders:
                s.send(take, index, m, m / self.I.fps, round(latency * 1e6))

    async def _fail(self, writer, message: str) -> str:
        await self._close(writer, f"error: {' '.join(message.split())}\n")
        return f"with an error: {message}"

    async def _close(self, writer, line: str | None = None, reader=None):
        """Write ``line`` (if any) and close, whatever the client does meanwhile. With the
        ``reader`` of a client never read (refused), what it sent is read and dropped for up
        to :data:`REFUSE_LINGER_S` after the line and an end of writing, so that closing
        with its bytes unread does not reset the connection before the line is read."""
        with contextlib.suppress(Exception):
            if line is not None and not writer.is_closing():
                writer.write(line.encode())
                await asyncio.wait_for(writer.drain(), 1.0)
            if reader is not None and writer.can_write_eof():
                writer.write_eof()
                async with asyncio.timeout(REFUSE_LINGER_S):
                    while await reader.read(65536):
                        pass
        with contextlib.suppress(Exception):
            writer.close()
            await asyncio.wait_for(writer.wait_closed(), 1.0)


def _format_summary(s: dict) -> str:
    if not s["frames"]:
        return f" ({s['lines']} lines, no frame)"
    lat = f"server latency p50 {s['p50_us']:.0f} us, p99 {s['p99_us']:.0f} us"
    return (
        f" ({s['frames']} frames, {s['ticks']} target frames at the input's rate, "
        f"{s['lost']} lost and {s['filled']} filled; {lat})"
    )


def run_server(server: Server, host: str, port: int, *, out=None) -> int:
    """Run ``server`` on ``host:port`` until SIGINT or SIGTERM; return 0.

    Prints ``listening on HOST:PORT`` (the port bound, also when 0 was asked) to ``out``
    (default stdout) once it accepts connections; ``server.view`` (``--view``), if set,
    serves its page in the same loop from before then.
    """
    out = sys.stdout if out is None else out

    async def main():
        loop = asyncio.get_running_loop()
        stop = asyncio.Event()
        got = []
        for sig in (signal.SIGINT, signal.SIGTERM):
            loop.add_signal_handler(sig, lambda s=sig: (got.append(s), stop.set()))
        if server.view is not None:
            await server.view.start(out)
        bound = await server.start(host, port)
        print(f"listening on {_show(bound[0])}:{bound[1]}", file=out, flush=True)
        try:
            await stop.wait()
        finally:
            await server.stop()
            if server.view is not None:
                await server.view.stop()
            for sig in (signal.SIGINT, signal.SIGTERM):
                loop.remove_signal_handler(sig)
        name = signal.Signals(got[0]).name if got else "stop"
        server.log(
            f"stopped ({name}): {server.takes} takes served, {server.refused} refused "
            f"(--max-clients), {server.errors} internal errors"
        )

    asyncio.run(main())
    return 0


def _show(host: str) -> str:
    return f"[{host}]" if ":" in host else host


@contextlib.contextmanager
def server_processes(input_path, methods: dict, *, extra=(), timeout=300.0):
    """Run one ``fpdtw serve`` process per method on loopback (any free port), started
    together; stop them all (SIGTERM) when the block ends.

    Parameters
    ----------
    input_path : str or os.PathLike
        The recorded motion file.
    methods : dict of str to sequence of str
        Label -> its options, e.g. ``{"Mc w40": ["-m", "c", "-w", "40"]}``.
    extra : sequence of str
        Options for every server (e.g. ``["--gap", "hold"]``).
    timeout : float
        Seconds to wait for each to listen (and to stop).

    Yields
    ------
    addresses : dict of str to str
        Label -> ``"127.0.0.1:PORT"``.

    Raises
    ------
    RuntimeError
        A server that exits before listening (with its error output).

    Notebook: 20_align_a_live_performance.ipynb
    """
    import subprocess
    import tempfile

    procs = {}
    with tempfile.TemporaryDirectory(prefix="fpdtw-serve-") as tmp:
        try:
            for label, opts in methods.items():
                log = open(Path(tmp) / f"{len(procs)}.log", "w+")  # noqa: SIM115
                cmd = [sys.executable, "-m", "fpdtw.app.cli", "serve", str(input_path),
                       *opts, *extra, "--listen", "127.0.0.1:0"]  # fmt: skip
                proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=log, text=True)
                procs[label] = (proc, log)
            addresses = {}
            for label, (proc, log) in procs.items():
                line = _first_line(proc, timeout)
                if not line.startswith("listening on "):
                    log.seek(0)
                    raise RuntimeError(f"fpdtw serve for {label} did not start: {log.read()}")
                addresses[label] = line.split()[-1]
            yield addresses
        finally:
            for proc, _ in procs.values():
                if proc.poll() is None:
                    proc.send_signal(signal.SIGTERM)
            for proc, log in procs.values():
                try:
                    proc.wait(timeout)
                except subprocess.TimeoutExpired:
                    proc.kill()
                    proc.wait()
                proc.stdout.close()
                log.close()


def _first_line(proc, timeout: float) -> str:
    """The first line a process prints ("" if it exits or ``timeout`` passes first)."""
    import selectors

    with selectors.DefaultSelector() as sel:
        sel.register(proc.stdout, selectors.EVENT_READ)
        if not sel.select(timeout):
            return ""
    return proc.stdout.readline().strip()


__all__ = [
    "IDLE_TIMEOUT_S",
    "MAX_CLIENTS",
    "OSC_ADDRESS",
    "Server",
    "Session",
    "parse_address",
    "run_server",
    "server_processes",
]
