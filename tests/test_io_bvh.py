"""BVH reader and writer: CMU 18_01, a hand-computed pose, bvhio cross-check, bad input."""

from __future__ import annotations

import numpy as np
import pytest
from reference.files import bvhio_positions, with_line

from fpdtw.errors import MotionFormatError
from fpdtw.io import load_motion
from fpdtw.io.asfamc import read_amc
from fpdtw.io.bvh import bvh_euler, read_bvh, write_bvh
from fpdtw.motion.joints import OPW_JOINTS, PAPER_JOINTS


@pytest.fixture(scope="module")
def cmu_path(data_path):
    return data_path("cmu/18_01.bvh")


@pytest.fixture(scope="module")
def cmu(cmu_path):
    return read_bvh(cmu_path)


# --------------------------------------------------------------------------- CMU 18_01
def test_cmu_loads(cmu):
    m = cmu
    assert m.n_frames == 303 and m.fps == 30.0 and m.source == "bvh"
    assert m.name == "18_01"
    assert m.skeleton.n_joints == 31 and m.joint_names[0] == "hip"
    assert set(m.skeleton.rotation_orders) == {"XYZ"}  # Zrotation Yrotation Xrotation
    assert m.joint_map["center_hip"] == "hip"
    paper = [m.joint_names[i] for i in m.joint_indices(PAPER_JOINTS)]
    assert paper == ["lfemur", "rfemur", "ltibia", "rtibia", "lhumerus", "rhumerus"] + [
        "lradius",
        "rradius",
    ]
    opw = [m.joint_names[i] for i in m.joint_indices(OPW_JOINTS)]
    assert opw[:6] == ["head", "hip", "rfemur", "lfemur", "upperback", "thorax"]
    assert opw[10:12] == ["lwrist", "rwrist"] and opw[14:] == ["lfoot", "rfoot"]
    # values from the file (first data line; channels Z Y X stored as x, y, z columns)
    np.testing.assert_array_equal(m.root_translation[0], [9.2465, 17.8507, 15.8856])
    np.testing.assert_array_equal(m.euler[0, 0], [-176.8490, 6.9835, -174.2600])
    np.testing.assert_array_equal(
        m.euler[0, m.joint_names.index("lfemur")], [-26.4138, -7.7791, -11.7134]
    )
    np.testing.assert_array_equal(
        m.skeleton.offsets[m.joint_names.index("lfemur")], [1.37959, -1.78713, 0.86582]
    )
    np.testing.assert_array_equal(m.skeleton.offsets[0], 0.0)
    # last line of the file
    np.testing.assert_array_equal(m.euler[-1, -1], [2.4612, -7.0833, 2.8284])


def test_cmu_bone_lengths_constant(cmu):
    pos, _ = cmu.forward_kinematics()
    sk = cmu.skeleton
    for j in range(1, sk.n_joints):
        d = np.linalg.norm(pos[:, j] - pos[:, sk.parents[j]], axis=1)
        np.testing.assert_allclose(d, np.linalg.norm(sk.offsets[j]), rtol=1e-9, atol=1e-9)


def test_cmu_positions_match_bvhio(cmu, cmu_path):
    frames = [0, 1, 150, 302]
    names, ref = bvhio_positions(cmu_path, frames)
    assert names == list(cmu.joint_names)
    pos, _ = cmu.forward_kinematics()
    # bvhio computes in float32 (glm): agreement to ~1e-5 of a ~20-unit skeleton
    np.testing.assert_allclose(pos[frames], ref, atol=1e-4)


