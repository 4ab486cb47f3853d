"""Exception types, one per family of failure: every error bad input can provoke is one of
these, its message naming the file (and line or frame, where there is one) and what is wrong.
"""

from __future__ import annotations

import os


class FpdtwError(Exception):
    """Base class of every error raised on purpose by fpdtw."""


class MotionFormatError(FpdtwError, ValueError):
    """A motion or skeleton file (FBX, ASF/AMC, BVH) is unreadable or inconsistent.

    Parameters
    ----------
    path : str or os.PathLike or None
        The file that is wrong.
    message : str
        What is wrong.
    line : int, optional
        1-based line number in a text file.
    frame : int, optional
        0-based frame index (or the file's own frame number where it has one).
    """

    def __init__(self, path, message, *, line=None, frame=None):
        self.path = None if path is None else str(path)
        self.line = line
        self.frame = frame
        self.reason = message
        where = []
        if line is not None:
            where.append(f"line {line}")
        if frame is not None:
            where.append(f"frame {frame}")
        loc = f" ({', '.join(where)})" if where else ""
        head = f"{self.path}{loc}: " if self.path else (f"{', '.join(where)}: " if where else "")
        super().__init__(f"{head}{message}")


class AlignmentError(FpdtwError, ValueError):
    """Bad arguments to an aligner (e.g. a window of 0, mismatched joints)."""


class LimitError(FpdtwError, ValueError):
    """A size is outside the limits of :mod:`fpdtw.limits`, raised before anything of that
    size is allocated.

    Parameters
    ----------
    paths : str or os.PathLike or sequence of them, or None
        The file(s) (or motion names) the size comes from.
    message : str
        The number, the limit (and its environment variable), what to do.
    """

    def __init__(self, paths, message):
        if paths is None:
            paths = ()
        elif isinstance(paths, str | os.PathLike):
            paths = (paths,)
        self.paths = tuple(str(p) for p in paths if p is not None and str(p))
        self.reason = message
        head = f"{', '.join(self.paths)}: " if self.paths else ""
        super().__init__(f"{head}{message}")


class ClusterError(FpdtwError, RuntimeError):
    """A run on a Dask cluster cannot go on (a scheduler unreachable, a worker running other
    code, a task lost or cancelled, a file a worker wrote not visible here)."""
