"""Similarity and deviation per algorithm over all pairs: Figs. 5 and 6, Table 1.

Intervals and verdicts are the claims table's
(:func:`fpdtw.paper.claims.evidence.shared_evidence`), so a figure and a claim cannot disagree.
"""

from __future__ import annotations

import numpy as np
from matplotlib.lines import Line2D
from matplotlib.patches import Patch

from fpdtw import registry
from fpdtw.paper import numbers
from fpdtw.paper.claims.evidence import METRICS, shared_evidence
from fpdtw.paper.claims.paper_claims import best_window_test
from fpdtw.paper.claims.rules import evaluate
from fpdtw.paper.claims.types import reading_alias
from fpdtw.paper.figures.plotting import new_axes, style_beyond_paper
from fpdtw.paper.numbers import FPDTW_NAMES, WINDOWS
from fpdtw.registry import TYPE_V_SUFFIX, method_c_name


def base_names() -> tuple:
    """Figs. 5 and 6's algorithms in plotting order: the paper's, then the registry's
    baselines (read at each call).

    Paper: FP-DTW Figs. 5 and 6.
    """
    return ("DTW", "UTW", "OE-DTW") + FPDTW_NAMES + registry.baselines()


#: :func:`base_names` with the registry as built in.
BASE_NAMES = base_names()

#: Colours: unconstrained online algorithms, offline baselines, "+ Type V" (pink, as the paper).
COLOURS = {"plain": "#8fb3d9", "offline": "#bdbdbd", "typev": "#f4a6c8"}
#: Their legend entries, in legend order.
_KIND_LABELS = {"offline": "offline", "plain": "online, no constraint", "typev": "+ Type V"}


def _rate_suffix(rate_hz: int) -> str:
    return "" if rate_hz == 120 else f"@{int(rate_hz)}Hz"


def _raw(results, name: str, metric: str, dataset=None) -> np.ndarray:
    """All per-pair values of a metric (NaN kept), optionally of one dataset's pairs only."""
    if metric not in METRICS:
        raise ValueError(f"metric must be one of {METRICS}, got {metric!r}")
    arr = results.get(name)
    v = np.asarray(arr[metric], dtype=np.float64)
    if dataset is not None:
        ds = {int(p["id"]): p["dataset"] for p in results.pairs}
        keep = np.array([ds[int(k)] == dataset for k in arr["pair_id"]], dtype=bool)
        if not keep.any():
            raise ValueError(f"no pairs of dataset {dataset!r} in the results")
        v = v[keep]
    return v


def scores(results, name: str, metric: str, dataset=None) -> np.ndarray:
    """One algorithm's finite per-pair scores, float64 (P',), optionally of one dataset.

    Paper: FP-DTW eq. 2 (similarity), eq. 3 (deviation).
    """
    v = _raw(results, name, metric, dataset)
    return v[np.isfinite(v)]


def utw_median(results, rate_hz: int = 120, dataset=None) -> float:
    """The similarity benchmark: UTW's median similarity over all pairs (at ``rate_hz``).

    Paper: FP-DTW Section 4 (benchmark (i)), Fig. 5 red line, Table 1 last column.
    """
    return float(np.median(scores(results, "UTW" + _rate_suffix(rate_hz), "similarity", dataset)))


def benchmark(results, metric: str, dataset=None) -> float:
    """The benchmark of a metric: UTW's median similarity, or 18 frames deviation."""
    if metric == "similarity":
        return utw_median(results, dataset=dataset)
    if metric == "deviation":
        return float(numbers.DEVIATION_BENCHMARK_FRAMES)
    raise ValueError(f"metric must be one of {METRICS}, got {metric!r}")


def figure_names(names=None, typev=True) -> list[tuple[str, str | None]]:
    """``(name, its "+ Type V" or None)`` for ``names`` (default :func:`base_names`)."""
    return [
        (n, n + TYPE_V_SUFFIX if (typev and n in FPDTW_NAMES) else None)
        for n in (base_names() if names is None else names)
    ]


def score_summary(results, metric: str, names=None, dataset=None) -> list[dict]:
    """Per algorithm (default: Figs. 5 and 6's that were run), over all pairs or one
    ``dataset``'s: median with its 95 % interval, quartiles, counts, benchmark,
    ``passes_benchmark`` (the paper's rule on the median) and the claims' ``verdict``.

    Paper: FP-DTW Figs. 5 and 6, Section 5 (the median must pass the benchmark).
    Notebook: 06_fig5_fig6_scores.ipynb
    """
    if names is None:
        have = set(results.algorithms)
        names = [n for pair in figure_names() for n in pair if n is not None and n in have]
    bench = benchmark(results, metric, dataset)
    ev = shared_evidence(results, dataset)
    rows = []
    for name in names:
        raw = _raw(results, name, metric, dataset)
        v = raw[np.isfinite(raw)]
        if v.size == 0:
            raise ValueError(f"{name}: no finite {metric} values")
        q1, med, q3 = (float(x) for x in np.percentile(v, [25, 50, 75]))
        lo, hi = ev.interval(name, metric)
        online = name not in ("DTW", "UTW")
        sim = metric == "similarity"
        passes = numbers.passes_similarity(med, bench) if sim else numbers.passes_deviation(med)
        rows.append(
            dict(algorithm=name, type_v=name.endswith(TYPE_V_SUFFIX), median=med, ci_low=lo,
                 ci_high=hi, q1=q1, q3=q3, n=int(v.size), n_missing=int(raw.size - v.size),
                 benchmark=float(bench), passes_benchmark=passes,
                 verdict=ev.passes(name, metric).verdict if online else "-")
        )  # fmt: skip
    return rows


