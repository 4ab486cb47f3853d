"""``fpdtw serve --source natnet://``: Motive's NatNet 4.1 unicast stream, served by our own
emulator of the layout (``fpdtw stream --as natnet``) over 127.0.0.1, and hostile packets.

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
from reference.live_sources import offline_map, read_queued, serve_and_stream
from reference.live_sources import performers as shared_performers

from fpdtw.app import cli
from fpdtw.app.source_natnet import (
    _EULER,
    BONE,
    CONNECT,
    JOINT_MAPS,
    MAX_DATAGRAM,
    RIG_BONES,
    UNIT_TOLERANCE,
    Bad,
    NatNetSkeleton,
    Source,
    _checked_row,
    motive_to_fpdtw,
    natnet_packets,
    parse_descriptions,
    parse_frame,
    play_as_natnet,
)
from fpdtw.app.sources import MAX_QUEUE, TakeEnd, parse_source
from fpdtw.app.stream import session_map
from fpdtw.io.bvh import parse_bvh_header, read_bvh
from fpdtw.motion.joints import find_joint_map
from fpdtw.motion.rotations import quat_conj, quat_mul

SERVER = ("127.0.0.1", 1510)


@pytest.fixture(scope="module")
def cmu(cmu_retimed):
    """The recording's path and features and two retimed takes of it (paths)."""
    return cmu_retimed


def performers(FI, log, **kw):
    return shared_performers(FI, log, JOINT_MAPS, **kw)


def free_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def loopback(takes, FI, *, idle=0.5, garbage=()):
    """Serve ``takes`` with :func:`play_as_natnet` (one skeleton each) on a free port of
    127.0.0.1 and read them with the natnet source (``garbage`` also sent to the source's
    socket from elsewhere): (performers, how the take ended, log)."""
    port = free_port()

    async def main():
        source = Source("127.0.0.1", port, rate=30)
        server = threading.Thread(target=play_as_natnet, args=(takes, f"127.0.0.1:{port}"),
                                  kwargs={"fast": True, "wait_s": 60})  # fmt: skip
        server.start()
        conn = await source.connect()
        log = []
        perf = performers(FI, log)

        async def junk():  # once the take is under way, so that it does not end before
            while not perf.by_key:
                await asyncio.sleep(0.001)
            with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
                for d in garbage:
                    s.sendto(d, ("127.0.0.1", conn[0].get_extra_info("sockname")[1]))

        sending = asyncio.ensure_future(junk())
        try:
            end = await asyncio.wait_for(source.read(conn, perf, idle), 120)
        except TakeEnd as e:
            end = f"error: {e}"
        sending.cancel()
        await asyncio.to_thread(server.join)
        return perf, end, log

    return asyncio.run(main())


def inject(datagrams, FI, *, idle=0.2, **kw):
    """``datagrams`` handed to the source as its socket would, nothing lost, all from the
    server's address: (performers, how the take ended, log)."""
    source = Source(*SERVER, rate=30)
    return read_queued(source, [(d, SERVER) for d in datagrams], FI, JOINT_MAPS, idle=idle, **kw)


# ------------------------------------------------------------------------- the wire format
#: A NAT_FRAMEOFDATA packet written out from the layout's field table: frame 1234, no marker
#: sets, legacy markers or rigid bodies, one skeleton (ID 2) of one bone (ID 3, so composite
#: 0x00020003) at (1, -2, 0.5) turned 90 degrees about Y (qx qy qz qw = 0, s, 0, s; float32
#: sqrt(1/2) = 0x3F3504F3), mean error 0, tracked (params 1), no assets, labeled markers,
#: force plates or devices, a suffix of zeros but its timestamp (0.5 s).
HAND_FRAME = bytes.fromhex("".join([
    "0700", "A400",  # NAT_FRAMEOFDATA, 164 bytes follow
    "D2040000",  # frame number 1234
    "00000000", "00000000",  # marker sets: count, bytes
    "00000000", "00000000",  # legacy markers
    "00000000", "00000000",  # rigid bodies
    "01000000", "2E000000",  # skeletons: 1 in 46 bytes
    "02000000", "01000000",  # skeleton ID 2, 1 bone
    "03000200",  # bone ID: skeleton 2 (high word), bone 3 (low word)
    "0000803F", "000000C0", "0000003F",  # x 1.0, y -2.0, z 0.5
    "00000000", "F304353F", "00000000", "F304353F",  # qx, qy, qz, qw
    "00000000", "0100",  # mean error, params (tracked)
    "0000000000000000" * 4,  # assets, labeled markers, force plates, devices: none
    "00000000", "00000000",  # time code, subframe
    "000000000000E03F",  # timestamp 0.5 (double)
    "00" * 24,  # mid-exposure, received and transmit stamps
    "00000000", "00000000",  # precise timestamp: seconds, fraction
    "0000",  # parameters
]))  # fmt: skip
#: A NAT_MODELDEF of one skeleton "Bob" (ID 2) of two bones: Hip (ID 1, no parent, offset 0)
#: and Chest (ID 3, parent 1, 0.25 m above it), no markers.
HAND_MODELDEF = bytes.fromhex(
    "0500" "5200"  # NAT_MODELDEF, 82 bytes follow
    "01000000"  # 1 description
    "02000000" "46000000"  # type 2 (skeleton), 70 bytes
    "426F6200" "02000000" "02000000"  # "Bob", ID 2, 2 bones
    "48697000" "01000000" "00000000" "00000000" "00000000" "00000000" "00000000"
    "436865737400" "03000000" "01000000" "00000000" "0000803E" "00000000" "00000000"
)  # fmt: skip


