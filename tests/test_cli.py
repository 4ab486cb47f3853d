"""The ``fpdtw`` command line (as a subprocess, ``python -m fpdtw.app.cli``) and fpdtw.app.export.

Real files come from the verified data cache (``data_path`` fixture). The exported BVH is
read back with our reader and with the independent ``bvhio`` package.
"""

from __future__ import annotations

import importlib.util
import os
import subprocess
import sys

import numpy as np
import pytest
from reference.files import bvhio_positions

from fpdtw.app.export import MAP_COLUMNS, read_map_csv, retime_by_map, write_map_csv
from fpdtw.dtw import dtw_pair
from fpdtw.errors import AlignmentError
from fpdtw.io import load_motion
from fpdtw.io.bvh import read_bvh, write_bvh
from fpdtw.motion.features import MotionFeatures
from fpdtw.registry import align

WALK1 = "mocap_single_person_actions/MoCapData/Walk_01.fbx"
WALK2 = "mocap_single_person_actions/MoCapData/Walk_02.fbx"
SQUAT1 = "hdm05/HDM05_cut_amc/squat1Reps/HDM_bd_squat1Reps_001_120.amc"
SQUAT2 = "hdm05/HDM05_cut_amc/squat1Reps/HDM_bd_squat1Reps_002_120.amc"
CMU = "cmu/18_01.bvh"


def cli(*args, env=None):
    """Run ``python -m fpdtw.app.cli ARGS`` in a fresh interpreter; return the CompletedProcess."""
    return subprocess.run(
        [sys.executable, "-m", "fpdtw.app.cli", *map(str, args)],
        capture_output=True,
        text=True,
        env=env,
        timeout=300,
    )


def one_error_line(r, code=1):
    """The process failed with ``code`` and printed exactly one 'fpdtw: error:' line."""
    assert r.returncode == code, r.stderr
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("fpdtw: error: "), r.stderr
    assert "Traceback" not in r.stderr
    return lines[0]


def frame_time(path):
    for line in open(path):
        if line.startswith("Frame Time:"):
            return float(line.split(":")[1])
    raise AssertionError("no Frame Time line")


