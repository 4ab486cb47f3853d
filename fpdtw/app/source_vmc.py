"""``vmc://HOST:PORT``: the VMC protocol (markerless webcam trackers, VTuber tools), both ways.

VMC is OSC over UDP; its senders ("Performers") send to a receiver on port 39539 by default,
so fpdtw LISTENS on ``HOST:PORT`` and only reads. Datagrams are parsed by python-osc
(:class:`pythonosc.osc_packet.OscPacket`: a message or a bundle, nested bundles flattened).
A sender's next bundles that differ from the last one python-osc read only in their timetag
and numbers are read by :class:`Layout` from the places python-osc found them (the same
values, a fifth of the time); one holding a whole frame goes from its bytes to the frame's
channel values in one compiled call (:func:`_whole`). The messages read (the rest, blend
shapes included, are ignored):

* ``/VMC/Ext/Root/Pos name p.x p.y p.z q.x q.y q.z q.w [s.x s.y s.z o.x o.y o.z]``: the
  avatar's root in the world (its scale and offset are ignored);
* ``/VMC/Ext/Bone/Pos name p.x p.y p.z q.x q.y q.z q.w``: a Unity ``HumanBodyBones`` bone's
  local position and rotation (relative to its parent bone);
* ``/VMC/Ext/T time``: the sender's relative time in seconds.

**Frames.** The protocol names no frame delimiter; fpdtw takes ``/VMC/Ext/T`` as the end of
a frame (its time is the frame's capture time) and, for a sender that never sends it, a
``/VMC/Ext/Root/Pos`` after bones as the start of the next one (then the arrival time
counts). **Performers**: one per sender address (host:port of its datagrams; VMC carries no
performer id), named by it. **Skeleton**: the body bones of a performer's first complete
frame (:data:`PARENTS`, the parent of a bone being its nearest ancestor the sender has), their
local positions as offsets, identity rotations as the rest pose (a VRM avatar's normalised
T-pose), sent to its session as the BVH header of that skeleton; later local positions of
bones other than the hips are not read. **Axes**: Unity's are left-handed, Y up; fpdtw's
right-handed: :func:`unity_to_fpdtw` mirrors X.

:func:`play_as_vmc` is the other side without hardware: each take a sender, python-osc's own
UDP client sending one bundle a frame (``fpdtw stream --as vmc``).
"""

from __future__ import annotations

import math
import struct
import sys
import time

import numba
import numpy as np
from pythonosc import osc_bundle_builder, osc_message_builder, udp_client
from pythonosc.osc_packet import OscPacket

from fpdtw import limits
from fpdtw.app.serve import parse_address
from fpdtw.app.sources import DatagramSource, bvh_header, sender_name
from fpdtw.motion.joints import PAPER_JOINTS, resolve_joint_map
from fpdtw.motion.rotations import (
    euler_into,
    euler_kernel,
    quat_conj,
    quat_mul,
    quat_normalize,
    quat_to_euler,
)

#: The VMC protocol's usual receiver port.
DEFAULT_PORT = 39539
#: The default rate of a sender (``--rate``): the frame period a gap is measured in.
DEFAULT_RATE = 60.0
#: Bytes a datagram may have (a frame of 55 bones and 52 blend shapes is about 8 KiB).
MAX_DATAGRAM = 32768
#: Sender addresses tracked in one take (each has a frame in the making).
MAX_SENDERS = 64
#: A quaternion whose norm is further than this from 1 is not a rotation.
UNIT_TOLERANCE = 1e-3

_SIDES = ("Left", "Right")
#: Unity's humanoid body bones read, each with its parent in Unity's humanoid hierarchy.
PARENTS = {"Hips": None, "Spine": "Hips", "Chest": "Spine", "UpperChest": "Chest",
           "Neck": "UpperChest", "Head": "Neck"}  # fmt: skip
for _s in _SIDES:
    PARENTS.update({f"{_s}UpperLeg": "Hips", f"{_s}LowerLeg": f"{_s}UpperLeg",
                    f"{_s}Foot": f"{_s}LowerLeg", f"{_s}Toes": f"{_s}Foot",
                    f"{_s}Shoulder": "UpperChest", f"{_s}UpperArm": f"{_s}Shoulder",
                    f"{_s}LowerArm": f"{_s}UpperArm", f"{_s}Hand": f"{_s}LowerArm"})  # fmt: skip
#: The other HumanBodyBones names (eyes, jaw, fingers): valid, not read.
OTHER_BONES = frozenset(
    ["LeftEye", "RightEye", "Jaw"]
    + [f"{s}{f}{p}" for s in _SIDES for f in ("Thumb", "Index", "Middle", "Ring", "Little")
       for p in ("Proximal", "Intermediate", "Distal")]
)  # fmt: skip

