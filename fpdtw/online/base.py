"""The one streaming interface every online aligner implements::

    aligner = MethodC(input_features, w=40)
    for frame in target_features.frames():
        m = aligner.step(frame)      # input frame mapped to this target frame

``step`` returns ``M_{n+1}`` before the next target frame exists. :func:`run_online`
does this over a whole target and times each step.
"""

from __future__ import annotations

import time
from abc import ABC, abstractmethod

import numpy as np

from fpdtw import limits
from fpdtw.errors import AlignmentError
from fpdtw.motion.features import Frame, MotionFeatures
from fpdtw.motion.rig import cost_input
from fpdtw.motion.rotations import check_order

#: Fewest rows kept when compacting (the rules of the first frames, ``q < 16``, see none).
_MIN_KEEP = 16


def check_input(I, who: str = "") -> None:
    """Refuse (AlignmentError naming ``who``) an input that is not MotionFeatures or empty."""
    who = f"{who}: " if who else ""
    if not isinstance(I, MotionFeatures):
        raise AlignmentError(
            f"{who}the input motion must be given as MotionFeatures, got {type(I).__name__}"
        )
    if I.n_frames == 0:
        raise AlignmentError(f"{who}input motion {I.name or '(unnamed)'!r} has no frames")


def check_count(value, what: str, who: str, minimum: int = 1) -> int:
    """``value`` as an int, or AlignmentError unless it is an int >= minimum (not a bool)."""
    if isinstance(value, bool) or not isinstance(value, int | np.integer) or value < minimum:
        raise AlignmentError(f"{who}: {what} must be an int >= {minimum}, got {value!r}")
    return int(value)


def compiled_frame(frame, i: int, capacity: int, Tp):
    """``(quats, euler)`` of a streamed frame a compiled step can take, else None.

    Plain 2-D ndarrays and room for row ``i`` (its positions stored in ``Tp[i]``); None
    sends the frame the general way."""
    fq, fe, p = frame.quats, frame.euler, frame.positions
    if not (
        i < capacity
        and type(fq) is np.ndarray
        and type(fe) is np.ndarray
        and fq.ndim == 2
        and fe.ndim == 2
        and (p is None or Tp is not None)
    ):
        return None
    if p is not None:
        Tp[i] = p
    return fq, fe


class OnlineAligner(ABC):
    """Base class of online aligners (``I``: the input motion); subclasses implement :meth:`_step`.

    It keeps the received frames (``T_quats``, ``T_euler``, ``T_positions``) and the map
    (``M``). With a bounded :attr:`history`, once the buffers hold
    :data:`fpdtw.limits.HISTORY_FRAMES` rows only the latest ``max(history, 16)`` are kept
    (from :attr:`history_start` on); ``history = None`` or ``record=True`` keeps all.
    :meth:`_step`'s ``q`` is the new frame's ROW in the buffers."""

    #: Short name used in results and figures (e.g. ``"Mc w40"``).
    name = "online"
    #: Earlier target frames a step reads besides the newest (None: any, so all are kept).
    history: int | None = None

    #: Rotation orders of the target's cost joints (of the current take's first frame).
    T_orders: tuple | None = None

    def __init__(self, I: MotionFeatures):
        check_input(I, who=type(self).__name__)
        self.I = I
        self.m = I.n_frames - 1  # index of the last input frame (paper: I_0..I_m)
        self.reset()

    def reset(self) -> None:
        """Forget every target frame; ready for a new target."""
        k = self.I.quats.shape[1]
        cap = 256
        self._Tq = np.empty((cap, k, 4))
        self._Te = np.empty((cap, k, 3))
        self._Tp = None
        self._M = np.empty(cap, dtype=np.int64)
        self._start = 0
        self._history_rows = int(limits.get("history_frames"))
        self.n_received = 0

    @property
    def history_start(self) -> int:
        """Frame number of the first target frame still kept (0 unless compacted)."""
        return self._start

    @property
    def T_quats(self) -> np.ndarray:
        """Target rotations kept, shape (n+1 - history_start, k, 4)."""
        return self._Tq[: self.n_received - self._start]

    @property
    def T_euler(self) -> np.ndarray:
        """Target Euler angles kept, shape (n+1 - history_start, k, 3)."""
        return self._Te[: self.n_received - self._start]

    @property
    def T_positions(self):
        """Target positions kept, shape (n+1 - history_start, p, 3), or None."""
        return None if self._Tp is None else self._Tp[: self.n_received - self._start]

    @property
    def M(self) -> np.ndarray:
        """The map so far: ``M[q]`` is the input frame of target frame ``history_start + q``."""
        return self._M[: self.n_received - self._start]

    def _buffers(self):
        return [name for name in ("_Tq", "_Te", "_Tp", "_M") if getattr(self, name) is not None]

    def _grow(self):
        cap = 2 * self._Tq.shape[0]
        for name in self._buffers():
            old = getattr(self, name)
            new = np.empty((cap,) + old.shape[1:], dtype=old.dtype)
            new[: old.shape[0]] = old
            setattr(self, name, new)

    def _make_room(self) -> None:
        """The buffers are full: compact them (bounded history) or grow them."""
        rows = self._Tq.shape[0]
        if self.history is None or getattr(self, "record", False):
            self._grow()  # keep everything
            return
        keep = max(int(self.history), _MIN_KEEP)
        if rows < max(self._history_rows, 2 * keep):
            self._grow()
            return
        shift = rows - keep
        for name in self._buffers():
            buf = getattr(self, name)
            buf[:keep] = buf[shift:rows]
        self._start += shift

    def _begin_take(self, frame: Frame) -> None:
        """The first frame of a take: adopt its rotation orders and rig.

        :attr:`T_orders` serve the forecasts; the rig decides what eq. 1 compares
        (:func:`fpdtw.motion.rig.cost_input`, to :meth:`_use_input`). AlignmentError for bad orders.
        """
        I = self.I
        k = np.shape(I.quats)[1]
        orders = I.orders if frame.orders is None else frame.orders
        if orders is not I.orders:
            try:
                orders = tuple(check_order(o) for o in orders)
            except (TypeError, ValueError) as e:
                raise AlignmentError(f"target frame 0: bad rotation orders ({e})") from None
            if len(orders) != k:
                raise AlignmentError(
                    f"target frame 0: {len(orders)} rotation orders for {k} joints"
                )
        self.T_orders = tuple(orders)
        rig = frame.rig
        Iq = I.quats if rig is None or rig is I.rig else cost_input(I.quats, I.rig, rig)
        self._use_input(Iq, self.T_orders)

    def _use_input(self, Iq, orders) -> None:  # noqa: B027 - a hook, not abstract
        """Use input rotations ``Iq`` (m + 1, k, 4) and the target's ``orders`` from now on."""

    def step(self, frame: Frame) -> int:
        """Receive target frame ``T_{n+1}`` and return ``M_{n+1}``; AlignmentError, the aligner
        unchanged, when the frame holds a NaN or inf."""
        if self.n_received == 0:
            self._begin_take(frame)
        i = self.n_received - self._start
        if i == self._Tq.shape[0]:
            self._make_room()
            i = self.n_received - self._start
        self._Tq[i] = frame.quats
        self._Te[i] = frame.euler
        if frame.positions is not None:
            if self._Tp is None:
                self._Tp = np.empty((self._Tq.shape[0],) + np.shape(frame.positions))
            self._Tp[i] = frame.positions
        bad = ~(np.isfinite(self._Tq[i]).all(axis=1) & np.isfinite(self._Te[i]).all(axis=1))
        if bad.any() or (frame.positions is not None and not np.isfinite(self._Tp[i]).all()):
            what = f"joint {int(np.argmax(bad))}" if bad.any() else "a joint position"
            raise AlignmentError(
                f"target frame {self.n_received}: {what} is not finite (NaN or inf), for every "
                "method; leave the frame out or fill it (a gap) before step()"
            )
        self.n_received += 1
        m = int(self._step(i))
        self._M[i] = m
        return m

    @abstractmethod
    def _step(self, q: int) -> int:
        """Map the new target frame, stored in row ``q`` of the buffers, to an input frame."""


