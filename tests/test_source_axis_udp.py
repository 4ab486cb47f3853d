"""``fpdtw serve --source axis+udp://``: Axis' binary BVH broadcast (64-byte ``BvhDataHeader``,
float32 values), sent by our own encoder of Noitom's layout (``fpdtw stream --as axis+udp``)
over 127.0.0.1, and hostile datagrams.

The recording and the ``--header`` skeleton are CMU 18_01 (31 joints, 30 Hz); the live takes
are it retimed (written as BVH files), so that the maps are not the identity. The hostile
cases are put straight into the source's queue (what the socket would hand it), so that no
datagram is lost on the way.
"""

from __future__ import annotations

import socket
import struct
import threading

import numpy as np
import pytest
from reference.live_sources import offline_map, read_queued, read_sent, serve_and_stream
from reference.live_sources import performers as shared_performers

from fpdtw.app import cli
from fpdtw.app.source_axis_udp import (
    HEADER,
    MAX_AVATARS,
    Source,
    axis_udp_datagrams,
    play_as_axis_udp,
)
from fpdtw.app.sources import MAX_QUEUE, parse_source
from fpdtw.app.stream import TakeLines, session_map, take_lines
from fpdtw.io.bvh import parse_bvh_header
from fpdtw.motion.rotations import quat_rotate


@pytest.fixture(scope="module")
def cmu(cmu_retimed):
    """The recording's path and features and two retimed takes of it (paths)."""
    return cmu_retimed


def performers(FI, log, **kw):
    return shared_performers(FI, log, (), **kw)


def send_all(datagrams, port):
    """Send ``datagrams`` to 127.0.0.1:``port``, one a millisecond."""
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        for d in datagrams:
            s.sendto(d, ("127.0.0.1", port))
            threading.Event().wait(0.001)


def loopback(send, header, FI, *, idle=0.5):
    """``send(port)`` in a thread to the axis+udp source (skeleton ``header``) listening on
    127.0.0.1: (performers, how the take ended, log)."""
    return read_sent(Source("127.0.0.1", 0, header=header), send, FI, idle=idle)


def inject(datagrams, header, FI, *, addr=("127.0.0.1", 5000), idle=0.2, **kw):
    """``datagrams`` handed to the source as its socket would, nothing lost: (performers,
    how the take ended, log)."""
    source = Source("127.0.0.1", 0, header=header)
    return read_queued(source, [(d, addr) for d in datagrams], FI, idle=idle, **kw)


class Recorder:
    """What a source hands to :class:`Performers`, kept: performers added, values fed, kinds."""

    def __init__(self):
        self.frames, self.added, self.fed, self.kinds = 0, [], [], []

    def add(self, key, name, lines, fps, about):
        self.added.append((key, name, lines, fps, about))
        return key

    def feed(self, perf, values, arrival, t=None):
        self.fed.append((perf, [float(v) for v in values], t))

    def count_bad(self, perf, kind, what):
        self.kinds.append((kind, what))


def decode(header_path, datagrams):
    """``datagrams`` through a source of ``header_path``'s skeleton: the Recorder."""
    source = Source("127.0.0.1", 0, header=header_path)
    source.n = 0
    source.begin_take()
    rec = Recorder()
    for d in datagrams:
        source.datagram(d, ("127.0.0.1", 5000), 0.0, rec)
    return rec


# ------------------------------------------------------------------------- the wire format
ONE_JOINT = ["HIERARCHY", "ROOT Hips", "{", "OFFSET 0 0 0",
             "CHANNELS 6 Xposition Yposition Zposition Yrotation Xrotation Zrotation",
             "End Site", "{", "OFFSET 0 10 0", "}", "}", "MOTION", "Frames: 0",
             "Frame Time: 0.01"]  # fmt: skip