def test_hand_written_packets(cmu):
    """The bytes above, read by the source's layouts field by field; the emulator's server
    info is the one the SDK's client reads (name, versions at 256 and 260 of the message)."""
    number, skeletons = parse_frame(HAND_FRAME)
    assert len(HAND_FRAME) == 4 + 164 and number == 1234 and len(skeletons) == 1
    sid, bones = skeletons[0]
    assert sid == 2 and bones.shape == (1,) and int(bones["id"][0]) == 0x00020003
    s = np.float32(np.sqrt(0.5))
    np.testing.assert_array_equal(bones["v"][0], [1.0, -2.0, 0.5, 0.0, s, 0.0, s])
    assert bones["error"][0] == 0.0 and bones["params"][0] == 1
    (name, sid, bones) = parse_descriptions(HAND_MODELDEF)[0]
    assert (name, sid) == ("Bob", 2) and [b[:3] for b in bones] == [("Hip", 1, 0),
                                                                     ("Chest", 3, 1)]  # fmt: skip
    np.testing.assert_array_equal(bones[1][3], [0.0, 0.25, 0.0])
    rate, info, modeldef, frames = natnet_packets([read_bvh(cmu[2][0])])
    assert info[:4] == bytes([1, 0, 23, 1]) and info[4:10] == b"Motive"  # 279 bytes follow
    assert info[260:268] == bytes([3, 1, 0, 0, 4, 1, 0, 0])
    assert struct.unpack_from("<i", frames[1], 4)[0] == 5001
    assert CONNECT[:8] == b"\x00\x00\x0f\x01Ping" and CONNECT[269:273] == bytes([4, 1, 0, 0])


def test_the_source_asks_as_a_natnet_client():
    """Until described the source sends NAT_CONNECT (asking for NatNet 4.1) and
    NAT_REQUEST_MODELDEF to HOST:PORT from its own socket, again every half second."""
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as server:
        server.bind(("127.0.0.1", 0))
        server.settimeout(30)

        async def main():
            source = Source(*server.getsockname(), rate=30)
            transport, _ = await source.connect()
            got = [await asyncio.to_thread(server.recvfrom, 1024) for _ in range(4)]
            port = transport.get_extra_info("sockname")[1]
            transport.close()
            return got, port

        got, port = asyncio.run(main())
    assert [d for d, _ in got] == [CONNECT, b"\x04\x00\x00\x00"] * 2
    assert {a[1] for _, a in got} == {port}


# ------------------------------------------------------------------------------ the axes
def _rotate(q, v):
    return quat_mul(quat_mul(q, np.r_[0.0, v]), quat_conj(q))[1:]


