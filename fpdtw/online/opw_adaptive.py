"""OPW with gamma adapted by a feedback loop on its own decisions ("OPW adaptive").

The poster's conclusion suggests adjusting gamma "by a feedback loop measuring the
alignment as it is built". The rule, committed in 64f220a before Q4's first results in
81545c1 (docs/history.md): gamma starts at 5 %; after a non-zero decision (direction
``s - 1``), ``gamma *= 1.5`` (at most 30 %) if the last 3 all had that direction, else
``gamma /= 1.5`` (at least 1 %) if the last two non-zero ones differ in sign.

Paper: OPW poster Section 6 (conclusion: gamma by a feedback loop).
Notebook: 16_open_questions.ipynb
"""

from __future__ import annotations

from fpdtw.online.opw import OPW

#: gamma at the start, its bounds, the factor and the run length of the rule.
GAMMA_START, GAMMA_MIN, GAMMA_MAX, FACTOR, RUN = 0.05, 0.01, 0.30, 1.5, 3


def next_gamma(gamma: float, decisions) -> float:
    """gamma after the latest of ``decisions`` (OPW's ``s``, latest last; the module's rule).

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
    """OPW (poster reading) whose gamma follows :func:`next_gamma` from the next step on.

    Arguments as :class:`~fpdtw.online.opw.OPW`'s; ``gammas``: the gamma of each step.

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
