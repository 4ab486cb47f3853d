"""Issue 11: bounds on every size, errors that name the file (fpdtw.limits, the readers, the CLI).

One regression test per case of the audit (before: what a new user saw; after: a clear
error naming the file, or a correct result), then the limits themselves in the library.
The command line runs as a subprocess (``tests/test_cli.py``'s ``cli`` helper).
"""

from __future__ import annotations

import os
import re

import numpy as np
import pytest
from reference.synthetic import random_walk_features
from test_cli import CMU, SQUAT1, SQUAT2, WALK1, WALK2, cli, one_error_line, read_csv_checked

from fpdtw import limits
from fpdtw.dtw import dtw_pair
from fpdtw.errors import AlignmentError, LimitError, MotionFormatError
from fpdtw.io import load_motion
from fpdtw.io.asfamc import read_amc
from fpdtw.io.bvh import read_bvh
from fpdtw.io.fbx import read_fbx
from fpdtw.motion.features import MotionFeatures
from fpdtw.online import OEDTW, MethodA, MethodB, MethodC
from fpdtw.online.base import run_online
from fpdtw.online.oltw import OLTW
from fpdtw.online.opw import OPW


def error_line(r, code=1):
    """Exit ``code``, no traceback, and the last stderr line (after any "resampling ..."
    progress lines) is the one ``fpdtw: error:`` line."""
    assert r.returncode == code, r.stderr
    lines = r.stderr.strip().splitlines()
    assert "Traceback" not in r.stderr and lines[-1].startswith("fpdtw: error: "), r.stderr
    assert sum(x.startswith("fpdtw") for x in lines) == 1, r.stderr
    return lines[-1]


def bvh_with(data_path, tmp_path, name, *, frame_time=None, frames=None, keep=None, bom=b""):
    """CMU 18_01 with its ``Frame Time`` / ``Frames`` replaced, cut to ``keep`` frames."""
    lines = data_path(CMU).read_text().splitlines()
    at = next(i for i, s in enumerate(lines) if s.startswith("Frames:"))
    if keep is not None:
        lines = lines[: at + 2 + keep]
        lines[at] = f"Frames: {keep}"
    if frames is not None:
        lines[at] = f"Frames: {frames}"
    if frame_time is not None:
        lines[at + 1] = f"Frame Time: {frame_time}"
    p = tmp_path / name
    p.write_bytes(bom + ("\n".join(lines) + "\n").encode())
    return p


# ------------------------------------------------------------------------ the audit cases
@pytest.mark.parametrize("order", ["as input", "as target"])
def test_frame_time_1e300_is_refused_naming_the_file(data_path, tmp_path, order):
    """Before: a 1e-300 Hz motion; as the input, the target was resampled to it and
    `align` reported success with a 1-row map; as the target, numpy's "Maximum allowed
    size exceeded". After: exit 1, the file, its line, the rate and the range."""
    bad = bvh_with(data_path, tmp_path, "slow.bvh", frame_time="1e300")
    pair = (bad, data_path(CMU)) if order == "as input" else (data_path(CMU), bad)
    out = tmp_path / "m.csv"
    line = one_error_line(cli("align", *pair, "-m", "c", "-o", out))
    assert line.startswith(f"fpdtw: error: {bad} (line 187): Frame Time 1e300 s: ")
    assert "1e-300 Hz is outside the plausible range 1..10000 Hz" in line
    assert "FPDTW_MIN_FPS" in line and not out.exists()


@pytest.mark.parametrize("order", ["as input", "as target"])
def test_frame_time_1e_minus_300_is_refused_naming_the_file(data_path, tmp_path, order):
    """Before: numpy's "Maximum allowed size exceeded" naming no file (or, as the
    target, a 1-frame success). After: exit 1 naming the file."""
    bad = bvh_with(data_path, tmp_path, "fast.bvh", frame_time="1e-300")
    pair = (bad, data_path(CMU)) if order == "as input" else (data_path(CMU), bad)
    line = one_error_line(cli("align", *pair, "-m", "c", "-o", tmp_path / "m.csv"))
    assert line.startswith(f"fpdtw: error: {bad} (line 187): Frame Time 1e-300 s: ")
    assert "1e+300 Hz is outside the plausible range" in line


