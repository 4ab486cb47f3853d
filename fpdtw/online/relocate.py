"""Any online aligner with a global search beside it, to find the performer again after a
skip, a repeat or a restart (``"<method> (relocate)"``, ``--relocate``; beyond the papers,
open question Q7).

Every online method of the papers looks a window ahead of its last input frame, so a
performer who jumps is not found again. Music score followers meet the same problem and
search the whole score beside the local tracker (Arzt and Widmer's "any-time" tracking). Here
the search is a subsequence DTW over the whole input, streamed with one row of state, as
SPRING (Sakurai et al. 2007) streams it, with old terms forgotten instead of a star-padded
start.

**The rule** (fixed here on 2026-11-26 before it was run on any edited target or any pair
of the open run; docs/history.md says what its unit tests had run by then). Beside the wrapped
aligner (``inner``), each target frame ``T_n`` updates, for every input frame ``j``,

    G_n[j] = c(T_n, I_j) + lam * min(G_{n-1}[j], G_{n-1}[j-1], G_{n-1}[j-2]),   G_{-1} = 0,

``c`` eq. 1 over the cost joints, steps of slope 0, 1 and 2 (one term per target frame, the
performer at most twice the recording's speed), ``lam = 1 - 1/K`` with ``K`` the input frames
in :data:`MEMORY_S`: a path may begin anywhere, and what it did more than a few ``K`` frames
ago has faded. The inner map's own cost is followed the same way, ``L_n = c(T_n, I_{M_n}) +
lam L_{n-1}``. With ``j* = argmin_j G_n[j]`` (the first of equal ones): when ``j*`` is more
than :data:`FAR_S` of input frames from ``M_n``, ``G_n[j*] < RATIO * L_n`` (the global path
costs less than half the inner one) and at least :data:`REST_S` of input follows ``j*``, for
:data:`HOLD_S` of target frames in a row, the aligner JUMPS: the inner aligner is made afresh
on the input from ``j*`` on (its frame 0 is ``j*``), fed this frame, and ``L_n = G_n[j*]``.

A jump may go backwards: the map of a relocating aligner is not monotone, and
:attr:`Relocating.jumps` lists every jump (target frame, input frame before, after).

Paper: neither (beyond the papers, Q7); eq. 1 of FP-DTW; SPRING (Sakurai, Faloutsos and
Yamamuro, ICDE 2007).
"""

from __future__ import annotations

from dataclasses import replace

import numba
import numpy as np

from fpdtw.costs import _geo_line
from fpdtw.errors import AlignmentError
from fpdtw.motion.features import Frame, MotionFeatures
from fpdtw.motion.rig import cost_input
from fpdtw.online.base import FrameWrapper, OnlineAligner

#: The search's memory (its forgetting factor: 1 - 1 / frames in this many seconds).
MEMORY_S = 1.0
#: A jump: further than this from the inner map, ...
FAR_S = 0.5
#: ... a global path cheaper than this share of the inner one, ...
RATIO = 0.5
#: ... with at least this much input after it, for this long.
REST_S, HOLD_S = 0.25, 0.25


@numba.njit(cache=True)
def _search_step(q, Isoa, G, lam, acc, c):
    """One target frame of the search: ``c`` (N,) becomes eq. 1 between ``q`` (k, 4) and
    every input frame (:func:`fpdtw.costs._geo_line`; ``Isoa`` (k, 4, N) joint-major,
    ``acc`` (N,) scratch), and ``G`` (N,) float64, the previous row, the new one in place;
    returns ``(j*, G[j*])``.

    Plain version: fpdtw.plain.relocate_step.
    """
    N = G.shape[0]
    _geo_line(q, Isoa, 0, N, acc, c)
    best, arg = np.inf, 0
    for j in range(N - 1, -1, -1):  # downwards: G[j - 1], G[j - 2] are still the old row's
        m = G[j]
        if j >= 1 and G[j - 1] < m:
            m = G[j - 1]
        if j >= 2 and G[j - 2] < m:
            m = G[j - 2]
        G[j] = c[j] + lam * m
        if G[j] <= best:
            best, arg = G[j], j
    return arg, best


def input_from(I: MotionFeatures, j: int) -> MotionFeatures:
    """The input from frame ``j`` on (its frame 0 is ``I``'s frame ``j``)."""
    pos = None if I.positions is None else I.positions[j:]
    return replace(I, quats=I.quats[j:], euler=I.euler[j:], positions=pos)


class Relocating(FrameWrapper):
    """An online aligner with the module's global search and jump rule.

    Parameters
    ----------
    I : MotionFeatures
        The input motion.
    make_inner : callable
        ``make_inner(J) -> OnlineAligner`` for an input ``J`` (``I``, or ``I`` from a frame on).
    name : str, optional
        Default: the inner aligner's name with ``" (relocate)"``.

    Attributes
    ----------
    jumps : list of (int, int, int)
        Every jump of the take: target frame, input frame before, input frame after.

    Paper: neither (beyond the papers, Q7).
    """

    def __init__(self, I: MotionFeatures, make_inner, name: str | None = None):
        self.make_inner = make_inner
        self.inner = make_inner(I)
        if not isinstance(self.inner, OnlineAligner):
            raise AlignmentError(f"Relocating: make_inner gave {type(self.inner).__name__}, "
                                 "not an OnlineAligner")  # fmt: skip
        self.name = name or f"{self.inner.name} (relocate)"
        fps = float(I.fps)
        self.lam = 1.0 - 1.0 / max(1, round(MEMORY_S * fps))
        self.far = round(FAR_S * fps)
        self.hold = max(1, round(HOLD_S * fps))
        self.rest = max(1, round(REST_S * fps))
        self._fresh = True
        super().__init__(I)

    def reset(self) -> None:
        super().reset()
        if not self._fresh:
            self.inner = self.make_inner(self.I)
        self._fresh = False
        self.offset, self.L, self.run = 0, 0.0, 0
        self.G = np.zeros(self.I.n_frames)
        self.jumps = []

    def _begin_take(self, frame: Frame) -> None:
        """The take's orders; the input as eq. 1 compares it with the take's rig."""
        super()._begin_take(frame)
        I = self.I
        Iq = I.quats if frame.rig is None or frame.rig is I.rig else cost_input(
            I.quats, I.rig, frame.rig)  # fmt: skip
        self._Isoa = np.ascontiguousarray(np.transpose(Iq, (1, 2, 0)), dtype=np.float64)
        self._acc, self._c = np.empty(I.n_frames), np.empty(I.n_frames)

    def _step(self, q: int) -> int:
        frame = self._frame
        m = self.offset + int(self.inner.step(frame))
        fq = np.ascontiguousarray(frame.quats, dtype=np.float64)
        j, g = _search_step(fq, self._Isoa, self.G, self.lam, self._acc, self._c)
        self.L = float(self._c[m]) + self.lam * self.L  # eq. 1 at M_n, from the search's row
        wants = abs(j - m) > self.far and g < RATIO * self.L
        self.run = self.run + 1 if wants and self.I.n_frames - j >= self.rest else 0
        if self.run >= self.hold:
            self.jumps.append((self.n_received - 1, m, int(j)))
            self.inner, self.offset = self.make_inner(input_from(self.I, int(j))), int(j)
            m = self.offset + int(self.inner.step(frame))
            self.L, self.run = float(g), 0
        return m
