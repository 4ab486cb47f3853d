"""The experiment grid: which algorithms each mode runs, by the registry's names.

* mode ``"full"`` / ``"smoke"``: :data:`DEFAULT_ALGORITHMS`, the paper's evaluation
  (Figs. 5-7, 10, Table 1 at 60 Hz), Method C's literal window beside the default and
  the two online baselines beyond the paper (OPW, OLTW);
* mode ``"study"`` / ``"smoke-study"``: :data:`STUDY_ALGORITHMS`, notebook 15's readings of
  Algorithm 3 and the paper's silent choices (:data:`SILENT_CHOICES`).

* mode ``"open"`` / ``"smoke-open"``: :data:`OPEN_ALGORITHMS`, notebook 16's answers to
  the questions the papers leave open, with the baselines they are compared with.

A name ending in ``"@60Hz"`` runs the named algorithm on the motions resampled to 60 Hz; a
name ending in ``"@pause"`` runs it at 120 Hz on the targets with a held pose inserted
(:func:`fpdtw.pause.insert_pause`; its deviation is from DTW of the same modified pair).
"""

from __future__ import annotations

from typing import NamedTuple

from fpdtw import registry
from fpdtw.paper.numbers import PAPER_NAMES, WINDOWS
from fpdtw.paper.runner.results import BASE_FPS, LOW_FPS, RATE_SUFFIX
from fpdtw.registry import C_READINGS, method_c_name

#: Method C's literal window at every w, without and with Type V.
MC_LITERAL_NAMES = tuple(method_c_name(w, "literal", t) for t in (False, True) for w in WINDOWS)

#: The algorithms of Table 1 at 60 Hz (DTW for the deviation, UTW for the benchmark).
TABLE1_60HZ_NAMES = (
    "DTW@60Hz",
    "UTW@60Hz",
    "Mc w10@60Hz",
    "Mc w20@60Hz",
    "Mc w40@60Hz",
    "Mc w80@60Hz",
)
#: Method C's literal ``(w_i + 1) x w`` window, at 120 Hz (with and without Type V) and,
#: for Table 1, at 60 Hz: the claims table shows its verdicts next to the default's.
LITERAL_NAMES = MC_LITERAL_NAMES + tuple(method_c_name(w, "literal") + "@60Hz" for w in WINDOWS)


def default_algorithms() -> tuple:
    """What a run computes by default (modes "full" and "smoke"): the paper's algorithms,
    Table 1 at 60 Hz, the registry's online baselines beyond the FP-DTW paper
    (:func:`fpdtw.registry.baselines`: the OPW poster's method and Dixon's OLTW, the
    paper's ref. 3) and Method C's literal window. Read from the registry at each call: an
    aligner registered as a baseline joins the grid.

    Returns
    -------
    names : tuple of str
    """
    return tuple(PAPER_NAMES) + TABLE1_60HZ_NAMES + registry.baselines() + LITERAL_NAMES


#: :func:`default_algorithms` with the registry as built in (the names notebook 05 prints).
DEFAULT_ALGORITHMS = default_algorithms()


def _study_algorithms() -> tuple:
    """The algorithms of notebook 15 (modes "study" and "smoke-study").

    * DTW and UTW at 120 and 60 Hz (the references of deviation and similarity);
    * every reading of Algorithm 3 (:data:`fpdtw.registry.C_READINGS`) at every w,
      with and without Type V, at 120 and 60 Hz;
    * Methods A and B as in the paper (the headline medians on this selection);
    * the paper's silent choices (:data:`SILENT_CHOICES`), each on the algorithms it
      touches (:data:`CHOICE_TARGETS`), and on Method C at 60 Hz (Table 1).
    """
    names = ["DTW", "UTW", "DTW@60Hz", "UTW@60Hz"]
    for rate in ("", "@60Hz"):
        for reading in C_READINGS:
            for typev in (False, True):
                names += [method_c_name(w, reading, typev) + rate for w in WINDOWS]
    names += [n for n in PAPER_NAMES if n.startswith(("Ma", "Mb"))]
    for choice in SILENT_CHOICES.values():
        if choice.option is not None:
            names += [choice_variant(n, choice) for n in choice_targets(choice)]
    # Table 1's Method C at 60 Hz under each choice (claim 3's robustness)
    for choice in SILENT_CHOICES.values():
        if choice.option is not None and "C" in choice.methods:
            names += [choice_variant(f"Mc w{w}", choice) + "@60Hz" for w in WINDOWS]
    out = []
    for n in names:  # keep the first of any duplicate
        if n not in out:
            out.append(n)
    return tuple(out)