def test_frame_time_below_the_smallest_double_inverse(data_path, tmp_path):
    """1 / 1e-310 is inf (round() of it used to raise OverflowError): a clear error."""
    bad = bvh_with(data_path, tmp_path, "tiny.bvh", frame_time="1e-310")
    with pytest.raises(MotionFormatError, match=r"tiny\.bvh \(line 187\).*inf Hz is outside"):
        read_bvh(bad)


@pytest.mark.parametrize("method,fps", [("c", "1e6"), ("dtw", "1e5")])
def test_fps_outside_the_range_is_a_usage_error(data_path, tmp_path, method, fps):
    """Before: 9-34 GiB allocations ending as `internal error: MemoryError`. After: a
    usage error (exit 2) before anything is read, with the range and how to change it."""
    r = cli("align", data_path(WALK1), data_path(WALK2), "-m", method, "--fps", fps,
            "-o", tmp_path / "m.csv")  # fmt: skip
    assert r.returncode == 2, r.stderr
    assert "usage: fpdtw align" in r.stderr and "Traceback" not in r.stderr
    assert re.search(r"argument --fps: frame rate \S+ Hz is outside the plausible range "
                     r"1\.\.10000 Hz \(FPDTW_MIN_FPS, FPDTW_MAX_FPS\)", r.stderr)  # fmt: skip
    assert "resampling" not in r.stderr


def test_dtw_too_large_after_resampling_names_both_files_and_the_way_out(data_path, tmp_path):
    """--fps 1e4 is a plausible rate, but DTW of the two 5.4 s walks at 10 kHz would need
    two 54001 x 53001 matrices: refused before allocating, exit 1."""
    r = cli("align", data_path(WALK1), data_path(WALK2), "-m", "dtw", "--fps", "1e4",
            "-o", tmp_path / "m.csv")  # fmt: skip
    line = error_line(r)
    assert line.startswith(f"fpdtw: error: {data_path(WALK1)}, {data_path(WALK2)}: ")
    assert "two 54001 x 53001 float64 matrices (42.6 GiB)" in line
    assert "more than the limit of 2 GiB (FPDTW_MAX_MATRIX_BYTES)" in line
    assert "use an online method" in line and "--fps" in line


def test_matrix_limit_is_overridable_by_environment(data_path, tmp_path):
    env = dict(os.environ, FPDTW_MAX_MATRIX_BYTES="100000")  # 140 x 148 x 16 = 331520
    args = ("align", data_path(SQUAT1), data_path(SQUAT2), "-m", "dtw", "-o", tmp_path / "m.csv")
    line = one_error_line(cli(*args, env=env))
    assert "two 140 x 148 float64 matrices (324 KiB), more than the limit of 97.7 KiB" in line
    assert not (tmp_path / "m.csv").exists()
    r = cli(*args)  # the default limit: fine
    assert r.returncode == 0, r.stderr
    read_csv_checked(tmp_path / "m.csv", 148, 120.0, 120.0, online=False)


def test_directory_given_as_motion_file(data_path, tmp_path):
    """Before: "no such file". After: "is a directory" (and a missing file stays "no such
    file")."""
    folder = tmp_path / "take.bvh"
    folder.mkdir()
    line = one_error_line(cli("align", folder, data_path(CMU), "-m", "a", "-o", tmp_path / "m"))
    assert line == f"fpdtw: error: {folder}: is a directory, not a motion file"
    with pytest.raises(MotionFormatError, match="is a directory"):
        load_motion(folder)
    for reader in (read_bvh, read_fbx):
        with pytest.raises(MotionFormatError, match="is a directory"):
            reader(folder)
    with pytest.raises(MotionFormatError, match="no such file"):
        load_motion(tmp_path / "nothere.bvh")


def test_bvh_with_a_utf8_byte_order_mark_is_read(data_path, tmp_path):
    """Before: "file must start with HIERARCHY, got 'ï»¿HIERARCHY'". After: read like the
    file without the mark; the CLI gives the same map."""
    plain = read_bvh(data_path(CMU))
    bom = bvh_with(data_path, tmp_path, "bom.bvh", bom=b"\xef\xbb\xbf")
    m = read_bvh(bom)
    np.testing.assert_array_equal(m.euler, plain.euler)
    assert m.joint_names == plain.joint_names and m.fps == plain.fps
    text = data_path(CMU).read_text()
    for mark, codec in ((b"\xff\xfe", "utf-16-le"), (b"\xfe\xff", "utf-16-be")):
        (tmp_path / f"{codec}.bvh").write_bytes(mark + text.encode(codec))
        np.testing.assert_array_equal(read_bvh(tmp_path / f"{codec}.bvh").euler, plain.euler)
    (tmp_path / "odd.bvh").write_bytes(b"\xff\xfe" + b"HIERARCHY\n\x00")
    with pytest.raises(MotionFormatError, match=r"odd\.bvh: .*UTF-16"):
        read_bvh(tmp_path / "odd.bvh")
    r = cli("align", bom, data_path(CMU), "-m", "c", "-o", tmp_path / "bom.csv")
    assert r.returncode == 0, r.stderr
    r = cli("align", data_path(CMU), data_path(CMU), "-m", "c", "-o", tmp_path / "plain.csv")
    a = read_csv_checked(tmp_path / "bom.csv", 303, 30.0, 30.0, online=True)
    b = read_csv_checked(tmp_path / "plain.csv", 303, 30.0, 30.0, online=True)
    np.testing.assert_array_equal(a, b)


