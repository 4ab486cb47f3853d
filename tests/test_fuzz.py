"""Fuzzing the readers and ``fpdtw align`` with mutants of real files (hypothesis).

Real BVH (CMU 18_01, cut to 20 frames), ASF/AMC (HDM05 HDM_bd.asf and a squat clip cut
to 10 frames) and FBX (the authors' Walk_01) files are mutated: truncated, bytes
flipped, numbers swapped for huge, tiny, NaN, infinite, negative or out-of-range values
(text formats: any number or one of the header's; FBX: a double or an integer
or an FBX number property or array element overwritten in place), lines (FBX: byte
ranges) dropped or duplicated, one to three
mutations per file. Every outcome must be a valid :class:`~fpdtw.motion.Motion` (shapes,
finite values, unit quaternions, frame rate and count within :mod:`fpdtw.limits`,
finite forward kinematics) or a :class:`~fpdtw.errors.MotionFormatError` naming the
file, within :data:`TIME_BOUND` seconds. The same holds for ``fpdtw align`` run as a
subprocess on a few mutants: a map, or exit 1 with one ``fpdtw: error:`` line naming
a file.

Budget: the ``fpdtw`` hypothesis profile (``make test``: derandomized, 40 examples per
reader test, fewer for FBX and the command line) or the ``fuzz`` profile (``make fuzz``:
15 times as many, from a fixed ``--hypothesis-seed``); see ``tests/conftest.py``.
"""

from __future__ import annotations

import contextlib
import re
import signal
import struct
import tempfile
import time
from pathlib import Path

import numpy as np
import pytest
from hypothesis import event, given, settings
from hypothesis import strategies as st
from test_cli import CMU, SQUAT1, cli

from fpdtw import limits
from fpdtw.app.export import MAP_COLUMNS, read_map_csv
from fpdtw.errors import MotionFormatError
from fpdtw.io import load_motion
from fpdtw.io.asfamc import read_amc
from fpdtw.motion.motion import Motion

#: Seconds one read may take (the seeds read in 0.01-0.2 s).
TIME_BOUND = 20.0
#: Seconds one ``fpdtw align`` may take (start-up about 2 s).
CLI_TIME_BOUND = 120.0
ASF = "hdm05/HDM05_cut_amc/HDM_bd.asf"
WALK1 = "mocap_single_person_actions/MoCapData/Walk_01.fbx"
WALK2 = "mocap_single_person_actions/MoCapData/Walk_02.fbx"

