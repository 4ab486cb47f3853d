"""``fpdtw serve --source xsens://``: MVN's network streamer (MXTP02), sent by our own encoder
of the specification (``fpdtw stream --as xsens``) over 127.0.0.1, and hostile datagrams.

The recording is CMU 18_01 (31 joints, 30 Hz); the live takes are it retimed (written as
BVH files), so that the maps are not the identity. The hostile cases are put straight into
the source's queue (what the socket would hand it), so that no datagram is lost on the way.
"""

from __future__ import annotations

import asyncio
import socket
import struct
import threading

import numpy as np
import pytest
from reference.live_sources import offline_map, read_queued, read_sent, serve_and_stream
from reference.live_sources import performers as shared_performers

from fpdtw.app import cli
from fpdtw.app.source_xsens import (
    HEADER,
    ITEM,
    JOINT_MAPS,
    MAX_DATAGRAM,
    SEGMENTS,
    MvnSkeleton,
    Source,
    _Character,
    fpdtw_to_mvn,
    mvn_to_fpdtw,
    mxtp02,
    play_as_xsens,
    xsens_datagrams,
)
from fpdtw.app.sources import MAX_QUEUE, parse_source
from fpdtw.app.stream import session_map
from fpdtw.io.bvh import parse_bvh_header, read_bvh
from fpdtw.motion.joints import find_joint_map
from fpdtw.motion.rotations import quat_conj, quat_mul


@pytest.fixture(scope="module")
def cmu(cmu_retimed):
    """The recording's path and features and two retimed takes of it (paths)."""
    return cmu_retimed


def performers(FI, log, **kw):
    return shared_performers(FI, log, JOINT_MAPS, **kw)


def loopback(takes, FI, *, idle=0.5, parts=1):
    """Send ``takes`` with :func:`play_as_xsens` (one character each) to the xsens source on
    127.0.0.1: (performers, how the take ended, log)."""
    send = lambda port: play_as_xsens(takes, f"127.0.0.1:{port}", fast=True, parts=parts)  # noqa: E731
    return read_sent(Source("127.0.0.1", 0, rate=30), send, FI, JOINT_MAPS, idle=idle)


def inject(datagrams, FI, *, addr=("127.0.0.1", 5000), idle=0.2, **kw):
    """``datagrams`` handed to the source as its socket would, nothing lost: (performers,
    how the take ended, log)."""
    source = Source("127.0.0.1", 0, rate=30)
    return read_queued(source, [(d, addr) for d in datagrams], FI, JOINT_MAPS, idle=idle, **kw)


# ------------------------------------------------------------------------- the wire format
#: One MXTP02 datagram written out from the specification's field table (2.4.1, 2.5.3):
#: character 2's sample 42 in one datagram, time code 1000 ms, one item: segment 7 (Head) at
#: (1, -2, 0.5), turned 90 degrees about Z (re = k = sqrt(1/2), float32 0x3F3504F3).
HAND = bytes.fromhex(
    "4D5854503032"  # "MXTP02"
    "0000002A"  # sample counter 42
    "80"  # datagram counter: index 0, the last of its sample
    "01"  # items
    "000003E8"  # time code 1000 ms
    "02"  # character ID
    "17" "00" "00"  # 23 body segments, no props, no finger segments
    "0000"  # reserved
    "0020"  # payload size 32
    "00000007"  # segment ID 7
    "3F800000" "C0000000" "3F000000"  # x 1.0, y -2.0, z 0.5
    "3F3504F3" "00000000" "00000000" "3F3504F3"  # re, i, j, k
)  # fmt: skip


