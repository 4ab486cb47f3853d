"""``axis+udp://HOST:PORT``: Axis Neuron's and Axis Studio's binary BVH broadcast over UDP.

Axis sends the datagrams (to port 7002 by default, as issue 32 says; the documents below do
not name a port), so fpdtw LISTENS on ``HOST:PORT`` and only reads. The scheme reads "Axis
over UDP" (as ``git+ssh`` names a protocol over a transport; RFC 3986 allows ``+`` in a
scheme), next to the text broadcast's ``axis://``; the emulator is ``fpdtw stream --as
axis+udp``, the same word on both sides. What follows is from Noitom's "NeuronDataReader
Runtime API Documentation" (b18, 20.01.2020; "the SDK document") and the SDK's
``DataType.h``, unless another source is named.

**Datagram.** A 64-byte header, the packed C struct ``BvhDataHeader`` (``#pragma pack(1)``):
``Token1`` uint16 ``0xDDFF``; ``DataVersion`` 4 bytes (build, revision, minor, major);
``DataCount`` uint16, the float values that follow; ``WithDisp`` and ``WithReference`` one byte
each; ``AvatarIndex`` uint32; ``AvatarName`` 32 bytes; ``FrameIndex`` uint32; three reserved
uint32 ("only enable this package has 64bytes length"); ``Token2`` uint16 ``0xEEFF``
(2+4+2+1+1+4+32+4+12+2 = 64). Then ``DataCount`` float32. The byte order is the SDK's
platforms' (x86, ARM: little-endian); no document names it. A managed reader of the same
stream (``NeuronDataReaderManaged``, commented out in a Perception Neuron Unity integration)
takes a header as valid when both tokens are, and a frame as ``64 + 4 * DataCount`` bytes.

**Values** (the SDK document, 1.2.1): with displacement each bone sends six floats, its X Y Z
displacement and its rotation ("default rotation order is Y X Z"); without, the root (Hips)
sends six and every other bone three. With reference, six values come first: a "Reference"
node, the parent of the root, whose displacement and pose place the whole skeleton. No bone
names go over the wire: the skeleton comes from ``--header FILE.bvh`` exactly as for
``axis://`` (:class:`fpdtw.app.source_axis.AxisHeader` and its ``wire_channels``), so both
Axis variants read the same values the same way.

**Axes.** None to convert: the values are the BVH channels of the ``--header`` skeleton, in
its world. Axis' BVH (the SDK document's Appendix B: Hips at ``OFFSET 0 84.102 0``, RightUpLeg
at ``-9.5 0 0``) is Y up, right-handed, the right side at -X (facing +Z): fpdtw's axes.

**What fpdtw makes of it.** A performer per avatar index (at most :data:`MAX_AVATARS` tracked,
``--max-clients`` aligned), named by its first datagram's avatar name; its layout (with or
without displacement) is its first frame's and must stay. Frame index ``f`` counts at ``(f -
f0) / rate`` (``rate`` the header's ``Frame Time``), so a lost datagram is a gap; an index
not after the last read is duplicated (equal) or reordered (older). A reference block is
composed into the root: its position ``t + R (o + p) - o`` (``o`` the root's OFFSET), its
rotation ``R Q``, written back in the root's rotation order; an all-zero reference is the
identity and leaves the values as sent.

:func:`play_as_axis_udp` is the other side without hardware (``fpdtw stream --as axis+udp``):
an encoder of the SDK's layout written apart from the reader (its own BVH walk, header
bytes and value order), each take an avatar, over one UDP socket.
"""

from __future__ import annotations

import struct

import numpy as np

from fpdtw import limits
from fpdtw.app.source_axis import AxisHeader
from fpdtw.app.sources import DatagramSource, send_paced, sender_name
from fpdtw.io.bvh import parse_bvh_header
from fpdtw.motion.rotations import euler_to_quat, quat_mul, quat_rotate, quat_to_euler

#: Axis' default port of the binary BVH broadcast over UDP.
DEFAULT_PORT = 7002
#: ``BvhDataHeader``: Token1, DataVersion, DataCount, WithDisp, WithReference, AvatarIndex,
#: AvatarName, FrameIndex, three reserved, Token2; little-endian, packed.
HEADER = struct.Struct("<H4sHBBI32sI3IH")
TOKEN1, TOKEN2 = 0xDDFF, 0xEEFF
#: Values of the reference block (the SDK document: "totally 6 value").
REFERENCE = 6
#: Avatar indices tracked in one take.
MAX_AVATARS = 64
assert HEADER.size == 64
_XYZ = ("xposition", "yposition", "zposition")


class _Avatar:
    """One avatar index of a take: its performer, layout and last frame index."""

    def __init__(self):
        self.perf = self.disp = self.f0 = self.last = None
        self.refused = False


