"""Loading the claims' evidence: the contexts a claim is decided on, made from a run's results.

:func:`load_context` makes the headline context of a run (its pairs, the notebooks' facts,
``make bench``'s timings and the open run); :func:`claim_contexts` derives every other body
of evidence from it (the movements fixed, each dataset, the paper-shaped selection, Method
C's literal window, OPW's plugin reading, the second seed, the other reading of eq. 2).

Paper: FP-DTW Sections 5-7; OPW poster Section 5.
"""

from __future__ import annotations

import json
from dataclasses import replace

import numpy as np

from fpdtw.paper.claims.evidence import Evidence, shared_evidence
from fpdtw.paper.claims.open import open_mode
from fpdtw.paper.claims.types import (
    DATASETS,
    EQ2_OTHER,
    FIG8_JSON,
    OPW_FIG4_JSON,
    OPW_FIG56_JSON,
    OPW_PLUGIN,
    OTHER_EVIDENCE,
    SEED2_OFFSET,
    ClaimContext,
    opw_reading,
    reading_alias,
)
from fpdtw.paper.figures.timing import TIMED_NAMES, load_bench, time_per_frame_rows
from fpdtw.paper.paths import results_dir
from fpdtw.paper.readings import study_mode
from fpdtw.paper.runner import load_results
from fpdtw.paper.runner.results import EQ2_READINGS, STORED_EQ2, load_json
from fpdtw.paper.similarity_level import reading_values


def load_context(
    results, mode="full", fig8_path=None, reading="square", scheme="movements", **evidence
) -> ClaimContext:
    """The context of a run (:func:`fpdtw.paper.runner.run.load_results`).

    ``reading`` chooses Method C's reading of Algorithm 3: with ``"literal"`` every Mc
    name (``"Mc w40"``, ``"Mc w80 + Type V"``, ``"Mc w20@60Hz"``) stands for the
    results of that reading (``"Mc w40 (literal window)"``, ...).

    Parameters
    ----------
    results : fpdtw.paper.runner.Results
    mode : {"full", "smoke"}
        Where the notebooks' facts are read (``results/<mode>/figs/``) and which open run.
    fig8_path : path, optional
        The Fig. 8 notebook's JSON (default :data:`~fpdtw.paper.claims.types.FIG8_JSON`
        under ``figs/``).
    reading : str
        Method C's reading (:func:`~fpdtw.paper.claims.types.reading_alias`).
    scheme : str
        The bootstrap scheme of the evidence (:data:`fpdtw.paper.claims.bootstrap.SCHEMES`).
    **evidence
        Passed to :class:`~fpdtw.paper.claims.evidence.Evidence`.

    Returns
    -------
    ctx : ClaimContext

    Paper: FP-DTW Sections 5-7; OPW poster Section 5.
    """
    alias = reading_alias(reading)
    ev = Evidence(results, scheme=scheme, alias=alias, **evidence)
    bench = load_bench()
    timing = plain = None
    if bench is not None:
        timing = time_per_frame_rows(bench, names=list(TIMED_NAMES)) or None
        plain = bench.get("plain") or None
    figs = results_dir() / mode / "figs"
    return ClaimContext(
        mode=mode,
        ev=ev,
        timing=timing,
        fig8=_read_json(figs / FIG8_JSON if fig8_path is None else fig8_path),
        alias=alias,
        opw_fig4=_read_json(figs / OPW_FIG4_JSON),
        opw_fig56=_read_json(figs / OPW_FIG56_JSON),
        counts=getattr(results, "counts", None) or data_counts(results.pairs),
        open_ev=open_evidence(mode),
        plain=plain,
        bench=bench,
    )


def open_evidence(mode: str = "full"):
    """The :class:`~fpdtw.paper.claims.evidence.Evidence` of the open run of ``mode``, or
    None when that run does not exist (the Q claims are then "not computed").

    Notebook: 16_open_questions.ipynb
    """
    if not (results_dir() / open_mode(mode) / "summary.json").is_file():
        return None
    return shared_evidence(load_results(open_mode(mode)))


def oedtw_backward_jumps(results, name="OE-DTW") -> dict:
    """How often OE-DTW's end point moves backwards (``M_{q+1} < M_q``), over all pairs.

    Returns
    -------
    out : dict
        ``pairs``, ``pairs_backward`` (at least one backward jump), ``fraction``,
        ``jumps`` (total number of backward jumps).

    Paper: FP-DTW Section 2, Fig. 1.
    """
    arr = results.get(name)
    offsets = np.asarray(arr["offsets"], dtype=np.int64)
    maps = np.asarray(arr["maps"], dtype=np.int64)
    P = len(offsets) - 1
    back = jumps = 0
    for k in range(P):
        d = np.diff(maps[offsets[k] : offsets[k + 1]])
        j = int(np.count_nonzero(d < 0))
        jumps += j
        back += j > 0
    return dict(pairs=P, pairs_backward=back, fraction=back / P if P else 0.0, jumps=jumps)


