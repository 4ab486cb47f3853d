"""ASF/AMC reader: real HDM05 files, a hand-computed pose, and every bad-input case."""

from __future__ import annotations

import math
import re
import time

import numpy as np
import pytest
from reference.files import with_line

from fpdtw.errors import MotionFormatError
from fpdtw.io import load_motion
from fpdtw.io.asfamc import (
    AsfSkeleton,
    amc_fps,
    complete_order,
    find_asf,
    read_amc,
    read_asf,
)
from fpdtw.motion.joints import OPW_JOINTS, PAPER_JOINTS

ACTORS = ("bd", "bk", "dg", "mm", "tr")
CLASSES = (
    "depositFloorR",
    "elbowToKnee1RepsLelbowStart",
    "grabHighR",
    "hopBothLegs1hops",
    "jogLeftCircle4StepsRstart",
    "kickLFront1Reps",
    "lieDownFloor",
    "rotateArmsBothBackward1Reps",
    "sneak2StepsLStart",
    "squat1Reps",
    "throwBasketball",
)


@pytest.fixture(scope="module")
def hdm_rows():
    """The HDM05 clips of the data manifest (class, actor, frames per clip)."""
    from fpdtw.paper.datasets import load_manifest

    rows = [
        {"path": f.path, "motion_class": f.movement, "actor": f.actor, "frames": str(f.frames)}
        for f in load_manifest("hdm05").files
        if f.path.endswith(".amc")
    ]
    assert len(rows) == 287
    return rows


@pytest.fixture(scope="module")
def clip(data_path, hdm_rows):
    """``clip(key=value, ...)`` -> local path of the first HDM05 clip matching all fields."""

    def get(**match):
        row = next(r for r in hdm_rows if all(r[k] == v for k, v in match.items()))
        return data_path("hdm05/" + row["path"])

    return get


def _bone_table(text):
    """Independent mini-parser: bone name -> (direction, length) straight from the ASF text."""
    out = {}
    for block in re.findall(
        r"begin(.*?)end", text.split(":bonedata")[1].split(":hierarchy")[0], re.S
    ):
        name = re.search(r"name\s+(\S+)", block).group(1)
        d = [float(x) for x in re.search(r"direction\s+(\S+)\s+(\S+)\s+(\S+)", block).groups()]
        length = float(re.search(r"length\s+(\S+)", block).group(1))
        out[name] = (np.array(d), length)
    return out


# --------------------------------------------------------------------------- ASF
@pytest.mark.parametrize("actor", ACTORS)
def test_read_all_asf(data_path, actor):
    path = data_path(f"hdm05/HDM05_cut_amc/HDM_{actor}.asf")
    asf = read_asf(path)
    sk = asf.skeleton
    assert isinstance(asf, AsfSkeleton)
    assert sk.n_joints == 31 and sk.joint_names[0] == "root"
    assert asf.length_scale == 0.45 and asf.angle_unit == "deg"
    assert asf.meters_per_unit == pytest.approx(0.0254 / 0.45)
    assert "0.45" in sk.units
    assert asf.root_order == ("TX", "TY", "TZ", "RX", "RY", "RZ")
    # every bone's direction and length equal the file's (independent regex parse)
    table = _bone_table(path.read_text(encoding="latin-1"))
    assert set(table) == set(sk.joint_names[1:])
    for name, (d, length) in table.items():
        j = sk.index(name)
        np.testing.assert_allclose(asf.directions[j], d / np.linalg.norm(d), atol=1e-12)
        assert asf.lengths[j] == length
        # offset of each child = this bone's direction * length
        for c in np.flatnonzero(sk.parents == j):
            np.testing.assert_allclose(sk.offsets[c], asf.directions[j] * length, atol=1e-12)
    # hierarchy as in the file
    P = {sk.joint_names[j]: sk.joint_names[sk.parents[j]] for j in range(1, sk.n_joints)}
    assert P["lhipjoint"] == "root" and P["lfemur"] == "lhipjoint" and P["lthumb"] == "lwrist"
    assert P["lclavicle"] == "thorax" and P["head"] == "upperneck"
    # dofs and the rotation orders they give
    assert asf.dofs[sk.index("lfemur")] == ("rx", "ry", "rz")
    assert asf.dofs[sk.index("ltibia")] == ("rx",)
    assert asf.dofs[sk.index("lclavicle")] == ("ry", "rz")
    assert asf.dofs[sk.index("lhipjoint")] == ()
    assert sk.rotation_orders[sk.index("lfemur")] == "XYZ"
    assert sk.rotation_orders[sk.index("lclavicle")] == "YZX"
    assert sk.rotation_orders[sk.index("lwrist")] == "YXZ"
    # axis 0 0 20 XYZ -> C = Rz(20): quaternion (cos 10deg, 0, 0, sin 10deg); post = C^-1
    j = sk.index("lfemur")
    c10, s10 = math.cos(math.radians(10)), math.sin(math.radians(10))
    np.testing.assert_allclose(sk.pre_rotations[j], [c10, 0, 0, s10], atol=1e-12)
    np.testing.assert_allclose(sk.post_rotations[j], [c10, 0, 0, -s10], atol=1e-12)
    np.testing.assert_allclose(sk.pre_rotations[0], [1, 0, 0, 0], atol=1e-12)