class SilentChoice(NamedTuple):
    """A choice the paper leaves open (notebook 15 measures how much each moves a result)."""

    #: What we do, in words.
    ours: str
    #: The other reading, in words.
    alternative: str
    #: ``(aligner option, alternative value)`` for choices that change the maps; None for
    #: choices of the metrics (recomputed from the stored maps).
    option: tuple | None
    #: The methods it touches (letters of A, B, C).
    methods: str


#: The paper's silent choices, by key.
SILENT_CHOICES = {
    "ties": SilentChoice(
        "ties go to the lowest offset (Methods A, C)",
        "ties go to the highest offset",
        ("ties", "high"), "AC",
    ),
    "backtrack": SilentChoice(
        "Method B's back-track prefers the diagonal, then the target step",
        "the diagonal, then the input step",
        ("backtrack", "input-first"), "B",
    ),
    "forecast": SilentChoice(
        "dead reckoning in Euler angles (the paper)",
        "zero-order hold: every forecast frame is T_{n+1}",
        ("forecast", "hold"), "BC",
    ),
    "forecast_start": SilentChoice(
        "Method C's forecast window starts with T_{n+1} itself",
        "it starts with the first prediction T^_{n+2}",
        ("forecast_start", "next"), "C",
    ),
    "start": SilentChoice(
        "M_0 = 0 (both motions start together)",
        "M_0 = the best match of T_0 among I_0..I_w",
        ("start", "best"), "ABC",
    ),
    "deviation_frames": SilentChoice(
        "eq. 3 averages over the n frames q = 1..n, as printed",
        "over all n + 1 target frames q = 0..n",
        None, "ABC",
    ),
    "flat_axis": SilentChoice(
        "eq. 2: an axis flat in only one motion scores 0",
        "such an axis is left out of the average",
        None, "ABC",
    ),
    "after_input": SilentChoice(
        "once the input is exhausted the map holds at m (forced, even under Type V), "
        "and those frames are scored",
        "frames after the first frame mapped to m are not scored",
        None, "ABC",
    ),
}  # fmt: skip

#: Per method, the algorithms a silent choice is run on: every FP-DTW configuration of the
#: paper (at 120 Hz), so that every claim about them can be decided under each choice
#: (the robustness column of the claims table).
CHOICE_TARGETS = {
    m: tuple(n for n in PAPER_NAMES if n.startswith(f"M{m.lower()}")) for m in ("A", "B", "C")
}


def choice_targets(choice: SilentChoice) -> list:
    """The algorithms of :data:`CHOICE_TARGETS` a silent choice touches."""
    return [n for method in choice.methods for n in CHOICE_TARGETS[method]]


def choice_variant(name: str, choice: SilentChoice) -> str:
    """``name`` with the choice's alternative option: ``"Mc w40"`` -> ``"Mc w40 (ties high)"``."""
    a = registry.resolve(name)
    key, value = choice.option
    return registry.name(a.entry.key, a.value, a.typev, **{**a.options, key: value})


#: What notebook 15 computes by default (modes "study" and "smoke-study").
STUDY_ALGORITHMS = _study_algorithms()

#: Suffix of a name run on the targets with a pause inserted (:func:`fpdtw.pause.insert_pause`).
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


#: Q3 (a global band around the diagonal): Methods B and C with the band of 1 s (the first
#: reading: it masks, and barely binds these windows) and with the band of half the window,
#: whose rows outside the band are not computed (the claim's band; its rule w/2 chosen on
#: 2026-11-24, after the 1 s band's results were seen and before any run of it).
BAND_BASES = ("Mb w40", "Mc w40", "Mc w80")
#: The labels of Q3's two bands in names, the first reading first.
BAND_1S, BAND_HALF_W = "band 1 s", "band w/2"
BAND_1S_NAMES = tuple(f"{n} ({BAND_1S})" for n in BAND_BASES)
BAND_HALF_W_NAMES = tuple(f"{n} ({BAND_HALF_W})" for n in BAND_BASES)
BAND_NAMES = BAND_1S_NAMES + BAND_HALF_W_NAMES
OPEN_Q3 = BAND_BASES + BAND_NAMES


