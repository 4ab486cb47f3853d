"""Acclaim ASF (skeleton) and AMC (motion) readers, as used by HDM05 and CMU.

An ASF bone has a unit ``direction``, a ``length`` and an axis frame ``C_j`` (``axis 0 0 20 XYZ``:
``C = Rz(20) Ry(0) Rx(0)``); an AMC frame gives each bone's rotation ``M_j`` in that frame, Euler
angles in dof order (``dof rx ry rz``: order ``"XYZ"``; a missing dof is zero). The Acclaim rule
``F_j = F_p C_p^-1 C_j M_j`` is read in the rest-aligned frame ``G_j = F_j C_j^-1 = G_p C_j M_j
C_j^-1``: joint ``j`` is bone ``j`` at its START (joint 0 the root), ``offset_j`` = the parent
bone's ``direction * length`` (zero under the root; the root's own: ``:root position``), ``pre_j =
C_j``, ``post_j = C_j^-1``, ``R_j = M_j``; the root's translation is the AMC ``TX TY TZ``. All-zero
AMC values give the ASF rest pose. Lengths stay in the file's unit (HDM05 and CMU: ``:units length
0.45``, 1 unit = 1/0.45 inch); angles become degrees (ASF by ``:units angle``, AMC by its
``:DEGREES`` / ``:RADIANS`` header, else the ASF's).
"""

from __future__ import annotations

import math
import os
import re
from dataclasses import dataclass
from functools import partial
from pathlib import Path

import numpy as np

from fpdtw import limits
from fpdtw.errors import MotionFormatError
from fpdtw.io._text import read_lines
from fpdtw.motion.motion import Motion, Skeleton
from fpdtw.motion.rotations import euler_to_quat, quat_conj

_AXIS = {"X": 0, "Y": 1, "Z": 2}
_ROT_DOFS = ("rx", "ry", "rz")
_ROOT_CHANNELS = ("TX", "TY", "TZ", "RX", "RY", "RZ")
#: Rate of CMU AMC files, the default when the file name gives none.
DEFAULT_AMC_FPS = 120.0


def complete_order(applied: str) -> str:
    """Rotation order from the axes present, the missing ones appended in X, Y, Z order.

    A missing axis has a zero angle, so it may go anywhere: ``"XZ"`` -> ``"XZY"``, ``""``
    -> ``"XYZ"``."""
    return applied + "".join(a for a in "XYZ" if a not in applied)


@dataclass(frozen=True, eq=False)
class AsfSkeleton:
    """A parsed ASF file: the :class:`~fpdtw.motion.Skeleton` plus what the AMC reader needs.

    ``skeleton``: rest-aligned, ``("root", bones...)`` depth first in ``:hierarchy`` order;
    ``dofs``: each joint's rotational dofs in file order; ``root_order``: the AMC root channels;
    ``directions`` (J, 3) and ``lengths`` (J,): unit bone directions and lengths at rest (zero for
    the root); ``angle_unit`` ("deg" or "rad"); ``length_scale`` (``:units length``); ``path``."""

    skeleton: Skeleton
    dofs: tuple
    root_order: tuple
    directions: np.ndarray
    lengths: np.ndarray
    angle_unit: str
    length_scale: float
    path: str

    @property
    def meters_per_unit(self) -> float:
        """Metres per file length unit, by the CMU convention ``0.0254 / length_scale``."""
        return 0.0254 / self.length_scale

    def bone_ends(self, positions: np.ndarray) -> np.ndarray:
        """Bone ends at rest, ``start + direction * length``, from the starts (..., J, 3)."""
        return positions + self.directions * self.lengths[:, None]


def _floats(path, tokens, line, what, count=None):
    err = partial(MotionFormatError, path)
    if count is not None and len(tokens) != count:
        raise err(
            f"{what} needs {count} number(s), got {len(tokens)}: {' '.join(tokens)!r}", line=line
        )
    try:
        vals = [float(t) for t in tokens]
    except ValueError:
        raise err(f"{what}: non-numeric value in {' '.join(tokens)!r}", line=line) from None
    if not all(math.isfinite(v) for v in vals):
        raise err(f"{what}: non-finite value in {' '.join(tokens)!r}", line=line)
    return vals


def _order(path, letters, line, what):
    o = "".join(letters).upper()
    if len(o) != 3 or sorted(o) != ["X", "Y", "Z"]:
        raise MotionFormatError(path, f"{what}: bad rotation order {o!r}", line=line)
    return o


