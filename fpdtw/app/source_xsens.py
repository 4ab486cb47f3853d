"""``xsens://HOST:PORT``: Xsens MVN Analyze/Animate's network streamer, both ways.

MVN sends UDP datagrams to a receiver, port 9763 by default, so fpdtw LISTENS on
``HOST:PORT`` and only reads. What follows is from Xsens' "MVN real-time network streaming
protocol specification" (revision N, September 2018, MVN 2019's header; "the spec") unless
another source is named.

**Datagram** (the spec, 2.4): a 24-byte header, then the items; every number big-endian
("network byte order"), floats IEEE 32-bit. The header: 6 ASCII bytes ``MXTP`` and a
two-digit message type (``MXTP02``); the sample counter (uint32, one more for each sample
sent; the spec warns it is not a time code, the sender may skip frames); the datagram
counter (one byte: bits 0-6 the datagram's index within its sample, bit 7 set on the last
datagram of the sample, so ``0x80`` for a sample in one datagram); the number of items
(uint8, in this datagram); the time code (uint32, milliseconds of MVN's clock, which "starts
running at the start of a recording"); the character ID (uint8; 0 with one character, others
usually incremental); the numbers of body segments (always 23), props (0-4) and finger
tracking segments (0 or 40) (one byte each, "from MVN 2019"); two reserved bytes; the payload
size (uint16: the datagram without its header, "to skip [an unknown datagram's] contents").

**Type 02** (pose data, quaternion; the spec, 2.5.3): per item 32 bytes, the segment ID
(int32), its position x, y, z and its orientation quaternion ``q1 q2 q3 q4`` = ``re i j k``
(w first), both GLOBAL ("absolute position and orientation", 2.4.1.1), in MVN's world: Z up,
right-handed. Items come in the order body segments, props, left then right hand fingers.
Segment ID = index + 1 (the spec, 3.1); the 23 body segments by index: Pelvis, L5, L3, T12,
T8, Neck, Head, Right Shoulder, Upper Arm, Forearm, Hand, the same on the left, Right Upper
Leg, Lower Leg, Foot, Toe, the same on the left (:data:`SEGMENTS`). The hierarchy
(:data:`PARENTS`) is the one of the joint-angle pairs Xsens' own ``xsens_mvn_ros2`` reads
from type 20 (T8 the parent of Neck and both shoulders, Pelvis of L5 and both upper legs);
its ``datagram.cpp`` reads the header field by field as above and its stream client names
body segments by IDs 1-23. The rest pose is the one the spec's type 13 describes: an ideal
T-pose "where all segment orientations are set to identity". **Units**: the spec says
positions are in cm; a third-party Unity reader of ``MXTP02`` notes the stream has been seen
in metres, and ``xsens_mvn_ros2`` publishes them unscaled as metres. fpdtw keeps positions in
the unit they come in: the alignment rescales positions by body size.

**Axes.** MVN's Z up, right-handed, with X forward and Y to the left (the Unity reader's
reading; the spec names only "Z-up, right-handed"). fpdtw's Y up, right-handed, Z forward:
:func:`mvn_to_fpdtw` takes ``(x, y, z)`` to ``(y, z, x)``, a rotation (a cyclic permutation),
so a quaternion's vector part is permuted the same way: ``(w, x, y, z)`` to ``(w, y, z, x)``.

**What fpdtw makes of it.** A performer per character ID (at most :data:`MAX_CHARACTERS`
IDs tracked, ``--max-clients`` performers aligned). A sample is the datagrams of one sample
counter of one character, complete when the one with bit 7 and every index before it have
come (in any order). Its skeleton is the 23 body segments of its first complete sample: each
segment's offset is its position minus its parent's, in the parent's own axes (its global
orientation undone), identity rotations the rest pose; each later sample's local rotations
are ``parent^-1 child`` of the global ones, the pelvis' position the root's. Sample ``s``
counts at ``(s - s0) / rate`` (``--rate``, the stream's rate), so a lost sample is a gap;
the time code is not used (the spec ties it to a recording). Datagrams of other types (01,
03, 05, 12, 13, 20-25, ...) are skipped by their payload size and counted. Props and finger
segments (IDs 24 up to the header's counts) are valid and not read.

:func:`play_as_xsens` is the other side without hardware (``fpdtw stream --as xsens``): an
encoder of the spec written apart from the reader (its own segment table, header layout and
axis conversion), each take a character, over one UDP socket.
"""

