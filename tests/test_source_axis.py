"""``fpdtw serve --source axis://``: Axis Neuron's BVH string broadcast, read from our own
emulator of it (``fpdtw stream --as axis``, written from the published format) over
127.0.0.1, and from a raw sender of hostile bytes.

The recording and the skeleton are CMU 18_01 (31 joints, 30 Hz); the live takes are it
retimed (written as BVH files), so that the maps are not the identity.
"""

from __future__ import annotations

import asyncio
import socket
import subprocess
import sys
import threading

import numpy as np
import pytest
from reference.live_sources import METHOD, offline_map

from fpdtw import limits
from fpdtw.app import cli
from fpdtw.app.export import read_map_csv
from fpdtw.app.source_axis import AxisHeader, Source, axis_frames, serve_axis
from fpdtw.app.sources import Performers, TakeEnd, map_path, parse_source
from fpdtw.app.stream import session_map, take_lines
from fpdtw.io.bvh import parse_bvh_header, read_bvh
from fpdtw.registry import resolve

CMU = "cmu/18_01.bvh"


@pytest.fixture(scope="module")
def cmu(cmu_retimed):
    """The recording (path, features) and two retimed takes of it (paths)."""
    return cmu_retimed


def run(frames, header, FI, *, fast=True, max_performers=8, idle=5.0):
    """Serve ``frames`` [(time s, bytes)] as Axis does on 127.0.0.1 and read them with the
    axis source: (performers, how the take ended, log)."""

    async def main():
        port = asyncio.get_running_loop().create_future()
        emu = asyncio.ensure_future(
            serve_axis(
                frames, "127.0.0.1", 0, fast=fast, on_listening=lambda h, p: port.set_result(p)
            )
        )
        source = Source("127.0.0.1", await port, header=header)
        log = []
        perf = Performers(FI, resolve(METHOD).make, record=True, log=log.append,
                          max_performers=max_performers)  # fmt: skip
        try:
            end = await source.read(await source.connect(), perf, idle)
        except TakeEnd as e:
            end = f"error: {e}"
        await asyncio.wait_for(emu, 20)
        return perf, end, log

    return asyncio.run(main())


def raw(*chunks):
    return [(0.0, c) for c in chunks]


# ------------------------------------------------------------------------------- the format
def _chain_bvh(n_joints: int) -> list:
    """A BVH header of a chain of ``n_joints`` joints, Axis' YXZ rotation order."""
    out = ["HIERARCHY", "ROOT Hips", "{", "OFFSET 0 0 0",
           "CHANNELS 6 Xposition Yposition Zposition Yrotation Xrotation Zrotation"]  # fmt: skip
    for j in range(1, n_joints):
        out += [f"JOINT J{j}", "{", "OFFSET 0 1 0", "CHANNELS 3 Yrotation Xrotation Zrotation"]
    out += ["End Site", "{", "OFFSET 0 1 0", "}"] + ["}"] * n_joints
    return out + ["MOTION", "Frames: 0", "Frame Time: 0.01"]


def test_value_counts_and_rotation_order_follow_the_header(tmp_path, cmu):
    """59 joints: 354 values with displacement, 180 without (the published counts); CMU's
    31: 186 and 96. The layouts keep the header's rotation order (YXZ here) and offsets."""
    f = tmp_path / "axis59.bvh"
    f.write_text("\n".join(_chain_bvh(59)) + "\n")
    h59 = AxisHeader(f)
    assert sorted(h59.counts) == [180, 354] and h59.fps == 100.0
    for n, (disp, lines) in h59.counts.items():
        h = parse_bvh_header(lines, None, stream=True)
        assert h.n_channels == n and disp == (n == 354)
        ref = parse_bvh_header(_chain_bvh(59), None, stream=True).skeleton.rotation_orders
        assert h.skeleton.rotation_orders == ref and len(set(ref)) == 1
    path, _, _ = cmu
    hc = AxisHeader(path)
    assert sorted(hc.counts) == [96, 186]
    ref = read_bvh(path).skeleton
    for _, lines in hc.counts.values():
        sk = parse_bvh_header(lines, None, stream=True).skeleton
        assert sk.rotation_orders == ref.rotation_orders
        np.testing.assert_array_equal(sk.offsets, ref.offsets)


