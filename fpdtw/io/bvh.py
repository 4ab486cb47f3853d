"""Biovision BVH reader and writer.

A joint's local transform is ``T(OFFSET) * R``, ``R`` composed from its rotation channels as listed,
outermost first: ``Zrotation Yrotation Xrotation`` is order ``"XYZ"`` (identity pre/post rotations).
Missing rotation channels are zero (order completed as :func:`~fpdtw.io.asfamc.complete_order`).
Root position channels become ``Motion.root_translation``, added to the root OFFSET (the usual rule;
Blender and ``bvhio`` ignore the OFFSET, the same whenever it is zero, as in CMU's files). Non-root
position channels must be constant: their value replaces the OFFSET (as Blender and ``bvhio`` read
them). ``End Site`` offsets are checked and dropped. The frame rate ``1 / Frame Time`` snaps to an
integer rate printed rounded (``0.033333`` -> 30 Hz).
"""

from __future__ import annotations

import dataclasses
import io
import math
from functools import partial
from pathlib import Path

import numpy as np

from fpdtw import limits
from fpdtw.errors import MotionFormatError
from fpdtw.io._text import read_lines
from fpdtw.io.asfamc import complete_order
from fpdtw.motion.joints import find_joint_map
from fpdtw.motion.motion import Motion, Skeleton
from fpdtw.motion.rig import rest_rotations
from fpdtw.motion.rotations import quat_conj, quat_mul, quat_rotate, quat_to_euler, unwrap_degrees
from fpdtw.motion.stream import split_channels

_CHANNELS = {
    f"{a.lower()}{kind}": (kind, i)
    for i, a in enumerate("XYZ")
    for kind in ("position", "rotation")
}
_AXIS_NAME = "XYZ"


class _Joint:
    __slots__ = ("name", "parent", "offset", "channels", "line", "chan_line")

    def __init__(self, name, parent, line):
        self.name = name
        self.parent = parent
        self.offset = None
        self.channels = None
        self.line = line
        self.chan_line = None


def check_start(token: str, path, line: int) -> None:
    """MotionFormatError unless a BVH file's first word is HIERARCHY (a stream checks it early)."""
    if token.upper() != "HIERARCHY":
        raise MotionFormatError(path, f"file must start with HIERARCHY, got {token!r}", line=line)


