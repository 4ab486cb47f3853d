"""The Motion type: resampling, cropping, joint selection, validation."""

from __future__ import annotations

from contextlib import nullcontext

import numpy as np
import pytest
from scipy.spatial.transform import Rotation, Slerp

from fpdtw.errors import MotionFormatError
from fpdtw.io.asfamc import read_amc
from fpdtw.io.bvh import read_bvh
from fpdtw.motion.joints import FBX_NAMES, OPW_JOINTS, PAPER_JOINTS
from fpdtw.motion.motion import Motion, Skeleton
from fpdtw.motion.rotations import ORDERS, euler_to_quat, quat_to_euler

HDM = "hdm05/HDM05_cut_amc/{}"
PAPER_ASF = ["lfemur", "rfemur", "ltibia", "rtibia", "lhumerus", "rhumerus", "lradius", "rradius"]


@pytest.fixture(scope="module")
def hdm(data_path):
    return read_amc(data_path(HDM.format("squat1Reps/HDM_dg_squat1Reps_030_120.amc")))


@pytest.fixture(scope="module")
def cmu(data_path):
    return read_bvh(data_path("cmu/18_01.bvh"))


def _same_rotation(a, b, atol=1e-9):
    """Unit quaternions a, b (..., 4) describe the same rotation (q and -q)."""
    return np.allclose(np.abs(np.sum(a * b, axis=-1)), 1.0, atol=atol)


def _synthetic(euler, orders, fps=120.0, names=None, source="fbx"):
    F, J, _ = np.shape(euler)
    names = names or tuple(f"j{k}" for k in range(J))
    sk = Skeleton(names, [-1] + [0] * (J - 1), np.tile([0.0, 1.0, 0.0], (J, 1)), orders)
    return Motion("syn", fps, sk, euler, np.zeros((F, 3)), source=source)


# --------------------------------------------------------------------------- resampling
@pytest.mark.parametrize("order", ORDERS)
def test_quat_to_euler_is_scipys_bit_for_bit(order):
    """The compiled Euler angles are scipy's as_euler, bit for bit: random quaternions of any
    norm, and the gimbal lock of each order (second angle 0 or pi: the third is set to 0)."""
    rng = np.random.default_rng(7)
    q = rng.standard_normal((20000, 4)) * rng.uniform(0.5, 2.0, (20000, 1))
    axes = {"X": [1.0, 0, 0], "Y": [0, 1.0, 0], "Z": [0, 0, 1.0]}
    second = np.array(axes[order[1]])
    locked = np.array(
        [[np.cos(a / 2), *(np.sin(a / 2) * second)] for a in (np.pi / 2, -np.pi / 2, 0.3)]
    )
    for qq in (q, locked):
        with pytest.warns(UserWarning, match="Gimbal") if qq is locked else nullcontext():
            ang = Rotation.from_quat(qq[:, [1, 2, 3, 0]]).as_euler(order.lower(), degrees=True)
        ref = ang[:, [order.index(a) for a in "XYZ"]]
        np.testing.assert_array_equal(quat_to_euler(qq, order), ref)
        np.testing.assert_array_equal(quat_to_euler(qq[:, [1, 2, 3, 0]], order, False), ref)
    assert quat_to_euler(q.reshape(100, 200, 4), order).shape == (100, 200, 3)


def test_resample_120_to_60_keeps_every_second_frame(hdm):
    r = hdm.resample(60)
    n = (hdm.n_frames - 1) // 2 + 1
    assert r.fps == 60.0 and r.n_frames == n
    np.testing.assert_array_equal(r.euler, hdm.euler[::2][:n])
    # quaternions: Motion re-normalises the quats it is given, which may move the last bit
    np.testing.assert_allclose(r.quats, hdm.quats[::2][:n], rtol=0, atol=1e-15)
    np.testing.assert_allclose(r.root_translation, hdm.root_translation[::2][:n], atol=1e-12)
    assert r.skeleton is hdm.skeleton and r.joint_map == hdm.joint_map


@pytest.mark.parametrize("which,fps", [("hdm", 50.0), ("hdm", 97.0), ("cmu", 24.0), ("cmu", 48.0)])
def test_resample_non_integer_ratio_is_slerp(hdm, cmu, which, fps):
    """Quaternions equal scipy's Slerp between the neighbouring frames, per joint."""
    m = hdm if which == "hdm" else cmu
    r = m.resample(fps)
    t = np.arange(r.n_frames) / fps
    assert r.n_frames == int(np.floor(m.duration * fps + 1e-9)) + 1 and t[-1] <= m.duration
    for j in range(m.skeleton.n_joints):
        rot = Rotation.from_quat(m.quats[:, j][:, [1, 2, 3, 0]])
        ref = Slerp(m.times, rot)(t).as_quat()[:, [3, 0, 1, 2]]
        assert _same_rotation(r.quats[:, j], ref, atol=1e-9), m.joint_names[j]
    for a in range(3):
        np.testing.assert_allclose(
            r.root_translation[:, a], np.interp(t, m.times, m.root_translation[:, a]), atol=1e-9
        )