def test_axes_hand_checked():
    """Motive's world is Y up and right-handed, as fpdtw's: a +90 degree turn about Motive's Y
    (qx qy qz qw = 0, s, 0, s) is one about fpdtw's Y, taking (0, 0, 1) to (1, 0, 0); one
    about X (s, 0, 0, s) takes (0, 1, 0) to (0, 0, 1). Positions are kept."""
    s = np.sqrt(0.5)
    p, q = motive_to_fpdtw([1.0, 2.0, 3.0], [0.0, s, 0.0, s])
    np.testing.assert_array_equal(p, [1.0, 2.0, 3.0])
    np.testing.assert_array_equal(q, [s, 0.0, s, 0.0])
    np.testing.assert_allclose(_rotate(q, [0.0, 0.0, 1.0]), [1.0, 0.0, 0.0], atol=1e-12)
    _, q = motive_to_fpdtw([0, 0, 0], [s, 0.0, 0.0, s])
    np.testing.assert_array_equal(q, [s, s, 0.0, 0.0])
    np.testing.assert_allclose(_rotate(q, [0.0, 1.0, 0.0]), [0.0, 0.0, 1.0], atol=1e-12)


@pytest.mark.filterwarnings("ignore:Gimbal lock")  # Y at 90 degrees in the XYZ order
def test_a_turn_about_motives_up_axis_is_a_turn_about_y():
    """The hand-written skeleton (Hip, Chest 0.25 above): its BVH header has Chest's offset
    as described; the root turned +90 degrees about Motive's Y is a root Y rotation of +90
    and nothing else; Chest bent +90 degrees about X (local) is Chest's X rotation only."""
    (_, _, bones) = parse_descriptions(HAND_MODELDEF)[0]
    sk = NatNetSkeleton(bones, 60.0)
    h = parse_bvh_header(sk.header, None, stream=True)
    assert list(h.skeleton.joint_names) == ["Hip", "Chest"] and sk.index == {1: 0, 3: 1}
    np.testing.assert_allclose(h.skeleton.offsets[1], [0.0, 0.25, 0.0])
    s = np.sqrt(0.5)
    v = np.array([[0.1, 0.9, 0.2, 0.0, s, 0.0, s], [0.0, 0.25, 0.0, 0.0, 0.0, 0.0, 1.0]])
    values = sk.row(v)
    np.testing.assert_allclose(values, [0.1, 0.9, 0.2, 0.0, 90.0, 0.0, 0.0, 0.0, 0.0], atol=1e-9)
    v = np.array([[0.0, 0.9, 0.0, 0.0, 0.0, 0.0, 1.0], [0.0, 0.25, 0.0, s, 0.0, 0.0, s]])
    values = sk.row(v)
    np.testing.assert_allclose(values[3:], [0, 0, 0, 0.0, 0.0, 90.0], atol=1e-9)  # Z Y X
    names = [b for b, _, _ in RIG_BONES]
    jm, label = find_joint_map(names, "bvh", JOINT_MAPS)
    assert label == "user map 1" and jm["left_elbow"] == "LFArm" and jm["middle_chest"] == "Ab"


def test_the_compiled_check_and_row_are_the_numpy_ones():
    """_checked_row equals NatNetSkeleton.row bit for bit on random float32 frames sent in a
    shuffled bone order, and takes exactly the frames whose every value is within the limit
    and every quaternion within 0.999 of the tolerance of unit norm (the NumPy checks name
    the others)."""
    rng = np.random.default_rng(5)
    (_, _, bones) = parse_descriptions(HAND_MODELDEF)[0]
    sk = NatNetSkeleton(bones, 60.0)
    tol, big, taken = UNIT_TOLERANCE * 0.999, 1e3, 0
    for k in range(3000):
        q = rng.normal(size=(2, 4))
        q /= np.linalg.norm(q, axis=1)[:, None]
        q *= rng.uniform(1 - 2 * tol, 1 + 2 * tol, (2, 1))
        sent = np.zeros(2, BONE)
        sent["v"] = np.c_[rng.normal(size=(2, 3)) * (3e2 if k % 7 else 1e3), q]
        if k % 97 == 0:
            sent["v"][1, k % 7] = np.nan
        rows = rng.permutation(2)
        v, out = np.empty((2, 7)), np.empty(9)
        ok = _checked_row(sent["v"], rows, big, tol, _EULER, v, out)
        values = np.empty((2, 7))
        values[rows] = sent["v"]
        norms = np.linalg.norm(values[:, 3:], axis=1)
        assert ok == bool((np.abs(values) <= big).all() and (np.abs(norms - 1) < tol).all())
        if ok:
            taken += 1
            np.testing.assert_array_equal(out, sk.row(values))
    assert 300 < taken < 2700  # both sides seen often


