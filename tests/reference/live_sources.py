"""What the tests of the capture sources share: the offline map a source must reproduce, and one
take end to end through both commands."""

from __future__ import annotations

import asyncio
import socket
import subprocess
import sys
import threading

import numpy as np

from fpdtw.app import cli
from fpdtw.app.export import read_map_csv
from fpdtw.app.sources import DatagramReceiver, Performers, TakeEnd
from fpdtw.io.bvh import read_bvh
from fpdtw.motion.features import MotionFeatures
from fpdtw.registry import align, resolve

#: The method every source test runs.
METHOD = "Mc w40"
_OFFLINE: dict = {}


def offline_map(FI, take) -> np.ndarray:
    """``fpdtw align``'s map (:data:`METHOD`) of a take against the recording ``FI``: int64
    (n+1,)."""
    key = (FI.name, str(take))
    if key not in _OFFLINE:
        M, _ = align(METHOD, FI, MotionFeatures.from_motion(read_bvh(take)))
        _OFFLINE[key] = np.asarray(M, dtype=np.int64)
    return _OFFLINE[key]


def serve_and_stream(scheme: str, recording, takes, tmp_path, options=("--rate", "30")) -> tuple:
    """``fpdtw serve RECORDING --source SCHEME://127.0.0.1:PORT OPTIONS --once --out`` in its
    own process (``options``: ``--rate 30``, or ``--header FILE`` for a source without a
    skeleton) and ``fpdtw stream TAKES --as SCHEME --fast`` in this one; checks that each map
    file is ``fpdtw align``'s (Mc w40) and returns the server's stderr and the map files."""
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    serve = subprocess.Popen(
        [sys.executable, "-m", "fpdtw.app.cli", "serve", str(recording), "--source",
         f"{scheme}://127.0.0.1:{port}", *options, "--once", "--idle-timeout", "1",
         "--out", str(tmp_path / "live.csv")],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )  # fmt: skip
    try:
        assert serve.stdout.readline().strip() == f"connected to {scheme}://127.0.0.1:{port}"
        assert cli.main(["stream", *map(str, takes), "--as", scheme, "--to",
                         f"127.0.0.1:{port}", "--fast"]) == 0  # fmt: skip
        assert serve.wait(60) == 0
        err = serve.stderr.read()
    finally:
        if serve.poll() is None:
            serve.kill()
        serve.wait()
        serve.stdout.close()
        serve.stderr.close()
    files = sorted(tmp_path.glob("live-take1-*.csv"))
    assert len(files) == len(takes), err
    for f, take in zip(files, takes, strict=True):
        ref = tmp_path / f"ref-{take.stem}.csv"
        align = ["align", str(recording), str(take), "-m", "c", "-w", "40", "--out", str(ref)]
        assert cli.main(align) == 0
        np.testing.assert_array_equal(
            read_map_csv(f)["input_frame"], read_map_csv(ref)["input_frame"]
        )
    return err, files


def performers(FI, log: list, joint_maps=(), **kw) -> Performers:
    """The :class:`Performers` of a source test: :data:`METHOD`, recording, logging to ``log``."""
    return Performers(FI, resolve(METHOD).make, record=True, log=log.append,
                      joint_maps=list(joint_maps), **kw)  # fmt: skip


def read_sent(source, send, FI, joint_maps=(), *, idle=0.5) -> tuple:
    """What UDP ``source`` reads while ``send(port)`` sends to it from a thread:
    (performers, how the take ended, log)."""

    async def main():
        conn = await source.connect()
        log = []
        perf = performers(FI, log, joint_maps)
        sender = threading.Thread(target=send, args=(conn[0].get_extra_info("sockname")[1],))
        sender.start()
        try:
            end = await source.read(conn, perf, idle)
        except TakeEnd as e:
            end = f"error: {e}"
        sender.join()
        return perf, end, log

    return asyncio.run(main())


class NoTransport:
    """The transport of datagrams put straight into a source's queue: nothing to close."""

    def close(self):
        pass


def read_queued(source, datagrams, FI, joint_maps=(), *, idle=0.2, **kw) -> tuple:
    """``datagrams`` (``(bytes, addr)`` pairs) handed to ``source`` as its socket would,
    nothing lost: (performers, how the take ended, log)."""

    async def main():
        proto = DatagramReceiver()
        for data, addr in datagrams:
            proto.datagram_received(data, addr)
        log = []
        perf = performers(FI, log, joint_maps, **kw)
        try:
            end = await source.read((NoTransport(), proto), perf, idle)
        except TakeEnd as e:
            end = f"error: {e}"
        return perf, end, log

    return asyncio.run(main())