def test_a_hand_written_datagram():
    """The bytes above, read by the source's header and item layouts and its item check; and
    the emulator, given the same values, writes exactly these bytes."""
    assert len(HAND) == 24 + 32
    head = HEADER.unpack_from(HAND)
    assert head == (b"MXTP02", 42, 0x80, 1, 1000, 2, 23, 0, 0, 0, 32)
    c = _Character(2, ("127.0.0.1", 5000))
    items = Source("127.0.0.1", 0).items(c, HAND, 1, 0, 0, "here")
    assert c.problem is None and list(items) == [7] and SEGMENTS[7 - 1] == "Head"
    s = np.float32(np.sqrt(0.5))
    np.testing.assert_array_equal(items[7], [1.0, -2.0, 0.5, s, 0.0, 0.0, s])
    assert ITEM.unpack_from(HAND, 24)[0] == 7
    p = np.array([[1.0, -2.0, 0.5]])
    q = np.array([[s, 0.0, 0.0, s]])
    hand = HAND[:17] + b"\x01" + HAND[18:]  # the emulator says 1 body segment for 1 item
    assert mxtp02(42, 1000, 2, [7], p, q) == [hand]


def test_a_sample_split_over_three_datagrams():
    """Indices 0, 1 and 0x82 (the specification's example), the items shared out, one
    sample counter; every header's payload size is its datagram's."""
    ids = list(range(1, 24))
    p, q = np.zeros((23, 3)), np.tile([1.0, 0, 0, 0], (23, 1))
    parts = mxtp02(7, 0, 0, ids, p, q, parts=3)
    assert [d[10] for d in parts] == [0x00, 0x01, 0x82]
    assert [d[11] for d in parts] == [8, 8, 7]
    for d in parts:
        assert struct.unpack(">H", d[22:24])[0] == len(d) - 24 and d[6:10] == bytes([0, 0, 0, 7])


# ------------------------------------------------------------------------------ the axes
def _rotate(q, v):
    return quat_mul(quat_mul(q, np.r_[0.0, v]), quat_conj(q))[1:]


def test_axes_hand_checked():
    """MVN: X forward, Y left, Z up (right-handed). A +90 degree turn about MVN's Z takes
    forward (X) to left (Y); in fpdtw's axes (X left, Y up, Z forward) it must be a +90
    degree turn about Y taking (0, 0, 1) to (1, 0, 0). A +90 degree turn about MVN's X takes
    left (Y) to up (Z): about fpdtw's Z, taking (1, 0, 0) to (0, 1, 0)."""
    s = np.sqrt(0.5)
    p, q = mvn_to_fpdtw([1.0, 2.0, 3.0], [s, 0.0, 0.0, s])
    np.testing.assert_array_equal(p, [2.0, 3.0, 1.0])
    np.testing.assert_array_equal(q, [s, 0.0, s, 0.0])
    np.testing.assert_allclose(_rotate(q, [0.0, 0.0, 1.0]), [1.0, 0.0, 0.0], atol=1e-12)
    _, q = mvn_to_fpdtw([0, 0, 0], [s, s, 0.0, 0.0])
    np.testing.assert_array_equal(q, [s, 0.0, 0.0, s])
    np.testing.assert_allclose(_rotate(q, [1.0, 0.0, 0.0]), [0.0, 1.0, 0.0], atol=1e-12)
    # a general rotation R acts on converted vectors as P R P^T; the emulator's map inverts it
    rng = np.random.default_rng(0)
    qm = rng.normal(size=4)
    qm /= np.linalg.norm(qm)
    v = rng.normal(size=3)
    _, qf = mvn_to_fpdtw([0, 0, 0], qm)
    P = np.array([[0.0, 1, 0], [0, 0, 1], [1, 0, 0]])
    np.testing.assert_allclose(_rotate(qf, P @ v), P @ _rotate(qm, v), atol=1e-12)
    p2, q2 = fpdtw_to_mvn(*mvn_to_fpdtw([1.0, 2.0, 3.0], qm))
    np.testing.assert_array_equal(p2, [1.0, 2.0, 3.0])
    np.testing.assert_array_equal(q2, qm)


def _t_pose():
    """23 segments at identity, positions of a rough T-pose in MVN's axes (cm)."""
    p = np.zeros((23, 3))
    p[1:7, 2] = np.arange(1, 7) * 10.0  # up the spine
    p[7:15, 1] = np.r_[-np.arange(1, 5), np.arange(1, 5)] * 15.0  # right arm -Y, left +Y
    p[7:15, 2] = 50.0
    p[15:23, 2] = -np.tile(np.arange(1, 5), 2) * 20.0
    p[15:19, 1], p[19:23, 1] = -10.0, 10.0
    return p


