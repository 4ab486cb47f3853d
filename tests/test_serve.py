"""A live take over the network: ``fpdtw serve`` and ``fpdtw stream`` (fpdtw.app.serve,
fpdtw.app.stream), the live target they build (fpdtw.motion.stream) and the BVH parser they
share with the file reader.

Everything runs on 127.0.0.1. A server runs in a thread of this process (an asyncio loop)
or, for the command line and its signals, as a subprocess. Every hostile client is bounded
in count and time (the server's idle timeout here is 2 s). No timing is asserted.
"""

from __future__ import annotations

import asyncio
import os
import re
import signal
import socket
import subprocess
import sys
import threading
import time

import numpy as np
import pytest
from reference.files import with_line

from fpdtw import limits
from fpdtw.app import cli
from fpdtw.app.export import read_map_csv
from fpdtw.app.serve import Server, Session, parse_address
from fpdtw.app.stream import (
    TakeLines,
    lines_motion,
    plan,
    play,
    play_many,
    session_map,
    simulate,
    stamp,
    take_lines,
)
from fpdtw.errors import MotionFormatError
from fpdtw.io import load_motion
from fpdtw.io.bvh import parse_bvh_header, read_bvh, write_bvh
from fpdtw.motion.features import MotionFeatures
from fpdtw.motion.joints import OPW_JOINTS
from fpdtw.motion.motion import blend_poses
from fpdtw.motion.stream import LiveTarget
from fpdtw.registry import align, resolve

WALK1 = "mocap_single_person_actions/MoCapData/Walk_01.fbx"
WALK2 = "mocap_single_person_actions/MoCapData/Walk_02.fbx"
CMU = "cmu/18_01.bvh"
IDLE = 2.0  # the hostile server's idle timeout (s): a stall of the shared machine is not one


# ------------------------------------------------------------------------------ fixtures
@pytest.fixture(scope="module")
def walk(data_path, tmp_path_factory):
    """Walk_01 (FBX, the recording) and Walk_02 written as BVH (the live take), as files."""
    d = tmp_path_factory.mktemp("takes")
    take = write_bvh(load_motion(data_path(WALK2)), d / "Walk_02.bvh")
    take30 = write_bvh(load_motion(data_path(WALK2)).resample(30.0), d / "Walk_02_30hz.bvh")
    return data_path(WALK1), take, take30


@pytest.fixture(scope="module")
def walk_input(walk):
    return load_motion(walk[0])


def cli_map(*args, tmp_path):
    """The map ``fpdtw align ARGS`` writes (run in this process)."""
    out = tmp_path / f"map{len(list(tmp_path.iterdir()))}.csv"
    assert cli.main(["align", *map(str, args), "--out", str(out)]) == 0
    return read_map_csv(out)["input_frame"]


class Running:
    """A Server on an asyncio loop in a thread of this process, on 127.0.0.1:any port."""

    def __init__(self, server):
        self.server = server
        self.loop = asyncio.new_event_loop()
        self.thread = threading.Thread(target=self.loop.run_forever, daemon=True)
        self.thread.start()
        host, port = self.call(server.start("127.0.0.1", 0))
        self.address = f"{host}:{port}"
        self.host, self.port = host, port

    def call(self, coro, timeout=60):
        return asyncio.run_coroutine_threadsafe(coro, self.loop).result(timeout)

    def close(self):
        self.call(self.server.stop())
        self.loop.call_soon_threadsafe(self.loop.stop)
        self.thread.join(30)
        self.loop.close()


def running(I_motion, name, **kw):
    """A running server aligning with the registry's ``name`` against ``I_motion``."""
    a = resolve(name)
    pj = OPW_JOINTS if a.family == "OPW" else None
    FI = MotionFeatures.from_motion(I_motion, position_joints=pj)
    log = []
    server = Server(FI, a.make, name, position_joints=pj, log=log.append, **kw)
    r = Running(server)
    r.log = log
    return r


# ------------------------------------------------------------------- the shared BVH parser
def test_stream_header_is_the_file_header(walk):
    """A stream's header (no 'Frames:' line, or any count) parses like the file's."""
    _, take, _ = walk
    text = take.read_text().splitlines()
    h_file = parse_bvh_header(text, take)
    end = h_file.end_line
    head = text[:end]
    frames_at = next(i for i, s in enumerate(head) if s.startswith("Frames:"))
    many = with_line("\n".join(head), frames_at + 1, "Frames: many").splitlines()
    for variant in (head, head[:frames_at] + head[frames_at + 1 :], many):
        h = parse_bvh_header(variant, None, stream=True)
        assert h.frames is None and h.fps == h_file.fps == 120.0
        assert h.skeleton.joint_names == h_file.skeleton.joint_names
        assert h.skeleton.rotation_orders == h_file.skeleton.rotation_orders
        np.testing.assert_array_equal(h.skeleton.offsets, h_file.skeleton.offsets)
    # a file needs its Frames: line
    with pytest.raises(MotionFormatError, match="expected 'Frames:'"):
        parse_bvh_header(head[:frames_at] + head[frames_at + 1 :], take)
    # each motion line through the same parser gives the file's values
    m = read_bvh(take)
    rows = np.stack([h_file.parse_line(s, end + 1 + k, k) for k, s in enumerate(text[end:])])
    euler, trans = h_file.split(rows)
    np.testing.assert_array_equal(euler, m.euler)
    np.testing.assert_array_equal(trans, m.root_translation)


