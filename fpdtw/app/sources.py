"""``fpdtw serve --source URL``: takes read from a capture system's own stream.

Without ``--source``, ``fpdtw serve`` listens for fpdtw's own protocol (:mod:`fpdtw.app.serve`).
With it, fpdtw reads the stream a capture system sends as that system sends it. One module
per system (:data:`SOURCES`) reads and frames its bytes and hands every frame of a performer
to :class:`Performers`, the part every source shares:

* one :class:`fpdtw.app.serve.Session` (its own live target and aligner) per performer, fed the
  performer's frames (their channel values, or BVH motion lines) stamped with their place in the
  stream (frame ``k`` of a performer at ``k / rate``, so that a take without loss gives the map of
  ``fpdtw align INPUT TAKE`` and a dropped frame is a gap filled by ``--gap``);
* every answer sent to ``--send`` with the performer's index and name;
* the frames a source could not use, counted by kind (the first of each kind logged with its
  frame number), and frames that arrive ahead of real time;
* at the end of a take, its summary and, with ``--out``, each performer's map.

A source module has ``DEFAULT_PORT`` and a class ``Source(host, port, **options)`` with
``describe()``, ``async connect()`` (OSError when nobody answers) and ``async read(connection,
performers, idle_timeout)`` returning how the take ended (or raising :class:`TakeEnd`). A source of
UDP datagrams (``axis+udp``, VMC, Xsens, Rokoko; NatNet builds on it) gets all but its datagrams'
meaning from :class:`DatagramSource`.
"""

from __future__ import annotations

import asyncio
import collections
import contextlib
import importlib
import os
import re
import signal
import socket
import sys
import time
from pathlib import Path

import numpy as np

from fpdtw.app.export import write_map_csv
from fpdtw.app.serve import Session, parse_address
from fpdtw.app.stream import session_map, stamp
from fpdtw.errors import FpdtwError
from fpdtw.motion.rotations import quat_to_euler

#: URL scheme -> the module reading that system's stream.
SOURCES = {"axis": "fpdtw.app.source_axis", "axis+udp": "fpdtw.app.source_axis_udp",
           "vmc": "fpdtw.app.source_vmc", "xsens": "fpdtw.app.source_xsens",
           "rokoko": "fpdtw.app.source_rokoko",
           "natnet": "fpdtw.app.source_natnet"}  # fmt: skip
#: A frame arriving this many seconds before its time at the stream's rate is "ahead".
AHEAD_S = 0.5
#: A performer whose frames are unusable for this many seconds of its rate in a row ends the
#: take (at least this many frames: a take of 1 Hz is not ended by one bad frame).
BAD_RUN_S = 1.0
BAD_RUN_MIN = 10
#: Seconds between two attempts to reach a source that is not there (after the first take).
RETRY_S = 1.0

#: Kinds of unusable frames, as the summary names them.
BAD_KINDS = {
    "empty": "empty frames",
    "name": "frames without an avatar index and name",
    "count": "frames with a wrong value count",
    "number": "frames with a value that is not a number",
    "finite": "frames with NaN or inf",
    "large": "frames with an implausible value",
    "refused": "frames of performers beyond --max-clients",
    "cut": "frames cut by the connection closing",
    "oversize": "frames over the size bound",
    "osc": "datagrams that are not OSC",
    "bone": "frames with a bone the skeleton lacks",
    "missing": "frames without a bone or time of the skeleton",
    "rotation": "frames with a quaternion that is not a rotation",
    "duplicate": "duplicated frames",
    "order": "frames older than the one before",
    "flood": "datagrams dropped by a full queue",
    "mxtp": "datagrams that are not MVN's (MXTP) or whose sizes disagree",
    "skipped": "MVN datagrams of types not read (skipped)",
    "axisbin": "datagrams that are not Axis' binary BVH (0xDDFF, 0xEEFF) or whose sizes disagree",
    "rokoko": "datagrams that are not Rokoko's JSON v3",
    "lz4": "LZ4-compressed datagrams (not read)",
    "natnet": "datagrams that are not NatNet 4.1's or whose counts and sizes disagree",
    "undescribed": "frames of a skeleton the NatNet data descriptions lack",
}


class TakeEnd(Exception):
    """The take cannot go on; the message names the frame and what is wrong."""


#: Datagrams a UDP source keeps waiting to be read; more are dropped and counted (a flood).
MAX_QUEUE = 4096


def sender_name(addr) -> str:
    """``host:port`` of a datagram's sender address (an IPv6 host in brackets)."""
    return f"[{addr[0]}]:{addr[1]}" if ":" in addr[0] else f"{addr[0]}:{addr[1]}"