def test_source_urls_and_map_names(tmp_path):
    module, host, port = parse_source("axis://10.0.0.5")
    assert module.DEFAULT_PORT == 7001 and (host, port) == ("10.0.0.5", 7001)
    assert parse_source("axis://[::1]:7005")[1:] == ("::1", 7005)
    for bad in ("kinect://127.0.0.1:1", "axis://h:0", "127.0.0.1:7001"):
        with pytest.raises(ValueError):
            parse_source(bad)
    assert map_path(tmp_path / "m.csv", 2, 1, "Av 1/x").name == "m-take2-1-Av_1_x.csv"


# --------------------------------------------------------------------- the offline map
@pytest.mark.parametrize("displacement", [False, True])
def test_one_performer_gives_the_map_of_fpdtw_align(cmu, displacement):
    """A retimed take through the emulator, flooding (no pacing): frame for frame the
    offline map; every frame ahead of real time is counted, none is lost or filled."""
    path, FI, (warp, _) = cmu
    frames = axis_frames([take_lines(warp)], displacement=displacement)
    assert len(frames[0][1].split()) == 2 + (186 if displacement else 96) + 1
    perf, end, _ = run(frames, path, FI)
    assert end == "ended: the source closed the connection"
    (p,) = perf.by_key.values()
    assert (p.key, p.name, p.n_values) == (0, "warpA", 186 if displacement else 96)
    np.testing.assert_array_equal(session_map(p.session), offline_map(FI, warp))
    s = perf.summary()[0]
    assert s["frames"] == s["ticks"] == 303 and s["lost"] == s["filled"] == 0
    assert s["ahead"] > 250  # 10 s of capture sent in well under 9 s
    assert not any(perf.bad.values())


def test_two_performers_interleaved_each_get_their_map(cmu):
    path, FI, warps = cmu
    perf, end, log = run(axis_frames([take_lines(w) for w in warps]), path, FI)
    assert end.startswith("ended")
    assert [(p.key, p.name) for p in perf.by_key.values()] == [(0, "warpA"), (1, "warpB")]
    maps = [session_map(p.session) for p in perf.by_key.values()]
    for M, w in zip(maps, warps, strict=True):
        np.testing.assert_array_equal(M, offline_map(FI, w))
    assert not np.array_equal(maps[0], maps[1])
    assert perf.frames == 606 and sum(perf.bad.values()) == 0


def test_the_command_line_end_to_end(cmu, tmp_path):
    """``fpdtw stream A B --as axis`` in its own process; ``fpdtw serve --source axis://
    --once --out --send udp://`` here: one map file per performer, each ``fpdtw align``'s;
    every answer sent carries its performer."""
    path, _, warps = cmu
    emu = subprocess.Popen(
        [sys.executable, "-m", "fpdtw.app.cli", "stream", *map(str, warps), "--as", "axis",
         "--listen", "127.0.0.1:0", "--fast"],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )  # fmt: skip
    udp = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    udp.bind(("127.0.0.1", 0))
    udp.settimeout(0.2)
    try:
        address = emu.stdout.readline().split()[-1]
        out = tmp_path / "live.csv"
        code = cli.main(["serve", str(path), "--source", f"axis://{address}", "--header",
                         str(path), "--once", "--out", str(out), "--send",
                         f"udp://127.0.0.1:{udp.getsockname()[1]}"])  # fmt: skip
        assert code == 0
        assert emu.wait(30) == 0
        assert "sent 606 of 606 frames (2 avatars)" in emu.stdout.read()
        sent = []
        try:
            while True:
                sent.append(udp.recv(4096).decode().split())
        except TimeoutError:
            pass
    finally:
        udp.close()
        if emu.poll() is None:
            emu.kill()
        emu.wait()
        emu.stdout.close()
        emu.stderr.close()
    for key, w in enumerate(warps):
        got = read_map_csv(tmp_path / f"live-take1-{key}-{w.stem}.csv")
        ref = tmp_path / f"ref{key}.csv"
        assert cli.main(["align", str(path), str(w), "-m", "c", "-w", "40", "--out", str(ref)]) == 0
        np.testing.assert_array_equal(got["input_frame"], read_map_csv(ref)["input_frame"])
        np.testing.assert_array_equal(got["target_frame"], np.arange(303))
        mine = [f for f in sent if f[5:] == [str(key), w.stem]]
        index = [int(f[1]) for f in mine]  # UDP: a burst may lose datagrams on the way in
        assert mine and index == sorted(set(index)) and set(index) <= set(range(303))
    assert all(len(f) == 7 and f[0] == "1" for f in sent)  # take, ..., avatar index, name


