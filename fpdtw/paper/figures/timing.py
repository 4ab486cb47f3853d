"""Time per target frame of the online aligners (``make bench``'s ``results/bench.json``,
measurements): Table 2, and why Mc w80 looks cheap (:func:`exhausted_fraction`).
"""

from __future__ import annotations

import json

import numpy as np

from fpdtw.paper.figures.plotting import new_axes
from fpdtw.paper.numbers import FPDTW_NAMES, FPDTW_TYPEV_NAMES, TABLE2_US, WINDOWS
from fpdtw.paper.paths import results_dir
from fpdtw.paper.runner.grid import BAND_1S, BAND_BASES, BAND_HALF_W, MC_LITERAL_NAMES
from fpdtw.registry import baselines, resolve


def timed_names() -> tuple:
    """Table 2's online algorithms in table order, the registry's baselines (read at each
    call) and Method C's literal window of notebook 15.

    Paper: FP-DTW Table 2.
    """
    return ("OE-DTW",) + FPDTW_NAMES + FPDTW_TYPEV_NAMES + baselines() + MC_LITERAL_NAMES


#: :func:`timed_names` with the registry as built in.
TIMED_NAMES = timed_names()


def _default_rows(rows):
    """Rows of the paper's configurations (no options in brackets)."""
    return [r for r in rows if "(" not in r.get("algorithm", "")]


def pair_maps(results, name: str):
    """Each pair's map of an algorithm with the pair's last input frame: ``(M, m)``."""
    arr = results.get(name)
    m, _ = results.frames(name)
    m_of = {int(p["id"]): int(m[i]) for i, p in enumerate(results.pairs)}
    for k, pid in enumerate(arr["pair_id"]):
        yield arr.map(k), m_of[int(pid)]


def exhausted_fraction(results, name: str) -> dict:
    """How many target frames ``q >= 1`` an aligner processed with the input run out
    (``M_{q-1} = m``), over all pairs: counts, ``fraction``, ``pairs_exhausted_early``.

    Paper: FP-DTW Section 5 (Table 2: "Mc w80 ... running out of input frames").
    """
    counts = [(int(np.count_nonzero(M[:-1] >= m)), M.size - 1) for M, m in pair_maps(results, name)]
    exhausted, frames = (sum(c[k] for c in counts) for k in (0, 1))
    fraction = float(exhausted / frames) if frames else 0.0
    return dict(frames=int(frames), exhausted=int(exhausted), fraction=fraction,
                pairs_exhausted_early=sum(e > 0 for e, _ in counts))  # fmt: skip


def time_per_frame_rows(bench: dict, results=None, names=None) -> list[dict]:
    """Table 2: the time per target frame of each aligner of ``names`` (default
    :func:`timed_names`) the bench timed, with :func:`exhausted_fraction` given ``results``
    and the paper's mean.

    Paper: FP-DTW Table 2.
    Notebook: 09_table2_timing.ipynb
    """
    by = {r["name"]: r for r in list(bench.get("online", [])) + list(bench.get("oe_dtw", []))}
    rows = []
    for name in [n for n in (timed_names() if names is None else names) if n in by]:
        b = by[name]
        a = resolve(name)
        method, w, typev = a.family, (a.w if a.family in ("B", "C") else None), a.typev
        ex = None
        if results is not None and name in results.algorithms:
            ex = exhausted_fraction(results, name)["fraction"]
        rows.append(
            dict(algorithm=name, method=method, w=w, type_v=typev, frames=int(b["frames"]),
                 mean_us=float(b["mean_s"] * 1e6), median_us=float(b["median_s"] * 1e6),
                 p95_us=float(b["p95_s"] * 1e6), exhausted_fraction=ex,
                 paper_mean_us=None if typev else TABLE2_US.get((method, w)))
        )  # fmt: skip
    return rows