class DatagramReceiver(asyncio.DatagramProtocol):
    """Queues datagrams with their arrival time; counts those a full queue drops."""

    def __init__(self):
        self.queue = collections.deque()
        self.dropped = 0
        self.ready = asyncio.Event()

    def datagram_received(self, data, addr):
        if len(self.queue) >= MAX_QUEUE:
            self.dropped += 1
        else:
            self.queue.append((data, addr, time.perf_counter()))
        self.ready.set()


class DatagramSource:
    """What every UDP source shares: it listens on ``host:port`` and only reads, its skeleton
    comes from the stream (no ``--header``), a take ends after ``--idle-timeout`` of silence,
    and datagrams a full queue drops are counted as a flood.

    A subclass sets :attr:`scheme`, :attr:`skeleton_from` and ``DEFAULT_RATE`` and implements
    :meth:`begin_take`, ``datagram(data, addr, arrival, performers)`` (``self.n`` counts
    datagrams) and :meth:`end_take`.
    """

    scheme = ""
    skeleton_from = "the stream"
    DEFAULT_RATE = 60.0

    def __init__(self, host: str, port: int, *, rate=None, header=None):
        if header is not None:
            raise ValueError(
                f"{self.scheme}:// takes no --header: the skeleton comes from {self.skeleton_from}"
            )
        self.host, self.port = host, port
        self.rate = float(rate or self.DEFAULT_RATE)

    def describe(self) -> str:
        host = f"[{self.host}]" if ":" in self.host else self.host
        return f"{self.scheme}://{host}:{self.port}"

    async def connect(self):
        """Bind the UDP port; return the transport and its receiver (OSError when taken)."""
        loop = asyncio.get_running_loop()
        transport, proto = await loop.create_datagram_endpoint(
            DatagramReceiver, local_addr=(self.host, self.port)
        )
        sock = transport.get_extra_info("socket")
        try:
            sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 1 << 22)
        except OSError:
            pass
        return transport, proto

    def warm_up(self) -> None:
        """Load (or compile) the source's compiled kernels before the first take, not during
        its first frame; the live session's are loaded by ``Server.warm_up``. Each source's
        are those of Euler angles from quaternions, and its own."""
        quat_to_euler(np.array([[1.0, 0.0, 0.0, 0.0]]))

    def begin_take(self) -> None:
        """Forget the last take's senders."""

    def end_take(self, performers) -> None:
        """The take went silent: finish what its senders had begun."""

    async def read(self, connection, performers, idle_timeout: float) -> str:
        """Read datagrams until ``idle_timeout`` s of silence after the first; return how the
        take ended (TakeEnd when it cannot go on)."""
        transport, proto = connection
        self.n = 0
        self.begin_take()
        started = False
        try:
            while True:
                proto.ready.clear()
                if not proto.queue:
                    self.flood(proto, performers)
                    try:
                        async with asyncio.timeout(idle_timeout if started else None):
                            await proto.ready.wait()
                    except TimeoutError:
                        self.end_take(performers)
                        return f"ended: nothing received for {idle_timeout:g} s (--idle-timeout)"
                started = True
                for _ in range(64):
                    if not proto.queue:
                        break
                    self.datagram(*proto.queue.popleft(), performers)
                await asyncio.sleep(0)
        except TakeEnd:
            self.flood(proto, performers)
            raise
        finally:
            transport.close()

    def flood(self, proto, performers) -> None:
        """Count the datagrams a full queue dropped (they came after those queued)."""
        if proto.dropped:
            k, proto.dropped = proto.dropped, 0
            performers.frames += k
            performers.count_bad(None, "flood", f"datagrams {self.n + 1} to {self.n + k} "
                                 f"dropped: more than {MAX_QUEUE} waiting (a flood)")  # fmt: skip
            performers.bad["flood"] += k - 1
            self.n += k


