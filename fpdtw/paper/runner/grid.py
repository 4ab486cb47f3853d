"""The experiment grid: which algorithms each mode runs (:func:`mode_algorithms`), by the
registry's names; ``"@60Hz"`` at the end runs one at 60 Hz, ``"@pause"`` on the targets with a
held pose inserted (:func:`fpdtw.paper.pause.insert_pause`), an edit's suffix
(:data:`EDIT_SUFFIXES`) on the targets with that edit (:func:`fpdtw.paper.edits.edit_target`).
"""

from __future__ import annotations

from typing import NamedTuple

from fpdtw import registry
from fpdtw.paper.edits import EDITS, edit_suffix
from fpdtw.paper.numbers import PAPER_NAMES, WINDOWS
from fpdtw.paper.runner.results import BASE_FPS, LOW_FPS, RATE_SUFFIX
from fpdtw.registry import C_READINGS, method_c_name

#: Method C's literal window at every w, without and with Type V.
MC_LITERAL_NAMES = tuple(method_c_name(w, "literal", t) for t in (False, True) for w in WINDOWS)
#: The algorithms of Table 1 at 60 Hz (DTW for the deviation, UTW for the benchmark).
TABLE1_60HZ_NAMES = ("DTW@60Hz", "UTW@60Hz", "Mc w10@60Hz", "Mc w20@60Hz", "Mc w40@60Hz",
                     "Mc w80@60Hz")  # fmt: skip
#: Method C's literal window at 120 Hz and, for Table 1, at 60 Hz (the claims' literal column).
LITERAL_NAMES = MC_LITERAL_NAMES + tuple(method_c_name(w, "literal") + "@60Hz" for w in WINDOWS)


def default_algorithms() -> tuple:
    """What modes "full" and "smoke" compute: the paper's algorithms, Table 1 at 60 Hz, the
    registry's baselines (read at each call: a new one joins) and Method C's literal window."""
    return tuple(PAPER_NAMES) + TABLE1_60HZ_NAMES + registry.baselines() + LITERAL_NAMES


#: :func:`default_algorithms` with the registry as built in (the names notebook 05 prints).
DEFAULT_ALGORITHMS = default_algorithms()


def _study_algorithms() -> tuple:
    """Notebook 15's grid: DTW and UTW, every reading of Algorithm 3 at every w with and
    without Type V (at 120 and 60 Hz), Methods A and B, and each silent choice on the
    algorithms it touches (Method C's also at 60 Hz, for Table 1)."""
    names = ["DTW", "UTW", "DTW@60Hz", "UTW@60Hz"]
    for rate in ("", "@60Hz"):
        for reading in C_READINGS:
            for typev in (False, True):
                names += [method_c_name(w, reading, typev) + rate for w in WINDOWS]
    names += [n for n in PAPER_NAMES if n.startswith(("Ma", "Mb"))]
    for choice in SILENT_CHOICES.values():
        if choice.option is not None:
            names += [choice_variant(n, choice) for n in choice_targets(choice)]
    for choice in SILENT_CHOICES.values():
        if choice.option is not None and "C" in choice.methods:
            names += [choice_variant(f"Mc w{w}", choice) + "@60Hz" for w in WINDOWS]
    return tuple(dict.fromkeys(names))


class SilentChoice(NamedTuple):
    """A choice the paper leaves open (notebook 15): what we do and the alternative, in
    words; ``option``: ``(aligner option, alternative value)``, or None for a choice of the
    metrics (recomputed from the stored maps); ``methods``: the letters it touches."""

    ours: str
    alternative: str
    option: tuple | None
    methods: str


#: The paper's silent choices, by key.
SILENT_CHOICES = {
    "ties": SilentChoice("ties go to the lowest offset (Methods A, C)",
                         "ties go to the highest offset", ("ties", "high"), "AC"),
    "backtrack": SilentChoice("Method B's back-track prefers the diagonal, then the target step",
                              "the diagonal, then the input step", ("backtrack", "input-first"),
                              "B"),
    "forecast": SilentChoice("dead reckoning in Euler angles (the paper)",
                             "zero-order hold: every forecast frame is T_{n+1}",
                             ("forecast", "hold"), "BC"),
    "forecast_start": SilentChoice("Method C's forecast window starts with T_{n+1} itself",
                                   "it starts with the first prediction T^_{n+2}",
                                   ("forecast_start", "next"), "C"),
    "start": SilentChoice("M_0 = 0 (both motions start together)",
                          "M_0 = the best match of T_0 among I_0..I_w", ("start", "best"), "ABC"),
    "deviation_frames": SilentChoice("eq. 3 averages over the n frames q = 1..n, as printed",
                                     "over all n + 1 target frames q = 0..n", None, "ABC"),
    "flat_axis": SilentChoice("eq. 2: an axis flat in only one motion scores 0",
                              "such an axis is left out of the average", None, "ABC"),
    "after_input": SilentChoice(
        "once the input is exhausted the map holds at m (forced, even under Type V), "
        "and those frames are scored",
        "frames after the first frame mapped to m are not scored", None, "ABC"),
}  # fmt: skip


def choice_targets(choice: SilentChoice) -> list:
    """The algorithms a silent choice is run on: every FP-DTW configuration of the paper at
    120 Hz of the methods it touches (the robustness column of the claims table)."""
    return [n for m in choice.methods for n in PAPER_NAMES if n.startswith(f"M{m.lower()}")]