_FULL = {"center_hip": "Hips", "middle_chest": "Chest", "upper_chest": "UpperChest",
         "head": "Head"}  # fmt: skip
for _s, _c in (("Left", "left"), ("Right", "right")):
    _FULL.update({f"{_c}_hip": f"{_s}UpperLeg", f"{_c}_knee": f"{_s}LowerLeg",
                  f"{_c}_ankle": f"{_s}Foot", f"{_c}_shoulder": f"{_s}UpperArm",
                  f"{_c}_elbow": f"{_s}LowerArm", f"{_c}_wrist": f"{_s}Hand"})  # fmt: skip
#: The built-in joint maps of a VMC skeleton (our joint -> HumanBodyBones), tried in order
#: after ``--joint-map``'s: all 16 joints; without UpperChest; the paper's 8.
JOINT_MAPS = (
    _FULL,
    {**_FULL, "middle_chest": "Spine", "upper_chest": "Chest"},
    {j: _FULL[j] for j in PAPER_JOINTS},
)
#: Bones a first frame must have to make a skeleton.
REQUIRED = ("Hips", *JOINT_MAPS[2].values())

#: The emulator: each body bone -> its name in common rigs (ASF/CMU, FBX/Mixamo), first wins.
RIG_NAMES = {"Hips": ("hip", "root", "Hips", "Pelvis"), "Spine": ("lowerback", "Spine"),
             "Chest": ("upperback", "Spine1", "Chest"),
             "UpperChest": ("thorax", "Spine2", "UpperChest"),
             "Neck": ("lowerneck", "Neck"), "Head": ("head", "Head")}  # fmt: skip
for _s, _c in (("Left", "l"), ("Right", "r")):
    RIG_NAMES.update({f"{_s}UpperLeg": (f"{_c}femur", f"{_s}UpLeg", f"{_s}UpperLeg"),
                      f"{_s}LowerLeg": (f"{_c}tibia", f"{_s}Leg", f"{_s}LowerLeg"),
                      f"{_s}Foot": (f"{_c}foot", f"{_s}Foot"),
                      f"{_s}Toes": (f"{_c}toes", f"{_s}ToeBase", f"{_s}Toes"),
                      f"{_s}Shoulder": (f"{_c}clavicle", f"{_s}Shoulder", f"{_s}Collar"),
                      f"{_s}UpperArm": (f"{_c}humerus", f"{_s}Arm", f"{_s}UpperArm"),
                      f"{_s}LowerArm": (f"{_c}radius", f"{_s}ForeArm", f"{_s}LowerArm"),
                      f"{_s}Hand": (f"{_c}wrist", f"{_s}Hand")})  # fmt: skip

_ORDER = "XYZ"  # the built skeleton's rotation order, written Zrotation Yrotation Xrotation
_MIRROR = np.array([-1.0, 1.0, 1.0])


def unity_to_fpdtw(p, q_xyzw):
    """Unity's position (..., 3) and quaternion ``x y z w`` (..., 4) in fpdtw's axes:
    ``(-x, y, z)`` and ``(w, x, -y, -z)``.

    Mirroring X (``M = diag(-1, 1, 1)``) turns Unity's left-handed, Y-up axes into
    right-handed, Y-up ones with the same up and forward. A rotation ``R`` becomes
    ``M R M``: about the axis ``M a`` by ``-theta`` (a mirror reverses the sense of turning),
    that is about ``-M a`` by ``theta``; its quaternion ``(w, -M v)`` keeps the mirrored
    axis' component and negates the other two. The map is its own inverse."""
    p = np.asarray(p, dtype=float) * _MIRROR
    q = np.asarray(q_xyzw, dtype=float)
    return p, np.stack([q[..., 3], q[..., 0], -q[..., 1], -q[..., 2]], axis=-1)


def fpdtw_to_unity(p, q_wxyz):
    """The inverse of :func:`unity_to_fpdtw`: Unity's position and quaternion ``x y z w``."""
    p = np.asarray(p, dtype=float) * _MIRROR
    q = np.asarray(q_wxyz, dtype=float)
    return p, np.stack([q[..., 1], -q[..., 2], -q[..., 3], q[..., 0]], axis=-1)


def nearest_parent(bone: str, have) -> str | None:
    """The nearest ancestor of ``bone`` in :data:`PARENTS` that ``have`` holds."""
    p = PARENTS[bone]
    while p is not None and p not in have:
        p = PARENTS[p]
    return p


