"""``axis://HOST:PORT``: Axis Neuron's and Axis Studio's "BVH string" broadcast, both ways.

Axis is the TCP server (port 7001 by default); fpdtw connects to it as a client and only
reads. The stream carries no HIERARCHY: each frame is the text
``<avatar index> <avatar name> v1 ... vN ||``, framed by ``||`` (whitespace or newlines may
come between frames). The skeleton comes from ``--header FILE.bvh``, a BVH file of the same
joints (its ``Frame Time`` is the stream's rate; its motion lines, if any, are ignored).

The values are the header's joints in its order. With displacement each joint sends six
values, its position and its rotation; without, only the root sends a position. Which one a
performer's stream is follows from its first frame's value count (for a 59-joint skeleton 354
or 180); any other count is refused. A joint's rotation channels are in the header's order
(Axis' default is ``Yrotation Xrotation Zrotation``); positions in the header's order when the
joint has position channels there, else X, Y, Z, before the rotations. A non-root position
becomes the joint's offset, as in a BVH file, and must stay the same over the take.

:func:`play_as_axis` is the other side without hardware: a TCP server that plays takes
(one avatar each, frames interleaved) as this broadcast (``fpdtw stream --as axis``).
"""

from __future__ import annotations

import asyncio
import re
import sys
from pathlib import Path

import numpy as np

from fpdtw import limits
from fpdtw.app.serve import _TimedReader, parse_address
from fpdtw.app.sources import TakeEnd
from fpdtw.io._text import read_lines
from fpdtw.io.bvh import parse_bvh_header

#: Axis Neuron's default port of the BVH broadcast.
DEFAULT_PORT = 7001
#: What ends a frame.
SEPARATOR = b"||"
_XYZ = ("xposition", "yposition", "zposition")


def wire_channels(joints, displacement: bool) -> list:
    """Each joint's channels on the wire (lower case, as the BVH parser keeps them)."""
    out = []
    for j, jt in enumerate(joints):
        rot = [c for c in jt.channels if c.endswith("rotation")]
        if j == 0 or displacement:
            has_pos = any(c.endswith("position") for c in jt.channels)
            out.append(list(jt.channels) if has_pos else [*_XYZ, *rot])
        else:
            out.append(rot)
    return out


def _channel_line(line: str, chans) -> str:
    names = " ".join(c[0].upper() + c[1:] for c in chans)
    return f"{line[: line.index('CHANNELS')]}CHANNELS {len(chans)} {names}"


class AxisHeader:
    """The ``--header`` file and the BVH header of each wire layout.

    Attributes
    ----------
    path : str
    fps : float
        Its ``Frame Time``'s rate: the stream's.
    counts : dict of int to (bool, list of str)
        Values a frame -> (with displacement, the BVH header the frames are read with).
    """

    def __init__(self, path):
        self.path = str(path)
        text = read_lines(Path(path))
        h = parse_bvh_header(text, self.path, stream=True)
        self.fps, self.n_joints = h.fps, len(h.joints)
        head = [s for s in text[: h.end_line] if not s.strip().lower().startswith("frames:")]
        self.counts = {}
        for displacement in (True, False):
            chans = wire_channels(h.joints, displacement)
            lines = list(head)
            for jt, c in zip(h.joints, chans, strict=True):
                lines[jt.chan_line - 1] = _channel_line(text[jt.chan_line - 1], c)
            self.counts.setdefault(sum(map(len, chans)), (displacement, lines))

    def expected(self) -> str:
        with_d = next(n for n, (d, _) in self.counts.items() if d)
        without = next((n for n, (d, _) in self.counts.items() if not d), with_d)
        return (f"{with_d} (with displacement) or {without} (without) for the {self.n_joints} "
                f"joints of {self.path}")  # fmt: skip