def test_asf_and_amc_with_a_byte_order_mark_are_read(data_path, tmp_path):
    asf, amc = data_path("hdm05/HDM05_cut_amc/HDM_bd.asf"), data_path(SQUAT1)
    (tmp_path / "s.asf").write_bytes(b"\xef\xbb\xbf" + asf.read_bytes())
    (tmp_path / "c.amc").write_bytes(b"\xef\xbb\xbf" + amc.read_bytes())
    np.testing.assert_array_equal(
        read_amc(tmp_path / "c.amc", tmp_path / "s.asf").euler, read_amc(amc, asf).euler
    )


def test_one_frame_motion_with_opw_names_the_file(data_path, tmp_path):
    """Before: "OPW needs a recording of at least two frames" naming no file. After: the
    file and its frame count, for every method."""
    one = bvh_with(data_path, tmp_path, "one.bvh", keep=1)
    assert read_bvh(one).n_frames == 1  # a valid file
    for method in ("opw", "c", "dtw"):
        line = one_error_line(cli("align", one, data_path(CMU), "-m", method, "-o", tmp_path / "m"))
        assert line == (
            f"fpdtw: error: {one}: the input has 1 frame; aligning needs at least 2 frames "
            "per motion"
        )
    line = one_error_line(cli("align", data_path(CMU), one, "-m", "opw", "-o", tmp_path / "m"))
    assert line.startswith(f"fpdtw: error: {one}: the target has 1 frame")
    from fpdtw.motion.joints import OPW_JOINTS

    f = MotionFeatures.from_motion(read_bvh(one), position_joints=OPW_JOINTS)
    with pytest.raises(AlignmentError, match="at least two frames; 'one' has 1"):
        OPW(f)


def test_out_pointing_at_a_directory_names_it(data_path, tmp_path):
    """Before: "fpdtw: error: <out>.part: Is a directory". After: the --out path, before
    the motions are read; a missing folder likewise."""
    folder = tmp_path / "maps"
    folder.mkdir()
    line = one_error_line(cli("align", data_path(CMU), data_path(CMU), "-m", "c", "-o", folder))
    assert line == f"fpdtw: error: {folder}: is a directory; --out needs a file name"
    bvh = tmp_path / "x.bvh"
    bvh.mkdir()
    r = cli("align", data_path(CMU), data_path(CMU), "-m", "utw", "-o", tmp_path / "m.csv",
            "--export-bvh", bvh)  # fmt: skip
    line = one_error_line(r)
    assert line == f"fpdtw: error: {bvh}: is a directory; --export-bvh needs a file name"
    assert not (tmp_path / "m.csv").exists()
    r = cli("live", data_path(CMU), data_path(CMU), "--fast", "-o", folder)
    assert one_error_line(r) == f"fpdtw: error: {folder}: is a directory; --out needs a file name"
    assert ".part" not in r.stderr


def test_write_map_csv_names_the_file_not_the_temporary_one(tmp_path):
    from fpdtw.app.export import write_map_csv

    folder = tmp_path / "m.csv"
    folder.mkdir()
    with pytest.raises(OSError) as info:
        write_map_csv(folder, np.array([0, 1]), 120.0, 120.0)
    assert info.value.filename == str(folder)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["m.csv"]  # no .part left