from __future__ import annotations

import struct
import time

import numba
import numpy as np

from fpdtw import limits
from fpdtw.app.sources import DatagramSource, bvh_header, send_paced, sender_name
from fpdtw.motion.joints import PAPER_JOINTS, resolve_joint_map
from fpdtw.motion.rig import rest_rotations
from fpdtw.motion.rotations import (
    euler_into,
    euler_kernel,
    quat_conj,
    quat_mul,
    quat_normalize,
    quat_rotate,
    quat_to_euler,
)

#: MVN's network streamer's default port (the spec, 2.3: "9=X, M=6, E=3").
DEFAULT_PORT = 9763
#: The default stream rate (``--rate``): the period a gap is measured in.
DEFAULT_RATE = 60.0
#: Bytes a datagram may have (a whole type-02 sample of 23 segments, 4 props and 40 finger
#: segments is 2168 bytes; MVN splits a sample at the MTU, about 1500).
MAX_DATAGRAM = 16384
#: Character IDs tracked in one take (each has a sample in the making).
MAX_CHARACTERS = 64
#: Datagrams one sample may be split into (the index is 7 bits; MVN needs two or three).
MAX_PARTS = 16
#: A quaternion whose norm is further than this from 1 is not a rotation (the spec: "always
#: normalized"; float32 on the wire).
UNIT_TOLERANCE = 1e-3

#: The header (the spec, 2.4.1): ID string, sample counter, datagram counter, items, time
#: code, character ID, body segments, props, finger segments, reserved, payload size.
HEADER = struct.Struct(">6sIBBIBBBBHH")
#: One item of type 02: segment ID, position x y z, quaternion re i j k.
ITEM = struct.Struct(">i7f")
#: The same, for the items of a datagram at once.
_ITEMS = np.dtype([("sid", ">i4"), ("v", ">f4", 7)])
assert HEADER.size == 24 and ITEM.size == 32 == _ITEMS.itemsize

#: The 23 body segments, ID 1 first (the spec, 3.1, Table 1).
SEGMENTS = ("Pelvis", "L5", "L3", "T12", "T8", "Neck", "Head",
            "RightShoulder", "RightUpperArm", "RightForearm", "RightHand",
            "LeftShoulder", "LeftUpperArm", "LeftForearm", "LeftHand",
            "RightUpperLeg", "RightLowerLeg", "RightFoot", "RightToe",
            "LeftUpperLeg", "LeftLowerLeg", "LeftFoot", "LeftToe")  # fmt: skip
#: Each body segment's parent.
PARENTS = {"Pelvis": None, "L5": "Pelvis", "L3": "L5", "T12": "L3", "T8": "T12", "Neck": "T8",
           "Head": "Neck"}  # fmt: skip
for _s in ("Right", "Left"):
    PARENTS.update({f"{_s}Shoulder": "T8", f"{_s}UpperArm": f"{_s}Shoulder",
                    f"{_s}Forearm": f"{_s}UpperArm", f"{_s}Hand": f"{_s}Forearm",
                    f"{_s}UpperLeg": "Pelvis", f"{_s}LowerLeg": f"{_s}UpperLeg",
                    f"{_s}Foot": f"{_s}LowerLeg", f"{_s}Toe": f"{_s}Foot"})  # fmt: skip
_PARENT_INDEX = np.array([-1 if PARENTS[s] is None else SEGMENTS.index(PARENTS[s])
                          for s in SEGMENTS])  # fmt: skip

_FULL = {"center_hip": "Pelvis", "middle_chest": "L3", "upper_chest": "T8", "head": "Head"}
for _s, _c in (("Left", "left"), ("Right", "right")):
    _FULL.update({f"{_c}_hip": f"{_s}UpperLeg", f"{_c}_knee": f"{_s}LowerLeg",
                  f"{_c}_ankle": f"{_s}Foot", f"{_c}_shoulder": f"{_s}UpperArm",
                  f"{_c}_elbow": f"{_s}Forearm", f"{_c}_wrist": f"{_s}Hand"})  # fmt: skip