_BASE = settings.default.max_examples  # 40 in make test, 600 in make fuzz
#: Examples per test: the reader tests the profile's, FBX (0.2 s a read) half as many, the
#: command line (a subprocess, 2-3 s) an eighth.
BUDGET = dict(bvh=_BASE, amc=_BASE, asf=_BASE, fbx=max(5, _BASE // 2), cli=max(4, _BASE // 8))

#: Values swapped in for a number of a text file.
TEXT_VALUES = ["1e300", "-1e300", "1e-300", "1e-310", "1e308", "-1e308", "nan", "NaN", "inf",
               "-inf", "-1", "0", "-0", "2", "0.5", "99999999999999999999", "4294967296",
               "-2147483649", "1e6", "-7"]  # fmt: skip
#: Values written over the bytes of an FBX file: (struct format, value).
BINARY_VALUES = [("<d", 1e300), ("<d", -1e300), ("<d", float("nan")), ("<d", float("inf")),
                 ("<d", -1.0), ("<d", 0.0), ("<d", 1e-300), ("<i", -1), ("<i", 2**31 - 1),
                 ("<q", -1), ("<q", 2**62), ("<I", 0), ("<f", float("nan"))]  # fmt: skip
_NUMBER = re.compile(rb"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")


# ------------------------------------------------------------------------------ mutations
_pos = st.integers(0, 2**31)
TEXT_OPS = st.one_of(
    st.tuples(st.just("truncate"), st.floats(0.0, 1.0)),
    st.tuples(st.just("flip"), _pos, st.integers(1, 255)),
    st.tuples(st.just("number"), _pos, st.sampled_from(TEXT_VALUES)),
    st.tuples(st.just("header_number"), st.integers(0, 199), st.sampled_from(TEXT_VALUES)),
    st.tuples(st.just("drop_line"), _pos),
    st.tuples(st.just("dup_line"), _pos),
)
#: Values written over one number of an FBX file, by its FBX type code (``I``/``i`` int32,
#: ``L``/``l`` int64 (times: 46186158000 per second), ``F``/``f`` float32, ``D``/``d`` float64).
FBX_VALUES = {
    "I": [-1, 0, 2**31 - 1, -(2**31), 1_000_000],
    "L": [-1, 0, 2**62, -(2**62), 46_186_158_000 * 3600, 46_186_158_000 * 10**7, 1],
    "F": [float("nan"), float("inf"), -1.0, 0.0, 3e38, 1e-38],
    "D": [float("nan"), float("inf"), -float("inf"), -1.0, 0.0, 1e300, -1e300, 1e-300, 1e6],
}
_FBX_FORMAT = {"I": "<i", "L": "<q", "F": "<f", "D": "<d"}
BINARY_OPS = st.one_of(
    st.tuples(st.just("truncate"), st.floats(0.0, 1.0)),
    st.tuples(st.just("flip"), _pos, st.integers(1, 255)),
    st.tuples(st.just("value"), _pos, st.sampled_from(BINARY_VALUES)),
    st.tuples(st.just("fbx_number"), _pos, _pos),
    st.tuples(st.just("fbx_number"), _pos, _pos),  # twice as likely: it gets past ufbx
    st.tuples(st.just("drop_bytes"), _pos, st.integers(1, 4096)),
    st.tuples(st.just("dup_bytes"), _pos, st.integers(1, 4096)),
)


def mutations(binary: bool):
    """One to three mutations (tuples, see :func:`mutate`)."""
    return st.lists(BINARY_OPS if binary else TEXT_OPS, min_size=1, max_size=3)


def fbx_numbers(data: bytes) -> list[tuple[int, str]]:
    """Offset and type (``I L F D``) of every number of a binary FBX file stored as is:
    scalar properties and the elements of uncompressed arrays (compressed arrays, whose
    bytes ufbx checks, are left out). Empty if the file is not a well-formed binary FBX.
    """
    out: list[tuple[int, str]] = []
    try:
        wide = struct.unpack_from("<I", data, 23)[0] >= 7500
        head = struct.Struct("<QQQ" if wide else "<III")
        scalar = {"Y": 2, "C": 1, "I": 4, "F": 4, "D": 8, "L": 8}
        todo = [(27, len(data))]
        while todo:
            pos, end = todo.pop()
            while pos < end:
                stop, n_props, props_len = head.unpack_from(data, pos)
                pos += head.size
                if stop == 0 or stop > end:
                    break
                pos += 1 + data[pos]  # the name
                p = pos
                for _ in range(n_props):
                    t = chr(data[p])
                    p += 1
                    if t in scalar:
                        if t in "IFDL":
                            out.append((p, t))
                        p += scalar[t]
                    elif t in "fdlib":
                        count, encoding, size = struct.unpack_from("<III", data, p)
                        p += 12
                        if encoding == 0 and t != "b":
                            width = size // max(count, 1)
                            out += [(p + k * width, t.upper()) for k in range(count)]
                        p += size
                    else:  # S, R: length and bytes
                        p += 4 + struct.unpack_from("<I", data, p)[0]
                if pos + props_len < stop:
                    todo.append((pos + props_len, stop))
                pos = stop
    except (struct.error, IndexError):
        return []
    return out


def mutate(data: bytes, ops) -> bytes:
    """Apply mutations in order; positions are taken modulo the current length."""
    for op in ops:
        kind, args = op[0], op[1:]
        n = len(data)
        if kind == "truncate":
            data = data[: int(args[0] * n)]
        elif n == 0:
            continue
        elif kind == "flip":
            i = args[0] % n
            data = data[:i] + bytes([data[i] ^ args[1]]) + data[i + 1 :]
        elif kind in ("number", "header_number"):
            spans = [m.span() for m in _NUMBER.finditer(data)]
            if spans:
                a, b = spans[args[0] % (len(spans) if kind == "number" else min(200, len(spans)))]
                data = data[:a] + args[1].encode() + data[b:]
        elif kind in ("drop_line", "dup_line"):
            lines = data.splitlines(keepends=True)
            i = args[0] % len(lines)
            lines[i : i + 1] = [] if kind == "drop_line" else [lines[i], lines[i]]
            data = b"".join(lines)
        elif kind == "value":
            fmt, value = args[1]
            raw = struct.pack(fmt, value)
            i = args[0] % max(1, n - len(raw))
            data = data[:i] + raw + data[i + len(raw) :]
        elif kind == "fbx_number":
            slots = fbx_numbers(data)
            if slots:
                at, t = slots[args[0] % len(slots)]
                values = FBX_VALUES[t]
                raw = struct.pack(_FBX_FORMAT[t], values[args[1] % len(values)])
                data = data[:at] + raw + data[at + len(raw) :]
        elif kind in ("drop_bytes", "dup_bytes"):
            i = args[0] % n
            chunk = data[i : i + args[1]]
            middle = b"" if kind == "drop_bytes" else chunk + chunk
            data = data[:i] + middle + data[i + len(chunk) :]
    return data


# ---------------------------------------------------------------------------------- seeds
def _cut_bvh(data: bytes, frames: int) -> bytes:
    lines = data.splitlines()
    at = next(i for i, s in enumerate(lines) if s.startswith(b"Frames:"))
    lines[at] = b"Frames: %d" % frames
    return b"\n".join(lines[: at + 2 + frames]) + b"\n"


def _cut_amc(data: bytes, frames: int) -> bytes:
    lines = data.splitlines(keepends=True)
    starts = [i for i, s in enumerate(lines) if s.strip().isdigit()]
    return b"".join(lines[: starts[frames]])


class Seeds(dict):
    """name -> (file name, bytes); a short repr, for hypothesis's failure reports."""

    def __repr__(self):
        return f"<seeds: {', '.join(f'{k}={v[0]} ({len(v[1])} bytes)' for k, v in self.items())}>"


@pytest.fixture(scope="session")
def seeds(data_path):
    """The real files the mutants start from: name -> (file name, bytes)."""
    return Seeds(
        {
            "bvh": ("18_01.bvh", _cut_bvh(data_path(CMU).read_bytes(), 20)),
            "amc": (Path(SQUAT1).name, _cut_amc(data_path(SQUAT1).read_bytes(), 10)),
            "asf": ("HDM_bd.asf", data_path(ASF).read_bytes()),
            "fbx": ("Walk_01.fbx", data_path(WALK1).read_bytes()),
        }
    )


def test_seeds_are_valid_motions(seeds, tmp_path):
    """The unmutated seeds read (so that a mutant's failure is the mutation's)."""
    for fmt in ("bvh", "amc", "fbx"):
        m = read_case(seeds, fmt, [], tmp_path)[2]()
        check_motion(m)
        assert m.n_frames == {"bvh": 20, "amc": 10, "fbx": 649}[fmt]
    assert mutate(b"a 1.5 b\nc 2\n", [("number", 1, "nan")]) == b"a 1.5 b\nc nan\n"
    assert mutate(b"0123456789", [("drop_bytes", 12, 3)]) == b"0156789"


def read_case(seeds, fmt, ops, folder: Path):
    """Write the mutant (and the real file it is read with); return (mutant, partner, read)."""
    name, data = seeds[fmt]
    mutant = folder / name
    mutant.write_bytes(mutate(data, ops))
    if fmt == "amc":
        partner = folder / seeds["asf"][0]
        partner.write_bytes(seeds["asf"][1])
        return mutant, partner, lambda: read_amc(mutant, partner)
    if fmt == "asf":
        partner = folder / seeds["amc"][0]
        partner.write_bytes(seeds["amc"][1])
        return mutant, partner, lambda: read_amc(partner, mutant)
    return mutant, None, lambda: load_motion(mutant)


# ------------------------------------------------------------------------------- outcomes
class _TooSlow(Exception):
    pass


@contextlib.contextmanager
def time_limit(seconds: float):
    """Raise _TooSlow in this (main) thread after ``seconds`` (a hang fails the test)."""

    def handler(signum, frame):
        raise _TooSlow(f"no result after {seconds} s")

    old = signal.signal(signal.SIGALRM, handler)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)


def check_motion(m) -> None:
    """A valid Motion: shapes, finite values, unit quaternions, sizes within the limits."""
    assert isinstance(m, Motion)
    F, J = m.n_frames, m.skeleton.n_joints
    lo, hi = limits.fps_range()
    assert 1 <= F <= limits.get("max_frames") and J >= 1
    assert lo <= m.fps <= hi
    assert m.euler.shape == (F, J, 3) and m.quats.shape == (F, J, 4)
    assert m.root_translation.shape == (F, 3)
    for a in (m.euler, m.quats, m.root_translation, m.skeleton.offsets):
        assert np.isfinite(a).all()
    np.testing.assert_allclose(np.linalg.norm(m.quats, axis=-1), 1.0, atol=1e-9)
    pos, _ = m.forward_kinematics()
    assert np.isfinite(pos).all()


def _gist(reason: str) -> str:
    """The kind of an error message (its words without quoted parts and numbers)."""
    words = re.sub(r"'[^']*'|\"[^\"]*\"|\([^)]*\)|[-+.\w]*\d[-+.\w]*", "", reason).split()
    return " ".join(words[:6])


def check_outcome(read, names) -> str:
    """``read()`` gives a valid Motion or a MotionFormatError naming one of ``names``,
    within TIME_BOUND; returns ``"valid Motion"`` or the kind of error (statistics)."""
    t0 = time.perf_counter()
    try:
        with time_limit(TIME_BOUND):
            m = read()
    except MotionFormatError as e:
        assert any(str(n) in str(e) for n in names if n), f"error names no file: {e}"
        return f"MotionFormatError ({_gist(e.reason)})"
    finally:
        assert time.perf_counter() - t0 < TIME_BOUND
    check_motion(m)
    return "valid Motion"


def _reader_test(seeds, fmt, ops):
    with tempfile.TemporaryDirectory() as d:
        mutant, partner, read = read_case(seeds, fmt, ops, Path(d))
        event(f"{fmt}: {check_outcome(read, (mutant, partner))}")


@pytest.mark.parametrize("fmt", ["bvh", "amc", "asf", "fbx"])
def test_fuzz_reader(seeds, fmt):
    """Mutated files of one format: a Motion or a MotionFormatError naming the file."""

    @settings(max_examples=BUDGET[fmt])
    @given(ops=mutations(binary=fmt == "fbx"))
    def check(ops):
        _reader_test(seeds, fmt, ops)

    check()


# --------------------------------------------------------------------------- fpdtw align
@st.composite
def cli_cases(draw):
    fmt = draw(st.sampled_from(["bvh", "amc", "fbx"]))
    ops = draw(mutations(binary=fmt == "fbx"))
    return fmt, ops, draw(st.booleans()), draw(st.sampled_from(["c", "oltw", "dtw", "opw"]))


@settings(max_examples=BUDGET["cli"])
@given(case=cli_cases())
def test_fuzz_fpdtw_align(seeds, data_path, case):
    """A mutant as INPUT or TARGET of ``fpdtw align`` against the real file of the same
    format: a map, or exit 1 with one error line naming a file; never a traceback."""
    fmt, ops, as_input, method = case
    with tempfile.TemporaryDirectory() as d:
        d = Path(d)
        mutant, _, _ = read_case(seeds, fmt, ops, d)
        other = d / "other"
        other.mkdir()
        real = other / seeds[fmt][0]
        real.write_bytes(seeds[fmt][1] if fmt != "fbx" else data_path(WALK2).read_bytes())
        if fmt == "amc":
            (other / seeds["asf"][0]).write_bytes(seeds["asf"][1])
        pair = (mutant, real) if as_input else (real, mutant)
        out = d / "map.csv"
        t0 = time.perf_counter()
        r = cli("align", *pair, "-m", method, "-o", out)
        assert time.perf_counter() - t0 < CLI_TIME_BOUND
        assert "Traceback" not in r.stderr and "internal error" not in r.stderr, r.stderr
        event(f"{fmt} as {'input' if as_input else 'target'}, {method}: exit {r.returncode}")
        if r.returncode == 0:
            header = out.read_text().splitlines()[0].split(",")
            assert tuple(header) == MAP_COLUMNS
            M = read_map_csv(out)["input_frame"]
            assert M.size >= limits.MIN_FRAMES and M.min() >= 0
            return
        assert r.returncode == 1, r.stderr
        line = r.stderr.strip().splitlines()[-1]
        assert line.startswith("fpdtw: error: "), r.stderr
        assert str(mutant) in line or str(real) in line, line