def check_exported_bvh(path, I, M, fps):
    """The BVH holds I retimed by M: frame count, frame time, joint positions (FK)."""
    R = retime_by_map(I, M, fps)
    B = read_bvh(path)
    assert B.n_frames == R.n_frames == len(M)
    assert frame_time(path) == pytest.approx(1.0 / fps, rel=1e-8) and B.fps == fps
    n = R.n_frames
    frames = sorted({0, n // 3, (2 * n) // 3, n - 1})
    pR, _ = R.forward_kinematics()
    size = np.ptp(pR[0], axis=0).max()  # extent of the first pose
    pB, _ = B.forward_kinematics()
    idx = [B.joint_names.index(j) for j in R.joint_names]
    assert np.abs(pB[frames][:, idx] - pR[frames]).max() <= 1e-4 * size
    names, pX = bvhio_positions(path, frames)
    ix = [names.index(j) for j in R.joint_names]
    # bvhio takes the root position channels as absolute: add the root OFFSET back
    pX = pX[:, ix] + R.skeleton.offsets[0]
    assert np.abs(pX - pR[frames]).max() <= 1e-4 * size
    # and the poses really follow the map: frame q of the file is input frame M[q]
    pI, _ = I.forward_kinematics()
    np.testing.assert_allclose(pR[frames], pI[np.asarray(M)[frames]], atol=1e-9)


def read_csv_checked(path, n_target, fps_T, fps_I, online):
    header = open(path).readline().strip().split(",")
    assert tuple(header) == MAP_COLUMNS
    cols = read_map_csv(path)
    q = cols["target_frame"]
    np.testing.assert_array_equal(q, np.arange(n_target))
    np.testing.assert_allclose(cols["target_time_s"], q / fps_T, atol=5e-7)
    np.testing.assert_allclose(cols["input_time_s"], cols["input_frame"] / fps_I, atol=5e-7)
    if online:
        assert np.all(np.isfinite(cols["step_us"])) and np.all(cols["step_us"] >= 0)
    else:
        assert np.all(np.isnan(cols["step_us"]))
    return cols["input_frame"]


# ------------------------------------------------------------------------------- help
@pytest.mark.parametrize(
    "args",
    [[], ["align"], ["live"], ["data"], ["data", "fetch"], ["data", "verify"], ["data", "cite"]],
)
def test_help_works_for_every_command(args):
    r = cli(*args, "--help")
    assert r.returncode == 0 and r.stderr == ""
    assert r.stdout.startswith("usage: fpdtw" + "".join(" " + a for a in args))
    if args in (["align"], ["live"]):
        for text in ("oltw", "step_us", "resampled", "--window", "typeV", "--skeleton"):
            assert text in r.stdout
    if args == ["live"]:
        assert "DROPPED" in r.stdout and "--animate" in r.stdout and "--fast" in r.stdout


def test_no_command_is_a_usage_error():
    r = cli()
    assert r.returncode == 2 and "usage: fpdtw" in r.stderr


# ----------------------------------------------------------------------- real alignments
@pytest.fixture(scope="module")
def walk(data_path):
    I, T = load_motion(data_path(WALK1)), load_motion(data_path(WALK2))
    M, _ = align("Mc w40", MotionFeatures.from_motion(I), MotionFeatures.from_motion(T))
    return I, T, M


def test_align_fbx_method_c_and_export(walk, data_path, tmp_path):
    I, T, M_lib = walk
    out, bvh = tmp_path / "map.csv", tmp_path / "aligned.bvh"
    r = cli("align", data_path(WALK1), data_path(WALK2), "-m", "c", "-w", 40, "--out", out,
            "--export-bvh", bvh)  # fmt: skip
    assert r.returncode == 0, r.stderr
    assert "Mc w40" in r.stdout and "time per target frame" in r.stdout
    M = read_csv_checked(out, T.n_frames, 120.0, 120.0, online=True)
    np.testing.assert_array_equal(M, M_lib)  # the same map as the library
    check_exported_bvh(bvh, I, M, 120.0)


def test_align_amc_dtw_and_export(data_path, tmp_path):
    I, T = load_motion(data_path(SQUAT1)), load_motion(data_path(SQUAT2))
    out, bvh = tmp_path / "map.csv", tmp_path / "squat_aligned.bvh"
    r = cli("align", data_path(SQUAT1), data_path(SQUAT2), "--method", "dtw", "-o", out,
            "--export-bvh", bvh)  # fmt: skip
    assert r.returncode == 0, r.stderr
    M = read_csv_checked(out, T.n_frames, 120.0, 120.0, online=False)
    np.testing.assert_array_equal(
        M, dtw_pair(MotionFeatures.from_motion(I), MotionFeatures.from_motion(T)).map
    )
    check_exported_bvh(bvh, I, M, 120.0)


def test_align_amc_with_explicit_skeleton(data_path, tmp_path):
    asf = data_path("hdm05/HDM05_cut_amc/HDM_bd.asf")
    r = cli("align", data_path(SQUAT1), data_path(SQUAT2), "-m", "utw", "-o", tmp_path / "m.csv",
            "--skeleton", asf, "--target-skeleton", asf)  # fmt: skip
    assert r.returncode == 0, r.stderr
    M = read_csv_checked(tmp_path / "m.csv", 148, 120.0, 120.0, online=False)
    assert M[0] == 0 and M[-1] == 139


def test_align_bvh_follows_a_known_warp(data_path, tmp_path):
    """CMU 18_01 (30 Hz) against a copy of itself played at a known varying speed."""
    I = load_motion(data_path(CMU))
    s = np.linspace(0.0, 1.0, 241) ** 1.3 * I.duration  # slow start, then faster
    target = write_bvh(I.retime(s, name="warped"), tmp_path / "warped.bvh")
    truth = s * I.fps
    for method, extra, tol in (("dtw", [], 1.0), ("oltw", ["-w", 30], 3.0)):
        out, bvh = tmp_path / f"{method}.csv", tmp_path / f"{method}.bvh"
        r = cli("align", data_path(CMU), target, "-m", method, *extra, "-o", out,
                "--export-bvh", bvh)  # fmt: skip
        assert r.returncode == 0, r.stderr
        M = read_csv_checked(out, 241, 30.0, 30.0, online=method == "oltw")
        assert np.median(np.abs(M - truth)) <= tol, method
        check_exported_bvh(bvh, I, M, 30.0)


@pytest.fixture(scope="module")
def walk2_bvh_60hz(walk, tmp_path_factory):
    """Walk_02 (FBX) written as BVH at 60 Hz: a target in another format and frame rate."""
    _, T, _ = walk
    return write_bvh(T.resample(60.0), tmp_path_factory.mktemp("bvh") / "walk2_60.bvh")


def test_align_mixed_fbx_input_bvh_target_resamples_the_target(walk, data_path, tmp_path,
                                                               walk2_bvh_60hz):  # fmt: skip
    I, T, _ = walk
    r = cli("align", data_path(WALK1), walk2_bvh_60hz, "-m", "a", "-o", tmp_path / "m.csv")
    assert r.returncode == 0, r.stderr
    assert "resampling the target walk2_60 from 60 Hz to the input's 120 Hz" in r.stderr
    n_T = T.resample(60.0).resample(120.0).n_frames
    M = read_csv_checked(tmp_path / "m.csv", n_T, 120.0, 120.0, online=True)
    assert np.all(np.diff(M) >= 0) and M.max() <= I.n_frames - 1


def test_fps_option_resamples_both(walk, data_path, tmp_path, walk2_bvh_60hz):
    I, _, _ = walk
    r = cli("align", data_path(WALK1), walk2_bvh_60hz, "-m", "c", "-w", 20, "--fps", 60,
            "-o", tmp_path / "m.csv", "--export-bvh", tmp_path / "a.bvh")  # fmt: skip
    assert r.returncode == 0, r.stderr
    assert "resampling the input Walk_01 from 120 Hz to 60 Hz" in r.stderr
    I60 = I.resample(60.0)
    T60 = read_bvh(walk2_bvh_60hz)
    M = read_csv_checked(tmp_path / "m.csv", T60.n_frames, 60.0, 60.0, online=True)
    assert M.max() <= I60.n_frames - 1
    check_exported_bvh(tmp_path / "a.bvh", I60, M, 60.0)


def test_align_opw(data_path, tmp_path):
    r = cli("align", data_path(SQUAT1), data_path(SQUAT2), "-m", "opw", "-o", tmp_path / "m.csv")
    assert r.returncode == 0, r.stderr
    M = read_csv_checked(tmp_path / "m.csv", 148, 120.0, 120.0, online=True)
    assert np.all(np.diff(M) >= 0)


# ------------------------------------------------------------------------------------ live
def test_live_fast_with_map_and_animation(walk, data_path, tmp_path):
    _, T, M_lib = walk
    out, gif = tmp_path / "live.csv", tmp_path / "walk.gif"
    r = cli("live", data_path(WALK1), data_path(WALK2), "--method", "c", "--window", 40,
            "--fast", "--out", out, "--animate", gif, "--stride", 40)  # fmt: skip
    assert r.returncode == 0, r.stderr
    lines = r.stdout.splitlines()
    assert lines[0].startswith("aligner: Mc w40; 637 target frames at 120 Hz; as fast as")
    assert lines[1].split() == ["p50", "p90", "p99", "max", "budget"]
    assert lines[2].split()[:3] == ["step", "time", "(ms)"] and lines[2].split()[-1] == "8.333"
    assert lines[3].split()[:2] == ["response", "(ms)"] and lines[3].split()[-1] == "8.333"
    assert lines[4].startswith("dropped frames: ") and "of 637" in lines[4]
    M = read_csv_checked(out, T.n_frames, 120.0, 120.0, online=True)
    np.testing.assert_array_equal(M, M_lib)
    from PIL import Image

    assert Image.open(gif).n_frames == 16  # ceil(637 / 40)


def test_live_mp4_needs_ffmpeg(data_path, tmp_path):
    env = dict(os.environ, PATH=str(tmp_path))  # no ffmpeg on PATH
    r = cli("live", data_path(SQUAT1), data_path(SQUAT2), "--fast", "--animate",
            tmp_path / "a.mp4", env=env)  # fmt: skip
    if importlib.util.find_spec("imageio_ffmpeg") is None:
        line = one_error_line(r)
        assert "a.mp4" in line and "needs ffmpeg" in line and ".gif" in line
        assert not (tmp_path / "a.mp4").exists()
    else:  # imageio-ffmpeg brings its own binary
        assert r.returncode == 0 and (tmp_path / "a.mp4").stat().st_size > 0


def test_data_fetch_and_verify_into_a_fresh_cache(mirror_root, tmp_path):
    env = dict(os.environ, FPDTW_DATA_DIR=str(tmp_path / "cache"), FPDTW_MIRROR=str(mirror_root))
    r = cli("data", "fetch", "--dataset", "cmu", "--quiet", env=env)
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "cache" / CMU).is_file() and "1 files verified" in r.stdout
    r = cli("data", "verify", "--dataset", "cmu", env=env)
    assert r.returncode == 0 and "1 verified, 0 corrupt, 0 missing" in r.stdout
    r = cli("data", "verify", "--dataset", "cmu", "--dataset", "hdm05", env=env)
    assert r.returncode == 1 and "1 verified, 0 corrupt, 292 missing" in r.stdout
    assert "FAILED: 292 of 293 files missing or wrong" in r.stdout
    r = cli("data", "fetch", "--dataset", "nosuch", "--quiet", env=env)
    assert r.returncode == 1 and "nosuch" in r.stderr
    assert r.stderr.strip().splitlines()[-1].startswith("fpdtw: error: ")
    r = cli("data", "fetch", "--file", "18_01.bvh", env=env)  # usage: needs one --dataset
    assert r.returncode == 2 and "--file needs exactly one --dataset" in r.stderr


def test_data_cite():
    r = cli("data", "cite")
    assert r.returncode == 0, r.stderr
    assert r.stdout.count("Licence:") == 3 and "ODC-By" in r.stdout


# ----------------------------------------------------------------------------- bad input
def test_window_zero_is_a_usage_error(data_path, tmp_path):
    r = cli("align", data_path(SQUAT1), data_path(SQUAT2), "-m", "c", "--window", 0, "-o",
            tmp_path / "m.csv")  # fmt: skip
    assert r.returncode == 2
    assert "usage: fpdtw align" in r.stderr and "--window" in r.stderr and "at least 1" in r.stderr
    assert not (tmp_path / "m.csv").exists()


@pytest.mark.parametrize(
    "args,needle",
    [
        (["-m", "zz"], "invalid choice: 'zz'"),
        (["-m", "dtw", "--constraint", "typeV"], "--constraint applies to methods a, b, c"),
        (["-m", "utw", "--window", "3"], "--window does not apply to method 'utw'"),
        (["-m", "oltw", "--window", "1"], "at least 2"),
        (["-m", "c", "--window", "1"], "--window of method c must be at least 2"),
        (["-m", "c", "--skeleton", "x.asf"], "--skeleton applies to an .amc motion"),
        (["-m", "c", "--window", "ten"], "must be a whole number"),
        (["-m", "c", "--fps", "-5"], "must be a positive number"),
        (["-m", "c"], "the following arguments are required: --out"),
    ],
)
def test_bad_options_are_usage_errors(data_path, args, needle):
    extra = [] if needle.startswith("the following") else ["-o", "m.csv"]
    r = cli("align", data_path(CMU), data_path(CMU), *args, *extra)
    assert r.returncode == 2 and needle in r.stderr, r.stderr


def test_live_rejects_offline_methods(data_path):
    r = cli("live", data_path(CMU), data_path(CMU), "-m", "dtw")
    assert r.returncode == 2 and "'dtw' is offline" in r.stderr


def test_missing_file(data_path, tmp_path):
    missing = tmp_path / "nothere.fbx"
    r = cli("align", missing, data_path(CMU), "-m", "a", "-o", tmp_path / "m.csv")
    assert one_error_line(r) == f"fpdtw: error: {missing}: no such file"
    r = cli("align", missing, data_path(CMU), "-m", "a", "-o", tmp_path / "m.csv", "--debug")
    assert r.returncode == 1 and "Traceback" in r.stderr and "MotionFormatError" in r.stderr


@pytest.mark.parametrize(
    "name,content,needle",
    [
        ("junk.bvh", b"this is not a motion\n", "no MOTION section"),
        ("junk.fbx", bytes(range(256)) * 8, "not a readable FBX file"),
        ("junk.amc", b"1\nroot 0 0\n", "no skeleton found"),
        ("motion.txt", b"1 2 3\n", "unknown motion file type '.txt'"),
    ],
)
def test_garbage_files(data_path, tmp_path, name, content, needle):
    bad = tmp_path / name
    bad.write_bytes(content)
    r = cli("align", data_path(CMU), bad, "-m", "a", "-o", tmp_path / "m.csv")
    line = one_error_line(r)
    assert line.startswith(f"fpdtw: error: {bad}") and needle in line


NO_RIGHT_ELBOW = (
    """HIERARCHY
ROOT hip
{
  OFFSET 0 0 0
  CHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation
  JOINT lfemur
  { OFFSET 1 0 0 CHANNELS 3 Zrotation Yrotation Xrotation
    JOINT ltibia { OFFSET 0 -4 0 CHANNELS 3 Zrotation Yrotation Xrotation
      End Site { OFFSET 0 -4 0 } } }
  JOINT rfemur
  { OFFSET -1 0 0 CHANNELS 3 Zrotation Yrotation Xrotation
    JOINT rtibia { OFFSET 0 -4 0 CHANNELS 3 Zrotation Yrotation Xrotation
      End Site { OFFSET 0 -4 0 } } }
  JOINT lhumerus
  { OFFSET 1 5 0 CHANNELS 3 Zrotation Yrotation Xrotation
    JOINT lradius { OFFSET 2 0 0 CHANNELS 3 Zrotation Yrotation Xrotation
      End Site { OFFSET 2 0 0 } } }
  JOINT rhumerus
  { OFFSET -1 5 0 CHANNELS 3 Zrotation Yrotation Xrotation
    End Site { OFFSET -2 0 0 } }
}
MOTION
Frames: 2
Frame Time: 0.0333333
"""
    + "\n".join(" ".join(["0"] * 27) for _ in range(2))
    + "\n"
)


def test_mismatched_skeleton_names_file_and_joint(data_path, tmp_path):
    tiny = tmp_path / "tiny.bvh"
    tiny.write_text(NO_RIGHT_ELBOW)
    assert read_bvh(tiny).n_frames == 2  # a valid BVH, just without a right elbow
    for args in (["-m", "a"], ["-m", "oltw"]):
        r = cli("align", data_path(CMU), tiny, *args, "-o", tmp_path / "m.csv")
        line = one_error_line(r)
        assert line.startswith(f"fpdtw: error: {tiny}: ")
        assert "'right_elbow'" in line and "8 joints" in line
    r = cli("align", data_path(CMU), tiny, "-m", "opw", "-o", tmp_path / "m.csv")
    assert "16 OPW joints" in one_error_line(r)


def test_unwritable_output(data_path, tmp_path):
    out = tmp_path / "no" / "such" / "folder" / "m.csv"
    r = cli("align", data_path(CMU), data_path(CMU), "-m", "utw", "-o", out)
    line = one_error_line(r)  # the file asked for, not its temporary .part name
    assert line == f"fpdtw: error: {out}: cannot write it: no folder {out.parent}"


# ------------------------------------------------------------------ fpdtw.app.export library
def test_retime_by_map_copies_frames_exactly(data_path):
    I = load_motion(data_path(SQUAT1))
    M = np.array([0, 0, 5, 9, 9, 139, 3])
    R = retime_by_map(I, M, 60.0)
    assert R.n_frames == 7 and R.fps == 60.0 and R.skeleton is I.skeleton
    np.testing.assert_array_equal(R.euler, I.euler[M])
    np.testing.assert_array_equal(R.quats, I.quats[M])
    np.testing.assert_array_equal(R.root_translation, I.root_translation[M])
    assert R.name == f"{I.name}_aligned"
    for bad in ([], [[0, 1]], [0, 140], [-1, 0], [0.5, 1.0]):
        with pytest.raises(AlignmentError):
            retime_by_map(I, bad, 60.0)
    with pytest.raises(AlignmentError, match="frame rate"):
        retime_by_map(I, [0, 1], 0.0)
    np.testing.assert_array_equal(retime_by_map(I, [0.0, 2.0], 120).quats, I.quats[[0, 2]])


def test_map_csv_round_trip(tmp_path):
    M = np.array([0, 1, 1, 3])
    p = write_map_csv(tmp_path / "m.csv", M, 60.0, 120.0, [1e-6, 2.5e-6, 3e-6, 4e-6])
    assert p.read_text().splitlines()[:2] == [
        "target_frame,target_time_s,input_frame,input_time_s,step_us",
        "0,0.000000,0,0.000000,1.000",
    ]
    c = read_map_csv(p)
    np.testing.assert_array_equal(c["input_frame"], M)
    np.testing.assert_allclose(c["target_time_s"], [0, 1 / 60, 2 / 60, 3 / 60], atol=5e-7)
    np.testing.assert_allclose(c["input_time_s"], M / 120.0, atol=5e-7)
    np.testing.assert_allclose(c["step_us"], [1.0, 2.5, 3.0, 4.0])
    c = read_map_csv(write_map_csv(tmp_path / "o.csv", M, 60.0, 120.0))
    assert np.isnan(c["step_us"]).all()
    with pytest.raises(AlignmentError, match="step times"):
        write_map_csv(tmp_path / "x.csv", M, 60.0, 120.0, [1.0])
    assert sorted(f.name for f in tmp_path.iterdir()) == ["m.csv", "o.csv"]  # no .part left
