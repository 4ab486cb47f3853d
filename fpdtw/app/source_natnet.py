"""``natnet://HOST:PORT``: OptiTrack Motive's NatNet 4.1 skeleton stream, both ways.

``HOST:PORT`` is Motive's COMMAND port (1510 by default; frames come from its data port, 1511,
in multicast). fpdtw is a NatNet unicast client: from one UDP socket of its own it sends
``NAT_CONNECT`` and ``NAT_REQUEST_MODELDEF`` to ``HOST:PORT`` until the skeletons are
described, then ``NAT_KEEPALIVE`` every second; the server answers, and streams its frames,
to that socket. Multicast is not read: set Motive's transmission type to Unicast.

What follows is the layout the NatNet SDK 4.1's own clients read (its ``PythonClient``'s
``NatNetClient.py``, Apache 2.0, and ``PacketClient.cpp``; "the SDK"); only NatNet 4.1 is read
(Motive 3.1): 4.2 adds fields to the descriptions, 3.x lacks the section sizes. Every number
is little-endian; a packet is its message ID (uint16), the size of what follows (uint16),
then the message:

* ``NAT_SERVERINFO`` (1), the answer to ``NAT_CONNECT`` (0): the application's name (256
  bytes), its version and its NatNet version (4 bytes each), ... A server that is not NatNet
  4.1 ends the take with a message naming its version.
* ``NAT_MODELDEF`` (5), the answer to ``NAT_REQUEST_MODELDEF`` (4): the number of
  descriptions, then each as its type (int32), its size in bytes (int32, from 4.1) and
  itself; a skeleton (type 2) is its name (NUL-ended), ID (int32), number of bones, and per
  bone its name, ID, parent's ID (0: none), offset from the parent x y z (float32) and its
  markers (count, positions, labels, names; not read). Other types are skipped by size.
* ``NAT_FRAMEOFDATA`` (7): the frame number (int32), then eight sections, each a count and
  its size in bytes (int32 each) and its items: marker sets, legacy markers (12 bytes each),
  rigid bodies (38), SKELETONS, assets, labeled markers (26), force plates, devices; then a
  50-byte suffix (time codes, timestamps, parameters). A skeleton is its ID, its number of
  bones, and 38 bytes a bone: the ID (the skeleton's in the high 16 bits, the bone's in the
  low 16; the SDK's ``NatNet_DecodeID``), position x y z, quaternion ``qx qy qz qw``, mean
  marker error (float32 each) and parameters (int16). Only skeletons are read.

**Skeleton.** From each skeleton's description: its bones depth first from the one without a
parent, their offsets as BVH offsets, identity rotations the rest pose (the pose the offsets
describe). Bone poses are read as LOCAL, each relative to its parent bone (Motive's default:
"Local Rigid Bodies" in Motive 2's streaming pane, "Skeleton Coordinates: Local" in Motive
3's; "Global" would be misread): each frame's root position and every bone's local rotation
make the BVH line; other bones' positions are not read (their offsets stand). Motive's
default bone names (its "Motive" naming convention): Hip, Ab, Chest, Neck, Head, LShoulder,
LUArm, LFArm, LHand, LThigh, LShin, LFoot, LToe and the same with R (:data:`JOINT_MAPS`).
**Axes**: Motive's world is Y up, right-handed (OptiTrack's documentation), as fpdtw's, so
:func:`motive_to_fpdtw` keeps positions and only reorders the quaternion to ``w x y z``;
units are the stream's (metres by default; positions are rescaled by body size anyway).

**Performers** are skeleton IDs (named as described), at most :data:`MAX_SKELETONS` tracked;
frame ``f`` of a skeleton counts at ``(f - f0) / rate`` (``--rate``: Motive's frame rate), so
a lost frame is a gap. A frame of a skeleton the descriptions lack asks for them again.

:func:`play_as_natnet` is the other side without hardware (``fpdtw stream --as natnet``): a
server written from the same layout apart from the reader (its own bone table and packets
packed field by field), answering one client on the command port and streaming to it.
"""

from __future__ import annotations

import asyncio
import contextlib
import re
import socket
import struct
import time

import numba
import numpy as np

from fpdtw import limits
from fpdtw.app.serve import parse_address
from fpdtw.app.sources import DatagramReceiver, DatagramSource, TakeEnd, bvh_header, sender_name
from fpdtw.motion.joints import PAPER_JOINTS, resolve_joint_map
from fpdtw.motion.rig import rest_rotations
from fpdtw.motion.rotations import (
    euler_into,
    euler_kernel,
    quat_conj,
    quat_mul,
    quat_rotate,
    quat_to_euler,
)