def passing(rows, online_only=False) -> list[str]:
    """Names of the :func:`score_summary` rows that pass."""
    return [
        r["algorithm"]
        for r in rows
        if r["passes_benchmark"] and not (online_only and r["algorithm"] in ("DTW", "UTW"))
    ]


def _clip_top(bp, bench: float) -> float:
    """Top of Fig. 6's linear axis: the highest upper whisker or twice the benchmark, + 8 %."""
    tops = [float(np.max(w.get_ydata())) for w in bp["whiskers"][1::2]]
    return 1.08 * max(max(tops, default=0.0), 2.0 * bench)


def plot_score_boxes(
    results, metric="similarity", names=None, typev=True, ax=None, intervals=True, clip=None
):
    """Fig. 5 / Fig. 6: box plot of a score per algorithm, with the benchmark line.

    Each FP-DTW algorithm gets two boxes, without constraint (blue) and "+ Type V" (pink).
    ``intervals``: each median's 95 % interval and, on Fig. 5, UTW's. Fig. 6's linear axis
    is cut at ``clip`` frames (default :func:`_clip_top`), the values above counted.

    Paper: FP-DTW Fig. 5 (similarity, eq. 2) and Fig. 6 (deviation, eq. 3).
    Notebook: 06_fig5_fig6_scores.ipynb
    """
    fig, ax = new_axes(ax, figsize=(12, 4.5))
    have = set(results.algorithms)
    names = [n for n in (base_names() if names is None else names) if n in have]  # as run
    boxes = []  # (name, position, width, colour) of each box
    for i, (name, tv) in enumerate(figure_names(names, typev)):
        if tv is None:
            boxes.append((name, i, 0.6, COLOURS["offline" if name in ("DTW", "UTW") else "plain"]))
        else:
            boxes += [
                (name, i - 0.2, 0.36, COLOURS["plain"]),
                (tv, i + 0.2, 0.36, COLOURS["typev"]),
            ]
    drawn, pos, widths, colours = ([b[k] for b in boxes] for k in range(4))
    data = [scores(results, n, metric) for n in drawn]
    bp = ax.boxplot(
        data, positions=pos, widths=widths, patch_artist=True, showfliers=True,
        flierprops=dict(marker=".", markersize=2, alpha=0.3, markeredgecolor="0.4"),
        medianprops=dict(color="k", lw=1.2, gid="median"), boxprops=dict(edgecolor="0.25"),
        manage_ticks=False,
    )  # fmt: skip
    for box, c in zip(bp["boxes"], colours):
        box.set_facecolor(c)
    bench = benchmark(results, metric)
    if intervals:
        ev = shared_evidence(results)
        for name, x, w in zip(drawn, pos, widths):
            lo, hi = ev.interval(name, metric)
            ax.vlines(x + 0.5 * w + 0.04, lo, hi, color="k", lw=2.2, zorder=6, gid="median_ci")
        if metric == "similarity":
            lo, hi = ev.interval("UTW", metric)
            ax.axhspan(lo, hi, color="red", alpha=0.10, lw=0, zorder=0.5, gid="benchmark_ci")
    handles = [
        Patch(facecolor=COLOURS[kind], edgecolor="0.25", label=label)
        for kind, label in _KIND_LABELS.items()
        if typev or kind != "typev"
    ]
    if metric == "similarity":
        line_colour = "red"
        handles.append(Line2D([], [], color="red", lw=1.2,
                              label=f"our UTW median (benchmark) = {bench:.3f}"))  # fmt: skip
        paper_utw = float(numbers.TABLE1[numbers.SAMPLE_RATE_HZ]["UTW"])
        paper = ax.axhline(paper_utw, color="darkred", lw=1.2, ls=(0, (5, 3)), zorder=5)
        paper.set_gid("paper_benchmark")
        handles.append(Line2D([], [], color="darkred", lw=1.2, ls=(0, (5, 3)),
                              label=f"paper's UTW median = {paper_utw:.3f} (Table 1)"))  # fmt: skip
        ax.set_ylabel("similarity (eq. 2, mean Kendall tau)")
    else:
        line_colour = "blue"
        handles.append(Line2D([], [], color="blue", lw=1.2,
                              label=f"benchmark: {bench:g} frames (150 ms)"))  # fmt: skip
        ax.set_ylabel("deviation from DTW (eq. 3), frames (linear)")
        top = float(clip) if clip is not None else _clip_top(bp, bench)
        ax.set_ylim(0.0, top)
        above = [int(np.sum(v > top)) for v in data]
        for x, k in zip(pos, above):
            if k:
                ax.text(x, top, f"\u25b2{k}", ha="center", va="top", fontsize=6.5, color="0.2",
                        zorder=7, gid="clipped_count")  # fmt: skip
        total = sum(len(v) for v in data)
        handles.append(Line2D([], [], ls="", marker="^", ms=5, color="0.2",
                              label=f"\u25b2k: k values above {top:.0f} frames, not drawn "
                              f"({sum(above)} of {total})"))  # fmt: skip
    ax.axhline(bench, color=line_colour, lw=1.2, zorder=5, gid="benchmark")
    ax.set_xticks(range(len(names)), names, rotation=45, ha="right")
    ax.set_xlim(-0.6, len(names) - 0.4)
    boxes_of = {}  # each name's boxes, "+ Type V" with its base
    for n, b in zip(drawn, bp["boxes"]):
        boxes_of.setdefault(n.removesuffix(TYPE_V_SUFFIX), []).append(b)
    handles += style_beyond_paper(ax, names, patches=boxes_of)
    if intervals:
        handles.append(Line2D([], [], color="k", lw=2.2, label="95 % interval of the median"))
        if metric == "similarity":
            band_label = "95 % interval of our UTW median"
            handles.append(Patch(facecolor="red", alpha=0.10, label=band_label))
    ax.legend(handles=handles, fontsize=8, loc="upper left", bbox_to_anchor=(1.005, 1.0))
    ax.grid(axis="y", alpha=0.3)
    return fig, ax