# --------------------------------------------------------------------------- hand-computed pose
TINY = """HIERARCHY
ROOT Hips
{
  OFFSET 0 0 0
  CHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation
  JOINT Chest
  {
    OFFSET 0 1 0
    CHANNELS 3 Zrotation Xrotation Yrotation
    JOINT Head
    {
      OFFSET 0 2 0
      CHANNELS 2 Zrotation Xrotation
      JOINT Nose
      {
        OFFSET 0 0 1
        CHANNELS 0
        End Site
        {
          OFFSET 0 0 0.5
        }
      }
    }
  }
}
MOTION
Frames: 3
Frame Time: 0.5
1 2 3 0 0 0 90 0 0 0 0
0 0 0 0 90 0 0 90 0 0 0
0 0 0 0 0 0 90 90 0 90 90
"""
# Worked on paper (Rx(90): y->z, z->-y; Ry(90): z->x, x->-z; Rz(90): x->y, y->-x).
# Frame 0: root at (1,2,3); Chest Rz90: Head = (1,3,3) + Rz90 (0,2,0) = (-1,3,3);
#   Nose = Head + Rz90 (0,0,1) = (-1,3,4).
# Frame 1: root Ry90 (Z 0, Y 90, X 0); Chest = Ry90 (0,1,0) = (0,1,0); Chest Rx90:
#   Head = Chest + Ry90 Rx90 (0,2,0) = (0,1,0) + Ry90 (0,0,2) = (2,1,0);
#   Nose = Head + Ry90 Rx90 (0,0,1) = Head + Ry90 (0,-1,0) = (2,0,0).
# Frame 2: Chest "Zrotation Xrotation Yrotation" = Rz Rx Ry with Z=X=90: Head = (0,1,0) +
#   Rz90 Rx90 (0,2,0) = (0,1,0) + Rz90 (0,0,2) = (0,1,2) (Rx90 Rz90 would give (-2,1,0));
#   Head "Zrotation Xrotation" = Rz90 Rx90 too: Nose = Head + (Rz90 Rx90)^2 (0,0,1)
#   = Head + Rz90 Rx90 (1,0,0) = Head + (0,1,0) = (0,2,2).
TINY_POS = np.array(
    [
        [[1, 2, 3], [1, 3, 3], [-1, 3, 3], [-1, 3, 4]],
        [[0, 0, 0], [0, 1, 0], [2, 1, 0], [2, 0, 0]],
        [[0, 0, 0], [0, 1, 0], [0, 1, 2], [0, 2, 2]],
    ],
    dtype=float,
)


@pytest.fixture
def tiny(tmp_path):
    p = tmp_path / "tiny.bvh"
    p.write_text(TINY)
    return p


def test_hand_computed_pose(tiny):
    m = read_bvh(tiny)
    assert m.joint_names == ("Hips", "Chest", "Head", "Nose")
    assert m.skeleton.rotation_orders == ("XYZ", "YXZ", "XZY", "XYZ")
    assert m.fps == 2.0 and m.n_frames == 3
    np.testing.assert_array_equal(m.skeleton.parents, [-1, 0, 1, 2])
    np.testing.assert_array_equal(m.euler[2, 1], [90, 0, 90])
    np.testing.assert_array_equal(m.euler[2, 2], [90, 0, 90])
    np.testing.assert_array_equal(m.euler[:, 3], 0.0)
    pos, _ = m.forward_kinematics()
    np.testing.assert_allclose(pos, TINY_POS, atol=1e-12)
    # FBX-style joint names resolve through the FBX naming
    assert m.joint_map["center_hip"] == "Hips" and m.joint_map["head"] == "Head"


def test_tiny_matches_bvhio(tiny):
    names, ref = bvhio_positions(tiny, [0, 1, 2])
    assert names == ["Hips", "Chest", "Head", "Nose"]
    np.testing.assert_allclose(ref, TINY_POS, atol=1e-5)


def test_root_offset_is_added(tmp_path):
    """Root OFFSET + position channels (bvhio would take the channels as absolute)."""
    p = tmp_path / "o.bvh"
    p.write_text(TINY.replace("  OFFSET 0 0 0\n", "  OFFSET 0 10 0\n", 1))
    m = read_bvh(p)
    np.testing.assert_array_equal(m.skeleton.offsets[0], [0, 10, 0])
    np.testing.assert_allclose(m.forward_kinematics()[0], TINY_POS + [0, 10, 0], atol=1e-12)


def test_constant_non_root_position_replaces_offset(tmp_path):
    text = TINY.replace(
        "CHANNELS 3 Zrotation Xrotation Yrotation",
        "CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation",
    )
    lines = text.splitlines()
    for i in range(-3, 0):  # Chest position channel = (0, 1, 0), its OFFSET, in every frame
        v = lines[i].split()
        lines[i] = " ".join(v[:6] + ["0", "1", "0"] + v[6:])
    p = tmp_path / "c.bvh"
    p.write_text("\n".join(lines) + "\n")
    m = read_bvh(p)
    np.testing.assert_allclose(m.forward_kinematics()[0], TINY_POS, atol=1e-12)
    _, ref = bvhio_positions(p, [0, 1, 2])
    np.testing.assert_allclose(ref, TINY_POS, atol=1e-5)
    # a different constant moves the joint (replaces, does not add to, the OFFSET)
    p.write_text(
        "\n".join(s.replace(" 0 1 0 ", " 0 3 0 ") if i > 27 else s for i, s in enumerate(lines))
        + "\n"
    )
    m = read_bvh(p)
    np.testing.assert_array_equal(m.skeleton.offsets[1], [0, 3, 0])
    # varying: unsupported
    lines[-1] = lines[-1].replace(" 0 1 0 ", " 0 1.5 0 ", 1)
    p.write_text("\n".join(lines) + "\n")
    with pytest.raises(MotionFormatError, match=r"c\.bvh \(line 9\).*'Chest'.*varies"):
        read_bvh(p)