BROKEN_HEADERS = [
    # (line to change, new text, words)
    (1, "HIERARCHIES", "must start with HIERARCHY"),
    (5, "CHANNELS 4 Xposition Yposition Zposition", "channel count mismatch"),
    (12, "OFFSET 0 two 0", "OFFSET value 'two'"),
]


@pytest.mark.parametrize("line,new,words", BROKEN_HEADERS)
def test_a_broken_header_gets_the_file_readers_error(data_path, tmp_path, line, new, words):
    """The same text as a file and as a stream: the same message, the same line."""
    text = with_line(data_path(CMU).read_text(), line, new)
    f = tmp_path / "broken.bvh"
    f.write_text(text)
    with pytest.raises(MotionFormatError) as file_err:
        read_bvh(f)
    s = Session(MotionFeatures.from_motion(load_motion(data_path(CMU))), resolve("Mc w40").make)
    with pytest.raises(MotionFormatError) as stream_err:
        for raw in text.splitlines(keepends=True)[:187]:
            s.feed(raw.encode(), 0.0)
    assert file_err.value.line == stream_err.value.line == line
    assert file_err.value.reason == stream_err.value.reason and words in stream_err.value.reason
    assert str(stream_err.value).startswith(f"line {line}: ")


def test_channel_limit(data_path):
    text = data_path(CMU).read_text().splitlines()
    with limits.override(max_channels=95), pytest.raises(MotionFormatError, match="96 channels"):
        parse_bvh_header(text[:187], None, stream=True)


# ------------------------------------------------------------------------ the live target
@pytest.mark.parametrize(
    "rel", [WALK2, CMU, "hdm05/HDM05_cut_amc/squat1Reps/HDM_bd_squat1Reps_001_120.amc"]
)
def test_one_frame_kernels_equal_their_numpy_twins(data_path, rel):
    """Per frame, bit for bit: the compiled forward kinematics against
    Motion.forward_kinematics (FBX pre/post rotations, BVH, ASF axes), the streaming unwrap
    against unwrap_degrees, joint_quats of one frame and a subset against the motion's."""
    from fpdtw.motion.kinematics import frame_positions, frame_quats, order_codes
    from fpdtw.motion.motion import joint_quats
    from fpdtw.motion.rotations import UnwrapDegrees, unwrap_degrees

    m = load_motion(data_path(rel))
    pos, _ = m.forward_kinematics()
    idx = m.joint_indices(OPW_JOINTS)
    P = m.positions(OPW_JOINTS, root_relative=True)
    u = UnwrapDegrees()
    E = m.eulers()
    cost = m.joint_indices()
    orders = [m.skeleton.rotation_orders[j] for j in cost]
    codes = order_codes(m.skeleton.rotation_orders)
    for k in range(m.n_frames):
        q, r = m.quats[k], m.root_translation[k]
        assert np.array_equal(frame_quats(m.euler[k], codes), q)
        assert np.array_equal(frame_positions(m.skeleton, q, r, root_relative=False), pos[k])
        assert np.array_equal(frame_positions(m.skeleton, q, r, idx), P[k])
        assert np.array_equal(joint_quats(m.euler[k : k + 1, cost], orders)[0], m.quats[k, cost])
        E[k] = u(E[k])
    np.testing.assert_array_equal(E, unwrap_degrees(m.eulers(), axis=0))


def _push_all(T, rate, *, pj=None, skip=(), gap="slerp"):
    lt = LiveTarget(T.skeleton, T.fps, rate, joint_map=T.joint_map, position_joints=pj, gap=gap)
    out = []
    for k in range(T.n_frames):
        if k not in skip:
            out += lt.push(T.euler[k], T.root_translation[k], k / T.fps)
    return lt, out


_MIXED = """HIERARCHY
ROOT hips
{
  OFFSET 0 0 0
  CHANNELS 6 Xposition Zrotation Yposition Xrotation Zposition Yrotation
  JOINT spine
  {
    OFFSET 0 10 0
    CHANNELS 2 Zrotation Xrotation
    JOINT head
    {
      OFFSET 0 10 0
      CHANNELS 6 Xposition Yposition Zposition Yrotation Xrotation Zrotation
      End Site
      {
        OFFSET 0 5 0
      }
    }
  }
  JOINT leg
  {
    OFFSET 3 -10 0
    CHANNELS 0
    JOINT foot
    {
      OFFSET 0 -10 0
      CHANNELS 3 Xrotation Yrotation Zrotation
      End Site
      {
        OFFSET 0 -2 1
      }
    }
  }
}
MOTION
Frame Time: 0.0083333333
"""


