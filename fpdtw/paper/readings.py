"""Readings of Algorithm 3 and the paper's other silent choices: what each one changes.

Notebook 15's analysis of the ``"study"`` (paper-shaped) and ``"full"`` runs, per reading of
Method C's window (:data:`fpdtw.registry.C_READINGS`); Type V read as a mask (ours) or as a
choice only (:func:`type_v_mask_changes`).

Paper: FP-DTW Algorithm 3, Section 3.3, Sections 4-6.
Notebook: 15_readings_of_algorithm_3.ipynb
"""

from __future__ import annotations

import dataclasses
from collections import Counter

import numpy as np

from fpdtw import plain
from fpdtw.metrics import deviation, similarity_per_axis, step_counts, stick_skip_index
from fpdtw.motion.rig import cost_input
from fpdtw.online import MethodC
from fpdtw.paper import numbers
from fpdtw.paper.numbers import WINDOWS
from fpdtw.paper.runner.grid import SILENT_CHOICES, choice_targets, choice_variant
from fpdtw.registry import C_READINGS, align, method_c_name

#: Rates of the study (Hz) and their name suffixes.
RATES = {120: "", 60: "@60Hz"}


def study_mode(smoke: bool) -> str:
    """Results folder of notebook 15: ``"smoke-study"`` or ``"study"``.

    Notebook: 15_readings_of_algorithm_3.ipynb
    """
    return "smoke-study" if smoke else "study"


def reading_name(reading: str, w: int, typev: bool = False, rate: int = 120) -> str:
    """``reading_name("literal", 40, rate=60)`` -> ``"Mc w40 (literal window)@60Hz"``.

    Notebook: 15_readings_of_algorithm_3.ipynb
    """
    return method_c_name(w, reading, typev) + RATES[rate]


def _pair_rows(results, dataset):
    """Indices (into the algorithm arrays, which follow ``results.pairs``) of a dataset."""
    ds = np.array([p["dataset"] for p in results.pairs])
    return np.arange(ds.size) if dataset is None else np.flatnonzero(ds == dataset)


def map_shape(results, name: str, dataset=None) -> dict:
    """How an algorithm's maps move through the input over a dataset's pairs (None: all):
    ``exhausted`` and ``hold`` shares of the steps (pooled), median ``stick_skip``
    (:func:`fpdtw.metrics.stick_skip_index`), ``pairs``."""
    arr = results.get(name)
    m_all, _ = results.frames(name)
    total, index = Counter(), []
    for k in _pair_rows(results, dataset):
        M = np.asarray(arr.map(k), dtype=np.int64)
        total.update(step_counts(M, int(m_all[k])))
        index.append(stick_skip_index(M, int(m_all[k])))
    return dict(
        exhausted=total["exhausted"] / total["steps"] if total["steps"] else 0.0,
        hold=total["holds"] / total["live"] if total["live"] else 0.0,
        stick_skip=float(np.median(index)) if index else float("nan"),
        pairs=len(index),
    )


def _median(results, name, metric, dataset):
    v = np.asarray(results.get(name)[metric], dtype=np.float64)[_pair_rows(results, dataset)]
    v = v[np.isfinite(v)]
    return float(np.median(v)) if v.size else float("nan")


def _medians(results, name, dataset=None) -> tuple[float, float]:
    """Median similarity and deviation of ``name`` over a dataset's pairs."""
    return tuple(_median(results, name, k, dataset) for k in ("similarity", "deviation"))


def _passes(similarity, deviation, utw_similarity, rate=120) -> tuple[bool, bool]:
    """Whether medians pass the similarity and the deviation benchmark."""
    return (
        numbers.passes_similarity(similarity, utw_similarity),
        numbers.passes_deviation(deviation, rate),
    )


def benchmarks(results, dataset=None, rate: int = 120) -> dict:
    """The paper's benchmarks at a rate: ``similarity`` (UTW's median), ``deviation`` (frames).

    Paper: FP-DTW Sections 4 and 5.
    Notebook: 15_readings_of_algorithm_3.ipynb
    """
    return dict(
        similarity=_median(results, "UTW" + RATES[rate], "similarity", dataset),
        deviation=numbers.deviation_benchmark_frames(rate),
    )


