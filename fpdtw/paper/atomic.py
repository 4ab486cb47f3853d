"""Files written whole or not at all: a temporary file beside the destination, flushed to
disk, then renamed over it (a killed process leaves at most a ``.<name>.<pid>.part`` file)."""

from __future__ import annotations

import os
from pathlib import Path

#: Suffix of temporary files.
TMP_SUFFIX = ".part"


def write_atomic(path, data: bytes) -> Path:
    """Write ``data`` to ``path`` (its folder created if needed); returns ``path`` as a Path."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.{os.getpid()}{TMP_SUFFIX}")
    try:
        with open(tmp, "wb") as f:
            f.write(data)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)
    return path
