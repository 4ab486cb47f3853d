"""Motion file readers (FBX via ufbx, ASF/AMC, BVH), all returning a :class:`~fpdtw.motion.Motion`.

:func:`load_motion` picks the reader from the file extension.
"""

from __future__ import annotations

from pathlib import Path

from fpdtw.errors import MotionFormatError
from fpdtw.io._text import check_input_file
from fpdtw.io.asfamc import read_amc
from fpdtw.io.bvh import read_bvh
from fpdtw.io.fbx import read_fbx

READERS = {".fbx": "fbx", ".amc": "asfamc", ".bvh": "bvh"}


def load_motion(path, **kwargs):
    """Read a motion file of any supported format.

    Parameters
    ----------
    path : str or os.PathLike
        ``.fbx``, ``.amc`` (skeleton ``.asf`` found next to it, or pass
        ``skeleton=``) or ``.bvh``.
    **kwargs
        Passed to the format's reader (e.g. ``fps=``, ``name=``).

    Returns
    -------
    motion : Motion

    Raises
    ------
    MotionFormatError
        Unknown extension, no such file, a directory or other non-regular file, a file
        larger than :data:`fpdtw.limits.MAX_FILE_BYTES`, or a file the reader rejects
        (including a frame rate or frame count outside :mod:`fpdtw.limits`).
    """
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