@pytest.mark.parametrize(
    "frame_time,fps",
    [
        ("0.033333", 30.0),
        ("0.0333333", 30.0),
        ("0.008333", 120.0),
        ("0.04", 25.0),
        ("0.0333667", 1 / 0.0333667),
        ("0.3", 1 / 0.3),
    ],
)
def test_frame_rate(tmp_path, frame_time, fps):
    p = tmp_path / "f.bvh"
    p.write_text(TINY.replace("Frame Time: 0.5", f"Frame Time: {frame_time}"))
    assert read_bvh(p).fps == pytest.approx(fps, rel=1e-12)


# --------------------------------------------------------------------------- bad input


def _with(line_no, new):
    return with_line(TINY, line_no, new)


BAD = [
    # (id, text, line, frame, words in the message)
    ("missing value", _with(30, "0 0 0 0 90 0 0 90 0 0"), 30, 1, "missing value(s): expected 11"),
    ("extra value", _with(29, "1 2 3 0 0 0 90 0 0 0 0 7"), 29, 0, "extra value(s): expected 11"),
    ("non-numeric", _with(31, "0 0 0 0 0 0 90 abc 0 90 90"), 31, 2, "non-numeric value 'abc'"),
    ("nan", _with(30, "0 0 0 0 nan 0 0 90 0 0 0"), 30, 1, "non-finite"),
    ("inf", _with(31, "0 0 0 0 0 0 90 90 -inf 90 90"), 31, 2, "non-finite"),
    ("fewer frames", _with(27, "Frames: 4"), 31, 3, "Frames: 4 but the file has only 3"),
    ("more frames", _with(27, "Frames: 2"), 31, 2, "Frames: 2 but the file has 3"),
    ("frames not int", _with(27, "Frames: many"), 27, None, "not an integer"),
    ("zero frame time", _with(28, "Frame Time: 0"), 28, None, "Frame Time must be > 0"),
    ("negative frame time", _with(28, "Frame Time: -0.1"), 28, None, "Frame Time must be > 0"),
    ("no frame time", _with(28, None), 28, None, "expected 'Frame Time:'"),
    (
        "channel count low",
        _with(9, "CHANNELS 2 Zrotation Xrotation Yrotation"),
        9,
        None,
        "channel count mismatch: CHANNELS 2 lists 3",
    ),
    (
        "channel count high",
        _with(9, "CHANNELS 4 Zrotation Xrotation Yrotation"),
        9,
        None,
        "channel count mismatch: CHANNELS 4 lists 3",
    ),
    (
        "unknown channel",
        _with(13, "CHANNELS 2 Zrotation Wrotation"),
        13,
        None,
        "unknown channel 'Wrotation'",
    ),
    ("repeated channel", _with(13, "CHANNELS 2 Zrotation Zrotation"), 13, None, "repeated"),
    ("missing close brace", _with(25, None), 25, None, "missing '}'"),
    ("extra close brace", _with(25, ["}", "}"]), 26, None, "after the root's closing"),
    ("missing open brace", _with(7, None), 7, None, "expected '{' after JOINT Chest"),
    ("duplicate joint", _with(14, "      JOINT Chest"), 14, None, "duplicate joint name 'Chest'"),
    ("no offset", _with(16, None), 21, None, "'Nose' has no OFFSET"),
    ("no channels", _with(17, None), 21, None, "'Nose' has no CHANNELS"),
    ("end site without offset", _with(20, None), 20, None, "End Site without OFFSET"),
    ("bad offset", _with(12, "OFFSET 0 two 0"), 12, None, "OFFSET value 'two'"),
    ("not hierarchy", _with(1, "HIERARCHIES"), 1, None, "must start with HIERARCHY"),
    ("second root", _with(25, ["}", "ROOT Other", "{", "}"]), 26, None, "second ROOT"),
    ("stray word", _with(12, "      OFSET 0 2 0"), 12, None, "unexpected 'OFSET'"),
]