def best_window(medians: dict) -> int:
    """The int key of ``{w: median}`` with the highest median (ties: the smaller)."""
    ws = sorted(k for k in medians if isinstance(k, int))
    if not ws:
        raise ValueError("no windows given")
    return max(ws, key=lambda w: (medians[w], -w))


def table1_rows(results, reading="square", with_paper=True) -> list[dict]:
    """Table 1: Method C's median similarity per window and UTW's, at 60 and 120 Hz: per
    rate the paper's row (if ``with_paper``), then ours with the claims' verdicts.

    Paper: FP-DTW Table 1.
    Notebook: 07_table1_60hz.ipynb
    """
    ev = shared_evidence(results)
    if reading != "square":
        ev = ev.reading(alias=reading_alias(reading))
    rows = []
    for rate in (60, 120):
        sfx = _rate_suffix(rate)
        names = {w: method_c_name(w, reading) + sfx for w in WINDOWS} | {"UTW": "UTW" + sfx}
        ours = {k: float(np.median(scores(results, n, "similarity"))) for k, n in names.items()}
        paper = numbers.TABLE1.get(rate) if with_paper else None
        label = "ours" if reading == "square" else f"ours ({reading} window)"
        for source, med in (("paper", paper), (label, ours)):
            if med is None:
                continue
            row = {"rate_hz": rate, "source": source, **{f"w{w}": med[w] for w in WINDOWS}}
            row["UTW"] = med["UTW"]
            row["best_w"] = best_window(med)
            row["above_utw"] = " ".join(str(w) for w in WINDOWS if med[w] > med["UTW"])
            if source != "paper":
                for w in WINDOWS:
                    row[f"verdict_w{w}"] = ev.passes(f"Mc w{w}{sfx}", "similarity").verdict
                if rate in numbers.BEST_WINDOW:
                    row["best_verdict"] = evaluate(best_window_test(ev, rate))
            rows.append(row)
    return rows


def plot_table1(rows, ax=None):
    """Table 1 as a plot: Method C's median similarity against w per row of
    :func:`table1_rows`, and UTW's median per rate as a thin line.

    Paper: FP-DTW Table 1.
    Notebook: 07_table1_60hz.ipynb
    """
    fig, ax = new_axes(ax, figsize=(8.5, 4))
    colours = {60: "tab:orange", 120: "tab:blue"}
    for r in rows:
        c = colours.get(r["rate_hz"], "k")
        style = {"ours": "-o", "paper": "--s"}.get(r["source"], ":^")
        ys = [r[f"w{w}"] for w in WINDOWS]
        ax.plot(WINDOWS, ys, style, color=c, label=f"{r['source']}, {r['rate_hz']} Hz, Method C")
        if r["source"] != "ours (literal window)":
            ax.axhline(
                r["UTW"], color=c, lw=0.8, ls="-" if r["source"] == "ours" else "--", alpha=0.5,
                label=f"{r['source']}, {r['rate_hz']} Hz, UTW median (thin)",
            )  # fmt: skip
    ax.set_xscale("log", base=2)
    ax.set(xticks=list(WINDOWS), xticklabels=[str(w) for w in WINDOWS], xlabel="window w (frames)")
    ax.set(ylabel="median similarity (eq. 2)", title="Table 1")
    ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0)
    ax.grid(alpha=0.3)
    return fig, ax