class Source:
    """Reads one Axis broadcast per take (see the module's docstring).

    Parameters
    ----------
    host, port : str, int
        Where Axis broadcasts.
    header : str or os.PathLike
        The BVH file of the streamed skeleton (``--header``).
    """

    def __init__(self, host: str, port: int, *, header=None):
        if header is None:
            raise ValueError("axis:// needs --header FILE.bvh: the stream carries no skeleton")
        self.host, self.port = host, port
        self.header = AxisHeader(header)
        self.max_frame = int(limits.get("max_line_bytes"))

    def describe(self) -> str:
        host = f"[{self.host}]" if ":" in self.host else self.host
        return f"axis://{host}:{self.port}"

    async def connect(self):
        """Connect; return the reader and its transport (OSError when nobody answers)."""
        loop = asyncio.get_running_loop()
        reader = _TimedReader(limit=self.max_frame, loop=loop)
        transport, _ = await loop.create_connection(
            lambda: asyncio.StreamReaderProtocol(reader, loop=loop), self.host, self.port
        )
        return reader, transport

    async def read(self, connection, performers, idle_timeout: float) -> str:
        """Read frames until the connection closes; return how the take ended."""
        reader, transport = connection
        try:
            while True:
                try:
                    async with asyncio.timeout(idle_timeout):
                        raw, arrival = await reader.timed_until(SEPARATOR)
                except asyncio.IncompleteReadError as e:
                    if e.partial.strip():
                        performers.frames += 1
                        performers.count_bad(None, "cut", f"{len(e.partial)} bytes without "
                                             "'||' when the connection closed")  # fmt: skip
                    return "ended: the source closed the connection"
                except asyncio.LimitOverrunError:
                    performers.frames += 1
                    performers.count_bad(None, "oversize", "")
                    raise TakeEnd(
                        f"frame {performers.frames}: more than {self.max_frame} bytes without "
                        f"'||' ({limits.env_name('max_line_bytes')})"
                    ) from None
                except TimeoutError:
                    raise TakeEnd(
                        f"frame {performers.frames + 1}: nothing received for {idle_timeout:g} "
                        "s (--idle-timeout)"
                    ) from None
                except ConnectionError as e:
                    return f"ended: the connection was lost ({type(e).__name__})"
                self.frame(raw[: -len(SEPARATOR)], arrival, performers)
                await asyncio.sleep(0)
        finally:
            transport.close()

    def frame(self, body: bytes, arrival: float, performers) -> None:
        """One frame's bytes (without ``||``): checked, then aligned (or counted)."""
        performers.frames += 1
        toks = body.split()
        if not toks:
            return performers.count_bad(None, "empty", "no values between two '||'")
        try:
            key = int(toks[0])
        except ValueError:
            key = None
        if key is None or len(toks) < 2:
            return performers.count_bad(
                None, "name", f"expected '<avatar index> <avatar name> values ||', got "
                f"{body[:40].decode('latin-1')!r}"
            )  # fmt: skip
        name, values = toks[1].decode("latin-1"), toks[2:]
        perf = performers.get(key)
        if perf is None:
            layout = self.header.counts.get(len(values))
            if layout is None:
                return performers.count_bad(
                    None, "count", f"avatar {key} {name!r}: {len(values)} values, expected "
                    f"{self.header.expected()}"
                )  # fmt: skip
            displacement, lines = layout
            about = f"{len(values)} values a frame, {'with' if displacement else 'without'} "
            perf = performers.add(key, name, lines, self.header.fps, about + "displacement")
            if perf is None:
                return None
            perf.n_values = len(values)
        if len(values) != perf.n_values:
            return performers.count_bad(
                perf, "count", f"{len(values)} values, expected {perf.n_values}"
            )
        try:
            x = np.array(values, dtype=float)
        except ValueError:
            bad = next(v for v in values if not _is_number(v))
            return performers.count_bad(perf, "number", f"value {bad.decode('latin-1')!r} "
                                        "is not a number")  # fmt: skip
        if not np.isfinite(x).all():
            return performers.count_bad(perf, "finite", "a value is NaN or inf")
        big = limits.get("max_abs_value")
        if np.abs(x).max() > big:
            return performers.count_bad(
                perf, "large", f"a value beyond {big:g} ({limits.env_name('max_abs_value')})"
            )
        return performers.feed(perf, x, arrival)


def _is_number(token: bytes) -> bool:
    try:
        float(token)
    except ValueError:
        return False
    return True


# -- the broadcast, without hardware ----------------------------------------------------------