def choice_variant(name: str, choice: SilentChoice) -> str:
    """``name`` with the choice's alternative option: ``"Mc w40"`` -> ``"Mc w40 (ties high)"``."""
    a = registry.resolve(name)
    key, value = choice.option
    return registry.name(a.entry.key, a.value, a.typev, **{**a.options, key: value})


#: What notebook 15 computes by default (modes "study" and "smoke-study").
STUDY_ALGORITHMS = _study_algorithms()

#: Suffix of a name run on targets with a pause inserted (:func:`fpdtw.paper.pause.insert_pause`).
PAUSE_SUFFIX = "@pause"
#: Q1 (the window from the input's period): Mc auto beside every fixed window, 120 and 60 Hz.
OPEN_Q1 = tuple(
    n + rate for rate in ("", RATE_SUFFIX) for n in ("Mc auto", *(f"Mc w{w}" for w in WINDOWS))
)
#: Q6 (standing still): every online method of the papers, with and without a pause.
PAUSE_METHODS = (
    "Ma", "Ma + Type V", "Mb w40", "Mc w40", "Mc w80", "Mc w80 + Type V", "OE-DTW", "OLTW", "OPW",
)  # fmt: skip
OPEN_Q6 = ("DTW" + PAUSE_SUFFIX, *PAUSE_METHODS, *(n + PAUSE_SUFFIX for n in PAUSE_METHODS))
#: Q7 (a performer who skips, repeats or starts again): suffix -> edit of
#: :data:`fpdtw.paper.edits.EDITS`.
EDIT_SUFFIXES = {edit_suffix(e): e for e in EDITS}
#: Q7's methods: Q6's online methods, each without and with the relocating search.
EDIT_METHODS = tuple(m for n in PAUSE_METHODS for m in (n, registry.with_option(n, "relocate")))
OPEN_Q7 = (*EDIT_METHODS, *(n + s for s in EDIT_SUFFIXES for n in EDIT_METHODS))
#: Q3 (a global band around the diagonal): Methods B and C with the band of 1 s (the first
#: reading, which masks) and with the band of half the window (the claim's band; its rule
#: chosen on 2026-11-24, after the 1 s band's results were seen and before any run of it).
BAND_BASES = ("Mb w40", "Mc w40", "Mc w80")
#: The labels of Q3's two bands in names, the first reading first.
BAND_1S, BAND_HALF_W = "band 1 s", "band w/2"
BAND_NAMES = tuple(f"{n} ({band})" for band in (BAND_1S, BAND_HALF_W) for n in BAND_BASES)
OPEN_Q3 = BAND_BASES + BAND_NAMES
#: Q4 (OPW's gamma from a feedback loop): OPW adaptive beside OPW at gamma 5 %.
OPEN_Q4 = ("OPW", "OPW adaptive")
#: Q2 (eq. 1's joints weighted by their travel in the input): each without and with weights.
WEIGHT_BASES = ("Mb w40", "Mc w40", "OLTW")
WEIGHT_SUFFIX = " (weighted joints)"
OPEN_Q2 = tuple(n for b in WEIGHT_BASES for n in (b, b + WEIGHT_SUFFIX))
#: Q5 (Keogh and Pazzani's derivative DTW, :mod:`fpdtw.derivative`): on poses and derivatives.
DERIVATIVE_BASES = ("Mc w40", "OPW")
OPEN_Q5 = tuple(n for b in DERIVATIVE_BASES for n in (b, f"{b} (derivative)"))
#: What notebook 16 computes by default (modes "open" and "smoke-open"): DTW and UTW at both
#: rates, then Q1, Q6, Q3, Q4, Q2, Q5, Q7 (the first of any duplicate kept).
OPEN_ALGORITHMS = tuple(
    dict.fromkeys(("DTW", "UTW", "DTW@60Hz", "UTW@60Hz", *OPEN_Q1, *OPEN_Q6, *OPEN_Q3, *OPEN_Q4,
                   *OPEN_Q2, *OPEN_Q5, *OPEN_Q7))
)  # fmt: skip
#: The default algorithm list of each mode but "full" and "smoke" (:func:`mode_algorithms`).
MODE_ALGORITHMS = {
    "study": STUDY_ALGORITHMS,
    "smoke-study": STUDY_ALGORITHMS,
    "open": OPEN_ALGORITHMS,
    "smoke-open": OPEN_ALGORITHMS,
}


def mode_algorithms(mode: str) -> tuple:
    """The default algorithm list of a mode: :data:`MODE_ALGORITHMS`, else
    :func:`default_algorithms`."""
    return MODE_ALGORITHMS.get(mode) or default_algorithms()


def split_rate(name: str) -> tuple:
    """``"Mc w40@60Hz"`` -> ``("Mc w40", 60.0)``; names without the suffix run at 120 Hz."""
    base = name.removesuffix(RATE_SUFFIX)
    return base, BASE_FPS if base == name else LOW_FPS


def split_transform(name: str) -> tuple:
    """``"Mc w40@pause"`` -> ``("Mc w40", "pause")``, ``"OLTW@cut1s"`` -> ``("OLTW", "cut 1
    s")`` (:data:`EDIT_SUFFIXES`); other names -> ``(name, None)``."""
    for suffix, edit in ((PAUSE_SUFFIX, PAUSE_SUFFIX[1:]), *EDIT_SUFFIXES.items()):
        if name.endswith(suffix):
            return name.removesuffix(suffix), edit
    return name, None