def test_asf_rest_pose_literal(data_path):
    """All-zero frame: FK reproduces the rest pose; knee position from the file's numbers."""
    asf = read_asf(data_path("hdm05/HDM05_cut_amc/HDM_bd.asf"))
    sk = asf.skeleton
    from fpdtw.motion.motion import Motion

    m = Motion("rest", 120, sk, np.zeros((2, sk.n_joints, 3)), np.zeros((2, 3)), source="asf")
    pos, _ = m.forward_kinematics()
    # ltibia (the knee) = lhipjoint direction*length + lfemur direction*length (HDM_bd.asf)
    knee = 2.28399 * np.array([0.567149, -0.783011, 0.255413]) / np.linalg.norm(
        [0.567149, -0.783011, 0.255413]
    ) + 7.34031 * np.array([0.34202, -0.939693, 0]) / np.linalg.norm([0.34202, -0.939693, 0])
    np.testing.assert_allclose(pos[0, sk.index("ltibia")], knee, atol=1e-9)
    # every joint = parent joint + parent's bone vector; bone ends = start + direction*length
    ends = asf.bone_ends(pos[0])
    for j in range(1, sk.n_joints):
        p = sk.parents[j]
        np.testing.assert_allclose(pos[0, j], ends[p] if p > 0 else pos[0, 0], atol=1e-12)
    np.testing.assert_allclose(pos[0], pos[1])


# --------------------------------------------------------------------------- AMC, real files
@pytest.mark.parametrize(
    "key,value", [("motion_class", c) for c in CLASSES] + [("actor", a) for a in ACTORS]
)
def test_amc_frames_match_manifest(hdm_rows, data_path, key, value):
    row = next(r for r in hdm_rows if r[key] == value)
    m = read_amc(data_path("hdm05/" + row["path"]))
    assert m.n_frames == int(row["frames"])
    assert m.fps == 120.0 and m.source == "asf"
    assert m.name == row["path"].rsplit("/", 1)[1][:-4]
    assert m.skeleton.n_joints == 31
    # all paper and OPW joints resolve to ASF bones
    assert list(m.skeleton.joint_names[i] for i in m.joint_indices(PAPER_JOINTS)) == [
        "lfemur",
        "rfemur",
        "ltibia",
        "rtibia",
        "lhumerus",
        "rhumerus",
        "lradius",
        "rradius",
    ]
    assert len(m.joint_indices(OPW_JOINTS)) == 16


