"""Figures and tables of notebook 16: the questions the papers leave open (Q1-Q6), from
the claims' evidence (:func:`fpdtw.paper.claims.contexts.open_evidence`).

Paper: FP-DTW Section 7; OPW poster Section 6.
Notebook: 16_open_questions.ipynb
"""

from __future__ import annotations

from functools import partial

import matplotlib.pyplot as plt
import numpy as np

from fpdtw import registry
from fpdtw.dtw import dtw_pair
from fpdtw.online.base import run_online
from fpdtw.online.opw import OPW
from fpdtw.online.opw_adaptive import AdaptiveOPW
from fpdtw.paper import opw_eval as oe
from fpdtw.paper.claims.open import BEST_FIXED, band_removed_share, per_movement_windows
from fpdtw.paper.edits import edit_target, true_map
from fpdtw.paper.figures.plotting import new_axes
from fpdtw.paper.numbers import WINDOWS
from fpdtw.paper.pause import insert_pause, pause_plan, pause_seed
from fpdtw.paper.runner.grid import (
    BAND_1S,
    BAND_BASES,
    BAND_HALF_W,
    DERIVATIVE_BASES,
    PAUSE_METHODS,
    PAUSE_SUFFIX,
    WEIGHT_BASES,
)
from fpdtw.period import MAX_PERIOD_S, MIN_PEAK, autocorrelation, dominant_period

_SFX = {120: "", 60: "@60Hz"}
#: The panels of the Q1-Q5 figures: the median's key, its interval's key prefix, the y label.
_PANELS = (
    ("similarity", "sim", "median similarity (eq. 2)"),
    ("deviation", "dev", "median deviation (frames)"),
)


def _errorbars(ax, x, rows, key: str, pre: str, **kw):
    """The medians ``r[key]`` of ``rows`` at ``x``, with their intervals ``r[pre + "_low"]``
    .. ``r[pre + "_high"]``."""
    lo, hi = pre + "_low", pre + "_high"
    y = np.array([r[key] for r in rows])
    err = np.array([[r[key] - r[lo] for r in rows], [r[hi] - r[key] for r in rows]])
    ax.errorbar(x, y, yerr=err, fmt="o", ms=4, capsize=2, **kw)


def plot_period(I, ax=None):
    """Q1's rule on one motion: its joints' mean autocorrelation and its period.

    Paper: FP-DTW Section 7.
    Notebook: 16_open_questions.ipynb
    """
    fig, ax = new_axes(ax, figsize=(7, 3))
    r = autocorrelation(I.quats)
    k = min(r.size, int(MAX_PERIOD_S * I.fps) + 1)
    t = np.arange(k) / I.fps
    ax.plot(t, r[:k], color="k", lw=1.2, label="autocorrelation (24 axes, variance-weighted)")
    ax.axhline(0.0, color="0.6", lw=0.8)
    ax.axhline(MIN_PEAK, color="0.6", lw=0.8, ls=":", label=f"cyclic if peak >= {MIN_PEAK}")
    P = dominant_period(I.quats, I.fps)
    if P is not None:
        ax.axvline(P / I.fps, color="C3", lw=1.2, label=f"period {P} frames ({P / I.fps:.2f} s)")
        ax.axvline(P / (2 * I.fps), color="C0", lw=1.0, ls="--", label="half the period")
    ax.set(xlabel="lag (s)", ylabel="autocorrelation")
    ax.set_title(f"{I.name}: {'acyclic' if P is None else 'cyclic'}")
    ax.legend(fontsize=7, loc="upper right")
    return fig, ax


def _medians(ev, name: str, utw_gap=False) -> dict:
    """Medians of ``name`` with 95 % intervals and verdicts (``utw_gap``: minus UTW's)."""
    s, d = ev.passes(name, "similarity"), ev.passes(name, "deviation")
    lo, hi = ev.interval(name, "similarity")
    gap = dict(sim_minus_utw_low=s.low, sim_minus_utw_high=s.high) if utw_gap else {}
    return dict(similarity=ev.median(name, "similarity"), sim_low=lo, sim_high=hi, **gap,
                passes_similarity=s.verdict, deviation=d.estimate, dev_low=d.low,
                dev_high=d.high, passes_deviation=d.verdict)  # fmt: skip


def window_rows(ev) -> list[dict]:
    """Q1: Mc auto and every fixed window at 120 and 60 Hz (:func:`_medians`).

    Notebook: 16_open_questions.ipynb
    """
    return [
        dict(algorithm=base, rate=rate, **_medians(ev, base + _SFX[rate], utw_gap=True))
        for rate in (120, 60)
        for base in ("Mc auto", *(f"Mc w{w}" for w in WINDOWS))
    ]