# --------------------------------------------------------------------- the offline map
def test_one_skeleton_gives_the_map_of_fpdtw_align(cmu):
    """A retimed take served by the emulator (float32 values): frame for frame the offline
    map; nothing lost, filled or unusable."""
    _, FI, (warp, _) = cmu
    perf, end, log = loopback([read_bvh(warp)], FI)
    assert end == "ended: nothing received for 0.5 s (--idle-timeout)", end
    (p,) = perf.by_key.values()
    assert p.key == 1 and p.name == "warpA"
    np.testing.assert_array_equal(session_map(p.session), offline_map(FI, warp))
    s = perf.summary()[0]
    assert s["frames"] == s["ticks"] == 303 and s["lost"] == s["filled"] == 0
    assert not any(perf.bad.values()) and "21 bones, Motive 3.1.0.0, NatNet 4.1" in s["about"]


def test_two_skeletons_and_garbage_over_loopback(cmu):
    """Two skeletons in every frame: two performers, each the offline map; datagrams that are
    not NatNet sent to the source's socket meanwhile are counted."""
    _, FI, warps = cmu
    junk = [b"not natnet", b"\x07\x00\x10\x00" + bytes(16), bytes(70000)[:65000]]
    perf, end, _ = loopback([read_bvh(w) for w in warps], FI, garbage=junk)
    assert end.startswith("ended") and [p.key for p in perf.by_key.values()] == [1, 2]
    for p, w in zip(perf.by_key.values(), warps, strict=True):
        np.testing.assert_array_equal(session_map(p.session), offline_map(FI, w))
    assert perf.frames == 606 + 3 and perf.bad["natnet"] == 3 and sum(perf.bad.values()) == 3


def test_the_command_line_end_to_end(cmu, tmp_path):
    """``fpdtw serve --source natnet:// --once --out`` in its own process; ``fpdtw stream A B
    --as natnet`` here: one map file per skeleton, each ``fpdtw align``'s."""
    path, _, warps = cmu
    err, files = serve_and_stream("natnet", path, warps, tmp_path)
    assert "606 frames read; unusable: none" in err
    assert [f.name for f in files] == ["live-take1-1-warpA.csv", "live-take1-2-warpB.csv"]


# ------------------------------------------------------------------------- hostile input
def _take(cmu):
    _, FI, (warp, _) = cmu
    _, info, modeldef, frames = natnet_packets([read_bvh(warp)])
    return FI, warp, info, modeldef, frames


BONE0 = 48  # the first bone of the first skeleton: packet header 4, number 4, 3 sections 24,
# skeleton section 8, skeleton ID and bone count 8


def _put(frame: bytes, at: int, fmt: str, *values) -> bytes:
    b = bytearray(frame)
    struct.pack_into(fmt, b, at, *values)
    return bytes(b)


def _bone(frame, k, bid=None, v=None):
    """``frame`` with bone ``k``'s composite ID and/or its 7 values replaced."""
    at = BONE0 + 38 * k
    if bid is not None:
        frame = _put(frame, at, "<I", bid)
    return frame if v is None else _put(frame, at + 4, "<7f", *v)


NAN = [0, 0, 0, np.nan, 0, 0, 1]


