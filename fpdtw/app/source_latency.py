"""How long a capture source takes: from a frame on the wire to fpdtw's answer (issue 32).

For each source (:data:`fpdtw.app.sources.SOURCES`), ``fpdtw serve INPUT -m c -w 40 --source
SCHEME://127.0.0.1:PORT --send udp://127.0.0.1:PORT --once`` runs as a command in its own
process, and this one plays a take as the system sends it, through that source's emulator,
in real time, for 1 and for N performers at once (the same take each). A frame's latency is
the time from just before its datagrams (or its TCP bytes) are written to the moment its
answer arrives on the ``--send`` socket: the loopback, the source's decoding, the live
target, the aligner and the answer. The first :data:`WARMUP_FRAMES` frames of every performer
are left out (a take's first frames load code paths; the server compiles its kernels before
the take starts).
"""

from __future__ import annotations

import socket
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

import numpy as np

from fpdtw.app.source_axis import axis_frames
from fpdtw.app.source_axis_udp import axis_udp_datagrams
from fpdtw.app.source_natnet import natnet_packets
from fpdtw.app.source_rokoko import rokoko_datagrams
from fpdtw.app.source_vmc import vmc_frames
from fpdtw.app.source_xsens import xsens_datagrams
from fpdtw.app.stream import take_lines
from fpdtw.io.bvh import write_bvh

#: Frames of every performer left out of the statistics, at the start of a take.
WARMUP_FRAMES = 10
#: The method measured, as ``fpdtw serve`` options.
OPTIONS = ("-m", "c", "-w", "40")
#: The bar (issue 32, as for fpdtw's own protocol): p99 below this, one performer, in ms.
BAR_MS = 2.0