#: The built-in joint maps of an MVN skeleton (our joint -> segment), after ``--joint-map``'s:
#: all 16 joints; the paper's 8.
JOINT_MAPS = (_FULL, {j: _FULL[j] for j in PAPER_JOINTS})

_ORDER = "XYZ"  # the built skeleton's rotation order, written Zrotation Yrotation Xrotation
# ``quat_mul(quat_conj(a), b)`` in ``x y z w`` order: the sum over j of ``a_j * b[_TERM[j]] *
# _SIGN[j]``, added in the same order (each term's sign is exact), so the same bits.
_TERM = np.array([[1, 2, 3, 0], [0, 3, 2, 1], [3, 0, 1, 2], [2, 1, 0, 3]])
_SIGN = np.array([[1.0, 1, 1, 1], [-1, 1, -1, 1], [-1, -1, 1, 1], [1, -1, -1, 1]])
_TO_FPDTW = np.array([1, 2, 0]), np.array([0, 2, 3, 1])  # the columns mvn_to_fpdtw takes


def mvn_to_fpdtw(p, q_wxyz):
    """MVN's position (..., 3) and quaternion ``w x y z`` (..., 4) in fpdtw's axes:
    ``(y, z, x)`` and ``(w, y, z, x)``.

    MVN's X (forward), Y (left), Z (up) become fpdtw's Z, X, Y: the rotation ``P`` with
    ``P e_x = e_z``, ``P e_y = e_x``, ``P e_z = e_y`` (a cyclic permutation, determinant 1).
    A rotation ``R`` becomes ``P R P^T``, about ``P a`` by the same angle: its quaternion's
    vector part is permuted as a position is."""
    p = np.asarray(p, dtype=float)
    q = np.asarray(q_wxyz, dtype=float)
    return p[..., _TO_FPDTW[0]], q[..., _TO_FPDTW[1]]


class MvnSkeleton:
    """A character's skeleton, from its first complete sample.

    Parameters
    ----------
    p, q : ndarray
        The 23 body segments' positions (23, 3) and quaternions (23, 4), fpdtw's axes.
    rate : float
        The stream's rate (the header's ``Frame Time``).

    Attributes
    ----------
    header : list of str
        Its BVH header: joints named as :data:`SEGMENTS`, depth first from Pelvis.
    order : list of int
        The segments' indices in the header's order.
    """

    def __init__(self, p, q, rate: float):
        a = np.maximum(_PARENT_INDEX, 0)  # the root's offset is not written
        offsets = quat_rotate(quat_conj(q[a]), p - p[a])
        self.header, self.order = bvh_header(SEGMENTS, _PARENT_INDEX, offsets, rate)
        self._terms = 4 * np.array(self.order)[:, None, None] + _TERM  # flat indices of q
        self._parents = np.maximum(_PARENT_INDEX[self.order], 0)

    def row(self, p, q) -> np.ndarray:
        """The BVH channel values (n_channels,) float64 of a sample: (23, 3) positions, (23, 4)
        global quaternions (fpdtw's axes).

        Each local rotation ``parent^-1 child`` (the root's global one), in the header's
        order, as ``quat_to_euler(local, "XYZ")`` (scipy's extrinsic ``xyz``) gives it, the
        channels Z Y X. One compiled call (:func:`_row`); :meth:`row_numpy` is its twin."""
        out = np.empty(3 + 3 * len(self._parents))
        _row(np.ascontiguousarray(p, dtype=np.float64), np.ascontiguousarray(q, dtype=np.float64),
             self._parents, self._terms, _SIGN, _EULER, out)  # fmt: skip
        return out

    def row_numpy(self, p, q) -> np.ndarray:
        """:meth:`row` in NumPy and :func:`~fpdtw.motion.rotations.quat_to_euler` (equal
        bit for bit, tested)."""
        q = quat_normalize(q)
        t = q[self._parents][:, :, None] * (q.take(self._terms) * _SIGN)
        local = ((t[:, 0] + t[:, 1]) + t[:, 2]) + t[:, 3]  # x y z w
        local[0] = q.take(_TERM[0])  # order[0] is the root
        e = quat_to_euler(local, _ORDER, scalar_first=False)[:, ::-1]
        return np.concatenate([p[0], e.ravel()])