def _parse_hierarchy(path, lines):
    """Joints (parents first) from the HIERARCHY lines."""
    err = partial(MotionFormatError, path)
    toks = [(t, ln) for ln, raw in enumerate(lines, 1) for t in raw.split()]
    end_line = len(lines) + 1  # the MOTION line
    pos = 0

    def take(what):
        nonlocal pos
        if pos >= len(toks):
            raise err(f"HIERARCHY ends while expecting {what} (missing '}}'?)", line=end_line)
        pos += 1
        return toks[pos - 1]

    def expect(word, after):
        t, ln = take(f"{word!r} after {after}")
        if t != word:
            raise err(f"expected {word!r} after {after}, got {t!r}", line=ln)

    t, ln = take("HIERARCHY")
    check_start(t, path, ln)
    t, ln = take("ROOT")
    if t.upper() != "ROOT":
        raise err(f"expected ROOT, got {t!r}", line=ln)
    name, ln = take("the root's name")
    expect("{", f"ROOT {name}")
    joints = [_Joint(name, -1, ln)]
    stack = [0]  # joint indices; None marks an End Site block
    end_offset = {}  # id of End Site block on the stack -> has offset
    while stack:
        t, ln = take("'}'")
        cur = stack[-1]
        if t == "OFFSET":
            vals = []
            for _ in range(3):
                v, vln = take("three OFFSET values")
                try:
                    vals.append(float(v))
                except ValueError:
                    raise err(f"OFFSET value {v!r} is not a number", line=vln) from None
            if not all(math.isfinite(v) for v in vals):
                raise err("non-finite OFFSET value", line=ln)
            if cur is None:
                if end_offset.get(len(stack)):
                    raise err("End Site has two OFFSETs", line=ln)
                end_offset[len(stack)] = True
            else:
                if joints[cur].offset is not None:
                    raise err(f"joint {joints[cur].name!r} has two OFFSETs", line=ln)
                joints[cur].offset = vals
        elif t == "CHANNELS":
            if cur is None:
                raise err("End Site cannot have CHANNELS", line=ln)
            jt = joints[cur]
            if jt.channels is not None:
                raise err(f"joint {jt.name!r} has two CHANNELS", line=ln)
            n_tok, nln = take("the channel count")
            try:
                n = int(n_tok)
            except ValueError:
                raise err(f"channel count {n_tok!r} is not an integer", line=nln) from None
            names = []
            while pos < len(toks) and toks[pos][1] == ln:
                names.append(toks[pos][0])
                pos += 1
            if len(names) != n or n < 0:
                raise err(
                    f"channel count mismatch: CHANNELS {n} lists {len(names)} channel(s) "
                    f"for joint {jt.name!r}",
                    line=ln,
                )
            chans = []
            for c in names:
                key = c.lower()
                if key not in _CHANNELS:
                    raise err(f"unknown channel {c!r} on joint {jt.name!r}", line=ln)
                if key in chans:
                    raise err(f"channel {c!r} repeated on joint {jt.name!r}", line=ln)
                chans.append(key)
            jt.channels = chans
            jt.chan_line = ln
        elif t == "JOINT":
            if cur is None:
                raise err("End Site cannot have child joints", line=ln)
            name, nln = take("a joint name")
            if name in ("{", "}"):
                raise err("JOINT without a name", line=nln)
            expect("{", f"JOINT {name}")
            joints.append(_Joint(name, cur, nln))
            stack.append(len(joints) - 1)
        elif t == "End":
            if cur is None:
                raise err("End Site inside an End Site", line=ln)
            expect("Site", "End")
            expect("{", "End Site")
            stack.append(None)
            end_offset[len(stack)] = False
        elif t == "}":
            stack.pop()
            if cur is None:
                if not end_offset.pop(len(stack) + 1):
                    raise err("End Site without OFFSET", line=ln)
                continue
            jt = joints[cur]
            if jt.offset is None:
                raise err(f"joint {jt.name!r} has no OFFSET", line=ln)
            if jt.channels is None:
                raise err(f"joint {jt.name!r} has no CHANNELS", line=ln)
        else:
            raise err(f"unexpected {t!r} in HIERARCHY", line=ln)
    if pos < len(toks):
        t, ln = toks[pos]
        what = "a second ROOT (unsupported)" if t.upper() == "ROOT" else f"{t!r}"
        raise err(f"{what} after the root's closing '}}' (unbalanced braces?)", line=ln)
    seen = {}
    for jt in joints:
        if jt.name in seen:
            raise err(f"duplicate joint name {jt.name!r}", line=jt.line)
        seen[jt.name] = jt
    return joints


def _is_key(text: str, key: str) -> bool:
    """``text`` is the line ``<key>: ...`` (any case and spacing, e.g. ``Frame  time:``)."""
    head, sep, _ = text.partition(":")
    return bool(sep) and " ".join(head.split()).lower() == key


def is_header_end(text: str) -> bool:
    """True for the ``Frame Time:`` line, the last of a BVH header."""
    return _is_key(text.strip(), "frame time")


