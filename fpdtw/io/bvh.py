"""Biovision BVH reader and writer.

Model
-----
A BVH joint has an ``OFFSET`` from its parent and a list of ``CHANNELS``. Its
local transform is ``T(offset) * R`` with ``R`` composed from the rotation
channels **as listed, outermost first**: ``Zrotation Yrotation Xrotation`` means
``R = Rz Ry Rx``, i.e. our rotation order ``"XYZ"`` (the order in which the
rotations are applied, see :mod:`fpdtw.motion.rotations`). In
:class:`fpdtw.motion.Skeleton` terms: offsets as in the file, identity pre/post
rotations.

* Joints with fewer than 3 rotation channels: the missing angles are zero; the
  order is the present axes in applied order followed by the missing axes in
  X, Y, Z order (``Zrotation Xrotation`` -> ``"XZY"``), which gives the same
  rotation wherever a zero-angle axis goes.
* Root position channels become ``Motion.root_translation``; the root's
  ``OFFSET`` stays in ``Skeleton.offsets`` and forward kinematics adds the two
  (the usual rule, e.g. Meredith & Maddock, "Motion capture file formats
  explained"). Blender and the ``bvhio`` package instead take the root position
  channels as the absolute position, ignoring the root OFFSET; the two agree
  whenever the root OFFSET is zero, as in the CMU files.
* Non-root position channels are supported only when constant over all
  frames: their value then *replaces* the joint's OFFSET (how Blender and
  ``bvhio`` read them; exporters that key every joint write the offset there).
  Position channels that vary raise :class:`~fpdtw.errors.MotionFormatError`.
* ``End Site`` blocks are not joints; their offsets are checked and dropped.
* The frame rate is ``1 / Frame Time``, snapped to the nearest integer when the
  printed frame time is that integer rate rounded (``0.033333`` -> 30 Hz).
"""

from __future__ import annotations

import io
import math
from pathlib import Path

import numpy as np

from fpdtw import limits
from fpdtw.errors import MotionFormatError
from fpdtw.io._text import read_lines
from fpdtw.motion.joints import NAMINGS, resolve_joint_map
from fpdtw.motion.motion import Motion, Skeleton
from fpdtw.motion.rotations import quat_mul, quat_to_euler, unwrap_degrees

_CHANNELS = {
    f"{a.lower()}{kind}": (kind, i)
    for i, a in enumerate("XYZ")
    for kind in ("position", "rotation")
}
_AXIS_NAME = "XYZ"


def _complete_order(applied: str) -> str:
    """Present axes in applied order, then the missing ones in X, Y, Z order."""
    return applied + "".join(a for a in "XYZ" if a not in applied)


def _fps_from_frame_time(ft: float) -> float:
    n = round(1.0 / ft)
    if n >= 1 and abs(ft * n - 1.0) < 1e-4:
        return float(n)
    return 1.0 / ft


class _Joint:
    __slots__ = ("name", "parent", "offset", "channels", "line", "chan_line")

    def __init__(self, name, parent, line):
        self.name = name
        self.parent = parent
        self.offset = None
        self.channels = None
        self.line = line
        self.chan_line = None