#: Segment IDs 1..23 in order: a sample sent whole in one datagram.
_ALL_IDS = list(range(1, 24))


@numba.njit(cache=True)
def _surely_fine(sid, v, top, big, tol):  # pragma: no cover - compiled
    """Whether every item (IDs ``sid`` (n,), values ``v`` (n, 7)) is surely fine: its ID in
    ``1..top``, no value beyond ``big`` (NaN, inf: not), its quaternion's squared norm
    within ``tol`` of 1."""
    for r in range(sid.shape[0]):
        if not 1 <= sid[r] <= top:
            return False
        for c in range(7):
            if not abs(v[r, c]) <= big:
                return False
        s = ((v[r, 3] * v[r, 3] + v[r, 4] * v[r, 4]) + v[r, 5] * v[r, 5]) + v[r, 6] * v[r, 6]
        if not abs(s - 1.0) < tol:
            return False
    return True


#: :func:`fpdtw.motion.rotations.euler_kernel` of the built skeleton's order, ``x y z w``.
_EULER = euler_kernel(_ORDER, scalar_first=False)


@numba.njit(cache=True)
def _row(p, q, parents, terms, sign, euler, out):  # pragma: no cover - compiled
    """:meth:`MvnSkeleton.row` into ``out``, its operations in its order: each quaternion
    normalised as ``np.linalg.norm`` sums its squares (left to right), each
    local rotation's four terms added left to right, then ``quat_to_euler`` of each."""
    n = q.shape[0]
    u = np.empty((n, 4))
    for r in range(n):
        s = ((q[r, 0] * q[r, 0] + q[r, 1] * q[r, 1]) + q[r, 2] * q[r, 2]) + q[r, 3] * q[r, 3]
        norm = np.sqrt(s)
        for c in range(4):
            u[r, c] = q[r, c] / norm
    flat = u.ravel()
    local = np.empty((parents.shape[0], 4))
    for r in range(parents.shape[0]):
        for c in range(4):
            acc = u[parents[r], 0] * (flat[terms[r, 0, c]] * sign[0, c])
            for m in range(1, 4):
                acc = acc + u[parents[r], m] * (flat[terms[r, m, c]] * sign[m, c])
            local[r, c] = acc
    for c in range(4):  # order[0] is the root: its global rotation, x y z w
        local[0, c] = u[0, (c + 1) % 4]
    e = np.empty((parents.shape[0], 3))
    euler_into(local, euler, e)
    out[0], out[1], out[2] = p[0, 0], p[0, 1], p[0, 2]
    for r in range(parents.shape[0]):
        out[3 + 3 * r], out[4 + 3 * r], out[5 + 3 * r] = e[r, 2], e[r, 1], e[r, 0]


# -- reading ---------------------------------------------------------------------------------


class _Character:
    """One character ID: its sample in the making and its performer."""

    def __init__(self, cid, addr):
        self.cid = cid
        self.addr = sender_name(addr)
        self.perf = self.skeleton = None
        self.refused = False
        self.sc = None  # the sample counter in the making
        self.parts = {}  # its datagrams: index -> items {segment ID: values}
        self.total = None  # its datagram count (known from the one with bit 7)
        self.problem = None
        self.whole = None  # the sample's (23, 7) values when one datagram held them in order
        self.done = None  # the last sample counter finished
        self.s0 = None  # the first sample counter aligned

    def spoil(self, kind, what):
        if self.problem is None:
            self.problem = (kind, what)