def readings_table(results, datasets=(None,)) -> list[dict]:
    """Every reading of Algorithm 3 at every w, with and without Type V, per dataset (None:
    every pair) and rate, from a ``"study"`` run: medians, verdicts and :func:`map_shape`;
    DTW's row (reading ``"DTW"``) first per dataset and rate.

    Notebook: 15_readings_of_algorithm_3.ipynb
    """
    rows = []
    for dataset in datasets:
        for rate in RATES:
            bench = benchmarks(results, dataset, rate)
            cases = [("DTW", None, False, "DTW" + RATES[rate])]
            cases += [
                (r, w, t, reading_name(r, w, t, rate))
                for r in C_READINGS
                for t in (False, True)
                for w in WINDOWS
            ]
            for reading, w, typev, name in cases:
                sim, dev = _medians(results, name, dataset)
                ps, pd = _passes(sim, dev, bench["similarity"], rate)
                verdict = {"passes_similarity": ps, "passes_deviation": pd}
                where = {"dataset": dataset or "all", "rate_hz": rate, "reading": reading}
                what = {"w": w, "type_v": typev, "algorithm": name}
                measured = {"similarity": sim, "deviation": dev}
                shape = map_shape(results, name, dataset)
                rows.append(where | what | measured | verdict | shape)
    return rows


def _best_w(rows, rate):
    sims = {r["w"]: r["similarity"] for r in rows if r["rate_hz"] == rate and not r["type_v"]}
    return max(sorted(sims), key=lambda w: (sims[w], -w)) if sims else None


def reading_signature(rows, dataset: str = "all") -> list[dict]:
    """The paper's qualitative signature of Method C per reading, from :func:`readings_table`
    (the paper's: :data:`PAPER_SIGNATURE`).

    Paper: FP-DTW Section 5, Table 1, Figs. 5-7.
    Notebook: 15_readings_of_algorithm_3.ipynb
    """
    out = []
    readings = [r for r in dict.fromkeys(x["reading"] for x in rows) if r != "DTW"]
    for reading in readings:
        rr = [x for x in rows if x["reading"] == reading and x["dataset"] == dataset]
        at120 = {(x["w"], x["type_v"]): x for x in rr if x["rate_hz"] == 120}
        both = [k for k, x in at120.items() if x["passes_similarity"] and x["passes_deviation"]]
        plain = {w: x for (w, t), x in at120.items() if not t}
        exhausted = [x["exhausted"] for x in plain.values()]
        out.append(
            dict(
                dataset=dataset,
                reading=reading,
                best_w_120=_best_w(rr, 120),
                best_w_60=_best_w(rr, 60),
                w10_stick_skip=plain[10]["stick_skip"] if 10 in plain else None,
                w80_stick_skip=plain[80]["stick_skip"] if 80 in plain else None,
                w40_passes_both=(40, False) in both if 40 in plain else None,
                pass_both=", ".join(f"w{w}" + (" + Type V" if t else "") for w, t in both)
                or "none",
                exhausted=float(np.mean(exhausted)) if exhausted else None,
            )
        )
    return out


#: The paper's signature (Section 5, Table 1), in the columns of :func:`reading_signature`.
PAPER_SIGNATURE = dict(
    dataset="paper",
    reading="(the paper's Method C)",
    best_w_120=numbers.BEST_WINDOW[120],
    best_w_60=numbers.BEST_WINDOW[60],
    w10_stick_skip="sticks (< 0)",
    w80_stick_skip="skips (> 0)",
    w40_passes_both="Mc w40" in numbers.PASS_BOTH,
    pass_both=", ".join(n[3:] for n in numbers.PASS_BOTH if n.startswith("Mc ")),
    exhausted="Mc w80 runs out early",
)


