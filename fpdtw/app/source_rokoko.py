"""``rokoko://HOST:PORT``: Rokoko Studio's custom streaming (JSON v3 over UDP), both ways.

Studio sends UDP datagrams to a receiver (port 14043 by default in Rokoko's Unity plugin),
so fpdtw LISTENS on ``HOST:PORT`` and only reads. What follows is from Rokoko's "Custom
Streaming" support article and its attached JSON v3 layout ("the layout") unless another
source is named; bone names, hierarchy and rest pose come from Rokoko's public plugins
(``rokoko-studio-live-unity``, ``-blender``, ``-unreal-engine``), which read this stream.

**Datagram.** One JSON object: ``version`` (3), ``fps`` (Studio's target rate), ``scene``:
``timestamp`` and ``actors``, each with ``name``, ``color``, ``meta``, ``dimensions``, an
optional ``body`` and ``face``; and ``props``. ``body`` maps a bone name to ``{"position":
{x, y, z}, "rotation": {x, y, z, w}}``: GLOBAL values (the Unity plugin sets them as a
bone's world position and rotation unchanged; the Unreal plugin takes each joint relative
to its parent's), in metres (the Unreal plugin: "values ... are in meters"), in Unity's
world: Y up, Z forward (the layout), left-handed (the Blender plugin mirrors X to reach
its right-handed one). The Blender plugin reads ``version`` as a number or a string (``3``,
``"3.0"``, ``"3,0"``); its major number must be 3. Studio may LZ4-compress the datagram (an
LZ4 frame, tried first by the Blender plugin, always expected by the Unreal one); no LZ4
package is installed here, so such datagrams are counted as their own kind, never read.

**Skeleton.** The 21 body bones :data:`BONES` (fingers and toe ends valid, not read), each
with its parent (:data:`PARENTS`, the Unreal plugin's table). The rest pose is Studio's
T-pose, each bone's world rotation :data:`TPOSE` there (the Unity plugin's
``SmartsuitTPose``; the Blender plugin's "Tpose from Studio live" is the same). A bone's
rotation from its rest is ``D = R T^-1`` (``R`` its world rotation, ``T`` its T-pose one):
the skeleton of an actor's first complete frame has each bone's offset from its parent in
the parent's rest axes (``D_parent^-1 (p - p_parent)``), zero channels are the T-pose,
each later frame's local rotations are ``D_parent^-1 D``, the hip's position the root's.

**Axes.** Unity's X (right), Y (up), Z (forward) are left-handed; fpdtw's are Y up,
right-handed, Z forward: :func:`studio_to_fpdtw` mirrors X, as for VMC.

**What fpdtw makes of it.** Each actor name is a performer (at most :data:`MAX_ACTORS`
names tracked, ``--max-clients`` aligned), numbered in order of arrival. An actor's frame
counts at ``scene.timestamp`` minus its first's, read as seconds (the layout names no unit);
one not after the last read is duplicated (equal) or reordered (older). The datagram's size
(:data:`MAX_DATAGRAM`) and nesting (:data:`MAX_DEPTH`) are bounded before parsing, actors
and bones before reading; JSON ``NaN`` and ``Infinity`` (Python's parser takes them) are
refused. A sender's next datagram whose bytes outside its numbers are those of its last one
read whole is read from its number tokens in one compiled call (:class:`_Template`), into
exactly what the full reading gives (tested); anything else is read in full.

:func:`play_as_rokoko` is the other side without hardware (``fpdtw stream --as rokoko``): an
encoder of the layout written apart from the reader (its own bone table, the Blender
plugin's T-pose table, its own axis conversion and JSON text), one datagram a frame.
"""

from __future__ import annotations

import json
import math
import re
from operator import itemgetter

import numba
import numpy as np
import orjson

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

#: Studio's custom streaming port (Rokoko's Unity plugin listens on it by default).
DEFAULT_PORT = 14043
#: The default stream rate (``--rate``; else the datagram's ``fps``).
DEFAULT_RATE = 60.0
#: Bytes a datagram may have (the largest UDP payload over IPv4).
MAX_DATAGRAM = 65507
#: Nesting of JSON objects and arrays a datagram may have (the layout needs 7).
MAX_DEPTH = 16
#: Actor names tracked in one take, and actors one datagram may carry.
MAX_ACTORS = 64
#: Characters an actor's name may have, and bones one body may name.
MAX_NAME, MAX_BONES = 128, 128
#: A quaternion whose norm is further than this from 1 is not a rotation.
UNIT_TOLERANCE = 1e-3
#: The first bytes of an LZ4 frame (its magic number 0x184D2204, little-endian).
LZ4_MAGIC = b"\x04\x22\x4d\x18"

_SIDES = ("left", "right")
#: Each body bone read with its parent (the Unreal plugin's hierarchy), the hip first.
PARENTS = {"hip": None, "spine": "hip", "chest": "spine", "neck": "chest", "head": "neck"}
for _s in _SIDES:
    PARENTS.update({f"{_s}Shoulder": "chest", f"{_s}UpperArm": f"{_s}Shoulder",
                    f"{_s}LowerArm": f"{_s}UpperArm", f"{_s}Hand": f"{_s}LowerArm",
                    f"{_s}UpLeg": "hip", f"{_s}Leg": f"{_s}UpLeg", f"{_s}Foot": f"{_s}Leg",
                    f"{_s}Toe": f"{_s}Foot"})  # fmt: skip