class Source(DatagramSource):
    """Listens for MVN's network streamer, one take at a time (see the module's docstring).

    Parameters
    ----------
    host, port : str, int
        Where to listen (UDP).
    rate : float, optional
        The stream's rate (``--rate``; default :data:`DEFAULT_RATE`): sample ``s`` counts at
        ``(s - s0) / rate``.
    header : None
        Not used: the skeleton comes from the stream (ValueError when given).
    """

    scheme = "xsens"
    skeleton_from = "the segments"
    DEFAULT_RATE = DEFAULT_RATE  # the module's

    def __init__(self, host: str, port: int, **kw):
        super().__init__(host, port, **kw)
        self.begin_take()

    def warm_up(self) -> None:
        super().warm_up()
        p, q = np.zeros((len(SEGMENTS), 3)), np.tile([1.0, 0.0, 0.0, 0.0], (len(SEGMENTS), 1))
        MvnSkeleton(p, q, self.rate).row(p, q)
        _surely_fine(np.ones(1, np.int64), np.zeros((1, 7)), 1, float(self._big), 1.0)

    def begin_take(self) -> None:
        self.characters = {}
        self._big = limits.get("max_abs_value")  # the limits in force when a take starts

    def end_take(self, performers) -> None:
        for c in self.characters.values():
            if c.sc is not None:
                self.finish(c, performers, None, "at the end of the take")

    def _refuse(self, performers, perf, kind, what):
        performers.frames += 1
        performers.count_bad(perf, kind, what)

    def datagram(self, data: bytes, addr, arrival: float, performers) -> None:
        """One datagram: its header checked, its items added to its character's sample."""
        self.n += 1
        n = self.n
        sender = sender_name(addr)
        where = f"datagram {n} from {sender}"
        if len(data) > MAX_DATAGRAM:
            return self._refuse(performers, None, "oversize", f"{where}: {len(data)} bytes, "
                                f"more than {MAX_DATAGRAM}")  # fmt: skip
        if len(data) < HEADER.size or data[:4] != b"MXTP" or not data[4:6].isdigit():
            return self._refuse(performers, None, "mxtp", f"{where}: {len(data)} bytes "
                                f"starting {data[:6]!r}, not an MXTP header")  # fmt: skip
        (ident, sc, dc, items, _tc, cid, _body, props, fingers, _res,
         size) = HEADER.unpack_from(data)  # fmt: skip
        kind = ident[4:].decode("ascii")
        if size != len(data) - HEADER.size:
            rest = len(data) - HEADER.size
            return self._refuse(performers, None, "mxtp", f"{where}: payload size {size}, "
                                f"but {rest} bytes follow the header")  # fmt: skip
        if kind != "02":
            return self._refuse(performers, None, "skipped", f"{where}: MXTP{kind} (only "
                                "type 02 is read)")  # fmt: skip
        if items * ITEM.size != size:
            return self._refuse(performers, None, "mxtp", f"{where}: {items} items of "
                                f"{ITEM.size} bytes in a payload of {size}")  # fmt: skip
        c = self.characters.get(cid)
        if c is None:
            if len(self.characters) >= MAX_CHARACTERS:
                return self._refuse(performers, None, "refused", f"{where}: more than "
                                    f"{MAX_CHARACTERS} character IDs")  # fmt: skip
            c = self.characters[cid] = _Character(cid, addr)
        where = f"{where} (character {cid}, sample {sc})"
        index, last = dc & 0x7F, bool(dc & 0x80)
        if index >= MAX_PARTS:
            return self._refuse(performers, c.perf, "mxtp", f"{where}: datagram index {index}"
                                f" of a sample, more than {MAX_PARTS}")  # fmt: skip
        if c.sc is not None and sc != c.sc:
            if sc > c.sc:
                self.finish(c, performers, arrival, where)  # a newer sample: the last is over
            else:
                return self._refuse(performers, c.perf, "order", f"{where}: older than the "
                                    f"sample in the making ({c.sc})")  # fmt: skip
        if c.sc is None:
            if c.done is not None and sc <= c.done:
                kind = "duplicate" if sc == c.done else "order"
                return self._refuse(performers, c.perf, kind, f"{where}: not after the last "
                                    f"sample read ({c.done})")  # fmt: skip
            c.sc, c.parts, c.total, c.problem, c.whole = sc, {}, None, None, None
        if index in c.parts:
            return self._refuse(performers, c.perf, "duplicate", f"{where}: datagram "
                                f"{index} of the sample twice")  # fmt: skip
        c.parts[index] = self.items(c, data, items, props, fingers, where)
        if last:
            if c.total is not None:
                c.spoil("mxtp", f"{where}: a second datagram marked last in the sample")
            c.total = index + 1
        if c.total is not None and any(i >= c.total for i in c.parts):
            c.spoil("mxtp", f"{where}: a datagram after the one marked last ({c.total - 1})")
        if c.total is not None and all(i in c.parts for i in range(c.total)):
            self.finish(c, performers, arrival, where)
        return None

    def items(self, c, data, count, props, fingers, where) -> dict:
        """The body segments of one datagram, checked (a problem spoils the sample).

        All items are checked at once; unless each is surely fine, one by one, the first
        problem found being the sample's."""
        a = np.frombuffer(data, _ITEMS, count, HEADER.size)
        sid, values = a["sid"].astype(np.int64), a["v"].astype(float)
        ids = sid.tolist()
        top = len(SEGMENTS) + 1 + props + fingers  # props' and fingers' IDs: 24 up, not read
        big = self._big
        # every item surely fine (props' and fingers' too: else one by one, below)
        if count and _surely_fine(sid, values, top, big, 1.99 * UNIT_TOLERANCE):
            n = len(SEGMENTS)
            if ids == _ALL_IDS and not c.parts:
                c.whole = values
            sids = [sid for sid in ids if sid <= n]
            rows = values if len(sids) == count else values[[sid <= n for sid in ids]]
            if len(set(sids)) == len(sids) and all(
                part.keys().isdisjoint(sids) for part in c.parts.values()
            ):
                return dict(zip(sids, rows))
        out = {}
        for sid, v in zip(ids, values):
            if 1 <= sid <= len(SEGMENTS):
                name = SEGMENTS[sid - 1]
                if not np.isfinite(v).all():
                    c.spoil("finite", f"{where}: segment {sid} ({name}) has NaN or inf")
                elif np.abs(v).max() > big:
                    c.spoil("large", f"{where}: segment {sid} ({name}) has a value beyond "
                            f"{big:g} ({limits.env_name('max_abs_value')})")  # fmt: skip
                elif abs((norm := float(np.linalg.norm(v[3:]))) - 1.0) > UNIT_TOLERANCE:
                    c.spoil("rotation", f"{where}: segment {sid} ({name})'s quaternion has "
                            f"norm {norm:.6g}")  # fmt: skip
                elif sid in out or any(sid in part for part in c.parts.values()):
                    c.spoil("duplicate", f"{where}: segment {sid} ({name}) twice in a sample")
                else:
                    out[sid] = v
            elif not len(SEGMENTS) < sid <= top:
                c.spoil("bone", f"{where}: segment ID {sid} is neither a body segment (1-23) "
                        f"nor one of the header's {props} props and {fingers} finger "
                        "segments")  # fmt: skip
        return out

    def finish(self, c, performers, arrival, where) -> None:
        """The end of a character's sample: checked, then aligned (or counted)."""
        sc, parts, total, problem, whole = c.sc, c.parts, c.total, c.problem, c.whole
        c.sc, c.parts, c.total, c.problem, c.whole = None, {}, None, None, None
        performers.frames += 1
        if c.done is None or sc > c.done:
            c.done = sc
        if c.refused:
            return performers.count_bad(None, "refused", f"{where}: character {c.cid} refused")
        if problem is not None:
            return performers.count_bad(c.perf, *problem)
        if total is None or len(parts) < total:
            lost = (
                "its last datagram"
                if total is None
                else "datagram(s) " + ", ".join(str(i) for i in range(total) if i not in parts)
            )
            return performers.count_bad(c.perf, "missing", f"{where}: sample {sc} of "
                                        f"character {c.cid} lacks {lost} (lost)")  # fmt: skip
        if whole is not None and len(parts) == 1:  # one datagram, segments 1..23 in order
            v = whole
        else:
            body = {sid: v for part in parts.values() for sid, v in part.items()}
            if len(body) < len(SEGMENTS):
                lacks = [SEGMENTS[i - 1] for i in range(1, len(SEGMENTS) + 1) if i not in body]
                what = f"{where}: sample {sc} of character {c.cid} lacks {', '.join(lacks[:4])}"
                return performers.count_bad(c.perf, "missing", what)
            v = np.array([body[i] for i in range(1, len(SEGMENTS) + 1)])
        p, q = mvn_to_fpdtw(v[:, :3], v[:, 3:])
        if c.perf is None:
            c.skeleton = MvnSkeleton(p, quat_normalize(q), self.rate)
            about = f"{len(SEGMENTS)} segments, from {c.addr}"
            c.perf = performers.add(c.cid, f"character {c.cid}", c.skeleton.header, self.rate,
                                    about)  # fmt: skip
            if c.perf is None:
                c.refused = True
                return None
            c.s0 = sc
        performers.feed(c.perf, c.skeleton.row(p, q), arrival if arrival is not None
                        else time.perf_counter(), t=(sc - c.s0) / self.rate)  # fmt: skip
        return None