@pytest.mark.parametrize(
    "spoil,kind,what",
    [
        (lambda f: b"hello", "natnet", "but 1 follow its header"),
        (lambda f: b"\x63\x00" + f[2:], "natnet", "message ID 99 is not one"),
        (lambda f: f[:-4], "natnet", "of 924 bytes, but 920 follow"),
        (lambda f: _put(f[:-2], 2, "<H", len(f) - 6), "natnet", "48 bytes after the devices"),
        (lambda f: _put(f, 32, "<i", 5), "natnet", "5 skeletons in 806 bytes (cut)"),
        (lambda f: _put(f, 44, "<i", 1000), "natnet", "skeleton 1 with 1000 bones"),
        (lambda f: _put(f, 24, "<i", 3), "natnet", "3 rigid bodies in 0 bytes"),
        (lambda f: _put(f, 36, "<i", 10**6), "natnet", "1000000 bytes, with"),
        (lambda f: f + bytes(MAX_DATAGRAM), "oversize", f"more than {MAX_DATAGRAM}"),
        (lambda f: _put(f, 40, "<i", 9), "undescribed", "skeleton 9 is not in the server's"),
        (lambda f: _bone(f, 20, bid=0x00010063), "bone", "bone ID 1:99 is not a bone of"),
        (lambda f: _bone(f, 20, bid=0x00020015), "bone", "bone ID 2:21 is not"),
        (lambda f: _bone(f, 3, bid=0x00010003), "duplicate", "a bone twice"),
        (lambda f: _bone(f, 13, v=NAN), "finite", "bone LThigh has NaN or inf"),
        (lambda f: _bone(f, 6, v=[np.inf, 0, 0, 0, 0, 0, 1]), "finite", "NaN or inf"),
        (lambda f: _bone(f, 6, v=[0, 0, 0, 0.5, 0, 0, 0.5]), "rotation", "norm 0.707"),
        (lambda f: _bone(f, 6, v=[1e30, 0, 0, 0, 0, 0, 1]), "large", "beyond"),
    ],
)
def test_an_unusable_packet_is_counted_and_filled(cmu, spoil, kind, what):
    """Frame 41's packet spoilt (of the take's first 120, after the server info and the
    descriptions): dropped, counted, named by its datagram's number; its place is a one-frame
    gap filled by slerp; every answer before it is the offline map's (an online map is
    causal)."""
    FI, warp, info, modeldef, frames = _take(cmu)
    frames = frames[:120]
    frames[40] = spoil(frames[40])
    perf, end, log = inject([info, modeldef, *frames], FI)
    assert end.startswith("ended") and perf.bad[kind] == 1 and sum(perf.bad.values()) == 1
    first = next(m for m in log if "dropped; counted" in m)
    assert "datagram 43 from 127.0.0.1:1510" in first and what in first, first
    s = perf.summary()[0]
    assert (s["frames"], s["ticks"], s["lost"], s["filled"]) == (119, 120, 1, 1)
    M, ref = session_map(perf.get(1).session), offline_map(FI, warp)
    assert M.size == 120 and abs(int(M[40]) - int(ref[40])) <= 2
    np.testing.assert_array_equal(M[:40], ref[:40])


def test_a_bone_missing_from_a_frame(cmu):
    """A frame that lacks its last bone (its counts and sizes made to agree): counted."""
    FI, warp, info, modeldef, frames = _take(cmu)
    f = frames[40]
    short = f[: BONE0 + 38 * 20] + f[BONE0 + 38 * 21 :]
    short = _put(_put(_put(short, 2, "<H", len(short) - 4), 36, "<i", 8 + 38 * 20), 44, "<i", 20)
    perf, end, log = inject([info, modeldef, *frames[:40], short, *frames[41:]], FI)
    assert perf.bad["missing"] == 1 and sum(perf.bad.values()) == 1
    assert any("the frame lacks RToe" in m for m in log)


def test_duplicated_and_reordered_frames(cmu):
    """A frame sent twice: the copy is counted, the map is the offline one exactly. Frames
    41 and 42 swapped: 42 arrives first (41 is a gap, filled), 41 is counted as older."""
    FI, warp, info, modeldef, frames = _take(cmu)
    perf, end, _ = inject([info, modeldef, *frames[:41], frames[40], *frames[41:]], FI)
    assert perf.bad["duplicate"] == 1 and sum(perf.bad.values()) == 1
    np.testing.assert_array_equal(session_map(perf.get(1).session), offline_map(FI, warp))
    swapped = [info, modeldef, *frames[:40], frames[41], frames[40], *frames[42:]]
    perf, end, log = inject(swapped, FI)
    assert perf.bad["order"] == 1 and sum(perf.bad.values()) == 1
    assert any("datagram 44 from 127.0.0.1:1510 (frame 5040, skeleton 1): not after the last "
               "frame read (5041)" in m for m in log)  # fmt: skip
    s = perf.summary()[0]
    assert (s["frames"], s["lost"], s["filled"]) == (302, 1, 1)