BONES = tuple(PARENTS)
_PARENT = np.array([-1 if PARENTS[b] is None else BONES.index(PARENTS[b]) for b in BONES])
_PARENT0 = np.maximum(_PARENT, 0)
#: Bones of the layout that are valid and not read (toe ends, fingers).
OTHER_BONES = frozenset(
    [f"{s}ToeEnd" for s in _SIDES]
    + [f"{s}{f}{p}" for s in _SIDES for f in ("Thumb", "Index", "Middle", "Ring", "Little")
       for p in ("Proximal", "Medial", "Distal", "Tip")]
)  # fmt: skip

_R = math.sqrt(0.5)
#: Studio's T-pose: each bone's world rotation ``x y z w`` in Studio's axes (the Unity
#: plugin's ``SmartsuitTPose``, its 0.707 read as sqrt(1/2)).
TPOSE = {"hip": (0, 0, 0, 1), "spine": (0, 0, 1, 0), "chest": (0, 0, 1, 0),
         "neck": (0, 0, 1, 0), "head": (0, 0, 1, 0),
         "leftShoulder": (0, 0, _R, -_R), "rightShoulder": (0, 0, _R, _R),
         "leftUpLeg": (0, _R, 0, _R), "rightUpLeg": (0, -_R, 0, _R),
         "leftLeg": (0, _R, 0, _R), "rightLeg": (0, -_R, 0, _R),
         "leftFoot": (0, _R, -_R, 0), "rightFoot": (0, -_R, _R, 0),
         "leftToe": (0, _R, -_R, 0), "rightToe": (0, -_R, _R, 0)}  # fmt: skip
for _b in ("UpperArm", "LowerArm", "Hand"):
    TPOSE.update({f"left{_b}": (-0.5, -0.5, 0.5, -0.5), f"right{_b}": (0.5, -0.5, 0.5, 0.5)})

_FULL = {"center_hip": "hip", "middle_chest": "spine", "upper_chest": "chest", "head": "head"}
for _s in _SIDES:
    _FULL.update({f"{_s}_hip": f"{_s}UpLeg", f"{_s}_knee": f"{_s}Leg",
                  f"{_s}_ankle": f"{_s}Foot", f"{_s}_shoulder": f"{_s}UpperArm",
                  f"{_s}_elbow": f"{_s}LowerArm", f"{_s}_wrist": f"{_s}Hand"})  # fmt: skip
#: The built-in joint maps of a Rokoko body (our joint -> bone), after ``--joint-map``'s:
#: all 16 joints; the paper's 8.
JOINT_MAPS = (_FULL, {j: _FULL[j] for j in PAPER_JOINTS})

_ORDER = "XYZ"  # the built skeleton's rotation order, written Zrotation Yrotation Xrotation
#: A motion line: 17 significant digits read back to the same float (repr's shortest text
#: takes twice as long to find).


def studio_to_fpdtw(p, q_xyzw):
    """Studio's (Unity's) position (..., 3) and quaternion ``x y z w`` (..., 4) in fpdtw's
    axes: ``(-x, y, z)`` and ``(w, x, -y, -z)``.

    The mirror ``M = diag(-1, 1, 1)`` makes Unity's left-handed Y-up axes right-handed with
    the same up and forward; a rotation ``R`` becomes ``M R M``, about ``M a`` by ``-theta``,
    i.e. about ``-M a`` by ``theta``."""
    p = np.asarray(p, dtype=float)
    q = np.asarray(q_xyzw, dtype=float)
    return p * [-1.0, 1.0, 1.0], np.stack([q[..., 3], q[..., 0], -q[..., 1], -q[..., 2]], -1)


_TPOSE_F = quat_normalize(studio_to_fpdtw(np.zeros(3), np.array([TPOSE[b] for b in BONES]))[1])
_TPOSE_C = quat_conj(_TPOSE_F)
_MIRROR_ORDER, _MIRROR = [0, 1, 2, 6, 3, 4, 5], np.array([-1.0, 1, 1, 1, 1, -1, -1])

# quat_mul's term k of part o (w x y z) is a_k b_(o xor k) times a sign
_XOR = np.arange(4)[None, :] ^ np.arange(4)[:, None]
_SIGNS = np.array([[1, 1, 1, 1], [-1, 1, -1, 1], [-1, 1, 1, -1], [-1, -1, 1, 1.0]])
_CONJ_SIGNS = _SIGNS * [[1.0], [-1], [-1], [-1]]  # a's x y z negated first


def _qmul(a, b, signs=_SIGNS):
    """:func:`~fpdtw.motion.rotations.quat_mul` of (n, 4) quaternions bit for bit (the same
    products, negated exactly, summed in the same order), in a few array operations;
    ``signs=_CONJ_SIGNS``: ``quat_conj(a) * b``."""
    t = a[:, :, None] * b[:, _XOR] * signs
    return t[:, 0] + t[:, 1] + t[:, 2] + t[:, 3]


def _normalize(q):
    """:func:`~fpdtw.motion.rotations.quat_normalize` of (n, 4) quaternions, bit for bit."""
    return q / np.sqrt(np.add.reduce(q * q, axis=-1, keepdims=True))


