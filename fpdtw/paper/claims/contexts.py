"""The contexts a claim is decided on: a run's headline context (:func:`load_context`) and
every other body of evidence derived from it (:func:`claim_contexts`).

Paper: FP-DTW Sections 5-7; OPW poster Section 5.
"""

from __future__ import annotations

import operator
from dataclasses import replace

import numpy as np

from fpdtw.paper.claims import types as T
from fpdtw.paper.claims.evidence import Evidence, shared_evidence
from fpdtw.paper.claims.open import open_mode
from fpdtw.paper.figures.timing import TIMED_NAMES, load_bench, time_per_frame_rows
from fpdtw.paper.paths import results_dir
from fpdtw.paper.readings import study_mode
from fpdtw.paper.runner import load_results
from fpdtw.paper.runner.results import EQ2_READINGS, STORED_EQ2, load_json
from fpdtw.paper.runner.selection import DATASETS
from fpdtw.paper.similarity_level import reading_values


def load_context(results, mode="full") -> T.ClaimContext:
    """The context of a run (:func:`fpdtw.paper.runner.run.load_results`).

    Paper: FP-DTW Sections 5-7; OPW poster Section 5.
    """
    bench = load_bench()
    timing = plain = None
    if bench is not None:
        timing = time_per_frame_rows(bench, names=list(TIMED_NAMES)) or None
        plain = bench.get("plain") or None
    figs = results_dir() / mode / "figs"  # load_bench(path): any JSON file, None if absent
    return T.ClaimContext(
        mode=mode,
        ev=Evidence(results),
        timing=timing,
        fig8=load_bench(figs / T.FIG8_JSON),
        opw_fig4=load_bench(figs / T.OPW_FIG4_JSON),
        opw_fig56=load_bench(figs / T.OPW_FIG56_JSON),
        counts=getattr(results, "counts", None) or data_counts(results.pairs),
        open_ev=open_evidence(mode),
        plain=plain,
        bench=bench,
    )


def open_evidence(mode: str = "full"):
    """The :class:`~fpdtw.paper.claims.evidence.Evidence` of the open run of ``mode`` (or None).

    Notebook: 16_open_questions.ipynb
    """
    if not (results_dir() / open_mode(mode) / "summary.json").is_file():
        return None
    return shared_evidence(load_results(open_mode(mode)))


def data_counts(pairs) -> dict:
    """Motions, movements and pairs in a pair list (``Results.pairs``), total and per dataset."""
    out = {}
    for ds in sorted({p["dataset"] for p in pairs}) + [None]:
        pp = [p for p in pairs if ds is None or p["dataset"] == ds]
        motions = {(p["dataset"], p[k]) for p in pp for k in ("input", "target")}
        movements = {(p["dataset"], p["movement"]) for p in pp}
        out[ds or "total"] = dict(motions=len(motions), movements=len(movements), pairs=len(pp))
    return out


def paper_shaped_rows(results, mode: str = "full"):
    """Indices into ``results.pairs`` of the study run's pairs (notebook 15), or None."""
    path = results_dir() / study_mode(mode == "smoke") / "pairs.json"
    if not path.is_file():
        return None
    key = operator.itemgetter("dataset", "movement", "input", "target")
    row = {key(p): i for i, p in enumerate(results.pairs)}
    rows = [row.get(key(p)) for p in load_json(path)["pairs"]]
    return np.array(sorted(r for r in rows if r is not None), dtype=np.int64)


def claim_contexts(ctx, results=None, mode="full") -> dict:
    """Every body of evidence of the table: key (``""``: all pairs) -> context (or None)."""
    ev, alias = ctx.ev, T.reading_alias("literal")
    literal = ev.reading(alias=alias, label="literal window") if ev is not None else None
    out = dict.fromkeys(("", *T.OTHER_EVIDENCE, "literal", T.OPW_PLUGIN, "seed2", *T.EQ2_OTHER))
    out[""], out["literal"] = ctx, replace(ctx, ev=literal, alias=alias)
    out[T.OPW_PLUGIN] = T.opw_reading(ctx)
    if ev is not None or ctx.open_ev is not None:

        def reseeded(e):
            if e is not None:
                return e.again(seed=e.seed + T.SEED2_OFFSET, label=f"{e.label} (second seed)")

        out["seed2"] = replace(ctx, ev=reseeded(ev), open_ev=reseeded(ctx.open_ev))
    if ev is None:
        return out
    out["same_movements"] = replace(ctx, ev=ev.again(scheme="motions", label="these movements"))
    ds = np.array([ev.results.pairs[r]["dataset"] for r in ev.rows])
    for d in DATASETS:
        if np.any(ds == d):
            out[d] = replace(ctx, ev=ev.restrict(ds == d, d))
    rows = paper_shaped_rows(ev.results, mode) if results is not None else None
    if rows is not None and rows.size:
        out["paper_shaped"] = replace(ctx, ev=ev.again(rows=rows, label="paper-shaped selection"))
    if (other := _other_eq2_values(ev.results)) is not None:  # each body rescored, same weights
        label = f"eq. 2 {other_eq2(ev.results)}"
        for key in ("", *DATASETS, "paper_shaped"):
            if out[key] is not None:
                o = out[key].ev.reading(values=other, label=None if key else label)
                out[f"eq2_other_{key}" if key else "eq2_other"] = replace(ctx, ev=o)
    return out


def other_eq2(results) -> str | None:
    """The reading of eq. 2 other than the one ``results`` scores with (None: a run without
    readings or without its selection, which cannot be rescored)."""
    if (eq2 := getattr(results, "eq2", None)) is None:
        return None
    other = next(r for r in EQ2_READINGS if r != eq2)
    return other if other == STORED_EQ2 or getattr(results, "selection", None) else None


def _other_eq2_values(results):
    """``values(name, metric)`` of :class:`Evidence` under the other reading of eq. 2."""
    other = other_eq2(results)
    if other is None:
        return None
    if other == STORED_EQ2:

        def stored(name, metric):  # in results.pairs order, as Evidence expects
            if metric != "similarity":
                return None
            arr = results.stored(name)
            pos = {int(p): k for k, p in enumerate(arr["pair_id"])}
            sim = np.asarray(arr["similarity"], dtype=np.float64)
            return np.array([sim[pos[int(p["id"])]] for p in results.pairs])

        return stored
    return reading_values(results, other)
