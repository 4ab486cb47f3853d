"""Plausible ranges and size limits, checked wherever a size enters fpdtw.

A motion file or a command-line option decides how much memory and time fpdtw will
use: the frame rate (a BVH ``Frame Time: 1e-300`` is a 1e300 Hz motion), the frame count
after resampling (``--fps 1e6`` turns 5 s into 5 million frames), the matrices an
aligner allocates (offline DTW of two one-hour takes needs ``432001 x 432001`` cells).
Each such number is checked against the limits below *before* anything of that size is
allocated; past a limit, the error names the file(s), the number, the limit and the way
out. File content that is implausible (a frame rate outside the range) is a
:class:`~fpdtw.errors.MotionFormatError` of that file; a request that is too large for
files that are fine (DTW of two long takes) is a :class:`~fpdtw.errors.LimitError`.

=====================  ===============  ============================  =======================
limit                  default          environment variable          checked by
=====================  ===============  ============================  =======================
:data:`MIN_FPS`        1 Hz             ``FPDTW_MIN_FPS``             readers, ``--fps``,
:data:`MAX_FPS`        10000 Hz         ``FPDTW_MAX_FPS``             ``Motion.resample``
:data:`MAX_FRAMES`     1,000,000        ``FPDTW_MAX_FRAMES``          readers, resampling
:data:`MIN_FRAMES`     2                (fixed)                       resampling, ``fpdtw``
:data:`MAX_FILE_BYTES` 1 GiB            ``FPDTW_MAX_FILE_BYTES``      readers
:data:`MAX_ABS_VALUE`  1e12             ``FPDTW_MAX_ABS_VALUE``       every ``Motion``
:data:`MAX_MATRIX_BYTES` 2 GiB          ``FPDTW_MAX_MATRIX_BYTES``    DTW, OE-DTW, OLTW band,
                                                                      windows of A, B, C
:data:`HISTORY_FRAMES` 4096             ``FPDTW_HISTORY_FRAMES``      online aligners (not a
                                                                      limit: a buffer size)
:data:`MAX_CHANNELS`   10,000           ``FPDTW_MAX_CHANNELS``        BVH header (file, stream)
:data:`MAX_LINE_BYTES` 256 KiB          ``FPDTW_MAX_LINE_BYTES``      ``fpdtw serve``: a line
:data:`MAX_HEADER_BYTES` 1 MiB          ``FPDTW_MAX_HEADER_BYTES``    ``fpdtw serve``: a header
:data:`MAX_GAP_S`      10 s             ``FPDTW_MAX_GAP_S``           ``fpdtw serve``: a gap
=====================  ===============  ============================  =======================

Why these numbers:

* Frame rates 1-10000 Hz: video and consumer capture run at 24-60 Hz, optical motion
  capture at 60-2000 Hz (more at reduced resolution), inertial suits at 60-1000 Hz;
  keyframed animation is exported at 1 Hz and up. Every file here is 30 or 120 Hz.
* 1,000,000 frames per motion: 2.3 hours at 120 Hz (an hour, 432,000 frames, must
  work). A motion of the authors' 33-joint skeleton takes about 2 kB per frame (Euler
  angles, quaternions), so 2 GB at the limit, plus what resampling needs on the way.
* 2 frames at least: one frame has no motion to align; a motion that resampling would
  shrink to one frame is an error, never a one-row result.
* 1 GiB per motion file: an hour of 120 Hz BVH of a 31-joint skeleton is about 0.4 GiB.
* 1e12 for any angle (degrees), offset or translation (file units): human motion in any
  length unit stays below 1e7, angles unwrapped over hours below 1e9 degrees, and with
  1e12 every sum, product and forecast (a window of 80 frames ahead) stays far from the
  float64 overflow at 1e308 (a BVH OFFSET of 1e308 made forward kinematics infinite).
* 2 GiB per set of matrices: offline DTW keeps two float64 ``(m + 1) x (n + 1)``
  matrices (cost and accumulated cost, 16 bytes per cell), so two takes of up to
  about 11,500 frames each (96 s at 120 Hz); OE-DTW keeps every accumulated column (8
  bytes per cell); OLTW a ``c x c`` band; Methods B and C two ``(w + 1) x (w + 1)``
  windows at most (so ``w`` and ``c`` up to about 11,500 and 16,000 frames). Online
  methods need memory proportional to the window, not to ``n x m``: they are the way
  out for long takes.
* 10,000 BVH channels: a full body with hands and face is about 300 joints, at most six
  channels each (1,800); every channel costs memory per frame and time per streamed line.
* 256 KiB per streamed line, 1 MiB per streamed header: a motion line of 10,000 channels
  printed with 6 decimals is about 120 KB; a header is about 150 bytes per joint. A client of
  ``fpdtw serve`` that sends a longer line or header gets an error line and is closed,
  before the server holds more than that in memory.
* 10 s of gap between two streamed frames: the gap is filled with one target frame per
  input-rate tick (:mod:`fpdtw.motion.stream`), and the server does that work before it
  answers anyone else; 10 s at 120 Hz is 1,200 aligner steps (a few tens of milliseconds).
  A capture that loses the actor for longer is a new take, not a dropped frame. A stream
  also stops at :data:`MAX_FRAMES` frames.
* 4096 target frames of history: online aligners whose steps read only the last few
  target frames (Methods A, B, C, OLTW) keep every frame received until the history
  reaches this size, then only the latest (see :class:`fpdtw.online.base.OnlineAligner`).

Override a limit with its environment variable (read at every check, so it applies to
the command line and to a running session alike), or in Python with :func:`override`::

    with fpdtw.limits.override(max_matrix_bytes=8 * 2**30):
        result = dtw_pair(I, T)
"""

