"""Plausible ranges and size limits, checked before anything of that size is allocated.

docs/limits.md tables the limits, what checks each and the errors past them; each limit's
comment says why its number. A limit is overridden by its environment variable (``FPDTW_``
and its name, read at every check) or :func:`override`.
"""

from __future__ import annotations

import contextlib
import math
import os
from collections.abc import Iterator

from fpdtw.errors import LimitError, MotionFormatError

#: Lowest plausible frame rate (Hz): keyframed animation is exported at 1 Hz and up.
MIN_FPS = 1.0
#: Highest plausible frame rate (Hz): optical capture runs at 60-2000 Hz, inertial at 60-1000.
MAX_FPS = 10_000.0
#: Most frames of a motion (read or resampled): 2.3 h at 120 Hz, ~2 GB of features.
MAX_FRAMES = 1_000_000
#: Fewest frames a motion to align may have (fixed): one frame has no motion to align.
MIN_FRAMES = 2
#: Largest motion file read (bytes): an hour of 120 Hz BVH of 31 joints is ~0.4 GiB.
MAX_FILE_BYTES = 2**30
#: Largest angle (degrees), offset or translation (file units): human motion stays below
#: 1e7, and every sum, product and forecast stays far from the float64 overflow.
MAX_ABS_VALUE = 1e12
#: Largest set of matrices an aligner allocates at once (bytes): offline DTW of two takes
#: of ~11,500 frames (16 bytes a cell); the online methods need the window's only.
MAX_MATRIX_BYTES = 2 * 2**30
#: Target frames an online aligner keeps before it keeps only the latest (a buffer size).
HISTORY_FRAMES = 4096
#: Most channels of a BVH hierarchy: a body with hands and face has ~1,800.
MAX_CHANNELS = 10_000
#: Longest line a client of ``fpdtw serve`` may send (bytes): 10,000 channels is ~120 KB.
MAX_LINE_BYTES = 256 * 2**10
#: Longest BVH header a client may send (bytes): about 150 bytes a joint.
MAX_HEADER_BYTES = 2**20
#: Longest gap of a stream that is filled (s): 1,200 steps at 120 Hz; longer is a new take.
MAX_GAP_S = 10.0

#: keyword of :func:`override` -> (environment variable, default, type)
_NAMES = "MIN_FPS MAX_FPS MAX_FRAMES MAX_FILE_BYTES MAX_ABS_VALUE MAX_MATRIX_BYTES HISTORY_FRAMES"
_NAMES += " MAX_CHANNELS MAX_LINE_BYTES MAX_HEADER_BYTES MAX_GAP_S"
_LIMITS = {n.lower(): (f"FPDTW_{n}", globals()[n], type(globals()[n])) for n in _NAMES.split()}
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
    """Current value of a limit (``"max_frames"``: a key of ``_LIMITS``): :func:`override`,
    else its environment variable (LimitError if not a positive number), else the default."""
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
    """A frame rate read from file ``path`` (at ``line``; ``source``: how the file gives it,
    e.g. ``"Frame Time 1e-300 s"``); MotionFormatError naming the file if implausible."""
    why = fps_problem(fps)
    if why is not None:
        raise MotionFormatError(path, f"{source}: {why}" if source else why, line=line)
    return float(fps)


def _beyond(name: str, value, show=str) -> str | None:
    """``"more than the limit of <limit> (<env var>)"`` past limit ``name`` (``show``) or None."""
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
    """A frame count about to be allocated (``what``: how it came about, e.g.
    ``"resampling to 1e+06 Hz"``): LimitError naming ``paths`` if it is above
    :data:`MAX_FRAMES` or below :data:`MIN_FRAMES`."""
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


def check_file_size(path, size: int) -> None:
    """A file to read whole: MotionFormatError naming it past :data:`MAX_FILE_BYTES`."""
    why = _beyond("max_file_bytes", size, format_bytes)
    if why:
        raise MotionFormatError(
            path, f"file is {format_bytes(size)}, {why}; split or crop the take"
        )


def dtw_bytes(rows: int, cols: int) -> int:
    """Bytes offline DTW allocates: cost and accumulated cost, float64 ``rows x cols``."""
    return 16 * int(rows) * int(cols)


def window_bytes(w: int) -> int:
    """Bytes of Methods B and C's window matrices, at most two float64 ``(w + 1) x (w + 1)``."""
    return 16 * (int(w) + 1) ** 2


def band_bytes(c: int) -> int:
    """Bytes of OLTW's ``c x c`` float64 band."""
    return 8 * int(c) ** 2


def check_bytes(nbytes: int, paths, what: str, hint: str = HINT_LONG) -> None:
    """``nbytes`` about to be allocated for ``what`` (with its shape): LimitError naming
    ``paths`` and the way out (``hint``) past :data:`MAX_MATRIX_BYTES`."""
    why = _beyond("max_matrix_bytes", nbytes, format_bytes)
    if why:
        raise LimitError(paths, f"{what} ({format_bytes(nbytes)}), {why}; {hint}")
