"""Method C with its window from the input's dominant period ("Mc auto"; beyond the papers).

The FP-DTW conclusion's open question (the window below half the movement's period):
``w`` is :func:`fpdtw.period.auto_window` of the recording, fixed before the first frame.

Paper: FP-DTW Section 7 (conclusion) and Algorithm 3.
"""

from __future__ import annotations

from fpdtw.motion.features import MotionFeatures
from fpdtw.online.method_c import MethodC
from fpdtw.period import auto_window


class MethodCAuto(MethodC):
    """Method C whose ``w`` is :func:`fpdtw.period.auto_window` of the input.

    Fallback 40 frames at 120 Hz; the other arguments as
    :class:`~fpdtw.online.method_c.MethodC`'s.

    Paper: FP-DTW Section 7, Algorithm 3.
    """

    def __init__(self, I: MotionFeatures, *, constraint=None, record=False, cache=None, **options):
        super().__init__(
            I, auto_window(I), constraint=constraint, record=record, cache=cache, **options
        )