@pytest.mark.parametrize("rate", [120.0, 50.0])
def test_a_motion_line_pushed_whole_gives_the_frames_of_its_split_values(rate):
    """LiveTarget.push_channels (one compiled call per line, as fpdtw serve pushes it):
    channels in any order, a joint with two rotation channels, one with none, a non-root
    joint with positions. At the capture rate its frames are scipy's quaternions and the
    unwrapped angles of BVHHeader.split's values, bit for bit; at another, push's frames. A
    value beyond the limit or NaN takes the general path, which names it."""
    from fpdtw.motion.motion import joint_quats
    from fpdtw.motion.rotations import unwrap_degrees

    h = parse_bvh_header(_MIXED.splitlines(), None, stream=True)
    rng = np.random.default_rng(3)
    rows = rng.uniform(-200.0, 200.0, (40, h.n_channels))
    rows[:, 12:15] = 10.0  # head's position channels: constant, as a stream must keep them
    joints = ("hips", "spine", "head", "foot")
    a, b = (LiveTarget(h.skeleton_for(rows[0]), 120.0, rate, joints=joints) for _ in "ab")
    got, want = [], []
    for k, row in enumerate(rows):
        got += a.push_channels(row, *h.channel_map, k / 120.0)
        want += b.push(*(x[0] for x in h.split(row[None])), k / 120.0)
    E = h.split(rows)[0][:, [0, 1, 2, 4]]  # the cost joints, as split gives them
    if rate == 120.0:
        orders = [h.skeleton.rotation_orders[j] for j in (0, 1, 2, 4)]
        want = [(k, (joint_quats(E[k : k + 1], orders)[0], e), False)
                for k, e in enumerate(unwrap_degrees(E, axis=0))]  # fmt: skip
    else:
        want = [(k, (f.quats, f.euler), filled) for k, f, filled in want]
    assert [(k, filled) for k, _, filled in got] == [(k, filled) for k, _, filled in want]
    for (_, f, _), (_, (q, e), _) in zip(got, want):
        np.testing.assert_array_equal(f.quats, q)
        np.testing.assert_array_equal(f.euler, e)
    bad = rows[0].copy()
    bad[4] = limits.get("max_abs_value") * 2  # hips' Zposition
    with pytest.raises(MotionFormatError, match="implausible translation value"):
        a.push_channels(bad, *h.channel_map, 1.0)
    if rate == 120.0:
        bad[4], bad[6] = 0.0, np.nan  # spine's Zrotation: on to the aligner, which names it
        ((_, f, _),) = a.push_channels(bad, *h.channel_map, 40 / 120.0)
        assert np.isnan(f.euler[1]).any() and not np.isnan(f.euler[[0, 2, 3]]).any()


def test_compiled_euler_to_quaternion_is_scipys_bit_for_bit():
    """Random angles (and whole, zero and gimbal-lock ones) in all six orders."""
    from fpdtw.motion.kinematics import frame_quats, order_codes
    from fpdtw.motion.motion import joint_quats
    from fpdtw.motion.rotations import ORDERS

    rng = np.random.default_rng(7)
    E = rng.uniform(-720.0, 720.0, (20_000, 6, 3))
    E[:100] = np.round(E[:100])
    E[100:200] = 0.0
    E[200:300, :, 1] = 90.0
    ref = joint_quats(E, ORDERS)
    codes = order_codes(ORDERS)
    got = np.stack([frame_quats(e, codes) for e in E[:2000]])
    np.testing.assert_array_equal(got, ref[:2000])
    big = frame_quats(E.reshape(-1, 3), np.tile(codes, E.shape[0]))  # every angle, one call
    np.testing.assert_array_equal(big.reshape(ref.shape), ref)


@pytest.mark.parametrize("rate", [None, 120.0, 25.0])
def test_live_target_gives_the_offline_features(data_path, rate):
    """Frame by frame, the features of the whole (resampled) motion: rotations and Euler
    angles bit for bit; positions bit for bit at equal rates, else within 1e-12 (the one
    documented exception: root translation of a tick just after a frame)."""
    T = load_motion(data_path(CMU))
    rate = rate or T.fps
    lt, ticks = _push_all(T, rate, pj=OPW_JOINTS)
    R = T if rate == T.fps else T.resample(rate)
    F = MotionFeatures.from_motion(R, position_joints=OPW_JOINTS)
    assert [k for k, _, _ in ticks] == list(range(F.n_frames))
    assert not any(filled for _, _, filled in ticks) and lt.n_lost == 0
    np.testing.assert_array_equal(np.stack([f.quats for _, f, _ in ticks]), F.quats)
    np.testing.assert_array_equal(np.stack([f.euler for _, f, _ in ticks]), F.euler)
    P = np.stack([f.positions for _, f, _ in ticks])
    if rate == T.fps:
        np.testing.assert_array_equal(P, F.positions)
    else:
        np.testing.assert_allclose(P, F.positions, rtol=0, atol=1e-12)
    assert lt.orders == T.rotation_orders()