def plot_windows(ev, rows):
    """Q1: :func:`window_rows` drawn.

    Notebook: 16_open_questions.ipynb
    """
    fig, axes = plt.subplots(1, 2, figsize=(9, 3.2))
    for rate, dx, col in ((120, -0.12, "C0"), (60, 0.12, "C1")):
        rr = [r for r in rows if r["rate"] == rate]
        for ax, (key, pre, _) in zip(axes, _PANELS):
            _errorbars(ax, np.arange(len(rr)) + dx, rr, key, pre, color=col, label=f"{rate} Hz")
        u = ev.median("UTW" + _SFX[rate], "similarity")
        axes[0].axhline(u, color=col, lw=0.8, ls=":", label=f"UTW median {rate} Hz")
        axes[1].axhline(18 * rate / 120, color=col, lw=0.8, ls=":", label=f"150 ms at {rate} Hz")
    labels = [r["algorithm"] for r in rows if r["rate"] == 120]
    for ax, (*_, ylabel) in zip(axes, _PANELS):
        ax.set_xticks(range(len(labels)), labels, rotation=30, fontsize=8)
        ax.set_ylabel(ylabel)
        ax.legend(fontsize=6)
    fig.tight_layout()
    return fig, axes


def movement_rows(ev) -> list[dict]:
    """Q1 per movement at 120 and 60 Hz: Mc auto's median similarity beside the best fixed
    w on that movement and the overall best.

    Notebook: 16_open_questions.ipynb
    """
    return [
        dict(rate=rate, movement=r["movement"], pairs=r["pairs"], auto=r["auto"],
             best_w=r["best_w"], best=r["best"], overall=r[f"w{BEST_FIXED[rate]}"],
             beats_best=r["beats"], beats_overall=bool(r["auto"] > r[f"w{BEST_FIXED[rate]}"]))
        for rate in (120, 60)
        for r in per_movement_windows(ev, rate)
    ]  # fmt: skip


def _variant_rows(ev, bases, suffix: str) -> list[dict]:
    """Each base and its variant ``f"{base} ({suffix})"``: :func:`_medians` and paired changes."""
    rows = []
    for n in bases:
        b = f"{n} ({suffix})"
        for who in (n, b):
            change = {}
            for key, metric in (("sim", "similarity"), ("dev", "deviation")):
                c = ev.better(b, n, metric) if who == b else None
                for end in ("", "_low", "_high"):
                    change[f"{key}_change{end}"] = getattr(c, end[1:] or "estimate", None)
            rows.append(dict(algorithm=who, **_medians(ev, who), **change))
    return rows


def _plot_variants(ev, rows, mark: str):
    """:func:`_variant_rows` drawn, the names containing ``mark`` in colour."""
    fig, axes = plt.subplots(1, 2, figsize=(9, 3.2))
    x = np.arange(len(rows))
    for ax, (key, pre, ylabel) in zip(axes, _PANELS):
        for i, r in enumerate(rows):
            _errorbars(ax, x[i], [r], key, pre, color="C2" if mark in r["algorithm"] else "0.4")
        ax.set_xticks(x, [r["algorithm"] for r in rows], rotation=30, fontsize=7)
        ax.set_ylabel(ylabel)
    axes[0].axhline(ev.median("UTW", "similarity"), color="k", lw=0.8, ls=":", label="UTW median")
    axes[1].axhline(18, color="k", lw=0.8, ls=":", label="18 frames (150 ms)")
    for ax in axes:
        ax.legend(fontsize=7)
    fig.tight_layout()
    return fig, axes


def band_rows(ev) -> list[dict]:
    """Q3: Methods B and C without a band, with the band of 1 s (the first reading) and of
    w/2 (the claim's), with ``cells_removed`` (:func:`fpdtw.paper.claims.open.band_removed_share`).

    Notebook: 16_open_questions.ipynb
    """
    rows = []
    for n in BAND_BASES:
        rows += _variant_rows(ev, [n], BAND_1S) + _variant_rows(ev, [n], BAND_HALF_W)[1:]
    for r in rows:
        a = r["algorithm"]
        r["cells_removed"] = None if a in BAND_BASES else band_removed_share(ev, a)
    return rows


#: Q2: Mb w40, Mc w40 and OLTW without and with the joint weights (:mod:`fpdtw.weights`).
weight_rows = partial(_variant_rows, bases=WEIGHT_BASES, suffix="weighted joints")
#: Q5: Mc w40 and OPW on poses and on derivative motions (:mod:`fpdtw.derivative`).
derivative_rows = partial(_variant_rows, bases=DERIVATIVE_BASES, suffix="derivative")
#: The rows of Q2, Q3 and Q5 drawn (medians with 95 % intervals, the variants in colour).
plot_weights = partial(_plot_variants, mark="weighted")
plot_band = partial(_plot_variants, mark="band")
plot_derivative = partial(_plot_variants, mark="derivative")