def read_asf(path) -> AsfSkeleton:
    """Read an Acclaim ASF skeleton file (the rest-aligned model of the module docstring).

    MotionFormatError, naming the file and line, for missing sections or fields, bad
    numbers, unknown or duplicate bones, translation or length dofs, or a hierarchy that
    does not reach every bone exactly once."""
    path = Path(path)
    err = partial(MotionFormatError, path)
    lines = read_lines(path)
    units = {"length": 1.0, "angle": "deg"}
    root = {}
    bones = {}  # name -> dict(direction, length, axis, order, dofs, line)
    bone_list = []
    children = {"root": []}
    parent_of = {}
    section = None
    bone = None
    hier_state = None  # None, "open", "closed"
    seen_sections = set()

    for ln, raw in enumerate(lines, 1):
        s = raw.split("#", 1)[0].strip()
        if not s:
            continue
        tok = s.split()
        key = tok[0].lower()
        if tok[0].startswith(":"):
            if bone is not None:
                raise err("bone block not closed with 'end'", line=ln)
            section = tok[0][1:].lower()
            seen_sections.add(section)
            if section == "units" and len(tok) > 1:
                raise err("':units' takes its values on later lines", line=ln)
            continue
        if section == "units":
            if key == "length":
                (scale,) = _floats(path, tok[1:], ln, "units length", 1)
                if scale <= 0:
                    raise err(f"units length must be > 0, got {scale}", line=ln)
                units["length"] = scale
            elif key == "angle":
                if len(tok) != 2 or tok[1].lower() not in ("deg", "rad"):
                    raise err("units angle must be 'deg' or 'rad'", line=ln)
                units["angle"] = tok[1].lower()
            # mass and others: not needed
        elif section == "root":
            if key == "order":
                chans = tuple(t.upper() for t in tok[1:])
                bad = [c for c in chans if c not in _ROOT_CHANNELS]
                if bad or len(set(chans)) != len(chans) or not chans:
                    raise err(
                        f"root order {' '.join(tok[1:])!r}: expected distinct channels "
                        f"from {' '.join(_ROOT_CHANNELS)}",
                        line=ln,
                    )
                root["order"] = chans
            elif key == "axis":
                if len(tok) != 2:
                    raise err("root axis must be one order, e.g. XYZ", line=ln)
                root["axis"] = _order(path, tok[1], ln, "root axis")
            elif key in ("position", "orientation"):
                root[key] = _floats(path, tok[1:], ln, f"root {key}", 3)
            else:
                raise err(f"unknown root field {tok[0]!r}", line=ln)
        elif section == "bonedata":
            if key == "begin":
                if bone is not None:
                    raise err("'begin' inside a bone block", line=ln)
                bone = {"line": ln}
            elif bone is None:
                raise err(f"{tok[0]!r} outside a begin/end bone block", line=ln)
            elif key == "end":
                for need in ("name", "direction", "length", "axis"):
                    if need not in bone:
                        raise err(f"bone {bone.get('name', '?')!r} has no {need!r}", line=ln)
                bones[bone["name"]] = bone
                bone_list.append(bone["name"])
                bone = None
            elif key == "name":
                if len(tok) != 2:
                    raise err("bone name must be one word", line=ln)
                name = tok[1]
                if name in bones or name == "root":
                    raise err(f"duplicate bone name {name!r}", line=ln)
                bone["name"] = name
            elif key == "direction":
                d = np.array(_floats(path, tok[1:], ln, "direction", 3))
                scale = np.abs(d).max()
                if scale < 1e-12:
                    raise err("bone direction is zero", line=ln)
                d = d / scale  # the norm of (1e300, 0, 0) itself would overflow
                bone["direction"] = d / np.linalg.norm(d)
            elif key == "length":
                (length,) = _floats(path, tok[1:], ln, "length", 1)
                if length < 0:
                    raise err(f"negative bone length {length}", line=ln)
                bone["length"] = length
            elif key == "axis":
                if len(tok) != 5:
                    raise err(
                        "axis needs three angles and an order, e.g. 'axis 0 0 20 XYZ'", line=ln
                    )
                bone["axis"] = _floats(path, tok[1:4], ln, "axis", 3)
                bone["order"] = _order(path, tok[4], ln, "axis")
            elif key == "dof":
                dofs = tuple(t.lower() for t in tok[1:])
                unsupported = [d for d in dofs if d not in _ROT_DOFS]
                if unsupported:
                    raise err(
                        f"unsupported dof(s) {' '.join(unsupported)} (only rx ry rz)", line=ln
                    )
                if len(set(dofs)) != len(dofs):
                    raise err(f"repeated dof in {' '.join(dofs)!r}", line=ln)
                bone["dofs"] = dofs
            # id, limits (and their continuation lines), bodymass, cofmass: ignored
        elif section == "hierarchy":
            if key in ("begin", "end"):
                hier_state = "open" if key == "begin" else "closed"
                continue
            if hier_state != "open":
                raise err("hierarchy line outside begin/end", line=ln)
            par, kids = tok[0], tok[1:]
            if par != "root" and par not in bones:
                raise err(f"hierarchy names unknown bone {par!r}", line=ln)
            for kid in kids:
                if kid not in bones:
                    raise err(f"hierarchy names unknown bone {kid!r}", line=ln)
                if kid in parent_of:
                    raise err(f"bone {kid!r} has two parents ({parent_of[kid]}, {par})", line=ln)
                parent_of[kid] = par
                children.setdefault(par, []).append(kid)
        # other sections (:version, :name, :documentation, :skin...): ignored

    if not lines or not seen_sections:
        raise err("empty file or not an ASF file (no ':' sections)")
    if bone is not None:
        raise err("file ends inside a bone block", line=len(lines))
    for need in ("root", "bonedata", "hierarchy"):
        if need not in seen_sections:
            raise err(f"no ':{need}' section")
    if hier_state != "closed":
        raise err("':hierarchy' has no begin/end block")
    if "order" not in root or "axis" not in root:
        raise err("':root' needs 'order' and 'axis'")

    # depth-first order from the root, children in hierarchy order
    names = ["root"]
    parents = [-1]
    stack = [(k, 0) for k in reversed(children.get("root", []))]
    while stack:
        name, p = stack.pop()
        names.append(name)
        parents.append(p)
        me = len(names) - 1
        stack.extend((k, me) for k in reversed(children.get(name, [])))
    orphans = [b for b in bone_list if b not in names]
    if orphans:
        raise err(f"bone(s) not reachable from root in ':hierarchy': {', '.join(orphans)}")

    to_deg = 1.0 if units["angle"] == "deg" else 180.0 / math.pi
    J = len(names)
    directions = np.zeros((J, 3))
    lengths = np.zeros(J)
    root_rot = "".join(c[1] for c in root["order"] if c.startswith("R"))
    orders = [complete_order(root_rot)]
    axes = np.zeros((J, 3))
    axes[0] = np.asarray(root.get("orientation", [0.0, 0.0, 0.0])) * to_deg
    axis_orders = [root["axis"]]
    dofs = [()]
    for j, name in enumerate(names[1:], 1):
        b = bones[name]
        directions[j] = b["direction"]
        lengths[j] = b["length"]
        axes[j] = np.asarray(b["axis"]) * to_deg
        axis_orders.append(b["order"])
        d = b.get("dofs", ())
        dofs.append(d)
        orders.append(complete_order("".join(x[1].upper() for x in d)))

    offsets = np.zeros((J, 3))
    offsets[0] = root.get("position", [0.0, 0.0, 0.0])
    for j in range(1, J):
        p = parents[j]
        offsets[j] = directions[p] * lengths[p]  # zero for the root's children
    C = np.stack([euler_to_quat(axes[j], axis_orders[j]) for j in range(J)])
    skeleton = Skeleton(
        joint_names=tuple(names),
        parents=np.asarray(parents),
        offsets=offsets,
        rotation_orders=tuple(orders),
        pre_rotations=C,
        post_rotations=quat_conj(C),
        units=f"asf length {units['length']:g} (1 unit = {0.0254 / units['length']:.5g} m)",
    )
    return AsfSkeleton(
        skeleton=skeleton,
        dofs=tuple(dofs),
        root_order=root["order"],
        directions=directions,
        lengths=lengths,
        angle_unit=units["angle"],
        length_scale=float(units["length"]),
        path=str(path),
    )


