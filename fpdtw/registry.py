"""One registry: every alignment algorithm by name, and how to run it.

Names follow the papers' figures: ``"DTW"``, ``"UTW"``, ``"OE-DTW"``, ``"OPW"``, ``"OLTW
c60"`` (Dixon's search width), ``"Ma"``, ``"Mb w40"``, ``"Mc w40"``; the suffix ``" + Type
V"``; non-default options in brackets by their labels in the class's ``options`` table
(``"Mc w40 (literal window) + Type V"``, ``"OLTW (weighted joints)"``); beyond the papers
``"Mc auto"`` and ``"OPW adaptive"``, and for any online name the options ``"derivative"``
(``"OPW (derivative)"``) and ``"relocate"`` (``"Mc w40 (relocate)"``,
:mod:`fpdtw.online.relocate`). :func:`resolve` turns a name into an :class:`Algorithm`,
:func:`make_online` builds its aligner, :func:`align` runs a pair.

Adding an aligner: its class and one :class:`Entry` in :data:`ENTRIES` (docs/layout.md).

Notebook: 11_fig9_typev.ipynb
"""

from __future__ import annotations

import importlib
import inspect
import re
from dataclasses import dataclass, field

import numpy as np

from fpdtw.derivative import DerivativeAligner, derivative_features
from fpdtw.dtw import dtw_pair, utw_map
from fpdtw.errors import AlignmentError
from fpdtw.motion.features import MotionFeatures
from fpdtw.online import MethodC
from fpdtw.online.base import run_online
from fpdtw.online.relocate import Relocating

#: Suffix of the Type V constraint in names.
TYPE_V_SUFFIX = " + Type V"
#: The general options (any online entry): run on derivative motions (:mod:`fpdtw.derivative`);
#: search the whole input beside the method and jump (:mod:`fpdtw.online.relocate`).
DERIVATIVE, RELOCATE = "derivative", "relocate"


def _dtw(I: MotionFeatures, T: MotionFeatures):
    return dtw_pair(I, T).map


def _utw(I: MotionFeatures, T: MotionFeatures):
    return utw_map(I.n_frames - 1, T.n_frames - 1)


def _import(target: str):
    """``"fpdtw.online.oltw:OLTW"`` -> the class (imported when first needed)."""
    module, _, attr = target.partition(":")
    return getattr(importlib.import_module(module), attr)


def online(target: str):
    """Builder of an online aligner class ``"module:Class"``: ``Class(I)``, or ``Class(I,
    value)`` for a name with a parameter (``"OLTW c60"``), the name's options as keywords."""

    def build(I, value=None, options=None, **_):
        cls = _import(target)
        opts = dict(options or {})
        return cls(I, **opts) if value is None else cls(I, value, **opts)

    build.target, build.window = target, False
    return build


def window_method(target: str):
    """Builder of an FP-DTW window method (``Class(I, w, constraint=..., **options)``)."""

    def build(I, value, typev=False, options=None, cache=None, record=False):
        cls = _import(target)
        opts = dict(options or {})
        if "cache" in inspect.signature(cls).parameters:
            opts["cache"] = cache
        return cls(I, value, constraint="typeV" if typev else None, record=record, **opts)

    build.target, build.window = target, True
    return build


@dataclass(frozen=True)
class Entry:
    """One algorithm family of the registry.

    Attributes
    ----------
    key, family, cli : str
        Its name or names' start (``"Mc"``), short code for tables (``"C"``), ``--method``.
    online : bool
    build : callable
        Online: ``build(I, value=..., typev=..., options=..., cache=..., record=...)``
        returns the aligner; offline: ``build(I, T)`` returns the map.
    param : str or None
        Letter of its numeric parameter in names (``"w"``: window, ``"c"``: band width).
    default : int or None
        The parameter's value when a name leaves it out (None: a name must give it).
    typev : bool
        Takes the Type V constraint.
    about : str
        One line for ``fpdtw --help``.
    baseline : bool
        An online method beyond the FP-DTW paper run on its pairs (:func:`baselines`).
    """

    key: str
    family: str
    cli: str
    online: bool
    build: object = field(repr=False)
    param: str | None = None
    default: int | None = None
    typev: bool = False
    about: str = ""
    baseline: bool = False

    @property
    def window_method(self) -> bool:
        """An FP-DTW window method (options in names, a window cache, snapshots)."""
        return getattr(self.build, "window", False)

    @property
    def aligner_class(self):
        """The online aligner's class (None for an offline algorithm)."""
        target = getattr(self.build, "target", None)
        return None if target is None else _import(target)


