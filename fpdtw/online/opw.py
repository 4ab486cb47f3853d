"""On-line Predictive Warping (OPW), the poster's Algorithm 1, as a streaming aligner.

The recording ``A`` (the poster's Y, the INPUT) is played through a time-warp curve
``f`` (:class:`~fpdtw.warpcurve.WarpCurve`, live time ``t`` -> recording time ``t'``)
while the live motion ``B`` (X, the TARGET) arrives. Our reading of the poster (reading
notes; * where it is silent or contradicts itself):

1. ``f`` starts as the identity, keys ``(0, 0)`` and ``(D_A, D_A)``, and holds at
   ``D_A`` after its last key.
2. Steps at ``t = omega, 2 omega, ...`` (0.04 s), each once the live frame at or after
   ``t`` is in; B between frames is interpolated linearly (*).
3. Forecast ``b_hat = B(t) + (B(t) - B(t - omega))`` on root-relative positions of the
   16 :data:`~fpdtw.motion.joints.OPW_JOINTS`.
4. ``p_i`` = eq. 5 (summed Euclidean distances) between ``b_hat`` and A at
   ``f(t) + i omega``, ``i = 0, 1, 2`` (eq. 4, ``read_at="eq4"``, the default); A is
   interpolated, clamped to ``[0, D_A]`` (*). Algorithm 1's lines 2-3 read A at
   ``f(t + i omega)`` instead (``read_at="listing"``).
5. ``s = argmin p``; ``s = 1`` unless ``p_0`` or ``p_2`` is STRICTLY smallest (*; we
   follow eqs. 1, 2, 4, not the listing's inverted comparisons).
6. ``s != 1``: pin a key at ``(t, f(t))``, then move the last key's live time (eq. 2):
   ``x_last <- x_last - (x_last - t) gamma (s - 1)``.
7. No steps once ``t >= x_last`` (*). Target frame ``q`` maps to
   ``round(f(q / fps) * fps_A)``, clipped to ``[0, m]``.

The plugin reading (``reading="plugin"``, the authors' MotionBuilder plugin,
matRandall/realTimeDTW): ``reference="ratio"`` reads A at ``(t + i omega) D_A / x_last``, and
``clock="frames"`` steps at the first frame strictly after the previous step plus ``omega``. Its
readme states the opposite direction: ``direction="readme"``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fpdtw.errors import AlignmentError
from fpdtw.motion.features import MotionFeatures
from fpdtw.online.base import OnlineAligner, check_input
from fpdtw.plain import OPW_READ_AT, interpolate_positions, opw_times
from fpdtw.warpcurve import WarpCurve

#: Tolerance when comparing a step time with a frame time (seconds).
_EPS = 1e-9


def opw_step(
    f, t, A, B, omega, gamma, fps_A, fps_B, reference="curve", direction="code", read_at="eq4"
):
    """One OPW step at live time ``t``, changing ``f`` in place: ``(s, [p_0, p_1, p_2])``.

    ``A`` (F_A, p, 3): the recording's positions; ``B`` (F_B, p, 3): the live ones so far;
    ``reference``, ``direction``, ``read_at``: the readings of the module docstring.

    Plain version: fpdtw.plain.opw_step (``reference="curve"``, ``direction="code"``).
    Paper: OPW poster Algorithm 1, eqs. 1, 2, 4, 5.
    """
    sign = {"code": 1.0, "readme": -1.0}.get(direction)
    if sign is None:
        raise ValueError(f"direction must be 'code' or 'readme', got {direction!r}")
    t_w = f.value(t)
    x_t = interpolate_positions(B, fps_B, t)
    x_hat = x_t + (x_t - interpolate_positions(B, fps_B, t - omega))
    if reference == "curve":
        times = opw_times(f, t, omega, read_at)
    elif reference == "ratio":
        r = f.y[-1] / f.x[-1]
        times = [(t + i * omega) * r for i in range(3)]
    else:
        raise ValueError(f"reference must be 'curve' or 'ratio', got {reference!r}")
    A_t = [interpolate_positions(A, fps_A, tau) for tau in times]
    p = [float(np.sqrt(((x_hat - a) ** 2).sum(axis=1)).sum()) for a in A_t]
    s = 1
    if p[0] < p[1] and p[0] < p[2]:
        s = 0
    elif p[2] < p[1] and p[2] < p[0]:
        s = 2
    if s != 1:
        x_k = f.x[-1]
        f.add_key(t, t_w)
        f.move_key(-1, x=x_k - (x_k - t) * gamma * (s - 1) * sign)
    return s, p


#: OPW's readings: name -> the options it sets (module doc).
READINGS = {
    "poster": {"reference": "curve", "clock": "exact"},
    "plugin": {"reference": "ratio", "clock": "frames"},
}


@dataclass(frozen=True)
class OPWDecision:
    """One OPW step at live time ``t``: ``t_warped = f(t)`` before it, ``costs`` (p_0, p_1, p_2),
    the decision ``s`` (0 slow the recording down, 1 keep, 2 speed it up), ``x_last`` after it."""

    t: float
    t_warped: float
    costs: tuple
    s: int
    x_last: float


class OPW(OnlineAligner):
    """On-line Predictive Warping (poster Algorithm 1) behind the online interface.

    ``I``: the recording, WITH ``positions`` (``position_joints=OPW_JOINTS``); ``omega``:
    the step period (s; the poster's 0.04); ``gamma``: the warp parameter in (0, 1) (the
    poster's 5 %); ``fps``: the live frames' rate (default the recording's); ``reading``:
    ``"poster"`` or ``"plugin"``, whose ``reference`` and ``clock`` may be overridden;
    ``direction``, ``read_at``: the other switches of the module docstring. ``curve`` is the
    warp curve so far, ``decisions`` the :class:`OPWDecision` of every step.

    Plain version: fpdtw.plain.opw_step.
    Paper: OPW poster Section 3, eqs. 1, 2, 4, 5, Algorithm 1.
    """

    name = "OPW"

    def __init__(
        self,
        I: MotionFeatures,
        omega: float = 0.04,
        gamma: float = 0.05,
        fps=None,
        reading: str = "poster",
        *,
        reference: str | None = None,
        clock: str | None = None,
        direction: str = "code",
        read_at: str = "eq4",
    ):
        check_input(I, who="OPW")
        if I.positions is None:
            raise ValueError(
                "OPW needs joint positions: build the features with "
                "MotionFeatures.from_motion(motion, position_joints=OPW_JOINTS)"
            )
        if I.n_frames < 2:
            raise AlignmentError(
                f"OPW needs a recording of at least two frames; {I.name or 'the input'!r} "
                f"has {I.n_frames}"
            )
        if not omega > 0:
            raise ValueError(f"omega must be positive, got {omega}")
        if not 0 < gamma < 1:
            raise ValueError(f"gamma must satisfy 0 < gamma < 1, got {gamma}")
        if reading not in READINGS:
            raise ValueError(f"reading must be one of {sorted(READINGS)}, got {reading!r}")
        self.reading = reading
        self.reference = READINGS[reading]["reference"] if reference is None else reference
        self.clock = READINGS[reading]["clock"] if clock is None else clock
        self.direction = direction
        self.read_at = read_at
        for name, value, allowed in (
            ("read_at", self.read_at, OPW_READ_AT),
            ("reference", self.reference, ("curve", "ratio")),
            ("clock", self.clock, ("exact", "frames")),
            ("direction", self.direction, ("code", "readme")),
        ):
            if value not in allowed:
                raise ValueError(f"{name} must be one of {allowed}, got {value!r}")
        self.omega = float(omega)
        self.gamma = float(gamma)
        self.fps_A = float(I.fps)
        self.fps = self.fps_A if fps is None else float(fps)
        self.duration_A = (I.n_frames - 1) / self.fps_A
        self._PA = np.ascontiguousarray(I.positions, dtype=np.float64)
        super().__init__(I)

    def reset(self) -> None:
        super().reset()
        self.curve = WarpCurve.identity(self.duration_A)
        self.decisions = []
        self._k = 1  # index of the next OPW step (live time k * omega), clock "exact"
        self._t_prev = 0.0  # live time of the previous step, clock "frames"

    def _opw_step(self, t: float, last: int) -> None:
        tw = self.curve.value(t)
        s, costs = opw_step(
            self.curve, t, self._PA, self._Tp[: last + 1], self.omega, self.gamma, self.fps_A,
            self.fps, self.reference, self.direction, self.read_at,
        )  # fmt: skip
        self.decisions.append(OPWDecision(t, tw, tuple(costs), s, self.curve._x[-1]))

    def _step(self, q: int) -> int:
        if self._Tp is None:
            raise ValueError("OPW needs target frames with positions")
        now = q / self.fps
        if self.clock == "frames":  # the plugin: at this frame, once omega has passed
            if now > self._t_prev + self.omega + _EPS:
                self._t_prev = now
                if now < self.curve._x[-1]:
                    self._opw_step(now, q)
        while self.clock == "exact" and self._k * self.omega <= now + _EPS:
            t = self._k * self.omega
            self._k += 1
            if t >= self.curve._x[-1]:  # the recording has been played out
                continue
            self._opw_step(t, q)
        m = int(round(self.curve.value(now) * self.fps_A))
        return min(max(m, 0), self.m)

    def decision_table(self) -> dict:
        """The decisions as arrays: ``t``, ``t_warped``, ``costs`` (N, 3), ``s``, ``x_last``."""
        d = self.decisions
        return {
            "t": np.array([e.t for e in d], dtype=float),
            "t_warped": np.array([e.t_warped for e in d], dtype=float),
            "costs": np.array([e.costs for e in d], dtype=float).reshape(len(d), 3),
            "s": np.array([e.s for e in d], dtype=np.int64),
            "x_last": np.array([e.x_last for e in d], dtype=float),
        }
