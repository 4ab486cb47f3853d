"""Shared helpers of the text-format readers (ASF/AMC, BVH)."""

from __future__ import annotations

from pathlib import Path

from ..errors import MotionFormatError


def read_lines(path: Path) -> list[str]:
    """Lines of a text file; latin-1 never fails (HDM05 headers hold umlauts)."""
    try:
        data = path.read_bytes()
    except OSError as exc:
        raise MotionFormatError(path, f"cannot read file: {exc.strerror or exc}") from None
    return data.decode("latin-1").splitlines()
