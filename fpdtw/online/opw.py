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
   This is the reading of eq. 4 (``read_at="eq4"``, the default). Algorithm 1's lines
   2-3 take the sample times ``{t - omega, t, t + omega, t + 2 omega}`` and "unwarp" them
   through ``f``, so line 8 reads A at ``f(t + i omega)`` (``read_at="listing"``). The two
   agree where the curve's slope is 1 and differ elsewhere
   (:func:`fpdtw.paper.opw_eval.read_at_table` measures both on the poster's protocol).
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
mapped never see a jump.

**The plugin reading** (``reading="plugin"``): the authors' only public OPW code is
their MotionBuilder plugin (matRandall/realTimeDTW, ``ortoolDTWManager_tool.cxx``, its
``EventHandler``). It agrees with the reading above on the forecast (constant velocity,
one period ahead), the cost (eq. 5 over 16 effectors), the strict inequalities of item 5
and the key change of item 6 (``+gamma`` when the current sample is closest: the last key
moves later, the recording slows down). It differs in two mechanisms, each an option:

* ``reference="ratio"``: item 4 reads A at ``(t + i omega) * r``, ``r = D_A / x_last``
  (the curve's start length over its current end: one global rate), not at
  ``f(t) + i omega`` through the curve.
* ``clock="frames"``: item 2 steps at the first live frame whose time is STRICTLY later
  than the previous step's time plus ``omega`` (the plugin's playback callback), at that
  frame's time: at 120 Hz every 5th frame (41.7 ms), at 30 Hz every 2nd (66.7 ms).

It also compares the effectors' positions in the control rig's reference space (world
positions, the root's travel included), not root-relative ones: that is a property of the
features, chosen by the caller (:func:`fpdtw.paper.opw_eval.opw_features`). The plugin
keeps stepping after ``t >= x_last``, but there all three reference times lie at or past
the recording's end, whose pose is held, so the costs tie and nothing changes: item 7 is
the same. The plugin's readme states the opposite direction (current sample closest:
speed the recording up); ``direction="readme"`` runs it.

Because the key slopes are automatic (F-curve style), a new key also changes the slope
at the previous key, i.e. the shape of the PAST segment of the final curve slightly; the
realised online map is :attr:`OPW.M` (what was output), the final curve is
:attr:`OPW.curve` (what the poster evaluates). Both readings use the same
:class:`~fpdtw.warpcurve.WarpCurve` (the plugin's curve is MotionBuilder's own F-curve,
whose automatic tangents are not published).
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
    """One OPW step at live time ``t`` with the plugin's options; changes ``f`` in place.

    Parameters
    ----------
    f : WarpCurve
    t, omega, gamma, fps_A, fps_B : float
    A : ndarray of float, shape (F_A, p, 3)
        The recording's positions.
    B : ndarray of float, shape (F_B, p, 3)
        The live positions received so far.
    reference : {"curve", "ratio"}
        ``"curve"``: A read through the curve (:func:`fpdtw.plain.opw_times`, ``read_at``);
        ``"ratio"`` (the plugin): at ``(t + i omega) r``, ``r = D_A / x_last`` (the
        recording's duration, the last key's value, over the last key's live time).
    direction : {"code", "readme"}
        ``"code"``: ``s = 0`` slows ``A`` down (eq. 1's bullets, the plugin's code);
        ``"readme"``: ``s = 0`` speeds it up (the plugin's readme).
    read_at : {"eq4", "listing"}
        With ``reference="curve"``: ``f(t) + i omega`` (eq. 4, default) or ``f(t + i
        omega)`` (Algorithm 1, lines 2-3).

    Returns
    -------
    s : int
    p : list of float, length 3

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
    reading : {"poster", "plugin"}
        ``"poster"`` (default): the poster's text (module doc, items 1-8);
        ``"plugin"``: the authors' MotionBuilder plugin, ``reference="ratio"`` and
        ``clock="frames"``.
    reference : {"curve", "ratio"}, optional
        Overrides the reading's: where the recording is read
        (:func:`opw_step`).
    clock : {"exact", "frames"}, optional
        Overrides the reading's: steps at ``t = k omega`` (``"exact"``) or at the first
        live frame strictly after the previous step plus ``omega`` (``"frames"``).
    direction : {"code", "readme"}
        ``"code"``: the current sample closest slows the recording down (eq. 1's
        bullets, the plugin's code); ``"readme"``: it speeds it up (the plugin's readme).
    read_at : {"eq4", "listing"}
        With ``reference="curve"``, where the recording is read
        (:func:`fpdtw.plain.opw_times`): ``"eq4"`` (default), ``f(t) + i omega``, the
        poster's eq. 4; ``"listing"``, ``f(t + i omega)``, Algorithm 1's lines 2-3.

    Attributes
    ----------
    curve : WarpCurve
        The time-warp curve built so far (live time -> recording time).
    decisions : list of OPWDecision
        One per OPW step performed.

    Each step is :func:`opw_step` (plain Python and NumPy: a step every 40 ms needs no
    compiled kernel), which with the poster's options is :func:`fpdtw.plain.opw_step`.

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

    # -- one OPW step ---------------------------------------------------------------------
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


__all__ = ["OPW", "OPWDecision", "READINGS", "interpolate_positions", "opw_step"]