def bvh_header(names, parents, offsets, rate: float) -> tuple[list, list]:
    """The BVH header (through ``Frame Time``) of a skeleton a source built from its stream.

    ``names`` (J,), ``parents`` (J,; -1 for the one root; children in index order),
    ``offsets`` (J, 3; in the parent's axes; the root's is written 0 0 0); every joint turns
    ``Zrotation Yrotation Xrotation`` and the root moves too. Returns the lines and the
    joints' indices in written (depth-first) order, the order of a motion line's values."""
    kids = [[] for _ in names]
    for j, p in enumerate(parents):
        if p >= 0:
            kids[p].append(j)
    lines, order = ["HIERARCHY"], []

    def joint(j, pad):
        order.append(j)
        if parents[j] < 0:
            lines.extend([f"ROOT {names[j]}", "{", "  OFFSET 0 0 0", "  CHANNELS 6 Xposition "
                          "Yposition Zposition Zrotation Yrotation Xrotation"])  # fmt: skip
        else:
            lines.extend([f"{pad}JOINT {names[j]}", pad + "{", f"{pad}  OFFSET "
                          + " ".join(repr(float(v)) for v in offsets[j]),
                          f"{pad}  CHANNELS 3 Zrotation Yrotation Xrotation"])  # fmt: skip
        for c in kids[j]:
            joint(c, pad + "  ")
        if not kids[j]:
            lines.extend([f"{pad}  End Site", pad + "  {", f"{pad}    OFFSET 0 0 0",
                          pad + "  }"])  # fmt: skip
        lines.append(pad + "}")

    joint(list(parents).index(-1), "")
    return lines + ["MOTION", f"Frame Time: {1.0 / rate!r}"], order


def send_paced(ticks, to: str, rate: float, *, fast=False) -> int:
    """Send ``ticks`` (``[[datagram bytes of frame k] per k]``) over one UDP socket to ``to``
    (``HOST:PORT``), frame ``k`` at ``k / rate`` s (``fast``: one every millisecond: UDP has
    no back-pressure), as an emulated capture system does. Return the datagrams sent."""
    host, port = parse_address(to)
    family = socket.AF_INET6 if ":" in host else socket.AF_INET
    sent = 0
    with socket.socket(family, socket.SOCK_DGRAM) as sock:
        t0 = time.perf_counter()
        for k, frame in enumerate(ticks):
            if (wait := t0 + (k / 1000 if fast else k / rate) - time.perf_counter()) > 0:
                time.sleep(wait)
            for d in frame:
                sock.sendto(d, (host, port))
                sent += 1
    return sent


def parse_source(url: str):
    """``"axis://HOST:PORT"`` -> (module, host, port); ValueError naming what is wrong.

    ``axis://HOST`` takes the system's default port."""
    scheme, sep, rest = str(url).partition("://")
    if not sep or scheme not in SOURCES:
        known = ", ".join(f"{k}://HOST:PORT" for k in SOURCES)
        raise ValueError(f"--source {url!r}: expected {known}")
    module = importlib.import_module(SOURCES[scheme])
    if ":" not in (rest.rpartition("]")[2] if rest.startswith("[") else rest):
        rest = f"{rest}:{module.DEFAULT_PORT}"
    host, port = parse_address(rest)
    if port == 0:
        raise ValueError(f"--source {url!r}: port 0 is not a source's port")
    return module, host, port


def map_path(out, take: int, key, name: str) -> Path:
    """The ``--out`` file of one performer of one take: ``STEM-take<T>-<index>-<name>.csv``
    next to ``out`` (the name with anything but letters, digits, ``.``, ``_``, ``-`` as ``_``)."""
    out = Path(out)
    safe = re.sub(r"[^A-Za-z0-9._-]", "_", str(name))[:64] or "_"
    return out.with_name(f"{out.stem}-take{take}-{key}-{safe}{out.suffix or '.csv'}")


class Performer:
    """One performer of a take: its session and its counts."""

    def __init__(self, key, name, session, fps, about):
        self.key, self.name, self.session, self.fps, self.about = key, name, session, fps, about
        self.slot = 0  # the performer's frames in the stream so far, unusable ones included
        self.bad_run = 0
        self.ahead = 0
        self.t0 = None
        self.last_arrival = None