def growth_ratio(rows, method: str, key="mean_us", type_v=False):
    """Per-frame time (``key``) of a method at w80 over w10, or None when either is missing.

    Paper: FP-DTW Table 2 (B: 16945 / 856 = 19.8; C: 10106 / 782 = 12.9).
    Notebook: 09_table2_timing.ipynb
    """
    by = {(r["method"], r["w"], r["type_v"]): r[key] for r in _default_rows(rows)}
    a, b = by.get((method, 10, type_v)), by.get((method, 80, type_v))
    if a is None or b is None or a <= 0:
        return None
    return float(b / a)


def paper_growth_ratio(method: str) -> float:
    """The paper's Table 2 ratio of per-frame time at w80 over w10."""
    return TABLE2_US[(method, 80)] / TABLE2_US[(method, 10)]


def slowest_window(rows, method: str, key="mean_us"):
    """The unconstrained window with the highest per-frame time of a method (None if none)."""
    cand = [r for r in _default_rows(rows) if r["method"] == method and not r["type_v"] and r["w"]]
    if not cand:
        return None
    return int(max(cand, key=lambda r: r[key])["w"])


def load_bench(path=None):
    """The report of ``make bench`` (``results/bench.json``), or None if it does not exist.

    Notebook: 09_table2_timing.ipynb
    """
    path = results_dir() / "bench.json" if path is None else path
    try:
        with open(path) as fh:
            return json.load(fh)
    except FileNotFoundError:
        return None


def plot_time_vs_w(rows, ax=None):
    """Median time per frame against w (Methods B and C), next to the paper's Table 2 means.

    Paper: FP-DTW Table 2 ("per-frame cost grows steeply with w").
    Notebook: 09_table2_timing.ipynb
    """
    key = "median_us"
    fig, ax = new_axes(ax, figsize=(6, 4.2))
    rows = _default_rows(rows)
    colours = {"B": "tab:green", "C": "tab:purple"}
    for method in ("B", "C"):
        ws = list(WINDOWS)
        ax.plot(ws, [TABLE2_US[(method, w)] for w in ws], "--s", color=colours[method], alpha=0.6,
                label=f"paper M{method.lower()} (mean, Table 2)")  # fmt: skip
        for tv in (False, True):
            pts = sorted(
                (r["w"], r[key])
                for r in rows
                if r["method"] == method and r["type_v"] == tv and r.get(key) is not None
            )
            if not pts:
                continue
            x, y = zip(*pts)
            label = f"ours M{method.lower()}{' + Type V' if tv else ''} ({key[:-3]})"
            ax.plot(x, y, "-o" if not tv else ":^", color=colours[method], label=label)
    ax.axhline(1e6 / 120, color="red", lw=0.8)
    ax.text(10, 1e6 / 120 * 1.1, "120 Hz budget: 8333 us", color="red", fontsize=8)
    ax.set_xscale("log", base=2)
    ax.set(yscale="log", xticks=list(WINDOWS), xticklabels=[str(w) for w in WINDOWS])
    ax.set(xlabel="window w (frames)", ylabel="time per target frame (us)")
    ax.legend(fontsize=7, loc="center right")
    ax.grid(alpha=0.3, which="both")
    return fig, ax


def step_s(row) -> float:
    """A bench row's median time per window step when measured, else per frame."""
    return row.get("step_median_s") or row["median_s"]


def band_cost(report) -> list:
    """Per-frame cost (:func:`step_s`) of notebook 16's global band variants (Q3) beside
    their bases, with ``ratio`` (band / base).

    Paper: FP-DTW Section 7 (conclusion: a global constraint).
    Notebook: 16_open_questions.ipynb
    """
    by_name = {r["name"]: r for r in report.get("online", [])}
    rows = []
    for label in (BAND_1S, BAND_HALF_W):
        for base in BAND_BASES:
            band = f"{base} ({label})"
            if base in by_name and band in by_name:
                b, v = step_s(by_name[base]), step_s(by_name[band])
                rows.append(
                    {"name": base, "band": band, "base_us": b * 1e6, "band_us": v * 1e6,
                     "ratio": v / b}
                )  # fmt: skip
    return rows
