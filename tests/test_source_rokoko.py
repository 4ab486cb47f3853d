"""``fpdtw serve --source rokoko://``: Rokoko Studio's custom streaming (JSON v3), sent by our
own encoder of the layout (``fpdtw stream --as rokoko``) over 127.0.0.1, and hostile datagrams.

The recording is CMU 18_01 (31 joints, 30 Hz); the live takes are it retimed (written as
BVH files), so that the maps are not the identity. The hostile cases are put straight into
the source's queue (what the socket would hand it), so that no datagram is lost on the way.
"""

from __future__ import annotations

import asyncio
import json
import re
import socket
import threading

import numpy as np
import orjson
import pytest
from reference.live_sources import offline_map, read_queued, read_sent, serve_and_stream
from reference.live_sources import performers as shared_performers

from fpdtw.app import cli
from fpdtw.app.source_rokoko import (
    BONES,
    JOINT_MAPS,
    LZ4_MAGIC,
    MAX_DATAGRAM,
    MAX_DEPTH,
    PARENTS,
    RIG_BONES,
    TPOSE,
    Refused,
    RokokoSkeleton,
    Source,
    actor_name,
    fpdtw_to_studio,
    nesting,
    play_as_rokoko,
    read_body,
    read_datagram,
    rest_relative,
    rokoko_datagrams,
    studio_to_fpdtw,
    v3_datagram,
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


def loopback(takes, FI, *, idle=0.5):
    """Send ``takes`` with :func:`play_as_rokoko` (one actor each) to the rokoko source on
    127.0.0.1: (performers, how the take ended, log)."""
    send = lambda port: play_as_rokoko(takes, f"127.0.0.1:{port}", fast=True)  # noqa: E731
    return read_sent(Source("127.0.0.1", 0, rate=30), send, FI, JOINT_MAPS, idle=idle)


def inject(datagrams, FI, *, addr=("127.0.0.1", 5000), idle=0.2, rate=30, **kw):
    """``datagrams`` handed to the source as its socket would, nothing lost: (performers,
    how the take ended, log)."""
    source = Source("127.0.0.1", 0, rate=rate)
    return read_queued(source, [(d, addr) for d in datagrams], FI, JOINT_MAPS, idle=idle, **kw)


# ------------------------------------------------------------------------- the wire format
#: One datagram written out from the JSON v3 layout of Rokoko's "Custom Streaming" article:
#: actor "Ann" at scene time 12.5 s, her hip at (1, -2, 0.5) m turned 90 degrees about
#: Studio's Y (x y z w = 0, sqrt(1/2), 0, sqrt(1/2)), her left toe end and a prop (valid,
#: not read), the version as the string "3,0" the Blender plugin also accepts.
HAND = b"""{"version": "3,0", "fps": 60,
 "scene": {"timestamp": 12.5,
  "actors": [{"name": "Ann", "color": {"r": 255, "g": 0, "b": 0},
    "meta": {"hasGloves": false, "hasLeftGlove": false, "hasRightGlove": false,
             "hasBody": true, "hasFace": false},
    "dimensions": {"totalHeight": 1.8, "hipHeight": 1.0},
    "body": {"hip": {"position": {"x": 1, "y": -2, "z": 0.5},
                     "rotation": {"x": 0, "y": 0.70710677, "z": 0, "w": 0.70710677}},
             "leftToeEnd": {"position": {"x": 0, "y": 0, "z": 0},
                            "rotation": {"x": 0, "y": 0, "z": 0, "w": 1}}}}],
  "props": [{"name": "Box1", "color": {"r": 1, "g": 2, "b": 3}, "type": 0,
             "position": {"x": 0, "y": 0, "z": 0},
             "rotation": {"x": 0, "y": 0, "z": 0, "w": 1}}]}}"""


def _full_body(actor, values=None):
    """``actor`` (a dict) with every body bone at ``values`` (7: p, q x y z w; default its
    T-pose at the origin)."""
    for b in BONES:
        v = values if values is not None else [0.0, 0.0, 0.0, *TPOSE[b]]
        actor["body"][b] = {"position": dict(zip("xyz", v[:3], strict=True)),
                            "rotation": dict(zip("xyzw", v[3:], strict=True))}  # fmt: skip
    return actor


def test_a_hand_written_datagram():
    """The text above, read field by field by the source: its time, fps and actor; the hip's
    values as written; the toe end and the prop ignored; 20 body bones missing."""
    fps, t, actors = read_datagram(HAND)
    assert (fps, t, len(actors)) == (60, 12.5, 1) and actor_name(actors[0]) == "Ann"
    with pytest.raises(Refused) as e:
        read_body(actors[0])
    assert e.value.args == ("missing", "the body lacks spine, chest, neck, head")
    doc = json.loads(HAND)
    _full_body(doc["scene"]["actors"][0])
    doc["scene"]["actors"][0]["body"]["hip"] = json.loads(HAND)["scene"]["actors"][0]["body"]["hip"]
    v = read_body(read_datagram(json.dumps(doc).encode())[2][0])
    np.testing.assert_array_equal(v[0], [1.0, -2.0, 0.5, 0.0, 0.70710677, 0.0, 0.70710677])
    # in fpdtw's axes: X mirrored; the turn about Y by -90 degrees (a mirror reverses it)
    p, q = studio_to_fpdtw(v[0, :3], v[0, 3:])
    np.testing.assert_array_equal(p, [-1.0, -2.0, 0.5])
    np.testing.assert_array_equal(q, [0.70710677, 0.0, -0.70710677, -0.0])
    # the emulator writes the same values as JSON v3 text (float32 numbers)
    s = float(np.float32(np.sqrt(0.5)))
    text = v3_datagram(12.5, 60, [("Ann", {"hip": ([1, -2, 0.5], [0, s, 0, s])})])
    back = json.loads(text)
    assert back["version"] == 3 and back["scene"]["timestamp"] == 12.5
    assert back["scene"]["actors"][0]["body"] == {
        "hip": {"position": {"x": 1, "y": -2, "z": 0.5},
                "rotation": {"x": 0, "y": 0.70710677, "z": 0, "w": 0.70710677}}}  # fmt: skip


def test_the_two_t_pose_tables_agree():
    """The reader's T-pose (the Unity plugin's table, x y z w) and the emulator's (the Blender
    plugin's, w x y z) are the same rotations, bone by bone."""
    assert sorted(RIG_BONES) == sorted(TPOSE) == sorted(BONES)
    for b, (parent, wxyz, _) in RIG_BONES.items():
        assert parent == PARENTS[b]
        x, y, z, w = TPOSE[b]
        assert abs(abs(np.dot(wxyz, [w, x, y, z])) - 1.0) < 1e-12, b


# ------------------------------------------------------------------------------ the axes
def _rotate(q, v):
    return quat_mul(quat_mul(q, np.r_[0.0, v]), quat_conj(q))[1:]


def test_axes_hand_checked():
    """Studio's (Unity's) X right, Y up, Z forward, left-handed; fpdtw's X left, Y up, Z
    forward. A +90 degree turn about Studio's Y takes forward (Z) to right (X) (Unity's
    matrices are the right-handed ones); in fpdtw's axes it takes (0, 0, 1) to the right,
    (-1, 0, 0): a -90 degree turn about Y. A +90 degree turn about Studio's X takes up to
    forward: in fpdtw's axes the same, +90 degrees about X."""
    s = np.sqrt(0.5)
    p, q = studio_to_fpdtw([1.0, 2.0, 3.0], [0.0, s, 0.0, s])
    np.testing.assert_array_equal(p, [-1.0, 2.0, 3.0])
    np.testing.assert_array_equal(q, [s, 0.0, -s, -0.0])
    np.testing.assert_allclose(_rotate(q, [0.0, 0.0, 1.0]), [-1.0, 0.0, 0.0], atol=1e-12)
    _, q = studio_to_fpdtw([0, 0, 0], [s, 0.0, 0.0, s])
    np.testing.assert_array_equal(q, [s, s, -0.0, -0.0])
    np.testing.assert_allclose(_rotate(q, [0.0, 1.0, 0.0]), [0.0, 0.0, 1.0], atol=1e-12)
    # a general rotation R acts on converted vectors as M R M; the emulator's map inverts it
    rng = np.random.default_rng(0)
    qu = rng.normal(size=4)
    qu /= np.linalg.norm(qu)
    v = rng.normal(size=3)
    M = np.diag([-1.0, 1.0, 1.0])
    _, qf = studio_to_fpdtw([0, 0, 0], qu)
    q_wxyz = np.r_[qu[3], qu[:3]]
    np.testing.assert_allclose(_rotate(qf, M @ v), M @ _rotate(q_wxyz, v), atol=1e-12)
    p2, q2 = fpdtw_to_studio(*studio_to_fpdtw([1.0, 2.0, 3.0], qu))
    np.testing.assert_array_equal(p2, [1.0, 2.0, 3.0])
    np.testing.assert_array_equal(q2, qu)


def _t_pose():
    """The 21 bones' positions of a rough T-pose in Studio's axes (m): left is -X."""
    p = {"hip": (0, 1.0, 0), "spine": (0, 1.1, 0), "chest": (0, 1.3, 0), "neck": (0, 1.5, 0),
         "head": (0, 1.6, 0)}  # fmt: skip
    for side, sx in (("left", -1.0), ("right", 1.0)):
        p.update({f"{side}Shoulder": (0.05 * sx, 1.45, 0), f"{side}UpperArm": (0.2 * sx, 1.45, 0),
                  f"{side}LowerArm": (0.5 * sx, 1.45, 0), f"{side}Hand": (0.75 * sx, 1.45, 0),
                  f"{side}UpLeg": (0.1 * sx, 0.95, 0), f"{side}Leg": (0.1 * sx, 0.5, 0),
                  f"{side}Foot": (0.1 * sx, 0.08, 0),
                  f"{side}Toe": (0.1 * sx, 0.0, 0.12)})  # fmt: skip
    return np.array([p[b] for b in BONES])


def _frame(p, q):
    """(21, 7) values of positions (21, 3) and rotations x y z w (21, 4), Studio's axes."""
    return np.c_[p, q]


@pytest.mark.filterwarnings("ignore:Gimbal lock")  # Y at 90 degrees in the XYZ order
def test_a_turn_about_studios_up_axis_is_a_turn_about_y():
    """In the T-pose (each bone at its T-pose rotation) every channel is zero and the offsets
    are the positions relative to the parent in fpdtw's axes. The whole body turned +90
    degrees about Studio's Y (each world rotation ``turn * T``, the positions turned with it):
    the root's channels are a Y rotation of -90 degrees and every other joint's zero. A left
    forearm and hand bent +90 degrees about Studio's X: a rotation of +90 degrees about
    fpdtw's X of the elbow only."""
    s = np.sqrt(0.5)
    p0 = _t_pose()
    T = np.array([TPOSE[b] for b in BONES], dtype=float)
    sk = RokokoSkeleton(*rest_relative(_frame(p0, T)), 60.0)
    h = parse_bvh_header(sk.header, None, stream=True)
    names = list(h.skeleton.joint_names)
    assert sorted(names) == sorted(BONES)
    np.testing.assert_allclose(h.skeleton.offsets[names.index("neck")], [0, 0.2, 0], atol=1e-12)
    # the left lower arm 0.3 m along Studio's -X (left) from the upper arm: fpdtw's +X
    off = h.skeleton.offsets[names.index("leftLowerArm")]
    np.testing.assert_allclose(off, [0.3, 0, 0], atol=1e-12)
    values = sk.row(*rest_relative(_frame(p0, T)))
    np.testing.assert_allclose(values[3:], 0.0, atol=1e-9)

    def turned(turn, bones=BONES):  # x y z w quaternion product turn * T per bone
        out = T.copy()
        for i, b in enumerate(BONES):
            if b in bones:
                tw = np.r_[turn[3], turn[:3]]
                r = quat_mul(tw, np.r_[T[i, 3], T[i, :3]])
                out[i] = np.r_[r[1:], r[0]]
        return out

    Ry = np.array([[0.0, 0, 1], [0, 1, 0], [-1, 0, 0]])  # +90 degrees about Y: Z to X
    values = sk.row(*rest_relative(_frame(p0 @ Ry.T, turned([0, s, 0, s]))))
    np.testing.assert_allclose(values[3:6], [0.0, -90.0, 0.0], atol=1e-9)  # Z Y X of the hip
    np.testing.assert_allclose(values[6:], 0.0, atol=1e-9)
    bent = turned([s, 0, 0, s], ("leftLowerArm", "leftHand"))
    values = sk.row(*rest_relative(_frame(p0, bent)))
    values = values[3:].reshape(-1, 3)
    elbow = sk.order.index(BONES.index("leftLowerArm"))
    np.testing.assert_allclose(values[elbow], [0.0, 0.0, 90.0], atol=1e-9)  # Z, Y, X
    values[elbow] = 0.0
    np.testing.assert_allclose(values, 0.0, atol=1e-9)
    jm, label = find_joint_map(names, "bvh", JOINT_MAPS)
    assert label == "user map 1" and jm["left_elbow"] == "leftLowerArm"


# --------------------------------------------------------------------- the offline map
def test_one_actor_gives_the_map_of_fpdtw_align(cmu):
    """A retimed take streamed by the emulator (float32 values as JSON text): frame for frame
    the offline map; nothing lost, filled or unusable."""
    _, FI, (warp, _) = cmu
    perf, end, log = loopback([read_bvh(warp)], FI)
    assert end == "ended: nothing received for 0.5 s (--idle-timeout)"
    (p,) = perf.by_key.values()
    assert p.key == 0 and p.name == "actor1"
    np.testing.assert_array_equal(session_map(p.session), offline_map(FI, warp))
    s = perf.summary()[0]
    assert s["frames"] == s["ticks"] == 303 and s["lost"] == s["filled"] == 0
    assert not any(perf.bad.values()) and "21 bones" in s["about"]


def test_two_actors(cmu):
    """Two actors in every datagram: two performers, each the offline map."""
    _, FI, warps = cmu
    perf, end, _ = loopback([read_bvh(w) for w in warps], FI)
    assert end.startswith("ended") and [p.key for p in perf.by_key.values()] == [0, 1]
    assert [p.name for p in perf.by_key.values()] == ["actor1", "actor2"]
    for p, w in zip(perf.by_key.values(), warps, strict=True):
        np.testing.assert_array_equal(session_map(p.session), offline_map(FI, w))
    assert perf.frames == 606 and not any(perf.bad.values())


def test_the_command_line_end_to_end(cmu, tmp_path):
    """``fpdtw serve --source rokoko:// --once --out`` in its own process; ``fpdtw stream A B
    --as rokoko`` here: one map file per actor, each ``fpdtw align``'s."""
    path, _, warps = cmu
    err, files = serve_and_stream("rokoko", path, warps, tmp_path)
    assert "606 frames read; unusable: none" in err
    assert [f.name for f in files] == ["live-take1-0-actor1.csv", "live-take1-1-actor2.csv"]


# ------------------------------------------------------------------------- hostile input
def _take(cmu):
    _, FI, (warp, _) = cmu
    _, frames = rokoko_datagrams([read_bvh(warp)])
    return FI, warp, frames


def _edit(frame: bytes, change) -> bytes:
    """``frame`` parsed, ``change(doc)`` applied, written again."""
    doc = json.loads(frame)
    change(doc)
    return json.dumps(doc).encode()


def _bone(doc, name="leftLeg"):
    return doc["scene"]["actors"][0]["body"][name]


def _set(d, **kw):
    d.update(kw)


def test_json_numbers_are_read_as_float_reads_them():
    """_json_number gives the bits of float(orjson.loads(text)) (an integer's float: -0 is
    0.0) for every number it reads, on float32 values as Studio writes them, their negations,
    integers, exponents and zeros; NaN for what is not a JSON number or not readable by the
    fast path (over 15 significant digits, a power of ten beyond 22)."""
    from fpdtw.app.source_rokoko import _json_number

    rng = np.random.default_rng(8)
    x = rng.normal(size=3000) * 10.0 ** rng.integers(-8, 8, 3000)
    texts = [str(np.float32(v)) for v in x] + [str(int(v)) for v in x * 1e3]
    texts += ["0", "-0", "0.0", "-0.0", "1e22", "1E-22", "-2.5e+3", "123456789012345",
              "0.000000000000001", "9007199254740993"]  # fmt: skip
    read = 0
    for t in texts:
        b = np.frombuffer(t.encode(), np.uint8)
        got = _json_number(b, 0, len(b))
        if not np.isnan(got):
            read += 1
            want = float(orjson.loads(t))
            assert np.float64(got).view(np.int64) == np.float64(want).view(np.int64), t
    assert read > 0.95 * len(texts)
    for bad in ["", "-", "01", "1.", ".5", "1e", "1e+", "+1", "1.2.3", "--1", "1e999", "1e23",
                "1234567890123456", "1.0000000000000001", "0x10", "1-2"]:  # fmt: skip
        b = np.frombuffer(bad.encode(), np.uint8)
        assert np.isnan(_json_number(b, 0, len(b))), bad


def test_a_senders_next_datagrams_are_read_from_their_numbers(cmu):
    """After a datagram read whole, a sender's next one with the same bytes outside its
    numbers is read from its number tokens (_Template) into exactly what read_datagram and
    read_body give; one that differs elsewhere, holds a number the fast path does not read,
    or a value that may fail a check is left to them (None or False)."""
    from fpdtw.app.source_rokoko import _Template

    _, _, frames = _take(cmu)
    two = rokoko_datagrams([read_bvh(w) for w in cmu[2]])[1]
    for datagrams in (frames, two):
        template = _Template(datagrams[0])
        assert template is not None
        for d in datagrams[1:]:
            fps, t, actors = template.read(d, 1e6)
            fps0, t0, actors0 = read_datagram(d, 1e6)
            assert (fps, t) == (fps0, t0) and len(actors) == len(actors0)
            for (name, v), a in zip(actors, actors0, strict=True):
                assert name == actor_name(a)
                np.testing.assert_array_equal(v, read_body(a, 1e6))
    template, f = _Template(frames[0]), frames[5]
    x = f.index(b'"x":') + 4
    x_end = f.index(b",", x)
    for other in (f.replace(b'"x":', b'"x": ', 1), f[:x] + b"1e999" + f[x_end:],
                  f[:x] + b"01" + f[x_end:], f[:x] + b"1.0000000000000001" + f[x_end:],
                  f.replace(b'"actor1"', b'"actor2"'), f + b" "):  # fmt: skip
        assert template.read(other, 1e6) is None
    assert template.read(f[:x] + b"2e6" + f[x_end:], 1e6) is False  # beyond the limit
    doubled = f.replace(b'"fps":', b'"version":3,"fps":', 1)
    assert _Template(doubled) is None  # a key twice: which token is which cannot be told
    assert _Template(f.replace(b'"head":', b'"tail":', 1)) is None  # not read whole


def test_orjson_reads_every_datagram_as_the_standard_library_does(cmu, monkeypatch):
    """read_datagram through orjson gives what the standard library's reading gives (orjson
    made to refuse everything): on every datagram of a take and on documents where the two
    readers differ (orjson refuses NaN, 1e999, a BOM, UTF-16 and lone surrogates; it reads
    integers of 19 to 20 digits as ints, json here as floats)."""
    _, _, frames = _take(cmu)
    f = frames[3]
    odd = [
        f.replace(b'"fps":', b'"fps":12345678901234567890,"f":'),
        f.replace(b'"fps":', b'"fps":1e999,"f":'),
        f.replace(b'"fps":', b'"fps":NaN,"f":'),
        f.replace(b'"name":"', b'"name":"\\ud800', 1),
        b"\xef\xbb\xbf" + f,
        f.decode().encode("utf-16"),
        f.replace(b'"x":', b'"x":1' + b"0" * 19 + b',"q":', 1),
    ]

    def outcome(data):
        try:
            fps, t, actors = read_datagram(data, 1e6)
            return repr((fps, t, [(actor_name(a), read_body(a, 1e6).tolist()) for a in actors]))
        except Refused as e:
            return "{}: {}".format(*e.args)

    fast = [outcome(d) for d in [*frames, *odd]]
    fail = orjson.JSONDecodeError("made to refuse", "", 0)
    monkeypatch.setattr(orjson, "loads", lambda data: (_ for _ in ()).throw(fail))
    assert fast == [outcome(d) for d in [*frames, *odd]]
    starts = ["(None, 0.1, [('actor1'", "(None, 0.1, [('actor1'", "finite: JSON NaN",
              "(30, 0.1, [('\\ud800actor1'", "(30, 0.1, [('actor1'", "(30, 0.1, [('actor1'",
              "large: bone 'hip' has a value beyond"]  # fmt: skip
    assert all(o.startswith(w) for o, w in zip(fast[-7:], starts, strict=True)), fast[-7:]


@pytest.mark.parametrize(
    "spoil,kind,what",
    [
        (lambda f: b"hello", "rokoko", "not JSON"),
        (lambda f: f[:-7], "rokoko", "not JSON"),
        (lambda f: b"[" * 40 + b"]" * 40, "rokoko", f"nested 40 deep, more than {MAX_DEPTH}"),
        (lambda f: f.replace(b'"version":3', b'"version":2'), "rokoko", "version '2'"),
        (lambda f: f.replace(b'"version":3', b'"version":"4.0"'), "rokoko", "version '4.0'"),
        (lambda f: _edit(f, lambda d: d.pop("scene")), "rokoko", "no scene"),
        (lambda f: _edit(f, lambda d: d["scene"].pop("timestamp")), "rokoko", "not a finite"),
        (lambda f: f + b" " * MAX_DATAGRAM, "oversize", f"more than {MAX_DATAGRAM}"),
        (lambda f: LZ4_MAGIC + f, "lz4", "an LZ4 frame"),
        (lambda f: f.replace(b'"x":', b'"x":NaN,"q":', 1), "finite", "JSON NaN"),
        (lambda f: f.replace(b'"w":', b'"w":-Infinity,"q":', 1), "finite", "JSON -Infinity"),
        (lambda f: f.replace(b'"x":', b'"x":1e999,"q":', 1), "large", "'hip' has a value"),
        (lambda f: f.replace(b'"x":', b'"x":' + b"9" * 5000 + b',"q":', 1), "large", "beyond"),
        (lambda f: _edit(f, lambda d: _bone(d)["position"].update(y=1e30)), "large", "beyond"),
        (
            lambda f: _edit(f, lambda d: _bone(d)["rotation"].update(w=3.0)),
            "rotation",
            "'leftLeg''s quaternion has norm",
        ),
        (
            lambda f: _edit(f, lambda d: _bone(d)["rotation"].update(w="1")),
            "number",
            "bone 'leftLeg' without numbers",
        ),
        (lambda f: _edit(f, lambda d: _bone(d).pop("position")), "number", "without numbers"),
        (
            lambda f: _edit(f, lambda d: d["scene"]["actors"][0]["body"].pop("head")),
            "missing",
            "the body lacks head",
        ),
        (lambda f: _edit(f, lambda d: d["scene"]["actors"][0].pop("body")), "missing", "no body"),
        (
            lambda f: _edit(f, lambda d: _set(d["scene"]["actors"][0]["body"], tail=_bone(d))),
            "bone",
            "bone 'tail' is not one of Rokoko's",
        ),
        (
            lambda f: _edit(f, lambda d: _set(d["scene"]["actors"][0], name="")),
            "name",
            "an actor whose name ''",
        ),
        (
            lambda f: _edit(f, lambda d: _set(d["scene"]["actors"][0], name="x" * 999)),
            "name",
            "is not a string",
        ),
        (
            lambda f: _edit(f, lambda d: d["scene"]["actors"].append(d["scene"]["actors"][0])),
            "duplicate",
            "actor 'actor1' twice in one datagram",
        ),
    ],
)
def test_an_unusable_datagram_is_counted_and_filled(cmu, spoil, kind, what):
    """Frame 41's datagram spoilt (of the take's first 120): counted, named by its number;
    a lost frame is a one-frame gap filled by slerp; every answer before it is the offline
    map's (an online map is causal)."""
    FI, warp, frames = _take(cmu)
    frames = frames[:120]
    frames[40] = spoil(frames[40])
    perf, end, log = inject(frames, FI)
    assert end.startswith("ended") and perf.bad[kind] == 1 and sum(perf.bad.values()) == 1
    first = next(m for m in log if "dropped; counted" in m)
    assert "datagram 41 from 127.0.0.1:5000" in first and what in first, first
    s = perf.summary()[0]
    M, ref = session_map(perf.get(0).session), offline_map(FI, warp)
    if kind == "duplicate":  # the actor's first frame in the datagram was read
        assert (s["frames"], s["lost"]) == (120, 0)
        np.testing.assert_array_equal(M, ref[:120])
        return
    assert (s["frames"], s["ticks"], s["lost"], s["filled"]) == (119, 120, 1, 1)
    assert M.size == 120 and abs(int(M[40]) - int(ref[40])) <= 2
    np.testing.assert_array_equal(M[:40], ref[:40])


def test_nesting_is_counted_outside_strings():
    """Brackets inside strings (escaped quotes included) do not count; a string cut at the
    end is read to the end without a second pass."""
    assert nesting(b'{"a": [1, {"b": "[[[{{{\\"]]"}]}') == 3
    assert nesting(b'"' + b'\\"' * 30000) == 0
    assert nesting(b"") == 0
    assert nesting(b"]]}[") == 0 and nesting(b'["\\\n[') == 2  # a lone backslash ends it


def test_nesting_agrees_with_a_regular_expression_reading():
    """The compiled scan against an independent reading: strings removed by a regular
    expression (a string cut at the end included), then the running sum of the brackets."""
    string = re.compile(rb'"(?:[^"\\]+|\\.)*"?')
    steps = {ord("{"): 1, ord("["): 1, ord("}"): -1, ord("]"): -1}

    def reference(data):
        rest = string.sub(b"", data)
        return max(0, *np.cumsum([steps.get(c, 0) for c in rest] or [0]).tolist())

    rng = np.random.default_rng(3)
    alphabet = np.frombuffer(b'{}[]"\\\na, ', np.uint8)
    for _ in range(20000):
        data = bytes(rng.choice(alphabet, rng.integers(0, 24)))
        assert nesting(data) == reference(data), data


def test_duplicated_and_reordered_datagrams(cmu):
    """A datagram sent twice: the copy is counted, the map is the offline one exactly.
    Frames 41 and 42 swapped: 42 arrives first (41 is a gap, filled), 41 is counted as
    older."""
    FI, warp, frames = _take(cmu)
    perf, end, _ = inject(frames[:41] + [frames[40]] + frames[41:], FI)
    assert perf.bad["duplicate"] == 1 and sum(perf.bad.values()) == 1
    np.testing.assert_array_equal(session_map(perf.get(0).session), offline_map(FI, warp))
    perf, end, log = inject(frames[:40] + [frames[41], frames[40]] + frames[42:], FI)
    assert perf.bad["order"] == 1 and sum(perf.bad.values()) == 1
    assert any("datagram 42 from 127.0.0.1:5000 (time 1.3333334 s): not after" in m
               for m in log), log  # fmt: skip
    s = perf.summary()[0]
    assert (s["frames"], s["lost"], s["filled"]) == (302, 1, 1)


def test_a_first_frame_without_every_bone(cmu):
    """A first frame without the right toe: counted as missing; the skeleton comes from the
    next."""
    FI, warp, frames = _take(cmu)
    first = _edit(frames[0], lambda d: d["scene"]["actors"][0]["body"].pop("rightToe"))
    perf, end, log = inject([first] + frames[1:], FI)
    assert perf.bad["missing"] == 1 and sum(perf.bad.values()) == 1
    assert any("datagram 1 from 127.0.0.1:5000 (time 0.0 s): actor 'actor1': the body lacks "
               "rightToe" in m for m in log), log  # fmt: skip
    assert perf.summary()[0]["frames"] == 302


def test_a_flood_is_bounded_counted_and_ends_the_take(cmu):
    """More datagrams than the queue holds: the excess is dropped and counted at once; the
    take's frames before the garbage are aligned as usual; a run of garbage then ends the
    take with a message naming its datagram."""
    FI, warp, frames = _take(cmu)
    flood = frames + [b"\x01" * 20] * (MAX_QUEUE + 700 - len(frames))
    perf, end, log = inject(flood, FI)
    assert perf.bad["flood"] == 700
    assert end.startswith("error: frame 314: datagram 314 from 127.0.0.1:5000: not JSON"), end
    assert "11 unusable frames in a row" in end
    assert any("datagrams 315 to 1014 dropped: more than 4096 waiting" in m for m in log)
    np.testing.assert_array_equal(session_map(perf.get(0).session), offline_map(FI, warp))


def test_compressed_datagrams_end_the_take_with_a_clear_message(cmu):
    """Studio set to LZ4-compressed JSON: every datagram counted as such, and the take ends
    saying what to choose in Studio."""
    FI, _, frames = _take(cmu)
    perf, end, _ = inject([LZ4_MAGIC + f for f in frames[:30]], FI)
    assert perf.bad["lz4"] == 11 and not perf.by_key
    assert "choose uncompressed JSON v3 in Studio's Custom streaming" in end, end


def test_actors_beyond_the_bound(cmu):
    """Two actors with --max-clients 1: the second's frames are refused, the first's
    aligned."""
    _, FI, warps = cmu
    _, frames = rokoko_datagrams([read_bvh(w) for w in warps])
    perf, end, _ = inject(frames[:60], FI, max_performers=1)
    assert end.startswith("ended") and list(perf.by_key) == [0]
    assert perf.bad["refused"] == 60 and perf.summary()[0]["frames"] == 60


def test_the_rate_comes_from_the_stream_without_rate(cmu):
    """Without --rate the first datagram's fps (the take's 30 Hz here) is the stream's rate."""
    FI, warp, frames = _take(cmu)
    perf, end, _ = inject(frames, FI, rate=None)
    assert "30 Hz" in perf.summary()[0]["about"]
    np.testing.assert_array_equal(session_map(perf.get(0).session), offline_map(FI, warp))


def test_hostile_datagrams_over_loopback(cmu):
    """Not JSON, cut, compressed and wrong-version datagrams over a real UDP socket, between
    a take's frames: counted, and the take's map is the offline one."""
    FI, warp, frames = _take(cmu)

    async def main():
        source = Source("127.0.0.1", 0, rate=30)
        conn = await source.connect()
        port = conn[0].get_extra_info("sockname")[1]
        log = []
        perf = performers(FI, log)
        bad = {10: b"not json", 20: frames[5][:37], 30: LZ4_MAGIC + frames[5],
               40: frames[5].replace(b'"version":3', b'"version":2')}  # fmt: skip

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
    assert end.startswith("ended") and perf.bad["rokoko"] == 3 and perf.bad["lz4"] == 1
    np.testing.assert_array_equal(session_map(perf.get(0).session), offline_map(FI, warp))


# ------------------------------------------------------------------------- usage
def test_source_url_and_usage_errors(capsys):
    module, host, port = parse_source("rokoko://0.0.0.0")
    assert module.DEFAULT_PORT == 14043 and (host, port) == ("0.0.0.0", 14043)
    for args, needle in [
        (["serve", "IN.bvh", "--source", "rokoko://h:1", "--header", "H.bvh"], "--header does not"),
        (["stream", "A.bvh", "--as", "rokoko", "--listen", "h:1"], "--listen does not apply"),
        (["stream", "A.bvh", "--as", "rokoko", "--to", "h:0"], "port 0"),
    ]:  # fmt: skip
        assert cli.main(args) == 2
        assert needle in capsys.readouterr().err


def test_a_frames_compiled_row_is_rest_relative_then_row_bit_for_bit():
    """RokokoSkeleton.row_of (one compiled call) equals row(*rest_relative(v)) on random
    frames whose quaternions are near unit length, as the checks let through."""
    rng = np.random.default_rng(11)

    def frame():
        v = np.empty((len(BONES), 7))
        v[:, :3] = rng.normal(size=(len(BONES), 3))
        q = rng.normal(size=(len(BONES), 4))
        v[:, 3:] = q / np.linalg.norm(q, axis=1)[:, None] * rng.uniform(0.999, 1.001, (21, 1))
        return v

    sk = RokokoSkeleton(*rest_relative(frame()), 60.0)
    for _ in range(2000):
        v = frame()
        np.testing.assert_array_equal(sk.row_of(v), sk.row(*rest_relative(v)))