class Performers:
    """The performers of one take (see the module's docstring).

    Parameters
    ----------
    I : MotionFeatures
        The recorded input's features.
    make_aligner : callable
        ``make_aligner(I) -> OnlineAligner``.
    take : int
        The take's number (1, 2, ...), sent with every answer.
    max_performers : int
        Performers aligned at once; frames of more are counted as refused.
    senders : sequence
        ``fpdtw.app.serve._Sender`` of ``--send``.
    record : bool
        Keep every target frame (``--out``).
    log : callable
    **session_options
        ``position_joints``, ``gap``, ``joint_maps`` of :class:`fpdtw.app.serve.Session`.
    """

    def __init__(self, I, make_aligner, *, take=1, max_performers=8, senders=(), record=False,
                 log=print, view=None, **session_options):  # fmt: skip
        self.I, self.make_aligner, self.take = I, make_aligner, int(take)
        self.view = view  # --view: fpdtw.app.view.Viewer, watching every performer
        self.max_performers, self.senders, self.record = int(max_performers), senders, record
        self.log, self.options = log, session_options
        self.by_key = {}
        self.frames = 0  # frames read from the stream (their numbers, from 1)
        self.bad = dict.fromkeys(BAD_KINDS, 0)
        self.first_bad = {}
        self.loose_run = 0  # unusable frames in a row of no known performer

    def get(self, key):
        return self.by_key.get(key)

    def add(self, key, name, header_lines, fps: float, about: str):
        """A new performer whose stream is the BVH ``header_lines``; None (and the frame
        counted as refused) beyond ``max_performers``. TakeEnd for a header that fails."""
        if len(self.by_key) >= self.max_performers:
            self.count_bad(None, "refused", f"performer {key} {name!r}: {self.max_performers} "
                           "performers already (--max-clients)")  # fmt: skip
            return None
        s = Session(self.I, self.make_aligner, record=self.record, **self.options)
        try:
            for line in header_lines:
                s.feed(f"{line}\n".encode("latin-1"), 0.0)
        except FpdtwError as e:
            raise TakeEnd(f"frame {self.frames} (avatar {key} {name!r}): {_reason(e)}") from None
        if self.view is not None:
            s.watch = self.view.slot(f"{self.take}.{key}", name, s)  # take 2's 0 is not 1's
        p = self.by_key[key] = Performer(key, name, s, fps, about)
        self.log(f"take {self.take}: performer {key} {name!r} ({about})")
        return p

    def count_bad(self, perf, kind: str, what: str) -> None:
        """Count frame ``self.frames`` as unusable (``kind`` of :data:`BAD_KINDS`); its
        performer's slot stays taken (a gap). TakeEnd after too many in a row."""
        self.bad[kind] += 1
        where = f"frame {self.frames}"
        if perf is not None:
            where += f" (avatar {perf.key} {perf.name!r})"
        message = f"{where}: {what}"
        if kind not in self.first_bad:
            self.first_bad[kind] = message
            self.log(f"take {self.take}: {message} (dropped; counted in the summary)")
        if kind in ("cut", "oversize", "empty", "refused", "flood", "skipped"):
            return
        if perf is None:
            self.loose_run += 1
            run, limit = self.loose_run, BAD_RUN_MIN
        else:
            perf.slot += 1
            perf.bad_run += 1
            run, limit = perf.bad_run, max(BAD_RUN_MIN, round(BAD_RUN_S * perf.fps))
        if run > limit:
            raise TakeEnd(f"{message}; {run} unusable frames in a row: the take cannot go on")

    def feed(self, perf: Performer, values, arrival: float, t=None) -> None:
        """Frame ``self.frames`` of ``perf``: its BVH channel values (checked by the source;
        a motion line, or the values (n_channels,) float64, which skip writing and parsing
        the line), aligned and answered, at capture time ``t`` (default: its slot at the
        rate). TakeEnd when its session refuses it."""
        k = perf.slot
        if perf.t0 is None:
            perf.t0 = arrival
        elif arrival < perf.t0 + k / perf.fps - AHEAD_S:
            perf.ahead += 1
        perf.last_arrival = arrival
        try:
            t = k / perf.fps if t is None else t
            if isinstance(values, str):
                answer = perf.session.feed(stamp(values, t).encode("latin-1"), arrival)
            else:
                answer = perf.session.feed_row(values, t, arrival)
        except FpdtwError as e:
            raise TakeEnd(
                f"frame {self.frames} (avatar {perf.key} {perf.name!r}): {_reason(e)}"
            ) from None
        perf.slot += 1
        perf.bad_run = 0
        self.loose_run = 0
        if answer is not None and self.senders:
            (index, m), latency = perf.session.last, perf.session.latencies[-1]
            for s in self.senders:
                s.send(self.take, index, m, m / self.I.fps, round(latency * 1e6),
                       (perf.key, perf.name))  # fmt: skip

    def summary(self) -> list:
        """One dict per performer: key, name, about, the session's summary, ahead, the
        rate the frames arrived at (Hz, None with fewer than two)."""
        out = []
        for p in self.by_key.values():
            s = dict(key=p.key, name=p.name, about=p.about, ahead=p.ahead, **p.session.summary())
            span = (p.last_arrival or 0.0) - (p.t0 or 0.0)
            s["arrival_hz"] = (s["frames"] - 1) / span if s["frames"] > 1 and span > 0 else None
            out.append(s)
        return out

    def report(self) -> list:
        """The summary as log lines."""
        bad = [f"{n} {BAD_KINDS[k]}" for k, n in self.bad.items() if n]
        lines = [f"  {self.frames} frames read; unusable: {', '.join(bad) or 'none'}"]
        for s in self.summary():
            lat = (f"; server latency p50 {s['p50_us']:.0f} us, p99 {s['p99_us']:.0f} us"
                   if s["p50_us"] is not None else "")  # fmt: skip
            rate = f", arrived at {s['arrival_hz']:.1f} Hz" if s["arrival_hz"] else ""
            lines.append(
                f"  avatar {s['key']} {s['name']!r} ({s['about']}): {s['frames']} frames, "
                f"{s['ticks']} target frames at the input's rate, {s['lost']} lost and "
                f"{s['filled']} filled, {s['ahead']} ahead of real time{rate}{lat}"
            )
        return lines

    def write_maps(self, out) -> list:
        """Each performer's map as ``fpdtw align --out`` writes it (:func:`map_path`);
        return the paths (none for a performer without a target frame)."""
        paths = []
        for p in self.by_key.values():
            M = session_map(p.session)
            if M.size:
                path = map_path(out, self.take, p.key, p.name)
                write_map_csv(path, M, self.I.fps, self.I.fps)
                paths.append(path)
        return paths