def _axis(motions):
    frames = axis_frames([take_lines(m) for m in motions])
    n = len(motions)
    return motions[0].fps, [[(p, frames[k * n + p][1]) for p in range(n)]
                            for k in range(len(frames) // n)]  # fmt: skip


def _axis_udp(motions):
    rate, ticks = axis_udp_datagrams([take_lines(m) for m in motions])
    return rate, [list(enumerate(t)) for t in ticks]


def _vmc(motions):
    takes = [vmc_frames(m) for m in motions]
    return takes[0][0], [[(p, b.dgram) for p, b in enumerate(f)]
                         for f in zip(*(t[1] for t in takes))]  # fmt: skip


def _xsens(motions):
    rate, ticks = xsens_datagrams(motions)
    return rate, [list(enumerate(t)) for t in ticks]


def _rokoko(motions):
    rate, datagrams = rokoko_datagrams(motions)  # one datagram holds every actor
    return rate, [[(0, d)] for d in datagrams]


def _natnet(motions):
    rate, info, modeldef, frames = natnet_packets(motions)
    return rate, [[(0, d)] for d in frames], {0: info, 4: modeldef}


#: Scheme -> ``(wire, role)``: ``wire(motions)`` gives ``(rate, [[(performer, bytes) of frame
#: k] per k])`` (and, for a server, its answers by request type); ``role``: ``"send"`` (UDP to
#: the port fpdtw listens on), ``"tcp"`` (a TCP server fpdtw connects to) or ``"serve"`` (a
#: UDP server fpdtw asks, then streams to).
WIRES = {"axis": (_axis, "tcp"), "axis+udp": (_axis_udp, "send"), "vmc": (_vmc, "send"),
         "xsens": (_xsens, "send"), "rokoko": (_rokoko, "send"),
         "natnet": (_natnet, "serve")}  # fmt: skip


def _reply(sock, replies: dict, timeout: float):
    """Answer one request arriving on ``sock`` within ``timeout`` s (by its little-endian
    uint16 type, from ``replies``); return the address of a request for the descriptions
    (type 4), else None. TimeoutError when nothing came within a positive ``timeout``."""
    sock.settimeout(timeout)
    try:
        data, addr = sock.recvfrom(65536)
    except BlockingIOError:
        return None
    kind = int.from_bytes(data[:2], "little")
    if kind in replies:
        sock.sendto(replies[kind], addr)
    return addr if kind == 4 else None


def _answers(sock, got: list, stop: threading.Event) -> None:
    """Collect ``(arrival, index, performer key)`` of every answer line until ``stop``."""
    sock.settimeout(0.2)
    while not stop.is_set():
        try:
            data = sock.recv(65536)
        except TimeoutError:
            continue
        now = time.perf_counter()
        words = data.split()  # take index m t latency_us key name
        if len(words) >= 6:
            got.append((now, int(words[1]), words[5].decode(), int(words[4])))


def measure(scheme: str, input_path, take, performers: int = 1, timeout: float = 120.0):
    """The latency of one source for ``performers`` copies of ``take`` (a Motion).

    Returns
    -------
    result : dict
        ``source``, ``performers``, ``frames`` (sent per performer), ``answers`` (counted),
        ``p50_ms``, ``p99_ms``, ``max_ms`` (wire to answer) and ``server_p50_ms``,
        ``server_p99_ms`` (the server's own time per frame, as it reports it).

    Notebook: 20_align_a_live_performance.ipynb
    """
    wire, role = WIRES[scheme]
    motions = [take.replace(name=f"{take.name}_{p}") for p in range(performers)]
    rate, ticks, *replies = wire(motions)
    answers = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    answers.bind(("127.0.0.1", 0))
    got, stop = [], threading.Event()
    reader = threading.Thread(target=_answers, args=(answers, got, stop), daemon=True)
    reader.start()
    if role == "tcp":
        ours = socket.create_server(("127.0.0.1", 0))
    else:
        ours = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        ours.bind(("127.0.0.1", 0))
    port = ours.getsockname()[1]
    if role == "send":  # fpdtw listens on this port: free it
        ours.close()
    cmd = [sys.executable, "-m", "fpdtw.app.cli", "serve", str(input_path), *OPTIONS,
           "--source", f"{scheme}://127.0.0.1:{port}", "--once", "--idle-timeout", "2",
           "--send", f"udp://127.0.0.1:{answers.getsockname()[1]}"]  # fmt: skip
    tmp = tempfile.TemporaryDirectory()
    if scheme.startswith("axis"):
        cmd += ["--header", str(write_bvh(take, Path(tmp.name) / "header.bvh"))]
    else:
        cmd += ["--rate", repr(float(rate))]
    sent = np.full(len(ticks), np.nan)
    socks = []
    try:
        server = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        try:
            if role == "tcp":
                ours.settimeout(timeout)
                conn, _ = ours.accept()
                conn.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
                socks = [conn]
                send = [conn.sendall] * performers
            elif role == "serve":  # answer fpdtw's requests; stream to whoever asked
                client = None
                while client is None:
                    client = _reply(ours, replies[0], timeout)
                send = [lambda d: ours.sendto(d, client)]
            else:
                socks = [socket.socket(socket.AF_INET, socket.SOCK_DGRAM) for _ in motions]
                send = [lambda d, s=s: s.sendto(d, ("127.0.0.1", port)) for s in socks]
            line = server.stdout.readline()
            if not line.startswith("connected to"):
                raise RuntimeError(f"fpdtw serve --source {scheme}:// did not start: {line!r}")
            t0 = time.perf_counter() + 0.2
            for k, tick in enumerate(ticks):
                if role == "serve":
                    _reply(ours, replies[0], 0.0)
                if (wait := t0 + k / rate - time.perf_counter()) > 0:
                    time.sleep(wait)
                sent[k] = time.perf_counter()
                for p, data in tick:
                    send[p](data)
            for s in socks:
                s.close()
            server.wait(timeout)
        finally:
            if server.poll() is None:
                server.kill()
                server.wait()
            err = server.stderr.read()
            server.stdout.close()
            server.stderr.close()
    finally:
        stop.set()
        reader.join()
        answers.close()
        ours.close()
        tmp.cleanup()
    keep = [(a, i, us) for a, i, _, us in got if WARMUP_FRAMES <= i < len(ticks)]
    if not keep:
        raise RuntimeError(f"no answers from --source {scheme}://: {err[-500:]}")
    lat = np.array([(a - sent[i]) * 1e3 for a, i, _ in keep])
    own = np.array([us for *_, us in keep]) / 1e3
    return dict(
        source=scheme,
        performers=int(performers),
        frames=len(ticks),
        answers=len(got),
        p50_ms=float(np.percentile(lat, 50)),
        p99_ms=float(np.percentile(lat, 99)),
        max_ms=float(lat.max()),
        server_p50_ms=float(np.percentile(own, 50)),
        server_p99_ms=float(np.percentile(own, 99)),
    )


def bar_rows(rows, bar_ms: float = BAR_MS) -> list:
    """The bar per source, over every one-performer run of :func:`measure` in ``rows``: the
    p99 of each run (ms), and a verdict. A p99 of 600 frames moves by tenths of a
    millisecond from run to run on a shared machine, so a source passes only when every run
    is below the bar; runs on both sides are not a pass.

    Notebook: 20_align_a_live_performance.ipynb
    """
    out = []
    for source in dict.fromkeys(r["source"] for r in rows):
        p99 = [r["p99_ms"] for r in rows if r["source"] == source and r["performers"] == 1]
        below = sum(p < bar_ms for p in p99)
        verdict = ("below in every run" if below == len(p99) else
                   "below in no run" if not below else
                   f"below in {below} of {len(p99)} runs: not a pass")  # fmt: skip
        out.append(dict(source=source, runs=len(p99), p99_ms=" ".join(f"{p:.2f}" for p in p99),
                        bar_ms=bar_ms, verdict=verdict))  # fmt: skip
    return out