@pytest.mark.filterwarnings("ignore:Gimbal lock")  # Y at 90 degrees in the XYZ order
def test_a_turn_about_mvns_up_axis_is_a_turn_about_y():
    """The whole body turned +90 degrees about MVN's Z (its global orientations all that turn,
    its positions turned with it): the root's BVH channels are a Y rotation of +90 degrees and
    every other joint's local rotation is zero; a forearm bent 90 degrees about MVN's X (in
    the T-pose) is a rotation about fpdtw's Z of its elbow only. The offsets are the T-pose's
    positions relative to the parent, in fpdtw's axes."""
    s = np.sqrt(0.5)
    p0 = _t_pose()
    pf, qf = mvn_to_fpdtw(p0, np.tile([1.0, 0, 0, 0], (23, 1)))
    sk = MvnSkeleton(pf, qf, 60.0)
    h = parse_bvh_header(sk.header, None, stream=True)
    names = list(h.skeleton.joint_names)
    assert sorted(names) == sorted(SEGMENTS)
    # Neck (ID 6) is 10 cm above T8 in MVN's Z: (0, 10, 0) in fpdtw's axes
    np.testing.assert_allclose(h.skeleton.offsets[names.index("Neck")], [0.0, 10.0, 0.0])
    # the left upper arm 15 cm along MVN's +Y (left): fpdtw's +X
    np.testing.assert_allclose(h.skeleton.offsets[names.index("LeftForearm")], [15.0, 0, 0])
    turn = np.array([s, 0.0, 0.0, s])
    Rz = np.array([[0.0, -1, 0], [1, 0, 0], [0, 0, 1]])
    pt, qt = mvn_to_fpdtw(p0 @ Rz.T, np.tile(turn, (23, 1)))
    values = sk.row(pt, qt)
    np.testing.assert_allclose(values[3:6], [0.0, 90.0, 0.0], atol=1e-9)  # Z Y X of Pelvis
    np.testing.assert_allclose(values[6:], 0.0, atol=1e-9)
    bent = np.tile([1.0, 0, 0, 0], (23, 1))
    bent[SEGMENTS.index("LeftForearm")] = [s, s, 0.0, 0.0]
    bent[SEGMENTS.index("LeftHand")] = [s, s, 0.0, 0.0]
    values = sk.row(*mvn_to_fpdtw(p0, bent))[3:].reshape(-1, 3)
    elbow = sk.order.index(SEGMENTS.index("LeftForearm"))
    np.testing.assert_allclose(values[elbow], [90.0, 0.0, 0.0], atol=1e-9)  # Z, Y, X
    values[elbow] = 0.0
    np.testing.assert_allclose(values, 0.0, atol=1e-9)
    jm, label = find_joint_map(names, "bvh", JOINT_MAPS)
    assert label == "user map 1" and jm["left_elbow"] == "LeftForearm"


# --------------------------------------------------------------------- the offline map
def test_one_character_gives_the_map_of_fpdtw_align(cmu):
    """A retimed take streamed by the emulator (float32 values): frame for frame the offline
    map; nothing lost, filled or unusable."""
    _, FI, (warp, _) = cmu
    perf, end, log = loopback([read_bvh(warp)], FI)
    assert end == "ended: nothing received for 0.5 s (--idle-timeout)"
    (p,) = perf.by_key.values()
    assert p.key == 0 and p.name == "character 0"
    np.testing.assert_array_equal(session_map(p.session), offline_map(FI, warp))
    s = perf.summary()[0]
    assert s["frames"] == s["ticks"] == 303 and s["lost"] == s["filled"] == 0
    assert not any(perf.bad.values()) and "23 segments" in s["about"]


