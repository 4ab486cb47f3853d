"""On-line Predictive Warping (OPW), the poster's Algorithm 1, as a streaming aligner.

Poster symbols: the recording is ``A`` (the poster's time series Y, "the known values",
the INPUT here), the live motion is ``B`` (time series X, being captured, the TARGET);
``t`` is live time, ``t' = f(t)`` the warped time in the recording, ``f`` the time-warp
curve (:class:`~fpdtw.warpcurve.WarpCurve`), ``omega`` the sample period of OPW's
steps, ``gamma`` the warp parameter.

Our reading of the poster (Section 3, eqs. 1, 2, 4, 5 and Algorithm 1), settled by the
reading notes (``notebooks/reading_notes.md``); choices where the poster is silent or
contradicts itself are marked (*):

1. Start: ``f`` is the identity, keys ``(0, 0)`` and ``(D_A, D_A)`` (``D_A`` = duration
   of the recording): ``t' = t``. After the last key ``f`` holds at ``D_A`` (the
   recording has ended and holds its last pose).
2. OPW steps at live times ``t = omega, 2 omega, ...`` (``omega = 0.04`` s: the poster's
   25 steps per second). A step is performed as soon as the live frame at or after
   ``t`` has been received; B at a time between two frames is the linear interpolation
   of the two received frames' positions (*).
3. Dead reckoning (poster Section 4): ``b_hat = B(t) + (B(t) - B(t - omega))``, the
   forecast of ``B(t + omega)``, on joint POSITIONS (16 joints, root-relative, from
   forward kinematics; :data:`fpdtw.motion.joints.OPW_JOINTS`). The first step is at
   ``t = omega`` because it needs ``B(t - omega) = B(0)`` (*).
4. Compare ``b_hat`` with the recording at the warped times ``t' + i omega``,
   ``i = 0, 1, 2`` (``t' = f(t)``; poster eq. 4); A between its frames is the linear
   interpolation of its positions, clamped to ``[0, D_A]`` (*). The cost is eq. 5:
   ``p_i = sum over joints of |b_hat_j - A_j(t' + i omega)|`` (Euclidean).
5. ``s = argmin_i p_i`` (eq. 1 / 4). Ties keep the alignment: ``s = 1`` unless ``p_0``
   or ``p_2`` is STRICTLY the smallest cost (*). (Algorithm 1's listing compares
   ``p_1 > p_2 and p_1 > p_3`` with the roles seemingly inverted and adds ``gamma`` to
   the key; we follow eqs. 1, 2 and 4, which agree with the bullet list under eq. 1.)
6. ``s = 1``: nothing. ``s = 0`` (the live motion is behind: slow the recording
   down) or ``s = 2`` (ahead: speed it up): pin a key at the current time
   ``(t, f(t))`` (the poster's "split the warp curve at time t"), then move the LAST
   key's live-time coordinate by ``gamma`` times the live time left (eq. 2)::

       x_last <- x_last - (x_last - t) * gamma * (s - 1)

   ``s = 0`` moves the end of the recording later in live time (expands what is left
   of A), ``s = 2`` earlier (contracts it). ``y_last = D_A`` never changes.
7. Once ``t >= x_last`` the recording has been played out: no further steps (*).
8. Target frame ``q`` (live time ``q / fps``) is mapped, after every step due at or
   before ``q / fps``, to ``M_q = round(f(q / fps) * fps_A)``, clipped to ``[0, m]``.

The pinned key makes ``f(t)`` unchanged at the current time, so the frames already
mapped never see a jump. Because the key slopes are automatic (F-curve style), a new
key also changes the slope at the previous key, i.e. the shape of the PAST segment of
the final curve slightly; the realised online map is :attr:`OPW.M` (what was output),
the final curve is :attr:`OPW.curve` (what the poster evaluates).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fpdtw.errors import AlignmentError
from fpdtw.motion.features import MotionFeatures
from fpdtw.online.base import OnlineAligner, check_input
from fpdtw.plain import interpolate_positions, opw_step
from fpdtw.warpcurve import WarpCurve

#: Tolerance when comparing a step time with a frame time (seconds).
_EPS = 1e-9


@dataclass(frozen=True)
class OPWDecision:
    """One OPW step.

    Attributes
    ----------
    t : float
        Live time of the step (s).
    t_warped : float
        ``t' = f(t)`` before the step's change (s).
    costs : tuple of float, length 3
        ``(p_0, p_1, p_2)``, eq. 5 between the forecast and A at ``t' + i omega``.
    s : int
        0 (slow the recording down), 1 (keep), 2 (speed it up).
    x_last : float
        Live time of the last key after the step (s).
    """

    t: float
    t_warped: float
    costs: tuple
    s: int
    x_last: float


class OPW(OnlineAligner):
    """On-line Predictive Warping (poster Algorithm 1) behind the online interface.

    Parameters
    ----------
    I : MotionFeatures
        The recording A, WITH ``positions`` (e.g. ``MotionFeatures.from_motion(m,
        position_joints=OPW_JOINTS)``).
    omega : float
        Sample period of OPW's steps in live time (s); the poster: 25 Hz, 0.04 s.
    gamma : float
        Warp parameter, ``0 < gamma < 1``; the poster's Figs. 4-5: 5 %.
    fps : float, optional
        Frame rate of the live (target) frames; default the recording's.

    Attributes
    ----------
    curve : WarpCurve
        The time-warp curve built so far (live time -> recording time).
    decisions : list of OPWDecision
        One per OPW step performed.

    Each step is :func:`fpdtw.plain.opw_step` itself (plain Python and NumPy: a step
    every 40 ms needs no compiled kernel).

    Plain version: fpdtw.plain.opw_step.
    Paper: OPW poster Section 3, eqs. 1, 2, 4, 5, Algorithm 1.
    """

    name = "OPW"

    def __init__(self, I: MotionFeatures, omega: float = 0.04, gamma: float = 0.05, fps=None):
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
        self._k = 1  # index of the next OPW step (live time k * omega)

    # -- one OPW step ---------------------------------------------------------------------
    def _opw_step(self, t: float, last: int) -> None:
        tw = self.curve.value(t)
        s, costs = opw_step(
            self.curve, t, self._PA, self._Tp[: last + 1], self.omega, self.gamma, self.fps_A,
            self.fps,
        )  # fmt: skip
        self.decisions.append(OPWDecision(t, tw, tuple(costs), s, self.curve._x[-1]))

    def _step(self, q: int) -> int:
        if self._Tp is None:
            raise ValueError("OPW needs target frames with positions")
        now = q / self.fps
        while self._k * self.omega <= now + _EPS:
            t = self._k * self.omega
            self._k += 1
            if t >= self.curve._x[-1]:  # the recording has been played out
                continue
            self._opw_step(t, q)
        m = int(round(self.curve.value(now) * self.fps_A))
        return min(max(m, 0), self.m)

    # -- inspection -----------------------------------------------------------------------
    def decision_table(self) -> dict:
        """The decisions as arrays.

        Returns
        -------
        table : dict
            ``t`` (N,), ``t_warped`` (N,), ``costs`` (N, 3), ``s`` (N,) int, ``x_last`` (N,).
        """
        d = self.decisions
        return {
            "t": np.array([e.t for e in d], dtype=float),
            "t_warped": np.array([e.t_warped for e in d], dtype=float),
            "costs": np.array([e.costs for e in d], dtype=float).reshape(len(d), 3),
            "s": np.array([e.s for e in d], dtype=np.int64),
            "x_last": np.array([e.x_last for e in d], dtype=float),
        }


__all__ = ["OPW", "OPWDecision", "interpolate_positions"]
