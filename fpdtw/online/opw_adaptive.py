"""OPW with gamma adapted by a feedback loop on its own decisions ("OPW adaptive").

The OPW poster's conclusion suggests adjusting gamma "by a feedback loop measuring the
alignment as it is built". The rule (committed in 64f220a, 2026-11-23, before Q4's first
results in 81545c1, and unchanged since; docs/history.md):
gamma starts at :data:`GAMMA_START` (5 %, the poster's); after each OPW decision ``s``
(direction ``s - 1``: -1 slow the recording down, 0 keep, +1 speed it up):

* a keep (direction 0) changes nothing;
* if the last :data:`RUN` (3) decisions all have the same non-zero direction (the warp is
  too timid: it keeps correcting the same way), ``gamma *= 1.5``, at most :data:`GAMMA_MAX`
  (30 %);
* otherwise, if the last two NON-ZERO decisions have opposite signs (it overshoots),
  ``gamma /= 1.5``, at least :data:`GAMMA_MIN` (1 %).

Everything else is :class:`~fpdtw.online.opw.OPW` (the poster reading), a subclass: the new
gamma is used from the next step on.

Paper: OPW poster Section 6 (conclusion: gamma by a feedback loop).
Notebook: 16_open_questions.ipynb
"""

from __future__ import annotations

from fpdtw.online.opw import OPW

#: gamma at the start, its bounds, the factor and the run length of the rule.
GAMMA_START, GAMMA_MIN, GAMMA_MAX, FACTOR, RUN = 0.05, 0.01, 0.30, 1.5, 3


def next_gamma(gamma: float, decisions) -> float:
    """gamma after the latest of ``decisions`` (the rule of the module).

    Parameters
    ----------
    gamma : float
        gamma before it.
    decisions : sequence of int
        OPW's decisions ``s`` (0, 1, 2) so far, the latest last.

    Returns
    -------
    gamma : float

    Paper: OPW poster Section 6.
    Notebook: 16_open_questions.ipynb
    """
    d = [int(s) - 1 for s in decisions]
    if not d or d[-1] == 0:
        return gamma
    if len(d) >= RUN and len(set(d[-RUN:])) == 1:
        return min(gamma * FACTOR, GAMMA_MAX)
    nz = [x for x in d if x != 0]
    if len(nz) >= 2 and nz[-1] != nz[-2]:
        return max(gamma / FACTOR, GAMMA_MIN)
    return gamma


class AdaptiveOPW(OPW):
    """OPW (poster reading) whose gamma follows :func:`next_gamma` after every decision.

    Parameters
    ----------
    I : MotionFeatures
        The recording, with positions.
    omega, fps, reading, **options
        As for :class:`~fpdtw.online.opw.OPW`; gamma starts at :data:`GAMMA_START`.

    Attributes
    ----------
    gammas : list of float
        gamma used at each step.

    Paper: OPW poster Section 6, Algorithm 1.
    """

    name = "OPW adaptive"

    def __init__(self, I, omega: float = 0.04, fps=None, reading: str = "poster", **options):
        super().__init__(I, omega=omega, gamma=GAMMA_START, fps=fps, reading=reading, **options)

    def reset(self) -> None:
        super().reset()
        self.gamma = GAMMA_START
        self.gammas = []

    def _opw_step(self, t: float, last: int) -> None:
        self.gammas.append(self.gamma)
        super()._opw_step(t, last)
        self.gamma = next_gamma(self.gamma, [e.s for e in self.decisions[-8:]])


__all__ = ["FACTOR", "GAMMA_MAX", "GAMMA_MIN", "GAMMA_START", "RUN", "AdaptiveOPW", "next_gamma"]