#: Every algorithm family, in the order of the papers' figures and the command line.
ENTRIES = (
    Entry("DTW", "DTW", "dtw", False, _dtw,
          about="offline DTW over the whole motions (the reference the papers compare with)"),
    Entry("UTW", "UTW", "utw", False, _utw,
          about="uniform time warping: stretch the input linearly (offline)"),
    Entry("OE-DTW", "OE", "oe-dtw", True, online("fpdtw.online.oedtw:OEDTW"),
          about="open-end DTW, online (its answer can jump backwards)"),
    Entry("Ma", "A", "a", True, window_method("fpdtw.online.method_a:MethodA"), "w", 2, True,
          "FP-DTW Method A: greedy window of 2 frames (online)"),
    Entry("Mb", "B", "b", True, window_method("fpdtw.online.method_b:MethodB"), "w", None, True,
          "FP-DTW Method B: forecast window, forward DTW path (online; --window)"),
    Entry("Mc", "C", "c", True, window_method("fpdtw.online.method_c:MethodC"), "w", None, True,
          "FP-DTW Method C: forecast window, reverse accumulation (online; --window)"),
    Entry("Mc auto", "Cauto", "c-auto", True, online("fpdtw.online.method_c_auto:MethodCAuto"),
          about="Method C with w from the input's dominant period (beyond the papers; online)"),
    Entry("OPW", "OPW", "opw", True, online("fpdtw.online.opw:OPW"),
          about="On-line Predictive Warping (the OPW poster; online, joint positions)",
          baseline=True),
    Entry("OPW adaptive", "OPWa", "opw-adaptive", True,
          online("fpdtw.online.opw_adaptive:AdaptiveOPW"),
          about="OPW with gamma adapted from its own decisions (beyond the papers; online)"),
    Entry("OLTW", "OLTW", "oltw", True, online("fpdtw.online.oltw:OLTW"), "c", 120,
          about="Dixon's on-line time warping (DAFx 2005; online; --window = search width c)",
          baseline=True),
)  # fmt: skip

_BY_KEY = {e.key: e for e in ENTRIES}


def baselines() -> tuple:
    """The names of the :attr:`Entry.baseline` entries in registry order (``("OPW",
    "OLTW")``), read from :data:`ENTRIES` at each call: what the grid, Figs. 5-7, Table 2's
    benchmark and claim B1 add to the paper's algorithms.

    Paper: none (the FP-DTW paper's ref. 3 and the OPW poster, run on its pairs).
    Notebook: 05_run_experiments.ipynb
    """
    return tuple(e.key for e in ENTRIES if e.baseline)


_PATTERN = re.compile(
    r"^(?P<key>[A-Za-z][A-Za-z-]*(?: auto| adaptive)?)(?: (?P<p>[a-z])(?P<n>\d+))?"
    r"(?: \((?P<opts>[^()]+)\))?"
    r"(?P<tv> \+ Type V)?$"
)