def test_frames_before_the_descriptions_and_bad_descriptions(cmu):
    """Frames before NAT_MODELDEF are counted as undescribed; a NAT_MODELDEF whose count
    passes its bytes, or whose skeleton is not a tree, is counted and the next one is read;
    the performer starts at the first described frame."""
    FI, warp, info, modeldef, frames = _take(cmu)
    many = _put(modeldef, 4, "<i", 3)
    orphan = bytearray(modeldef)
    at = modeldef.index(b"Ab\0") + 3 + 4  # Ab's parent ID: 1 (Hip) -> 77
    struct.pack_into("<i", orphan, at, 77)
    perf, end, log = inject([info, *frames[:5], many, bytes(orphan), modeldef, *frames[5:]], FI)
    assert perf.bad["undescribed"] == 5 and perf.bad["natnet"] == 2, perf.bad
    assert any("datagram 2 from 127.0.0.1:1510 (frame 5000, skeleton 1): skeleton 1 is not in "
               "the server's data descriptions" in m for m in log)  # fmt: skip
    assert any("datagram 7 from 127.0.0.1:1510: description 2 of 3 cut" in m for m in log)
    assert perf.summary()[0]["frames"] == 298 and perf.get(1).slot == 298
    (_, _, bones) = parse_descriptions(bytes(orphan))[0]
    with pytest.raises(Bad, match="a parent that is not a bone"):
        NatNetSkeleton(bones, 30.0)
    bones[3] = (bones[3][0], 2, *bones[3][2:])
    with pytest.raises(Bad, match="bone IDs or names twice"):
        NatNetSkeleton(bones, 30.0)
    (_, _, bones) = parse_descriptions(modeldef)[0]
    bones[4] = (*bones[4][:3], np.array([0.0, np.nan, 0.0]))
    with pytest.raises(Bad, match="an offset that is NaN, inf or beyond"):
        NatNetSkeleton(bones, 30.0)


def test_a_server_of_another_natnet_version_ends_the_take(cmu):
    """NAT_SERVERINFO saying NatNet 3.1 (or 4.2) ends the take with a message naming it."""
    FI, warp, info, modeldef, frames = _take(cmu)
    for version, shown in ((bytes([3, 1, 0, 0]), "3.1.0.0"), (bytes([4, 2, 0, 0]), "4.2.0.0")):
        old = info[:264] + version + info[268:]
        perf, end, _ = inject([old, modeldef, *frames[:10]], FI)
        assert end == (f"error: datagram 1 from 127.0.0.1:1510: 'Motive' 3.1.0.0 streams NatNet "
                       f"{shown}; fpdtw reads NatNet 4.1 only (Motive 3.1)")  # fmt: skip


def test_a_flood_is_bounded_counted_and_ends_the_take(cmu):
    """More datagrams than the queue holds: the excess is dropped and counted at once; the
    take's frames before the garbage are aligned as usual; a run of garbage then ends the
    take with a message naming its datagram."""
    FI, warp, info, modeldef, frames = _take(cmu)
    head = [info, modeldef, *frames]
    perf, end, log = inject(head + [b"\x01" * 20] * (MAX_QUEUE + 700 - len(head)), FI)
    assert perf.bad["flood"] == 700
    assert end.startswith("error: frame 314: datagram 316 from 127.0.0.1:1510: message 257 of "), (
        end
    )
    assert "11 unusable frames in a row" in end
    assert any("datagrams 317 to 1016 dropped: more than 4096 waiting" in m for m in log)
    np.testing.assert_array_equal(session_map(perf.get(1).session), offline_map(FI, warp))


def test_skeletons_beyond_the_bound(cmu):
    """Two skeletons with --max-clients 1: the second's frames are refused, the first's
    aligned."""
    _, FI, warps = cmu
    _, info, modeldef, frames = natnet_packets([read_bvh(w) for w in warps])
    perf, end, _ = inject([info, modeldef, *frames[:60]], FI, max_performers=1)
    assert end.startswith("ended") and list(perf.by_key) == [1]
    assert perf.bad["refused"] == 60 and perf.summary()[0]["frames"] == 60


# ------------------------------------------------------------------------- usage
def test_source_url_and_usage_errors(cmu, capsys):
    module, host, port = parse_source("natnet://10.0.0.5")
    assert module.DEFAULT_PORT == 1510 and (host, port) == ("10.0.0.5", 1510)
    with pytest.raises(TimeoutError, match="no NatNet client asked 127.0.0.1:"):
        play_as_natnet([read_bvh(cmu[2][0])], f"127.0.0.1:{free_port()}", wait_s=0.2)
    for args, needle in [
        (["serve", "IN.bvh", "--source", "natnet://h:1", "--header", "H.bvh"], "--header does"),
        (["stream", "A.bvh", "--as", "natnet", "--listen", "h:1"], "--listen does not apply"),
        (["stream", "A.bvh", "--as", "natnet", "--to", "h:0"], "port 0"),
    ]:  # fmt: skip
        assert cli.main(args) == 2
        assert needle in capsys.readouterr().err