def test_all_287_clips_parse(hdm_rows, data_path):
    """Every clip parses with the right frame count (timing printed, not asserted)."""
    t0 = time.perf_counter()
    total = 0
    for row in hdm_rows:
        m = read_amc(data_path("hdm05/" + row["path"]))
        assert m.n_frames == int(row["frames"]), row["path"]
        assert np.isfinite(m.quats).all()
        total += m.n_frames
    dt = time.perf_counter() - t0
    print(f"parsed 287 AMC clips ({total} frames) in {dt:.2f} s")
    assert total == sum(int(r["frames"]) for r in hdm_rows)


def test_amc_values_stored_as_in_file(data_path):
    """Frame 1 of HDM_bd_depositFloorR_001_120.amc, values copied from the file."""
    m = read_amc(data_path("hdm05/HDM05_cut_amc/depositFloorR/HDM_bd_depositFloorR_001_120.amc"))
    names = m.joint_names
    np.testing.assert_array_equal(m.root_translation[0], [5.19708, 17.2839, -4.18609])
    np.testing.assert_array_equal(m.euler[0, 0], [248.435, 87.4513, -96.5087])
    np.testing.assert_array_equal(
        m.euler[0, names.index("lhumerus")], [-15.5038, -10.3134, 83.5213]
    )
    np.testing.assert_array_equal(m.euler[0, names.index("ltibia")], [28.0444, 0, 0])
    np.testing.assert_array_equal(m.euler[0, names.index("lwrist")], [0, 20.7222, 0])  # dof ry
    np.testing.assert_array_equal(m.euler[0, names.index("lfoot")], [-2.35707, 0, -6.42233])
    np.testing.assert_array_equal(
        m.euler[0, names.index("lclavicle")], [0, 3.97569e-15, 1.51076e-14]
    )
    np.testing.assert_array_equal(m.euler[:, names.index("lhipjoint")], 0.0)  # no dofs
    np.testing.assert_array_equal(m.root_translation[1], [5.28893, 17.294, -4.18958])
    np.testing.assert_array_equal(m.euler[-1, names.index("ltoes")], [-16.1021, 0, 0])