def poster_gamma_rows() -> list[dict]:
    """Q4 on the OPW poster's protocol: OPW at gamma 5 % and OPW adaptive on each motion.

    Notebook: 16_open_questions.ipynb
    """
    rows = []
    for mo in oe.FIG4_MOTIONS:
        A = oe.load_cropped(mo.dataset, mo.path)
        g = oe.example_curve(A.duration, oe.OFFSET)
        B = oe.warp_motion(A, g)
        I, T = oe.opw_features(A), oe.opw_features(B)
        for label, aligner in (
            (f"OPW (gamma {100 * oe.GAMMA:.0f} %)", OPW(I, oe.OMEGA, oe.GAMMA, fps=B.fps)),
            ("OPW adaptive", AdaptiveOPW(I, oe.OMEGA, fps=B.fps)),
        ):
            run_online(aligner, T)
            d = oe.deviation_ms(aligner.curve, g)
            rows.append(
                dict(motion=mo.label, method=label, mean_ms=d["mean"], max_ms=d["max"],
                     removed=oe.temporal_difference_removed(aligner.curve, g),
                     final_gamma=aligner.gamma)
            )  # fmt: skip
    return rows


def pause_rows(ev) -> list[dict]:
    """Q6: each online method's median deviation without and with a pause, and the change.

    Notebook: 16_open_questions.ipynb
    """
    rows = []
    for n in PAUSE_METHODS:
        p = n + PAUSE_SUFFIX
        d0, d1 = ev.passes(n, "deviation"), ev.passes(p, "deviation")  # medians, intervals
        diff = ev.better(p, n, "deviation")
        rows.append(
            dict(method=n, without=d0.estimate, without_low=d0.low, without_high=d0.high,
                 with_pause=d1.estimate, with_low=d1.low, with_high=d1.high, below_18=d1.verdict,
                 change=diff.estimate, change_low=diff.low, change_high=diff.high,
                 not_raised=diff.verdict)
        )  # fmt: skip
    return rows


def plot_pause(ev, rows, ax=None):
    """Q6: :func:`pause_rows` drawn.

    Notebook: 16_open_questions.ipynb
    """
    fig, ax = new_axes(ax, figsize=(8, 3.2))
    x = np.arange(len(rows))
    for key, pre, dx, col, lab in (
        ("without", "without", -0.12, "0.4", "target as recorded"),
        ("with_pause", "with", 0.12, "C3", "pause of 0.5-2 s inserted"),
    ):
        _errorbars(ax, x + dx, rows, key, pre, color=col, label=lab)
    ax.axhline(18, color="k", lw=0.8, ls=":", label="18 frames (150 ms)")
    ax.set_yscale("symlog", linthresh=10)
    ax.set_xticks(x, [r["method"] for r in rows], rotation=30, fontsize=8)
    ax.set_ylabel("median deviation from DTW (frames)")
    ax.legend(fontsize=7)
    fig.tight_layout()
    return fig, ax


def edit_example(I, T, name: str = "Mc w40", edit: str = "cut 1 s") -> dict:
    """Q7 on one pair: the target ``T`` edited, and the true map, ``name``'s and ``name
    (relocate)``'s maps on it (input frames per edited target frame).

    Returns
    -------
    dict
        ``edited`` (MotionFeatures), ``at`` (the edit's first frame), ``maps`` (label -> int
        array (F',): ``"true map"``, ``name``, ``name (relocate)``).

    Paper: neither (beyond the papers, Q7).
    Notebook: 16_open_questions.ipynb
    """
    E, idx, at = edit_target(T, edit)
    maps = {"true map": true_map(dtw_pair(I, T).map, idx)}
    for who in (name, registry.with_option(name, "relocate")):
        maps[who] = np.asarray(registry.align(who, I, E)[0], dtype=np.int64)
    return dict(edited=E, at=at, edit=edit, maps=maps)


def plot_edit_example(example: dict, ax=None):
    """:func:`edit_example`'s maps, the edit marked; a jump of the relocating map is drawn
    as a vertical step (the map may go backwards).

    Notebook: 16_open_questions.ipynb
    """
    fig, ax = new_axes(ax, figsize=(7, 3.2))
    ax.axvline(
        example["at"], color="0.6", ls=":", label=f"{example['edit']} at frame {example['at']}"
    )
    for (label, M), (col, lw) in zip(
        example["maps"].items(), (("k", 2.2), ("C3", 1.2), ("C0", 1.2))
    ):
        ax.plot(M, color=col, lw=lw, label=label)
    ax.set(xlabel="edited target frame", ylabel="input frame")
    ax.legend(fontsize=7)
    return fig, ax


def plot_pause_example(I, T, name: str = "Mc w40", ax=None):
    """Q6 on one pair: DTW's and ``name``'s maps with and without the pause.

    Notebook: 16_open_questions.ipynb
    """
    fig, ax = new_axes(ax, figsize=(7, 3.2))
    at, L = pause_plan(T.n_frames, T.fps, pause_seed(T.name))
    Tp = insert_pause(T, at, L)
    ax.axvspan(at, at + L, color="0.85", label=f"pause: frame {at} held {L} frames")
    for who, col in (("DTW", "k"), (name, "C3")):
        ax.plot(registry.align(who, I, Tp)[0], color=col, lw=1.2, label=f"{who}, with the pause")
        ax.plot(registry.align(who, I, T)[0], color=col, lw=0.8, ls="--", label=f"{who}, without")
    ax.set(xlabel="target frame", ylabel="input frame")
    ax.legend(fontsize=7)
    return fig, ax