#: Motive's command port (its data port, for multicast, is 1511).
DEFAULT_PORT = 1510
#: The default frame rate (``--rate``): the period a gap is measured in.
DEFAULT_RATE = 120.0
#: The NatNet version read (and asked for in ``NAT_CONNECT``, as the SDK does).
VERSION = (4, 1)
#: Bytes a datagram may have: its header and the most a uint16 size can announce.
MAX_DATAGRAM = 4 + 0xFFFF
#: Skeleton IDs described and tracked in one take; bones of one skeleton; descriptions in one
#: ``NAT_MODELDEF``; bytes of a name.
MAX_SKELETONS, MAX_BONES, MAX_DESCRIPTIONS, MAX_NAME = 64, 256, 1024, 256
#: A quaternion whose norm is further than this from 1 is not a rotation (float32 on the wire).
UNIT_TOLERANCE = 1e-3
#: Seconds between requests until the skeletons are described, and between keep-alives after.
REQUEST_S, KEEPALIVE_S = 0.5, 1.0

NAT_CONNECT, NAT_SERVERINFO, NAT_RESPONSE, NAT_REQUEST_MODELDEF, NAT_MODELDEF = 0, 1, 3, 4, 5
NAT_FRAMEOFDATA, NAT_MESSAGESTRING, NAT_KEEPALIVE, NAT_UNRECOGNIZED_REQUEST = 7, 8, 10, 100
#: Answers to requests fpdtw does not make: ignored.
QUIET = frozenset({NAT_RESPONSE, NAT_MESSAGESTRING, NAT_UNRECOGNIZED_REQUEST})

HEADER = struct.Struct("<HH")  # message ID, bytes that follow
PAIR = struct.Struct("<ii")  # a section's count and bytes; a skeleton's ID and bones; ...
BONE_DESCRIPTION = struct.Struct("<ii3fi")  # after the name: ID, parent, offset, markers
#: A bone of a frame: composite ID, position, quaternion qx qy qz qw, mean error, parameters.
BONE = np.dtype([("id", "<u4"), ("v", "<f4", (7,)), ("error", "<f4"), ("params", "<i2")])
#: ``NAT_CONNECT`` as the SDK sends it: "Ping", zeros, the NatNet version wanted at byte 265.
CONNECT = HEADER.pack(NAT_CONNECT, 271) + b"Ping" + bytes(261) + bytes([*VERSION, 0, 0, 0, 0])
SUFFIX_BYTES = 50  # time code, subframe, timestamp (f64), 3 x u64 stamps, 2 x u32, params
SECTIONS = ("marker sets", "legacy markers", "rigid bodies", "skeletons", "assets",
            "labeled markers", "force plates", "devices")  # fmt: skip
_ITEM_BYTES = {1: 12, 2: 38, 5: 26}  # sections of fixed-size items
assert BONE.itemsize == 38 and BONE_DESCRIPTION.size == 24

_FULL = {"center_hip": "Hip", "middle_chest": "Ab", "upper_chest": "Chest", "head": "Head"}
for _s, _c in (("L", "left"), ("R", "right")):
    _FULL.update({f"{_c}_hip": f"{_s}Thigh", f"{_c}_knee": f"{_s}Shin", f"{_c}_ankle": f"{_s}Foot",
                  f"{_c}_shoulder": f"{_s}UArm", f"{_c}_elbow": f"{_s}FArm",
                  f"{_c}_wrist": f"{_s}Hand"})  # fmt: skip
#: The built-in joint maps of Motive's skeleton (our joint -> bone), after ``--joint-map``'s:
#: all 16 joints; the paper's 8.
JOINT_MAPS = (_FULL, {j: _FULL[j] for j in PAPER_JOINTS})

_ORDER = "XYZ"  # the built skeleton's rotation order, written Zrotation Yrotation Xrotation


def motive_to_fpdtw(p, q_xyzw):
    """Motive's position (..., 3) and quaternion ``qx qy qz qw`` (..., 4) in fpdtw's axes:
    the same position and ``(qw, qx, qy, qz)``: both worlds are Y up and right-handed."""
    q = np.asarray(q_xyzw, dtype=float)
    return np.asarray(p, dtype=float), q[..., [3, 0, 1, 2]]


class Bad(Exception):
    """A packet that cannot be read: ``kind`` of :data:`fpdtw.app.sources.BAD_KINDS`."""

    def __init__(self, kind: str, what: str):
        super().__init__(what)
        self.kind = kind


def _need(ok: bool, what: str, *args) -> None:
    """:class:`Bad` (kind ``natnet``) saying ``what`` (``what.format(*args)`` with ``args``: only
    written when it is said) unless ``ok``."""
    if not ok:
        raise Bad("natnet", what.format(*args) if args else what)