class BVHHeader:
    """What a BVH file says before its first motion line, and how to read a motion line.

    The one parser of :func:`read_bvh` and ``fpdtw serve``: a streamed take and the same
    file give identical frames, errors and limits. ``frames`` is None in a stream;
    ``end_line`` is the ``Frame Time:`` line's number."""

    def __init__(self, path, joints, frames, fps, end_line):
        self.path = path
        self.joints = joints
        self.frames = frames
        self.fps = fps
        self.end_line = end_line
        self.n_channels = sum(len(j.channels) for j in joints)
        orders, rot, trans, pos = [], [], [], []
        col = 0
        for j, jt in enumerate(joints):
            applied = ""
            for ch in jt.channels:
                kind, axis = _CHANNELS[ch]
                if kind == "rotation":
                    rot.append((col, j, axis))
                    applied = _AXIS_NAME[axis] + applied  # listed outermost first
                elif j == 0:
                    trans.append((col, axis))
                else:
                    pos.append((col, j, axis))
                col += 1
            orders.append(complete_order(applied))
        self._rot = np.array(rot, dtype=np.int64).reshape(-1, 3)
        self._trans = np.array(trans, dtype=np.int64).reshape(-1, 2)
        self._pos = np.array(pos, dtype=np.int64).reshape(-1, 3)
        self.skeleton = Skeleton(
            joint_names=tuple(jt.name for jt in joints),
            parents=np.array([jt.parent for jt in joints]),
            offsets=np.array([jt.offset for jt in joints], dtype=float),
            rotation_orders=tuple(orders),
        )
        self.joint_map, _ = find_joint_map(self.skeleton.joint_names, "bvh")

    def parse_line(self, text: str, line: int, frame: int) -> np.ndarray:
        """The values (n_channels,) of one motion line.

        MotionFormatError for a missing, extra, non-numeric or non-finite value, naming ``line``
        and ``frame`` (0-based)."""
        toks = text.split()
        if len(toks) != self.n_channels:
            kind = "missing" if len(toks) < self.n_channels else "extra"
            raise MotionFormatError(
                self.path,
                f"{kind} value(s): expected {self.n_channels} values (the CHANNELS of the "
                f"hierarchy), got {len(toks)}",
                line=line,
                frame=frame,
            )
        try:
            values = np.array(toks, dtype=float)
        except ValueError:
            bad = next(t for t in toks if not _is_number(t))
            raise MotionFormatError(
                self.path, f"non-numeric value {bad!r}", line=line, frame=frame
            ) from None
        if not np.isfinite(values).all():
            raise MotionFormatError(
                self.path, "non-finite value (NaN or inf)", line=line, frame=frame
            )
        return values

    @property
    def channel_map(self) -> tuple:
        """``(rot, trans)``: the column, joint and axis (n, 3) int64 of each rotation channel;
        the column and axis (m, 2) int64 of each root translation channel."""
        return self._rot, self._trans

    def split(self, data: np.ndarray):
        """Euler angles (F, J, 3) and root translation (F, 3) of motion lines (F, n_channels)."""
        return split_channels(data, self._rot, self._trans, len(self.joints))

    def skeleton_for(self, first: np.ndarray) -> Skeleton:
        """The skeleton with the first line's non-root position channels as offsets."""
        if not len(self._pos):
            return self.skeleton
        offsets = self.skeleton.offsets.copy()
        offsets[self._pos[:, 1], self._pos[:, 2]] = first[self._pos[:, 0]]
        return dataclasses.replace(self.skeleton, offsets=offsets)

    def check_positions(self, data: np.ndarray, first: np.ndarray, lines=None, frame0=0):
        """Refuse non-root position channels of ``data`` that differ from those of ``first``.

        The MotionFormatError names the first differing line when given ``lines`` (a stream),
        else the CHANNELS line."""
        if not len(self._pos):
            return
        cols = self._pos[:, 0]
        same = data[:, cols] == first[cols]
        if same.all():
            return
        c = int(np.flatnonzero(~same.all(axis=0))[0])  # the first channel that varies
        k = int(np.flatnonzero(~same[:, c])[0])
        _, j, axis = (int(x) for x in self._pos[c])
        jt = self.joints[j]
        what = (
            f"joint {jt.name!r} has a {_AXIS_NAME[axis]}position channel that varies "
            "over time (animated non-root translation is not supported)"
        )
        if lines is None:
            raise MotionFormatError(self.path, what, line=jt.chan_line)
        raise MotionFormatError(
            self.path,
            f"{what}; its CHANNELS are on line {jt.chan_line}",
            line=int(lines[k]),
            frame=frame0 + k,
        )

    def motion(self, data: np.ndarray, name: str, path: str = "") -> Motion:
        """The motion of all motion lines ``data`` (F, n_channels)."""
        self.check_positions(data, data[0])
        euler, trans = self.split(data)
        return Motion(
            name=name,
            fps=self.fps,
            skeleton=self.skeleton_for(data[0]),
            euler=euler,
            root_translation=trans,
            source="bvh",
            path=path,
            joint_map=self.joint_map,
        )


def _is_number(token: str) -> bool:
    try:
        float(token)
    except ValueError:
        return False
    return True