@pytest.mark.parametrize("cls", ["throwBasketball", "jogLeftCircle4StepsRstart", "lieDownFloor"])
def test_fk_bone_lengths_constant(clip, cls):
    path = clip(motion_class=cls)
    asf = read_asf(find_asf(path))
    m = read_amc(path, asf)
    pos, rot = m.forward_kinematics()
    sk = m.skeleton
    for j in range(1, sk.n_joints):
        p = sk.parents[j]
        d = np.linalg.norm(pos[:, j] - pos[:, p], axis=1)
        np.testing.assert_allclose(d, asf.lengths[p], rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(np.linalg.norm(rot, axis=-1), 1.0, atol=1e-12)


def test_fk_standing_pose_is_upright(clip):
    """A plausibility check of the whole convention: first frame of a standing clip, y up."""
    m = read_amc(clip(motion_class="throwBasketball", actor="bd"))
    pos, _ = m.forward_kinematics()
    y = {n: pos[0, m.joint_names.index(n), 1] for n in m.joint_names}
    assert y["head"] > y["thorax"] > y["root"] > y["ltibia"] > y["lfoot"] > 0
    assert y["rfemur"] > y["rtibia"] > y["rfoot"] > y["rtoes"] > 0
    assert y["lhumerus"] > y["lradius"] > y["lwrist"]  # arms hanging down
    # the feet touch a common floor: lowest toe height over the clip is small
    toes = pos[:, [m.joint_names.index("ltoes"), m.joint_names.index("rtoes")], 1]
    assert 0 < toes.min() < 1.5  # < 8.5 cm at 0.0564 m per unit


# --------------------------------------------------------------------------- hand-computed pose
TINY_ASF = """# hand-made skeleton
:version 1.10
:name tiny
:units
  mass 1.0
  length 1.0
  angle deg
:documentation
  begin and end words in documentation are ignored
:root
  order TX TY TZ RX RY RZ
  axis XYZ
  position 0 0 0
  orientation 0 0 0
:bonedata
  begin
    id 1
    name upper
    direction 1 0 0
    length 2
    axis 0 0 90 XYZ
    dof rx ry rz
    limits (-180.0 180.0)
           (-180.0 180.0)
           (-180.0 180.0)
  end
  begin
    id 2
    name lower
    direction 0 1 0
    length 1
    axis 0 90 0 XYZ
    dof rx
    limits (-180.0 180.0)
  end
  begin
    id 3
    name tip
    direction 0 0 1
    length 0.5
    axis 0 0 0 XYZ
  end
:hierarchy
  begin
    root upper
    upper lower
    lower tip
  end
"""

TINY_AMC = """:FULLY-SPECIFIED
:DEGREES
1
root 1 2 3 0 0 0
upper 90 0 0
lower 90
2
root 0 0 0 0 0 90
upper 0 0 0
lower 0
3
root 0 0 0 0 0 0
upper 90 0 90
lower 0
4
root 1 0 0 0 90 0
upper 0 0 0
lower 0
"""

# Worked on paper (Rx(90): y->z, z->-y; Ry(90): z->x, x->-z; Rz(90): x->y, y->-x).
# Frame 1: C_upper = Rz90, M = Rx90 -> G_upper = rotation by 90 about Rz90*x = y, i.e. Ry90.
#   lower = (1,2,3) + Ry90 (2,0,0) = (1,2,1).  C_lower = Ry90, M = Rx90 -> rotation by 90
#   about Ry90*x = -z, i.e. Rz(-90); tip = lower + Ry90 Rz(-90) (0,1,0) = lower + Ry90 (1,0,0)
#   = (1,2,1) + (0,0,-1) = (1,2,0).
# Frame 2: rest pose (upper at 0, lower at (2,0,0), tip at (2,1,0)) turned by the root's Rz90.
# Frame 3: M_upper = Rz90 Rx90 (dof order rx ry rz: x first), G = Rz90 M Rz(-90):
#   (2,0,0) -> (0,-2,0) -> (0,0,-2) -> (0,0,-2) -> (0,0,-2); (0,1,0) -> (1,0,0) -> (1,0,0)
#   -> (0,1,0) -> (-1,0,0). lower = (0,0,-2), tip = (-1,0,-2).
# Frame 4: root at (1,0,0) turned by Ry90: lower = (1,0,0) + (0,0,-2), tip = lower + (0,1,0).
EXPECTED = np.array(
    [
        # root, upper, lower, tip
        [[1, 2, 3], [1, 2, 3], [1, 2, 1], [1, 2, 0]],
        [[0, 0, 0], [0, 0, 0], [0, 2, 0], [-1, 2, 0]],
        [[0, 0, 0], [0, 0, 0], [0, 0, -2], [-1, 0, -2]],
        [[1, 0, 0], [1, 0, 0], [1, 0, -2], [1, 1, -2]],
    ],
    dtype=float,
)


@pytest.fixture
def tiny(tmp_path):
    asf = tmp_path / "tiny.asf"
    asf.write_text(TINY_ASF)
    amc = tmp_path / "tiny_clip.amc"
    amc.write_text(TINY_AMC)
    return asf, amc


def test_hand_computed_pose(tiny):
    asf_path, amc_path = tiny
    m = read_amc(amc_path, asf_path)
    assert m.joint_names == ("root", "upper", "lower", "tip")
    assert m.n_frames == 4 and m.fps == 120.0  # no _<fps> suffix -> 120
    pos, _ = m.forward_kinematics()
    np.testing.assert_allclose(pos, EXPECTED, atol=1e-12)
    # stored Euler angles are the AMC values in (x, y, z) columns
    np.testing.assert_array_equal(m.euler[2, 1], [90, 0, 90])
    np.testing.assert_array_equal(m.euler[0, 2], [90, 0, 0])
    np.testing.assert_array_equal(m.euler[:, 3], 0.0)
    np.testing.assert_array_equal(m.root_translation[0], [1, 2, 3])


def test_hand_computed_pose_in_radians(tmp_path):
    half_pi = repr(math.pi / 2)
    asf_text = (
        TINY_ASF.replace("angle deg", "angle rad")
        .replace("axis 0 0 90 XYZ", f"axis 0 0 {half_pi} XYZ")
        .replace("axis 0 90 0 XYZ", f"axis 0 {half_pi} 0 XYZ")
    )
    amc_text = re.sub(r"\b90\b", half_pi, TINY_AMC).replace(":DEGREES", ":RADIANS")
    (tmp_path / "r.asf").write_text(asf_text)
    (tmp_path / "r.amc").write_text(amc_text)
    m = read_amc(tmp_path / "r.amc", tmp_path / "r.asf")
    pos, _ = m.forward_kinematics()
    np.testing.assert_allclose(pos, EXPECTED, atol=1e-12)
    np.testing.assert_allclose(m.euler[2, 1], [90, 0, 90], atol=1e-12)  # stored in degrees
    # without :DEGREES/:RADIANS the AMC follows the ASF angle unit (rad here)
    (tmp_path / "r2.amc").write_text(amc_text.replace(":RADIANS\n", ""))
    m2 = read_amc(tmp_path / "r2.amc", read_asf(tmp_path / "r.asf"))
    np.testing.assert_allclose(m2.euler, m.euler, atol=1e-12)


def test_root_order_and_position(tmp_path):
    """A shuffled root order and a non-zero ASF root position (FK adds it)."""
    asf_text = TINY_ASF.replace("order TX TY TZ RX RY RZ", "order RZ TX RY TY RX TZ").replace(
        "position 0 0 0", "position 0 0 5"
    )
    (tmp_path / "o.asf").write_text(asf_text)
    # frame 4 of TINY_AMC (TX=1, RY=90) written in the order RZ TX RY TY RX TZ
    (tmp_path / "o.amc").write_text(
        ":FULLY-SPECIFIED\n1\nroot 0 1 90 0 0 0\nupper 0 0 0\nlower 0\n"
    )
    m = read_amc(tmp_path / "o.amc", tmp_path / "o.asf")
    assert m.skeleton.rotation_orders[0] == "ZYX"
    np.testing.assert_array_equal(m.root_translation[0], [1, 0, 0])
    np.testing.assert_array_equal(m.euler[0, 0], [0, 90, 0])
    pos, _ = m.forward_kinematics()
    np.testing.assert_allclose(pos[0], EXPECTED[3] + [0, 0, 5], atol=1e-12)


def test_irregular_but_valid_amc(tmp_path):
    """Bones in another order per frame, comments and blank lines: same result."""
    (tmp_path / "t.asf").write_text(TINY_ASF)
    lines = TINY_AMC.splitlines()
    lines[7:10] = ["# a comment", "", "lower 0", "upper 0 0 0", "root 0 0 0 0 0 90"]
    (tmp_path / "irr.amc").write_text("\n".join(lines) + "\n\n")
    (tmp_path / "reg.amc").write_text(TINY_AMC)
    irr = read_amc(tmp_path / "irr.amc", tmp_path / "t.asf")
    reg = read_amc(tmp_path / "reg.amc", tmp_path / "t.asf")
    np.testing.assert_array_equal(irr.euler, reg.euler)
    np.testing.assert_array_equal(irr.root_translation, reg.root_translation)
    np.testing.assert_allclose(irr.forward_kinematics()[0], EXPECTED, atol=1e-12)


def test_fast_and_checked_parsers_agree(clip):
    """The vectorised parser and the line-by-line one give identical frames."""
    from fpdtw.io._text import read_lines as _read_lines
    from fpdtw.io.asfamc import _amc_checked, _amc_fast

    for path in (clip(motion_class="grabHighR", actor="tr"), clip(motion_class="squat1Reps")):
        asf = read_asf(find_asf(path))
        sk = asf.skeleton
        layout, width = {"root": (0, 6)}, 6
        for j in range(1, sk.n_joints):
            if asf.dofs[j]:
                layout[sk.joint_names[j]] = (width, len(asf.dofs[j]))
                width += len(asf.dofs[j])
        lines = _read_lines(path)
        fast = _amc_fast(lines, layout, width)
        assert fast is not None  # HDM05 files are regular
        checked = _amc_checked(path, lines, asf, layout, width)
        np.testing.assert_array_equal(fast[0], checked[0])
        assert fast[1] == checked[1] == "deg"


def test_complete_order():
    assert complete_order("XYZ") == "XYZ"
    assert complete_order("XZ") == "XZY"
    assert complete_order("Y") == "YXZ"
    assert complete_order("") == "XYZ"


# --------------------------------------------------------------------------- fps, name, lookup
def test_fps_and_name(tmp_path):
    assert amc_fps("HDM_bd_depositFloorR_001_120.amc") == 120.0
    assert amc_fps("HDM_bd_walk_003_60.amc") == 60.0
    assert amc_fps("18_01.amc") == 120.0  # CMU: <subject>_<take>, no rate in the name
    assert amc_fps("clip.amc") == 120.0
    (tmp_path / "x.asf").write_text(TINY_ASF)
    (tmp_path / "HDM_zz_test_001_60.amc").write_text(TINY_AMC)
    m = read_amc(tmp_path / "HDM_zz_test_001_60.amc", tmp_path / "x.asf")
    assert m.fps == 60.0 and m.name == "HDM_zz_test_001_60"
    m = read_amc(tmp_path / "HDM_zz_test_001_60.amc", tmp_path / "x.asf", fps=30, name="n")
    assert m.fps == 30.0 and m.name == "n"


def test_find_asf_layouts(tmp_path):
    # HDM05: HDM_<actor>.asf in a parent folder (and another actor's skeleton beside it)
    (tmp_path / "HDM_zz.asf").write_text(TINY_ASF)
    (tmp_path / "HDM_yy.asf").write_text("not used")
    (tmp_path / "cls").mkdir()
    clip = tmp_path / "cls" / "HDM_zz_cls_001_120.amc"
    clip.write_text(TINY_AMC)
    assert find_asf(clip).resolve() == (tmp_path / "HDM_zz.asf").resolve()
    m = read_amc(clip)
    np.testing.assert_allclose(m.forward_kinematics()[0], EXPECTED, atol=1e-12)
    # CMU: <subject>.asf next to <subject>_<take>.amc
    cmu = tmp_path / "cmu"
    cmu.mkdir()
    (cmu / "07.asf").write_text(TINY_ASF)
    (cmu / "08.asf").write_text("not used")
    (cmu / "07_05.amc").write_text(TINY_AMC)
    assert find_asf(cmu / "07_05.amc") == cmu / "07.asf"
    # any name: the only .asf in the folder
    one = tmp_path / "one"
    one.mkdir()
    (one / "skel.asf").write_text(TINY_ASF)
    (one / "clip.amc").write_text(TINY_AMC)
    assert find_asf(one / "clip.amc") == one / "skel.asf"
    assert load_motion(one / "clip.amc").n_frames == 4
    assert load_motion(one / "clip.amc", skeleton=one / "skel.asf").n_frames == 4
    # none, or two candidates and no naming rule: a clear error
    none = tmp_path / "none"
    none.mkdir()
    (none / "clip.amc").write_text(TINY_AMC)
    with pytest.raises(MotionFormatError, match="no skeleton found"):
        read_amc(none / "clip.amc")
    (none / "a.asf").write_text(TINY_ASF)
    (none / "b.asf").write_text(TINY_ASF)
    with pytest.raises(MotionFormatError, match=r"clip\.amc.*no skeleton found"):
        read_amc(none / "clip.amc")


def test_skeleton_argument_type(tiny):
    asf_path, amc_path = tiny
    with pytest.raises(TypeError, match="AsfSkeleton"):
        read_amc(amc_path, read_asf(asf_path).skeleton)


# --------------------------------------------------------------------------- bad AMC input
BASE = TINY_AMC.splitlines()  # line k of the file is BASE[k - 1]


def _with(line_no, new):
    return with_line(TINY_AMC, line_no, new)


BAD_AMC = [
    # (id, text, line, frame, words in the message)
    ("missing value", _with(5, "upper 90 0"), 5, 1, "has 2 value(s), expected 3"),
    ("extra value", _with(6, "lower 90 1"), 6, 1, "has 2 value(s), expected 1"),
    ("non-numeric", _with(5, "upper 90 abc 0"), 5, 1, "non-numeric"),
    ("nan", _with(8, "root 0 0 nan 0 0 90"), 8, 2, "non-finite"),
    ("inf", _with(9, "upper inf 0 0"), 9, 2, "non-finite"),
    ("unknown bone", _with(9, "elbow 0 0 0"), 9, 2, "unknown bone 'elbow'"),
    ("bone without dofs", _with(10, "tip 0"), 10, 2, "'tip' has no dofs"),
    ("frame numbers", _with(7, "3"), 7, 3, "does not follow frame 1"),
    ("repeated bone", _with(10, "upper 0 0 0"), 10, 2, "repeated"),
    ("truncated last frame", "\n".join(BASE[:-1]), 15, 4, "lacks bone(s) lower"),
    ("truncated middle frame", _with(10, None), 7, 2, "lacks bone(s) lower"),
    ("unknown keyword", _with(1, ":FOO"), 1, None, "unknown AMC keyword"),
    ("keyword after frames", _with(11, ":DEGREES"), 11, None, "after the first frame"),
    ("data before frames", _with(3, "# no frame number"), 4, None, "before the first frame"),
]


@pytest.mark.parametrize(
    "text,line,frame,words", [c[1:] for c in BAD_AMC], ids=[c[0] for c in BAD_AMC]
)
def test_bad_amc(tmp_path, text, line, frame, words):
    (tmp_path / "tiny.asf").write_text(TINY_ASF)
    bad = tmp_path / "broken_clip.amc"
    bad.write_text(text)
    with pytest.raises(MotionFormatError) as ei:
        read_amc(bad, tmp_path / "tiny.asf")
    msg = str(ei.value)
    assert "broken_clip.amc" in msg and f"line {line}" in msg and words in msg
    assert ei.value.line == line and ei.value.frame == frame


@pytest.mark.parametrize(
    "text,words",
    [("", "empty file"), ("\n  \n", "empty file"), (":FULLY-SPECIFIED\n:DEGREES\n", "no frames")],
)
def test_empty_amc(tmp_path, text, words):
    (tmp_path / "tiny.asf").write_text(TINY_ASF)
    (tmp_path / "e.amc").write_text(text)
    with pytest.raises(MotionFormatError, match=rf"e\.amc: {words}"):
        read_amc(tmp_path / "e.amc", tmp_path / "tiny.asf")


def test_amc_skeleton_mismatch(tmp_path, clip):
    """A real HDM05 clip on the tiny skeleton, and the tiny clip on a skeleton with other dofs."""
    (tmp_path / "tiny.asf").write_text(TINY_ASF)
    real = clip(motion_class="squat1Reps")
    with pytest.raises(MotionFormatError) as ei:
        read_amc(real, tmp_path / "tiny.asf")
    assert real.name in str(ei.value) and "line 6" in str(ei.value)
    assert "unknown bone 'lowerback'" in str(ei.value) and ei.value.frame == 1
    # lower with two dofs in the skeleton, one value in the AMC
    (tmp_path / "two.asf").write_text(TINY_ASF.replace("    dof rx\n", "    dof rx rz\n"))
    (tmp_path / "c.amc").write_text(TINY_AMC)
    with pytest.raises(
        MotionFormatError, match=r"c\.amc \(line 6, frame 1\).*expected 2 \(rx rz\)"
    ):
        read_amc(tmp_path / "c.amc", tmp_path / "two.asf")


# --------------------------------------------------------------------------- bad ASF input
def _asf_with(old, new):
    assert old in TINY_ASF
    return TINY_ASF.replace(old, new, 1)


def _last_line_of(text, needle):
    return [i for i, s in enumerate(text.splitlines(), 1) if needle in s][-1]


BAD_ASF = [
    ("non-numeric length", _asf_with("length 2\n", "length two\n"), "length two", "non-numeric"),
    ("short direction", _asf_with("direction 1 0 0", "direction 1 0"), "direction 1 0", "needs 3"),
    ("zero direction", _asf_with("direction 1 0 0", "direction 0 0 0"), "direction 0 0 0", "zero"),
    ("nan axis", _asf_with("axis 0 0 90 XYZ", "axis 0 nan 90 XYZ"), "axis 0 nan", "non-finite"),
    ("bad axis order", _asf_with("axis 0 0 90 XYZ", "axis 0 0 90 XYQ"), "XYQ", "rotation order"),
    ("translation dof", _asf_with("dof rx ry rz", "dof rx tx"), "dof rx tx", "unsupported dof"),
    ("repeated dof", _asf_with("dof rx ry rz", "dof rx rx"), "dof rx rx", "repeated dof"),
    ("bad angle unit", _asf_with("angle deg", "angle grad"), "angle grad", "deg' or 'rad"),
    (
        "bad root order",
        _asf_with("order TX TY TZ RX RY RZ", "order TX TX"),
        "order TX",
        "root order",
    ),
    (
        "unknown in hierarchy",
        _asf_with("upper lower\n", "upper elbow\n"),
        "upper elbow",
        "unknown bone",
    ),
    (
        "two parents",
        _asf_with("lower tip\n", "lower tip\n    upper tip\n"),
        "upper tip",
        "two parents",
    ),
    ("duplicate name", _asf_with("name lower", "name upper"), "name upper", "duplicate bone"),
    ("missing field", _asf_with("    length 0.5\n", ""), None, "has no 'length'"),
    (
        "unclosed bone",
        _asf_with("    axis 0 0 0 XYZ\n  end\n", "    axis 0 0 0 XYZ\n"),
        ":hierarchy",
        "not closed",
    ),
]


@pytest.mark.parametrize("text,needle,words", [c[1:] for c in BAD_ASF], ids=[c[0] for c in BAD_ASF])
def test_bad_asf(tmp_path, text, needle, words):
    bad = tmp_path / "broken.asf"
    bad.write_text(text)
    with pytest.raises(MotionFormatError) as ei:
        read_asf(bad)
    msg = str(ei.value)
    assert "broken.asf" in msg and words in msg
    if needle is not None:
        line = _last_line_of(text, needle)
        assert f"line {line}" in msg and ei.value.line == line
    else:
        assert ei.value.line is not None


@pytest.mark.parametrize(
    "text,words",
    [
        ("", "empty file"),
        (TINY_ASF.split(":hierarchy")[0], "no ':hierarchy'"),
        (TINY_ASF.replace("    lower tip\n", ""), "not reachable from root in ':hierarchy': tip"),
        (TINY_ASF.replace("  axis XYZ\n", ""), "needs 'order' and 'axis'"),
    ],
    ids=["empty", "no hierarchy", "orphan bone", "root axis"],
)
def test_bad_asf_structure(tmp_path, text, words):
    (tmp_path / "s.asf").write_text(text)
    with pytest.raises(MotionFormatError, match=r"s\.asf") as ei:
        read_asf(tmp_path / "s.asf")
    assert words in str(ei.value)


def test_missing_files(tmp_path):
    with pytest.raises(MotionFormatError, match=r"nope\.asf: no such file"):
        read_asf(tmp_path / "nope.asf")
    (tmp_path / "t.asf").write_text(TINY_ASF)
    with pytest.raises(MotionFormatError, match=r"nope\.amc: no such file"):
        read_amc(tmp_path / "nope.amc", tmp_path / "t.asf")
    with pytest.raises(MotionFormatError, match=re.escape(f"{tmp_path}: is a directory")):
        read_amc(tmp_path / "t.amc", tmp_path)  # the skeleton given is a folder