class FrameWrapper(OnlineAligner):
    """An aligner around another: ``_step`` reads the whole frame (``self._frame``) and the
    rig is the wrapped aligner's business (:class:`fpdtw.derivative.DerivativeAligner`,
    :class:`fpdtw.online.relocate.Relocating`)."""

    #: Reads only the newest target frame (the wrapped aligner keeps its own).
    history = 1

    def _begin_take(self, frame: Frame) -> None:
        """The take's rotation orders."""
        self.T_orders = self.I.orders if frame.orders is None else tuple(frame.orders)

    def step(self, frame: Frame) -> int:
        self._frame = frame
        try:
            return super().step(frame)
        finally:
            self._frame = None


class JointMajorInput:
    """Mixin: the input for eq. 1 kept C-contiguous and joint-major.

    ``_Iq`` (m + 1, k, 4) and ``_Isoa`` (k, 4, m + 1), as compared with the take's rig."""

    def _use_input(self, Iq, orders) -> None:
        if Iq is not getattr(self, "_Iq", None):
            self._Iq = np.ascontiguousarray(Iq, dtype=np.float64)
            self._Isoa = np.ascontiguousarray(self._Iq.transpose(1, 2, 0))


def run_online(aligner: OnlineAligner, T: MotionFeatures, *, reset=True):
    """Run an online aligner over target ``T`` frame by frame: ``(M, seconds)``.

    The int64 map (n,) and each ``step`` call's wall time (n,); ``reset``: reset first."""
    if reset:
        aligner.reset()
    n = T.n_frames
    M = np.empty(n, dtype=np.int64)
    dt = np.empty(n)
    clock = time.perf_counter
    for q in range(n):
        frame = T.frame(q)
        t0 = clock()
        M[q] = aligner.step(frame)
        dt[q] = clock() - t0
    return M, dt


def run_together(aligners, T: MotionFeatures, *, reset=True) -> list:
    """Run several online aligners over one target in lockstep (nothing timed).

    Every aligner gets frame q before any gets q + 1, so aligners sharing a
    :class:`~fpdtw.online.window.WindowCache` compute shared work once; each map is the one
    :func:`run_online` gives. Returns one int64 map (n,) per aligner, in order."""
    aligners = list(aligners)
    if reset:
        for a in aligners:
            a.reset()
    n = T.n_frames
    maps = [np.empty(n, dtype=np.int64) for _ in aligners]
    for q in range(n):
        frame = T.frame(q)
        for a, M in zip(aligners, maps):
            M[q] = a.step(frame)
    return maps