def parse_bvh_header(lines, path=None, *, stream: bool = False) -> BVHHeader:
    """Parse a BVH header: HIERARCHY, MOTION, ``Frames:`` and ``Frame Time:``.

    ``path``: named in errors; ``stream``: ``Frames:`` may be missing and is ignored.
    MotionFormatError (naming the file and line) for no MOTION, bad braces or CHANNELS, too
    many channels, a missing or malformed ``Frames:`` or ``Frame Time:``, a frame time <= 0,
    a rate or ``Frames:`` outside :mod:`fpdtw.limits`."""
    err = partial(MotionFormatError, path)
    motion_at = next(
        (i for i, s in enumerate(lines) if s.split()[:1] and s.split()[0].upper() == "MOTION"), None
    )
    if motion_at is None:
        raise err("no MOTION section", line=len(lines) if stream else None)
    joints = _parse_hierarchy(path, lines[:motion_at])
    n_ch = sum(len(j.channels) for j in joints)
    limits.check_channels(n_ch, path, line=motion_at)

    rest = ((i + 1, s.strip()) for i, s in enumerate(lines) if i > motion_at and s.strip())
    header = {}
    for key, label in (("frames", "Frames:"), ("frame time", "Frame Time:")):
        ln, s = next(rest, (None, None))
        if stream and key == "frames" and s is not None and not _is_key(s, key):
            header[key] = None  # no Frames: line in a stream; this is the next line
            rest = iter([(ln, s)])
            continue
        if s is None:
            raise err(f"MOTION section has no {label!r} line", line=len(lines))
        if not _is_key(s, key):
            raise err(f"expected {label!r}, got {s!r}", line=ln)
        header[key] = (s.partition(":")[2].strip(), ln)
    n_frames = None
    if not stream:
        value, ln = header["frames"]
        try:
            n_frames = int(value)
        except ValueError:
            raise err(f"Frames: {value!r} is not an integer", line=ln) from None
        if n_frames < 1:
            raise err(f"Frames: {n_frames} (need at least one frame)", line=ln)
        limits.check_file_frames(n_frames, path, line=ln)
    value, ln = header["frame time"]
    try:
        frame_time = float(value)
    except ValueError:
        raise err(f"Frame Time: {value!r} is not a number", line=ln) from None
    if not math.isfinite(frame_time) or frame_time <= 0:
        raise err(f"Frame Time must be > 0, got {value}", line=ln)
    fps = 1.0 / frame_time  # inf for a frame time below about 1e-308
    n = round(fps) if math.isfinite(fps) else 0
    if n >= 1 and abs(frame_time * n - 1.0) < 1e-4:
        fps = float(n)  # a whole rate printed with rounding
    fps = limits.check_file_fps(fps, path, line=ln, source=f"Frame Time {value} s")
    return BVHHeader(path, joints, n_frames, fps, ln)


def read_bvh(path, *, name=None) -> Motion:
    """Read a BVH motion file (``source="bvh"``).

    Joint names are resolved by the ASF naming (CMU's BVH keeps it), or the FBX naming if
    that finds more. MotionFormatError (naming the file, line and 0-based frame) for what
    :func:`parse_bvh_header` refuses, an empty file, ``Frames:`` not matching the data
    lines, a bad motion line, or varying non-root position channels."""
    path = Path(path)
    err = partial(MotionFormatError, path)
    lines = read_lines(path)
    if not any(s.strip() for s in lines):
        raise err("empty file")
    header = parse_bvh_header(lines, path)
    rest = [(i + 1, s) for i, s in enumerate(lines) if i >= header.end_line and s.strip()]
    n_frames = header.frames
    if len(rest) < n_frames:
        for k, (ln, s) in enumerate(rest):
            header.parse_line(s, ln, k)
        msg = f"Frames: {n_frames} but the file has only {len(rest)} data line(s)"
        ln = rest[-1][0] if rest else header.end_line
        raise err(msg, line=ln, frame=len(rest))
    rows = [header.parse_line(s, ln, k) for k, (ln, s) in enumerate(rest[:n_frames])]
    if len(rest) > n_frames:
        header.parse_line(rest[n_frames][1], rest[n_frames][0], n_frames)
        raise err(
            f"Frames: {n_frames} but the file has {len(rest)} data lines",
            line=rest[n_frames][0],
            frame=n_frames,
        )
    return header.motion(np.stack(rows), name or path.stem, str(path))


def _snap_identity(q):
    """Unit quaternions (N, 4) within 1e-12 of the identity set to it exactly."""
    q = np.array(q, dtype=float)
    near = 1.0 - np.abs(q[:, 0]) < 1e-12
    q[near] = (1.0, 0.0, 0.0, 0.0)
    return q