# -- the streamer, without hardware ------------------------------------------------------------

# The encoder below is written from the spec on its own (its own table, header layout and axis
# conversion), not as the reader run backwards, so that a misreading of one shows in the other.

#: The emulator: MVN segment ID -> (its parent's ID, names of the rig joint playing it).
RIG_SEGMENTS = {
    1: (0, ("hip", "root", "Hips", "Pelvis")),
    2: (1, ("lowerback", "Spine")),
    3: (2, ("upperback", "Spine1")),
    4: (3, ()),  # T12: a rig seldom has it; it moves with L3
    5: (4, ("thorax", "Spine2", "Chest")),
    6: (5, ("lowerneck", "Neck")),
    7: (6, ("head", "Head")),
}
for _first, _c, _s in ((8, "r", "Right"), (12, "l", "Left")):
    RIG_SEGMENTS.update({
        _first: (5, (f"{_c}clavicle", f"{_s}Shoulder")),
        _first + 1: (_first, (f"{_c}humerus", f"{_s}Arm")),
        _first + 2: (_first + 1, (f"{_c}radius", f"{_s}ForeArm")),
        _first + 3: (_first + 2, (f"{_c}wrist", f"{_s}Hand")),
    })  # fmt: skip
for _first, _c, _s in ((16, "r", "Right"), (20, "l", "Left")):
    RIG_SEGMENTS.update({
        _first: (1, (f"{_c}femur", f"{_s}UpLeg")),
        _first + 1: (_first, (f"{_c}tibia", f"{_s}Leg")),
        _first + 2: (_first + 1, (f"{_c}foot", f"{_s}Foot")),
        _first + 3: (_first + 2, (f"{_c}toes", f"{_s}ToeBase")),
    })  # fmt: skip