# ------------------------------------------------------------------------- hostile input
def _frames(cmu, n=None):
    path, FI, (warp, _) = cmu
    frames = axis_frames([take_lines(warp)])
    return path, FI, warp, [b for _, b in frames[:n]]


def test_a_frame_cut_by_the_close_and_empty_frames(cmu):
    """The last frame cut in the middle by the connection closing is counted, not used;
    '||' with nothing between is counted too; the full frames give the offline map."""
    path, FI, warp, frames = _frames(cmu)
    body = frames[:100] + [b"\n  ||\r\n", b"||"] + frames[100:] + [frames[5][:50]]
    perf, end, log = run(raw(*body), path, FI)
    assert end.startswith("ended") and perf.bad["cut"] == 1 and perf.bad["empty"] == 2
    assert any("frame 306: 50 bytes without '||' when the connection closed" in m for m in log)
    np.testing.assert_array_equal(session_map(perf.get(0).session), offline_map(FI, warp))


def test_a_sender_that_never_sends_the_separator(cmu):
    """Bytes without '||' are read up to the bound only: the take ends naming the frame."""
    path, FI, _, frames = _frames(cmu, 3)
    with limits.override(max_line_bytes=4096):
        perf, end, _ = run(raw(*frames, b"0 warpA " + b"1.5 " * 200_000), path, FI)
    assert end == ("error: frame 4: more than 4096 bytes without '||' "
                   "(FPDTW_MAX_LINE_BYTES)")  # fmt: skip
    assert perf.bad["oversize"] == 1 and perf.summary()[0]["frames"] == 3


def _spoil(frame: bytes, value: bytes, drop: bool = False) -> bytes:
    toks = frame.split()
    toks = toks[:7] + toks[8:] if drop else toks[:7] + [value] + toks[8:]
    return b" ".join(toks)


@pytest.mark.parametrize(
    "spoil,kind,what",
    [
        (lambda f: _spoil(f, b"", drop=True), "count", "95 values, expected 96"),
        (lambda f: _spoil(f, b"1.2.3"), "number", "value '1.2.3' is not a number"),
        (lambda f: _spoil(f, b"nan"), "finite", "a value is NaN or inf"),
        (lambda f: _spoil(f, b"-inf"), "finite", "a value is NaN or inf"),
        (lambda f: _spoil(f, b"1e30"), "large", "a value beyond"),
    ],
)
def test_an_unusable_frame_is_counted_and_filled(cmu, spoil, kind, what):
    """Frame 41 of the stream spoilt: dropped, counted, named; its place is a one-frame
    gap filled by slerp (the documented rule); every other answer is the offline map's."""
    path, FI, warp, frames = _frames(cmu)
    frames[40] = spoil(frames[40])
    perf, end, log = run(raw(*frames), path, FI)
    assert end.startswith("ended") and perf.bad[kind] == 1 and sum(perf.bad.values()) == 1
    assert any(m.startswith(f"take 1: frame 41 (avatar 0 'warpA'): {what}") for m in log)
    s = perf.summary()[0]
    assert (s["frames"], s["ticks"], s["lost"], s["filled"]) == (302, 303, 1, 1)
    p = perf.get(0)
    assert [k for k, _, filled in p.session.ticks if filled] == [40]
    M, ref = session_map(p.session), offline_map(FI, warp)
    assert M.size == ref.size and abs(int(M[40]) - int(ref[40])) <= 2
    np.testing.assert_array_equal(M[:40], ref[:40])


