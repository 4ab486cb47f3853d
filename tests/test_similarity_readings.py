"""Readings of eq. 2 (fpdtw.metrics.similarity options, fpdtw.motion.rig trajectory frames and
bone directions): each on a case worked out by hand; defaults equal today's scores; the
plain twin equal to the kernel under every option."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest

from fpdtw import plain
from fpdtw.dtw import utw_map
from fpdtw.errors import AlignmentError, MotionFormatError
from fpdtw.metrics import joint_trajectories, similarity, similarity_per_axis, trajectory_scores
from fpdtw.motion.motion import Motion, Skeleton
from fpdtw.motion.rig import bone_directions, trajectory_rotations

sys.path.insert(0, str(Path(__file__).parent))
from reference.synthetic import synthetic_pair  # noqa: E402


def about(axis, degrees):
    """Quaternions (F, 1, 4) turning by ``degrees`` about the unit ``axis``."""
    axis = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    a = np.radians(np.asarray(degrees, dtype=float))[:, None]
    return np.concatenate([np.cos(a / 2), np.sin(a / 2) * axis], axis=1)[:, None, :]


def traj(*axes):
    """Trajectories (N, 1, 3) from three series (x, y, z)."""
    return np.stack(axes, axis=1)[:, None, :].astype(float)


def test_tau_a_and_b_by_hand():
    # x: input 0, 1, 1, 2 (one tie) against target 0, 1, 2, 3: 5 concordant pairs, 1 tied,
    # 0 discordant. tau-a = 5 / 6; tau-b = 5 / sqrt((6 - 1) * 6). y and z: identical -> 1.
    move = np.array([0.0, 0.01, 0.02, 0.03])
    XA = traj(np.array([0.0, 0.01, 0.01, 0.02]), move, move)
    XT = traj(move, move, move)
    np.testing.assert_allclose(trajectory_scores(XA, XT, tau="a"), [[5 / 6, 1, 1]], rtol=1e-15)
    np.testing.assert_allclose(
        trajectory_scores(XA, XT, tau="b"), [[5 / math.sqrt(30), 1, 1]], rtol=1e-15
    )
    assert trajectory_scores(XA, XT).tolist() == trajectory_scores(XA, XT, tau="b").tolist()


def test_flat_rules_by_hand():
    move = np.array([0.0, 0.01, 0.02, 0.03])
    tiny = np.array([0.0, 0.0001, 0.0002, 0.0005])  # range 0.0005 < 0.001: flat, increasing
    const = np.zeros(4)
    # x: flat (not constant) in the input, moving in the target; y: constant against moving;
    # z: flat in both
    XA, XT = traj(tiny, const, tiny), traj(move, move, tiny[::-1])
    assert trajectory_scores(XA, XT, flat="zero").tolist() == [[0.0, 0.0, 1.0]]
    # the toolkit computes tau when either range reaches 0.001: increasing vs increasing
    # is 1; the constant series has no tau (0); both flat: 1
    assert trajectory_scores(XA, XT, flat="toolkit").tolist() == [[1.0, 0.0, 1.0]]
    r = trajectory_scores(XA, XT, flat="skip")
    assert math.isnan(r[0, 0]) and math.isnan(r[0, 1]) and r[0, 2] == 1.0


def test_similarity_flat_skip_is_the_mean_of_what_is_left():
    F = 20
    t = np.linspace(0.0, 1.0, F)
    moving = about([1, 0, 1], 60 * t)
    still = about([0, 0, 1], np.degrees(0.0002 * t))
    I = np.concatenate([moving, moving], axis=1)
    T = np.concatenate([moving, still], axis=1)
    # joint 0: three identical moving axes, 1 each (its y stays moving too: turning about
    # (1, 0, 1) tilts y); joint 1: input moving, target flat on every axis
    assert similarity(I, T, np.arange(F)) == pytest.approx(3 / 6)
    assert similarity(I, T, np.arange(F), flat="skip") == 1.0
    assert math.isnan(similarity(I[:, 1:], T[:, 1:], np.arange(F), flat="skip"))


def test_skip_leaves_out_the_first_target_frames_by_hand():
    # about z: the y axis goes to (-sin a, cos a, 0); for a in 0..90 both x and y fall as a
    # grows. Input angles go down then up; after the first two frames both motions rise.
    I = about([0, 0, 1], [30, 20, 10, 20, 30, 40])
    T = about([0, 0, 1], [10, 20, 30, 40, 50, 60])
    M = np.arange(6)
    assert similarity(I, T, M, skip=2) == 1.0  # x, y: tau 1; z: flat in both -> 1
    # all frames: input angles 30 20 10 20 30 40 against 10 20 30 40 50 60 (x and y both
    # rank as the angle does): discordant (0,1) (0,2) (0,3) (1,2); tied in the input (0,4)
    # (1,3); concordant the other 9 of 15. tau-b = (9 - 4) / sqrt((15 - 2) * 15)
    expect = (2 * (5 / math.sqrt(13 * 15)) + 1) / 3
    assert similarity(I, T, M) == pytest.approx(expect, rel=1e-12)
    with pytest.raises(AlignmentError, match="skip=5 leaves 1"):
        similarity(I, T, M, skip=5)
    with pytest.raises(AlignmentError, match="skip must be"):
        similarity(I, T, M, skip=-1)


def test_bone_axis_by_hand():
    # turning about y: the (0, 1, 0) vector never moves, every axis is flat in both motions
    # and scores 1 even under a reversed map; the bone (2, 0, 0) (normalised to x) turns to
    # (cos a, 0, -sin a): x and z reversed -> -1, y flat -> 1.
    q = about([0, 1, 0], np.linspace(0, 80, 12))
    rev = np.arange(12)[::-1]
    assert similarity(q, q, rev) == 1.0
    assert similarity(q, q, rev, axis=np.array([[2.0, 0.0, 0.0]])) == pytest.approx(-1 / 3)
    X = joint_trajectories(q, np.array([[2.0, 0.0, 0.0]]))
    a = np.radians(np.linspace(0, 80, 12))
    np.testing.assert_allclose(X[:, 0], np.stack([np.cos(a), 0 * a, -np.sin(a)], 1), atol=1e-15)
    # a pair of axes: the input's and the target's own
    assert similarity(q, q, rev, axis=(np.array([1.0, 0, 0]), np.array([1.0, 0, 0]))) == (
        pytest.approx(-1 / 3)
    )
    with pytest.raises(AlignmentError, match="axis"):
        similarity(q, q, rev, axis="bone")
    with pytest.raises(AlignmentError, match="must not be zero"):
        similarity(q, q, rev, axis=np.zeros(3))


def _two_bones(root_deg, child_deg):
    """root -> a -> b, b 2 units along x from a; root turns about z, a about x (degrees)."""
    sk = Skeleton(
        ("root", "a", "b"),
        [-1, 0, 1],
        [[0.0, 0, 0], [0.0, 1, 0], [2.0, 0, 0]],
        ("XYZ", "XYZ", "XYZ"),
    )
    F = len(root_deg)
    euler = np.zeros((F, 3, 3))
    euler[:, 0, 2] = root_deg
    euler[:, 1, 0] = child_deg
    return Motion("m", 30, sk, euler, np.zeros((F, 3)), path="two_bones.bvh")


def test_trajectory_frames_by_hand():
    mo = _two_bones([90.0, 90.0], [0.0, 30.0])
    z90 = np.array([math.cos(math.pi / 4), 0, 0, math.sin(math.pi / 4)])
    x30 = np.array([math.cos(math.pi / 12), math.sin(math.pi / 12), 0, 0])
    local = trajectory_rotations(mo, "local", ["a"])
    glob = trajectory_rotations(mo, "global", ["a"])
    root = trajectory_rotations(mo, "root", ["a"])
    same = lambda p, q: np.allclose(p, q, atol=1e-12) or np.allclose(p, -q, atol=1e-12)  # noqa: E731
    assert same(local[0, 0], [1, 0, 0, 0]) and same(local[1, 0], x30)
    # global: the root's 90 degrees about z, then a's own 30 about x
    assert same(glob[0, 0], z90)
    zx = np.array(
        [
            z90[0] * x30[0],
            z90[0] * x30[1],
            z90[3] * x30[1],
            z90[3] * x30[0],
        ]
    )
    assert same(glob[1, 0], zx)
    # root-relative: the root's turn removed, the local rotation of a child of the root
    assert same(root[0, 0], [1, 0, 0, 0]) and same(root[1, 0], x30)
    with pytest.raises(MotionFormatError, match="two_bones.bvh.*frame 'world'"):
        trajectory_rotations(mo, "world", ["a"])


def test_bone_directions_by_hand():
    mo = _two_bones([0.0], [0.0])
    np.testing.assert_allclose(bone_directions(mo, ["root", "a"]), [[0, 1, 0], [1, 0, 0]])
    with pytest.raises(MotionFormatError, match="two_bones.bvh.*'b' has no child"):
        bone_directions(mo, ["b"])


def test_defaults_are_todays_scores_and_plain_twin_agrees():
    I, T, _ = synthetic_pair(120, seed=9)
    M = utw_map(I.n_frames - 1, T.n_frames - 1)
    base = similarity(I.quats, T.quats, M)
    explicit = similarity(I.quats, T.quats, M, tau="b", flat="zero", skip=0, axis="y")
    assert base == explicit == float(np.mean(similarity_per_axis(I.quats, T.quats, M)))
    assert base == plain.similarity(I.quats, T.quats, M)
    bones = np.random.default_rng(1).normal(size=(I.quats.shape[1], 3))
    for flat in ("zero", "toolkit", "skip"):  # tau-a: by hand, test_tau_a_and_b_by_hand
        for skip in (0, 3):
            for axis in ("y", bones, (bones, bones[::-1])):
                got = similarity(I.quats, T.quats, M, flat=flat, skip=skip, axis=axis)
                want = plain.similarity(I.quats, T.quats, M, flat=flat, skip=skip, axis=axis)
                assert got == pytest.approx(want, abs=1e-12), (flat, skip)
    with pytest.raises(AlignmentError, match="tau must be"):
        similarity(I.quats, T.quats, M, tau="c")
    with pytest.raises(AlignmentError, match="flat must be"):
        similarity(I.quats, T.quats, M, flat="one")


def test_level_table_helpers_by_hand():
    from fpdtw.paper.similarity_level import READINGS, closest_reading, level_comparison

    assert READINGS[0].name == "ours" and len({r.name for r in READINGS}) == len(READINGS)
    rows = [
        dict(reading="ours", changes="", dataset="all", UTW=0.43, DTW=0.5, **{"Mc w40": 0.47}),
        dict(reading="x", changes="", dataset="all", UTW=0.26, DTW=0.3, **{"Mc w40": 0.30}),
        dict(reading="x", changes="", dataset="hdm05", UTW=0.1, DTW=0.3, **{"Mc w40": 0.30}),
    ]
    best = closest_reading(rows)
    assert best["reading"] == "x" and best["gap"] == pytest.approx(0.02)
    assert [r["ours"] for r in level_comparison(rows)] == [
        "0.430 (not within 0.05)", "0.470 (not within 0.05)",
        "0.260 (within 0.05)", "0.300 (within 0.05)",
    ]  # fmt: skip
    assert level_comparison(rows)[2]["paper"] == "0.240"


def test_transform_frame_folds_in_pre_and_post_rotations_by_hand():
    # joint a: pre 90 degrees about z, post its inverse, animated 30 degrees about x: the
    # transform pre R post is 30 degrees about z(x) = y; without pre/post ("local") it is x
    z90 = np.array([math.cos(math.pi / 4), 0, 0, math.sin(math.pi / 4)])
    z90_inv = z90 * [1, -1, -1, -1]
    ident = np.array([1.0, 0, 0, 0])
    sk = Skeleton(
        ("root", "a", "b"),
        [-1, 0, 1],
        [[0.0, 0, 0], [0.0, 1, 0], [2.0, 0, 0]],
        ("XYZ", "XYZ", "XYZ"),
        pre_rotations=np.stack([ident, z90, ident]),
        post_rotations=np.stack([ident, z90_inv, ident]),
    )
    euler = np.zeros((1, 3, 3))
    euler[0, 1, 0] = 30.0
    mo = Motion("m", 30, sk, euler, np.zeros((1, 3)))
    tr = trajectory_rotations(mo, "transform", ["a"])[0, 0]
    y30 = np.array([math.cos(math.pi / 12), 0, math.sin(math.pi / 12), 0])
    assert np.allclose(tr, y30, atol=1e-12) or np.allclose(tr, -y30, atol=1e-12)
    loc = trajectory_rotations(mo, "local", ["a"])[0, 0]
    assert np.allclose(np.abs(loc), [math.cos(math.pi / 12), math.sin(math.pi / 12), 0, 0])