def _parse_hierarchy(path, lines):
    """Joints (parents first) from the HIERARCHY lines."""
    toks = [(t, ln) for ln, raw in enumerate(lines, 1) for t in raw.split()]
    end_line = len(lines) + 1  # the MOTION line
    pos = 0

    def take(what):
        nonlocal pos
        if pos >= len(toks):
            raise MotionFormatError(
                path, f"HIERARCHY ends while expecting {what} (missing '}}'?)", line=end_line
            )
        pos += 1
        return toks[pos - 1]

    def expect(word, after):
        t, ln = take(f"{word!r} after {after}")
        if t != word:
            raise MotionFormatError(path, f"expected {word!r} after {after}, got {t!r}", line=ln)

    t, ln = take("HIERARCHY")
    if t.upper() != "HIERARCHY":
        raise MotionFormatError(path, f"file must start with HIERARCHY, got {t!r}", line=ln)
    t, ln = take("ROOT")
    if t.upper() != "ROOT":
        raise MotionFormatError(path, f"expected ROOT, got {t!r}", line=ln)
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
                    raise MotionFormatError(
                        path, f"OFFSET value {v!r} is not a number", line=vln
                    ) from None
            if not all(math.isfinite(v) for v in vals):
                raise MotionFormatError(path, "non-finite OFFSET value", line=ln)
            if cur is None:
                if end_offset.get(len(stack)):
                    raise MotionFormatError(path, "End Site has two OFFSETs", line=ln)
                end_offset[len(stack)] = True
            else:
                if joints[cur].offset is not None:
                    raise MotionFormatError(
                        path, f"joint {joints[cur].name!r} has two OFFSETs", line=ln
                    )
                joints[cur].offset = vals
        elif t == "CHANNELS":
            if cur is None:
                raise MotionFormatError(path, "End Site cannot have CHANNELS", line=ln)
            jt = joints[cur]
            if jt.channels is not None:
                raise MotionFormatError(path, f"joint {jt.name!r} has two CHANNELS", line=ln)
            n_tok, nln = take("the channel count")
            try:
                n = int(n_tok)
            except ValueError:
                raise MotionFormatError(
                    path, f"channel count {n_tok!r} is not an integer", line=nln
                ) from None
            names = []
            while pos < len(toks) and toks[pos][1] == ln:
                names.append(toks[pos][0])
                pos += 1
            if len(names) != n or n < 0:
                raise MotionFormatError(
                    path,
                    f"channel count mismatch: CHANNELS {n} lists {len(names)} channel(s) "
                    f"for joint {jt.name!r}",
                    line=ln,
                )
            chans = []
            for c in names:
                key = c.lower()
                if key not in _CHANNELS:
                    raise MotionFormatError(
                        path, f"unknown channel {c!r} on joint {jt.name!r}", line=ln
                    )
                if key in chans:
                    raise MotionFormatError(
                        path, f"channel {c!r} repeated on joint {jt.name!r}", line=ln
                    )
                chans.append(key)
            jt.channels = chans
            jt.chan_line = ln
        elif t == "JOINT":
            if cur is None:
                raise MotionFormatError(path, "End Site cannot have child joints", line=ln)
            name, nln = take("a joint name")
            if name in ("{", "}"):
                raise MotionFormatError(path, "JOINT without a name", line=nln)
            expect("{", f"JOINT {name}")
            joints.append(_Joint(name, cur, nln))
            stack.append(len(joints) - 1)
        elif t == "End":
            if cur is None:
                raise MotionFormatError(path, "End Site inside an End Site", line=ln)
            expect("Site", "End")
            expect("{", "End Site")
            stack.append(None)
            end_offset[len(stack)] = False
        elif t == "}":
            stack.pop()
            if cur is None:
                if not end_offset.pop(len(stack) + 1):
                    raise MotionFormatError(path, "End Site without OFFSET", line=ln)
                continue
            jt = joints[cur]
            if jt.offset is None:
                raise MotionFormatError(path, f"joint {jt.name!r} has no OFFSET", line=ln)
            if jt.channels is None:
                raise MotionFormatError(path, f"joint {jt.name!r} has no CHANNELS", line=ln)
        else:
            raise MotionFormatError(path, f"unexpected {t!r} in HIERARCHY", line=ln)
    if pos < len(toks):
        t, ln = toks[pos]
        what = "a second ROOT (unsupported)" if t.upper() == "ROOT" else f"{t!r}"
        raise MotionFormatError(
            path, f"{what} after the root's closing '}}' (unbalanced braces?)", line=ln
        )
    seen = {}
    for jt in joints:
        if jt.name in seen:
            raise MotionFormatError(path, f"duplicate joint name {jt.name!r}", line=jt.line)
        seen[jt.name] = jt
    return joints


def _bad_value_error(path, data_lines):
    """Locate the first non-numeric token (slow path)."""
    for k, (ln, s) in enumerate(data_lines):
        for t in s.split():
            try:
                float(t)
            except ValueError:
                raise MotionFormatError(
                    path, f"non-numeric value {t!r}", line=ln, frame=k
                ) from None
    raise MotionFormatError(path, "unreadable MOTION data")  # pragma: no cover


