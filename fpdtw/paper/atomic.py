"""Files written whole or not at all: a temporary file beside the destination, flushed to
disk, then renamed over it (:func:`os.replace`). A reader never sees half a file, and a
killed process leaves at most a temporary file (``.<name>.<pid>.part``), which the runner
ignores and cleans up. Every result, table, facts and bench file of the paper layer is
written this way."""

from __future__ import annotations

import os
from pathlib import Path

#: Prefix and suffix of temporary files (a killed run may leave these; they are ignored).
TMP_PREFIX, TMP_SUFFIX = ".", ".part"


def tmp_path(path: Path) -> Path:
    """The temporary file of :func:`write_atomic` for ``path`` (``.<name>.<pid>.part``)."""
    return path.with_name(f"{TMP_PREFIX}{path.name}.{os.getpid()}{TMP_SUFFIX}")


def write_atomic(path, data: bytes) -> Path:
    """Write ``data`` to ``path`` through a temporary file and :func:`os.replace`.

    Parameters
    ----------
    path : path-like
        Destination; its folder is created if needed.
    data : bytes

    Returns
    -------
    path : Path
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = tmp_path(path)
    try:
        with open(tmp, "wb") as f:
            f.write(data)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    finally:
        if tmp.exists():
            tmp.unlink()
    return path


__all__ = ["TMP_PREFIX", "TMP_SUFFIX", "tmp_path", "write_atomic"]
