"""Files written whole or not at all: a temporary file beside the destination, flushed to
disk, then renamed over it (a killed process leaves at most a ``.<name>.<pid>.part`` file)."""

from __future__ import annotations

import os
from pathlib import Path

#: Prefix and suffix of temporary files.
TMP_PREFIX, TMP_SUFFIX = ".", ".part"


def tmp_path(path: Path) -> Path:
    """The temporary file of :func:`write_atomic` for ``path`` (``.<name>.<pid>.part``)."""
    return path.with_name(f"{TMP_PREFIX}{path.name}.{os.getpid()}{TMP_SUFFIX}")


def write_atomic(path, data: bytes) -> Path:
    """Write ``data`` to ``path`` (its folder created if needed); returns ``path`` as a Path."""
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
        tmp.unlink(missing_ok=True)
    return path
