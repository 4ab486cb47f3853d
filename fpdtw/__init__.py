"""fpdtw: online alignment of human motion (FP-DTW, Randall et al. 2023, and OPW).

The public API: motions (:class:`Motion`, :func:`load_motion`, :class:`MotionFeatures`,
:class:`LiveTarget`, the joint sets :data:`PAPER_JOINTS` and :data:`OPW_JOINTS`); costs and
offline alignment (:func:`geo_distance`, :func:`dtw_pair`, :func:`utw_map`); the online
aligners behind one streaming interface (:class:`OnlineAligner`, :class:`MethodC`,
:class:`OPW`, :class:`OLTW`, ...; :func:`make_online` and :func:`align` take the papers'
names, "Mc w40 + Type V"); the metrics :func:`similarity` (eq. 2) and :func:`deviation`
(eq. 3); the OPW :class:`WarpCurve`; beyond the papers :func:`auto_window`,
:func:`joint_weights`, :class:`AdaptiveOPW` and :func:`derivative_features`; the errors
(all :class:`FpdtwError`). :mod:`fpdtw.plain`: the papers' equations in plain NumPy.
"""

from fpdtw import plain
from fpdtw.costs import geo_distance, geodesic_cost_matrix, position_cost_matrix
from fpdtw.derivative import derivative_features
from fpdtw.dtw import dtw, dtw_pair, utw_map
from fpdtw.errors import AlignmentError, FpdtwError, MotionFormatError
from fpdtw.io import load_motion
from fpdtw.metrics import deviation, similarity
from fpdtw.motion.features import Frame, MotionFeatures
from fpdtw.motion.joints import OPW_JOINTS, PAPER_JOINTS
from fpdtw.motion.motion import Motion, Skeleton
from fpdtw.motion.stream import LiveTarget
from fpdtw.online import (
    OEDTW,
    OLTW,
    OPW,
    MethodA,
    MethodB,
    MethodC,
    OnlineAligner,
    TypeV,
    run_online,
)
from fpdtw.online.opw_adaptive import AdaptiveOPW
from fpdtw.period import auto_window, dominant_period
from fpdtw.registry import align, make_online
from fpdtw.warpcurve import WarpCurve
from fpdtw.weights import joint_weights

__version__ = "0.1.0"

__all__ = ["OEDTW", "OLTW", "OPW", "OPW_JOINTS", "PAPER_JOINTS", "AlignmentError",
           "FpdtwError", "Frame", "LiveTarget",
           "MethodA", "MethodB", "MethodC", "Motion", "MotionFeatures",
           "MotionFormatError", "OnlineAligner", "Skeleton", "TypeV", "WarpCurve",
           "align", "derivative_features", "deviation", "dtw", "dtw_pair",
           "geo_distance", "geodesic_cost_matrix", "joint_weights", "load_motion",
           "make_online", "plain", "position_cost_matrix", "run_online", "similarity",
           "utw_map", "AdaptiveOPW", "auto_window", "dominant_period"]  # fmt: skip