def mechanism_profile(pairs, w: int = 40, readings=("literal", "square")) -> dict:
    """Rest-of-path cost ``f(r) = D[r, 0] - C[r, 0]`` per row offset r in the full-size
    Method C windows of some pairs (the literal window's ``f(0)`` carries one cell more).
    Per reading: ``r`` int (rows,), ``mean_f`` float64 (rows,), medians ``excess`` (``f(0) -
    f(1)``) and ``neighbour``, shares ``hold`` and ``best_row0``, ``steps``.

    Notebook: 15_readings_of_algorithm_3.ipynb
    """
    pairs = list(pairs)
    out = {}
    for reading in readings:
        f_sum, excess, neighbour = None, [], []
        hold = best0 = steps = 0
        for I, T in pairs:
            a = MethodC(I, w, window=reading, record=True)
            full = a.window_rows(0)
            for frame in T.frames():
                a.step(frame)
                s = a.window_snapshot()
                if s.kind != "window" or s.C.shape[0] != full:
                    continue
                f = s.D[:, 0] - s.C[:, 0]
                f_sum = f.copy() if f_sum is None else f_sum + f
                excess.append(f[0] - f[1])
                neighbour.append(np.median(np.abs(np.diff(s.C[:, 0]))))
                hold += s.offset == 0
                best0 += int(np.argmin(s.C[:, 0])) == 0
                steps += 1
        out[reading] = dict(
            r=np.arange(0 if f_sum is None else f_sum.size),
            mean_f=np.zeros(0) if f_sum is None else f_sum / steps,
            excess=float(np.median(excess)) if excess else float("nan"),
            neighbour=float(np.median(neighbour)) if neighbour else float("nan"),
            hold=hold / steps if steps else 0.0,
            best_row0=best0 / steps if steps else 0.0,
            steps=steps,
        )
    return out


def choice_values(results, name: str, variant: str, features=None) -> dict:
    """Per-pair scores of ``name`` under a metric-side silent choice ``variant``
    (:data:`fpdtw.paper.runner.grid.SILENT_CHOICES`): metric -> float64 (P,), for the
    metrics it changes; the choices of eq. 2 need ``features(k) -> (I, T)``."""
    arr = results.get(name)
    dtw = results.get("DTW" + ("@60Hz" if name.endswith("@60Hz") else ""))
    m_all, _ = results.frames(name)
    P = np.asarray(arr["offsets"]).size - 1
    sims, devs = np.full(P, np.nan), np.full(P, np.nan)
    for k in range(P):
        M = np.asarray(arr.map(k), dtype=np.int64)
        D = np.asarray(dtw.map(k), dtype=np.int64)
        if variant == "deviation_frames":
            devs[k] = deviation(D, M, frames="all")
            continue
        if features is None:
            raise ValueError(f"the choice {variant!r} of eq. 2 needs the pairs' features")
        I, T = features(k)
        if variant == "flat_axis":
            r = similarity_per_axis(I.quats, T.quats, M, one_flat=np.nan)
            sims[k] = float(np.nanmean(r)) if np.isfinite(r).any() else np.nan
        elif variant == "after_input":
            end = int(np.argmax(M >= m_all[k])) + 1 if np.any(M >= m_all[k]) else M.size
            end = max(end, 2)
            sims[k] = float(np.mean(similarity_per_axis(I.quats, T.quats[:end], M[:end])))
            devs[k] = deviation(D[:end], M[:end])
        else:
            raise ValueError(f"not a metric-side choice: {variant!r}")
    left_out = {"deviation_frames": "similarity", "flat_axis": "deviation"}.get(variant)
    return {k: v for k, v in (("similarity", sims), ("deviation", devs)) if k != left_out}


_DETAIL_KEYS = (
    "choice algorithm similarity_ours similarity_alternative deviation_ours "
    "deviation_alternative verdict_changes"
).split()


