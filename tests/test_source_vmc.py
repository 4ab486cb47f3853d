"""``fpdtw serve --source vmc://``: the VMC protocol, sent by our own emulator of a sender
(``fpdtw stream --as vmc``: python-osc's own UDP client and bundle builder) over 127.0.0.1,
and hostile datagrams.

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
from pythonosc import osc_bundle_builder, osc_message_builder
from pythonosc.osc_packet import OscPacket
from reference.live_sources import (
    NoTransport,
    offline_map,
    read_queued,
    read_sent,
    serve_and_stream,
)
from reference.live_sources import performers as shared_performers

from fpdtw.app import cli
from fpdtw.app.source_vmc import (
    JOINT_MAPS,
    MAX_DATAGRAM,
    PARENTS,
    Layout,
    Source,
    VmcSkeleton,
    _message,
    fpdtw_to_unity,
    play_as_vmc,
    unity_to_fpdtw,
    vmc_frames,
)
from fpdtw.app.sources import MAX_QUEUE, DatagramReceiver, parse_source
from fpdtw.app.stream import session_map
from fpdtw.io.bvh import parse_bvh_header, read_bvh
from fpdtw.motion.joints import find_joint_map
from fpdtw.motion.rotations import quat_conj, quat_mul

CMU = "cmu/18_01.bvh"


@pytest.fixture(scope="module")
def cmu(cmu_retimed):
    """The recording's features and two retimed takes of it (paths)."""
    return cmu_retimed


def performers(FI, log, **kw):
    return shared_performers(FI, log, JOINT_MAPS, **kw)


def loopback(takes, FI, *, idle=0.5):
    """Send ``takes`` with :func:`play_as_vmc` (python-osc's client, one sender each) to the
    vmc source on 127.0.0.1: (performers, how the take ended, log)."""
    send = lambda port: play_as_vmc(takes, f"127.0.0.1:{port}", fast=True)  # noqa: E731
    return read_sent(Source("127.0.0.1", 0, rate=30), send, FI, JOINT_MAPS, idle=idle)


def inject(datagrams, FI, *, addr=("127.0.0.1", 5000), idle=0.2):
    """``datagrams`` handed to the source as its socket would (from ``addr``, or per item
    ``(bytes, addr)``), nothing lost: (performers, how the take ended, log)."""
    pairs = [d if isinstance(d, tuple) else (d, addr) for d in datagrams]
    return read_queued(Source("127.0.0.1", 0, rate=30), pairs, FI, JOINT_MAPS, idle=idle)


# ------------------------------------------------------------------------------ the axes
def _rotate(q, v):
    return quat_mul(quat_mul(q, np.r_[0.0, v]), quat_conj(q))[1:]


def test_handedness_hand_checked():
    """Unity (left-handed, Y up): a +90 degree turn about Y takes forward (+Z) to right (+X)
    (``Quaternion.Euler(0, 90, 0) * Vector3.forward == Vector3.right``); a +90 degree turn
    about X takes forward to down. With X mirrored, Unity's +Z is (0, 0, 1) and its +X is
    (-1, 0, 0): the first must take (0, 0, 1) to (-1, 0, 0), a -90 degree turn about Y in
    fpdtw's right-handed axes; the second (0, 0, 1) to (0, -1, 0), +90 degrees about X."""
    s = np.sqrt(0.5)
    p, q = unity_to_fpdtw([1.0, 2.0, 3.0], [0.0, s, 0.0, s])
    np.testing.assert_array_equal(p, [-1.0, 2.0, 3.0])
    np.testing.assert_allclose(q, [s, 0.0, -s, 0.0])
    np.testing.assert_allclose(_rotate(q, [0.0, 0.0, 1.0]), [-1.0, 0.0, 0.0], atol=1e-12)
    _, q = unity_to_fpdtw([0, 0, 0], [s, 0.0, 0.0, s])
    np.testing.assert_allclose(_rotate(q, [0.0, 0.0, 1.0]), [0.0, -1.0, 0.0], atol=1e-12)
    # a general rotation: mirrored, it acts on mirrored vectors as M R M
    rng = np.random.default_rng(0)
    qu = rng.normal(size=4)
    qu /= np.linalg.norm(qu)
    v = rng.normal(size=3)
    _, qf = unity_to_fpdtw([0, 0, 0], qu)
    # Unity's own (left-handed) rotation of v, computed as the same matrix in its axes
    R = _matrix(np.r_[qu[3], qu[:3]])
    M = np.diag([-1.0, 1.0, 1.0])
    np.testing.assert_allclose(_rotate(qf, M @ v), M @ (R @ v), atol=1e-12)
    p2, q2 = fpdtw_to_unity(*unity_to_fpdtw([1.0, 2.0, 3.0], qu))
    np.testing.assert_array_equal(p2, [1.0, 2.0, 3.0])
    np.testing.assert_array_equal(q2, qu)


