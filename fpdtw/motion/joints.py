"""Canonical joint names, how each data source names them, and joint maps (docs/align.md).

A rotation joint is the one that moves the limb ("left_hip" is ASF ``lfemur``,
"left_shoulder" the upper arm, not the clavicle).
"""

from __future__ import annotations

import csv
import functools
import io
from importlib import resources
from pathlib import Path

from fpdtw.errors import MotionFormatError

#: The FP-DTW paper's 8 joints (Section 4), in a fixed order.
PAPER_JOINTS = tuple(
    "left_hip right_hip left_knee right_knee "
    "left_shoulder right_shoulder left_elbow right_elbow".split()
)

#: The OPW poster's 16 joints (eq. 5), in the poster's order.
OPW_JOINTS = tuple(
    "head center_hip right_hip left_hip middle_chest upper_chest left_shoulder right_shoulder "
    "left_elbow right_elbow left_wrist right_wrist left_knee right_knee left_ankle "
    "right_ankle".split()
)

#: ASF/AMC naming (HDM05, and CMU's BVH exports which keep the ASF bone names).
ASF_NAMES = {
    "center_hip": ("root", "hip"),
    "left_hip": ("lfemur",),
    "right_hip": ("rfemur",),
    "left_knee": ("ltibia",),
    "right_knee": ("rtibia",),
    "left_ankle": ("lfoot",),
    "right_ankle": ("rfoot",),
    "middle_chest": ("upperback",),
    "upper_chest": ("thorax",),
    "head": ("head",),
    "left_shoulder": ("lhumerus",),
    "right_shoulder": ("rhumerus",),
    "left_elbow": ("lradius",),
    "right_elbow": ("rradius",),
    "left_wrist": ("lwrist", "lhand"),
    "right_wrist": ("rwrist", "rhand"),
}

#: Naming of common FBX / MotionBuilder / Mixamo rigs (the authors' rig: the first candidates).
FBX_NAMES = {
    "center_hip": ("Hips", "Pelvis", "Root"),
    "left_hip": ("LeftUpLeg", "LeftThigh", "LeftHip", "L_Thigh"),
    "right_hip": ("RightUpLeg", "RightThigh", "RightHip", "R_Thigh"),
    "left_knee": ("LeftLeg", "LeftShin", "LeftKnee", "L_Calf"),
    "right_knee": ("RightLeg", "RightShin", "RightKnee", "R_Calf"),
    "left_ankle": ("LeftFoot", "LeftAnkle", "L_Foot"),
    "right_ankle": ("RightFoot", "RightAnkle", "R_Foot"),
    "middle_chest": ("Spine1", "Spine2", "Chest"),
    "upper_chest": ("Spine3", "Spine2", "UpperChest", "Chest"),
    "head": ("Head",),
    "left_shoulder": ("LeftArm", "LeftUpperArm", "LeftShoulder", "L_UpperArm"),
    "right_shoulder": ("RightArm", "RightUpperArm", "RightShoulder", "R_UpperArm"),
    "left_elbow": ("LeftForeArm", "LeftLowerArm", "LeftElbow", "L_Forearm"),
    "right_elbow": ("RightForeArm", "RightLowerArm", "RightElbow", "R_Forearm"),
    "left_wrist": ("LeftHand", "LeftWrist", "L_Hand"),
    "right_wrist": ("RightHand", "RightWrist", "R_Hand"),
}

NAMINGS = {"asf": ASF_NAMES, "bvh": ASF_NAMES, "fbx": FBX_NAMES}

#: Every canonical joint a joint map may name (the OPW joints include the paper's 8).
ALL_JOINTS = OPW_JOINTS

#: The built-in joint maps (``joint_maps/<name>.csv``), tried after the source format's own.
BUILTIN_JOINT_MAPS = ("authors_fbx", "mixamo", "cmu_bvh_motionbuilder", "asf", "cmu_bvh_asf_names")
_FIRST_BY_SOURCE = {
    "fbx": ("authors_fbx", "mixamo"),
    "asf": ("asf",),
    "bvh": ("cmu_bvh_asf_names", "cmu_bvh_motionbuilder", "mixamo"),
}


def _by_bare_name(joint_names) -> dict:
    """The skeleton's joint names by name without namespace and case (the first wins)."""
    bare = {}
    for n in joint_names:
        bare.setdefault(n.rsplit(":", 1)[-1].lower(), n)
    return bare


def resolve_joint_map(joint_names, naming):
    """Canonical name -> skeleton joint name, by the candidates of ``naming``.

    ``naming``: a dict of candidates or a key of :data:`NAMINGS`; namespaces and case are
    ignored; names without a match are left out."""
    if isinstance(naming, str):
        naming = NAMINGS[naming]
    bare = _by_bare_name(joint_names)
    out = {}
    for canon, candidates in naming.items():
        for cand in candidates:
            hit = bare.get(cand.lower())
            if hit is not None:
                out[canon] = hit
                break
    return out