def bvh_pose(motion: Motion) -> tuple:
    """Euler angles (F, J, 3; degrees, unwrapped) and offsets (J, 3) of a motion as BVH.

    A BVH skeleton rests with zero rotations in world-aligned axes. A skeleton with pre/post
    rotations rests in the pose they give (global rest rotations ``G^0``,
    :func:`fpdtw.motion.rig.rest_rotations`): each joint turns by ``Delta_j = G_p^0 pre_j R_j
    post_j (G_j^0)^-1`` and its offset is ``G_p^0 offset_j``, so the file rests in the
    motion's pose with the same forward kinematics. Without them: the motion's own."""
    sk = motion.skeleton
    euler = motion.euler.copy()
    offsets = sk.offsets.copy()
    pre, post = _snap_identity(sk.pre_rotations), _snap_identity(sk.post_rotations)
    ident = np.array([1.0, 0.0, 0.0, 0.0])
    if np.all(pre == ident) and np.all(post == ident):
        return euler, offsets
    G0 = _snap_identity(rest_rotations(motion))
    for j, order in enumerate(sk.rotation_orders):
        p = sk.parents[j]
        left = pre[j] if p < 0 or np.all(G0[p] == ident) else quat_mul(G0[p], pre[j])
        right = post[j] if np.all(G0[j] == ident) else quat_mul(post[j], quat_conj(G0[j]))
        if p >= 0 and not np.all(G0[p] == ident):
            offsets[j] = quat_rotate(G0[p], sk.offsets[j])
        if np.all(left == ident) and np.all(right == ident):
            continue
        q = quat_mul(quat_mul(left, motion.quats[:, j]), right)
        euler[:, j] = unwrap_degrees(quat_to_euler(q, order), axis=0)
    return euler, offsets


def bvh_euler(motion: Motion) -> np.ndarray:
    """Euler angles (F, J, 3) of a motion in a BVH skeleton (:func:`bvh_pose`'s)."""
    return bvh_pose(motion)[0]


def bvh_lines(motion: Motion, *, precision: int = 6) -> tuple[list[str], list[str]]:
    """A motion as the lines of a BVH file: header (through ``Frame Time:``) and motion lines.

    What :func:`write_bvh` writes and ``fpdtw stream`` sends; ``precision``: decimals.
    MotionFormatError for a joint name BVH cannot hold."""
    sk = motion.skeleton
    for n in sk.joint_names:
        if not n or any(c.isspace() for c in n) or "{" in n or "}" in n:
            raise MotionFormatError(
                motion.path or motion.name or None, f"joint name {n!r} cannot be written to BVH"
            )
    euler, offsets = bvh_pose(motion)
    kids = [[] for _ in range(sk.n_joints)]
    for j in range(1, sk.n_joints):
        kids[sk.parents[j]].append(j)

    out = io.StringIO()
    out.write("HIERARCHY\n")
    order = []  # joints in written (depth-first) order

    def write_joint(j, depth):
        pad = "\t" * depth
        order.append(j)
        head = "ROOT" if j == 0 else "JOINT"
        rot = " ".join(f"{a}rotation" for a in reversed(sk.rotation_orders[j]))
        chans = f"6 Xposition Yposition Zposition {rot}" if j == 0 else f"3 {rot}"
        off = " ".join(repr(float(v)) for v in offsets[j])
        out.write(f"{pad}{head} {sk.joint_names[j]}\n{pad}{{\n")
        out.write(f"{pad}\tOFFSET {off}\n{pad}\tCHANNELS {chans}\n")
        for k in kids[j]:
            write_joint(k, depth + 1)
        if not kids[j]:
            out.write(f"{pad}\tEnd Site\n{pad}\t{{\n{pad}\t\tOFFSET 0.0 0.0 0.0\n{pad}\t}}\n")
        out.write(f"{pad}}}\n")

    write_joint(0, 0)
    cols = [motion.root_translation]
    for j in order:
        cols.append(euler[:, j, ["XYZ".index(a) for a in reversed(sk.rotation_orders[j])]])
    data = np.concatenate(cols, axis=1)
    out.write(f"MOTION\nFrames: {motion.n_frames}\nFrame Time: {1.0 / motion.fps:.10g}\n")
    header = out.getvalue().splitlines()
    body = io.StringIO()
    np.savetxt(body, data, fmt=f"%.{int(precision)}f", delimiter=" ")
    return header, body.getvalue().splitlines()


def write_bvh(motion: Motion, path, *, precision: int = 6) -> Path:
    """Write a motion as a BVH file (overwritten) and return its path.

    Three rotation channels per joint in its order, the root's position channels, a zero
    ``End Site`` per leaf, depth first, resting as :func:`bvh_pose` says: forward kinematics
    of the file equals the motion's. MotionFormatError for a joint name BVH cannot hold."""
    path = Path(path)
    try:
        header, lines = bvh_lines(motion, precision=precision)
    except MotionFormatError as e:
        raise MotionFormatError(path, e.reason) from None
    path.write_text("\n".join(header + lines) + "\n")
    return path