def _matrix(q):
    w, x, y, z = q
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])  # fmt: skip


# ----------------------------------------------------------------------------- the skeleton
def test_a_skeleton_from_the_bones_sent():
    """A sender without UpperChest, shoulders and toes: each bone hangs from its
    nearest ancestor it sends; offsets are the local positions, X mirrored; the joint map
    is the built-in one without UpperChest."""
    limbs = ("UpperLeg", "LowerLeg", "Foot", "UpperArm", "LowerArm", "Hand")
    bones = ["Hips", "Spine", "Chest", "Neck", "Head"]
    bones += [f"{s}{b}" for s in ("Left", "Right") for b in limbs]
    frame = {b: np.r_[0.1, 0.2, 0.3, 0.0, 0.0, 0.0, 1.0] for b in bones}
    sk = VmcSkeleton(frame, 60.0)
    h = parse_bvh_header(sk.header, None, stream=True)
    names = list(h.skeleton.joint_names)
    parent = {n: names[p] if p >= 0 else None for n, p in zip(names, h.skeleton.parents,
                                                               strict=True)}  # fmt: skip
    assert parent["Chest"] == "Spine" and parent["Neck"] == "Chest"
    assert parent["LeftUpperArm"] == "Chest" and parent["LeftHand"] == "LeftLowerArm"
    np.testing.assert_array_equal(h.skeleton.offsets[names.index("Chest")], [-0.1, 0.2, 0.3])
    assert h.fps == 60.0
    jm, label = find_joint_map(names, "bvh", JOINT_MAPS)
    assert label == "user map 2" and jm["upper_chest"] == "Chest"


def test_the_compiled_row_is_its_numpy_twin_bit_for_bit():
    """VmcSkeleton.row (one compiled call) equals row_numpy on random frames of any norm,
    with a root and without (the hips at the origin)."""
    rng = np.random.default_rng(11)
    frame = {b: np.r_[rng.normal(size=3), 0.0, 0.0, 0.0, 1.0] for b in PARENTS}
    sk = VmcSkeleton(frame, 60.0)
    for k in range(2000):
        v = rng.normal(size=(len(sk.bones), 7)) * rng.uniform(0.5, 2)
        root = rng.normal(size=7) if k % 2 else None
        np.testing.assert_array_equal(sk.row(v, root), sk.row_numpy(v.copy(), root))


# --------------------------------------------------------------------- the offline map
def test_one_performer_gives_the_map_of_fpdtw_align(cmu):
    """A retimed take sent by python-osc's client, one bundle a frame (float32 values):
    frame for frame the offline map; nothing lost, filled or unusable."""
    _, FI, (warp, _) = cmu
    perf, end, log = loopback([read_bvh(warp)], FI)
    assert end == "ended: nothing received for 0.5 s (--idle-timeout)"
    (p,) = perf.by_key.values()
    assert p.key == 0 and p.name.startswith("127.0.0.1:")
    np.testing.assert_array_equal(session_map(p.session), offline_map(FI, warp))
    s = perf.summary()[0]
    assert s["frames"] == s["ticks"] == 303 and s["lost"] == s["filled"] == 0
    assert not any(perf.bad.values()) and "22 bones" in s["about"]