def fpdtw_to_mvn(p, q_wxyz):
    """fpdtw's position (..., 3) and quaternion ``w x y z`` (..., 4) in MVN's Z-up axes:
    fpdtw's X (left), Y (up), Z (forward) are MVN's Y, Z, X."""
    p = np.asarray(p, dtype=float)
    q = np.asarray(q_wxyz, dtype=float)
    out_p = np.stack([p[..., 2], p[..., 0], p[..., 1]], axis=-1)
    out_q = np.stack([q[..., 0], q[..., 3], q[..., 1], q[..., 2]], axis=-1)
    return out_p, out_q


def xsens_samples(motion) -> tuple:
    """A motion as MVN streams a character: ``(rate, ids, p, q)``: segment IDs 1-23, global
    positions (F, 23, 3) and orientations ``re i j k`` (F, 23, 4) in MVN's axes.

    Each segment is the rig joint :data:`RIG_SEGMENTS` names (the first the rig has), its
    global orientation taken relative to the rig's rest pose (MVN's identity pose); a segment
    the rig lacks is where its parent segment is, turned as it is. ValueError without hips."""
    sk = motion.skeleton
    found = {}
    for sid, (_, names) in RIG_SEGMENTS.items():
        if names:
            hit = resolve_joint_map(sk.joint_names, {sid: names}).get(sid)
            if hit is not None:
                found[sid] = list(sk.joint_names).index(hit)
    if 1 not in found:
        raise ValueError(f"no hips among {', '.join(sk.joint_names[:8])}...")
    pos, rot = motion.forward_kinematics()
    rot = quat_mul(rot, quat_conj(rest_rotations(motion))[None])
    ids = sorted(RIG_SEGMENTS)
    P = np.empty((motion.n_frames, len(ids), 3))
    Q = np.empty((motion.n_frames, len(ids), 4))
    for k, sid in enumerate(ids):  # parents come first
        if sid in found:
            P[:, k], Q[:, k] = pos[:, found[sid]], rot[:, found[sid]]
        else:
            a = RIG_SEGMENTS[sid][0] - 1
            P[:, k], Q[:, k] = P[:, a], Q[:, a]
    P, Q = fpdtw_to_mvn(P, Q)
    return motion.fps, ids, P, Q


