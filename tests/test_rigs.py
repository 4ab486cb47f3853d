"""A performer captured on another system (issue 21): the same movement in another Euler
order, another file format or another rig gives the map it gives in its own.

Each case aligns an input to a target cut from the same motion (a later start, so the map is
not the identity) and compares the map with the one obtained when the target is that cut in
the input's own order, format and rig. Eq. 3 (mean |difference|, frames) must stay within
0.5 frame for reordered Euler angles and 1 frame across formats and rigs, for every online
method.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from fpdtw import registry
from fpdtw.errors import MotionFormatError
from fpdtw.io import load_motion
from fpdtw.io.bvh import read_bvh, write_bvh
from fpdtw.metrics import deviation
from fpdtw.motion.features import pair_features
from fpdtw.motion.joints import OPW_JOINTS, read_joint_map
from fpdtw.motion.rig import cost_input, position_scale, rig_transform
from fpdtw.motion.rotations import euler_to_quat, quat_conj, quat_mul, quat_rotate, quat_to_euler

CMU = "cmu/18_01.bvh"
KICK = "hdm05/HDM05_cut_amc/kickLFront1Reps/HDM_bd_kickLFront1Reps_001_120.amc"
WALK = "mocap_single_person_actions/MoCapData/Walk_01.fbx"

METHODS = ("Ma", "Mb w40", "Mc w40", "Mc w40 + Type V", "OLTW", "OPW")
#: input: frames [0, N); target: frames [SHIFT, SHIFT + N) of the same motion
N, SHIFT = 240, 24


def cut(motion, a, b=None):
    return motion.slice_frames(a, min(b or a + N, motion.n_frames))


def maps(I_motion, T_motion):
    I, T = pair_features(I_motion, T_motion, position_joints=OPW_JOINTS)
    return {name: registry.align(name, I, T)[0] for name in METHODS}


def assert_same_maps(I_motion, T_own, T_other, tolerance):
    ref, got = maps(I_motion, T_own), maps(I_motion, T_other)
    devs = {name: deviation(ref[name], got[name]) for name in METHODS}
    assert all(d <= tolerance for d in devs.values()), devs
    # the maps are not trivial: the target starts SHIFT frames into the input
    assert ref["Mc w40"][-1] > SHIFT


def reordered(motion, order):
    """The same rotations with every joint's Euler angles in ``order`` (converted with
    scipy, as a user would)."""
    from scipy.spatial.transform import Rotation

    J = motion.skeleton.n_joints
    q = motion.quats.reshape(-1, 4)
    euler = Rotation.from_quat(q[:, [1, 2, 3, 0]]).as_euler(
        order.lower(), degrees=True
    )  # our orders: extrinsic
    # scipy's columns follow the order's axes; ours are (x, y, z)
    cols = np.empty_like(euler)
    for i, axis in enumerate(order):
        cols[:, "XYZ".index(axis)] = euler[:, i]
    sk = dataclasses.replace(motion.skeleton, rotation_orders=(order,) * J)
    return motion.replace(skeleton=sk, euler=cols.reshape(motion.n_frames, J, 3), quats=None)


def random_rotations(n, seed):
    q = np.random.default_rng(seed).normal(size=(n, 4))
    return q / np.linalg.norm(q, axis=1, keepdims=True)


def rerigged(motion, seed=0, scale=2.54, order="YXZ", prefix="Bone"):
    """The same movement on another rig built here: every joint's axis frame rotated by a
    random C_j (pre-rotation C_p^-1 C_j, animated rotation C_j^-1 R_j C_j), offsets scaled
    (and expressed in the rotated parent frame), Euler angles in another order, joints
    renamed. Its rest pose has the same shape; forward kinematics gives the same pose x
    ``scale``."""
    sk = motion.skeleton
    J = sk.n_joints
    assert np.allclose(np.abs(sk.pre_rotations[:, 0]), 1.0)  # a BVH rig: no pre-rotations
    C = random_rotations(J, seed)
    pre = np.empty((J, 4))
    offsets = np.empty((J, 3))
    for j in range(J):
        p = sk.parents[j]
        Cp = np.array([1.0, 0, 0, 0]) if p < 0 else C[p]
        pre[j] = quat_mul(quat_conj(Cp), C[j])
        offsets[j] = scale * quat_rotate(quat_conj(Cp), sk.offsets[j])
    R = quat_mul(quat_mul(quat_conj(C)[None], motion.quats), C[None])
    euler = np.stack([quat_to_euler(R[:, j], order) for j in range(J)], axis=1)
    names = tuple(f"{prefix}{j:02d}" for j in range(J))
    new = dataclasses.replace(
        sk,
        joint_names=names,
        offsets=offsets,
        rotation_orders=(order,) * J,
        pre_rotations=pre,
        post_rotations=np.tile([1.0, 0, 0, 0], (J, 1)),
    )
    renamed = {canon: names[sk.joint_names.index(own)] for canon, own in motion.joint_map.items()}
    return motion.replace(
        skeleton=new,
        euler=euler,
        quats=None,
        root_translation=scale * motion.root_translation,
        name=f"{motion.name}_rerigged",
        path="rerigged.bvh",
        source="",
        joint_map=None,
    ), renamed


@pytest.fixture(scope="module")
def cmu(data_path):
    return load_motion(data_path(CMU))


def test_another_euler_order_gives_the_same_map(cmu, tmp_path):
    I, T = cut(cmu, 0), cut(cmu, SHIFT)
    # the file's channels are Zrotation Yrotation Xrotation (our order "XYZ"); rewritten
    # as Xrotation Yrotation Zrotation (our "ZYX")
    path = write_bvh(reordered(T, "ZYX"), tmp_path / "18_01_xyz.bvh")
    T_xyz = read_bvh(path)
    assert set(T_xyz.skeleton.rotation_orders) == {"ZYX"} != set(T.skeleton.rotation_orders)
    assert_same_maps(I, T, T_xyz, 0.5)


def test_amc_exported_to_bvh_gives_the_same_map(data_path, tmp_path):
    kick = load_motion(data_path(KICK))
    I, T = cut(kick, 0), cut(kick, SHIFT)
    T_bvh = read_bvh(write_bvh(T, tmp_path / "kick.bvh"))
    assert T_bvh.source == "bvh" and kick.source == "asf"
    assert_same_maps(I, T, T_bvh, 1.0)


def test_fbx_exported_to_bvh_gives_the_same_map(data_path, tmp_path):
    walk = load_motion(data_path(WALK))
    I, T = cut(walk, 0), cut(walk, SHIFT)
    T_bvh = read_bvh(write_bvh(T, tmp_path / "walk.bvh"))
    assert_same_maps(I, T, T_bvh, 1.0)


def test_rerigged_motion_gives_the_same_map(cmu, tmp_path):
    I, T = cut(cmu, 0), cut(cmu, SHIFT)
    R, renamed = rerigged(T)
    # an unknown rig: the error names the file, the joints missing and the joints it has
    with pytest.raises(MotionFormatError, match=r"rerigged\.bvh.*'left_hip'.*Bone00") as e:
        R.require_joints()
    assert "--joint-map" in str(e.value)
    csv = tmp_path / "rig.csv"
    csv.write_text("joint,name\n" + "".join(f"{k},{v}\n" for k, v in renamed.items()))
    R = R.with_joint_map(read_joint_map(csv))
    # forward kinematics: the same pose, x 2.54
    np.testing.assert_allclose(
        R.positions(OPW_JOINTS, root_relative=True),
        2.54 * T.positions(OPW_JOINTS, root_relative=True),
        atol=1e-6,
    )
    assert not rig_transform(R).same_as(rig_transform(T))
    assert_same_maps(I, T, R, 1.0)


def test_common_representation_keeps_same_rig_angles(cmu):
    """Eq. 1 between two motions of one rig is the same on local rotations and on the
    common representation (conjugation keeps angles); across rigs, the input expressed in
    the target's rig is the target's own rotation for the same movement."""
    T = cut(cmu, SHIFT)
    R, renamed = rerigged(T, seed=3)
    R = R.replace(joint_map=renamed)
    rT, rR = rig_transform(T), rig_transform(R)
    from fpdtw.motion.rig import common_rotations

    dT, dR = common_rotations(T), common_rotations(R)
    np.testing.assert_allclose(np.abs(np.sum(dT * dR, axis=-1)), 1.0, atol=1e-9)
    moved = cost_input(T.rotations(), rT, rR)
    np.testing.assert_allclose(np.abs(np.sum(moved * R.rotations(), axis=-1)), 1.0, atol=1e-9)
    # one rig: the raw local rotations are compared (same object, bit for bit)
    q = T.rotations()
    assert cost_input(q, rT, rig_transform(T)) is q


def test_position_scale_rule():
    assert position_scale(170.0, 180.0) == 1.0  # two adults, one unit
    assert position_scale(170.0, 170.0 / 2.54) == pytest.approx(2.54)  # cm vs inches
    assert position_scale(170.0, 180.0, "body-size") == pytest.approx(170 / 180)
    assert position_scale(170.0, 70.0, "raw") == 1.0
    assert position_scale(None, 70.0) == 1.0
    with pytest.raises(ValueError, match="rule must be one of"):
        position_scale(1.0, 1.0, "metres")


def test_frames_carry_their_own_orders(cmu):
    I, T = pair_features(cut(cmu, 0), reordered(cut(cmu, SHIFT), "YZX"))
    assert T.frame(5).orders == ("YZX",) * 8 and I.frame(5).orders == I.orders
    assert I.orders != T.orders
    # quaternions agree with the Euler angles in the frame's own orders
    f = T.frame(7)
    for j, o in enumerate(f.orders):
        q = euler_to_quat(f.euler[j], o)
        assert abs(abs(np.dot(q, f.quats[j])) - 1.0) < 1e-9


def test_cli_joint_map_and_rest_frame(cmu, tmp_path):
    """`fpdtw align` on a renamed rig: an error naming the file and the joints missing, then
    with --joint-map the map of the original file; a rest frame outside the motion is an
    error naming the file."""
    import subprocess
    import sys

    from fpdtw.app.export import read_map_csv

    I, T = cut(cmu, 0), cut(cmu, SHIFT)
    R, renamed = rerigged(T, scale=1.0)
    src_i, src_t = write_bvh(I, tmp_path / "in.bvh"), write_bvh(T, tmp_path / "t.bvh")
    src_r = write_bvh(R.replace(joint_map=renamed), tmp_path / "renamed.bvh")
    csv = tmp_path / "rig.csv"
    csv.write_text(
        "# renamed rig\njoint,name\n" + "".join(f"{k},{v}\n" for k, v in renamed.items())
    )

    def cli(*args):
        cmd = [sys.executable, "-m", "fpdtw.app.cli", "align", *map(str, args)]
        return subprocess.run(cmd, capture_output=True, text=True, timeout=300)

    r = cli(src_i, src_r, "-m", "c", "-w", 40, "-o", tmp_path / "x.csv")
    assert r.returncode == 1 and "renamed.bvh" in r.stderr and "'left_hip'" in r.stderr, r.stderr
    assert "Bone00" in r.stderr and "--joint-map" in r.stderr
    outs = []
    for target, extra in ((src_t, []), (src_r, ["--joint-map", csv])):
        out = tmp_path / f"{target.stem}.csv"
        r = cli(src_i, target, "-m", "c", "-w", 40, "-o", out, *extra)
        assert r.returncode == 0, r.stderr
        outs.append(read_map_csv(out)["input_frame"])
    assert deviation(outs[0], outs[1]) <= 1.0  # Euler angles in another order: forecasts differ
    r = cli(src_i, src_t, "-m", "c", "-w", 40, "-o", tmp_path / "y.csv", "--target-rest-frame",
            10_000)  # fmt: skip
    assert r.returncode == 1 and "t.bvh" in r.stderr and "rest frame 10000" in r.stderr, r.stderr


#: CMU's ASF bone names as the cgspeed BVH conversion of the CMU database spells them.
CGSPEED = dict(
    hip="Hips", lhipjoint="LHipJoint", lfemur="LeftUpLeg", ltibia="LeftLeg",
    lfoot="LeftFoot", ltoes="LeftToeBase", rhipjoint="RHipJoint", rfemur="RightUpLeg",
    rtibia="RightLeg", rfoot="RightFoot", rtoes="RightToeBase", lowerback="LowerBack",
    upperback="Spine", thorax="Spine1", lowerneck="Neck", upperneck="Neck1", head="Head",
    lclavicle="LeftShoulder", lhumerus="LeftArm", lradius="LeftForeArm", lwrist="LeftHand",
    lhand="LeftFingerBase", lfingers="LeftHandIndex1", lthumb="LThumb",
    rclavicle="RightShoulder", rhumerus="RightArm", rradius="RightForeArm",
    rwrist="RightHand", rhand="RightFingerBase", rfingers="RightHandIndex1", rthumb="RThumb",
)  # fmt: skip
#: Z up, facing -Y (Y up turned +90 degrees about X); mirrored: x -> -x as well.
Z_UP = np.array([np.cos(np.pi / 4), np.sin(np.pi / 4), 0.0, 0.0])
Z_UP_AXES = np.array([[1.0, 0, 0], [0, 0, 1], [0, -1, 0]])


def other_world(motion, path, mirror=False):
    """The same movement in a Z-up world with cgspeed's joint names, mirrored (x -> -x: a
    left-handed world read as right-handed) if asked, written to and read from BVH ``path``:
    every offset and the root's path turned (and mirrored), every local rotation conjugated."""
    sk = motion.skeleton
    q, off, t = motion.quats.copy(), sk.offsets.copy(), motion.root_translation.copy()
    if mirror:  # positions mirror; a rotation (w, x, y, z) becomes (w, x, -y, -z)
        off[:, 0] *= -1
        t[:, 0] *= -1
        q[..., 2:] *= -1
    q = quat_mul(quat_mul(Z_UP, q), quat_conj(Z_UP))
    euler = np.stack([quat_to_euler(q[:, j], o) for j, o in enumerate(sk.rotation_orders)], axis=1)
    names = tuple(CGSPEED[n] for n in sk.joint_names)
    new = dataclasses.replace(sk, joint_names=names, offsets=quat_rotate(Z_UP, off))
    moved = motion.replace(skeleton=new, euler=euler, quats=None, joint_map=None, source="",
                           root_translation=quat_rotate(Z_UP, t))  # fmt: skip
    return read_bvh(write_bvh(moved, path))