def test_whole_frames_are_read_from_their_floats(cmu, monkeypatch):
    """After a sender's first bundle, every bundle of the same layout holding a whole frame
    is aligned from its floats (only the first frame's bones are read one by one), with the
    offline map; a frame with a bone's NaN is then read message by message and refused by
    name."""
    _, FI, (warp, _) = cmu
    frames = [b.dgram for b in vmc_frames(read_bvh(warp))[1]]
    calls, bone = [], Source.bone
    monkeypatch.setattr(Source, "bone", lambda *a: calls.append(a[2]) or bone(*a))
    perf, _, _ = loopback([read_bvh(warp)], FI)
    (p,) = perf.by_key.values()
    assert len(calls) == frames[0].count(b"/VMC/Ext/Bone/Pos") == 22
    np.testing.assert_array_equal(session_map(p.session), offline_map(FI, warp))
    bad = bytearray(frames[5])
    at = bad.index(b"LeftUpperLeg\x00")
    at += (len("LeftUpperLeg") + 4) // 4 * 4 + 12  # past the name and ",sfffffff\0\0\0"
    bad[at : at + 4] = struct.pack(">f", float("nan"))
    perf, _, _ = inject([*frames[:5], bytes(bad), *frames[6:8]], FI)
    assert perf.bad["finite"] == 1 and perf.frames == 8
    assert "bone 'LeftUpperLeg' has NaN or inf" in perf.first_bad["finite"]


def test_two_senders_are_two_performers(cmu):
    _, FI, warps = cmu
    perf, end, _ = loopback([read_bvh(w) for w in warps], FI)
    assert end.startswith("ended") and [p.key for p in perf.by_key.values()] == [0, 1]
    for p, w in zip(perf.by_key.values(), warps, strict=True):
        np.testing.assert_array_equal(session_map(p.session), offline_map(FI, w))
    assert perf.frames == 606 and not any(perf.bad.values())


def test_the_command_line_end_to_end(cmu, tmp_path):
    """``fpdtw serve --source vmc:// --once --out`` in its own process; ``fpdtw stream A B
    --as vmc`` here: one map file per sender, each ``fpdtw align``'s."""
    path, _, warps = cmu
    err, _ = serve_and_stream("vmc", path, warps, tmp_path)
    assert "606 frames read; unusable: none" in err


# ------------------------------------------------------------------------- hostile input
def _take(cmu):
    _, FI, (warp, _) = cmu
    _, frames = vmc_frames(read_bvh(warp))
    return FI, warp, [b.dgram for b in frames]


def _bundle(*messages):
    b = osc_bundle_builder.OscBundleBuilder(osc_bundle_builder.IMMEDIATELY)
    for m in messages:
        b.add_content(m)
    return b.build().dgram


def _with_bone(k, name, *values):
    """Frame ``k`` of the take with one more (or a replaced) bone message, as a bundle."""
    return _bundle(
        _message("/VMC/Ext/Root/Pos", "root", *[0.0] * 6, 1.0),
        _message("/VMC/Ext/Bone/Pos", name, *values),
        _message("/VMC/Ext/T", k / 30),
    )