@dataclass(frozen=True)
class Algorithm:
    """A resolved name (as given): its entry, ``value`` (the window ``w`` or band width
    ``c``), Type V, non-default ``options`` (``{"window": "literal"}``), whether it runs
    on derivative motions (:class:`fpdtw.derivative.DerivativeAligner`) and whether it
    relocates (:class:`fpdtw.online.relocate.Relocating`)."""

    name: str
    entry: Entry
    value: int | None
    typev: bool
    options: dict
    derivative: bool = False
    relocate: bool = False

    @property
    def family(self) -> str:
        return self.entry.family

    @property
    def online(self) -> bool:
        return self.entry.online

    @property
    def w(self) -> int | None:
        """The window of an FP-DTW method (None for the others)."""
        return self.value if self.entry.param == "w" else None

    @property
    def shares_window(self) -> bool:
        """Methods B and C on poses, not relocating: their window costs can be shared (a
        WindowCache, in one compiled loop that has no relocating search)."""
        return self.family in ("B", "C") and not (self.derivative or self.relocate)

    def make(self, I: MotionFeatures, *, cache=None, record=False):
        """The streaming aligner of an online algorithm, for the input motion ``I``."""
        if not self.online:
            raise AlignmentError(f"{self.name!r} is offline: it has no streaming aligner")
        kw = dict(value=self.value, typev=self.typev, options=self.options)

        def build(J, cache=None):
            if self.derivative:
                inner = self.entry.build(derivative_features(J), cache=None, record=record, **kw)
                return DerivativeAligner(J, inner)
            return self.entry.build(J, cache=cache, record=record, **kw)

        if self.relocate:
            return Relocating(I, build, name=self.name)
        return build(I, cache)

    def run(self, I: MotionFeatures, T: MotionFeatures):
        """``(M, seconds)``: the map of the pair and, online, the time of each step."""
        if not self.online:
            return np.asarray(self.entry.build(I, T), dtype=np.int64), None
        M, seconds = run_online(self.make(I), T)
        return np.asarray(M, dtype=np.int64), seconds


def _general(entry: Entry, text: str, name: str) -> tuple:
    """``(derivative, relocate, rest)``: the general options taken out of a bracket's labels."""
    labels = [x.strip() for x in text.split(",")]
    found = []
    for option in (DERIVATIVE, RELOCATE):
        found.append(option in labels)
        if not found[-1]:
            continue
        if labels.count(option) > 1:
            raise AlignmentError(f"{name!r}: option {option!r} given twice")
        if not entry.online:
            raise AlignmentError(
                f"{name!r}: {entry.key} is offline; option {option!r} wraps online aligners only"
            )
        labels.remove(option)
    return found[0], found[1], ", ".join(labels)


def _options(entry: Entry, text: str, name: str) -> dict:
    """The options in brackets, by the labels of the class's ``options`` table: a window
    method's, or one a class defines itself (not inherits: ``"Mc auto"``)."""
    cls = entry.aligner_class
    own = cls is not None and "options" in vars(cls)
    if not (entry.window_method or own):
        if entry.online:
            raise AlignmentError(
                f"{name!r}: unknown option {text!r}; {entry.key} has no options but "
                f"{DERIVATIVE!r} and {RELOCATE!r}"
            )
        raise AlignmentError(f"{name!r}: {entry.key} has no options")
    table = cls.options
    by_label = {lab: (key, val) for key, (_, vals) in table.items() for val, lab in vals.items()}
    out = {}
    for label in (x.strip() for x in text.split(",")):
        if label not in by_label:
            known = ", ".join(repr(x) for x in (*by_label, DERIVATIVE, RELOCATE))
            raise AlignmentError(f"{name!r}: unknown option {label!r} (known: {known})")
        key, value = by_label[label]
        if key in out:
            raise AlignmentError(f"{name!r}: two values for {key}")
        out[key] = value
    return out