def read_bvh(path, *, name=None) -> Motion:
    """Read a BVH motion file.

    Parameters
    ----------
    path : str or os.PathLike
        The ``.bvh`` file.
    name : str, optional
        Motion name; default the file stem.

    Returns
    -------
    motion : Motion
        ``source="bvh"``; ``euler`` (F, J, 3) the rotation channels in degrees
        in (x, y, z) columns, rotation order per joint from its channel order;
        ``root_translation`` (F, 3) the root position channels. Joint names are
        resolved with the ASF naming (CMU BVH files keep the ASF bone names;
        the root is ``hip``), or the FBX naming if that resolves more joints.

    Raises
    ------
    MotionFormatError
        Empty file, no MOTION section, bad or unbalanced braces, a CHANNELS count
        that does not match the names listed, unknown or repeated channels,
        ``Frames:`` not matching the number of data lines, a data line with a
        missing or extra value, a non-numeric or non-finite value, ``Frame
        Time`` <= 0, position channels on a non-root joint that vary over time,
        a frame rate (``1 / Frame Time``) or ``Frames:`` outside :mod:`fpdtw.limits`.
        The message names the file, line and (0-based) frame.
    """
    path = Path(path)
    lines = read_lines(path)
    if not any(s.strip() for s in lines):
        raise MotionFormatError(path, "empty file")
    motion_at = next(
        (i for i, s in enumerate(lines) if s.split()[:1] and s.split()[0].upper() == "MOTION"),
        None,
    )
    if motion_at is None:
        raise MotionFormatError(path, "no MOTION section")
    joints = _parse_hierarchy(path, lines[:motion_at])

    # ---- MOTION header
    rest = [(i + 1, s.strip()) for i, s in enumerate(lines) if i > motion_at and s.strip()]
    header = {}
    for key, label in (("frames", "Frames:"), ("frame time", "Frame Time:")):
        if not rest:
            raise MotionFormatError(path, f"MOTION section has no {label!r} line", line=len(lines))
        ln, s = rest.pop(0)
        head, sep, value = s.partition(":")
        if not sep or " ".join(head.split()).lower() != key:
            raise MotionFormatError(path, f"expected {label!r}, got {s!r}", line=ln)
        header[key] = (value.strip(), ln)
    value, ln = header["frames"]
    try:
        n_frames = int(value)
    except ValueError:
        raise MotionFormatError(path, f"Frames: {value!r} is not an integer", line=ln) from None
    if n_frames < 1:
        raise MotionFormatError(path, f"Frames: {n_frames} (need at least one frame)", line=ln)
    limits.check_file_frames(n_frames, path, line=ln)
    value, ln = header["frame time"]
    try:
        frame_time = float(value)
    except ValueError:
        raise MotionFormatError(path, f"Frame Time: {value!r} is not a number", line=ln) from None
    if not math.isfinite(frame_time) or frame_time <= 0:
        raise MotionFormatError(path, f"Frame Time must be > 0, got {value}", line=ln)
    raw = 1.0 / frame_time  # inf for a frame time below about 1e-308
    fps = _fps_from_frame_time(frame_time) if math.isfinite(raw) else raw
    fps = limits.check_file_fps(fps, path, line=ln, source=f"Frame Time {value} s")

    # ---- data
    n_ch = sum(len(j.channels) for j in joints)
    for k, (ln, s) in enumerate(rest):
        got = len(s.split())
        if got != n_ch:
            kind = "missing" if got < n_ch else "extra"
            raise MotionFormatError(
                path,
                f"{kind} value(s): expected {n_ch} values (the CHANNELS of the hierarchy), "
                f"got {got}",
                line=ln,
                frame=k,
            )
    if len(rest) != n_frames:
        if len(rest) < n_frames:
            msg = f"Frames: {n_frames} but the file has only {len(rest)} data line(s)"
            ln = rest[-1][0] if rest else header["frame time"][1]
            raise MotionFormatError(path, msg, line=ln, frame=len(rest))
        raise MotionFormatError(
            path,
            f"Frames: {n_frames} but the file has {len(rest)} data lines",
            line=rest[n_frames][0],
            frame=n_frames,
        )
    try:
        data = np.array(" ".join(s for _, s in rest).split(), dtype=float).reshape(n_frames, n_ch)
    except ValueError:
        _bad_value_error(path, rest)
    finite = np.isfinite(data)
    if not finite.all():
        k = int(np.flatnonzero(~finite.all(axis=1))[0])
        raise MotionFormatError(path, "non-finite value (NaN or inf)", line=rest[k][0], frame=k)

    # ---- channels -> Euler, translation, offsets
    J = len(joints)
    euler = np.zeros((n_frames, J, 3))
    trans = np.zeros((n_frames, 3))
    offsets = np.array([jt.offset for jt in joints], dtype=float)
    orders = []
    col = 0
    for j, jt in enumerate(joints):
        applied = ""
        for ch in jt.channels:
            kind, axis = _CHANNELS[ch]
            x = data[:, col]
            if kind == "rotation":
                euler[:, j, axis] = x
                applied = _AXIS_NAME[axis] + applied  # listed outermost first
            elif j == 0:
                trans[:, axis] = x
            elif np.all(x == x[0]):
                offsets[j, axis] = x[0]
            else:
                raise MotionFormatError(
                    path,
                    f"joint {jt.name!r} has a {ch[0].upper()}position channel that varies "
                    "over time (animated non-root translation is not supported)",
                    line=jt.chan_line,
                )
            col += 1
        orders.append(_complete_order(applied))

    skeleton = Skeleton(
        joint_names=tuple(jt.name for jt in joints),
        parents=np.array([jt.parent for jt in joints]),
        offsets=offsets,
        rotation_orders=tuple(orders),
    )
    maps = [resolve_joint_map(skeleton.joint_names, NAMINGS[k]) for k in ("bvh", "fbx")]
    joint_map = maps[1] if len(maps[1]) > len(maps[0]) else maps[0]
    return Motion(
        name=name or path.stem,
        fps=fps,
        skeleton=skeleton,
        euler=euler,
        root_translation=trans,
        source="bvh",
        path=str(path),
        joint_map=joint_map,
    )