@pytest.mark.parametrize("mirror", [False, True], ids=["z-up", "z-up-mirrored"])
def test_another_world_gives_the_same_map(cmu, tmp_path, mirror):
    """The same take in a Z-up world (and a left-handed one) with cgspeed's names: its body
    axes are found from its rest pose, and every online method gives the map of the take in
    its own world (before the body axes: 137 frames apart for Ma, 57 for Mc w40 on the whole
    take). Mb's residue is its Euler dead reckoning, as in the other rigs."""
    I, T = cut(cmu, 0), cut(cmu, SHIFT)
    W = other_world(T, tmp_path / "18_01_zup.bvh", mirror)
    assert W.joint_map["left_hip"] == "LeftUpLeg"  # found by the built-in maps
    np.testing.assert_array_equal(rig_transform(T).axes, np.eye(3))
    expected = Z_UP_AXES * ([[-1.0], [1], [1]] if mirror else 1.0)
    np.testing.assert_array_equal(rig_transform(W).axes, expected)
    assert np.linalg.det(expected) == (-1.0 if mirror else 1.0)
    # --up/--facing say the same; a wrong facing is a different frame
    z, minus_y = np.eye(3)[2], -np.eye(3)[1]
    np.testing.assert_array_equal(rig_transform(W, up=z, facing=minus_y).axes, expected)
    assert not np.array_equal(rig_transform(W, up=z, facing=-minus_y).axes, expected)
    assert_same_maps(I, T, W, 0.5)