class RokokoSkeleton:
    """An actor's skeleton, from its first complete frame.

    Parameters
    ----------
    p, d : ndarray
        The 21 bones' positions (21, 3) and rotations from the T-pose ``D`` (21, 4, ``w x y
        z``), fpdtw's axes, in the order of :data:`BONES`.
    rate : float
        The stream's rate (the header's ``Frame Time``).

    Attributes
    ----------
    header : list of str
        Its BVH header: joints named as :data:`BONES`, depth first from the hip.
    order : list of int
        The bones' indices in the header's order.
    """

    def __init__(self, p, d, rate: float):
        offsets = quat_rotate(quat_conj(d[_PARENT0]), p - p[_PARENT0])  # the root's: unused
        self.header, self.order = bvh_header(BONES, _PARENT, offsets, rate)
        self._order = np.asarray(self.order, dtype=np.int64)

    def row(self, p, d) -> np.ndarray:
        """The BVH channel values (n_channels,) float64 of a frame: (21, 3) positions, (21, 4)
        rotations ``D``."""
        d = _normalize(d)
        local = _qmul(d[_PARENT0], d, _CONJ_SIGNS)
        local[0] = d[0]
        e = quat_to_euler(local[self.order], _ORDER)  # [:, ::-1]: Z Y X, as the channels
        return np.concatenate([p[0], e[:, ::-1].ravel()])

    def row_of(self, v) -> np.ndarray:
        """``row(*rest_relative(v))`` of a frame's bones ``v`` (21, 7), in one compiled call
        (:func:`_frame_row`; equal bit for bit, tested)."""
        out = np.empty(3 + 3 * len(BONES))
        _frame_row(np.ascontiguousarray(v, dtype=np.float64), self._order, _KERNEL, out)
        return out


def rest_relative(v):
    """A frame's bones (21, 7: Studio's ``x y z`` and ``x y z w``) as fpdtw's positions
    (21, 3) and rotations from the T-pose ``D = R T^-1`` (21, 4)."""
    pq = v[:, _MIRROR_ORDER] * _MIRROR  # studio_to_fpdtw's -x y z and w x -y -z
    return pq[:, :3], _qmul(_normalize(pq[:, 3:]), _TPOSE_C)


#: What :func:`_frame_row` reads besides a frame: the T-pose's conjugates, the parents, the
#: mirror's columns and signs, quat_mul's terms and signs, and :func:`euler_kernel`.
_KERNEL = (_TPOSE_C, np.asarray(_PARENT0, np.int64), np.array(_MIRROR_ORDER), _MIRROR, _XOR,
           _SIGNS, _CONJ_SIGNS, euler_kernel(_ORDER))  # fmt: skip


@numba.njit(cache=True)
def _quats(q, b, parent, xor, signs, out):  # pragma: no cover - compiled
    """``_qmul(q[parent], b, signs)`` (``parent`` None: ``_qmul(q, b, signs)``) into out."""
    for n in range(q.shape[0]):
        r = n if parent is None else parent[n]
        for o in range(4):
            acc = (q[r, 0] * b[n, xor[0, o]]) * signs[0, o]
            for k in range(1, 4):
                acc = acc + (q[r, k] * b[n, xor[k, o]]) * signs[k, o]
            out[n, o] = acc


@numba.njit(cache=True)
def _unit(q):  # pragma: no cover - compiled
    """:func:`_normalize`: each row over the root of its squares summed left to right."""
    out = np.empty_like(q)
    for n in range(q.shape[0]):
        s = ((q[n, 0] * q[n, 0] + q[n, 1] * q[n, 1]) + q[n, 2] * q[n, 2]) + q[n, 3] * q[n, 3]
        r = np.sqrt(s)
        for c in range(4):
            out[n, c] = q[n, c] / r
    return out


@numba.njit(cache=True)
def _frame_row(v, order, kernel, out):  # pragma: no cover - compiled
    """:func:`rest_relative` then :meth:`RokokoSkeleton.row`, their operations in their
    order, into ``out``."""
    tpose_c, parent, cols, mirror, xor, signs, conj_signs, euler = kernel
    n = v.shape[0]
    pq = np.empty((n, 7))
    for i in range(n):
        for c in range(7):
            pq[i, c] = v[i, cols[c]] * mirror[c]
    d = np.empty((n, 4))
    _quats(_unit(pq[:, 3:]), tpose_c, None, xor, signs, d)
    d = _unit(d)
    local = np.empty((n, 4))
    _quats(d, d, parent, xor, conj_signs, local)
    local[0] = d[0]
    e = np.empty((order.shape[0], 3))
    euler_into(local[order], euler, e)
    out[0], out[1], out[2] = pq[0, 0], pq[0, 1], pq[0, 2]
    for r in range(order.shape[0]):
        out[3 + 3 * r], out[4 + 3 * r], out[5 + 3 * r] = e[r, 2], e[r, 1], e[r, 0]


# -- reading ---------------------------------------------------------------------------------


class Refused(Exception):
    """A datagram or actor that cannot be read: ``(kind of BAD_KINDS, what)``."""


def nesting(data: bytes) -> int:
    """The deepest nesting of objects and arrays in JSON text ``data`` (strings skipped; a
    string cut at the end runs to it)."""
    return int(_nesting(np.frombuffer(data, np.uint8)))


@numba.njit(cache=True)
def _past_string(b, i):  # pragma: no cover - compiled
    """Where to read on after the JSON string opening at ``b[i]``: past its closing quote, its
    escapes (``\\`` then any byte but a newline) skipped; a lone backslash ends the string
    there (read on from it as text)."""
    i += 1
    while i < len(b) and b[i] != 34:
        if b[i] == 92:
            if i + 1 == len(b) or b[i + 1] == 10:
                return i
            i += 1
        i += 1
    return i + 1


@numba.njit(cache=True)
def _nesting(b):  # pragma: no cover - compiled
    depth = deepest = 0
    i, n = 0, len(b)
    while i < n:
        c = b[i]
        if c == 34:  # '"': the string skipped
            i = _past_string(b, i)
            continue
        elif c == 123 or c == 91:  # '{' '['
            depth += 1
            deepest = max(deepest, depth)
        elif c == 125 or c == 93:  # '}' ']'
            depth -= 1
        i += 1
    return deepest