def test_two_characters_split_samples(cmu):
    """Two characters, each sample split over three datagrams: two performers, each the
    offline map."""
    _, FI, warps = cmu
    perf, end, _ = loopback([read_bvh(w) for w in warps], FI, parts=3)
    assert end.startswith("ended") and [p.key for p in perf.by_key.values()] == [0, 1]
    for p, w in zip(perf.by_key.values(), warps, strict=True):
        np.testing.assert_array_equal(session_map(p.session), offline_map(FI, w))
    assert perf.frames == 606 and not any(perf.bad.values())


def test_the_command_line_end_to_end(cmu, tmp_path):
    """``fpdtw serve --source xsens:// --once --out`` in its own process; ``fpdtw stream A B
    --as xsens`` here: one map file per character, each ``fpdtw align``'s."""
    path, _, warps = cmu
    err, files = serve_and_stream("xsens", path, warps, tmp_path)
    assert "606 frames read; unusable: none" in err
    assert [f.name for f in files] == ["live-take1-0-character_0.csv",
                                       "live-take1-1-character_1.csv"]  # fmt: skip


# ------------------------------------------------------------------------- hostile input
def _take(cmu, parts=1):
    _, FI, (warp, _) = cmu
    _, frames = xsens_datagrams([read_bvh(warp)], parts=parts)
    return FI, warp, frames


def _item(frame: bytes, k: int, sid=None, values=None) -> bytes:
    """``frame`` with item ``k``'s segment ID and/or its 7 values replaced."""
    b = bytearray(frame)
    at = 24 + 32 * k
    if sid is not None:
        struct.pack_into(">i", b, at, sid)
    if values is not None:
        struct.pack_into(">7f", b, at + 4, *values)
    return bytes(b)


NAN = [0, 0, 0, np.nan, 0, 0, 1]


@pytest.mark.parametrize(
    "spoil,kind,what",
    [
        (lambda f: b"hello", "mxtp", "not an MXTP header"),
        (lambda f: b"MXTQ" + f[4:], "mxtp", "not an MXTP header"),
        (lambda f: f[:-4], "mxtp", "payload size 736, but 732 bytes"),
        (lambda f: f[:22] + b"\x02\xe4" + f[24:], "mxtp", "payload size 740"),
        (lambda f: f[:11] + b"\x16" + f[12:], "mxtp", "22 items of 32 bytes"),
        (lambda f: f + bytes(MAX_DATAGRAM), "oversize", f"more than {MAX_DATAGRAM}"),
        (lambda f: b"MXTP13" + f[6:], "skipped", "MXTP13 (only type 02"),
        (lambda f: b"MXTP25" + f[6:], "skipped", "MXTP25"),
        (lambda f: _item(f, 19, values=NAN), "finite", "segment 20 (LeftUpperLeg) has NaN"),
        (lambda f: _item(f, 6, values=[0, 0, 0, np.inf, 0, 0, 1]), "finite", "NaN or inf"),
        (lambda f: _item(f, 6, values=[0, 0, 0, 0.5, 0, 0, 0.5]), "rotation", "norm 0.707"),
        (lambda f: _item(f, 6, values=[1e30, 0, 0, 1, 0, 0, 0]), "large", "beyond"),
        (lambda f: _item(f, 22, sid=99), "bone", "segment ID 99 is neither"),
        (lambda f: _item(f, 22, sid=25), "bone", "segment ID 25"),
        (lambda f: _item(f, 3, sid=3), "duplicate", "segment 3 (L3) twice"),
    ],
)
def test_an_unusable_datagram_is_counted_and_filled(cmu, spoil, kind, what):
    """Sample 41's datagram spoilt (of the take's first 120): dropped, counted, named by its
    number; its place is a one-frame gap filled by slerp; every answer before it is the
    offline map's (an online map is causal)."""
    FI, warp, frames = _take(cmu)
    frames = [f for (f,) in frames[:120]]
    frames[40] = spoil(frames[40])
    perf, end, log = inject(frames, FI)
    assert end.startswith("ended") and perf.bad[kind] == 1 and sum(perf.bad.values()) == 1
    first = next(m for m in log if "dropped; counted" in m)
    assert "datagram 41 from 127.0.0.1:5000" in first and what in first, first
    s = perf.summary()[0]
    assert (s["frames"], s["ticks"], s["lost"], s["filled"]) == (119, 120, 1, 1)
    M, ref = session_map(perf.get(0).session), offline_map(FI, warp)
    assert M.size == 120 and abs(int(M[40]) - int(ref[40])) <= 2
    np.testing.assert_array_equal(M[:40], ref[:40])