def test_unusable_frames_in_a_row_end_the_take(cmu):
    """More than a second's frames in a row unusable (30 at 30 Hz): the take cannot go on."""
    path, FI, _, frames = _frames(cmu, 80)
    for k in range(10, 80):
        frames[k] = _spoil(frames[k], b"nan")
    perf, end, _ = run(raw(*frames), path, FI)
    assert end == ("error: frame 41 (avatar 0 'warpA'): a value is NaN or inf; 31 unusable "
                   "frames in a row: the take cannot go on")  # fmt: skip
    assert perf.bad["finite"] == 31


def test_a_count_no_layout_fits_and_other_garbage(cmu):
    """A first frame whose count fits neither layout is refused with both counts; a frame
    without its avatar name is counted; garbage only ends the take after a run."""
    path, FI, _, frames = _frames(cmu, 5)
    junk = [b"0 A 1 2 3 ||", b"7||", b"x y 1 ||"] * 5
    perf, end, log = run(raw(*junk), path, FI)
    assert any("frame 1: avatar 0 'A': 3 values, expected 186 (with displacement) or 96 "
               "(without) for the 31 joints of" in m for m in log)  # fmt: skip
    assert end.startswith("error: frame 11: ") and "11 unusable frames in a row" in end
    assert perf.bad["count"] == 4 and perf.bad["name"] == 7 and not perf.by_key


def test_performers_beyond_the_bound_are_refused(cmu):
    path, FI, warps = cmu
    frames = axis_frames([take_lines(w) for w in warps])[:40]
    perf, end, _ = run(frames, path, FI, max_performers=1)
    assert end.startswith("ended") and list(perf.by_key) == [0] and perf.bad["refused"] == 20


def test_a_hostile_source_through_the_command_line(cmu, capsys):
    """The command line's report of a take that cannot go on: exit 1, one message naming
    the frame, no traceback; a source that is not there: exit 1, the usual error line."""
    path, _, _, frames = _frames(cmu, 3)
    ready, port = threading.Event(), []

    def sender():
        def on(h, p):
            port.append(p)
            ready.set()

        asyncio.run(serve_axis(raw(*frames, b"0 warpA " + b"1 " * 400_000), "127.0.0.1", 0,
                               fast=True, on_listening=on, timeout=60))  # fmt: skip

    t = threading.Thread(target=sender, daemon=True)
    t.start()
    assert ready.wait(30)
    url = f"axis://127.0.0.1:{port[0]}"
    assert cli.main(["serve", str(path), "--source", url, "--header", str(path), "--once"]) == 1
    t.join(30)
    err = capsys.readouterr().err
    assert "ended with an error: frame 4: more than 262144 bytes without '||'" in err
    assert "Traceback" not in err and "3 frames read" not in err  # 4 read, the 4th oversize
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        free = s.getsockname()[1]
    url = f"axis://127.0.0.1:{free}"
    assert cli.main(["serve", str(path), "--source", url, "--header", str(path), "--once"]) == 1
    line = capsys.readouterr().err.strip().splitlines()[-1]
    assert line.startswith(f"fpdtw: error: {url}: cannot connect: Connection refused")


@pytest.mark.parametrize(
    "args,needle",
    [
        (["serve", "IN.bvh", "--source", "axis://127.0.0.1:7001"], "needs --header"),
        (["serve", "IN.bvh", "--source", "kinect://h:1", "--header", "H.bvh"], "axis://HOST"),
        (["serve", "IN.bvh", "--once"], "--once applies only with --source"),
        (
            ["serve", "IN.bvh", "--source", "axis://h:1", "--header", "H.bvh", "--listen", "h:1"],
            "--listen does not apply",
        ),
        (["stream", "A.bvh", "B.bvh", "--to", "127.0.0.1:1"], "only with --as axis"),
        (["stream", "A.bvh", "--as", "axis", "--drop", "0.1"], "--drop does not apply"),
        (["stream", "A.bvh", "--to", "127.0.0.1:1", "--displacement"], "only with --as axis"),
        (["stream", "A.bvh"], "--to HOST:PORT is required"),
    ],
)
def test_usage_errors(capsys, args, needle):
    assert cli.main(args) == 2
    assert needle in capsys.readouterr().err