class VmcSkeleton:
    """The skeleton of a performer, from the body bones of its first frame.

    Attributes
    ----------
    bones : list of str
        Depth first from Hips (the BVH joints, named as the bones).
    header : list of str
        Its BVH header (``Frame Time`` of ``rate``).
    """

    def __init__(self, frame: dict, rate: float):
        have = [b for b in PARENTS if b in frame]
        up = [-1 if b == "Hips" else have.index(nearest_parent(b, have)) for b in have]
        offsets = [unity_to_fpdtw(frame[b][:3], frame[b][3:])[0] for b in have]
        self.header, order = bvh_header(have, up, offsets, rate)
        self.bones = [have[j] for j in order]

    def row(self, v, root) -> np.ndarray:
        """The BVH channel values (n_channels,) float64 of a frame: ``v`` (n_bones, 7) float64,
        each bone's ``p.x p.y p.z q.x q.y q.z q.w`` in :attr:`bones`' order (Unity's values),
        with the root's ``(p, q)`` (Unity's; None: at the origin). One compiled call
        (:func:`_row`); :meth:`row_numpy` is its twin."""
        out = np.empty(3 + 3 * len(v))
        has_root = root is not None
        _row(np.ascontiguousarray(v, dtype=np.float64),
             np.asarray(root, dtype=np.float64) if has_root else _NO_ROOT, has_root, _EULER,
             out)  # fmt: skip
        return out

    @staticmethod
    def row_numpy(v, root) -> np.ndarray:
        """:meth:`row` in NumPy, :func:`~fpdtw.motion.rotations.quat_normalize` and
        :func:`~fpdtw.motion.rotations.quat_to_euler` (equal bit for bit, tested)."""
        q = v[:, [6, 3, 4, 5]]  # unity_to_fpdtw's (w, x, -y, -z), normalised
        q[:, 2:] *= -1.0
        q = quat_normalize(q)
        hx, hy, hz = v[0, :3].tolist()
        hips = (-hx, hy, hz)
        if root is not None:
            rx, ry, rz, x, y, z, w = (float(c) for c in root[:7])
            rq = quat_normalize([w, x, -y, -z])
            turned = quat_mul(quat_mul(rq, [0.0, *hips]), quat_conj(rq))
            hips = (-rx + turned[1], ry + turned[2], rz + turned[3])
            q[0] = quat_mul(rq, q[0])
        # quat_to_euler(q, "XYZ") column for column, as Z Y X (the channels)
        e = quat_to_euler(q, _ORDER)
        return np.concatenate([hips, e[:, ::-1].ravel()])


@numba.njit(cache=True)
def _qmul(a, b) -> tuple:  # pragma: no cover - compiled
    """:func:`~fpdtw.motion.rotations.quat_mul` of two quaternions (tuples of 4 floats), its
    operations in its order (so the same bits)."""
    aw, ax, ay, az = a
    bw, bx, by, bz = b
    return (
        aw * bw - ax * bx - ay * by - az * bz,
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
    )


#: :func:`fpdtw.motion.rotations.euler_kernel` of the built skeleton's order.
_EULER = euler_kernel(_ORDER)
_NO_ROOT = np.zeros(7)
_NO_INDEX = np.zeros(0, np.intp)


@numba.njit(cache=True)
def _row(v, root, has_root, euler, out):  # pragma: no cover - compiled
    """:meth:`VmcSkeleton.row` into ``out``, :meth:`VmcSkeleton.row_numpy`'s operations in
    its order: each quaternion normalised as ``np.linalg.norm`` sums its squares (left to
    right), the root's turn of the hips and of the first bone, then ``quat_to_euler``."""
    n = v.shape[0]
    q = np.empty((n, 4))
    for r in range(n):
        w, x, y, z = v[r, 6], v[r, 3], -v[r, 4], -v[r, 5]
        norm = np.sqrt(((w * w + x * x) + y * y) + z * z)
        q[r, 0], q[r, 1], q[r, 2], q[r, 3] = w / norm, x / norm, y / norm, z / norm
    hips = (-v[0, 0], v[0, 1], v[0, 2])
    if has_root:
        w, x, y, z = root[6], root[3], -root[4], -root[5]
        norm = np.sqrt(((w * w + x * x) + y * y) + z * z)
        rq = (w / norm, x / norm, y / norm, z / norm)
        turned = _qmul(_qmul(rq, (0.0, hips[0], hips[1], hips[2])),
                       (rq[0], -rq[1], -rq[2], -rq[3]))  # fmt: skip
        hips = (-root[0] + turned[1], root[1] + turned[2], root[2] + turned[3])
        q[0, 0], q[0, 1], q[0, 2], q[0, 3] = _qmul(rq, (q[0, 0], q[0, 1], q[0, 2], q[0, 3]))
    e = np.empty((n, 3))
    euler_into(q, euler, e)
    out[0], out[1], out[2] = hips
    for r in range(n):
        out[3 + 3 * r], out[4 + 3 * r], out[5 + 3 * r] = e[r, 2], e[r, 1], e[r, 0]


