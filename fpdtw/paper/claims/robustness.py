"""Does a verdict survive the paper's open readings? Each claim on the study run (notebook 15)
under every documented choice, one change at a time (runs that do not exist: "not run").

Paper: FP-DTW Algorithms 1-3, Sections 4-6 (the choices they leave open).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, field, replace

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
    """One documented reading other than ours: key, label, and a claim's name -> the results
    under it (``alias``) or a metric-side choice (``metric``)."""

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
    """``values(name, metric)`` of :class:`Evidence` for a metric-side choice (cached)."""

    @functools.cache
    def by_name(name):
        rate = 60 if name.endswith("@60Hz") else 120
        return choice_values(results, name, key, features(rate))

    return lambda name, metric: by_name(name).get(metric)


def robustness(claims, mode: str = "full") -> dict:
    """Per claim on the pairs: its verdict on the study run of ``mode`` and under how many
    documented readings it stands ({} without a study run)."""
    try:
        study = load_results(study_mode(mode == "smoke"))
    except FileNotFoundError:
        return {}
    base = Evidence(study, label="paper-shaped selection")
    ctx0 = ClaimContext(mode=mode, ev=base)
    todo = [c for c in claims if c.pairs and not c.beyond and not c.question]
    ours = {c.id: c.evaluate(ctx0)["holds"] for c in todo}
    verdicts = {c.id: [] for c in todo}
    # rate -> features(k), each pair read once (on first need)
    features = functools.cache(lambda rate: functools.cache(pair_features(study, fps=float(rate))))
    for alt in alternatives():
        values = _metric_values(study, alt.metric, features) if alt.metric else None
        ctx = replace(ctx0, ev=base.reading(alias=alt.alias, values=values, label=alt.key))
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
