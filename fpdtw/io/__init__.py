"""Motion file readers (FBX via ufbx, ASF/AMC, BVH), each giving a :class:`~fpdtw.motion.Motion`."""

from __future__ import annotations

from pathlib import Path

from fpdtw.errors import MotionFormatError
from fpdtw.io._text import check_input_file
from fpdtw.io.asfamc import read_amc
from fpdtw.io.bvh import read_bvh
from fpdtw.io.fbx import read_fbx

READERS = {".fbx": "fbx", ".amc": "asfamc", ".bvh": "bvh"}


def load_motion(path, **kwargs):
    """Read a ``.fbx``, ``.amc`` or ``.bvh`` motion file with the reader of its extension.

    ``kwargs`` go to the reader (``fps=``, ``name=``; ``skeleton=`` for AMC, else the
    ``.asf`` next to it). MotionFormatError for an unknown extension, a file
    :func:`check_input_file` refuses, or one the reader rejects."""
    p = Path(path)
    kind = READERS.get(p.suffix.lower())
    if kind is None:
        raise MotionFormatError(
            p, f"unknown motion file type {p.suffix!r}; expected one of {sorted(READERS)}"
        )
    check_input_file(p)
    if kind == "fbx":
        return read_fbx(p, **kwargs)
    if kind == "asfamc":
        skeleton = kwargs.pop("skeleton", None)
        return read_amc(p, skeleton, **kwargs)
    return read_bvh(p, **kwargs)


__all__ = ["load_motion"]
