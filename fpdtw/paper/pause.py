"""Targets with a held pose inserted: the OPW poster's "periods of standing still".

The OPW poster's conclusion warns that its method "may not work consistently if there are periods of
standing still"; to measure that, a pause is inserted in the TARGET, the input left unchanged. The
rule (committed in cbb3316, before Q6's first results in cfc7b1d, and unchanged since;
docs/history.md): frame ``a`` drawn uniformly from the middle 60 % of the target, ``[ceil(0.2 (F -
1)), floor(0.8 (F - 1))]``, is repeated ``L = round(u * fps)`` more times, ``u`` uniform in 0.5-2 s
(quaternions, Euler angles and positions alike); both draws come from a generator seeded by
:data:`PAUSE_SEED` and the target's name, so a take gets the same pause in every pair.

Paper: OPW poster Section 6 (conclusion: standing still).
Notebook: 16_open_questions.ipynb
"""

from __future__ import annotations

import hashlib
import math
from dataclasses import replace

import numpy as np

from fpdtw.errors import AlignmentError

#: Seed of every pause (with the target's name).
PAUSE_SEED = 2026
#: Shortest and longest pause, seconds.
PAUSE_SECONDS = (0.5, 2.0)
#: The pause starts inside this fraction of the target (the middle 60 %).
PAUSE_SPAN = (0.2, 0.8)


def pause_seed(name: str) -> int:
    """The generator seed of a target's pause: sha256 of ``"<PAUSE_SEED>/<name>"``."""
    return int.from_bytes(hashlib.sha256(f"{PAUSE_SEED}/{name}".encode()).digest()[:8], "little")


def pause_plan(n_frames: int, fps: float, seed: int) -> tuple[int, int]:
    """The held frame ``a`` and the extra frames ``L >= 1`` of a pause (the module's rule)
    in a target of ``n_frames >= 2`` frames.

    Paper: OPW poster Section 6.
    Notebook: 16_open_questions.ipynb
    """
    if n_frames < 2 or not fps > 0:
        raise AlignmentError(
            f"a pause needs a target of 2+ frames and fps > 0, got {n_frames}, {fps}"
        )
    rng = np.random.default_rng(seed)
    last = n_frames - 1
    lo = int(math.ceil(PAUSE_SPAN[0] * last))
    hi = max(lo, int(math.floor(PAUSE_SPAN[1] * last)))
    at = int(rng.integers(lo, hi + 1))
    length = max(1, int(round(rng.uniform(*PAUSE_SECONDS) * fps)))
    return at, length


def hold_frames(x, at: int, length: int):
    """``x`` (frames first) with frame ``at`` repeated ``length`` more times (None: None)."""
    if x is None:
        return None
    x = np.asarray(x)
    return np.ascontiguousarray(
        np.concatenate([x[: at + 1], np.repeat(x[at : at + 1], length, axis=0), x[at + 1 :]])
    )


def insert_pause(T, at: int | None = None, length: int | None = None, seed: int | None = None):
    """The target ``T`` with a held pose inserted.

    Parameters
    ----------
    T : MotionFeatures
    at, length : int, optional
        The held frame and the extra frames; default :func:`pause_plan` with ``seed``
        (default :func:`pause_seed` of ``T.name``).
    seed : int, optional

    Returns
    -------
    MotionFeatures
        ``F + length`` frames, named ``T.name + "+pause"``.

    Paper: OPW poster Section 6.
    Notebook: 16_open_questions.ipynb
    """
    F = T.n_frames
    if at is None or length is None:
        a, L = pause_plan(F, T.fps, pause_seed(T.name) if seed is None else seed)
        at = a if at is None else at
        length = L if length is None else length
    if not (0 <= at < F) or length < 0:
        raise AlignmentError(
            f"target {T.name!r}: a pause at frame {at} of {F} for {length} frames is outside it"
        )
    return replace(
        T,
        quats=hold_frames(T.quats, at, length),
        euler=hold_frames(T.euler, at, length),
        positions=hold_frames(T.positions, at, length),
        name=f"{T.name}+pause",
    )