_HDM_RE = re.compile(r"^HDM_([A-Za-z0-9]+)_")
_CMU_RE = re.compile(r"^(\d+)_\d+$")
_FPS_RE = re.compile(r"_\d+_(\d+)$")
#: AMC header keywords -> the angle unit they set (None: none).
_AMC_KEYWORDS = {":DEGREES": "deg", ":RADIANS": "rad", ":FULLY-SPECIFIED": None}


def find_asf(amc_path) -> Path:
    """The skeleton file of an AMC file, by the HDM05 or CMU layout.

    ``HDM_<actor>.asf`` for ``HDM_<actor>_...amc``, then ``<subject>.asf`` for
    ``<subject>_<take>.amc``, in its folder or a parent; else the only ``.asf`` in its
    folder; else MotionFormatError saying where it looked."""
    amc_path = Path(amc_path)
    stem = amc_path.stem
    folders = [amc_path.parent, *amc_path.parent.resolve().parents]
    wanted = []
    m = _HDM_RE.match(stem)
    if m:
        wanted.append(f"HDM_{m.group(1)}.asf")
    m = _CMU_RE.match(stem)
    if m:
        wanted.append(f"{m.group(1)}.asf")
    for name in wanted:
        for folder in folders:
            cand = folder / name
            if cand.is_file():
                return cand
    single = sorted(amc_path.parent.glob("*.asf"))
    if len(single) == 1:
        return single[0]
    looked = " or ".join(wanted) + " in its folder and parents, or " if wanted else ""
    raise MotionFormatError(
        amc_path,
        f"no skeleton found (looked for {looked}a single .asf in {amc_path.parent}); "
        "pass the .asf path",
    )