def silent_choice_rows(results, features=None) -> tuple[list[dict], list[dict]]:
    """How much each silent choice moves the headline medians (120 Hz, a ``"study"`` run);
    without ``features`` (:func:`choice_values`) the metric-side choices are left out.

    Returns
    -------
    summary : list of dict
        Per choice: ``choice``, ``ours``, ``alternative``, ``touches``, the largest change
        of each median ``max_d_*`` and ``verdicts_changed``.
    detail : list of dict
        Per choice and algorithm: the medians under ours and the alternative.

    Notebook: 15_readings_of_algorithm_3.ipynb
    """
    bench = benchmarks(results)
    summary, detail = [], []
    for key, choice in SILENT_CHOICES.items():
        if choice.option is None and key != "deviation_frames" and features is None:
            continue
        targets = [n for n in choice_targets(choice) if n in results.algorithms]
        rows = []
        for name in targets:
            s0, d0 = _medians(results, name)
            if choice.option is not None:
                alt = choice_variant(name, choice)
                if alt not in results.algorithms:
                    continue
                s1, d1 = _medians(results, alt)
            else:
                vals = choice_values(results, name, key, features)  # a metric it leaves: ours
                s1 = float(np.nanmedian(vals["similarity"])) if "similarity" in vals else s0
                d1 = float(np.nanmedian(vals["deviation"])) if "deviation" in vals else d0
            flips = _passes(s0, d0, bench["similarity"]) != _passes(s1, d1, bench["similarity"])
            rows.append(dict(zip(_DETAIL_KEYS, (key, name, s0, s1, d0, d1, bool(flips)))))
        detail += rows
        summary.append(
            dict(
                choice=key,
                ours=choice.ours,
                alternative=choice.alternative,
                touches=", ".join(r["algorithm"] for r in rows),
                **{
                    f"max_d_{m}": max(
                        (abs(r[f"{m}_alternative"] - r[f"{m}_ours"]) for r in rows), default=0.0
                    )
                    for m in ("similarity", "deviation")
                },
                verdicts_changed=", ".join(r["algorithm"] for r in rows if r["verdict_changes"])
                or "none",
            )
        )
    return summary, detail


#: The headline algorithms compared across selections (the paper's claims and ours).
HEADLINE_NAMES = (
    ("UTW", "DTW", "Ma", "Ma + Type V")
    + tuple(f"Mb w{w}" for w in WINDOWS)
    + ("Mb w80 + Type V",)
    + tuple(f"Mc w{w}" for w in WINDOWS)
    + ("Mc w80 + Type V",)
)


def selection_rows(full, study, names=HEADLINE_NAMES) -> list[dict]:
    """Headline medians (120 Hz) and verdicts of the ``"full"`` and ``"study"`` runs side by
    side (tags ``full`` and ``paper_shaped``).

    Notebook: 15_readings_of_algorithm_3.ipynb
    """
    out = []
    verdict = {(True, True): "both", (True, False): "similarity", (False, True): "deviation"}
    for name in names:
        row = {"algorithm": name}
        for tag, res in (("full", full), ("paper_shaped", study)):
            s = d = passed = None
            if name in res.algorithms:
                s, d = _medians(res, name)
                passed = verdict.get(_passes(s, d, benchmarks(res)["similarity"]), "neither")
            row |= {f"similarity_{tag}": s, f"deviation_{tag}": d, f"passes_{tag}": passed}
        out.append(row)
    return out


def choice_only_type_v_c(I, T, w: int) -> np.ndarray:
    """Method C + Type V read as a choice only, int64 map (T.n_frames,): the costs left
    unmasked (ours, :func:`fpdtw.plain.method_c_step`, masks them), the lowest allowed ``D[r, 0]``.

    Paper: FP-DTW Section 6 (Type V), Algorithm 3.
    """
    I = dataclasses.replace(I, quats=cost_input(I.quats, I.rig, T.rig))
    M, state = [0], plain.TYPE_V_START
    for _ in range(T.n_frames - 1):
        allowed = plain.type_v_allowed(state)
        s = plain.method_c_step(I, T, M, w)  # no mask: the costs as they are
        if s.kind == "window":
            ok = plain.allowed_rows(allowed, len(s.score))
            r = plain.checked_choice(ok, int(np.argmin(np.where(ok, s.score, np.inf))))
            M.append(M[-1] + r)
        else:
            M.append(s.M)
        state = plain.type_v_next(state, M[-1] - M[-2]) or state
    return np.array(M, dtype=np.int64)


def type_v_mask_changes(pairs, windows=WINDOWS) -> list[dict]:
    """How many maps (and target frames) Type V's mask changes against the choice-only
    reading, per window ``w``.

    Paper: FP-DTW Section 6 (Type V), Algorithm 3.
    Notebook: 15_readings_of_algorithm_3.ipynb
    """
    pairs = list(pairs)
    rows = []
    for w in windows:
        n_maps = n_frames = 0
        for I, T in pairs:
            masked = align(method_c_name(w, typev=True), I, T)[0]
            choice = choice_only_type_v_c(I, T, w)
            n_maps += int(not np.array_equal(masked, choice))
            n_frames += int(np.count_nonzero(masked != choice))
        rows.append({"w": int(w), "pairs": len(pairs), "maps_differ": n_maps,
                     "frames_differ": n_frames})  # fmt: skip
    return rows