from __future__ import annotations

import contextlib
import math
import os
from collections.abc import Iterator

from fpdtw.errors import LimitError, MotionFormatError

#: Lowest plausible frame rate (Hz) of a motion file, ``--fps`` and resampling.
MIN_FPS = 1.0
#: Highest plausible frame rate (Hz) of a motion file, ``--fps`` and resampling.
MAX_FPS = 10_000.0
#: Most frames a motion may have (read from a file or after resampling).
MAX_FRAMES = 1_000_000
#: Fewest frames a motion to align may have (fixed).
MIN_FRAMES = 2
#: Largest motion file the readers read (bytes).
MAX_FILE_BYTES = 2**30
#: Largest magnitude of an angle (degrees), offset or translation (file units) in a motion.
MAX_ABS_VALUE = 1e12
#: Largest set of matrices an aligner may allocate at once (bytes).
MAX_MATRIX_BYTES = 2 * 2**30
#: Target frames an online aligner keeps before it keeps only the latest it needs.
HISTORY_FRAMES = 4096
#: Most channels a BVH hierarchy may declare (a file or a stream).
MAX_CHANNELS = 10_000
#: Longest line a client of ``fpdtw serve`` may send (bytes, newline included).
MAX_LINE_BYTES = 256 * 2**10
#: Longest BVH header (HIERARCHY through ``Frame Time:``) a client may send (bytes).
MAX_HEADER_BYTES = 2**20
#: Longest gap between two frames of a stream that is filled (seconds).
MAX_GAP_S = 10.0

#: keyword of :func:`override` -> (environment variable, default, type)
_LIMITS = {
    "min_fps": ("FPDTW_MIN_FPS", MIN_FPS, float),
    "max_fps": ("FPDTW_MAX_FPS", MAX_FPS, float),
    "max_frames": ("FPDTW_MAX_FRAMES", MAX_FRAMES, int),
    "max_file_bytes": ("FPDTW_MAX_FILE_BYTES", MAX_FILE_BYTES, int),
    "max_abs_value": ("FPDTW_MAX_ABS_VALUE", MAX_ABS_VALUE, float),
    "max_matrix_bytes": ("FPDTW_MAX_MATRIX_BYTES", MAX_MATRIX_BYTES, int),
    "history_frames": ("FPDTW_HISTORY_FRAMES", HISTORY_FRAMES, int),
    "max_channels": ("FPDTW_MAX_CHANNELS", MAX_CHANNELS, int),
    "max_line_bytes": ("FPDTW_MAX_LINE_BYTES", MAX_LINE_BYTES, int),
    "max_header_bytes": ("FPDTW_MAX_HEADER_BYTES", MAX_HEADER_BYTES, int),
    "max_gap_s": ("FPDTW_MAX_GAP_S", MAX_GAP_S, float),
}
_overrides: dict[str, float] = {}