def _name(data, pos: int, end: int) -> tuple:
    """The NUL-ended name at ``pos`` (at most :data:`MAX_NAME` bytes) and the position after."""
    k = data.find(b"\0", pos, min(end, pos + MAX_NAME + 1))
    _need(k >= 0, f"a name at byte {pos} without its NUL within {MAX_NAME} bytes")
    return data[pos:k].decode("utf-8", "replace"), k + 1


def parse_descriptions(data: bytes) -> list:
    """The skeletons of a ``NAT_MODELDEF`` packet: ``[(name, ID, [(bone name, ID, parent ID,
    offset (3,)), ...]), ...]``; :class:`Bad` when a count or size disagrees with the bytes."""
    end, pos, out = len(data), 8, []
    _need(end >= 8, f"NAT_MODELDEF of {end} bytes, without its count")
    (n,) = struct.unpack_from("<i", data, 4)
    _need(0 <= n <= MAX_DESCRIPTIONS, f"{n} descriptions (at most {MAX_DESCRIPTIONS} are read)")
    for k in range(n):
        _need(pos + 8 <= end, f"description {k + 1} of {n} cut at byte {pos} of {end}")
        kind, size = PAIR.unpack_from(data, pos)
        pos += 8
        _need(0 <= size <= end - pos, f"description {k + 1} of {size} bytes, {end - pos} left")
        if kind == 2:
            out.append(_skeleton_description(data, pos, pos + size))
        pos += size
    _need(pos == end, f"{end - pos} bytes after the {n} descriptions")
    return out


def _skeleton_description(data, pos: int, end: int) -> tuple:
    """A skeleton's description in ``data[pos:end]``: ``(name, ID, bones)``."""
    name, pos = _name(data, pos, end)
    _need(pos + 8 <= end, f"skeleton {name!r}'s description cut before its bones")
    sid, n = PAIR.unpack_from(data, pos)
    pos += 8
    _need(0 < n <= MAX_BONES, f"skeleton {sid} ({name!r}) with {n} bones (1 to {MAX_BONES})")
    bones = []
    for _ in range(n):
        bone, pos = _name(data, pos, end)
        _need(pos + BONE_DESCRIPTION.size <= end, f"skeleton {sid}: bone {bone!r} cut")
        bid, parent, x, y, z, markers = BONE_DESCRIPTION.unpack_from(data, pos)
        pos += BONE_DESCRIPTION.size
        _need(
            0 <= markers <= (end - pos) // 17,  # 12 + 4 bytes and a name of 1 at least
            f"skeleton {sid}: bone {bone!r} with {markers} markers in {end - pos} bytes",
        )
        pos += 16 * markers
        for _ in range(markers):
            _, pos = _name(data, pos, end)
        bones.append((bone, bid, parent, np.array([x, y, z])))
    _need(pos == end, f"skeleton {sid}'s description fills {pos} of its {end} bytes")
    return name, sid, bones


def parse_frame(data: bytes) -> tuple:
    """A ``NAT_FRAMEOFDATA`` packet: ``(frame number, [(skeleton ID, bones), ...])``, the bones
    a structured array of :data:`BONE`; :class:`Bad` when a count or size disagrees."""
    end, pos, skeletons = len(data), 8, []
    _need(end >= 8, "a frame of {} bytes, without its number", end)
    (number,) = struct.unpack_from("<i", data, 4)
    for s, what in enumerate(SECTIONS):
        _need(pos + 8 <= end, "cut before its {} at byte {} of {}", what, pos, end)
        count, size = PAIR.unpack_from(data, pos)
        pos += 8
        item = _ITEM_BYTES.get(s)
        _need(count >= 0 and 0 <= size <= end - pos and (item is None or count * item == size),
              "{} {} in {} bytes, with {} left", count, what, size, end - pos)  # fmt: skip
        if s == 3:
            skeletons = _skeletons(data, pos, count, size)
        pos += size
    _need(end - pos == SUFFIX_BYTES, "{} bytes after the devices, not the {}-byte suffix",
          end - pos, SUFFIX_BYTES)  # fmt: skip
    return number, skeletons


