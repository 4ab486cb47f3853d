"""Every algorithm of the FP-DTW paper's evaluation, by the name the paper gives it.

Names follow the paper's figures: ``"DTW"``, ``"UTW"``, ``"OE-DTW"``, ``"Ma"``,
``"Mb w10"`` .. ``"Mb w80"``, ``"Mc w10"`` .. ``"Mc w80"``, and the constrained
variants with the suffix ``" + Type V"`` (e.g. ``"Mc w80 + Type V"``). An option other
than the default goes in brackets before the suffix, by its label in the method's
``options`` table: ``"Mc w40 (literal window) + Type V"``, ``"Mb w40 (hold forecast)"``.

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

#: Method C's readings of Algorithm 3's window (notebook 15), the default first; see
#: :class:`fpdtw.online.MethodC`.
C_READINGS = ("square", "literal", "square-tn", "open-end", "normalised")


def method_c_name(w: int, window: str = "square", typev: bool = False, **options) -> str:
    """Name of a Method C configuration: ``method_c_name(40, "literal")`` ->
    ``"Mc w40 (literal window)"``.

    Notebook: 15_readings_of_algorithm_3.ipynb
    """
    from .online import MethodC

    return MethodC.name_for(w, typev, window=window, **options)


#: The literal ``(w_i + 1) x w`` window of Method C at every w, without and with Type V
#: (the claims table shows its verdicts next to the default's).
MC_LITERAL_NAMES = tuple(method_c_name(w, "literal", t) for t in (False, True) for w in WINDOWS)

_PATTERN = re.compile(r"^(Ma|Mb|Mc)(?: w(\d+))?(?: \(([^()]+)\))?( \+ Type V)?$")


def _method_class(method: str):
    from .online import MethodA, MethodB, MethodC

    return {"A": MethodA, "B": MethodB, "C": MethodC}[method]


def parse_name(name: str):
    """Split ``"Mc w40 (literal window) + Type V"`` into ``("C", 40, True, options)``.

    Method A has w = 2 unless named. ``options`` maps option names to values (``{}``
    for the defaults), from the labels in the method class's ``options`` table.

    Raises
    ------
    AlignmentError
        For a name that is not an FP-DTW configuration.
    """
    m = _PATTERN.match(name)
    if not m:
        raise AlignmentError(
            f"unknown algorithm {name!r}; expected e.g. 'Ma', 'Mb w40', 'Mc w80 + Type V', "
            "'Mc w40 (literal window)'"
        )
    method = m.group(1)[1].upper()
    if method == "A":
        w = int(m.group(2)) if m.group(2) else 2
    else:
        if not m.group(2):
            raise AlignmentError(f"{name!r}: Methods B and C need a window, e.g. 'Mc w40'")
        w = int(m.group(2))
    options = {}
    if m.group(3):
        table = _method_class(method).options
        by_label = {
            label: (key, value) for key, (_, v) in table.items() for value, label in v.items()
        }
        for label in (x.strip() for x in m.group(3).split(",")):
            if label not in by_label:
                known = ", ".join(repr(x) for x in by_label)
                raise AlignmentError(f"{name!r}: unknown option {label!r} (known: {known})")
            key, value = by_label[label]
            if key in options:
                raise AlignmentError(f"{name!r}: two values for {key}")
            options[key] = value
    return method, w, bool(m.group(4)), options


def make_online(name: str, I: MotionFeatures, *, record=False, cache=None):
    """The online aligner called ``name``, for the input motion ``I``.

    Parameters
    ----------
    name : str
        ``"OE-DTW"`` or an FP-DTW configuration (see module docstring).
    I : MotionFeatures
        Input (recorded) motion.
    record : bool
        Keep the last window for inspection (FP-DTW methods only).
    cache : WindowCache, optional
        Shared by Methods B and C stepping together (see
        :class:`fpdtw.online.window.WindowCache`); ignored by the others.

    Returns
    -------
    aligner : OnlineAligner

    Notebook: 05_run_experiments.ipynb
    """
    from .online import OEDTW

    if name == "OE-DTW":
        return OEDTW(I)
    method, w, typev, options = parse_name(name)
    constraint = "typeV" if typev else None
    if method != "A":
        options["cache"] = cache
    return _method_class(method)(I, w, constraint=constraint, record=record, **options)


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