def test_split_samples_reordered_duplicated_and_lost(cmu):
    """Samples in three datagrams: each sample's parts sent last first: the offline map. One
    part sent twice: counted, the map is the offline one. One part lost: its sample is counted
    as missing when the next sample starts, a one-frame gap."""
    FI, warp, frames = _take(cmu, parts=3)
    ref = offline_map(FI, warp)
    perf, end, _ = inject([d for f in frames for d in reversed(f)], FI)
    assert not any(perf.bad.values())
    np.testing.assert_array_equal(session_map(perf.get(0).session), ref)
    flat = [d for f in frames for d in f]
    perf, end, log = inject(flat[:121] + [flat[120]] + flat[121:], FI)
    assert perf.bad["duplicate"] == 1 and sum(perf.bad.values()) == 1
    assert any("datagram 122 from 127.0.0.1:5000 (character 0, sample 1040): datagram 0 of "
               "the sample twice" in m for m in log)  # fmt: skip
    np.testing.assert_array_equal(session_map(perf.get(0).session), ref)
    perf, end, log = inject(flat[:121] + flat[122:], FI)
    assert perf.bad["missing"] == 1 and sum(perf.bad.values()) == 1
    assert any("sample 1040 of character 0 lacks datagram(s) 1 (lost)" in m for m in log)
    s = perf.summary()[0]
    assert (s["frames"], s["lost"], s["filled"]) == (302, 1, 1)
    perf, end, log = inject(flat[:-1], FI)  # the take's last sample without its last part
    assert perf.bad["missing"] == 1 and any("lacks its last datagram" in m for m in log)


def test_duplicated_and_reordered_samples(cmu):
    """A sample sent twice: the copy is counted, the map is the offline one exactly. Samples
    41 and 42 swapped: 42 arrives first (41 is a gap, filled), 41 is counted as older."""
    FI, warp, frames = _take(cmu)
    frames = [f for (f,) in frames]
    perf, end, _ = inject(frames[:41] + [frames[40]] + frames[41:], FI)
    assert perf.bad["duplicate"] == 1 and sum(perf.bad.values()) == 1
    np.testing.assert_array_equal(session_map(perf.get(0).session), offline_map(FI, warp))
    perf, end, log = inject(frames[:40] + [frames[41], frames[40]] + frames[42:], FI)
    assert perf.bad["order"] == 1 and sum(perf.bad.values()) == 1
    assert any("datagram 42 from 127.0.0.1:5000 (character 0, sample 1040): not after" in m
               for m in log)  # fmt: skip
    s = perf.summary()[0]
    assert (s["frames"], s["lost"], s["filled"]) == (302, 1, 1)


def test_a_first_sample_without_every_segment(cmu):
    """A first sample of 22 segments: counted as missing; the skeleton comes from the next."""
    FI, warp, frames = _take(cmu)
    frames = [f for (f,) in frames]
    f = frames[0]
    short = f[:11] + b"\x16" + f[12:22] + struct.pack(">H", 22 * 32) + f[24 : 24 + 22 * 32]
    perf, end, log = inject([short] + frames[1:], FI)
    assert perf.bad["missing"] == 1 and sum(perf.bad.values()) == 1
    assert any("sample 1000 of character 0 lacks LeftToe" in m for m in log)
    assert perf.summary()[0]["frames"] == 302