def _parse_joint_map(text: str, where) -> dict:
    """``{our joint: the rig's name}`` of a joint map CSV's text (errors name ``where``)."""
    rows = [
        (n, line)
        for n, line in enumerate(text.splitlines(), 1)
        if line.strip() and not line.lstrip().startswith("#")
    ]
    if not rows:
        raise MotionFormatError(where, "empty joint map: expected a header 'joint,name' and rows")
    first, header = rows[0]
    if [c.strip().lower() for c in next(csv.reader([header]))] != ["joint", "name"]:
        raise MotionFormatError(
            where, f"a joint map starts with the header 'joint,name', got {header!r}", line=first
        )
    out = {}
    for n, line in rows[1:]:
        cells = [c.strip() for c in next(csv.reader(io.StringIO(line)))]
        if len(cells) != 2 or not all(cells):
            raise MotionFormatError(
                where, f"expected two cells 'joint,name', got {line.strip()!r}", line=n
            )
        joint, name = cells
        if joint not in ALL_JOINTS:
            raise MotionFormatError(
                where,
                f"unknown joint {joint!r}; the joints a map names are {', '.join(ALL_JOINTS)}",
                line=n,
            )
        if joint in out:
            raise MotionFormatError(where, f"joint {joint!r} is mapped twice", line=n)
        out[joint] = name
    if not out:
        raise MotionFormatError(where, "the joint map has a header but no rows")
    return out


def read_joint_map(path) -> dict:
    """Read a joint map CSV ``joint,name``: ``{our joint: the rig's joint name}``.

    MotionFormatError for a file that is not UTF-8 text, no ``joint,name`` header, a row
    without two cells, an unknown joint or a joint mapped twice (naming the file and line)."""
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8-sig")
    except UnicodeDecodeError:
        raise MotionFormatError(p, "not a text (UTF-8) joint map") from None
    return _parse_joint_map(text, p)


@functools.cache
def builtin_joint_map(name: str) -> dict:
    """A built-in joint map by name (one of :data:`BUILTIN_JOINT_MAPS`)."""
    if name not in BUILTIN_JOINT_MAPS:
        raise KeyError(f"no built-in joint map {name!r}; known: {', '.join(BUILTIN_JOINT_MAPS)}")
    text = resources.files("fpdtw.motion").joinpath("joint_maps", f"{name}.csv").read_text()
    return _parse_joint_map(text, f"joint map {name}")


def _apply(joint_map: dict, joint_names) -> dict:
    """The entries of a map whose rig name the skeleton has (namespaces ignored)."""
    bare = _by_bare_name(joint_names)
    out = {}
    for canon, own in joint_map.items():
        hit = bare.get(own.rsplit(":", 1)[-1].lower())
        if hit is not None:
            out[canon] = hit
    return out


def find_joint_map(joint_names, source: str = "", maps=()) -> tuple:
    """The joint map of a skeleton, and which one it is.

    The first of ``maps`` (the user's) whose every joint the skeleton has (``"user map
    1"``); else the first built-in map (the ``source`` format's first) with all of
    :data:`ALL_JOINTS`, else with the 8 cost joints; else the usual names (:data:`NAMINGS`)
    that find the most (``"usual names"``). Names match without case and namespace."""
    for i, m in enumerate(maps):
        jm = _apply(m, joint_names)
        if len(jm) == len(m):
            return jm, f"user map {i + 1}"
    first = _FIRST_BY_SOURCE.get(source, ())
    order = [(n, builtin_joint_map(n)) for n in first]
    order += [(n, builtin_joint_map(n)) for n in BUILTIN_JOINT_MAPS if n not in first]
    found = [(label, _apply(m, joint_names)) for label, m in order]
    for need in (ALL_JOINTS, PAPER_JOINTS):
        for label, jm in found:
            if all(j in jm for j in need):
                return jm, label
    # the usual names of every format (the source's first), keeping the one that finds most
    namings = [NAMINGS.get(source, FBX_NAMES), ASF_NAMES, FBX_NAMES]
    partial = [resolve_joint_map(joint_names, n) for n in namings]
    return max(partial, key=len), "usual names"


def missing_joints_message(missing, have, what: str = "") -> str:
    """The message for joints no joint map finds.

    It names the joints ``missing`` (ours), those the skeleton ``have``, what they are for,
    and the way out (``--joint-map``)."""
    what = f" ({what})" if what else ""
    s = "s" if len(missing) > 1 else ""
    return (
        f"unknown joint{s} {', '.join(repr(m) for m in missing)}{what}: no joint map finds "
        f"{'them' if s else 'it'} in this skeleton, which has {', '.join(have)}. Give a joint "
        "map (a CSV 'joint,name': our joint -> this rig's name) with --joint-map FILE or "
        "Motion.with_joint_map"
    )