@pytest.mark.parametrize("text,line,frame,words", [c[1:] for c in BAD], ids=[c[0] for c in BAD])
def test_bad_bvh(tmp_path, text, line, frame, words):
    bad = tmp_path / "broken.bvh"
    bad.write_text(text)
    with pytest.raises(MotionFormatError) as ei:
        read_bvh(bad)
    msg = str(ei.value)
    assert "broken.bvh" in msg and f"line {line}" in msg and words in msg
    assert ei.value.line == line and ei.value.frame == frame


@pytest.mark.parametrize(
    "text,words",
    [("", "empty file"), (" \n\n", "empty file"), (TINY.split("MOTION")[0], "no MOTION section")],
    ids=["empty", "blank", "no motion"],
)
def test_bad_bvh_whole_file(tmp_path, text, words):
    bad = tmp_path / "whole.bvh"
    bad.write_text(text)
    with pytest.raises(MotionFormatError, match=rf"whole\.bvh: {words}"):
        read_bvh(bad)


def test_missing_file(tmp_path):
    with pytest.raises(MotionFormatError, match=r"nope\.bvh: no such file"):
        read_bvh(tmp_path / "nope.bvh")
    with pytest.raises(MotionFormatError, match="no such file"):
        load_motion(tmp_path / "nope.bvh")


# --------------------------------------------------------------------------- writing
def test_round_trip_cmu(cmu, tmp_path):
    out = write_bvh(cmu, tmp_path / "rt.bvh")
    back = read_bvh(out)
    assert back.joint_names == cmu.joint_names
    assert back.skeleton.rotation_orders == cmu.skeleton.rotation_orders
    np.testing.assert_array_equal(back.skeleton.parents, cmu.skeleton.parents)
    np.testing.assert_array_equal(back.skeleton.offsets, cmu.skeleton.offsets)  # exact (repr)
    np.testing.assert_allclose(back.euler, cmu.euler, atol=1e-4, rtol=0)
    np.testing.assert_allclose(back.root_translation, cmu.root_translation, atol=1e-4, rtol=0)
    assert back.fps == cmu.fps and back.n_frames == cmu.n_frames
    # and through the generic loader
    assert load_motion(out, name="x").name == "x"


def test_round_trip_keeps_orders_of_partial_channels(tiny, tmp_path):
    m = read_bvh(tiny)
    back = read_bvh(write_bvh(m, tmp_path / "t2.bvh"))
    assert back.skeleton.rotation_orders == m.skeleton.rotation_orders
    np.testing.assert_allclose(back.euler, m.euler, atol=1e-6)
    np.testing.assert_allclose(back.forward_kinematics()[0], TINY_POS, atol=1e-5)
    np.testing.assert_array_equal(bvh_euler(m), m.euler)  # identity pre/post: unchanged


def test_write_asf_motion_bakes_axes(data_path, tmp_path):
    """An AMC motion (pre/post = ASF axis) written as BVH keeps its joint positions."""
    m = read_amc(
        data_path("hdm05/HDM05_cut_amc/kickLFront1Reps/HDM_dg_kickLFront1Reps_013_120.amc")
    )
    assert not np.allclose(m.skeleton.pre_rotations[m.joint_names.index("lfemur")], [1, 0, 0, 0])
    out = write_bvh(m, tmp_path / "kick.bvh")
    back = read_bvh(out)
    assert back.fps == 120.0 and back.joint_names == m.joint_names
    np.testing.assert_allclose(back.forward_kinematics()[0], m.forward_kinematics()[0], atol=1e-4)
    # baked angles are continuous over time (unwrapped)
    assert np.abs(np.diff(back.euler, axis=0)).max() < 180
    # the independent reader sees the same joint positions
    frames = [0, m.n_frames // 2, m.n_frames - 1]
    names, ref = bvhio_positions(out, frames)
    assert names == list(m.joint_names)
    np.testing.assert_allclose(ref, m.forward_kinematics()[0][frames], atol=1e-4)


def test_write_rejects_unwritable_names(tiny, tmp_path):
    m = read_bvh(tiny)
    from fpdtw.motion.motion import Skeleton

    sk = m.skeleton
    bad = Skeleton(("Hips", "Ch est", "Head", "Nose"), sk.parents, sk.offsets, sk.rotation_orders)
    with pytest.raises(MotionFormatError, match=r"out\.bvh: joint name 'Ch est'"):
        write_bvh(m.replace(skeleton=bad, joint_map={}), tmp_path / "out.bvh")
