"""The file checks every reader makes, and text decoding (ASF/AMC, BVH)."""

from __future__ import annotations

import codecs
import os
import stat
from pathlib import Path

from fpdtw import limits
from fpdtw.errors import MotionFormatError

#: Byte-order marks at the start of a text file and the encoding each one means.
_BOMS = (
    (codecs.BOM_UTF8, "utf-8"),
    (codecs.BOM_UTF16_LE, "utf-16-le"),
    (codecs.BOM_UTF16_BE, "utf-16-be"),
)


def check_input_file(path: Path) -> int:
    """Size in bytes of a motion file about to be read whole.

    MotionFormatError for no such file, a directory, not a regular file (a FIFO would
    block), unreadable, or larger than :data:`fpdtw.limits.MAX_FILE_BYTES`."""
    try:
        st = os.stat(path)
    except FileNotFoundError:
        raise MotionFormatError(path, "no such file") from None
    except OSError as exc:
        raise MotionFormatError(path, f"cannot read file: {exc.strerror or exc}") from None
    if stat.S_ISDIR(st.st_mode):
        raise MotionFormatError(path, "is a directory, not a motion file")
    if not stat.S_ISREG(st.st_mode):
        raise MotionFormatError(path, "is not a regular file (a device, FIFO or socket)")
    limits.check_file_size(path, st.st_size)
    return st.st_size


def decode_text(data: bytes) -> str:
    """Text of a motion file, by its byte-order mark, else latin-1.

    A UTF-8 or UTF-16 mark selects the encoding (and is dropped); latin-1 never fails
    (HDM05 headers hold umlauts), also for UTF-8 that does not decode after its mark.
    UnicodeDecodeError for a UTF-16 mark followed by other bytes."""
    for bom, encoding in _BOMS:
        if data.startswith(bom):
            body = data[len(bom) :]
            if encoding == "utf-8":
                try:
                    return body.decode("utf-8")
                except UnicodeDecodeError:
                    return body.decode("latin-1")  # a mark, then not UTF-8: as without it
            return body.decode(encoding)
    return data.decode("latin-1")


def read_lines(path: Path) -> list[str]:
    """Lines of a text motion file (:func:`decode_text`), after :func:`check_input_file`."""
    check_input_file(path)
    try:
        data = path.read_bytes()
    except OSError as exc:
        raise MotionFormatError(path, f"cannot read file: {exc.strerror or exc}") from None
    try:
        text = decode_text(data)
    except UnicodeDecodeError as exc:
        raise MotionFormatError(
            path, f"starts with a UTF-16 byte-order mark but is not UTF-16 ({exc.reason})"
        ) from None
    return text.splitlines()