def _reason(e: Exception) -> str:
    return getattr(e, "reason", None) or str(e)


def run_source(source, make_performers, *, once=False, out=None, idle_timeout=10.0, log=None,
               stdout=None, view=None) -> int:  # fmt: skip
    """Read takes from ``source`` until SIGINT or SIGTERM (``once``: after the first take).

    Parameters
    ----------
    source
        A source module's ``Source``.
    make_performers : callable
        ``make_performers(take) -> Performers``.
    once : bool
    out : str, optional
        ``--out``: every performer's map (:func:`map_path`).
    idle_timeout : float
        Seconds the source may stay silent within a take.
    log, stdout
        Where the log (default stderr) and ``connected to ...`` (default stdout) go.
    view : fpdtw.app.view.Viewer, optional
        ``--view``: its page served in the same loop (its address printed to ``stdout``).

    Returns
    -------
    code : int
        0; 1 when the first take's source cannot be reached, or with ``once`` when the take
        ended with an error.

    Raises
    ------
    OSError
        The source cannot be reached for the first take.
    """
    log = log or (lambda msg: print(msg, file=sys.stderr, flush=True))
    stdout = sys.stdout if stdout is None else stdout

    async def main():
        loop = asyncio.get_running_loop()
        stop = asyncio.Event()
        for sig in (signal.SIGINT, signal.SIGTERM):
            loop.add_signal_handler(sig, stop.set)
        if view is not None:
            await view.start(stdout)
        try:
            return await _takes(loop, stop)
        finally:
            for sig in (signal.SIGINT, signal.SIGTERM):
                loop.remove_signal_handler(sig)
            if view is not None:
                await view.stop()

    async def _takes(loop, stop):
        take, failed, waiting = 0, False, False
        while not stop.is_set():
            try:
                conn = await source.connect()
            except OSError as e:
                why = os.strerror(e.errno) if e.errno else str(e)
                if take == 0:
                    raise ConnectionError(
                        f"cannot connect: {why} (is the capture system broadcasting there?)"
                    ) from None
                if not waiting:
                    log(f"waiting for {source.describe()} ({why})")
                    waiting = True
                with contextlib.suppress(TimeoutError):
                    await asyncio.wait_for(stop.wait(), RETRY_S)
                continue
            take, waiting = take + 1, False
            print(f"connected to {source.describe()}", file=stdout, flush=True)
            performers = make_performers(take)
            reading = asyncio.ensure_future(source.read(conn, performers, idle_timeout))
            stopping = asyncio.ensure_future(stop.wait())
            await asyncio.wait({reading, stopping}, return_when=asyncio.FIRST_COMPLETED)
            stopping.cancel()
            failed = False
            if not reading.done():
                reading.cancel()
                await asyncio.gather(reading, return_exceptions=True)
                end = "stopped (SIGINT or SIGTERM)"
            else:
                try:
                    end = reading.result()
                except TakeEnd as e:
                    end, failed = f"ended with an error: {e}", True
            log(f"take {take} from {source.describe()} {end}")
            for line in performers.report():
                log(line)
            if out is not None:
                for path in performers.write_maps(out):
                    log(f"  map: {path}")
            if once:
                break
        return 1 if (once and failed) else 0

    return asyncio.run(main())


__all__ = [
    "AHEAD_S",
    "BAD_KINDS",
    "BAD_RUN_S",
    "SOURCES",
    "Performer",
    "Performers",
    "TakeEnd",
    "map_path",
    "parse_source",
    "run_source",
]