def data_counts(pairs) -> dict:
    """Motions, movements and pairs in a pair list (``Results.pairs``), total and per dataset."""
    out = {}
    for ds in sorted({p["dataset"] for p in pairs}) + [None]:
        pp = [p for p in pairs if ds is None or p["dataset"] == ds]
        motions = {(p["dataset"], p[k]) for p in pp for k in ("input", "target")}
        movements = {(p["dataset"], p["movement"]) for p in pp}
        out[ds or "total"] = dict(motions=len(motions), movements=len(movements), pairs=len(pp))
    return out


def _read_json(path):
    try:
        with open(path) as fh:
            return json.load(fh)
    except FileNotFoundError:
        return None


def _reseeded(ev):
    """The same evidence with the second bootstrap seed (None stays None)."""
    if ev is None:
        return None
    seed = ev.seed + SEED2_OFFSET
    return Evidence(ev.results, ev.rows, ev.scheme, ev.n_resamples, seed, alias=ev.alias,
                    values=ev._values, label=f"{ev.label} (second seed)")  # fmt: skip


def _reading_context(ctx, reading):
    """The context under another reading of Method C (same pairs, same bootstrap weights)."""
    alias = reading_alias(reading)
    ev = ctx.ev.reading(alias=alias, label=f"{reading} window") if ctx.ev is not None else None
    return replace(ctx, ev=ev, alias=alias)


def paper_shaped_rows(results, mode: str = "full"):
    """Indices into ``results.pairs`` of the paper-shaped selection's pairs (notebook 15).

    The selection is the study run's (``results/study/pairs.json``, ``smoke-study`` for
    SMOKE): at most 8 takes per movement, drawn with a fixed seed. Returns None when that
    run does not exist.
    """
    path = results_dir() / study_mode(mode == "smoke") / "pairs.json"
    if not path.is_file():
        return None
    key = {
        (p["dataset"], p["movement"], p["input"], p["target"]): i
        for i, p in enumerate(results.pairs)
    }
    rows = [
        key.get((p["dataset"], p["movement"], p["input"], p["target"]))
        for p in load_json(path)["pairs"]
    ]
    return np.array(sorted(r for r in rows if r is not None), dtype=np.int64)


def claim_contexts(ctx, results=None, mode="full") -> dict:
    """Every body of evidence of the table: key -> context (None where it cannot be made).

    Keys: ``""`` (all pairs), ``"same_movements"``, ``"authors_fbx"``, ``"hdm05"``,
    ``"paper_shaped"``, ``"literal"``, ``"plugin"`` (OPW's plugin reading: None without its
    facts), ``"seed2"`` (all pairs and the open run, resampled with the second seed).
    """
    out = {
        "": ctx,
        **{k: None for k in OTHER_EVIDENCE},
        "literal": _reading_context(ctx, "literal"),
        OPW_PLUGIN: opw_reading(ctx),
        "seed2": None,
    }
    if ctx.ev is not None or ctx.open_ev is not None:
        out["seed2"] = replace(ctx, ev=_reseeded(ctx.ev), open_ev=_reseeded(ctx.open_ev))
    out |= dict.fromkeys(EQ2_OTHER)
    ev = ctx.ev
    if ev is None:
        return out
    other = _other_eq2_values(ev.results)
    out["same_movements"] = ctx.with_evidence(
        Evidence(
            ev.results,
            ev.rows,
            "motions",
            ev.n_resamples,
            ev.seed,
            alias=ev.alias,
            label="these movements",
        )
    )
    ds = np.array([ev.results.pairs[r]["dataset"] for r in ev.rows])
    if other is not None:
        o = ev.reading(values=other, label=f"eq. 2 {other_eq2(ev.results)}")
        out["eq2_other"] = ctx.with_evidence(o)
    for d in DATASETS:
        if np.any(ds == d):
            out[d] = ctx.with_evidence(ev.restrict(ds == d, d))
            if other is not None:
                out[f"eq2_other_{d}"] = ctx.with_evidence(o.restrict(ds == d, d))
    rows = paper_shaped_rows(ev.results, mode) if results is not None else None
    if rows is not None and rows.size:
        for key, values in (("paper_shaped", None), ("eq2_other_paper_shaped", other)):
            if key != "paper_shaped" and other is None:
                continue
            out[key] = ctx.with_evidence(
                Evidence(ev.results, rows, ev.scheme, ev.n_resamples, ev.seed, alias=ev.alias,
                         values=values, label="paper-shaped selection")
            )  # fmt: skip
    return out


def other_eq2(results) -> str | None:
    """The reading of eq. 2 other than the one ``results`` scores with (None: a run
    without readings, e.g. a test's fake run)."""
    eq2 = getattr(results, "eq2", None)
    if eq2 is None:
        return None
    other = next(r for r in EQ2_READINGS if r != eq2)
    if other != STORED_EQ2 and not getattr(results, "selection", None):
        return None  # a run without its selection cannot be rescored
    return other


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


__all__ = [
    "claim_contexts",
    "data_counts",
    "load_context",
    "oedtw_backward_jumps",
    "open_evidence",
    "other_eq2",
    "paper_shaped_rows",
]