# ------------------------------------------------------------------ more sizes that enter
def test_resampling_that_leaves_one_frame_is_an_error(data_path, tmp_path):
    """3 frames at 30 Hz last 1/15 s: at 10 Hz that is one frame, never a 1-row result."""
    short = bvh_with(data_path, tmp_path, "short.bvh", keep=3)
    m = read_bvh(short)
    with pytest.raises(LimitError, match=r"short\.bvh: resampling 3 frames at 30 Hz to 10 Hz "
                       r"would leave 1 frame \(at least 2 are needed\)"):  # fmt: skip
        m.resample(10.0)
    line = error_line(cli("align", data_path(CMU), short, "-m", "c", "--fps", 10, "-o",
                              tmp_path / "m.csv"))  # fmt: skip
    assert line.startswith(f"fpdtw: error: {short}: resampling 3 frames at 30 Hz to 10 Hz")
    assert m.resample(20.0).n_frames == 2  # 1/15 s at 20 Hz: two frames, fine
    assert m.slice_frames(0, 1).resample(10.0).n_frames == 1  # one frame stays one


def test_resampling_past_max_frames_names_the_file(data_path, tmp_path):
    cmu = read_bvh(data_path(CMU))  # 303 frames at 30 Hz
    with limits.override(max_frames=1000):
        with pytest.raises(LimitError) as info:
            cmu.resample(120.0)
        assert cmu.resample(90.0).n_frames == 907
    msg = str(info.value)
    assert msg.startswith(f"{data_path(CMU)}: resampling 303 frames at 30 Hz to 120 Hz would give")
    assert "1209 frames, more than the limit of 1000 frames (FPDTW_MAX_FRAMES)" in msg
    with pytest.raises(LimitError, match="cannot resample to it: frame rate 0.5 Hz is outside"):
        cmu.resample(0.5)
    env = dict(os.environ, FPDTW_MAX_FRAMES="1000")
    line = error_line(cli("align", data_path(CMU), data_path(CMU), "-m", "c", "--fps", 120,
                              "-o", tmp_path / "m.csv", env=env))  # fmt: skip
    assert f"{data_path(CMU)}: resampling 303 frames" in line and "FPDTW_MAX_FRAMES" in line


def test_every_reader_checks_frame_rate_and_frame_count(data_path, tmp_path):
    needle = r"Walk_01\.fbx: animation keys 0.00833333 s apart: frame rate 120 Hz is outside"
    with pytest.raises(MotionFormatError, match=needle), limits.override(max_fps=100.0):
        read_fbx(data_path(WALK1))
    with pytest.raises(MotionFormatError, match=r"Walk_01\.fbx: 649 frames, more than the limit"):
        with limits.override(max_frames=600):
            read_fbx(data_path(WALK1))
    with pytest.raises(MotionFormatError, match=r"squat1Reps_001_120\.amc: fps=0.001: frame rate"):
        read_amc(data_path(SQUAT1), fps=0.001)
    with pytest.raises(MotionFormatError, match=r"squat1Reps_001_120\.amc: 140 frames, more"):
        with limits.override(max_frames=100):
            read_amc(data_path(SQUAT1))
    huge = bvh_with(data_path, tmp_path, "many.bvh", frames=10**12)
    with pytest.raises(MotionFormatError, match=r"many\.bvh \(line 186\): 1000000000000 frames"):
        read_bvh(huge)  # refused from the header, before the data lines are parsed
    with pytest.raises(MotionFormatError, match=r"18_01\.bvh: file is 228 KiB, more than the "
                       r"limit of 97.7 KiB \(FPDTW_MAX_FILE_BYTES\)"):  # fmt: skip
        with limits.override(max_file_bytes=100_000):
            load_motion(data_path(CMU))


def test_window_and_band_sizes_are_bounded(data_path, tmp_path):
    I = random_walk_features(50)
    with limits.override(max_matrix_bytes=10**6):
        for cls in (MethodA, MethodB, MethodC):
            with pytest.raises(LimitError, match=rf"{cls.__name__}'s window matrices would be "
                               r"up to two 301 x 301 float64 \(1.38 MiB\)"):  # fmt: skip
                cls(I, 300)
            cls(I, 200)  # 0.6 MiB: fine
        with pytest.raises(LimitError, match=r"OLTW's search band would be c x c = 400 x 400"):
            OLTW(I, 400)
        OLTW(I, 300)
    for method, w, needle in (("c", 100000, "two 100001 x 100001 windows (149 GiB)"),
                              ("oltw", 100000, "OLTW's c x c band (100000 x 100000)")):  # fmt: skip
        r = cli(
            "align", data_path(CMU), data_path(CMU), "-m", method, "-w", w, "-o", tmp_path / "m"
        )
        assert r.returncode == 2 and needle in r.stderr and "FPDTW_MAX_MATRIX_BYTES" in r.stderr


