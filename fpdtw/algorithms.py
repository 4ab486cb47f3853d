"""Every algorithm of the FP-DTW paper's evaluation, by the name the paper gives it.

Names follow the paper's figures: ``"DTW"``, ``"UTW"``, ``"OE-DTW"``, ``"Ma"``,
``"Mb w10"`` .. ``"Mb w80"``, ``"Mc w10"`` .. ``"Mc w80"``, and the constrained
variants with the suffix ``" + Type V"`` (e.g. ``"Mc w80 + Type V"``).

:func:`make_online` builds the online aligner of a name; :func:`align` runs any
algorithm (offline or online) over a pair and returns its map.
"""

from __future__ import annotations

import re

import numpy as np

from .errors import AlignmentError
from .features import MotionFeatures

WINDOWS = (10, 20, 40, 80)
TYPE_V_SUFFIX = " + Type V"

#: The online FP-DTW configurations of Figs. 5-7 and 10, unconstrained then constrained.
FPDTW_NAMES = tuple(["Ma"] + [f"Mb w{w}" for w in WINDOWS] + [f"Mc w{w}" for w in WINDOWS])
FPDTW_TYPEV_NAMES = tuple(n + TYPE_V_SUFFIX for n in FPDTW_NAMES)
#: Offline baselines.
OFFLINE_NAMES = ("DTW", "UTW")
#: Every algorithm of the paper's evaluation.
PAPER_NAMES = OFFLINE_NAMES + ("OE-DTW",) + FPDTW_NAMES + FPDTW_TYPEV_NAMES

_PATTERN = re.compile(r"^(Ma|Mb|Mc)(?: w(\d+))?( \+ Type V)?$")


def parse_name(name: str):
    """Split ``"Mc w40 + Type V"`` into ``("C", 40, True)``; Method A has w = 2.

    Raises
    ------
    AlignmentError
        For a name that is not an FP-DTW configuration.
    """
    m = _PATTERN.match(name)
    if not m:
        raise AlignmentError(
            f"unknown algorithm {name!r}; expected e.g. 'Ma', 'Mb w40', 'Mc w80 + Type V'"
        )
    method = m.group(1)[1].upper()
    if method == "A":
        w = int(m.group(2)) if m.group(2) else 2
    else:
        if not m.group(2):
            raise AlignmentError(f"{name!r}: Methods B and C need a window, e.g. 'Mc w40'")
        w = int(m.group(2))
    return method, w, bool(m.group(3))


def make_online(name: str, I: MotionFeatures, *, record=False):
    """The online aligner called ``name``, for the input motion ``I``.

    Parameters
    ----------
    name : str
        ``"OE-DTW"`` or an FP-DTW configuration (see module docstring).
    I : MotionFeatures
        Input (recorded) motion.
    record : bool
        Keep the last window for inspection (FP-DTW methods only).

    Returns
    -------
    aligner : OnlineAligner

    Notebook: 05_run_experiments.ipynb
    """
    from .online import OEDTW, MethodA, MethodB, MethodC

    if name == "OE-DTW":
        return OEDTW(I)
    method, w, typev = parse_name(name)
    constraint = "typeV" if typev else None
    cls = {"A": MethodA, "B": MethodB, "C": MethodC}[method]
    return cls(I, w, constraint=constraint, record=record)


def align(name: str, I: MotionFeatures, T: MotionFeatures):
    """Map every target frame to an input frame with the algorithm ``name``.

    Returns
    -------
    M : ndarray of int64, shape (n + 1,)
        Input frame of each target frame.
    seconds : ndarray of float64, shape (n + 1,) or None
        Per-frame processing time (online algorithms only).

    Paper: FP-DTW Sections 3-6.
    Notebook: 05_run_experiments.ipynb
    """
    from .dtw import dtw_pair, utw_map
    from .online.base import run_online

    if name == "DTW":
        return dtw_pair(I, T).map, None
    if name == "UTW":
        return utw_map(I.n_frames - 1, T.n_frames - 1), None
    M, seconds = run_online(make_online(name, I), T)
    return np.asarray(M, dtype=np.int64), seconds