#: How to get an alignment of long takes without n x m memory.
HINT_LONG = (
    "use an online method (e.g. -m c or -m oltw: memory proportional to the window, not "
    "to n x m), a lower frame rate (--fps, Motion.resample) or shorter takes (Motion.crop)"
)


def env_name(name: str) -> str:
    """Environment variable of a limit (``"max_frames"`` -> ``"FPDTW_MAX_FRAMES"``)."""
    return _LIMITS[name][0]


def get(name: str) -> float | int:
    """Current value of a limit: :func:`override`, else its environment variable, else
    the default.

    Parameters
    ----------
    name : str
        ``"min_fps"``, ``"max_fps"``, ``"max_frames"``, ``"max_file_bytes"``,
        ``"max_abs_value"``, ``"max_matrix_bytes"``, ``"history_frames"``,
        ``"max_channels"``, ``"max_line_bytes"``, ``"max_header_bytes"`` or ``"max_gap_s"``.

    Raises
    ------
    LimitError
        The environment variable holds no positive number.
    """
    env, default, kind = _LIMITS[name]
    if name in _overrides:
        return _overrides[name]
    text = os.environ.get(env, "").strip()
    if not text:
        return default
    try:
        value = kind(float(text)) if kind is int else float(text)
    except (ValueError, OverflowError):
        value = -1
    if not (value > 0 and math.isfinite(value)):
        raise LimitError(None, f"{env}={text!r} is not a positive number")
    return value


@contextlib.contextmanager
def override(**values) -> Iterator[None]:
    """Change limits inside a ``with`` block (keywords as in :func:`get`)."""
    for key, value in values.items():
        if key not in _LIMITS:
            raise TypeError(f"unknown limit {key!r}; known: {', '.join(_LIMITS)}")
        if not (value > 0 and math.isfinite(value)):
            raise ValueError(f"limit {key} must be a positive number, got {value!r}")
    saved = dict(_overrides)
    _overrides.update(values)
    try:
        yield
    finally:
        _overrides.clear()
        _overrides.update(saved)


def format_bytes(n: float) -> str:
    """``2147483648`` -> ``"2 GiB"``, ``3.5e12`` -> ``"3.2 TiB"``."""
    for unit, size in (("TiB", 2**40), ("GiB", 2**30), ("MiB", 2**20), ("KiB", 2**10)):
        if n >= size:
            return f"{n / size:.3g} {unit}"
    return f"{int(n)} bytes"


# -- frame rates -----------------------------------------------------------------------------


def fps_range() -> tuple[float, float]:
    """(lowest, highest) plausible frame rate in Hz."""
    return float(get("min_fps")), float(get("max_fps"))


def fps_problem(fps: float) -> str | None:
    """Why ``fps`` is not a plausible frame rate, or None when it is."""
    lo, hi = fps_range()
    try:
        fps = float(fps)
    except (TypeError, ValueError):
        return f"frame rate {fps!r} is not a number"
    ok = math.isfinite(fps) and lo * (1 - 1e-9) <= fps <= hi * (1 + 1e-9)
    if ok:
        return None
    return (
        f"frame rate {fps:g} Hz is outside the plausible range {lo:g}..{hi:g} Hz "
        f"({env_name('min_fps')}, {env_name('max_fps')})"
    )


def check_file_fps(fps: float, path, *, line: int | None = None, source: str = "") -> float:
    """A frame rate read from a file; MotionFormatError naming the file if implausible.

    Parameters
    ----------
    fps : float
    path : str or os.PathLike
        The file it was read from.
    line : int, optional
        Line of a text file that gave it.
    source : str
        How the file gives it (e.g. ``"Frame Time 1e-300 s"``), put in the message.
    """
    why = fps_problem(fps)
    if why is not None:
        raise MotionFormatError(path, f"{source}: {why}" if source else why, line=line)
    return float(fps)


# -- frame counts ----------------------------------------------------------------------------


def _beyond(name: str, value, show=str) -> str | None:
    """``"more than the limit of <limit> (<env var>)"`` when ``value`` exceeds the limit
    ``name``, else None (``show`` formats the limit)."""
    hi = get(name)
    if value <= hi:
        return None
    return f"more than the limit of {show(hi)} ({env_name(name)})"


def _frames(n) -> str:
    return f"{int(n)} frames"


