"""Test-only helpers for motion files: edit one line of a text file, and read joint
positions with the independent ``bvhio`` package."""

from __future__ import annotations

import bvhio
import numpy as np


def with_line(text: str, line_no: int, new) -> str:
    """``text`` with line ``line_no`` (1-based) replaced.

    ``new`` is a string (the new line), a list of strings (lines put in its place) or None
    (the line deleted). The result ends with a newline.
    """
    lines = text.splitlines()
    if new is None:
        del lines[line_no - 1]
    elif isinstance(new, list):
        lines[line_no - 1 : line_no] = new
    else:
        lines[line_no - 1] = new
    return "\n".join(lines) + "\n"


def bvhio_positions(path, frames):
    """World joint positions per frame of a BVH file, read by ``bvhio`` (not by fpdtw).

    Returns
    -------
    names : list of str
        Joint names in bvhio's layout order.
    X : ndarray of float, shape (len(frames), joints, 3)
    """
    root = bvhio.readAsHierarchy(str(path))
    names = [j.Name for j, _, _ in root.layout()]
    out = []
    for f in frames:
        root.loadPose(f)
        out.append([list(j.PositionWorld) for j, _, _ in root.layout()])
    return names, np.array(out, dtype=float)