def _spoil_bone(frame: bytes, name: bytes, values) -> bytes:
    """``frame`` with bone ``name``'s 7 float32 values replaced (they follow its name)."""
    start = frame.index(name + b"\x00") + (len(name) // 4 + 1) * 4
    return frame[:start] + np.asarray(values, dtype=">f4").tobytes() + frame[start + 28 :]


NAN = [0, 0, 0, np.nan, 0, 0, 1]


@pytest.mark.parametrize(
    "spoil,kind,what",
    [
        (lambda f: b"hello, not OSC", "osc", "not an OSC packet"),
        (lambda f: f[: len(f) // 2], "osc", "not an OSC packet"),
        (lambda f: f + b"\x00" * MAX_DATAGRAM, "oversize", f"more than {MAX_DATAGRAM}"),
        (lambda f: _spoil_bone(f, b"LeftUpperLeg", NAN), "finite", "'LeftUpperLeg' has NaN"),
        (lambda f: _spoil_bone(f, b"Head", [0, 0, 0, np.inf, 0, 0, 1]), "finite", "NaN or inf"),
        (lambda f: _spoil_bone(f, b"Head", [0, 0, 0, 0.5, 0, 0, 0.5]), "rotation", "norm 0.707"),
        (lambda f: _spoil_bone(f, b"Head", [1e30, 0, 0, 0, 0, 0, 1]), "large", "beyond"),
        (lambda f: f.replace(b"LeftToes\x00", b"LeftTail\x00"), "bone", "'LeftTail' is not"),
        (lambda f: f.replace(b"LeftToes\x00", b"LeftFoot\x00"), "duplicate", "twice in one"),
    ],
)
def test_an_unusable_datagram_is_counted_and_filled(cmu, spoil, kind, what):
    """Frame 41's datagram spoilt (of the take's first 120): dropped, counted, named by its
    number; its place is a one-frame gap filled by slerp; every answer before it is the
    offline map's (an online map is causal: the first 120 frames' answers are its first 120)."""
    FI, warp, frames = _take(cmu)
    frames = frames[:120]
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


def _osc(data):
    return [(m.message.address, m.message.params) for m in OscPacket(data).messages]


def test_a_layout_reads_what_python_osc_reads(cmu):
    """A Layout learnt from one bundle reads every other bundle of the take exactly as
    python-osc does (timetags and numbers differ); a bundle whose strings, ints or size
    differ is not its (None: python-osc reads it); a message, a nested bundle or another
    type of argument has no layout."""
    _, _, frames = _take(cmu)
    first = _osc(frames[0])
    assert ("/VMC/Ext/OK", [1]) in first  # an int, read as a constant
    layout = Layout(frames[0], first)
    assert all(layout.read(f) == _osc(f) for f in frames)
    stamped = frames[5][:8] + b"\x01" * 8 + frames[5][16:]  # another timetag
    assert layout.read(stamped) == _osc(frames[5])
    assert layout.read(frames[5].replace(b"LeftToes\x00", b"LeftTail\x00")) is None
    ok = _message("/VMC/Ext/OK", 1).dgram
    assert layout.read(frames[5].replace(ok, _message("/VMC/Ext/OK", 2).dgram)) is None
    assert layout.read(frames[5][:-4]) is None
    inner = osc_bundle_builder.OscBundleBuilder(osc_bundle_builder.IMMEDIATELY)
    inner.add_content(_message("/VMC/Ext/T", 2.0))
    nested = _bundle(_message("/VMC/Ext/T", 1.0), inner.build())
    boolean = osc_message_builder.OscMessageBuilder(address="/VMC/Ext/Blend/Val")
    boolean.add_arg(True)
    for data in (ok, nested, _bundle(boolean.build())):
        with pytest.raises(ValueError):
            Layout(data, _osc(data))


def test_duplicated_and_reordered_datagrams(cmu):
    """A datagram sent twice: the copy is counted, the map is the offline one exactly.
    Frames 41 and 42 swapped: 42 arrives first (41 is a gap, filled), 41 is counted as
    older than the frame before."""
    FI, warp, frames = _take(cmu)
    perf, end, _ = inject(frames[:41] + [frames[40]] + frames[41:], FI)
    assert perf.bad["duplicate"] == 1 and sum(perf.bad.values()) == 1
    np.testing.assert_array_equal(session_map(perf.get(0).session), offline_map(FI, warp))
    swapped = frames[:40] + [frames[41], frames[40]] + frames[42:]
    perf, end, log = inject(swapped, FI)
    assert perf.bad["order"] == 1 and sum(perf.bad.values()) == 1
    assert any("datagram 42 from 127.0.0.1:5000: time" in m for m in log)
    s = perf.summary()[0]
    assert (s["frames"], s["lost"], s["filled"]) == (302, 1, 1)


def test_a_first_frame_without_the_needed_bones_and_a_bone_missing_later(cmu):
    FI, warp, frames = _take(cmu)
    partial = _with_bone(0, "Hips", 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0)
    tag = b",sfffffff\x00\x00\x00LeftHand"
    lacking = frames[50].replace(b"/VMC/Ext/Bone/Pos\x00\x00\x00" + tag,
                                 b"/VMC/Ext/Blend/Val\x00\x00" + tag)  # fmt: skip
    assert lacking != frames[50]
    perf, end, log = inject([partial] + frames[:50] + [lacking] + frames[51:], FI)
    assert perf.bad["missing"] == 2 and sum(perf.bad.values()) == 2
    assert any("datagram 1 from 127.0.0.1:5000: the first frame of 127.0.0.1:5000 lacks "
               "LeftUpperLeg" in m for m in log)  # fmt: skip
    assert perf.summary()[0]["frames"] == 302 and perf.summary()[0]["filled"] == 1


def test_a_flood_is_bounded_counted_and_ends_the_take(cmu):
    """More datagrams than the queue holds: the excess is dropped and counted at once; the
    take's frames before the garbage are aligned as usual; the garbage then ends the take
    with a message naming its datagram."""
    FI, warp, frames = _take(cmu)
    flood = frames + [b"\x01" * 20] * (MAX_QUEUE + 700 - len(frames))
    perf, end, log = inject(flood, FI)
    assert perf.bad["flood"] == 700
    assert (
        end.startswith(
            "error: frame 334 (avatar 0 '127.0.0.1:5000'): datagram 334 from "
            "127.0.0.1:5000: not an OSC packet"
        )
        and "31 unusable frames" in end
    )
    assert any("datagrams 335 to 1034 dropped: more than 4096 waiting" in m for m in log)
    np.testing.assert_array_equal(session_map(perf.get(0).session), offline_map(FI, warp))


def test_senders_beyond_the_bound_and_a_garbage_only_sender(cmu):
    """Two senders with --max-clients 1: the second's frames are refused, the first's
    aligned; garbage from a stranger is counted, and only a run of it ends the take."""
    FI, warp, frames = _take(cmu)
    a, b = ("127.0.0.1", 5000), ("127.0.0.1", 5001)
    mixed = [x for f in frames[:60] for x in ((f, a), (f, b))]

    async def main():
        proto = DatagramReceiver()
        for d, addr in mixed:
            proto.datagram_received(d, addr)
        log = []
        perf = performers(FI, log, max_performers=1)
        end = await Source("127.0.0.1", 0, rate=30).read((NoTransport(), proto), perf, 0.2)
        return perf, end

    perf, end = asyncio.run(main())
    assert end.startswith("ended") and list(perf.by_key) == [0]
    assert perf.bad["refused"] == 60 and perf.summary()[0]["frames"] == 60
    perf, end, _ = inject([(b"junk", ("127.0.0.1", 6000))] * 12, FI)
    assert end.startswith("error: frame 11: datagram 11 from 127.0.0.1:6000: not an OSC")


def test_hostile_datagrams_over_loopback(cmu):
    """Not OSC, cut and oversized datagrams over a real UDP socket, between a take's frames:
    counted, and the take's map is the offline one."""
    FI, warp, frames = _take(cmu)

    async def main():
        source = Source("127.0.0.1", 0, rate=30)
        conn = await source.connect()
        port = conn[0].get_extra_info("sockname")[1]
        log = []
        perf = performers(FI, log)

        def send():
            with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
                for k, f in enumerate(frames):
                    if k in (10, 20, 30):
                        s.sendto({10: b"not osc", 20: f[:37], 30: f + bytes(MAX_DATAGRAM)}[k],
                                 ("127.0.0.1", port))  # fmt: skip
                    s.sendto(f, ("127.0.0.1", port))
                    threading.Event().wait(0.001)

        t = threading.Thread(target=send)
        t.start()
        end = await source.read(conn, perf, 0.5)
        t.join()
        return perf, end

    perf, end = asyncio.run(main())
    assert end.startswith("ended") and perf.bad["osc"] == 2 and perf.bad["oversize"] == 1
    np.testing.assert_array_equal(session_map(perf.get(0).session), offline_map(FI, warp))


# ------------------------------------------------------------------------- usage
def test_source_url_and_usage_errors(capsys):
    module, host, port = parse_source("vmc://0.0.0.0")
    assert module.DEFAULT_PORT == 39539 and (host, port) == ("0.0.0.0", 39539)
    for args, needle in [
        (["serve", "IN.bvh", "--source", "vmc://h:1", "--header", "H.bvh"], "--header does not"),
        (["serve", "IN.bvh", "--source", "axis://h:1", "--header", "H", "--rate", "30"],
         "--rate applies only with --source vmc"),
        (["serve", "IN.bvh", "--rate", "30"], "--rate applies only with --source"),
        (["stream", "A.bvh", "--as", "vmc", "--listen", "h:1"], "--listen does not apply"),
        (["stream", "A.bvh", "--as", "vmc", "--to", "h:0"], "port 0"),
    ]:  # fmt: skip
        assert cli.main(args) == 2
        assert needle in capsys.readouterr().err
