"""argparse types shared by the command lines (``fpdtw``, :mod:`fpdtw.app.cli`): a bad value
is a usage error that says what was expected."""

from __future__ import annotations

import argparse


def _whole(text: str, low: int, what: str, bound: str) -> int:
    try:
        v = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be {what}, got {text!r}") from None
    if v < low:
        raise argparse.ArgumentTypeError(f"must be {bound}, got {text!r}")
    return v


def positive_int(text: str) -> int:
    """A whole number >= 1."""
    return _whole(text, 1, "a whole number", "at least 1")


def positive_float(text: str) -> float:
    """A finite number > 0."""
    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a number, got {text!r}") from None
    if not 0 < v < float("inf"):
        raise argparse.ArgumentTypeError(f"must be a positive number, got {text!r}")
    return v


def frame_number(text: str) -> int:
    """A whole number >= 0 (a frame of a motion)."""
    return _whole(text, 0, "a frame number", "0 or more")