def amc_fps(path) -> float:
    """Frame rate from an HDM05-style name ``..._<take>_<fps>.amc``, else 120 (CMU)."""
    m = _FPS_RE.search(Path(path).stem)
    if m and 10 <= int(m.group(1)) <= 1000:
        return float(m.group(1))
    return DEFAULT_AMC_FPS


def _amc_checked(path, lines, asf, layout, width):
    """Parse AMC frames line by line, erring precisely on the first problem: (data, unit)."""
    err = partial(MotionFormatError, path)
    sk = asf.skeleton
    dofless = {sk.joint_names[j] for j in range(1, sk.n_joints) if not asf.dofs[j]}
    rows = []
    row = None
    seen = set()
    frame_no = None
    frame_line = None
    unit = None

    def close_frame(end_line):
        missing = [b for b in layout if b not in seen]
        if missing:
            raise err(
                f"frame lacks bone(s) {', '.join(missing)} before line {end_line} "
                "(truncated frame, or a file that is not fully specified)",
                line=frame_line,
                frame=frame_no,
            )
        rows.append(row)

    for ln, raw in enumerate(lines, 1):
        s = raw.strip()
        if not s or s[0] == "#":
            continue
        tok = s.split()
        if s[0] == ":":
            if frame_no is not None:
                raise err(f"keyword {tok[0]!r} after the first frame", line=ln)
            key = tok[0].upper()
            if key not in _AMC_KEYWORDS:
                raise err(f"unknown AMC keyword {tok[0]!r}", line=ln)
            unit = _AMC_KEYWORDS[key] or unit
            continue
        if len(tok) == 1 and tok[0].isdigit():
            number = int(tok[0])
            if frame_no is not None:
                close_frame(ln)
                if number != frame_no + 1:
                    raise err(
                        f"frame number {number} does not follow frame {frame_no}",
                        line=ln,
                        frame=number,
                    )
            frame_no, frame_line = number, ln
            row = [0.0] * width
            seen = set()
            continue
        if frame_no is None:
            raise err(f"data before the first frame number: {s!r}", line=ln)
        bone = tok[0]
        spec = layout.get(bone)
        if spec is None:
            why = (
                f"bone {bone!r} has no dofs in the skeleton {asf.path}"
                if bone in dofless
                else f"unknown bone {bone!r} (not in the skeleton {asf.path})"
            )
            raise err(why, line=ln, frame=frame_no)
        start, k = spec
        if len(tok) - 1 != k:
            dof = " ".join(asf.root_order) if bone == "root" else " ".join(asf.dofs[sk.index(bone)])
            raise err(
                f"bone {bone!r} has {len(tok) - 1} value(s), expected {k} ({dof})",
                line=ln,
                frame=frame_no,
            )
        if bone in seen:
            raise err(f"bone {bone!r} repeated in a frame", line=ln, frame=frame_no)
        seen.add(bone)
        try:
            vals = [float(t) for t in tok[1:]]
        except ValueError:
            raise err(
                f"non-numeric value on bone {bone!r}: {s!r}", line=ln, frame=frame_no
            ) from None
        for v in vals:
            if not math.isfinite(v):
                raise err(f"non-finite value on bone {bone!r}: {s!r}", line=ln, frame=frame_no)
        row[start : start + k] = vals

    if frame_no is None:
        what = "empty file" if not any(x.strip() for x in lines) else "no frames"
        raise err(what)
    close_frame(len(lines) + 1)

    return np.asarray(rows, dtype=float), unit


