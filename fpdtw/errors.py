"""Exception types, one per family of failure.

Every error a user can provoke with bad input is one of these, and its message
names the file (and, where there is one, the line or frame) and what is wrong.
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


class DataFetchError(FpdtwError, RuntimeError):
    """A data file could not be fetched or failed verification against the manifest."""


class ManifestError(FpdtwError, ValueError):
    """A data manifest file is malformed."""


class AlignmentError(FpdtwError, ValueError):
    """Bad arguments to an aligner (e.g. a window of 0, mismatched joints)."""


class LimitError(FpdtwError, ValueError):
    """A size is outside the limits of :mod:`fpdtw.limits` (a frame rate, a frame count
    after resampling, a matrix or window an aligner would allocate).

    Raised before anything of that size is allocated. The message names the file(s) the
    size comes from, the number, the limit (and the environment variable that raises
    it) and the way out.

    Parameters
    ----------
    paths : str or os.PathLike or sequence of them, or None
        The file(s) (or motion names) the size comes from.
    message : str
        What is too large or too small, the number, the limit, what to do.
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
    """A run on a Dask cluster cannot go on.

    The scheduler address is malformed or cannot be reached, a worker runs other code
    than this process, the cluster lost the workers of a task too often or cancelled
    it, or a file a worker wrote is not visible here. The message names the address (or
    the worker, task or file) and what is wrong.
    """