def axis_frames(takes, *, displacement: bool = False) -> list:
    """The frames of ``takes`` (one avatar each, index 0, 1, ...) as Axis broadcasts them:
    ``[(capture time s, bytes)]``, frame ``k`` of every avatar at ``k / rate``, in order.

    Every take must have the same rate; an avatar's name is its take's name (whitespace
    as ``_``). ValueError otherwise."""
    takes = list(takes)
    fps = takes[0].fps
    out = []
    per_take = []
    for i, take in enumerate(takes):
        if abs(take.fps - fps) > 1e-9 * fps:
            raise ValueError(f"take {take.name} is at {take.fps:g} Hz, take {takes[0].name} at "
                             f"{fps:g} Hz: play them at one --rate")  # fmt: skip
        h = parse_bvh_header(take.header, take.name, stream=True)
        cols, col = [], 0
        for jt in h.joints:
            cols.append({c: col + n for n, c in enumerate(jt.channels)})
            col += len(jt.channels)
        pick = []  # per wire value: a column of the line, or the offset's text
        for jt, at, chans in zip(h.joints, cols, wire_channels(h.joints, displacement),
                                 strict=True):  # fmt: skip
            for c in chans:
                pick.append(at[c] if c in at else repr(float(jt.offset[_XYZ.index(c)])))
        name = re.sub(r"\s", "_", take.name) or f"Avatar{i:02d}"
        per_take.append((i, name, pick, take.lines))
    n = max(len(t.lines) for t in takes)
    for k in range(n):
        for i, name, pick, lines in per_take:
            if k < len(lines):
                v = lines[k].split()
                text = " ".join(v[p] if isinstance(p, int) else p for p in pick)
                out.append((k / fps, f"{i} {name} {text} ||".encode("latin-1")))
    return out


async def serve_axis(frames, host: str, port: int, *, fast=False, on_listening=None,
                     timeout: float = 60.0) -> int:  # fmt: skip
    """Listen on ``host:port`` as Axis does; play ``frames`` (:func:`axis_frames`) to the
    first client at their times (``fast``: as fast as it reads them), then close. Return the
    frames sent (fewer if the client left). ``on_listening(host, port)`` once listening;
    TimeoutError when no client comes within ``timeout`` seconds."""
    done = asyncio.get_running_loop().create_future()
    sent = 0

    async def client(reader, writer):
        nonlocal sent
        if done.done():
            writer.close()
            return
        try:
            loop = asyncio.get_running_loop()
            t0 = loop.time()
            for t, data in frames:
                if not fast and (wait := t0 + t - loop.time()) > 0:
                    await asyncio.sleep(wait)
                writer.write(data)
                await writer.drain()
                sent += 1
        except ConnectionError:
            pass
        finally:
            writer.close()
            if not done.done():
                done.set_result(sent)

    server = await asyncio.start_server(client, host, port)
    try:
        bound = server.sockets[0].getsockname()
        if on_listening is not None:
            on_listening(bound[0], bound[1])
        async with asyncio.timeout(timeout):
            return await done
    finally:
        server.close()
        await server.wait_closed()


def play_as_axis(takes, listen: str, *, fast=False, displacement=False, timeout=60.0,
                 out=None) -> int:  # fmt: skip
    """Play ``takes`` (:class:`fpdtw.app.stream.TakeLines`, one avatar each) as Axis' BVH
    broadcast on ``listen`` (``HOST:PORT``; port 0: any free one) to the first client; return
    the frames sent. Prints ``listening on HOST:PORT`` to ``out`` (default stdout)."""
    out = sys.stdout if out is None else out
    takes = list(takes)
    host, port = parse_address(listen)
    frames = axis_frames(takes, displacement=displacement)

    def say(h, p):
        print(f"listening on {f'[{h}]' if ':' in h else h}:{p}", file=out, flush=True)

    sent = asyncio.run(serve_axis(frames, host, port, fast=fast, on_listening=say,
                                  timeout=timeout))  # fmt: skip
    print(f"sent {sent} of {len(frames)} frames ({len(takes)} avatars)", file=out)
    return sent


__all__ = [
    "DEFAULT_PORT",
    "SEPARATOR",
    "AxisHeader",
    "Source",
    "axis_frames",
    "play_as_axis",
    "serve_axis",
    "wire_channels",
]