class Source(DatagramSource):
    """Listens for Axis' binary BVH broadcast, one take at a time (see the module's docstring).

    Parameters
    ----------
    host, port : str, int
        Where to listen (UDP).
    header : str or os.PathLike
        The BVH file of the streamed skeleton (``--header``); its ``Frame Time`` is the rate.
    """

    scheme = "axis+udp"

    def __init__(self, host: str, port: int, *, header=None):
        if header is None:
            raise ValueError("axis+udp:// needs --header FILE.bvh: the stream carries no skeleton")
        self.host, self.port = host, port
        self.header = AxisHeader(header)
        self.rate = self.header.fps
        self.layouts = {}  # with displacement -> (values, BVH header lines)
        for n, (disp, lines) in sorted(self.header.counts.items()):
            self.layouts.setdefault(disp, (n, lines))
        if False not in self.layouts:  # one joint: both layouts are the same
            self.layouts[False] = self.layouts[True]
        #: A datagram longer than the largest frame the skeleton allows is oversized.
        self.max_datagram = HEADER.size + 4 * (max(self.header.counts) + REFERENCE)
        h = parse_bvh_header(self.layouts[True][1], self.header.path, stream=True)
        root = list(h.joints[0].channels)
        self.order = h.skeleton.rotation_orders[0]
        self.offset = h.skeleton.offsets[0]
        self.pcol = [root.index(c) for c in _XYZ]
        self.rcol = [root.index(f"{a}rotation") for a in "xyz" if f"{a}rotation" in root]

    def begin_take(self) -> None:
        self.avatars = {}

    def compose(self, ref, root):
        """The root's channels (6,) under a reference block (6,) laid out as they are."""
        if len(self.rcol) != 3:
            return root
        p, r = self.pcol, self.rcol
        qr, qh = euler_to_quat(ref[r], self.order), euler_to_quat(root[r], self.order)
        out = root.copy()
        out[p] = ref[p] + quat_rotate(qr, self.offset + root[p]) - self.offset
        out[r] = quat_to_euler(quat_mul(qr, qh), self.order)
        return out

    def datagram(self, data: bytes, addr, arrival: float, performers) -> None:
        """One datagram: one frame of one avatar, checked, then aligned (or counted)."""
        self.n += 1
        performers.frames += 1
        where = f"datagram {self.n} from {sender_name(addr)}"
        if len(data) > self.max_datagram:
            return performers.count_bad(None, "oversize", f"{where}: {len(data)} bytes, more "
                                        f"than {self.max_datagram}")  # fmt: skip
        if len(data) < HEADER.size:
            return performers.count_bad(None, "axisbin", f"{where}: {len(data)} bytes, "
                                        f"shorter than the {HEADER.size}-byte header")  # fmt: skip
        (t1, ver, count, disp, ref, index, name, frame, *_, t2) = HEADER.unpack_from(data)
        if (t1, t2) != (TOKEN1, TOKEN2):
            return performers.count_bad(None, "axisbin", f"{where}: tokens 0x{t1:04X} ... "
                                        f"0x{t2:04X}, not 0xDDFF ... 0xEEFF")  # fmt: skip
        if HEADER.size + 4 * count != len(data):
            rest = len(data) - HEADER.size
            return performers.count_bad(None, "axisbin", f"{where}: data count {count}, but "
                                        f"{rest} bytes follow the header")  # fmt: skip
        av = self.avatars.get(index)
        if av is None:
            if len(self.avatars) >= MAX_AVATARS:
                return performers.count_bad(None, "refused", f"{where}: more than "
                                            f"{MAX_AVATARS} avatar indices")  # fmt: skip
            av = self.avatars[index] = _Avatar()
        where = f"{where} (avatar {index}, frame index {frame})"
        if av.refused:
            return performers.count_bad(None, "refused", f"{where}: avatar {index} refused")
        disp, ref = bool(disp), bool(ref)
        told = f"{'with' if disp else 'without'} displacement{', with reference' * ref}"
        if av.disp is not None and disp != av.disp:
            return performers.count_bad(av.perf, "count", f"{where}: {told}, but the avatar "
                                        f"began {'with' if av.disp else 'without'}")  # fmt: skip
        n_values, lines = self.layouts[disp]
        expected = n_values + (REFERENCE if ref else 0)
        if count != expected:
            return performers.count_bad(av.perf, "count", f"{where}: {count} values {told}, "
                                        f"expected {expected} for the {self.header.n_joints} "
                                        f"joints of {self.header.path}")  # fmt: skip
        if av.last is not None and frame <= av.last:
            kind = "duplicate" if frame == av.last else "order"
            return performers.count_bad(av.perf, kind, f"{where}: not after the last frame "
                                        f"index read ({av.last})")  # fmt: skip
        av.last = frame
        x = np.frombuffer(data, dtype="<f4", count=count, offset=HEADER.size).astype(float)
        if not np.isfinite(x).all():
            k = int(np.flatnonzero(~np.isfinite(x))[0])
            return performers.count_bad(av.perf, "finite", f"{where}: value {k} is {x[k]}")
        big = limits.get("max_abs_value")
        if np.abs(x).max(initial=0.0) > big:
            return performers.count_bad(av.perf, "large", f"{where}: a value beyond {big:g} "
                                        f"({limits.env_name('max_abs_value')})")  # fmt: skip
        if ref:
            r, x = x[:REFERENCE], x[REFERENCE:]
            if r.any():
                x[:6] = self.compose(r, x[:6])
        if av.perf is None:
            who = name.split(b"\0")[0].decode("utf-8", "replace").strip() or f"avatar{index}"
            v = ".".join(str(b) for b in reversed(ver))
            about = f"{count} values a frame, {told}, data version {v}, from {sender_name(addr)}"
            av.perf = performers.add(index, who, lines, self.rate, about)
            if av.perf is None:
                av.refused = True
                return None
            av.disp, av.f0 = disp, frame
        performers.feed(av.perf, x, arrival, t=(frame - av.f0) / self.rate)
        return None