def check_file_frames(n: int, path, *, line: int | None = None) -> int:
    """A frame count a file declares; MotionFormatError naming the file past the limit."""
    why = _beyond("max_frames", n, _frames)
    if why:
        raise MotionFormatError(path, f"{n} frames, {why}", line=line)
    return int(n)


def check_frames(n: int, paths, what: str) -> int:
    """A frame count about to be allocated (e.g. after resampling): LimitError if it is
    above :data:`MAX_FRAMES` or below :data:`MIN_FRAMES`.

    Parameters
    ----------
    n : int
        The frame count.
    paths : str or sequence of str
        File(s) or motion name(s) for the message.
    what : str
        How it came about, e.g. ``"resampling to 1e+06 Hz"``.
    """
    why = _beyond("max_frames", n, _frames)
    if why:
        raise LimitError(
            paths, f"{what} would give {n} frames, {why}; use a lower frame rate or shorter takes"
        )
    if n < MIN_FRAMES:
        raise LimitError(
            paths,
            f"{what} would leave {n} frame (at least {MIN_FRAMES} are needed); use a "
            "higher frame rate or a longer take",
        )
    return int(n)


def check_min_frames(n: int, path, role: str = "motion") -> None:
    """A motion to align has at least :data:`MIN_FRAMES` frames (LimitError otherwise)."""
    if n < MIN_FRAMES:
        raise LimitError(
            path,
            f"the {role} has {n} frame; aligning needs at least {MIN_FRAMES} frames per motion",
        )


def check_channels(n: int, path, *, line: int | None = None) -> int:
    """The channel count a BVH hierarchy declares; MotionFormatError naming the file (or
    stream) past :data:`MAX_CHANNELS`."""
    why = _beyond("max_channels", n, lambda v: f"{int(v)} channels")
    if why:
        raise MotionFormatError(path, f"the hierarchy declares {n} channels, {why}", line=line)
    return int(n)


# -- files -----------------------------------------------------------------------------------


def check_file_size(path, size: int) -> None:
    """A file to read whole: MotionFormatError naming it past :data:`MAX_FILE_BYTES`."""
    why = _beyond("max_file_bytes", size, format_bytes)
    if why:
        raise MotionFormatError(
            path, f"file is {format_bytes(size)}, {why}; split or crop the take"
        )


# -- matrices --------------------------------------------------------------------------------


def dtw_bytes(rows: int, cols: int) -> int:
    """Bytes offline DTW allocates: cost and accumulated cost, float64 ``rows x cols``."""
    return 16 * int(rows) * int(cols)


def window_bytes(w: int) -> int:
    """Bytes of the window matrices of Methods B and C, at most two float64
    ``(w + 1) x (w + 1)`` (Method A needs less)."""
    return 16 * (int(w) + 1) ** 2


def band_bytes(c: int) -> int:
    """Bytes of OLTW's ``c x c`` float64 band."""
    return 8 * int(c) ** 2


def check_bytes(nbytes: int, paths, what: str, hint: str = HINT_LONG) -> None:
    """Memory about to be allocated: LimitError past :data:`MAX_MATRIX_BYTES`.

    Parameters
    ----------
    nbytes : int
        Estimated bytes.
    paths : str or sequence of str or None
        File(s) or motion name(s) the size comes from.
    what : str
        What would be allocated, with its shape, e.g. ``"offline DTW needs two 432001 x
        432001 float64 matrices"``.
    hint : str
        The way out.
    """
    why = _beyond("max_matrix_bytes", nbytes, format_bytes)
    if why:
        raise LimitError(paths, f"{what} ({format_bytes(nbytes)}), {why}; {hint}")


__all__ = [
    "HINT_LONG",
    "HISTORY_FRAMES",
    "MAX_ABS_VALUE",
    "MAX_CHANNELS",
    "MAX_FILE_BYTES",
    "MAX_FPS",
    "MAX_FRAMES",
    "MAX_GAP_S",
    "MAX_HEADER_BYTES",
    "MAX_LINE_BYTES",
    "MAX_MATRIX_BYTES",
    "MIN_FPS",
    "MIN_FRAMES",
    "band_bytes",
    "check_bytes",
    "check_channels",
    "check_file_fps",
    "check_file_frames",
    "check_file_size",
    "check_frames",
    "check_min_frames",
    "dtw_bytes",
    "env_name",
    "format_bytes",
    "fps_problem",
    "fps_range",
    "get",
    "override",
    "window_bytes",
]