def test_a_flood_is_bounded_counted_and_ends_the_take(cmu):
    """More datagrams than the queue holds: the excess is dropped and counted at once; the
    take's samples before the garbage are aligned as usual; a run of garbage then ends the
    take with a message naming its datagram."""
    FI, warp, frames = _take(cmu)
    frames = [f for (f,) in frames]
    flood = frames + [b"\x01" * 20] * (MAX_QUEUE + 700 - len(frames))
    perf, end, log = inject(flood, FI)
    assert perf.bad["flood"] == 700
    assert end.startswith("error: frame 314: datagram 314 from 127.0.0.1:5000: 20 bytes"), end
    assert "11 unusable frames in a row" in end
    assert any("datagrams 315 to 1014 dropped: more than 4096 waiting" in m for m in log)
    np.testing.assert_array_equal(session_map(perf.get(0).session), offline_map(FI, warp))


def test_characters_beyond_the_bound(cmu):
    """Two characters with --max-clients 1: the second's samples are refused, the first's
    aligned."""
    _, FI, warps = cmu
    _, frames = xsens_datagrams([read_bvh(w) for w in warps])
    mixed = [d for f in frames[:60] for d in f]
    perf, end, _ = inject(mixed, FI, max_performers=1)
    assert end.startswith("ended") and list(perf.by_key) == [0]
    assert perf.bad["refused"] == 60 and perf.summary()[0]["frames"] == 60


def test_hostile_datagrams_over_loopback(cmu):
    """Not MVN, cut, oversized and other-type datagrams over a real UDP socket, between a
    take's samples: counted, and the take's map is the offline one."""
    FI, warp, frames = _take(cmu)
    frames = [f for (f,) in frames]

    async def main():
        source = Source("127.0.0.1", 0, rate=30)
        conn = await source.connect()
        port = conn[0].get_extra_info("sockname")[1]
        log = []
        perf = performers(FI, log)
        bad = {10: b"not mvn", 20: frames[5][:37], 30: frames[5] + bytes(MAX_DATAGRAM),
               40: b"MXTP12" + frames[5][6:]}  # fmt: skip

        def send():
            with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
                for k, f in enumerate(frames):
                    if k in bad:
                        s.sendto(bad[k], ("127.0.0.1", port))
                    s.sendto(f, ("127.0.0.1", port))
                    threading.Event().wait(0.001)

        t = threading.Thread(target=send)
        t.start()
        end = await source.read(conn, perf, 0.5)
        t.join()
        return perf, end

    perf, end = asyncio.run(main())
    assert end.startswith("ended") and perf.bad["mxtp"] == 2 and perf.bad["oversize"] == 1
    assert perf.bad["skipped"] == 1
    np.testing.assert_array_equal(session_map(perf.get(0).session), offline_map(FI, warp))


# ------------------------------------------------------------------------- usage
def test_source_url_and_usage_errors(capsys):
    module, host, port = parse_source("xsens://0.0.0.0")
    assert module.DEFAULT_PORT == 9763 and (host, port) == ("0.0.0.0", 9763)
    for args, needle in [
        (["serve", "IN.bvh", "--source", "xsens://h:1", "--header", "H.bvh"], "--header does not"),
        (["stream", "A.bvh", "--as", "xsens", "--listen", "h:1"], "--listen does not apply"),
        (["stream", "A.bvh", "--as", "xsens", "--to", "h:0"], "port 0"),
    ]:  # fmt: skip
        assert cli.main(args) == 2
        assert needle in capsys.readouterr().err


def test_the_compiled_row_is_its_numpy_twin_bit_for_bit():
    """MvnSkeleton.row (one compiled call) equals row_numpy on random samples of any norm."""
    rng = np.random.default_rng(7)
    q = rng.normal(size=(23, 4))
    sk = MvnSkeleton(rng.normal(size=(23, 3)) * 50, q / np.linalg.norm(q, axis=1)[:, None], 60.0)
    for _ in range(2000):
        p, q = rng.normal(size=(23, 3)) * 50, rng.normal(size=(23, 4)) * rng.uniform(0.5, 2)
        np.testing.assert_array_equal(sk.row(p, q), sk.row_numpy(p, q))
