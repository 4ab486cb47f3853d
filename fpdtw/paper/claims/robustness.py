"""Does a verdict survive the paper's open readings? Each claim under every documented choice.

The paper leaves choices open that our implementation had to make (notebook 15 measures
each): how Algorithm 3's window is read, and silent choices of the methods and the metrics
(:data:`fpdtw.paper.runner.grid.SILENT_CHOICES`). The study run (mode ``"study"``, the
paper-shaped selection) holds every alternative for every FP-DTW configuration at 120 Hz.
:func:`robustness` decides every claim that rests on the pairs once with our choices and
once under each alternative (one change at a time, the same pairs, intervals and rules)
and reports, per claim, the share of alternatives under which the verdict stands and the
ones that flip it.

An alternative a claim cannot be decided under (its runs do not exist, e.g. the silent
choices at 60 Hz for Table 1, or OE-DTW, which the study does not run) is listed as not
run, not counted.

Paper: FP-DTW Algorithms 1-3, Sections 4-6 (the choices they leave open).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, field

from tqdm.auto import tqdm

from fpdtw.paper.claims.evidence import Evidence
from fpdtw.paper.claims.rules import NA
from fpdtw.paper.claims.types import ClaimContext, reading_alias
from fpdtw.paper.readings import choice_values, study_mode
from fpdtw.paper.runner import load_results
from fpdtw.paper.runner.grid import SILENT_CHOICES, choice_targets, choice_variant
from fpdtw.paper.runner.run import pair_features
from fpdtw.registry import C_READINGS


@dataclass(frozen=True)
class Alternative:
    """One documented reading other than ours.

    Attributes
    ----------
    key : str
        ``"window: literal"``, ``"forecast"``, ...
    label : str
        In words, as the robustness column shows it.
    alias : dict
        A claim's name -> the results of that name under the alternative.
    metric : str or None
        A metric-side choice (:func:`fpdtw.paper.readings.choice_values`), or None.
    """

    key: str
    label: str
    alias: dict = field(default_factory=dict)
    metric: str | None = None


def alternatives() -> list[Alternative]:
    """Every reading and silent choice of notebook 15, as alternatives to ours."""

    out = [
        Alternative(f"window: {r}", f"Method C's {r} window", reading_alias(r))
        for r in C_READINGS
        if r != "square"
    ]
    for key, choice in SILENT_CHOICES.items():
        targets = choice_targets(choice)
        label = f"{key.replace('_', ' ')}: {choice.alternative}"
        if choice.option is not None:
            alias = {n: choice_variant(n, choice) for n in targets}
            alias.update({n + "@60Hz": alias[n] + "@60Hz" for n in targets})
            out.append(Alternative(key, label, alias))
        else:  # the metrics: the same maps, scored another way
            out.append(Alternative(key, label, metric=key))
    return out


def _metric_values(results, key, features):
    """``values(name, metric)`` of :class:`Evidence` for a metric-side choice (cached).

    ``features``: rate (120 or 60) -> ``features(k)``.
    """

    cache = {}

    def values(name, metric):
        if name not in cache:
            rate = 60 if name.endswith("@60Hz") else 120
            cache[name] = choice_values(results, name, key, features(rate))
        return cache[name].get(metric)

    return values


def _study_features(study):
    """``rate -> features(k)``, each pair read once (every algorithm is rescored on the same
    pairs)."""

    @functools.cache
    def at(rate):
        return functools.cache(pair_features(study, fps=float(rate)))

    return at


def robustness(claims, mode: str = "full", study=None, features=None, progress=False) -> dict:
    """Per claim: under how many documented readings its verdict stands, and which flip it.

    Parameters
    ----------
    claims : sequence of Claim
    mode : {"full", "smoke"}
        Reads the study run of this mode (``"study"`` or ``"smoke-study"``) unless ``study``
        is given.
    study : fpdtw.paper.runner.run.Results, optional
    features : callable, optional
        ``features(rate) -> (k -> (I, T))``: the study's pairs at 120 or 60 Hz (default:
        from its feature cache).
    progress : bool
        Show a progress bar over the alternatives.

    Returns
    -------
    out : dict
        Claim id -> text, e.g. ``"yes under ours; stands under 10 of 11 readings (not under:
        forecast hold -> partly); not run: ..."``. Claims not decided on the pairs are
        absent; {} when there is no study run.
    """

    if study is None:
        try:
            study = load_results(study_mode(mode == "smoke"))
        except FileNotFoundError:
            return {}
    base = Evidence(study, label="paper-shaped selection")
    ctx0 = ClaimContext(mode=mode, ev=base)
    todo = [c for c in claims if c.pairs and not c.beyond and not c.question]
    ours = {c.id: c.evaluate(ctx0)["holds"] for c in todo}
    alts = alternatives()
    verdicts = {c.id: [] for c in todo}
    if progress:
        alts = tqdm(alts, desc="readings")
    for alt in alts:
        values = None
        if alt.metric is not None:
            if features is None:
                features = _study_features(study)
            values = _metric_values(study, alt.metric, features)
        ctx = ctx0.with_evidence(base.reading(alias=alt.alias, values=values, label=alt.key))
        for c in todo:
            verdicts[c.id].append((alt, c.evaluate(ctx)["holds"]))
    out = {}
    for c in todo:
        if ours[c.id] == NA:
            out[c.id] = "n/a (not computed on the study run)"
            continue
        run = [(a, v) for a, v in verdicts[c.id] if v != NA]
        flips = [f"{a.label} -> {v}" for a, v in run if v != ours[c.id]]
        not_run = [a.key for a, v in verdicts[c.id] if v == NA]
        text = (
            f"{ours[c.id]} on the paper-shaped selection; stands under "
            f"{len(run) - len(flips)} of {len(run)} readings"
        )
        if flips:
            text += " (not under: " + "; ".join(flips) + ")"
        if not_run:
            text += "; not run: " + ", ".join(not_run)
        out[c.id] = text
    return out


__all__ = ["Alternative", "alternatives", "robustness"]