def mxtp02(sample: int, time_ms: int, character: int, ids, p, q, *, parts: int = 1) -> list:
    """One sample as ``MXTP02`` datagrams (bytes), its items split into ``parts`` datagrams
    (indices 0, 1, ..., the last with bit 7 set)."""
    chunks = np.array_split(np.arange(len(ids)), parts)
    out = []
    for i, chunk in enumerate(chunks):
        payload = b"".join(
            struct.pack(">i", int(ids[k])) + struct.pack(">3f", *p[k]) + struct.pack(">4f", *q[k])
            for k in chunk
        )
        counter = i | (0x80 if i == len(chunks) - 1 else 0)
        head = (b"MXTP02" + struct.pack(">I", sample & 0xFFFFFFFF)
                + bytes([counter, len(chunk)]) + struct.pack(">I", time_ms & 0xFFFFFFFF)
                + bytes([character, len(ids), 0, 0, 0, 0])
                + struct.pack(">H", len(payload)))  # fmt: skip
        out.append(head + payload)
    return out


def xsens_datagrams(motions, *, parts: int = 1, first_sample: int = 1000) -> tuple:
    """The datagrams of ``motions`` streamed together: ``(rate, [[datagrams of sample k of
    each character] per k])``; take ``i`` is character ``i``; its sample ``k`` has counter
    ``first_sample + k`` and time code ``round(1000 k / rate)`` ms."""
    takes = [xsens_samples(m) for m in motions]
    rates = {r for r, *_ in takes}
    if len(rates) > 1:
        raise ValueError(f"takes at {sorted(rates)} Hz: play them at one --rate")
    rate = rates.pop()
    n = max(len(p) for _, _, p, _ in takes)
    out = []
    for k in range(n):
        frame = []
        for cid, (_, ids, p, q) in enumerate(takes):
            if k < len(p):
                frame += mxtp02(first_sample + k, round(1000 * k / rate), cid, ids, p[k], q[k],
                                parts=parts)  # fmt: skip
        out.append(frame)
    return rate, out


def play_as_xsens(motions, to: str, *, fast=False, out=None, parts: int = 1) -> int:
    """Send ``motions`` as MVN's network streamer sends characters to ``to`` (``HOST:PORT``):
    one UDP socket, take ``i`` character ``i``, sample ``k`` of every take at ``k / rate``
    (``fast``: one every millisecond: UDP has no back-pressure). Return the datagrams sent."""
    rate, frames = xsens_datagrams(motions, parts=parts)
    sent = send_paced(frames, to, rate, fast=fast)
    if out is not None:
        print(f"sent {sent} datagrams ({len(motions)} characters) to {to}", file=out)
    return sent


__all__ = [
    "DEFAULT_PORT",
    "DEFAULT_RATE",
    "HEADER",
    "ITEM",
    "JOINT_MAPS",
    "PARENTS",
    "RIG_SEGMENTS",
    "SEGMENTS",
    "MvnSkeleton",
    "Source",
    "fpdtw_to_mvn",
    "mvn_to_fpdtw",
    "mxtp02",
    "play_as_xsens",
    "xsens_datagrams",
    "xsens_samples",
]