def test_dtw_and_oedtw_refuse_before_allocating():
    I, T = random_walk_features(2000, seed=1), random_walk_features(5000, seed=2)
    I = MotionFeatures(I.quats, I.euler, I.orders, I.fps, None, "long_in")
    T = MotionFeatures(T.quats, T.euler, T.orders, T.fps, None, "long_tg")
    with limits.override(max_matrix_bytes=64 * 2**20):  # 2000 x 5000 x 16 = 153 MiB
        needle = r"long_in, long_tg: offline DTW of 2000 input x 5000 target frames needs two"
        with pytest.raises(LimitError, match=needle):
            dtw_pair(I, T)
        oe = OEDTW(I)
        with pytest.raises(LimitError, match=r"long_in: OE-DTW keeps every accumulated column"):
            run_online(oe, T)  # 4096 columns x 2000 x 8 = 62.5 MiB fit; 8192 do not
        assert oe.n_received == 4097 and oe._cols.shape == (4096, 2000)
    assert dtw_pair(I.slice(0, 300), T.slice(0, 300)).map.shape == (300,)


def test_limits_from_environment_and_override(monkeypatch):
    assert limits.get("max_frames") == limits.MAX_FRAMES == 1_000_000
    monkeypatch.setenv("FPDTW_MAX_FRAMES", "5e5")
    assert limits.get("max_frames") == 500_000
    with limits.override(max_frames=10):
        assert limits.get("max_frames") == 10
    assert limits.get("max_frames") == 500_000
    for bad in ("-3", "nan", "lots", "inf"):
        monkeypatch.setenv("FPDTW_MAX_FRAMES", bad)
        with pytest.raises(LimitError, match=f"FPDTW_MAX_FRAMES={bad!r} is not a positive number"):
            limits.get("max_frames")
    with pytest.raises(TypeError, match="unknown limit"), limits.override(max_freams=3):
        pass
    assert limits.format_bytes(2**31) == "2 GiB" and limits.format_bytes(512) == "512 bytes"
    assert limits.fps_problem(120.0) is None and limits.fps_problem(10000.0) is None
    assert "outside" in limits.fps_problem(0.999) and "outside" in limits.fps_problem(float("nan"))


# ------------------------------------------------------------- found by tests/test_fuzz.py
def test_huge_offset_is_refused_not_turned_into_infinite_positions(data_path, tmp_path):
    """A BVH OFFSET of 1e308 read as a valid motion whose forward kinematics were -inf
    (test_fuzz_bvh, profile fuzz, seed 0: ops=[('number', 4, '1e308')])."""
    text = data_path(CMU).read_text().replace("OFFSET 1.37959 -1.78713", "OFFSET 1e308 -1.78713")
    (tmp_path / "far.bvh").write_text(text)
    with pytest.raises(MotionFormatError, match=r"far\.bvh: implausible joint offset 1e\+308 "
                       r"\(larger in magnitude than 1e\+12, FPDTW_MAX_ABS_VALUE\)"):  # fmt: skip
        read_bvh(tmp_path / "far.bvh")
    text = data_path(CMU).read_text().replace("\n9.2465 17.8507", "\n9.2465 2e12", 1)
    (tmp_path / "away.bvh").write_text(text)
    with pytest.raises(MotionFormatError, match=r"away\.bvh \(frame 0\): implausible translation"):
        read_bvh(tmp_path / "away.bvh")
    with limits.override(max_abs_value=1e13):
        assert read_bvh(tmp_path / "away.bvh").root_translation[0, 1] == 2e12


def test_asf_direction_with_huge_components_is_normalised(data_path, tmp_path):
    """``direction 1e300 0 0``: its norm overflowed to inf and the bone silently got a
    zero direction (test_fuzz_asf); now it is the unit vector it names."""
    asf = data_path("hdm05/HDM05_cut_amc/HDM_bd.asf").read_text()
    at = asf.index("direction", asf.index("name lfemur"))
    end = asf.index("\n", at)
    (tmp_path / "s.asf").write_text(asf[:at] + "direction 1e300 0 0" + asf[end:])
    from fpdtw.io.asfamc import read_asf

    sk = read_asf(tmp_path / "s.asf")
    j = sk.skeleton.index("lfemur")
    np.testing.assert_array_equal(sk.directions[j], [1.0, 0.0, 0.0])