@numba.njit(cache=True)
def _whole(buf, keep, fixed, at, bones, root_at, t_at, root, has_root, big, tol, out):
    """:meth:`Source.whole`'s frame in one compiled call: the time of the frame in bundle
    ``buf`` (uint8, its length the layout's) and its row in ``out``, or NaN (nothing of
    ``buf`` used) unless its fixed bytes (``keep``) are ``fixed``, each of its floats (at
    words ``at``, big-endian) is within ``big`` and each quaternion read (``bones`` (n, 7)
    and ``root_at`` (7,) or (0,) index the floats) within ``tol`` of unit norm. A root read
    is written into ``root`` (else ``root``, when ``has_root``, is the sender's last)."""
    for i in range(keep.shape[0]):
        if buf[keep[i]] != fixed[i]:
            return np.nan
    words = buf.view(np.uint32)
    raw = np.empty(at.shape[0], np.uint32)
    for i in range(at.shape[0]):
        w = words[at[i]]
        raw[i] = (w >> 24) | ((w >> 8) & 0xFF00) | ((w << 8) & 0xFF0000) | (w << 24)
    f = raw.view(np.float32)
    v = np.empty(at.shape[0])
    for i in range(at.shape[0]):
        v[i] = f[i]
        if not abs(v[i]) <= big:
            return np.nan
    b = np.empty(bones.shape)
    for r in range(bones.shape[0]):
        for c in range(7):
            b[r, c] = v[bones[r, c]]
        s = ((b[r, 3] * b[r, 3] + b[r, 4] * b[r, 4]) + b[r, 5] * b[r, 5]) + b[r, 6] * b[r, 6]
        if not abs(np.sqrt(s) - 1.0) < tol:
            return np.nan
    if root_at.shape[0]:
        s = 0.0
        for c in range(7):
            root[c] = v[root_at[c]]
            s += root[c] * root[c] if c >= 3 else 0.0
        if not abs(np.sqrt(s) - 1.0) < tol:
            return np.nan
        has_root = True
    _row(b, root, has_root, _EULER, out)
    return v[t_at]


# -- reading ---------------------------------------------------------------------------------


class _Sender:
    """One sender address: its frame in the making and its performer."""

    def __init__(self, addr):
        self.addr = sender_name(addr)
        self.perf = self.skeleton = self.root = self.problem = None
        self.bones = {}  # name -> its 7 values (those in unchecked not yet checked)
        self.unchecked = []  # (name, where) of bones whose values wait for check()
        self.refused = False
        self.timed = None  # sends /VMC/Ext/T (decided by its first frame)
        self.layout = None  # of its last bundle python-osc read
        self.plan = None  # (layout, frame_plan of it or None) once the skeleton is known
        self.t0 = self.last_t = None

    def spoil(self, kind, what):
        if self.problem is None:
            self.check()  # a bone before this problem may have the first
        if self.problem is None:
            self.problem = (kind, what)

    def check(self):
        """:func:`values` of the bones received since the last check, all at once: a bone
        that fails is dropped from :attr:`bones` and spoils the frame, in their order (as if
        each had been checked on arrival)."""
        if not self.unchecked:
            return
        todo, self.unchecked = self.unchecked, []
        v = np.array([self.bones[name] for name, _ in todo], dtype=float)
        n = np.sqrt(np.einsum("ij,ij->i", v[:, 3:], v[:, 3:]))
        ok = np.isfinite(v).all(1) & (np.abs(v).max(1) <= limits.get("max_abs_value"))
        ok &= np.abs(n - 1.0) < UNIT_TOLERANCE * 0.999  # else checked one by one
        for k in np.flatnonzero(~ok).tolist():
            name, where = todo[k]
            if values(self, v[k], f"bone {name!r}", where) is None:
                del self.bones[name]


def values(s, v, name, where):
    """``v`` (p, q) checked: finite, plausible, a unit quaternion (else the frame spoilt)."""
    if not np.isfinite(v).all():
        return s.spoil("finite", f"{where}: {name} has NaN or inf")
    big = limits.get("max_abs_value")
    if np.abs(v).max() > big:
        return s.spoil("large", f"{where}: {name} has a value beyond {big:g} "
                       f"({limits.env_name('max_abs_value')})")  # fmt: skip
    norm = float(np.linalg.norm(v[3:]))
    if abs(norm - 1.0) > UNIT_TOLERANCE:
        return s.spoil("rotation", f"{where}: {name}'s quaternion has norm {norm:.6g}")
    return v


