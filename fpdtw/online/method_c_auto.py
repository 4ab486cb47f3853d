"""Method C with its window set from the input's dominant period ("Mc auto").

An answer to an open question of the FP-DTW paper (its conclusion: the forecast window below
half the period of the movement cycle): the window is :func:`fpdtw.period.auto_window` of
the recorded input, fixed before the first target frame arrives; everything else is
:class:`~fpdtw.online.method_c.MethodC` with that window.

Paper: FP-DTW Section 7 (conclusion) and Algorithm 3.
"""

from __future__ import annotations

from fpdtw.motion.features import MotionFeatures
from fpdtw.online.method_c import MethodC
from fpdtw.period import auto_window


class MethodCAuto(MethodC):
    """Method C whose ``w`` is :func:`fpdtw.period.auto_window` of the input.

    Parameters
    ----------
    I : MotionFeatures
        Input (recorded) motion.
    constraint, record, cache, **options
        As for :class:`~fpdtw.online.method_c.MethodC`.

    Attributes
    ----------
    w : int
        The window chosen from the input's period (or the fallback, 40 frames at 120 Hz).

    Paper: FP-DTW Section 7, Algorithm 3.
    """

    def __init__(self, I: MotionFeatures, *, constraint=None, record=False, cache=None, **options):
        super().__init__(
            I, auto_window(I), constraint=constraint, record=record, cache=cache, **options
        )


__all__ = ["MethodCAuto"]