#: One datagram written out from the SDK's ``BvhDataHeader`` (DataType.h, b18), packed,
#: little-endian: avatar 2 "Bob", frame index 42, with displacement, no reference; then the
#: Hips' six float32 values, X Y Z displacement 1, -2, 0.5 and rotations Y X Z 90, 0, 0.
HAND = bytes.fromhex(
    "FFDD"  # Token1 0xDDFF
    "00000101"  # DataVersion: build 0, revision 0, minor 1, major 1 (1.1.0.0)
    "0600"  # DataCount 6
    "01"  # WithDisp
    "00"  # WithReference
    "02000000"  # AvatarIndex 2
    + "426F62".ljust(64, "0")  # AvatarName "Bob", 32 bytes
    + "2A000000"  # FrameIndex 42
    "000000000000000000000000"  # three reserved uint32
    "FFEE"  # Token2 0xEEFF
    "0000803F" "000000C0" "0000003F"  # 1.0, -2.0, 0.5
    "0000B442" "00000000" "00000000"  # 90.0, 0.0, 0.0
)  # fmt: skip


def test_a_hand_written_datagram(tmp_path):
    """The bytes above, read by the header layout and by the source (a one-joint skeleton); and
    the emulator, given the same values, writes exactly these bytes (its avatar is 0)."""
    assert len(HAND) == 64 + 24 and HEADER.size == 64
    head = HEADER.unpack_from(HAND)
    assert head[:6] == (0xDDFF, b"\x00\x00\x01\x01", 6, 1, 0, 2)
    assert head[6] == b"Bob" + bytes(29) and head[7:] == (42, 0, 0, 0, 0xEEFF)
    path = tmp_path / "one.bvh"
    path.write_text("\n".join(ONE_JOINT) + "\n")
    rec = decode(path, [HAND])
    assert rec.kinds == [] and len(rec.added) == 1
    key, name, lines, fps, about = rec.added[0]
    assert (key, name, fps) == (2, "Bob", 100.0) and "data version 1.1.0.0" in about
    assert rec.fed == [(2, [1.0, -2.0, 0.5, 90.0, 0.0, 0.0], 0.0)]
    take = TakeLines("Bob", 100.0, ONE_JOINT, ["1 -2 0.5 90 0 0"])
    _, frames = axis_udp_datagrams([take], displacement=True, first_frame=42)
    assert frames == [[HAND[:10] + bytes(4) + HAND[14:]]]


def test_value_counts_and_the_reference_block(cmu):
    """CMU's 31 joints: 96 values without displacement, 186 with, six more with reference;
    the emulator's frames have those counts and the source reads each as a frame."""
    path, _, (warp, _) = cmu
    take = take_lines(warp)
    for disp, ref, n in [(False, False, 96), (True, False, 186), (False, True, 102)]:
        _, frames = axis_udp_datagrams([take], displacement=disp, reference=ref)
        d = frames[0][0]
        assert struct.unpack_from("<H", d, 6)[0] == n and len(d) == 64 + 4 * n
        assert d[8:10] == bytes([disp, ref])
        rec = decode(path, [f for (f,) in frames[:3]])
        assert rec.kinds == [] and [len(v) for _, v, _ in rec.fed] == [96 if not disp else 186] * 3
        assert [t for _, _, t in rec.fed] == [0.0, 1 / 30, 2 / 30]


# ------------------------------------------------------------------------------ the axes
TWO_JOINTS = ["HIERARCHY", "ROOT Hips", "{", "OFFSET 0 0 0",
              "CHANNELS 6 Xposition Yposition Zposition Yrotation Xrotation Zrotation",
              "JOINT Head", "{", "OFFSET 0 10 0", "CHANNELS 3 Yrotation Xrotation Zrotation",
              "End Site", "{", "OFFSET 0 0 5", "}", "}", "}", "MOTION", "Frames: 0",
              "Frame Time: 0.01"]  # fmt: skip


def _positions(values) -> np.ndarray:
    """Global positions (2, 3) of Hips and Head for one frame of TWO_JOINTS' channels."""
    h = parse_bvh_header(TWO_JOINTS, None, stream=True)
    pos, _ = h.motion(np.array([values], dtype=float), "x").forward_kinematics()
    return pos[0]