@pytest.mark.parametrize("fps", [50.0, 97.0])
def test_resampled_euler_matches_quats(hdm, fps):
    r = hdm.resample(fps)
    for j, order in enumerate(r.skeleton.rotation_orders):
        assert _same_rotation(euler_to_quat(r.euler[:, j], order), r.quats[:, j])


def test_resampled_euler_continuous_across_full_turns():
    """A single-axis spin past 180 and past 360 degrees stays continuous and linear."""
    F = 121
    z = np.linspace(170.0, 430.0, F)  # crosses 180 and 360
    e = np.zeros((F, 2, 3))
    e[:, 1, 2] = z
    m = _synthetic(e, ("XYZ", "XYZ"))
    r = m.resample(50)
    t = np.arange(r.n_frames) / 50
    np.testing.assert_allclose(r.euler[:, 1, 2], np.interp(t, m.times, z), atol=1e-9)
    np.testing.assert_allclose(r.euler[:, 1, :2], 0.0, atol=1e-9)


def test_resampled_euler_continuous_past_gimbal_branch():
    """Middle angle of an XYZ joint sweeping 60 -> 120 degrees (past 90) with x, z fixed."""
    F = 121
    e = np.zeros((F, 2, 3))
    e[:, 1] = np.stack([np.full(F, 10.0), np.linspace(60.25, 120.25, F), np.full(F, 20.0)], 1)
    m = _synthetic(e, ("XYZ", "XYZ"))
    r = m.resample(50)
    # one output step (2.4 input frames) moves y by 1.2 deg; x and z stay put
    assert np.abs(np.diff(r.euler[:, 1], axis=0)).max() < 2.0


def test_resampled_euler_continuous_real_clip(hdm):
    """HDM05 squat: no resampled Euler step exceeds 3 input steps (+5 deg) of that joint."""
    r = hdm.resample(50)
    step_in = np.abs(np.diff(hdm.euler, axis=0)).max(axis=(0, 2))
    step_out = np.abs(np.diff(r.euler, axis=0)).max(axis=(0, 2))
    bad = [n for n, a, b in zip(hdm.joint_names, step_in, step_out) if b > 3 * a + 5]
    assert not bad


def test_sample_at_frame_times_returns_frames(cmu):
    q, tr = cmu.sample(cmu.times[[0, 7, 302]])
    np.testing.assert_allclose(q, cmu.quats[[0, 7, 302]], atol=1e-12)
    np.testing.assert_allclose(tr, cmu.root_translation[[0, 7, 302]], atol=1e-12)
    # clipped to [0, duration]
    q, _ = cmu.sample([-1.0, cmu.duration + 5])
    np.testing.assert_allclose(q, cmu.quats[[0, -1]], atol=1e-12)


# --------------------------------------------------------------------------- crop
def test_crop(hdm):
    c = hdm.crop(0.5, 1.0)  # 120 Hz: frames 60 .. 120 inclusive
    assert c.n_frames == 61 and c.fps == hdm.fps
    np.testing.assert_array_equal(c.euler, hdm.euler[60:121])
    np.testing.assert_allclose(c.quats, hdm.quats[60:121], rtol=0, atol=1e-15)  # see above
    np.testing.assert_array_equal(c.root_translation, hdm.root_translation[60:121])
    assert c.duration == pytest.approx(0.5)
    tail = hdm.crop(1.0)
    assert tail.n_frames == hdm.n_frames - 120
    np.testing.assert_array_equal(tail.euler[-1], hdm.euler[-1])
    with pytest.raises(ValueError, match="leaves no frame"):
        hdm.crop(hdm.duration + 1)
    # cropping does not touch the original
    assert hdm.n_frames > 121


# --------------------------------------------------------------------------- joint selection
def test_joint_selection_asf(hdm):
    idx = hdm.joint_indices(PAPER_JOINTS)
    assert [hdm.joint_names[i] for i in idx] == PAPER_ASF
    np.testing.assert_array_equal(hdm.rotations(), hdm.quats[:, idx])
    np.testing.assert_array_equal(hdm.eulers(), hdm.euler[:, idx])
    assert hdm.rotation_orders() == ("XYZ",) * 2 + ("XYZ",) * 2 + ("XYZ",) * 4
    # own names work too
    np.testing.assert_array_equal(hdm.joint_indices(["lfemur", "left_hip"]), [idx[0], idx[0]])
    P = hdm.positions(OPW_JOINTS)
    assert P.shape == (hdm.n_frames, 16, 3)
    np.testing.assert_array_equal(P[:, OPW_JOINTS.index("center_hip")], 0.0)  # root-relative