def test_another_world_live_and_cli(cmu, tmp_path):
    """Streamed, the Z-up take gives the offline map bit for bit (rotations and OPW's
    positions); `fpdtw align --up/--facing` naming the worlds gives the map found without."""
    from fpdtw.app import cli
    from fpdtw.app.export import read_map_csv
    from fpdtw.app.stream import session_map, simulate, take_lines

    I, T = cut(cmu, 0), cut(cmu, SHIFT)
    W = other_world(T, tmp_path / "zup.bvh")
    for name, pj in (("Mc w40", None), ("OPW", OPW_JOINTS)):
        FI, FW = pair_features(I, W, position_joints=pj)
        offline = registry.align(name, FI, FW)[0]
        live = session_map(simulate(FI, take_lines(W), name))
        np.testing.assert_array_equal(live, offline)
    src = write_bvh(I, tmp_path / "in.bvh")
    outs = []
    for extra in ([], ["--up", "y,z", "--facing", "z,-y"]):
        out = tmp_path / f"map{len(outs)}.csv"
        args = ["align", src, tmp_path / "zup.bvh", "-m", "c", "-w", "40", "-o", out, *extra]
        assert cli.main([str(a) for a in args]) == 0
        outs.append(read_map_csv(out)["input_frame"])
    np.testing.assert_array_equal(outs[0], outs[1])
    assert outs[0][-1] > SHIFT
