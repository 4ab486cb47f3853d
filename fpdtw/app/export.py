"""Use an alignment: retime the input motion by a map, write it as BVH, write the map as CSV.

A map ``M`` (one input frame per target frame, see :mod:`fpdtw.dtw`) says which frame of
the recorded input to show at each frame of the target. :func:`retime_by_map` builds that
motion: it has the target's frame count and frame rate and its frame ``q`` IS input frame
``M[q]`` (rotations, Euler angles and root translation copied, not interpolated), so it
plays in step with the target. :func:`export_bvh` writes it as a BVH file that Blender
(or any BVH reader) opens; :func:`write_map_csv` writes the map with frame times.
"""

from __future__ import annotations

import contextlib
import csv
import io
import os
from pathlib import Path

import numpy as np

from fpdtw.errors import AlignmentError
from fpdtw.motion.motion import Motion

#: Columns of the map CSV written by :func:`write_map_csv`, in order.
MAP_COLUMNS = ("target_frame", "target_time_s", "input_frame", "input_time_s", "step_us")


def _check_map(M, n_input: int) -> np.ndarray:
    M = np.asarray(M)
    if M.ndim != 1 or M.size == 0:
        raise AlignmentError(f"a map must be a non-empty 1-D array, got shape {M.shape}")
    if not np.issubdtype(M.dtype, np.integer):
        if not np.all(np.isfinite(M)) or np.any(M != np.round(M)):
            raise AlignmentError("a map must hold whole frame numbers")
        M = M.astype(np.int64)
    if M.min() < 0 or M.max() > n_input - 1:
        raise AlignmentError(
            f"map values must lie in 0..{n_input - 1} (input frames), got {M.min()}..{M.max()}"
        )
    return M.astype(np.int64)


def retime_by_map(input_motion: Motion, M, target_fps: float, name: str | None = None) -> Motion:
    """The input motion played in step with the target: frame ``q`` = input frame ``M[q]``.

    Parameters
    ----------
    input_motion : Motion
        The recorded motion that was aligned (at the frame rate the map refers to).
    M : array_like of int, shape (n + 1,)
        Input frame of each target frame, values in ``0 .. input_motion.n_frames - 1``.
    target_fps : float
        Frame rate of the target; the result plays at this rate.
    name : str, optional
        Name of the result (default ``"<input name>_aligned"``).

    Returns
    -------
    motion : Motion
        ``n + 1`` frames at ``target_fps`` on the input's skeleton; Euler angles,
        quaternions and root translation of each frame exactly those of input frame
        ``M[q]``.

    Raises
    ------
    AlignmentError
        A map that is not 1-D, holds non-integers or frames outside the input.

    Paper: FP-DTW Section 1 (the purpose: time a recorded character to a live actor).
    """
    M = _check_map(M, input_motion.n_frames)
    fps = float(target_fps)
    if not np.isfinite(fps) or fps <= 0:
        raise AlignmentError(f"target frame rate must be positive, got {target_fps}")
    return input_motion.replace(
        name=name or f"{input_motion.name}_aligned",
        fps=fps,
        euler=input_motion.euler[M].copy(),
        quats=input_motion.quats[M].copy(),
        root_translation=input_motion.root_translation[M].copy(),
    )


def export_bvh(input_motion: Motion, M, target_fps: float, path, *, precision: int = 6) -> Path:
    """Write the input motion retimed by a map (:func:`retime_by_map`) as a BVH file.

    The BVH has the target's frame count and frame time. Skeletons with fixed pre/post
    rotations (ASF, FBX) have them baked into the written rotations by
    :func:`fpdtw.io.bvh.write_bvh`, so joint positions (forward kinematics) are those of
    the input; the root OFFSET is the skeleton's (BVH readers such as Blender's and
    ``bvhio`` take the root position channels as absolute and ignore it: for a skeleton
    with a non-zero root offset they show the motion shifted by that offset).

    Parameters
    ----------
    input_motion : Motion
    M : array_like of int, shape (n + 1,)
    target_fps : float
    path : str or os.PathLike
        Output ``.bvh`` file (overwritten).
    precision : int
        Decimals of the written values.

    Returns
    -------
    path : Path

    Paper: FP-DTW Section 1 (the aligned character); BVH as in Fig. 8's poses.
    """
    from fpdtw.io.bvh import write_bvh

    return write_bvh(retime_by_map(input_motion, M, target_fps), path, precision=precision)


def write_map_csv(path, M, target_fps: float, input_fps: float, step_seconds=None) -> Path:
    """Write a map as CSV: one row per target frame, with frame times.

    Columns (:data:`MAP_COLUMNS`): ``target_frame`` (q), ``target_time_s`` (q / target
    fps), ``input_frame`` (M[q]), ``input_time_s`` (M[q] / input fps), ``step_us``
    (microseconds the online aligner took for that frame; empty for offline methods).
    The file is written to a temporary name and renamed, so it is never half-written.

    Parameters
    ----------
    path : str or os.PathLike
    M : array_like of int, shape (n + 1,)
    target_fps, input_fps : float
        Frame rates the frame numbers refer to.
    step_seconds : array_like of float, shape (n + 1,), optional
        Per-frame processing time of an online aligner.

    Returns
    -------
    path : Path

    Raises
    ------
    OSError
        The file cannot be written; ``filename`` is ``path`` (never the temporary name).

    Paper: FP-DTW Section 3 (the map M, one input frame per target frame).
    """
    path = Path(path)
    M = np.asarray(M, dtype=np.int64).reshape(-1)
    if step_seconds is not None:
        step_seconds = np.asarray(step_seconds, dtype=float).reshape(-1)
        if step_seconds.shape != M.shape:
            raise AlignmentError(
                f"{step_seconds.size} step times for a map of {M.size} target frames"
            )
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(MAP_COLUMNS)
    for q, m in enumerate(M):
        step = "" if step_seconds is None else f"{step_seconds[q] * 1e6:.3f}"
        w.writerow([q, f"{q / target_fps:.6f}", int(m), f"{m / input_fps:.6f}", step])
    tmp = path.with_name(path.name + ".part")
    try:
        tmp.write_text(buf.getvalue())
        os.replace(tmp, path)
    except OSError as exc:  # name the file asked for, not the temporary one
        with contextlib.suppress(OSError):
            tmp.unlink()
        raise OSError(exc.errno, exc.strerror, str(path)) from exc
    return path


def read_map_csv(path) -> dict:
    """Read a map CSV written by :func:`write_map_csv`.

    Returns
    -------
    columns : dict of str to ndarray
        ``target_frame``, ``input_frame`` (int64), ``target_time_s``, ``input_time_s``
        (float64), ``step_us`` (float64, NaN where empty).

    Paper: FP-DTW Section 3 (the map M).
    """
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    out = {}
    for col in MAP_COLUMNS:
        vals = [r[col] for r in rows]
        if col.endswith("_frame"):
            out[col] = np.array(vals, dtype=np.int64)
        else:
            out[col] = np.array([float(v) if v != "" else np.nan for v in vals])
    return out


__all__ = ["MAP_COLUMNS", "export_bvh", "read_map_csv", "retime_by_map", "write_map_csv"]