# -- the broadcast, without hardware ------------------------------------------------------------

# The encoder below is written from the SDK document on its own (its own walk of the BVH header,
# header bytes and value order), not as the reader run backwards.


def _joints(header_lines) -> list:
    """``[(name, offset, channels)]`` of a BVH header, in file order (End Sites skipped)."""
    out, depth, end_depth = [], 0, None
    for text in header_lines:
        tok = text.split()
        if not tok:
            continue
        key = tok[0].upper()
        if key in ("ROOT", "JOINT"):
            out.append([tok[1], None, []])
        elif key == "END":
            end_depth = depth
        elif key == "{":
            depth += 1
        elif key == "}":
            depth -= 1
            if end_depth is not None and depth == end_depth:
                end_depth = None
        elif key == "OFFSET" and end_depth is None and out[-1][1] is None:
            out[-1][1] = [float(v) for v in tok[1:4]]
        elif key == "CHANNELS" and end_depth is None:
            out[-1][2] = [c.lower() for c in tok[2:]]
        elif key == "MOTION":
            break
    return out


def axis_udp_datagrams(takes, *, displacement=False, reference=False, first_frame=0) -> tuple:
    """The datagrams of ``takes`` (:class:`fpdtw.app.stream.TakeLines`, avatars 0, 1, ...):
    ``(rate, [[bytes of frame k of each avatar] per k])``; frame ``k`` has FrameIndex
    ``first_frame + k``. With ``reference``, an all-zero reference block comes first."""
    takes = list(takes)
    rates = {t.fps for t in takes}
    if len(rates) > 1:
        raise ValueError(f"takes at {sorted(rates)} Hz: play them at one --rate")
    plans = []
    for take in takes:
        picks, col = [], 0
        for j, (_, offset, chans) in enumerate(_joints(take.header)):
            at = {c: col + k for k, c in enumerate(chans)}
            col += len(chans)
            if j == 0 or displacement:  # X Y Z displacement, then the rotations as listed
                xyz = ("xposition", "yposition", "zposition")
                picks += [at[c] if c in at else float(offset[i]) for i, c in enumerate(xyz)]
            picks += [at[c] for c in chans if c.endswith("rotation")]
        plans.append(picks)
    out = []
    for k in range(max(len(t.lines) for t in takes)):
        frame = []
        for i, (take, picks) in enumerate(zip(takes, plans, strict=True)):
            if k < len(take.lines):
                v = take.lines[k].split()
                values = [0.0] * (6 if reference else 0)
                values += [float(v[p]) if isinstance(p, int) else p for p in picks]
                head = (struct.pack("<H", 0xDDFF) + bytes([0, 0, 1, 1])
                        + struct.pack("<H", len(values)) + bytes([displacement, reference])
                        + struct.pack("<I", i) + take.name.encode("utf-8")[:31].ljust(32, b"\0")
                        + struct.pack("<I", first_frame + k) + bytes(12)
                        + struct.pack("<H", 0xEEFF))  # fmt: skip
                frame.append(head + struct.pack(f"<{len(values)}f", *values))
        out.append(frame)
    return rates.pop(), out


def play_as_axis_udp(takes, to: str, *, fast=False, displacement=False, out=None) -> int:
    """Send ``takes`` (one avatar each) as Axis' binary BVH broadcast to ``to`` (``HOST:PORT``)
    over one UDP socket, frame ``k`` of every take at ``k / rate`` (``fast``: one every
    millisecond: UDP has no back-pressure). Return the datagrams sent."""
    rate, frames = axis_udp_datagrams(takes, displacement=displacement)
    sent = send_paced(frames, to, rate, fast=fast)
    if out is not None:
        print(f"sent {sent} datagrams ({len(takes)} avatars) to {to}", file=out)
    return sent


__all__ = [
    "DEFAULT_PORT",
    "HEADER",
    "MAX_AVATARS",
    "REFERENCE",
    "TOKEN1",
    "TOKEN2",
    "Source",
    "axis_udp_datagrams",
    "play_as_axis_udp",
]