@numba.njit(cache=True)
def _scan(v, big, tol):  # pragma: no cover - compiled
    """:func:`read_body`'s checks of bones ``v`` (n, 7) at once: the first row with a value
    beyond ``big`` or NaN (n: none), and whether a row before it has a squared quaternion
    norm (components clipped to 2) further than ``tol`` from 1."""
    j = v.shape[0]
    for r in range(v.shape[0]):
        for c in range(7):
            if not abs(v[r, c]) <= big:
                j = min(j, r)
    suspect = False
    for r in range(j):
        s = 0.0
        for c in range(3, 7):
            x = min(abs(v[r, c]), 2.0)
            s += x * x
        if abs(s - 1.0) > tol:
            suspect = True
    return j, suspect


def _constant(name):
    raise Refused("finite", f"JSON {name}, not a finite number")


def _int(text: str):
    return int(text) if len(text) < 19 else float(text)  # a long one: no int's digit limit


def _number(x) -> bool:
    return isinstance(x, int | float) and not isinstance(x, bool)


_JSON = json.JSONDecoder(parse_constant=_constant, parse_int=_int)


def read_datagram(data: bytes, big=None) -> tuple:
    """A datagram checked as JSON v3: ``(fps or None, timestamp, actors)``, the actors as
    sent (dicts); :class:`Refused` naming what is wrong. ``big``: the value limit (default
    :func:`fpdtw.limits.get` of ``max_abs_value``)."""
    if len(data) > MAX_DATAGRAM:
        raise Refused("oversize", f"{len(data)} bytes, more than {MAX_DATAGRAM}")
    if data[:4] == LZ4_MAGIC:
        raise Refused("lz4", "an LZ4 frame (Studio's compressed JSON), which fpdtw does not "
                      "read: choose uncompressed JSON v3 in Studio's Custom streaming")  # fmt: skip
    if (depth := nesting(data)) > MAX_DEPTH:
        raise Refused("rokoko", f"JSON nested {depth} deep, more than {MAX_DEPTH}")
    try:  # orjson reads as the standard library does (tested), in a fourth of its time ...
        doc = orjson.loads(data)
    except orjson.JSONDecodeError:  # ... but refuses NaN, 1e400, UTF-16, a BOM: json reads them
        try:
            doc = _JSON.decode(data.decode(json.detect_encoding(data), "surrogatepass"))
        except (ValueError, RecursionError) as e:  # UnicodeDecodeError is a ValueError
            raise Refused("rokoko", f"not JSON ({str(e).splitlines()[0][:80]})") from None
    version = doc.get("version") if isinstance(doc, dict) else None
    major = (int(version) if _number(version) and math.isfinite(version) else
             int(m[1]) if isinstance(version, str) and (m := re.fullmatch(
                 r"\s*(\d{1,3})(?:[.,]\d{1,6})?\s*", version)) else None)  # fmt: skip
    if major != 3:
        raise Refused("rokoko", f"version {str(version)[:20]!r}, not JSON v3")
    scene = doc.get("scene")
    if not isinstance(scene, dict) or not isinstance(actors := scene.get("actors"), list):
        raise Refused("rokoko", "no scene with a list of actors")
    t = scene.get("timestamp")
    big = limits.get("max_abs_value") if big is None else big
    if not _number(t) or not math.isfinite(t) or abs(t) > big:
        raise Refused("rokoko", f"scene.timestamp {str(t)[:20]} is not a finite time")
    if len(actors) > MAX_ACTORS:
        raise Refused("rokoko", f"{len(actors)} actors, more than {MAX_ACTORS}")
    fps = doc.get("fps")
    return (fps if _number(fps) and 1 <= fps <= 1000 else None), float(t), actors


def actor_name(actor) -> str:
    """An actor's name (:class:`Refused` when it has none)."""
    name = actor.get("name") if isinstance(actor, dict) else None
    if not isinstance(name, str) or not name or len(name) > MAX_NAME:
        raise Refused("name", f"an actor whose name {str(name)[:40]!r} is not a string of 1 to "
                      f"{MAX_NAME} characters")  # fmt: skip
    return name


_INDEX = {b: i for i, b in enumerate(BONES)}
_IN_ORDER = list(range(len(BONES)))
_XYZ, _XYZW, _REAL = itemgetter("x", "y", "z"), itemgetter("x", "y", "z", "w"), {int, float}


def _no_numbers(name) -> Refused:
    """The refusal of a bone without seven numbers."""
    return Refused("number", f"bone {name!r} without numbers position x y z and rotation x y z w")