def test_gap_rules_hand_checked(data_path):
    """Frames 5 and 10, 11 lost (30 Hz): the ticks keep their indices; 'slerp' fills them
    between the frames around the gap, 'hold' with the frame before it."""
    T = load_motion(data_path(CMU)).slice_frames(0, 16)
    lt, ticks = _push_all(T, 30.0, skip={5, 10, 11})
    assert [k for k, _, _ in ticks] == list(range(16))
    assert [k for k, _, f in ticks if f] == [5, 10, 11]
    assert lt.n_lost == 3 and lt.n_filled == 3 and lt.n_received == 13
    idx = T.joint_indices()
    Q, E, R = T.quats, T.euler, T.root_translation
    for k, (s0, s1) in ((5, (4, 6)), (10, (9, 12)), (11, (9, 12))):
        a = np.array([(k - s0) / (s1 - s0)])
        q, _, _ = blend_poses(Q[[s0]], Q[[s1]], E[[s0]], E[[s1]], R[[s0]], R[[s1]], a,
                              T.skeleton.rotation_orders)  # fmt: skip
        np.testing.assert_array_equal(ticks[k][1].quats, q[0, idx])
    # halfway between frames 4 and 6 is the rotation halfway along the arc
    from fpdtw.motion.rotations import geodesic_angle

    d46 = geodesic_angle(Q[4, idx], Q[6, idx])
    np.testing.assert_allclose(geodesic_angle(Q[4, idx], ticks[5][1].quats), d46 / 2, atol=1e-9)
    _, held = _push_all(T, 30.0, skip={5, 10, 11}, gap="hold")
    for k, s0 in ((5, 4), (10, 9), (11, 9)):
        np.testing.assert_array_equal(held[k][1].quats, Q[s0, idx])
    for k in (4, 6, 9, 12):  # received frames are themselves under both rules
        np.testing.assert_array_equal(held[k][1].quats, Q[k, idx])
        np.testing.assert_array_equal(ticks[k][1].quats, Q[k, idx])


def test_gap_detection_by_arrival_time_and_jitter(data_path):
    """Without t=, arrival times count: jitter below half a period is no gap, a lost frame
    is; the slots are those the capture times give."""
    T = load_motion(data_path(CMU))
    I = MotionFeatures.from_motion(T)
    take = take_lines(data_path(CMU))
    by_time = simulate(I, take, "Mc w40", drop=0.05, seed=3)
    for jitter in (0.0, 15.0):  # 15 ms < 33.3 / 2 ms
        by_arrival = simulate(I, take, "Mc w40", drop=0.05, seed=3, jitter_ms=jitter,
                              timestamps=False)  # fmt: skip
        assert by_arrival.ticks == by_time.ticks
    assert by_time.target.n_lost == int((~plan(take.n_frames, take.fps, 0.05, 0, 3)[0]).sum()) > 0
    # a frame late by more than half a period looks like a gap: the documented limit
    late = simulate(I, take, "Mc w40", jitter_ms=30.0, seed=1, timestamps=False)
    assert late.target.n_lost > 0


def test_a_faster_target_repeats_the_index(data_path):
    """A 60 Hz target against a 30 Hz input: every second line completes no input-rate
    frame and repeats the previous answer's index; the map is fpdtw align's."""
    I = load_motion(data_path(CMU))
    take = take_lines(data_path(CMU), 60.0)
    s = simulate(I, take, "Mc w40")
    idx = [a[0] for a in s.answers]
    assert idx[:5] == [0, 0, 1, 1, 2] and len(idx) == take.n_frames
    T60 = lines_motion(take)
    FT = MotionFeatures.from_motion(T60.resample(30.0))
    M, _ = align("Mc w40", MotionFeatures.from_motion(I), FT)
    np.testing.assert_array_equal(session_map(s), M[: len(s.ticks)])
    assert len(s.ticks) == M.size


# ------------------------------------------------------------- the offline map, over loopback
@pytest.mark.parametrize(
    "name,opts",
    [("Mc w40", ["-m", "c", "-w", "40"]), ("OLTW", ["-m", "oltw"]), ("OPW", ["-m", "opw"])],
)
def test_loopback_gives_the_map_of_fpdtw_align(walk, walk_input, tmp_path, name, opts):
    """The 'done when' test: Walk_02 (BVH) streamed to a server aligning with Walk_01
    (FBX): frame for frame the map of ``fpdtw align Walk_01.fbx Walk_02.bvh``."""
    W1, take, _ = walk
    M = cli_map(W1, take, *opts, tmp_path=tmp_path)
    srv = running(walk_input, name)
    try:
        r = play(take, srv.address, fast=True)
    finally:
        srv.close()
    assert r.error is None
    np.testing.assert_array_equal(r.index, np.arange(M.size))
    np.testing.assert_array_equal(r.input_frame, M)
    np.testing.assert_allclose(r.input_time_s, M / 120.0, atol=5e-7)
    assert np.all(r.round_trip_s > 0) and np.all(r.server_us >= 0)
    assert any("0 lost and 0 filled" in line for line in srv.log)


def test_loopback_30hz_target_is_resampled_online(walk, walk_input, tmp_path):
    """A 30 Hz take against the 120 Hz input: the answers are the rows of the map of
    ``fpdtw align`` (which resamples the target offline), every fourth one."""
    W1, _, take30 = walk
    M = cli_map(W1, take30, "-m", "c", "-w", 40, tmp_path=tmp_path)
    srv = running(walk_input, "Mc w40")
    try:
        r = play(take30, srv.address, fast=True)
    finally:
        srv.close()
    assert r.error is None and r.index.size == read_bvh(take30).n_frames
    np.testing.assert_array_equal(r.index, 4 * np.arange(r.index.size))
    np.testing.assert_array_equal(r.input_frame, M[r.index])
    s = simulate(walk_input, take_lines(take30), "Mc w40")  # every tick, not only answered
    np.testing.assert_array_equal(session_map(s), M)


