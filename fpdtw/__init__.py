"""fpdtw: online alignment of human motion (FP-DTW, Randall et al. 2023, and OPW).

The public API, by what it holds:

* motions: :class:`Motion`, :class:`Skeleton`, :func:`load_motion`, the joint sets
  :data:`PAPER_JOINTS` (8) and :data:`OPW_JOINTS` (16), :class:`MotionFeatures`,
  :class:`LiveTarget` (a motion arriving frame by frame: lost frames, other rates);
* costs and offline alignment: :func:`geo_distance`, :func:`geodesic_cost_matrix`,
  :func:`position_cost_matrix`, :func:`dtw`, :func:`dtw_pair`, :func:`utw_map`;
* online aligners (one streaming interface, :meth:`OnlineAligner.step`):
  :class:`OEDTW`, :class:`MethodA`, :class:`MethodB`, :class:`MethodC`, :class:`OPW`,
  :class:`OLTW`, the :class:`TypeV` constraint, :func:`run_online`, and
  :func:`make_online` / :func:`align` by the paper's names ("Mc w40 + Type V");
* beyond the papers (the questions they leave open): :func:`dominant_period` and
  :func:`auto_window` (Method C's window from the input's period, "Mc auto");
  :func:`joint_weights` (eq. 1's joints weighted by their travel in the recording,
  "Mc w40 (weighted joints)"); the global bands ("Mc w40 (band 1 s)", which masks, and
  "Mc w40 (band w/2)", which computes only the window's rows inside it); :class:`AdaptiveOPW`
  (OPW's gamma from its own decisions); :func:`derivative_features` (derivative motions; any
  online name with the option ``"derivative"`` runs on them, "OPW (derivative)");
  :func:`insert_pause` (a held pose inserted in a target);
* metrics: :func:`similarity` (eq. 2), :func:`deviation` (eq. 3);
* the OPW warp curve: :class:`WarpCurve`;
* the papers' equations and algorithms in plain NumPy, line by line: :mod:`fpdtw.plain`
  (what the notebooks step through; the compiled aligners are tested equal to it);
* errors: :class:`MotionFormatError`, :class:`DataFetchError`, :class:`ManifestError`,
  :class:`AlignmentError` (all :class:`FpdtwError`).
"""

from fpdtw import plain
from fpdtw.costs import geo_distance, geodesic_cost_matrix, position_cost_matrix
from fpdtw.derivative import derivative_features
from fpdtw.dtw import dtw, dtw_pair, utw_map
from fpdtw.errors import (
    AlignmentError,
    DataFetchError,
    FpdtwError,
    ManifestError,
    MotionFormatError,
)
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
from fpdtw.pause import insert_pause
from fpdtw.period import auto_window, dominant_period
from fpdtw.registry import align, make_online
from fpdtw.warpcurve import WarpCurve
from fpdtw.weights import joint_weights

__version__ = "0.1.0"

__all__ = [
    "OEDTW",
    "OLTW",
    "OPW",
    "OPW_JOINTS",
    "PAPER_JOINTS",
    "AlignmentError",
    "DataFetchError",
    "FpdtwError",
    "Frame",
    "LiveTarget",
    "ManifestError",
    "MethodA",
    "MethodB",
    "MethodC",
    "Motion",
    "MotionFeatures",
    "MotionFormatError",
    "OnlineAligner",
    "Skeleton",
    "TypeV",
    "WarpCurve",
    "align",
    "derivative_features",
    "deviation",
    "dtw",
    "dtw_pair",
    "geo_distance",
    "geodesic_cost_matrix",
    "joint_weights",
    "load_motion",
    "make_online",
    "plain",
    "position_cost_matrix",
    "run_online",
    "similarity",
    "utw_map",
    "AdaptiveOPW",
    "insert_pause",
    "auto_window",
    "dominant_period",
]