def _amc_fast(lines, layout, width):
    """``(data, unit)`` of a regular AMC file (the same bones in the same order every frame),
    vectorised, as :func:`_amc_checked`; or None to let it find what is wrong."""
    unit = None
    i = 0
    n = len(lines)
    while i < n:
        s = lines[i].strip()
        if s and s[0] == ":":
            key = s.split()[0].upper()
            if key not in _AMC_KEYWORDS:
                return None
            unit = _AMC_KEYWORDS[key] or unit
        elif s and s[0] != "#":
            break
        i += 1
    toks = [t for t in (raw.split() for raw in lines[i:]) if t]
    if not toks or len(toks[0]) != 1 or not toks[0][0].isdigit():
        return None
    per = next((k for k in range(1, len(toks)) if len(toks[k]) == 1), len(toks))
    if len(toks) % per:
        return None
    F = len(toks) // per
    heads = [t[0] for t in toks]
    names = heads[1:per]
    if sorted(names) != sorted(layout):
        return None
    lens = [len(t) for t in toks]
    if lens != lens[:per] * F:
        return None
    if any(lens[1 + b] - 1 != layout[nm][1] for b, nm in enumerate(names)):
        return None
    numbers = heads[::per]
    if any(heads[f * per + 1 : (f + 1) * per] != names for f in range(F)):
        return None
    if not all(x.isdigit() for x in numbers):
        return None
    nums = np.array(numbers, dtype=np.int64)
    if np.any(np.diff(nums) != 1):
        return None
    try:
        vals = np.array([v for t in toks for v in t[1:]], dtype=float)
    except ValueError:
        return None
    if not np.isfinite(vals).all():
        return None
    vals = vals.reshape(F, width)
    cols = np.concatenate([np.arange(layout[nm][0], layout[nm][0] + layout[nm][1]) for nm in names])
    data = np.empty((F, width))
    data[:, cols] = vals
    return data, unit


def read_amc(path, skeleton_or_asf_path=None, *, fps=None, name=None) -> Motion:
    """Read an Acclaim AMC motion on its ASF skeleton (``source="asf"``).

    ``skeleton_or_asf_path``: an :class:`AsfSkeleton` or its file (default :func:`find_asf`);
    ``fps``: default from the name (:func:`amc_fps`); ``name``: default the file stem.
    ``euler`` (F, J, 3) holds the AMC values in degrees, ``root_translation`` ``TX TY TZ``.
    MotionFormatError, naming the file, line and frame, for an empty file, no frames, a
    frame missing a bone with dofs, a bad value, an unknown, dof-less or repeated bone,
    frame numbers not consecutive, unknown keywords, or limits (:mod:`fpdtw.limits`)."""
    path = Path(path)
    if fps is None:
        fps = amc_fps(path)
    else:
        fps = limits.check_file_fps(fps, path, source=f"fps={fps}")
    if skeleton_or_asf_path is None:
        asf = read_asf(find_asf(path))
    elif isinstance(skeleton_or_asf_path, AsfSkeleton):
        asf = skeleton_or_asf_path
    elif isinstance(skeleton_or_asf_path, str | os.PathLike):
        asf = read_asf(skeleton_or_asf_path)
    else:
        raise TypeError(
            "skeleton_or_asf_path must be an AsfSkeleton (from read_asf) or an .asf path, "
            f"not {type(skeleton_or_asf_path).__name__}"
        )
    sk = asf.skeleton

    # column layout of one frame's values: root first, then each bone with dofs
    layout = {"root": (0, len(asf.root_order))}
    width = len(asf.root_order)
    for j in range(1, sk.n_joints):
        k = len(asf.dofs[j])
        if k:
            layout[sk.joint_names[j]] = (width, k)
            width += k

    lines = read_lines(path)
    parsed = _amc_fast(lines, layout, width)
    if parsed is None:  # irregular or broken file: the line-by-line parser says where
        parsed = _amc_checked(path, lines, asf, layout, width)
    data, unit = parsed
    F = limits.check_file_frames(data.shape[0], path)
    to_deg = 180.0 / math.pi if (unit or asf.angle_unit) == "rad" else 1.0
    euler = np.zeros((F, sk.n_joints, 3))
    trans = np.zeros((F, 3))
    for c, ch in enumerate(asf.root_order):
        if ch[0] == "T":
            trans[:, _AXIS[ch[1]]] = data[:, c]
        else:
            euler[:, 0, _AXIS[ch[1]]] = data[:, c] * to_deg
    for bone, (start, _k) in layout.items():
        if bone == "root":
            continue
        j = sk.index(bone)
        for c, dof in enumerate(asf.dofs[j]):
            euler[:, j, _AXIS[dof[1].upper()]] = data[:, start + c] * to_deg

    return Motion(
        name=name or path.stem,
        fps=fps,
        skeleton=sk,
        euler=euler,
        root_translation=trans,
        source="asf",
        path=str(path),
    )