def test_dropped_frames_over_loopback_equal_the_simulation(walk, walk_input):
    """Seeded drops: the same answers over the network as in process; the indices jump by
    the frames lost and name the same target frames."""
    _, take, _ = walk
    lines = take_lines(take)
    srv = running(walk_input, "Mb w40", gap="hold")
    try:
        r = play(lines, srv.address, fast=True, drop=0.05, seed=11)
    finally:
        srv.close()
    s = simulate(walk_input, lines, "Mb w40", drop=0.05, seed=11, gap="hold")
    sent = np.flatnonzero(plan(lines.n_frames, lines.fps, 0.05, 0.0, 11)[0])
    np.testing.assert_array_equal(r.sent, sent)
    np.testing.assert_array_equal(r.index, sent)  # equal rates: index = captured frame
    np.testing.assert_array_equal(r.input_frame, [a[1] for a in s.answers])
    assert [k for k, _, _ in s.ticks] == list(range(sent[-1] + 1))
    assert s.target.n_lost == lines.n_frames - sent.size - (lines.n_frames - 1 - sent[-1])


# ------------------------------------------------------------------------ OSC and UDP out
def test_osc_messages_reach_a_python_osc_server(walk, walk_input):
    from pythonosc.dispatcher import Dispatcher
    from pythonosc.osc_server import ThreadingOSCUDPServer

    got = []
    d = Dispatcher()
    d.map("/fpdtw/frame", lambda address, *args: got.append((address, *args)))
    osc = ThreadingOSCUDPServer(("127.0.0.1", 0), d)
    t = threading.Thread(target=osc.serve_forever, daemon=True)
    t.start()
    try:
        port = osc.server_address[1]
        srv = running(walk_input, "Mc w40", send=[f"osc.udp://127.0.0.1:{port}"])
        try:
            lines = take_lines(walk[1])
            short = TakeLines(lines.name, lines.fps, lines.header, lines.lines[:120])
            r = play(short, srv.address, fast=True)
            deadline = time.monotonic() + 10
            while len(got) < 120 and time.monotonic() < deadline:
                time.sleep(0.02)
        finally:
            srv.close()
    finally:
        osc.shutdown()
        osc.server_close()
    assert len(got) == r.index.size == 120
    got.sort(key=lambda g: g[3])
    for (address, m, t_in, index, take), rm, ri in zip(got, r.input_frame, r.index, strict=True):
        assert address == "/fpdtw/frame" and take == 1
        assert (m, index) == (rm, ri) and isinstance(m, int) and isinstance(t_in, float)
        assert t_in == pytest.approx(rm / 120.0, rel=1e-6)


def test_udp_text_lines(walk, walk_input):
    rx = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    rx.bind(("127.0.0.1", 0))
    rx.settimeout(10)
    srv = running(walk_input, "OLTW", send=[f"udp://127.0.0.1:{rx.getsockname()[1]}"])
    try:
        lines = take_lines(walk[1])
        r = play(TakeLines("x", 120.0, lines.header, lines.lines[:50]), srv.address, fast=True)
        got = [rx.recv(2048).decode() for _ in range(50)]
    finally:
        srv.close()
        rx.close()
    rows = sorted((line.split() for line in got), key=lambda f: int(f[1]))
    assert all(line.endswith("\n") for line in got)
    assert [int(f[0]) for f in rows] == [1] * 50  # take 1
    assert [int(f[1]) for f in rows] == r.index.tolist()
    assert [int(f[2]) for f in rows] == r.input_frame.tolist()


# ------------------------------------------------------------------------ hostile clients
@pytest.fixture(scope="module")
def hostile_server(walk_input):
    """A server with small bounds: 8 KiB lines, 64 KiB headers, 2 s idle timeout."""
    with limits.override(max_line_bytes=8192, max_header_bytes=65536):
        srv = running(walk_input, "Mc w40", idle_timeout=IDLE, max_clients=4)
        yield srv
    srv.close()


def _good(walk):
    lines = take_lines(walk[1])
    return lines.header, lines.lines


def _exchange(address, payload: bytes, *, then=None, timeout=10.0):
    """Send ``payload``, optionally ``then(sock)``; return every line received until the
    server closes the connection (bounded by ``timeout``)."""
    host, port = parse_address(address)
    with socket.create_connection((host, port), timeout=timeout) as sock:
        sock.sendall(payload)
        if then is not None:
            then(sock)
        data = b""
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            chunk = sock.recv(65536)
            if not chunk:
                return data.decode("latin-1").splitlines()
            data += chunk
    raise AssertionError(f"the server did not close the connection; got {data[:200]!r}")