def test_axes_hand_checked(tmp_path):
    """Axis' BVH is Y up and right-handed, as fpdtw: no conversion. A +90 degree turn of the
    Hips about Axis' up axis (Yrotation 90) is a turn about fpdtw's Y: the Hips' quaternion is
    (cos 45, 0, sin 45, 0), taking (0, 0, 1) to (1, 0, 0), and the head (0, 10, 0) above stays.
    Xrotation 90 turns the head (0, 10, 0) to (0, 0, 10). The reference block is the Hips'
    parent: a reference at (5, 0, 0) turned 90 degrees about Y places Hips sent at (0, 0, 3)
    at (8, 0, 0), turned by 90 degrees about Y."""
    path = tmp_path / "two.bvh"
    path.write_text("\n".join(TWO_JOINTS) + "\n")
    take = TakeLines("a", 100.0, TWO_JOINTS,
                     ["0 0 0 90 0 0 0 0 0", "0 0 0 0 90 0 0 0 0"])  # fmt: skip
    _, frames = axis_udp_datagrams([take])
    rec = decode(path, [f for (f,) in frames])
    (_, yaw, _), (_, pitch, _) = rec.fed
    np.testing.assert_allclose(_positions(yaw)[1], [0.0, 10.0, 0.0], atol=1e-12)
    h = parse_bvh_header(TWO_JOINTS, None, stream=True)
    q = h.motion(np.array([yaw]), "x").quats[0, 0]
    np.testing.assert_allclose(q, [np.sqrt(0.5), 0.0, np.sqrt(0.5), 0.0], atol=1e-12)
    np.testing.assert_allclose(quat_rotate(q, [0.0, 0.0, 1.0]), [1.0, 0.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(_positions(pitch)[1], [0.0, 0.0, 10.0], atol=1e-12)
    # the reference: six values (X Y Z, then the Hips' Y X Z rotations) before the Hips'
    d = bytearray(axis_udp_datagrams([take], reference=True)[1][0][0])
    struct.pack_into("<6f", d, 64, 5.0, 0.0, 0.0, 90.0, 0.0, 0.0)
    struct.pack_into("<6f", d, 64 + 24, 0.0, 0.0, 3.0, 0.0, 0.0, 0.0)
    rec = decode(path, [bytes(d)])
    ((_, hips, _),) = rec.fed
    np.testing.assert_allclose(hips[:6], [8.0, 0.0, 0.0, 90.0, 0.0, 0.0], atol=1e-9)


# --------------------------------------------------------------------- the offline map
@pytest.mark.parametrize("displacement", [False, True])
def test_one_avatar_gives_the_map_of_fpdtw_align(cmu, displacement):
    """A retimed take through the emulator (float32 values, with and without displacement):
    frame for frame the offline map; nothing lost, filled or unusable."""
    path, FI, (warp, _) = cmu
    take = take_lines(warp)

    def send(port):
        play_as_axis_udp([take], f"127.0.0.1:{port}", fast=True, displacement=displacement)

    perf, end, log = loopback(send, path, FI)
    assert end == "ended: nothing received for 0.5 s (--idle-timeout)"
    (p,) = perf.by_key.values()
    assert p.key == 0 and p.name == "warpA"
    np.testing.assert_array_equal(session_map(p.session), offline_map(FI, warp))
    s = perf.summary()[0]
    assert s["frames"] == s["ticks"] == 303 and s["lost"] == s["filled"] == 0
    assert not any(perf.bad.values())
    assert f"{186 if displacement else 96} values a frame" in s["about"]


def test_two_avatars_with_a_reference_block(cmu):
    """Two avatars, each frame with an (all-zero) reference block: two performers, each the
    offline map."""
    path, FI, warps = cmu
    _, frames = axis_udp_datagrams([take_lines(w) for w in warps], reference=True)
    perf, end, _ = loopback(lambda port: send_all([d for f in frames for d in f], port), path, FI)
    assert end.startswith("ended") and [p.key for p in perf.by_key.values()] == [0, 1]
    for p, w in zip(perf.by_key.values(), warps, strict=True):
        np.testing.assert_array_equal(session_map(p.session), offline_map(FI, w))
    assert perf.frames == 606 and not any(perf.bad.values())


def test_the_command_line_end_to_end(cmu, tmp_path):
    """``fpdtw serve --source axis+udp:// --header --once --out`` in its own process;
    ``fpdtw stream A B --as axis+udp`` here: one map file per avatar, each ``fpdtw align``'s."""
    path, _, warps = cmu
    err, files = serve_and_stream("axis+udp", path, warps, tmp_path, ("--header", str(path)))
    assert "606 frames read; unusable: none" in err, err
    assert [f.name for f in files] == ["live-take1-0-warpA.csv", "live-take1-1-warpB.csv"]


# ------------------------------------------------------------------------- hostile input
def _take(cmu, **kw):
    path, FI, (warp, _) = cmu
    _, frames = axis_udp_datagrams([take_lines(warp)], **kw)
    return path, FI, warp, [f for (f,) in frames]


def _value(frame: bytes, k: int, v: float) -> bytes:
    b = bytearray(frame)
    struct.pack_into("<f", b, 64 + 4 * k, v)
    return bytes(b)


@pytest.mark.parametrize(
    "spoil,kind,what",
    [
        (lambda f: b"hello", "axisbin", "5 bytes, shorter than the 64-byte header"),
        (lambda f: f[:63], "axisbin", "63 bytes, shorter than the 64-byte header"),
        (lambda f: b"\xff\xdc" + f[2:], "axisbin", "tokens 0xDCFF ... 0xEEFF, not 0xDDFF"),
        (lambda f: f[:62] + b"\xff\xff" + f[64:], "axisbin", "tokens 0xDDFF ... 0xFFFF"),
        (lambda f: f[:-4], "axisbin", "data count 96, but 380 bytes follow the header"),
        (lambda f: f[:6] + b"\x63\x00" + f[8:] + bytes(12), "count",
         "99 values without displacement, expected 96 for the 31 joints"),
        (lambda f: f[:6] + b"\x5d\x00" + f[8:-12], "count", "93 values without"),
        (lambda f: f[:8] + b"\x01" + f[9:], "count", "with displacement, but the avatar began "
         "without"),
        (lambda f: f + bytes(1000), "oversize", "1448 bytes, more than 832"),
        (lambda f: _value(f, 10, np.nan), "finite", "value 10 is nan"),
        (lambda f: _value(f, 3, -np.inf), "finite", "value 3 is -inf"),
        (lambda f: _value(f, 3, 1e30), "large", "beyond"),
    ],
)  # fmt: skip
def test_an_unusable_datagram_is_counted_and_filled(cmu, spoil, kind, what):
    """Frame 41's datagram spoilt (of the take's first 120): dropped, counted, named by its
    number; its place is a one-frame gap filled by slerp; every answer before it is the
    offline map's (an online map is causal)."""
    path, FI, warp, frames = _take(cmu)
    frames = frames[:120]
    frames[40] = spoil(frames[40])
    perf, end, log = inject(frames, path, FI)
    assert end.startswith("ended") and perf.bad[kind] == 1 and sum(perf.bad.values()) == 1
    first = next(m for m in log if "dropped; counted" in m)
    assert "datagram 41 from 127.0.0.1:5000" in first and what in first, first
    s = perf.summary()[0]
    assert (s["frames"], s["ticks"], s["lost"], s["filled"]) == (119, 120, 1, 1)
    M, ref = session_map(perf.get(0).session), offline_map(FI, warp)
    assert M.size == 120 and abs(int(M[40]) - int(ref[40])) <= 2
    np.testing.assert_array_equal(M[:40], ref[:40])


def test_duplicated_and_reordered_frames(cmu):
    """A frame sent twice: the copy is counted, the map is the offline one exactly. Frames 41
    and 42 swapped: 42 arrives first (41 is a gap, filled), 41 is counted as older."""
    path, FI, warp, frames = _take(cmu)
    perf, end, log = inject(frames[:41] + [frames[40]] + frames[41:], path, FI)
    assert perf.bad["duplicate"] == 1 and sum(perf.bad.values()) == 1
    assert any("datagram 42 from 127.0.0.1:5000 (avatar 0, frame index 40): not after the "
               "last frame index read (40)" in m for m in log)  # fmt: skip
    np.testing.assert_array_equal(session_map(perf.get(0).session), offline_map(FI, warp))
    perf, end, log = inject(frames[:40] + [frames[41], frames[40]] + frames[42:], path, FI)
    assert perf.bad["order"] == 1 and sum(perf.bad.values()) == 1
    s = perf.summary()[0]
    assert (s["frames"], s["lost"], s["filled"]) == (302, 1, 1)


def test_a_lost_frame_is_a_gap(cmu):
    """Frame index 50 never comes: a one-frame gap by the frame index, filled."""
    path, FI, warp, frames = _take(cmu)
    perf, end, _ = inject(frames[:50] + frames[51:], path, FI)
    assert not any(perf.bad.values())
    s = perf.summary()[0]
    assert (s["frames"], s["ticks"], s["lost"], s["filled"]) == (302, 303, 1, 1)


def test_a_flood_is_bounded_counted_and_ends_the_take(cmu):
    """More datagrams than the queue holds: the excess is dropped and counted; the take's
    frames before the garbage are aligned as usual; a run of garbage then ends the take with
    a message naming its datagram."""
    path, FI, warp, frames = _take(cmu)
    flood = frames + [b"\x01" * 20] * (MAX_QUEUE + 700 - len(frames))
    perf, end, log = inject(flood, path, FI)
    assert perf.bad["flood"] == 700
    assert end.startswith("error: frame 314: datagram 314 from 127.0.0.1:5000: 20 bytes"), end
    assert "11 unusable frames in a row" in end
    assert any("datagrams 315 to 1014 dropped: more than 4096 waiting" in m for m in log)
    np.testing.assert_array_equal(session_map(perf.get(0).session), offline_map(FI, warp))


def test_avatars_beyond_the_bounds(cmu):
    """Two avatars with --max-clients 1: the second's frames are refused, the first's aligned.
    More than MAX_AVATARS avatar indices: the excess is refused, never tracked."""
    path, FI, warps = cmu
    _, frames = axis_udp_datagrams([take_lines(w) for w in warps])
    mixed = [d for f in frames[:60] for d in f]
    perf, end, _ = inject(mixed, path, FI, max_performers=1)
    assert end.startswith("ended") and list(perf.by_key) == [0]
    assert perf.bad["refused"] == 60 and perf.summary()[0]["frames"] == 60
    first = frames[0][0]
    many = [first[:10] + struct.pack("<I", i) + first[14:] for i in range(MAX_AVATARS + 5)]
    perf, end, log = inject(many, path, FI, max_performers=MAX_AVATARS + 5)
    assert len(perf.by_key) == MAX_AVATARS and perf.bad["refused"] == 5
    assert any(f"more than {MAX_AVATARS} avatar indices" in m for m in log)


def test_hostile_datagrams_over_loopback(cmu):
    """Not Axis', cut and oversized datagrams over a real UDP socket, between a take's frames:
    counted, and the take's map is the offline one."""
    path, FI, warp, frames = _take(cmu)
    bad = {10: b"not axis", 20: frames[5][:37], 30: frames[5] + bytes(2000)}
    sent = [d for k, f in enumerate(frames) for d in ([bad[k]] if k in bad else []) + [f]]
    perf, end, _ = loopback(lambda port: send_all(sent, port), path, FI)
    assert end.startswith("ended") and perf.bad["axisbin"] == 2 and perf.bad["oversize"] == 1
    np.testing.assert_array_equal(session_map(perf.get(0).session), offline_map(FI, warp))


# ------------------------------------------------------------------------- usage
def test_source_url_and_usage_errors(capsys):
    module, host, port = parse_source("axis+udp://0.0.0.0")
    assert module.DEFAULT_PORT == 7002 and (host, port) == ("0.0.0.0", 7002)
    with pytest.raises(ValueError, match="needs --header"):
        Source("127.0.0.1", 0)
    for args, needle in [
        (["serve", "IN.bvh", "--source", "axis+udp://h:1"], "axis+udp:// needs --header"),
        (["serve", "IN.bvh", "--source", "axis+udp://h:1", "--header", "H.bvh", "--rate", "30"],
         "--rate applies only"),
        (["stream", "A.bvh", "--as", "axis+udp", "--listen", "h:1"], "--listen does not apply"),
        (["stream", "A.bvh", "--as", "axis+udp", "--to", "h:0"], "port 0"),
    ]:  # fmt: skip
        assert cli.main(args) == 2
        assert needle in capsys.readouterr().err


def test_every_source_can_be_played():
    """`fpdtw stream --as` offers exactly the systems `fpdtw serve --source` reads."""
    from fpdtw.app import cli
    from fpdtw.app.sources import SOURCES

    assert set(cli._SYSTEMS) == set(SOURCES)