def resolve(name: str) -> Algorithm:
    """The :class:`Algorithm` a name stands for.

    Raises
    ------
    AlignmentError
        An unknown name, a missing or unexpected parameter, an unknown option, or Type V
        on an algorithm that does not take it.
    """
    m = _PATTERN.match(name) if isinstance(name, str) else None
    entry = _BY_KEY.get(m.group("key")) if m else None
    if entry is None:
        known = ", ".join(e.key for e in ENTRIES)
        raise AlignmentError(
            f"unknown algorithm {name!r}; known: {known} (e.g. 'Mc w40 + Type V', "
            "'Mc w40 (literal window)', 'OLTW c60')"
        )
    value = entry.default
    if m.group("p"):
        if m.group("p") != entry.param:
            raise AlignmentError(f"{name!r}: {entry.key} takes no parameter {m.group('p')!r}")
        value = int(m.group("n"))
    elif entry.param and value is None:
        raise AlignmentError(f"{name!r}: {entry.key} needs a window, e.g. '{entry.key} w40'")
    if m.group("tv") and not entry.typev:
        raise AlignmentError(f"{name!r}: {entry.key} does not take the Type V constraint")
    general = _general(entry, m.group("opts"), name) if m.group("opts") else (False, False, "")
    derivative, relocate, opts = general
    options = _options(entry, opts, name) if opts else {}
    return Algorithm(name, entry, value, bool(m.group("tv")), options, derivative, relocate)


def with_option(name: str, label: str) -> str:
    """``name`` with one more bracketed option: ``with_option("Mc w40 + Type V", "relocate")``
    -> ``"Mc w40 (relocate) + Type V"``; ``"Mc w40 (literal window)"`` -> ``"Mc w40 (literal
    window, relocate)"``."""
    tv = TYPE_V_SUFFIX if name.endswith(TYPE_V_SUFFIX) else ""
    base = name[: len(name) - len(tv)]
    return f"{base[:-1]}, {label}){tv}" if base.endswith(")") else f"{base} ({label}){tv}"


def by_cli(method: str) -> Entry:
    """The entry of a command-line ``--method`` value."""
    for e in ENTRIES:
        if e.cli == method:
            return e
    raise AlignmentError(f"unknown method {method!r}; known: {', '.join(e.cli for e in ENTRIES)}")


def name(key: str, value=None, typev: bool = False, **options) -> str:
    """The canonical name of a configuration: ``name("Mc", 40, window="literal")`` ->
    ``"Mc w40 (literal window)"``, ``name("OLTW", 60)`` -> ``"OLTW c60"``."""
    entry = _BY_KEY.get(key)
    if entry is None:
        raise AlignmentError(f"unknown algorithm {key!r}")
    if entry.window_method:
        w = entry.default if value is None else value
        return entry.aligner_class.name_for(w, typev, **options)
    if typev or options:
        raise AlignmentError(f"{key} takes neither Type V nor options")
    if entry.param and value is not None and value != entry.default:
        return f"{key} {entry.param}{value}"
    return key


def method_c_name(w: int, window: str = "square", typev: bool = False, **options) -> str:
    """``method_c_name(40, "literal")`` -> ``"Mc w40 (literal window)"``."""
    return name("Mc", w, typev, window=window, **options)


def make_online(name: str, I: MotionFeatures, *, record=False, cache=None):
    """The streaming aligner called ``name`` for the input ``I``; ``record`` keeps the last
    window (FP-DTW methods), ``cache`` (:class:`fpdtw.online.window.WindowCache`) is shared
    by Methods B and C stepping together."""
    return resolve(name).make(I, cache=cache, record=record)


def align(name: str, I: MotionFeatures, T: MotionFeatures):
    """Map every target frame to an input frame with the algorithm ``name``.

    Returns
    -------
    M : ndarray of int64, shape (n + 1,)
    seconds : ndarray of float64, shape (n + 1,) or None
        Per-frame processing time (online algorithms only).

    Paper: FP-DTW Sections 3-6.
    Notebook: 11_fig9_typev.ipynb
    """
    return resolve(name).run(I, T)


#: Method C's readings of Algorithm 3's window, the default first (:class:`fpdtw.online.MethodC`).
C_READINGS = (MethodC.options["window"][0], *MethodC.options["window"][1])