def _hostile_cases(walk):
    header, lines = _good(walk)
    H = ("\n".join(header) + "\n").encode()
    n = len(header)  # motion lines start at line n + 1
    first = (lines[0] + "\n").encode()
    st = lambda t, k: (stamp(lines[k], t) + "\n").encode()  # noqa: E731
    half = lines[1][: len(lines[1]) // 2].encode()
    L1, L2 = f"^error: line {n + 1}, frame 0: ", f"^error: line {n + 2}, frame 1: "
    no_hips = ("\n".join(header).replace("JOINT LeftUpLeg", "JOINT Leg_L_Up") + "\n").encode()
    nan = (lines[0].replace(lines[0].split()[5], "nan", 1) + "\n").encode()
    word = (lines[1].replace(lines[1].split()[7], "x7", 1) + "\n").encode()
    hang_up = lambda s: s.shutdown(socket.SHUT_WR)  # noqa: E731
    return {
        "malformed header": (b"HIERARCHIES\n" + H[10:], None, r"^error: line 1: .*HIERARCHY"),
        "garbage bytes": (bytes(range(256)).replace(b"\n", b"") + b"\n", None, r"^error: line 1: "),
        "no joints the method compares": (
            no_hips, None, rf"^error: line {n}: the skeleton has no joint for 'left_hip'"),
        "zero frame time": (H.replace(b"Frame Time: 0.008333333333", b"Frame Time: 0"), None,
                            rf"^error: line {n}: Frame Time must be > 0"),
        "header too long": (b"HIERARCHY\n" + b"ROOT a\n" * 10_000, None,
                            r"^error: line \d+: the header passes 65536 bytes"),
        "line too long": (H + first + b"1 " * 5000 + b"\n", None,
                          rf"^error: line {n + 2}: the line is longer than 8192 bytes"),
        "wrong channel count": (H + first + b"1 2 3\n", None,
                                L2 + r"missing value\(s\): expected 102"),
        "NaN": (H + nan, None, L1 + "non-finite value"),
        "non-numeric": (H + first + word, None, L2 + "non-numeric value 'x7'"),
        "stops mid-line and disconnects": (
            H + first + half, hang_up, rf"^error: line {n + 2}: the connection ended in the"),
        "stops mid-line and waits": (H + first + half, None,
                                     rf"^error: line {n + 2}: nothing received for {IDLE:g} s"),
        "time goes backwards": (H + st(1.0, 0) + st(0.5, 1), None,
                                L2 + "time t=0.5 s is not after"),
        "two clocks": (H + st(0.0, 0) + first, None, L2 + ".*one clock"),
        "bad time": (H + b"t=soon " + first, None, L1 + "time 't=soon'"),
        "gap too long": (H + st(0.0, 0) + st(100.0, 1), None,
                         L2 + "100.000 s since the previous frame"),
    }  # fmt: skip


@pytest.mark.parametrize(
    "case",
    ["malformed header", "garbage bytes", "no joints the method compares", "zero frame time",
     "header too long", "line too long", "wrong channel count", "NaN", "non-numeric",
     "stops mid-line and disconnects", "stops mid-line and waits", "time goes backwards",
     "two clocks", "bad time", "gap too long"],
)  # fmt: skip
def test_a_hostile_client_gets_one_error_line(walk, hostile_server, case):
    payload, then, pattern = _hostile_cases(walk)[case]
    got = _exchange(hostile_server.address, payload, then=then)
    errors = [g for g in got if g.startswith("error:")]
    assert len(errors) == 1 and errors[0] == got[-1], got[-3:]
    assert re.search(pattern, errors[0]), errors[0]
    assert "Traceback" not in errors[0]


def test_the_server_keeps_serving_while_hostile_clients_misbehave(walk, walk_input, hostile_server):
    """A well-behaved take in real time (1 s) gets the offline map while every hostile
    case, an abrupt reset and a ninth-client refusal happen meanwhile."""
    _, take, _ = walk
    lines = take_lines(take)
    good = TakeLines("good", 120.0, lines.header, lines.lines[:120])
    result = {}
    t = threading.Thread(target=lambda: result.update(r=play(good, hostile_server.address)))
    t.start()
    cases = _hostile_cases(walk)
    for name, spec in cases.items():
        if name == "stops mid-line and waits":
            continue
        _exchange(hostile_server.address, spec[0], then=spec[1])
    # an abrupt reset in the middle of a take
    host, port = parse_address(hostile_server.address)
    s = socket.create_connection((host, port), timeout=5)
    s.sendall(("\n".join(lines.header) + "\n" + "\n".join(lines.lines[:5]) + "\n").encode())
    s.recv(100)
    s.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, b"\x01\x00\x00\x00\x00\x00\x00\x00")
    s.close()
    t.join(60)
    r = result["r"]
    assert r.error is None and r.index.size == 120
    FI = MotionFeatures.from_motion(walk_input)
    M, _ = align("Mc w40", FI, MotionFeatures.from_motion(lines_motion(good)))
    np.testing.assert_array_equal(r.input_frame, M)
    assert hostile_server.server.errors == 0  # no internal error on any of them