def bvh_euler(motion: Motion) -> np.ndarray:
    """Euler angles of a motion in a BVH skeleton (identity pre/post rotations).

    Where the skeleton has pre/post rotations (ASF ``axis``, FBX pre-rotations)
    they are baked into the local rotation, ``R' = pre R post``, which leaves
    forward kinematics unchanged (each child's offset is expressed in the frame
    after ``post``). The angles are recomputed in each joint's own order and
    unwrapped over time. Without pre/post rotations the motion's own Euler angles
    are returned unchanged.

    Parameters
    ----------
    motion : Motion

    Returns
    -------
    euler : ndarray of float, shape (F, J, 3)
        Degrees, (x, y, z) columns, each joint in its rotation order.
    """
    sk = motion.skeleton
    ident = np.array([1.0, 0.0, 0.0, 0.0])
    euler = motion.euler.copy()
    for j, order in enumerate(sk.rotation_orders):
        pre, post = sk.pre_rotations[j], sk.post_rotations[j]
        if np.allclose(np.abs(pre @ ident), 1.0, atol=1e-12) and np.allclose(
            np.abs(post @ ident), 1.0, atol=1e-12
        ):
            continue
        q = quat_mul(quat_mul(pre, motion.quats[:, j]), post)
        euler[:, j] = unwrap_degrees(quat_to_euler(q, order), axis=0)
    return euler


def write_bvh(motion: Motion, path, *, precision: int = 6) -> Path:
    """Write a motion as a BVH file.

    Every joint gets three rotation channels in its rotation order (listed
    outermost first, so order ``"XYZ"`` is written ``Zrotation Yrotation
    Xrotation``); the root also gets ``Xposition Yposition Zposition`` (its
    translation; the root OFFSET is the skeleton's root offset). Leaf joints get
    a zero-length ``End Site``. Pre/post rotations (ASF, FBX skeletons) are baked
    into the local rotations (see :func:`bvh_euler`), so forward kinematics of
    the written file equals that of ``motion``. Joints are written depth first,
    which may reorder joints of a skeleton listed otherwise.

    Parameters
    ----------
    motion : Motion
    path : str or os.PathLike
        Output ``.bvh`` file (overwritten).
    precision : int
        Decimals of the motion values.

    Returns
    -------
    path : Path

    Raises
    ------
    MotionFormatError
        A joint name BVH cannot hold (empty, whitespace, braces).
    """
    path = Path(path)
    sk = motion.skeleton
    for n in sk.joint_names:
        if not n or any(c.isspace() for c in n) or "{" in n or "}" in n:
            raise MotionFormatError(path, f"joint name {n!r} cannot be written to BVH")
    euler = bvh_euler(motion)
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
        off = " ".join(repr(float(v)) for v in sk.offsets[j])
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
    np.savetxt(out, data, fmt=f"%.{int(precision)}f", delimiter=" ")
    path.write_text(out.getvalue())
    return path


__all__ = ["bvh_euler", "read_bvh", "write_bvh"]