def _skeletons(data, pos: int, count: int, size: int) -> list:
    """A frame's ``count`` skeletons in ``data[pos:pos + size]``: ``[(ID, bones), ...]``."""
    _need(count <= MAX_SKELETONS, "{} skeletons in a frame (at most {})", count, MAX_SKELETONS)
    end, out = pos + size, []
    for _ in range(count):
        _need(pos + 8 <= end, "{} skeletons in {} bytes (cut)", count, size)
        sid, n = PAIR.unpack_from(data, pos)
        pos += 8
        _need(0 <= n <= min(MAX_BONES, (end - pos) // BONE.itemsize),
              "skeleton {} with {} bones in {} bytes", sid, n, end - pos)  # fmt: skip
        out.append((sid, np.frombuffer(data, BONE, n, pos)))
        pos += n * BONE.itemsize
    _need(pos == end, "{} skeletons fill {} of their {} bytes", count, pos - end + size, size)
    return out


class NatNetSkeleton:
    """A described skeleton as a BVH header and the motion lines of its frames.

    Parameters
    ----------
    bones : list of tuple
        ``(name, ID, parent ID, offset (3,))`` per bone, as described.
    rate : float

    Attributes
    ----------
    header : list of str
        Joints named as the bones (anything but letters, digits, ``_ . : -`` as ``_``).
    index : dict
        Bone ID -> its row in the header's order.
    names : list of str
        The bones' names in the header's order.

    Raises
    ------
    Bad
        Bones that are not one tree (IDs outside 1..65535 or twice, not one root, a parent
        that is not a bone, a name twice).
    """

    def __init__(self, bones, rate: float):
        by_id = {b[1]: b for b in bones}
        names = [re.sub(r"[^A-Za-z0-9_.:-]", "_", b[0]) or f"bone{b[1]}" for b in bones]
        roots = [b[1] for b in bones if b[2] == 0]
        _need(len(by_id) == len(set(names)) == len(bones) and len(roots) == 1,
              "bone IDs or names twice, or not one bone without a parent")  # fmt: skip
        _need(all(0 < i <= 0xFFFF and (p == 0 or p in by_id) for _, i, p, _ in bones),
              "a bone ID outside 1..65535 or a parent that is not a bone")  # fmt: skip
        big = limits.get("max_abs_value")
        _need(all(np.isfinite(b[3]).all() and np.abs(b[3]).max() <= big for b in bones),
              "an offset that is NaN, inf or beyond FPDTW_MAX_ABS_VALUE")  # fmt: skip
        ids = [b[1] for b in bones]
        up = [-1 if b[2] == 0 else ids.index(b[2]) for b in bones]
        self.header, order = bvh_header(names, up, [b[3] for b in bones], rate)
        _need(len(order) == len(bones), "bones whose parents do not lead to the root")
        self.index = {ids[j]: r for r, j in enumerate(order)}
        self.names = [names[j] for j in order]

    def row(self, v) -> np.ndarray:
        """The BVH channel values (n_channels,) float64 of a frame: ``v`` (B, 7) float, each
        bone's local position and quaternion ``qx qy qz qw`` in the header's order (Motive's
        axes)."""
        q = v[:, 3:]  # qx qy qz qw: normalised as motive_to_fpdtw's w x y z (summed in that order)
        q = q / np.sqrt(np.add.reduce(np.square(q[:, [3, 0, 1, 2]]), axis=1, keepdims=True))
        e = quat_to_euler(q, _ORDER, scalar_first=False)[:, ::-1]  # Z Y X
        return np.concatenate([v[0, :3], e.ravel()])


#: :func:`fpdtw.motion.rotations.euler_kernel` of the built skeleton's order, ``x y z w``.
_EULER = euler_kernel(_ORDER, scalar_first=False)


@numba.njit(cache=True)
def _checked_row(sent, rows, big, tol, euler, v, out):  # pragma: no cover - compiled
    """:meth:`Source.check`'s checks and :meth:`NatNetSkeleton.row` in one call: the bones'
    values ``sent`` (B, 7) float32 put in rows ``rows`` of ``v`` (B, 7) float64; True and the
    row in ``out`` when every value is within ``big`` (NaN: not) and every quaternion's norm
    within ``tol`` of 1 (else False: the NumPy checks then name what is wrong). The row's
    operations in its order: each quaternion normalised by its squares summed ``w x y z``."""
    n = sent.shape[0]
    for b in range(n):
        for c in range(7):
            x = np.float64(sent[b, c])
            if not abs(x) <= big:
                return False
            v[rows[b], c] = x
    q = np.empty((n, 4))
    for r in range(n):
        x, y, z, w = v[r, 3], v[r, 4], v[r, 5], v[r, 6]
        if not abs(np.sqrt(((x * x + y * y) + z * z) + w * w) - 1.0) < tol:
            return False
        norm = np.sqrt(((w * w + x * x) + y * y) + z * z)
        q[r, 0], q[r, 1], q[r, 2], q[r, 3] = x / norm, y / norm, z / norm, w / norm
    e = np.empty((n, 3))
    euler_into(q, euler, e)
    out[0], out[1], out[2] = v[0, 0], v[0, 1], v[0, 2]
    for r in range(n):
        out[3 + 3 * r], out[4 + 3 * r], out[5 + 3 * r] = e[r, 2], e[r, 1], e[r, 0]
    return True


# -- reading ---------------------------------------------------------------------------------


class _Skeleton:
    """A described skeleton ID: its BVH skeleton, its performer, its last frame, the bone IDs
    of the last frame checked (bytes) and their rows."""

    def __init__(self, sid, name, skeleton):
        self.sid, self.name, self.skeleton = sid, name, skeleton
        self.perf, self.refused, self.done, self.f0 = None, False, None, None
        self.ids, self.rows = None, None


class Source(DatagramSource):
    """A NatNet 4.1 unicast client of Motive, one take at a time (the module's docstring).

    Parameters
    ----------
    host, port : str, int
        Motive's command port (UDP).
    rate : float, optional
        Motive's frame rate (``--rate``; default :data:`DEFAULT_RATE`): frame ``f`` counts at
        ``(f - f0) / rate``.
    header : None
        Not used: the skeleton comes from the data descriptions (ValueError when given).
    """

    scheme = "natnet"
    skeleton_from = "the server's data descriptions"
    DEFAULT_RATE = DEFAULT_RATE  # the module's

    async def connect(self):
        """Bind a socket of our own and start asking ``host:port`` for its descriptions
        (OSError when the host is unknown or no socket can be had); the server answers to
        this socket."""
        loop = asyncio.get_running_loop()
        family, *_, self.server_addr = (
            await loop.getaddrinfo(self.host, self.port, type=socket.SOCK_DGRAM)
        )[0]
        transport, proto = await loop.create_datagram_endpoint(
            DatagramReceiver, local_addr=("::" if family == socket.AF_INET6 else "0.0.0.0", 0),
            family=family)  # fmt: skip
        with contextlib.suppress(OSError):
            transport.get_extra_info("socket").setsockopt(
                socket.SOL_SOCKET, socket.SO_RCVBUF, 1 << 22
            )
        self.begin_take()
        self._asking = asyncio.ensure_future(self._ask(transport))
        return transport, proto

    async def _ask(self, transport) -> None:
        """``NAT_CONNECT`` and ``NAT_REQUEST_MODELDEF`` until described, then keep-alives."""
        while not transport.is_closing():
            if self.wanted:
                transport.sendto(CONNECT, self.server_addr)
                transport.sendto(HEADER.pack(NAT_REQUEST_MODELDEF, 0), self.server_addr)
            else:
                transport.sendto(HEADER.pack(NAT_KEEPALIVE, 0), self.server_addr)
            await asyncio.sleep(REQUEST_S if self.wanted else KEEPALIVE_S)

    def warm_up(self) -> None:
        super().warm_up()
        rows, v = np.arange(2), np.zeros((2, 7))  # two bones: unaligned, as a frame's are
        _checked_row(np.frombuffer(bytes(2 * BONE.itemsize), BONE)["v"], rows, 1.0, 1.0,
                     _EULER, v, np.empty(9))  # fmt: skip

    def begin_take(self) -> None:
        self.skeletons, self.wanted, self.server = {}, True, None
        self._big = limits.get("max_abs_value")  # the limits in force when a take starts

    def datagram(self, data: bytes, addr, arrival: float, performers) -> None:
        """One datagram: its header checked, then read as its message says."""
        self.n += 1
        try:
            if len(data) > MAX_DATAGRAM:
                raise Bad("oversize", f"{len(data)} bytes, more than {MAX_DATAGRAM}")
            _need(len(data) >= HEADER.size, "{} bytes, shorter than a NatNet header", len(data))
            mid, size = HEADER.unpack_from(data)
            _need(size == len(data) - 4, "message {} of {} bytes, but {} follow its header", mid,
                  size, len(data) - 4)  # fmt: skip
            if mid == NAT_FRAMEOFDATA:
                number, skeletons = parse_frame(data)
                for sid, bones in skeletons:
                    performers.frames += 1
                    self.frame(sid, bones, number, arrival, performers, addr)
            elif mid == NAT_MODELDEF:
                self.describe_skeletons(parse_descriptions(data))
            elif mid == NAT_SERVERINFO:
                self.server_info(data, self.where(addr))
            else:
                _need(mid in QUIET, f"message ID {mid} is not one a NatNet server sends")
        except Bad as e:
            performers.frames += 1
            performers.count_bad(None, e.kind, f"{self.where(addr)}: {e}")

    def where(self, addr) -> str:
        """The datagram being read, as messages name it."""
        return f"datagram {self.n} from {sender_name(addr)}"

    def server_info(self, data: bytes, where: str) -> None:
        """``NAT_SERVERINFO``: a NatNet version other than 4.1 ends the take."""
        _need(len(data) >= 4 + 264, f"NAT_SERVERINFO of {len(data)} bytes, not 268 or more")
        name = data[4:260].split(b"\0", 1)[0].decode("utf-8", "replace")[:64]
        app, nat = ".".join(map(str, data[260:264])), tuple(data[264:268])
        if nat[:2] != VERSION:
            raise TakeEnd(f"{where}: {name!r} {app} streams NatNet {'.'.join(map(str, nat))}; "
                          "fpdtw reads NatNet 4.1 only (Motive 3.1)")  # fmt: skip
        self.server = f"{name} {app}, NatNet {'.'.join(map(str, nat))}"

    def describe_skeletons(self, described) -> None:
        """The skeletons of a ``NAT_MODELDEF`` not known yet (a changed one keeps its first
        description for the take)."""
        for name, sid, bones in described:
            if sid not in self.skeletons:
                if len(self.skeletons) >= MAX_SKELETONS:
                    raise Bad("refused", f"more than {MAX_SKELETONS} skeletons described")
                try:
                    sk = NatNetSkeleton(bones, self.rate)
                except Bad as e:
                    raise Bad("natnet", f"skeleton {sid} ({name!r}): {e}") from None
                self.skeletons[sid] = _Skeleton(sid, name[:64] or f"skeleton {sid}", sk)
        self.wanted = not self.skeletons

    def frame(self, sid, bones, number, arrival, performers, addr) -> None:
        """One skeleton of a frame from ``addr``: checked, then aligned (or counted)."""
        s = self.skeletons.get(sid)
        try:
            row = self.check(s, sid, bones, number)
        except Bad as e:
            perf = None if s is None or s.refused else s.perf
            where = f"{self.where(addr)} (frame {number}, skeleton {sid})"
            return performers.count_bad(perf, e.kind, f"{where}: {e}")
        if s.perf is None:
            about = f"{len(s.rows)} bones, {self.server or 'server not identified'}"
            s.perf = performers.add(sid, s.name, s.skeleton.header, self.rate, about)
            if s.perf is None:
                s.refused = True
                return None
            s.f0 = number
        s.done = number
        performers.feed(s.perf, row, arrival, t=(number - s.f0) / self.rate)
        return None

    def check(self, s, sid, bones, number):
        """Skeleton ``sid``'s bones in frame ``number`` checked: its row
        (:meth:`NatNetSkeleton.row`, by :func:`_checked_row` when every value is surely
        fine); :class:`Bad` naming what is wrong."""
        if s is None:
            self.wanted = True  # ask for the descriptions again
            raise Bad("undescribed", f"skeleton {sid} is not in the server's data descriptions")
        if s.refused:
            raise Bad("refused", f"skeleton {sid} refused")
        if s.done is not None and number <= s.done:
            raise Bad("duplicate" if number == s.done else "order", "not after the last frame "
                      f"read ({s.done})")  # fmt: skip
        sk, ids = s.skeleton, bones["id"]
        if ids.tobytes() != s.ids:  # the bone IDs of the last frame checked need no check
            high, low = ids >> 16, ids & 0xFFFF
            rows = [sk.index.get(int(b), -1) for b in low]
            if (high != sid).any() or -1 in rows:
                b = int(ids[(high != sid) | (np.array(rows) < 0)][0])
                raise Bad("bone", f"bone ID {b >> 16}:{b & 0xFFFF} is not a bone of skeleton {sid}")
            if len(set(rows)) < len(rows):
                raise Bad("duplicate", "a bone twice")
            if len(rows) < len(sk.names):
                lacks = [n for r, n in enumerate(sk.names) if r not in set(rows)]
                raise Bad("missing", f"the frame lacks {', '.join(lacks[:4])}")
            s.ids, s.rows = ids.tobytes(), np.array(rows)
        v, out, big = np.empty((len(s.rows), 7)), np.empty(3 + 3 * len(s.rows)), self._big
        if _checked_row(bones["v"], s.rows, big, UNIT_TOLERANCE * 0.999, _EULER, v, out):
            return out
        v[s.rows] = bones["v"]
        if not np.abs(v).max() <= big:  # NaN, inf or too large: which, as before
            if not np.isfinite(v).all():
                bad = sk.names[int(np.flatnonzero(~np.isfinite(v).all(axis=1))[0])]
                raise Bad("finite", f"bone {bad} has NaN or inf")
            raise Bad("large", f"a value beyond {big:g} ({limits.env_name('max_abs_value')})")
        norms = np.sqrt(np.add.reduce(np.square(v[:, 3:]), axis=1))  # np.linalg.norm's
        k = int(np.abs(norms - 1.0).argmax())
        if abs(norms[k] - 1.0) > UNIT_TOLERANCE:
            raise Bad("rotation", f"bone {sk.names[k]}'s quaternion has norm {norms[k]:.6g}")
        return sk.row(v)


# -- the server, without hardware --------------------------------------------------------------

# Written from the layout on its own (its own bone table, every packet packed field by field),
# not as the reader run backwards, so that a misreading of one shows in the other.

#: The emulator's skeleton: Motive's default bones in ID order (1, 2, ...), each with its
#: parent and the rig joints that may play it (the first the rig has).
RIG_BONES = [("Hip", None, ("hip", "root", "Hips", "Pelvis")), ("Ab", "Hip", ("upperback",
             "Spine1")), ("Chest", "Ab", ("thorax", "Spine2", "Chest")), ("Neck", "Chest",
             ("lowerneck", "Neck")), ("Head", "Neck", ("head", "Head"))]  # fmt: skip
for _s, _c, _side in (("L", "l", "Left"), ("R", "r", "Right")):
    RIG_BONES += [(f"{_s}Shoulder", "Chest", (f"{_c}clavicle", f"{_side}Shoulder")),
                  (f"{_s}UArm", f"{_s}Shoulder", (f"{_c}humerus", f"{_side}Arm")),
                  (f"{_s}FArm", f"{_s}UArm", (f"{_c}radius", f"{_side}ForeArm")),
                  (f"{_s}Hand", f"{_s}FArm", (f"{_c}wrist", f"{_side}Hand"))]  # fmt: skip
for _s, _c, _side in (("L", "l", "Left"), ("R", "r", "Right")):
    RIG_BONES += [(f"{_s}Thigh", "Hip", (f"{_c}femur", f"{_side}UpLeg")),
                  (f"{_s}Shin", f"{_s}Thigh", (f"{_c}tibia", f"{_side}Leg")),
                  (f"{_s}Foot", f"{_s}Shin", (f"{_c}foot", f"{_side}Foot")),
                  (f"{_s}Toe", f"{_s}Foot", (f"{_c}toes", f"{_side}ToeBase"))]  # fmt: skip


def natnet_bones(motion) -> tuple:
    """A motion as Motive streams a skeleton in local coordinates: ``(rate, offsets (B, 3),
    local positions (F, B, 3), local quaternions qx qy qz qw (F, B, 4))``, bones as
    :data:`RIG_BONES`.

    A bone's rotation is its rig joint's global one relative to the rig's rest pose, taken
    relative to its parent bone's; its offset is the two joints' distance at rest. A bone the
    rig lacks is where its parent is, turned as it. ValueError without hips."""
    sk, names = motion.skeleton, list(motion.skeleton.joint_names)
    joint = {}
    for b, parent, candidates in RIG_BONES:
        hit = resolve_joint_map(names, {b: candidates}).get(b)
        joint[b] = names.index(hit) if hit is not None else joint.get(parent)
    if joint["Hip"] is None:
        raise ValueError(f"no hips among {', '.join(names[:8])}...")
    g0 = rest_rotations(motion)
    p0 = np.zeros((sk.n_joints, 3))  # joint positions at rest
    for j in range(sk.n_joints):
        a = sk.parents[j]
        p0[j] = sk.offsets[j] if a < 0 else p0[a] + quat_rotate(g0[a], sk.offsets[j])
    pos, rot = motion.forward_kinematics()
    turn = quat_mul(rot, quat_conj(g0)[None])  # each joint's turn from its rest pose
    B, F = len(RIG_BONES), motion.n_frames
    off, lp, lq = np.zeros((B, 3)), np.zeros((F, B, 3)), np.zeros((F, B, 4))
    for k, (b, parent, _) in enumerate(RIG_BONES):
        j = joint[b]
        if parent is None:
            lp[:, k], lq[:, k] = pos[:, j], turn[:, j]
            continue
        a = joint[parent]
        off[k] = p0[j] - p0[a]
        lp[:, k], lq[:, k] = off[k], quat_mul(quat_conj(turn[:, a]), turn[:, j])
    return motion.fps, off, lp, lq[..., [1, 2, 3, 0]]


def natnet_packets(motions, *, first_frame: int = 5000) -> tuple:
    """What the emulator sends: ``(rate, NAT_SERVERINFO, NAT_MODELDEF, [NAT_FRAMEOFDATA of
    frame k])``; take ``i`` is skeleton ``i + 1``, named after the take; frame ``k`` has
    number ``first_frame + k`` and holds every take that lasts that long."""
    takes = [natnet_bones(m) for m in motions]
    if len({r for r, *_ in takes}) > 1:
        raise ValueError(f"takes at {sorted({r for r, *_ in takes})} Hz: play them at one --rate")
    info = b"Motive".ljust(256, b"\0") + bytes([3, 1, 0, 0, 4, 1, 0, 0])
    info += struct.pack("<QH?4B", 10_000_000, 1511, False, 0, 0, 0, 0)
    descriptions = b""
    for i, (m, (_, off, _, _)) in enumerate(zip(motions, takes, strict=True)):
        d = (re.sub(r"\s", "_", getattr(m, "name", "") or f"Skeleton{i + 1}")[:60]).encode() + b"\0"
        d += struct.pack("<ii", i + 1, len(RIG_BONES))
        for k, (b, parent, _) in enumerate(RIG_BONES):
            up = 0 if parent is None else [r[0] for r in RIG_BONES].index(parent) + 1
            d += b.encode() + b"\0" + struct.pack("<ii", k + 1, up)
            d += struct.pack("<fff", *off[k]) + struct.pack("<i", 0)  # no markers
        descriptions += struct.pack("<ii", 2, len(d)) + d
    modeldef = struct.pack("<i", len(motions)) + descriptions
    frames = []
    for k in range(max(len(lp) for _, _, lp, _ in takes)):
        sk = b""
        live = [(i, t) for i, t in enumerate(takes) if k < len(t[2])]
        for i, (_, _, lp, lq) in live:
            sk += struct.pack("<ii", i + 1, len(RIG_BONES))
            for b in range(len(RIG_BONES)):
                sk += struct.pack("<i", ((i + 1) << 16) | (b + 1)) + struct.pack("<3f", *lp[k, b])
                sk += struct.pack("<4f", *lq[k, b]) + struct.pack("<fh", 0.0, 1)
        body = struct.pack("<i", first_frame + k) + struct.pack("<6i", 0, 0, 0, 0, 0, 0)
        body += struct.pack("<ii", len(live), len(sk)) + sk + struct.pack("<8i", *[0] * 8)
        body += struct.pack("<IId", 0, 0, k / takes[0][0]) + struct.pack("<3Q2Ih", 0, 0, 0, 0,
                                                                           0, 0)  # fmt: skip
        frames.append(struct.pack("<HH", 7, len(body)) + body)
    return (takes[0][0], struct.pack("<HH", 1, len(info)) + info,
            struct.pack("<HH", 5, len(modeldef)) + modeldef, frames)  # fmt: skip


def play_as_natnet(motions, to: str, *, fast=False, out=None, wait_s: float = 60.0) -> int:
    """Serve ``motions`` as Motive's NatNet 4.1 unicast stream on ``to`` (``HOST:PORT``, the
    command port a client's ``natnet://`` names): wait up to ``wait_s`` s for a client's
    ``NAT_CONNECT`` and ``NAT_REQUEST_MODELDEF``, answer them, then stream frame ``k`` of every
    take to it at ``k / rate`` (``fast``: one a millisecond), answering requests meanwhile.
    Return the frames sent; TimeoutError when no client asked."""
    host, port = parse_address(to)
    rate, info, modeldef, frames = natnet_packets(motions)
    family = socket.AF_INET6 if ":" in host else socket.AF_INET
    with socket.socket(family, socket.SOCK_DGRAM) as sock:
        sock.bind((host, port))
        client, t0, sent, deadline = None, None, 0, time.monotonic() + wait_s
        while sent < len(frames):
            sock.settimeout(max(deadline - time.monotonic(), 1e-3) if client is None else 0.0)
            try:  # a request: NAT_CONNECT (0) or NAT_REQUEST_MODELDEF (4), answered
                data, addr = sock.recvfrom(65536)
                kind = int.from_bytes(data[:2], "little")
                if kind in (0, 4):
                    sock.sendto(info if kind == 0 else modeldef, addr)
                client = addr if kind == 4 and client is None else client
                continue
            except BlockingIOError:
                pass
            except TimeoutError:
                raise TimeoutError(f"no NatNet client asked {to} within {wait_s:g} s") from None
            t0 = time.perf_counter() if t0 is None else t0
            if (wait := t0 + (sent / 1000 if fast else sent / rate) - time.perf_counter()) > 0:
                time.sleep(wait)
            sock.sendto(frames[sent], client)
            sent += 1
    if out is not None:
        print(f"sent {sent} frames ({len(motions)} skeletons) to {sender_name(client)}", file=out)
    return sent


__all__ = ["DEFAULT_PORT", "DEFAULT_RATE", "JOINT_MAPS", "RIG_BONES", "VERSION", "Bad",
           "NatNetSkeleton", "Source", "motive_to_fpdtw", "natnet_bones", "natnet_packets",
           "parse_descriptions", "parse_frame", "play_as_natnet"]  # fmt: skip