#: Q4 (OPW's gamma from a feedback loop): OPW adaptive beside OPW at gamma 5 %.
OPEN_Q4 = ("OPW", "OPW adaptive")


#: Q2 (eq. 1's joints weighted by their travel in the input, :func:`fpdtw.weights.joint_weights`):
#: Methods B and C and OLTW, each without and with the weights.
WEIGHT_BASES = ("Mb w40", "Mc w40", "OLTW")
WEIGHT_SUFFIX = " (weighted joints)"
OPEN_Q2 = tuple(n for b in WEIGHT_BASES for n in (b, b + WEIGHT_SUFFIX))

#: Q5 (Keogh and Pazzani's derivative DTW): Method C and OPW on poses and on derivative motions
#: (:mod:`fpdtw.derivative`).
DERIVATIVE_BASES = ("Mc w40", "OPW")
OPEN_Q5 = tuple(n for b in DERIVATIVE_BASES for n in (b, f"{b} (derivative)"))


def _open_algorithms() -> tuple:
    """The algorithms of notebook 16 (modes "open" and "smoke-open"): DTW and UTW at 120
    and 60 Hz, then :data:`OPEN_Q1`, :data:`OPEN_Q6`, :data:`OPEN_Q3`, :data:`OPEN_Q4`,
    :data:`OPEN_Q2`, :data:`OPEN_Q5` (first of any duplicate kept)."""
    out = []
    lists = (*OPEN_Q1, *OPEN_Q6, *OPEN_Q3, *OPEN_Q4, *OPEN_Q2, *OPEN_Q5)
    for n in ("DTW", "UTW", "DTW@60Hz", "UTW@60Hz", *lists):
        if n not in out:
            out.append(n)
    return tuple(out)


#: What notebook 16 computes by default (modes "open" and "smoke-open").
OPEN_ALGORITHMS = _open_algorithms()
#: The default algorithm list of each mode but "full" and "smoke" (:func:`mode_algorithms`).
MODE_ALGORITHMS = {
    "study": STUDY_ALGORITHMS,
    "smoke-study": STUDY_ALGORITHMS,
    "open": OPEN_ALGORITHMS,
    "smoke-open": OPEN_ALGORITHMS,
}


def mode_algorithms(mode: str) -> tuple:
    """The default algorithm list of a mode: :data:`MODE_ALGORITHMS`, else
    :func:`default_algorithms` (modes "full" and "smoke", and any other)."""
    return MODE_ALGORITHMS.get(mode) or default_algorithms()


def split_rate(name: str) -> tuple:
    """``"Mc w40@60Hz"`` -> ``("Mc w40", 60.0)``; names without the suffix run at 120 Hz."""
    if name.endswith(RATE_SUFFIX):
        return name[: -len(RATE_SUFFIX)], LOW_FPS
    return name, BASE_FPS


def split_transform(name: str) -> tuple:
    """``"Mc w40@pause"`` -> ``("Mc w40", "pause")``; other names -> ``(name, None)``."""
    if name.endswith(PAUSE_SUFFIX):
        return name[: -len(PAUSE_SUFFIX)], PAUSE_SUFFIX[1:]
    return name, None


__all__ = [
    "CHOICE_TARGETS",
    "DEFAULT_ALGORITHMS",
    "default_algorithms",
    "mode_algorithms",
    "LITERAL_NAMES",
    "MC_LITERAL_NAMES",
    "MODE_ALGORITHMS",
    "BAND_1S",
    "BAND_1S_NAMES",
    "BAND_BASES",
    "BAND_HALF_W",
    "BAND_HALF_W_NAMES",
    "BAND_NAMES",
    "DERIVATIVE_BASES",
    "OPEN_ALGORITHMS",
    "OPEN_Q2",
    "OPEN_Q3",
    "OPEN_Q4",
    "OPEN_Q5",
    "OPEN_Q1",
    "OPEN_Q6",
    "PAUSE_METHODS",
    "PAUSE_SUFFIX",
    "WEIGHT_BASES",
    "WEIGHT_SUFFIX",
    "SILENT_CHOICES",
    "SilentChoice",
    "STUDY_ALGORITHMS",
    "TABLE1_60HZ_NAMES",
    "choice_targets",
    "choice_variant",
    "split_rate",
    "split_transform",
]