def framing_error(data: bytes, depth: int = 0) -> str | None:
    """What is wrong with the framing of an OSC packet (None: nothing): a length that is not
    a multiple of 4, or a bundle element whose size is not one or passes the end (python-osc
    reads a cut bundle's first elements without a word)."""
    if len(data) % 4:
        return f"{len(data)} bytes, not a multiple of 4"
    if not data.startswith(b"#bundle\x00"):
        return None
    if depth > 8:
        return "bundles nested more than 8 deep"
    pos, end = 16, len(data)
    while pos < end:
        size = _INT.unpack_from(data, pos)[0] if pos + 4 <= end else -1
        if size <= 0 or size % 4 or pos + 4 + size > end:
            return f"a bundle element at byte {pos} of size {size} in {end} bytes (cut)"
        if data.startswith(b"#bundle\x00", pos + 4) and (
            why := framing_error(data[pos + 4 : pos + 4 + size], depth + 1)
        ):
            return why
        pos += 4 + size
    return None


_INT = struct.Struct(">i")
_NUMBER = frozenset((int, float))  # python-osc's types of numbers (not bool)


class Layout:
    """Where the floats of a flat bundle of messages with ``f``, ``i`` and ``s`` arguments
    are (its strings and ints are read as constants).

    Parameters
    ----------
    data : bytes
        The bundle (framing checked).
    messages : list of (str, list)
        Its messages as python-osc read them: address and arguments.

    Raises ValueError for any other packet (a message, a nested bundle, other types).
    """

    def __init__(self, data: bytes, messages: list):
        if not data.startswith(b"#bundle\x00"):
            raise ValueError("not a bundle")
        fixed = np.ones(len(data), bool)
        fixed[8:16] = False  # the timetag
        at, self.messages, pos = [], [], 16
        for address, args in messages:
            end = pos + 4 + _INT.unpack_from(data, pos)[0]
            tags = data.find(b",", pos + 4, end)
            if data.startswith(b"#bundle", pos + 4) or tags < 0:
                raise ValueError("a nested bundle")
            tag = data[tags + 1 : data.index(b"\x00", tags)].decode()
            if tag.strip("fis") or len(tag) != len(args):
                raise ValueError("not only f, i and s arguments")
            slots, q = [], tags + (len(tag) + 5) // 4 * 4
            for j, (t, a) in enumerate(zip(tag, args, strict=True)):
                if t == "f":
                    slots.append(j)
                    at.append(q // 4)
                    fixed[q : q + 4] = False
                q += (len(a.encode()) + 4) // 4 * 4 if t == "s" else 4
            self.messages.append((address, args, slots))
            pos = end
        if pos != len(data):
            raise ValueError("a nested bundle")
        self.size, self.at = len(data), np.array(at, np.intp)
        self.keep = np.flatnonzero(fixed)
        self.fixed = np.frombuffer(data, np.uint8)[self.keep]
        if self.read(data) != messages:  # NaN among them too: python-osc reads the next
            raise ValueError("the layout does not read its own bundle back")

    def floats(self, data: bytes):
        """The float arguments of ``data`` in order (n,) float64, or None if it does not have
        this layout (then its framing is this bundle's: its sizes and tags are fixed bytes)."""
        if len(data) != self.size or not np.array_equal(
            np.frombuffer(data, np.uint8)[self.keep], self.fixed
        ):
            return None
        return np.frombuffer(data, ">f4")[self.at].astype(float)

    def read(self, data: bytes):
        """The messages of ``data`` (as python-osc reads them), or None if it does not
        have this layout."""
        v = self.floats(data)
        if v is None:
            return None
        v = v.tolist()
        out, k = [], 0
        for address, args, slots in self.messages:
            args = list(args)
            for j in slots:
                args[j] = v[k]
                k += 1
            out.append((address, args))
        return out


def frame_plan(layout: Layout, bones: list):
    """Where one whole frame of a sender is in a bundle of this layout: ``(bone floats
    (n_bones, 7) intp in the skeleton's order, root floats (7,) intp or None, time float)``
    indices into :meth:`Layout.floats`; None unless the bundle is an optional
    ``/VMC/Ext/Root/Pos`` first, each of the skeleton's ``bones`` once (other bones the
    reader skips), a ``/VMC/Ext/T`` last and only messages the reader ignores besides, all
    their numbers floats."""
    found, root, t, k = {}, None, None, 0
    for i, (address, args, slots) in enumerate(layout.messages):
        at, k = list(range(k, k + len(slots))), k + len(slots)
        if t is not None:
            return None
        if address == "/VMC/Ext/Bone/Pos":
            if len(args) != 8 or slots != list(range(1, 8)):
                return None
            if args[0] in OTHER_BONES:
                continue
            if args[0] not in bones or args[0] in found:
                return None
            found[args[0]] = at
        elif address == "/VMC/Ext/Root/Pos":
            if i or len(args) not in (8, 14) or slots != list(range(1, len(args))):
                return None
            root = np.array(at[:7])
        elif address == "/VMC/Ext/T":
            if slots != [0]:
                return None
            t = at[0]
    if t is None or len(found) != len(bones):
        return None
    return np.array([found[b] for b in bones]), root, t


def _numbers(args) -> bool:
    return {*map(type, args)} <= _NUMBER


class Source(DatagramSource):
    """Listens for VMC senders, one take at a time (see the module's docstring).

    Parameters
    ----------
    host, port : str, int
        Where to listen (UDP).
    rate : float, optional
        The senders' frame rate (``--rate``; default :data:`DEFAULT_RATE`): the period a gap
        is measured in and the rate the live target resamples from.
    header : None
        Not used: the skeleton comes from the stream (ValueError when given).
    """

    scheme = "vmc"
    skeleton_from = "the bones sent"
    DEFAULT_RATE = DEFAULT_RATE  # the module's

    def warm_up(self) -> None:
        super().warm_up()
        bones = np.arange(7, dtype=np.intp)[None]
        _whole(np.frombuffer(bytes(28), np.uint8), _NO_INDEX, np.zeros(0, np.uint8), bones[0],
               bones, _NO_INDEX, 0, np.zeros(7), False, 1.0, 1.0, np.empty(6))  # fmt: skip
        VmcSkeleton.row(None, np.eye(1, 7, 6), None)  # a first frame's, from Python

    def begin_take(self) -> None:
        self.senders = {}
        self._big = limits.get("max_abs_value")  # the limits in force when a take starts

    def end_take(self, performers) -> None:
        for s in self.senders.values():
            s.check()
            if s.bones or s.problem:
                self.finish(s, performers, None, None)

    def datagram(self, data: bytes, addr, arrival: float, performers) -> None:
        """One datagram: parsed, its messages added to its sender's frame."""
        self.n += 1
        n = self.n
        s = self.senders.get(addr)
        if s is None:
            if len(self.senders) >= MAX_SENDERS:
                performers.frames += 1
                return performers.count_bad(None, "refused", f"datagram {n}: more than "
                                            f"{MAX_SENDERS} sender addresses")  # fmt: skip
            s = self.senders[addr] = _Sender(addr)
        where = f"datagram {n} from {s.addr}"
        if s.plan is not None and self.whole(s, data, arrival, performers, where):
            return None
        if len(data) > MAX_DATAGRAM:
            performers.frames += 1
            return performers.count_bad(s.perf, "oversize", f"{where}: {len(data)} bytes, "
                                        f"more than {MAX_DATAGRAM}")  # fmt: skip
        try:
            why = framing_error(data)
            messages = None if why or s.layout is None else s.layout.read(data)
            if messages is None and not why:
                messages = [(m.message.address, m.message.params)
                            for m in OscPacket(data).messages]  # fmt: skip
                try:
                    s.layout = Layout(data, messages)
                except ValueError:
                    s.layout = None
        except Exception as e:  # python-osc's parser on hostile bytes: any failure is a refusal
            why = str(e).splitlines()[0][:80] if str(e) else type(e).__name__
        if why:
            performers.frames += 1
            return performers.count_bad(s.perf, "osc", f"{where}: not an OSC packet ({why})")
        for a, args in messages:
            if a == "/VMC/Ext/Bone/Pos":
                self.bone(s, args, where)
            elif a == "/VMC/Ext/Root/Pos":
                s.check()
                if s.bones:
                    self.finish(s, performers, arrival, None, where)
                if len(args) not in (8, 14) or not _numbers(args[1:]):
                    s.spoil("count", f"{where}: /VMC/Ext/Root/Pos with {len(args)} arguments "
                            "or not numbers, expected name and 7 (or 13) numbers")  # fmt: skip
                else:
                    s.root = values(s, np.array(args[1:8], dtype=float), "root", where)
            elif a == "/VMC/Ext/T":
                if len(args) != 1 or not _numbers(args) or not math.isfinite(args[0]):
                    s.spoil("number", f"{where}: /VMC/Ext/T {args!r} is not a finite time")
                    self.finish(s, performers, arrival, None, where)
                else:
                    self.finish(s, performers, arrival, float(args[0]), where)

    def whole(self, s, data, arrival, performers, where) -> bool:
        """A bundle with the layout of the sender's last and the whole frame in it
        (:func:`frame_plan`), aligned without reading its messages one by one (one compiled
        call, :func:`_whole`), when every value surely passes :func:`values` and nothing of
        the frame came before; else False, and nothing changed (the datagram is read as any
        other)."""
        layout, plan = s.plan
        if plan is None or s.layout is not layout or s.bones or s.unchecked or s.problem:
            return False
        if len(data) != layout.size or sys.byteorder != "little":  # _whole swaps bytes
            return False
        at, root_at, t_at = plan
        read_root = root_at is not None
        root = np.empty(7) if read_root or s.root is None else s.root
        row = np.empty(3 + 3 * len(at))
        t = _whole(np.frombuffer(data, np.uint8), layout.keep, layout.fixed, layout.at, at,
                   root_at if read_root else _NO_INDEX, t_at, root, s.root is not None,
                   float(self._big), UNIT_TOLERANCE * 0.999, row)  # fmt: skip
        if t != t:
            return False
        if read_root:
            s.root = root
        performers.frames += 1
        self.aligned(s, performers, arrival, t, where, row)
        return True

    def bone(self, s, args, where) -> None:
        if len(args) != 8 or not isinstance(args[0], str) or not _numbers(args[1:]):
            return s.spoil("count", f"{where}: /VMC/Ext/Bone/Pos {args[:1]!r} with "
                           f"{len(args)} arguments, expected name, p.x p.y p.z, q.x q.y q.z "
                           "q.w")  # fmt: skip
        name = args[0]
        if name in OTHER_BONES:
            return None
        if name not in PARENTS:
            return s.spoil("bone", f"{where}: bone {name[:40]!r} is not a body bone of Unity's "
                           "HumanBodyBones")  # fmt: skip
        if s.skeleton is not None and name not in s.skeleton.bones:
            return s.spoil("bone", f"{where}: bone {name!r} is not in this sender's skeleton "
                           "(its first frame's bones)")  # fmt: skip
        if name in s.bones:
            s.check()  # the first copy may fail its values (then it is not in s.bones)
            if name in s.bones:
                return s.spoil("duplicate", f"{where}: bone {name!r} twice in one frame")
        s.bones[name] = args[1:]
        s.unchecked.append((name, where))

    def finish(self, s, performers, arrival, t, where="at the end of the take") -> None:
        """The end of a sender's frame: checked, then aligned (or counted)."""
        s.check()
        bones, problem = s.bones, s.problem
        s.bones, s.problem = {}, None
        if not bones and problem is None:
            return None  # a time without bones (e.g. before the sender loads its model)
        performers.frames += 1
        if s.refused:
            return performers.count_bad(None, "refused", f"{where}: sender {s.addr} refused")
        if problem is not None:
            return performers.count_bad(s.perf, *problem)
        if s.perf is None:
            missing = [b for b in REQUIRED if b not in bones]
            if missing:
                return performers.count_bad(None, "missing", f"{where}: the first frame of "
                                            f"{s.addr} lacks {', '.join(missing)}")  # fmt: skip
            s.skeleton = VmcSkeleton(bones, self.rate)
            s.timed = t is not None
            about = (f"{len(s.skeleton.bones)} bones, frames "
                     f"{'timed by /VMC/Ext/T' if s.timed else 'timed by arrival'}")  # fmt: skip
            key = sum(1 for x in self.senders.values() if x.perf is not None)
            s.perf = performers.add(key, s.addr, s.skeleton.header, self.rate, about)
            if s.perf is None:
                s.refused = True
                return None
        missing = [b for b in s.skeleton.bones if b not in bones]
        if missing:
            return performers.count_bad(s.perf, "missing", f"{where}: the frame lacks "
                                        f"{', '.join(missing[:4])}")  # fmt: skip
        if s.layout is not None and (s.plan is None or s.plan[0] is not s.layout):
            s.plan = (s.layout, frame_plan(s.layout, s.skeleton.bones))
        v = np.array([bones[b] for b in s.skeleton.bones], dtype=float)
        return self.aligned(s, performers, arrival, t, where, s.skeleton.row(v, s.root))

    def aligned(self, s, performers, arrival, t, where, row) -> None:
        """A whole checked frame of ``s``'s performer: ``row`` (n_channels,) float64, its
        BVH channel values (:meth:`VmcSkeleton.row`), timed and aligned (or counted)."""
        perf = s.perf
        if s.timed and t is None:
            return performers.count_bad(perf, "missing", f"{where}: a frame without its "
                                        "/VMC/Ext/T (a datagram lost or late)")  # fmt: skip
        clock = t if s.timed else arrival
        if s.last_t is not None and clock <= s.last_t:
            kind = "duplicate" if clock == s.last_t else "order"
            return performers.count_bad(perf, kind, f"{where}: time {clock!r} s, not after "
                                        f"the previous frame's {s.last_t!r} s")  # fmt: skip
        if s.t0 is None:
            s.t0 = clock
        s.last_t = clock
        performers.feed(perf, row, arrival, t=clock - s.t0)
        return None


# -- the senders, without hardware --------------------------------------------------------------


def rig_bones(skeleton) -> dict:
    """The body bones a rig has: ``{HumanBodyBones name: its joint index}`` (ValueError
    without hips or when the bones' nesting is not the rig's)."""
    found = resolve_joint_map(skeleton.joint_names, RIG_NAMES)
    index = {n: j for j, n in enumerate(skeleton.joint_names)}
    out, used = {}, set()
    for b in PARENTS:
        if b in found and found[b] not in used:
            out[b] = index[found[b]]
            used.add(found[b])
    if "Hips" not in out:
        raise ValueError(f"no hips among {', '.join(skeleton.joint_names[:8])}...")
    for b, j in out.items():
        p = nearest_parent(b, out)
        a = skeleton.parents[j]
        while p is not None and a >= 0 and a != out[p]:
            a = skeleton.parents[a]
        if p is not None and a < 0:
            raise ValueError(f"{skeleton.joint_names[j]} ({b}) is not below "
                             f"{skeleton.joint_names[out[p]]} ({p})")  # fmt: skip
    return out


def vmc_frames(motion) -> tuple:
    """A motion as a VMC sender sends it: ``(rate, [datagram bytes per frame])``, one bundle
    a frame: ``/VMC/Ext/Root/Pos`` (at the origin), ``/VMC/Ext/Bone/Pos`` of each body bone
    the rig has (:func:`rig_bones`; its rotation relative to the nearest such ancestor, the
    product of the local rotations between; its rest offset from it), ``/VMC/Ext/OK 1`` and
    ``/VMC/Ext/T`` (frame ``k`` at ``k / rate``); Unity's axes (:func:`fpdtw_to_unity`)."""
    sk = motion.skeleton
    have = rig_bones(sk)
    local = quat_mul(quat_mul(np.asarray(sk.pre_rotations)[None], motion.quats),
                     np.asarray(sk.post_rotations)[None])  # fmt: skip
    root = have["Hips"]
    msgs = []  # per bone: (name, offsets (F, 3), quats (F, 4))
    for b, j in have.items():
        p = nearest_parent(b, have)
        q, off, a = local[:, j], np.asarray(sk.offsets[j], dtype=float), j
        while p is not None and sk.parents[a] != have[p]:
            a = sk.parents[a]
            q = quat_mul(local[:, a], q)
            off = off + sk.offsets[a]
        if b == "Hips":
            pos = motion.root_translation + sk.offsets[root]
        else:
            pos = np.broadcast_to(off, (motion.n_frames, 3))
        msgs.append((b, *fpdtw_to_unity(pos, q)))
    out = []
    for k in range(motion.n_frames):
        bundle = osc_bundle_builder.OscBundleBuilder(osc_bundle_builder.IMMEDIATELY)
        bundle.add_content(_message("/VMC/Ext/Root/Pos", "root", *[0.0] * 6, 1.0))
        for b, pos, q in msgs:
            bundle.add_content(_message("/VMC/Ext/Bone/Pos", b, *pos[k], *q[k]))
        bundle.add_content(_message("/VMC/Ext/OK", 1))
        bundle.add_content(_message("/VMC/Ext/T", k / motion.fps))
        out.append(bundle.build())
    return motion.fps, out


def _message(address, *args):
    m = osc_message_builder.OscMessageBuilder(address=address)
    for a in args:
        if isinstance(a, str):
            m.add_arg(a)
        elif isinstance(a, int):
            m.add_arg(a, "i")
        else:
            m.add_arg(float(a), "f")
    return m.build()


def play_as_vmc(motions, to: str, *, fast=False, out=None) -> int:
    """Send ``motions`` as VMC senders to ``to`` (``HOST:PORT``): one python-osc UDP client
    (one sender address) per motion, frames interleaved, frame ``k`` at ``k / rate`` (``fast``:
    one every millisecond: UDP has no back-pressure). Return the datagrams sent."""
    host, port = parse_address(to)
    takes = [vmc_frames(m) for m in motions]
    clients = [udp_client.UDPClient(host, port) for _ in takes]
    rates = {r for r, _ in takes}
    if len(rates) > 1:
        raise ValueError(f"takes at {sorted(rates)} Hz: play them at one --rate")
    rate = rates.pop()
    n = max(len(f) for _, f in takes)
    t0, sent = time.perf_counter(), 0
    for k in range(n):
        due = t0 + (k / 1000 if fast else k / rate)
        if (wait := due - time.perf_counter()) > 0:
            time.sleep(wait)
        for c, (_, frames) in zip(clients, takes, strict=True):
            if k < len(frames):
                c.send(frames[k])
                sent += 1
    if out is not None:
        print(f"sent {sent} datagrams ({len(takes)} senders) to {to}", file=out)
    return sent


__all__ = [
    "DEFAULT_PORT",
    "DEFAULT_RATE",
    "JOINT_MAPS",
    "PARENTS",
    "Source",
    "VmcSkeleton",
    "fpdtw_to_unity",
    "play_as_vmc",
    "rig_bones",
    "unity_to_fpdtw",
    "vmc_frames",
]