def test_a_client_beyond_max_clients_is_refused(walk, hostile_server):
    """max_clients = 4: four open takes, the fifth gets one error line; after one of the
    four ends, a new client is served again."""
    header, lines = _good(walk)
    H = ("\n".join(header) + "\n" + lines[0] + "\n").encode()
    host, port = parse_address(hostile_server.address)
    deadline = time.monotonic() + 10
    while hostile_server.server.active and time.monotonic() < deadline:
        time.sleep(0.01)  # the takes of earlier tests have ended
    held = []
    try:
        for _ in range(4):
            s = socket.create_connection((host, port), timeout=5)
            s.sendall(H)
            assert s.makefile("rb").readline().split()[0] == b"0"  # answered: being served
            held.append(s)
        got = _exchange(hostile_server.address, H)
        assert len(got) == 1 and got[0].startswith("error: the server is full (4 takes at once")
        held.pop().close()
        deadline = time.monotonic() + 5
        while hostile_server.server.active >= 4 and time.monotonic() < deadline:
            time.sleep(0.01)
        with socket.create_connection((host, port), timeout=5) as s:
            s.sendall(H)
            assert s.makefile("rb").readline().split()[0] == b"0"
    finally:
        for s in held:
            s.close()


def test_frames_per_take_are_bounded(walk, walk_input):
    take = take_lines(walk[1])
    s = Session(MotionFeatures.from_motion(walk_input), resolve("Mc w40").make)
    with limits.override(max_frames=10):
        with pytest.raises(MotionFormatError, match=r"reaches 11 frames, more than the limit"):
            # arriving one period apart: a slow first step must not read as dropped frames
            for k, raw in enumerate([*take.header, *take.lines]):
                s.feed((raw + "\n").encode(), 1.0 + k / take.fps)
    assert s.n_frames == 10
    with limits.override(max_frames=10):  # blank lines count too
        s = Session(MotionFeatures.from_motion(walk_input), resolve("Mc w40").make)
        with pytest.raises(MotionFormatError, match=r"more than 10 blank lines"):
            for raw in [*take.header, *[""] * 11]:
                s.feed((raw + "\n").encode(), 0.0)


# --------------------------------------------------------- the command line, as a subprocess
def _serve(W1, *opts):
    env = dict(os.environ, PYTHONUNBUFFERED="1")
    p = subprocess.Popen(
        [sys.executable, "-m", "fpdtw.app.cli", "serve", str(W1), *map(str, opts), "--listen",
         "127.0.0.1:0"],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env,
    )  # fmt: skip
    line = p.stdout.readline()
    assert line.startswith("listening on 127.0.0.1:"), p.stderr.read() if p.poll() else line
    return p, line.split()[-1]


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
def test_serve_and_stream_commands_and_a_clean_stop(walk, tmp_path, sig):
    """``fpdtw serve`` in a subprocess; ``fpdtw stream`` with seeded drops against it; a
    take held open; then SIGINT or SIGTERM: the open take gets an error line, the server
    exits 0 with a summary and no traceback."""
    W1, take, _ = walk
    p, address = _serve(W1, "-m", "c", "-w", 40)
    try:
        if sig == signal.SIGTERM:
            out = tmp_path / "answers.csv"
            r = subprocess.run(
                [sys.executable, "-m", "fpdtw.app.cli", "stream", str(take), "--to", address,
                 "--fast", "--drop", "0.1", "--seed", "4", "--out", str(out)],
                capture_output=True, text=True, timeout=120,
            )  # fmt: skip
            assert r.returncode == 0, r.stderr
            head = r.stdout.splitlines()
            assert head[0].startswith("take Walk_02: 637 frames at 120 Hz, as fast as answered;")
            assert head[1].split() == ["p50", "p90", "p99", "max"]
            assert head[2].startswith("round trip (ms)") and head[3].startswith("server (ms)")
            sent = np.flatnonzero(plan(637, 120.0, 0.1, 0.0, 4)[0])
            rows = np.loadtxt(out, delimiter=",", skiprows=1)
            np.testing.assert_array_equal(rows[:, 1], sent)
            np.testing.assert_array_equal(rows[:, 2], sent)
        host, port = parse_address(address)
        lines = take_lines(take)
        with socket.create_connection((host, port), timeout=20) as s:
            # three lines in one packet, without t=: they arrived together, no gap
            s.sendall(("\n".join(lines.header) + "\n" + "\n".join(lines.lines[:3]) + "\n").encode())
            f = s.makefile("rb")
            assert [f.readline().split()[0] for _ in range(3)] == [b"0", b"1", b"2"]
            p.send_signal(sig)
            assert f.readline().decode().startswith("error: the server is shutting down")
        assert p.wait(30) == 0
        err = p.stderr.read()
        assert f"stopped ({sig.name})" in err and "Traceback" not in err
    finally:
        if p.poll() is None:
            p.kill()
        p.wait()
        p.stdout.close()
        p.stderr.close()


@pytest.mark.parametrize(
    "args,needle",
    [
        (["serve", "IN.bvh", "-m", "dtw"], "offline"),
        (["serve", "IN.bvh", "--send", "http://127.0.0.1:9"], "osc.udp://HOST:PORT"),
        (["serve", "IN.bvh", "--listen", "localhost"], "HOST:PORT"),
        (["stream", "T.bvh", "--to", "127.0.0.1:x"], "not a number"),
        (["stream", "T.bvh", "--to", "127.0.0.1:7447", "--fast", "--jitter-ms", "3"], "pacing"),
        (["stream", "T.bvh", "--to", "127.0.0.1:7447", "--drop", "1"], "probability"),
    ],
)
def test_usage_errors(capsys, args, needle):
    assert cli.main(args) == 2
    assert needle in capsys.readouterr().err