def read_body(actor, big=None) -> np.ndarray:
    """An actor's 21 body bones checked: (21, 7) float, Studio's ``x y z`` and ``x y z w``
    in the order of :data:`BONES` (:class:`Refused` naming the first problem); ``big``: as
    :func:`read_datagram`'s."""
    body = actor.get("body")
    if not isinstance(body, dict):
        raise Refused("missing", "no body")
    if len(body) > MAX_BONES:
        raise Refused("bone", f"{len(body)} bones, more than {MAX_BONES}")
    big = limits.get("max_abs_value") if big is None else big
    names, flat, stop = [], [], None  # the bones read up to the first not read (stop)
    for name, bone in body.items():
        if name in OTHER_BONES:
            continue
        if name not in _INDEX:
            stop = Refused("bone", f"bone {name[:40]!r} is not one of Rokoko's body bones")
            break
        try:
            flat += _XYZ(bone["position"]) + _XYZW(bone["rotation"])
        except (TypeError, KeyError, IndexError):  # not objects, or without the fields
            stop = _no_numbers(name)
            break
        names.append(name)
    if not set(map(type, flat)) <= _REAL:  # a bool, a string, ...: the first such bone
        if bad := [i // 7 for i, x in enumerate(flat) if not _number(x)]:
            stop = _no_numbers(names[bad[0]])
            del flat[7 * bad[0] :], names[bad[0] :]
    # each bone's checks in turn, all bones at once: the first that fails is refused
    v = np.array(flat, dtype=float).reshape(-1, 7)
    # j: the first bone with a value beyond big (NaN: not <=); a bone before it whose
    # squared norm (of components clipped to 2, which cannot overflow) is further than
    # 0.99 tol from 1 may have a norm further than tol from 1: each is then checked as one
    j, suspect = _scan(v, big, 0.99 * UNIT_TOLERANCE)
    for i in range(j) if suspect else ():
        if abs((norm := float(np.linalg.norm(v[i, 3:]))) - 1.0) > UNIT_TOLERANCE:
            raise Refused("rotation", f"bone {names[i]!r}'s quaternion has norm {norm:.6g}")
    if j < len(v):  # inf: a number past float's
        raise Refused("large", f"bone {names[j]!r} has a value beyond {big:g} "
                      f"({limits.env_name('max_abs_value')})")  # fmt: skip
    if stop is not None:
        raise stop
    if len(names) < len(BONES):
        lacks = ", ".join([b for b in BONES if b not in body][:4])
        raise Refused("missing", f"the body lacks {lacks}")
    order = [_INDEX[b] for b in names]
    return v if order == _IN_ORDER else v[np.argsort(order)]


# -- a sender's next datagrams, read from their numbers -----------------------------------------

#: 10**0 .. 10**22, each an exact double (Clinger's fast path).
_POW10 = np.array([10.0**k for k in range(23)])


@numba.njit(cache=True)
def _number_spans(b, spans):  # pragma: no cover - compiled
    """The number tokens of JSON text ``b`` (uint8) outside its strings
    (:func:`_past_string`) into ``spans`` (m, 2) int64, start and end: ``(count or -1 when
    more than m, the colons outside strings)``."""
    n, k, colons, i = len(b), 0, 0, 0
    while i < n:
        c = b[i]
        if c == 34:
            i = _past_string(b, i)
            continue
        elif c == 58:
            colons += 1
        elif c == 45 or 48 <= c <= 57:
            if k == spans.shape[0]:
                return -1, colons
            j = i + 1
            while j < n and (48 <= b[j] <= 57 or b[j] in (43, 45, 46, 69, 101)):
                j += 1
            spans[k, 0], spans[k, 1] = i, j
            k += 1
            i = j
            continue
        i += 1
    return k, colons


@numba.njit(cache=True)
def _json_number(b, s, e):  # pragma: no cover - compiled
    """JSON number ``b[s:e]`` as Python's ``float`` of what the JSON readers give (an integer
    as ``float(int)``: ``-0`` is ``0.0``), by Clinger's exact fast path: at most 15
    significant digits and a power of ten up to 22, one correctly rounded multiply or divide;
    NaN for anything else (not a JSON number, or not readable so)."""
    i, neg, m, digits, exp, whole = s, False, 0, 0, 0, True
    if i < e and b[i] == 45:
        neg, i = True, i + 1
    if i == e or not 48 <= b[i] <= 57 or (b[i] == 48 and i + 1 < e and 48 <= b[i + 1] <= 57):
        return np.nan
    while i < e and 48 <= b[i] <= 57:
        digits += m > 0 or b[i] != 48
        m, i = m * 10 + (b[i] - 48), i + 1
    if i < e and b[i] == 46:
        whole, i = False, i + 1
        if i == e or not 48 <= b[i] <= 57:
            return np.nan
        while i < e and 48 <= b[i] <= 57:
            digits += m > 0 or b[i] != 48
            m, exp, i = m * 10 + (b[i] - 48), exp - 1, i + 1
            if digits > 15:
                return np.nan
    if i < e and (b[i] == 101 or b[i] == 69):
        whole, i, sign = False, i + 1, 1
        if i < e and (b[i] == 43 or b[i] == 45):
            sign, i = (-1 if b[i] == 45 else 1), i + 1
        if i == e or not 48 <= b[i] <= 57:
            return np.nan
        x = 0
        while i < e and 48 <= b[i] <= 57:
            x, i = x * 10 + (b[i] - 48), i + 1
            if x > 999:
                return np.nan
        exp += sign * x
    if i != e or digits > 15 or not -22 <= exp <= 22:
        return np.nan
    v = float(m) * _POW10[exp] if exp >= 0 else float(m) / _POW10[-exp]
    return v if not neg or (whole and m == 0) else -v


@numba.njit(cache=True)
def _by_template(b, text, tspans, want, spans, out):  # pragma: no cover - compiled
    """Whether JSON text ``b`` has the bytes of ``text`` (a sender's last datagram read)
    outside its number tokens (``tspans``), every token of it read by :func:`_json_number`;
    if so the tokens ``want`` into ``out``. ``spans``: (len(tspans) + 1, 2) int64 room."""
    k, _ = _number_spans(b, spans)
    if k != tspans.shape[0]:
        return False
    at_b = at_t = 0
    for t in range(k + 1):
        end_b = spans[t, 0] if t < k else len(b)
        end_t = tspans[t, 0] if t < k else len(text)
        if end_b - at_b != end_t - at_t:
            return False
        for x in range(end_b - at_b):
            if b[at_b + x] != text[at_t + x]:
                return False
        if t < k:
            at_b, at_t = spans[t, 1], tspans[t, 1]
    values = np.empty(k)
    for t in range(k):
        values[t] = _json_number(b, spans[t, 0], spans[t, 1])
        if np.isnan(values[t]):
            return False
    for r in range(want.shape[0]):
        out[r] = values[want[r]]
    return True


def _numbers_of(x, path, out) -> int:
    """The numbers of a JSON document in its text's order, ``(path, value)`` into ``out``;
    the members of its objects counted."""
    members = 0
    if isinstance(x, dict):
        members = len(x)
        for k, v in x.items():
            members += _numbers_of(v, (*path, k), out)
    elif isinstance(x, list):
        for i, v in enumerate(x):
            members += _numbers_of(v, (*path, i), out)
    elif _number(x):
        out.append((path, float(x)))
    return members


class _Template:
    """Where a sender's last datagram (read and taken whole) has its timestamp, ``fps``,
    version and each actor's bone values among its number tokens, for :func:`_by_template`:
    None when that cannot be told for sure (then every datagram is read in full)."""

    def __new__(cls, data: bytes):
        try:  # read as read_datagram has just read it; every body as read_body reads it
            doc = orjson.loads(data)
            actors = doc["scene"]["actors"]
            names = [actor_name(a) for a in actors]
            for a in actors:
                read_body(a, np.inf)
        except (orjson.JSONDecodeError, KeyError, TypeError, Refused):
            return None
        found = []
        members = _numbers_of(doc, (), found)
        text = np.frombuffer(data, np.uint8)
        spans = np.empty((len(found) + 1, 2), np.int64)
        k, colons = _number_spans(text, spans)
        if k != len(found) or colons != members or len(set(names)) != len(names):
            return None  # a key twice, or a token not a number read
        read = np.array([_json_number(text, a, b) for a, b in spans[:k]])
        if not np.array_equal(read.view(np.int64), np.array([v for _, v in found]).view(np.int64)):
            return None  # a token read otherwise (or not at all) than the document holds it
        index = {path: i for i, (path, _) in enumerate(found)}
        extra = [index.get(("version",), -1), index.get(("scene", "timestamp"), -1),
                 index.get(("fps",), -1)]  # fmt: skip
        parts = [(part, c) for part, axes in (("position", "xyz"), ("rotation", "xyzw"))
                 for c in axes]  # fmt: skip
        bones = [index.get(("scene", "actors", a, "body", b, *part), -1)
                 for a in range(len(actors)) for b in BONES for part in parts]  # fmt: skip
        if -1 in bones or extra[1] < 0:
            return None
        self = super().__new__(cls)
        self.text, self.tspans, self.names = text, spans[:k].copy(), names
        self.want = np.array([max(i, 0) for i in extra] + bones, np.int64)
        self.version_read, self.fps_read = extra[0] >= 0, extra[2] >= 0
        fps = doc.get("fps")
        self.fps = fps if _number(fps) and 1 <= fps <= 1000 else None
        self.spans, self.out = np.empty((k + 1, 2), np.int64), np.empty(len(self.want))
        return self

    def read(self, data: bytes, big: float):
        """What :func:`read_datagram` and :func:`read_body` read of a datagram of this
        template, ``(fps or None, timestamp, [(name, bones (21, 7))])``, when its every
        checked value surely passes; False when one may not, None when the datagram is not
        of this template."""
        if len(data) > MAX_DATAGRAM or not _by_template(
            np.frombuffer(data, np.uint8), self.text, self.tspans, self.want, self.spans, self.out
        ):
            return None
        v, t = self.out, float(self.out[1])
        if (self.version_read and not 3.0 <= v[0] < 4.0) or not abs(t) <= big:
            return False
        fps = self.fps
        if self.fps_read:
            fps = v[2] if 1 <= v[2] <= 1000 else None
        bodies = v[3:].reshape(len(self.names), len(BONES), 7)
        for body in bodies:
            j, suspect = _scan(body, big, 0.99 * UNIT_TOLERANCE)
            if j < len(BONES) or suspect:
                return False
        return fps, t, list(zip(self.names, bodies.copy(), strict=True))


class _Actor:
    """One actor name: its performer and its times."""

    def __init__(self, name, addr):
        self.name, self.addr = name, sender_name(addr)
        self.perf = self.skeleton = self.t0 = self.last_t = None
        self.refused = False


class Source(DatagramSource):
    """Listens for Rokoko Studio's custom streaming, one take at a time (see the module's
    docstring).

    Parameters
    ----------
    host, port : str, int
        Where to listen (UDP).
    rate : float, optional
        The stream's rate (``--rate``); default: the first datagram's ``fps``, else
        :data:`DEFAULT_RATE`. The period a gap is measured in.
    header : None
        Not used: the skeleton comes from the stream (ValueError when given).
    """

    scheme = "rokoko"
    skeleton_from = "the bones sent"
    DEFAULT_RATE = DEFAULT_RATE  # the module's

    def __init__(self, host: str, port: int, *, rate=None, header=None):
        super().__init__(host, port, rate=rate, header=header)
        self.rate_given = rate is not None
        self.begin_take()

    def warm_up(self) -> None:
        super().warm_up()
        v = np.zeros((len(BONES), 7))
        v[:, 6] = 1.0
        RokokoSkeleton(*rest_relative(v), self.rate).row_of(v)
        _scan(v, float(self._big), 1.0)
        nesting(b"{}")
        text, spans = np.frombuffer(b"[1]", np.uint8), np.zeros((1, 2), np.int64)
        _number_spans(text, spans)
        _json_number(text, spans[0, 0], spans[0, 1])
        _by_template(text, text, spans, np.zeros(1, np.int64), np.empty((2, 2), np.int64),
                     np.empty(1))  # fmt: skip

    def begin_take(self) -> None:
        self.actors, self.templates = {}, {}  # actor name -> _Actor; address -> _Template
        self._big = limits.get("max_abs_value")  # the limits in force when a take starts

    def datagram(self, data: bytes, addr, arrival: float, performers) -> None:
        """One datagram: checked, then each of its actors' frames aligned (or counted)."""
        self.n += 1
        where = f"datagram {self.n} from {sender_name(addr)}"
        template = self.templates.get(addr)
        read = None if template is None else template.read(data, self._big)
        if read:
            fps, t, actors = read
        else:
            try:
                fps, t, actors = read_datagram(data, self._big)
            except Refused as e:
                performers.frames += 1
                return performers.count_bad(None, e.args[0], f"{where}: {e.args[1]}")
            if read is None and (template is not None or len(self.templates) < MAX_ACTORS):
                self.templates[addr] = _Template(data)  # the sender's datagrams changed
        seen = set()
        for actor in actors:
            performers.frames += 1
            if read:
                name, actor = actor  # its bones, read
            else:
                try:
                    name = actor_name(actor)
                except Refused as e:
                    performers.count_bad(None, e.args[0], f"{where}: {e.args[1]}")
                    continue
            a = self.actors.get(name)
            if a is None:
                if len(self.actors) >= MAX_ACTORS:
                    performers.count_bad(None, "refused", f"{where}: actor {name!r}: more "
                                         f"than {MAX_ACTORS} actor names")  # fmt: skip
                    continue
                a = self.actors[name] = _Actor(name, addr)
            self.frame(a, actor, name in seen, fps, t, arrival, f"{where} (time {t!r} s)",
                       performers)  # fmt: skip
            seen.add(name)
        return None

    def frame(self, a, actor, twice, fps, t, arrival, where, performers) -> None:
        """One actor's frame of a datagram: checked, then aligned (or counted)."""
        if a.refused:
            return performers.count_bad(None, "refused", f"{where}: actor {a.name!r} refused")
        if twice:
            return performers.count_bad(a.perf, "duplicate", f"{where}: actor {a.name!r} "
                                        "twice in one datagram")  # fmt: skip
        try:
            v = actor if isinstance(actor, np.ndarray) else read_body(actor, self._big)
        except Refused as e:
            return performers.count_bad(a.perf, e.args[0], f"{where}: actor {a.name!r}: "
                                        f"{e.args[1]}")  # fmt: skip
        if a.last_t is not None and t <= a.last_t:
            kind = "duplicate" if t == a.last_t else "order"
            return performers.count_bad(a.perf, kind, f"{where}: not after the previous "
                                        f"frame's {a.last_t!r} s")  # fmt: skip
        if a.perf is None:
            p, d = rest_relative(v)
            rate = self.rate if self.rate_given or fps is None else float(fps)
            a.skeleton = RokokoSkeleton(p, d, rate)
            about = (f"{len(BONES)} bones, from {a.addr}, frames timed by scene.timestamp, "
                     f"{rate:g} Hz")  # fmt: skip
            key = sum(1 for x in self.actors.values() if x.perf is not None)
            a.perf = performers.add(key, a.name, a.skeleton.header, rate, about)
            if a.perf is None:
                a.refused = True
                return None
            a.t0 = t
        a.last_t = t
        performers.feed(a.perf, a.skeleton.row_of(v), arrival, t=t - a.t0)
        return None


# -- Studio, without hardware ------------------------------------------------------------------

# The encoder below is written from the layout on its own (its own bone table, the T-pose
# as the Blender plugin lists it, its own axis conversion and JSON text), not as the reader
# run backwards, so that a misreading of one shows in the other.

#: The emulator: Rokoko bone -> (its parent, Studio's T-pose rotation ``w x y z`` as the
#: Blender plugin lists it, names of the rig joint playing it, the first the rig has).
RIG_BONES = {
    "hip": (None, (-1.0, 0.0, 0.0, 0.0), ("hip", "root", "Hips", "Pelvis")),
    "spine": ("hip", (0.0, 0.0, 0.0, -1.0), ("upperback", "Spine1", "Spine")),
    "chest": ("spine", (0.0, 0.0, 0.0, -1.0), ("thorax", "Spine2", "Chest")),
    "neck": ("chest", (0.0, 0.0, 0.0, -1.0), ("lowerneck", "Neck")),
    "head": ("neck", (0.0, 0.0, 0.0, -1.0), ("head", "Head")),
}
for _c, _side, _sg in (("l", "Left", 1.0), ("r", "Right", -1.0)):
    _b, _arm, _leg = _side.lower(), (-0.5 * _sg, -0.5 * _sg, -0.5, 0.5), (_R, 0.0, _R * _sg, 0.0)
    _foot, _sh = (0.0, 0.0, _R * _sg, -_R * _sg), (-_R * _sg, 0.0, 0.0, _R)
    RIG_BONES.update({
        f"{_b}Shoulder": ("chest", _sh, (f"{_c}clavicle", f"{_side}Shoulder")),
        f"{_b}UpperArm": (f"{_b}Shoulder", _arm, (f"{_c}humerus", f"{_side}Arm")),
        f"{_b}LowerArm": (f"{_b}UpperArm", _arm, (f"{_c}radius", f"{_side}ForeArm")),
        f"{_b}Hand": (f"{_b}LowerArm", _arm, (f"{_c}wrist", f"{_side}Hand")),
        f"{_b}UpLeg": ("hip", _leg, (f"{_c}femur", f"{_side}UpLeg")),
        f"{_b}Leg": (f"{_b}UpLeg", _leg, (f"{_c}tibia", f"{_side}Leg")),
        f"{_b}Foot": (f"{_b}Leg", _foot, (f"{_c}foot", f"{_side}Foot")),
        f"{_b}Toe": (f"{_b}Foot", _foot, (f"{_c}toes", f"{_side}ToeBase")),
    })  # fmt: skip


def fpdtw_to_studio(p, q_wxyz):
    """fpdtw's position (..., 3) and quaternion ``w x y z`` (..., 4) in Studio's (Unity's)
    left-handed axes: X mirrored; the quaternion as ``x y z w``."""
    p, q = np.asarray(p, dtype=float), np.asarray(q_wxyz, dtype=float)
    return p * [-1.0, 1.0, 1.0], np.stack([q[..., 1], -q[..., 2], -q[..., 3], q[..., 0]], -1)


def studio_bones(motion) -> tuple:
    """A motion as Studio streams an actor: ``(rate, names, p, q)``: the 21 Rokoko bones,
    their world positions (F, 21, 3) and world rotations ``x y z w`` (F, 21, 4) in Studio's
    axes: the rig's rotation from its rest pose, then Studio's T-pose rotation of the bone.
    A bone the rig lacks is where its parent bone is, turned as it (ValueError without
    hips)."""
    sk = motion.skeleton
    found = resolve_joint_map(sk.joint_names, {b: n for b, (_, _, n) in RIG_BONES.items()})
    if "hip" not in found:
        raise ValueError(f"no hips among {', '.join(sk.joint_names[:8])}...")
    pos, rot = motion.forward_kinematics()
    rot = quat_mul(rot, quat_conj(rest_rotations(motion))[None])
    here = {}  # bone -> the rig joint playing it (or its parent bone's)
    for b, (parent, _, _) in RIG_BONES.items():  # parents come first
        here[b] = list(sk.joint_names).index(found[b]) if b in found else here[parent]
    index = list(here.values())
    p, d = fpdtw_to_studio(pos[:, index], rot[:, index])  # the rotation from rest, x y z w
    tpose = np.array([t for _, t, _ in RIG_BONES.values()])  # w x y z
    q = quat_mul(np.roll(d, 1, axis=-1), tpose[None])  # from rest, after the T-pose
    return motion.fps, list(RIG_BONES), p, np.roll(q, -1, axis=-1)


def _f32(x) -> str:
    return str(np.float32(x))  # a float32 as its shortest text that reads back to it


def v3_datagram(timestamp: float, fps: float, actors) -> bytes:
    """One frame as Studio's JSON v3 text (UTF-8): ``actors`` a list of ``(name, {bone: (p
    (3,), q x y z w (4,))})``; every number a float32."""
    parts = []
    for k, (name, bones) in enumerate(actors):
        body = ",".join(
            f'"{b}":{{"position":{{"x":{_f32(p[0])},"y":{_f32(p[1])},"z":{_f32(p[2])}}},'
            f'"rotation":{{"x":{_f32(q[0])},"y":{_f32(q[1])},"z":{_f32(q[2])},'
            f'"w":{_f32(q[3])}}}}}'
            for b, (p, q) in bones.items()
        )
        parts.append(
            f'{{"name":{json.dumps(name)},"color":{{"r":{40 * k % 256},"g":200,"b":120}},'
            '"meta":{"hasGloves":false,"hasLeftGlove":false,"hasRightGlove":false,'
            '"hasBody":true,"hasFace":false},'
            '"dimensions":{"totalHeight":1.8,"hipHeight":1.0},'
            f'"body":{{{body}}}}}'
        )
    text = (f'{{"version":3,"fps":{fps:g},"scene":{{"timestamp":{_f32(timestamp)},'
            f'"actors":[{",".join(parts)}],"props":[]}}}}')  # fmt: skip
    return text.encode("utf-8")


def rokoko_datagrams(motions, names=None) -> tuple:
    """The datagrams of ``motions`` streamed together: ``(rate, [datagram of frame k])``;
    take ``i`` is actor ``names[i]`` (default ``actor1``, ``actor2``, ...), frame ``k`` at
    scene time ``k / rate`` s (a take that has ended is no longer sent)."""
    takes = [studio_bones(m) for m in motions]
    rates = {r for r, *_ in takes}
    if len(rates) > 1:
        raise ValueError(f"takes at {sorted(rates)} Hz: play them at one --rate")
    rate = rates.pop()
    names = names or [f"actor{i + 1}" for i in range(len(takes))]
    out = []
    for k in range(max(len(p) for _, _, p, _ in takes)):
        actors = [
            (n, dict(zip(bones, zip(p[k], q[k], strict=True), strict=True)))
            for n, (_, bones, p, q) in zip(names, takes, strict=True)
            if k < len(p)
        ]
        out.append(v3_datagram(k / rate, rate, actors))
    return rate, out


def play_as_rokoko(motions, to: str, *, fast=False, out=None) -> int:
    """Send ``motions`` as Rokoko Studio's custom streaming sends actors to ``to``
    (``HOST:PORT``): one UDP socket, one JSON v3 datagram a frame holding every take's actor,
    frame ``k`` at ``k / rate`` (``fast``: one every millisecond). Return the datagrams sent."""
    rate, frames = rokoko_datagrams(motions)
    send_paced([[d] for d in frames], to, rate, fast=fast)
    if out is not None:
        print(f"sent {len(frames)} datagrams ({len(motions)} actors) to {to}", file=out)
    return len(frames)


__all__ = [
    "BONES", "DEFAULT_PORT", "DEFAULT_RATE", "JOINT_MAPS", "PARENTS", "RIG_BONES", "TPOSE",
    "Refused", "RokokoSkeleton", "Source", "actor_name", "fpdtw_to_studio", "nesting",
    "play_as_rokoko", "read_body", "read_datagram", "rest_relative", "rokoko_datagrams",
    "studio_bones", "studio_to_fpdtw", "v3_datagram"
]  # fmt: skip