def test_joint_selection_bvh(cmu):
    assert [cmu.joint_names[i] for i in cmu.joint_indices(PAPER_JOINTS)] == PAPER_ASF
    opw = [cmu.joint_names[i] for i in cmu.joint_indices(OPW_JOINTS)]
    assert opw[0] == "head" and opw[1] == "hip"
    pos, _ = cmu.forward_kinematics()
    np.testing.assert_allclose(
        cmu.positions(["left_knee"], root_relative=False)[:, 0],
        pos[:, cmu.joint_names.index("ltibia")],
    )


def test_joint_selection_fbx():
    """FBX naming (with a Mixamo namespace): every canonical name resolves to its own joint."""
    own = ["mixamorig:" + FBX_NAMES["center_hip"][0]]
    for canon in OPW_JOINTS:
        name = "mixamorig:" + FBX_NAMES[canon][0]
        if name not in own:
            own.append(name)
    F = 4
    rng = np.random.default_rng(0)
    e = rng.uniform(-90, 90, (F, len(own), 3))
    m = _synthetic(e, ("ZXY",) * len(own), names=tuple(own), source="fbx")
    for canon in OPW_JOINTS + PAPER_JOINTS:
        (i,) = m.joint_indices([canon])
        assert own[i] == "mixamorig:" + FBX_NAMES[canon][0]
    np.testing.assert_array_equal(m.rotations()[:, 0], m.quats[:, own.index("mixamorig:LeftUpLeg")])


def test_unknown_joint(hdm):
    with pytest.raises(MotionFormatError) as ei:
        hdm.joint_indices(["left_tail"])
    msg = str(ei.value)
    assert "HDM_dg_squat1Reps_030_120.amc" in msg and "unknown joint 'left_tail'" in msg
    assert "lfemur" in msg  # lists what the skeleton has
    with pytest.raises(MotionFormatError, match="unknown joint"):
        hdm.rotations(["left_hip", "nope"])


# --------------------------------------------------------------------------- validation
def test_nan_rotation_names_frame():
    e = np.zeros((6, 2, 3))
    e[3, 1, 0] = np.nan
    with pytest.raises(MotionFormatError) as ei:
        _synthetic(e, ("XYZ", "XYZ"))
    assert ei.value.frame == 3 and "frame 3" in str(ei.value) and "rotation" in str(ei.value)


def test_nan_translation_names_frame():
    sk = Skeleton(("a", "b"), [-1, 0], np.zeros((2, 3)), ("XYZ", "XYZ"))
    tr = np.zeros((5, 3))
    tr[4, 2] = np.inf
    with pytest.raises(MotionFormatError) as ei:
        Motion("m", 30, sk, np.zeros((5, 2, 3)), tr, path="clip.bvh")
    assert ei.value.frame == 4 and str(ei.value).startswith("clip.bvh (frame 4)")


def test_bad_shapes_and_rate():
    sk = Skeleton(("a", "b"), [-1, 0], np.zeros((2, 3)), ("XYZ", "XYZ"))
    with pytest.raises(MotionFormatError, match="expected \\(frames, 2, 3\\)"):
        Motion("m", 30, sk, np.zeros((5, 3, 3)), np.zeros((5, 3)))
    with pytest.raises(MotionFormatError, match="no frames"):
        Motion("m", 30, sk, np.zeros((0, 2, 3)), np.zeros((0, 3)))
    with pytest.raises(MotionFormatError, match="frame rate must be positive"):
        Motion("m", 0, sk, np.zeros((5, 2, 3)), np.zeros((5, 3)))
    with pytest.raises(MotionFormatError, match="root translation"):
        Motion("m", 30, sk, np.zeros((5, 2, 3)), np.zeros((4, 3)))


def test_the_streaming_unwrap_is_unwrap_degrees_bit_for_bit_through_wraps_and_nan():
    """UnwrapDegrees, frame by frame (its compiled step where no angle moves by pi, NumPy's
    where one does or is NaN), against unwrap_degrees of the whole take."""
    from fpdtw.motion.rotations import UnwrapDegrees, unwrap_degrees

    rng = np.random.default_rng(5)
    for t in range(60):
        n = int(rng.integers(2, 120))
        a = np.cumsum(rng.normal(size=(n, 8, 3)) * rng.choice([5.0, 60.0, 200.0]), axis=0)
        a = (a + 180) % 360 - 180
        if t % 3 == 0:
            a[rng.integers(n), rng.integers(8), 0] = np.nan
        u = UnwrapDegrees()
        got = np.array([u(a[k]) for k in range(n)])
        np.testing.assert_array_equal(got, unwrap_degrees(a, axis=0))