def test_help_of_serve_and_stream(capsys):
    assert cli.main(["serve", "--help"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("usage: fpdtw serve")
    needles = [
        "t=<capture time s>", "<frame index> <input frame> <input time s> <latency us>",
        "error: line <n>, frame <k>", "1.5 frame periods", "--send", "--gap", "--listen",
        "--max-clients", "--idle-timeout", "FPDTW_MAX_LINE_BYTES", "oltw", "SIGTERM",
    ]  # fmt: skip
    for text in needles:
        assert text in out, text
    assert cli.main(["stream", "--help"]) == 0
    out = capsys.readouterr().out
    for text in ("--to", "--rate", "--drop", "--jitter-ms", "--seed", "--streams", "--fast",
                 "--no-timestamps", "--out"):  # fmt: skip
        assert text in out, text


def test_busy_port_and_missing_server(walk, capsys):
    W1, take, _ = walk
    with socket.socket() as busy:
        busy.bind(("127.0.0.1", 0))
        busy.listen()
        port = busy.getsockname()[1]
        assert cli.main(["serve", str(W1), "--listen", f"127.0.0.1:{port}"]) == 1
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 2 and err[0].startswith("serving Mc w40")
        assert err[1].startswith(f"fpdtw: error: 127.0.0.1:{port}: ")
    with socket.socket() as s:  # a port nobody listens on
        s.bind(("127.0.0.1", 0))
        free = s.getsockname()[1]
    assert cli.main(["stream", str(take), "--to", f"127.0.0.1:{free}"]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith(f"fpdtw: error: 127.0.0.1:{free}: ")


def test_many_streams_at_once(walk, walk_input):
    """Eight takes at once, each its own aligner: each gets the same (offline) map."""
    _, take, _ = walk
    lines = take_lines(take)
    short = TakeLines("s", 120.0, lines.header, lines.lines[:200])
    srv = running(walk_input, "OPW")
    try:
        reports = play_many(short, srv.address, 8, fast=True)
    finally:
        srv.close()
    FI = MotionFeatures.from_motion(walk_input, position_joints=OPW_JOINTS)
    FT = MotionFeatures.from_motion(lines_motion(short), position_joints=OPW_JOINTS)
    M, _ = align("OPW", FI, FT)
    for r in reports:
        assert r.error is None
        np.testing.assert_array_equal(r.input_frame, M)


def test_a_session_builds_its_live_target_once_unless_the_first_line_moves_a_joint(
    walk, walk_input, monkeypatch
):
    """The live target (its rig: most of a new performer's cost) is built at the header's
    end, and again at the first motion line only when that line's non-root position channels
    give the skeleton other offsets (then from them)."""
    built = []
    make = Session._live_target
    monkeypatch.setattr(Session, "_live_target", lambda s, sk: built.append(sk) or make(s, sk))
    take = take_lines(walk[1])
    spine = take.header.index("\t\tCHANNELS 3 Zrotation Yrotation Xrotation")  # Spine's
    moved = [*take.header[:spine], "\t\tCHANNELS 6 Xposition Yposition Zposition Zrotation "
             "Yrotation Xrotation", *take.header[spine + 1 :]]  # fmt: skip
    offset = take.header[spine - 1].split()[1:]  # Spine's OFFSET, sent as its positions ...
    offset[0] = "1.5"  # ... but for x, which the first line moves
    FI = MotionFeatures.from_motion(walk_input)
    for header, n in ((take.header, 1), (moved, 2)):
        built.clear()
        s = Session(FI, resolve("Mc w40").make)
        for raw in header:
            s.feed((raw + "\n").encode(), 0.0)
        for k, raw in enumerate(take.lines[:50]):
            v = raw.split()
            line = " ".join(v[:6] + offset + v[6:]) if n == 2 else raw
            assert s.feed(f"t={k / take.fps!r} {line}\n".encode(), 1.0).startswith(f"{k} ")
        assert len(built) == n and s.target.skeleton is built[-1]
    assert built[1].offsets[1, 0] == 1.5 and built[0].offsets[1, 0] == 0.0


def test_a_sources_rows_give_the_lines_answers(walk, walk_input):
    """`Session.feed_row` (a capture source's frame, already read) aligns exactly as the same
    frame's stamped motion line through `feed`, and refuses to come before the header."""
    take = take_lines(walk[1])
    FI = MotionFeatures.from_motion(walk_input)
    by_line, by_row = (Session(FI, resolve("Mc w40").make, record=True) for _ in range(2))
    with pytest.raises(ValueError, match="after a complete header"):
        by_row.feed_row(np.zeros(3), 0.0, 0.0)
    for raw in take.header:
        by_line.feed((raw + "\n").encode(), 0.0)
        by_row.feed((raw + "\n").encode(), 0.0)
    for k, raw in enumerate(take.lines[:200]):
        t = k / take.fps
        by_line.feed(f"t={t!r} {raw}\n".encode(), 1.0)
        by_row.feed_row(np.array(raw.split(), dtype=float), t, 1.0)
    assert [a[:2] for a in by_row.answers] == [a[:2] for a in by_line.answers]
    assert by_row.ticks == by_line.ticks and len(by_row.ticks) == 200
