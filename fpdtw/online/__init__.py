"""Online aligners behind one streaming interface (see :mod:`fpdtw.online.base`).

* :class:`OEDTW`: open-end DTW (Tormene et al. 2009), incremental.
* :class:`MethodA`, :class:`MethodB`, :class:`MethodC`: FP-DTW Algorithms 1-3.
* :class:`TypeV`: the forward Type V local constraint as a state table (Section 6).
* :class:`OPW`: On-line Predictive Warping (the OPW poster).
* :class:`OLTW`: Dixon's on-line time warping (DAFx 2005, the FP-DTW paper's ref. 3).
"""

from fpdtw.online.base import OnlineAligner, run_online, run_together
from fpdtw.online.method_a import MethodA
from fpdtw.online.method_b import MethodB
from fpdtw.online.method_c import MethodC
from fpdtw.online.oedtw import OEDTW
from fpdtw.online.oltw import OLTW
from fpdtw.online.opw import OPW, OPWDecision
from fpdtw.online.typev import TYPE_V, TypeV, is_legal_typev
from fpdtw.online.window import WindowCache, WindowSnapshot

__all__ = [
    "OEDTW",
    "OLTW",
    "OPW",
    "OPWDecision",
    "TYPE_V",
    "MethodA",
    "MethodB",
    "MethodC",
    "OnlineAligner",
    "TypeV",
    "WindowCache",
    "WindowSnapshot",
    "is_legal_typev",
    "run_online",
    "run_together",
]
