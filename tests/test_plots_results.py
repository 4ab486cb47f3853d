"""Figs. 5, 6, 7, 10 and Tables 1, 2 on a small FAKE results folder with hand-made numbers.

The folder is written here with numpy directly, in the runner's file format
(``pairs.json``, ``run.json``, ``algorithms/<slug>.npz``), and read
back with :func:`fpdtw.paper.runner.run.load_results`, so these tests also pin the format.
"""

from __future__ import annotations

import json

import matplotlib
import matplotlib.pyplot as plt
import numpy as np
import pytest

from fpdtw.paper.figures import heatmaps, scores, timing
from fpdtw.paper.numbers import FPDTW_NAMES, PAPER_NAMES

#: Pairs of the fake run: 20 input and 20 target frames at 120 Hz (10 and 10 at 60 Hz).
N_PAIRS = 5
M120 = N120 = 19
M60 = N60 = 9
#: Per-pair offsets around each algorithm's median: median = centre, q1/q3 = centre -/+ 0.5 step.
SPREAD = np.array([-2.0, -1.0, 0.0, 1.0, 2.0])
TABLE1_60 = ("DTW@60Hz", "UTW@60Hz", "Mc w10@60Hz", "Mc w20@60Hz", "Mc w40@60Hz", "Mc w80@60Hz")


def fake_slug(name):
    """The runner's file name rule, written out independently: " + Type V" -> "_TypeV",
    "@60Hz" -> "_60Hz", spaces -> "_", option brackets and commas dropped."""
    s = name.replace(" + Type V", "_TypeV").replace("@60Hz", "_60Hz").replace(" ", "_")
    return s.replace("(", "").replace(")", "").replace(",", "").replace("__", "_")


def diagonal_map(n, m):
    return np.round(np.arange(n + 1) * m / n).astype(np.int32)


def write_fake_results(folder, algos, n_pairs=N_PAIRS, sizes=None):
    """Write a results folder in the runner's format.

    Parameters
    ----------
    folder : Path
        ``results_dir() / mode``.
    algos : dict
        name -> dict(similarity=(P,), deviation=(P,), maps=list of P int arrays or None
        (diagonal), online=bool (default: not DTW or UTW), fps=120 or 60).
    sizes : list of (m, n, m60, n60), optional
    """
    sizes = sizes or [(M120, N120, M60, N60)] * n_pairs
    pairs = [
        dict(
            id=k,
            dataset="authors_fbx" if k < 3 else "hdm05",
            movement="Walk" if k < 3 else "squat",
            input=f"in{k}",
            target=f"tg{k}",
            input_path=f"in{k}.fbx",
            target_path=f"tg{k}.fbx",
            m=sizes[k][0],
            n=sizes[k][1],
            m60=sizes[k][2],
            n60=sizes[k][3],
        )
        for k in range(n_pairs)
    ]
    counts = {"total": {"motions": 2 * n_pairs, "movements": 2, "pairs": n_pairs}}
    folder.mkdir(parents=True)
    (folder / "pairs.json").write_text(
        json.dumps({"mode": folder.name, "selection": None, "counts": counts, "pairs": pairs})
    )
    info = []
    for name, a in algos.items():
        fps = a.get("fps", 120)
        maps = a.get("maps")
        if maps is None:
            maps = [
                diagonal_map(p["n"] if fps == 120 else p["n60"], p["m"] if fps == 120 else p["m60"])
                for p in pairs
            ]
        offsets = np.concatenate([[0], np.cumsum([len(M) for M in maps])]).astype(np.int64)
        ids = np.arange(n_pairs, dtype=np.int32)
        (folder / "algorithms").mkdir(exist_ok=True)
        np.savez(
            folder / "algorithms" / f"{fake_slug(name)}.npz",
            pair_id=ids,
            offsets=offsets,
            maps=np.concatenate(maps).astype(np.int32),
            similarity=np.asarray(a["similarity"], dtype=np.float64),
            deviation=np.asarray(a["deviation"], dtype=np.float64),
        )
        online = a.get("online", name.split("@")[0] not in ("DTW", "UTW"))
        info.append(dict(name=name, slug=fake_slug(name), fps=float(fps), online=online))
    (folder / "run.json").write_text(json.dumps({"algorithms": info}))
    return folder


def paper_like_medians():
    """Median similarity and deviation per algorithm of a fake run that mirrors the paper:
    UTW median 0.24; Mc w40 passes both; Ma + Type V and Mc w80 + Type V pass both."""
    sim = {"DTW": 0.6, "UTW": 0.24, "OE-DTW": 0.1}
    dev = {"DTW": 0.0, "UTW": 30.0, "OE-DTW": 50.0}
    base_sim = {"Ma": 0.02, "Mb w10": 0.05, "Mb w20": 0.08, "Mb w40": 0.1, "Mb w80": 0.12,
                "Mc w10": 0.04, "Mc w20": 0.2, "Mc w40": 0.3, "Mc w80": 0.14}  # fmt: skip
    base_dev = {"Ma": 90.0, "Mb w10": 80.0, "Mb w20": 70.0, "Mb w40": 60.0, "Mb w80": 50.0,
                "Mc w10": 85.0, "Mc w20": 40.0, "Mc w40": 10.0, "Mc w80": 45.0}  # fmt: skip
    for n in FPDTW_NAMES:
        sim[n], dev[n] = base_sim[n], base_dev[n]
        better = n.startswith(("Ma", "Mb")) or n == "Mc w80"
        sim[n + " + Type V"] = base_sim[n] + (0.01 if better else -0.01)
        dev[n + " + Type V"] = base_dev[n] + (-5.0 if better else 5.0)
    sim["Ma + Type V"], dev["Ma + Type V"] = 0.25, 12.0
    sim["Mc w80 + Type V"], dev["Mc w80 + Type V"] = 0.28, 8.0
    sim["Mc w40 + Type V"], dev["Mc w40 + Type V"] = 0.22, 25.0
    # Table 1: best window 40 at 120 Hz (above), 20 at 60 Hz
    sim.update({"DTW@60Hz": 0.6, "UTW@60Hz": 0.2, "Mc w10@60Hz": 0.1, "Mc w20@60Hz": 0.3,
                "Mc w40@60Hz": 0.15, "Mc w80@60Hz": 0.05})  # fmt: skip
    dev.update({n: 20.0 for n in TABLE1_60})
    return sim, dev


def paper_like_algos(sim, dev, step=(0.01, 1.0)):
    algos = {}
    for name in tuple(PAPER_NAMES) + TABLE1_60:
        a = dict(
            similarity=sim[name] + step[0] * SPREAD,
            deviation=np.maximum(dev[name] + step[1] * SPREAD, 0.0) if dev[name] else np.zeros(5),
            fps=60 if name.endswith("@60Hz") else 120,
        )
        algos[name] = a
    return algos


@pytest.fixture
def fake(tmp_path, monkeypatch):
    """A loaded fake run mirroring the paper (see :func:`paper_like_medians`)."""
    from fpdtw.paper.runner.run import load_results

    monkeypatch.setenv("FPDTW_RESULTS_DIR", str(tmp_path))
    sim, dev = paper_like_medians()
    write_fake_results(tmp_path / "fake", paper_like_algos(sim, dev))
    return load_results("fake")


# -- Figs. 5 and 6 -------------------------------------------------------------------------------


def test_score_summary_medians_quartiles_and_benchmarks(fake):
    rows = {r["algorithm"]: r for r in scores.score_summary(fake, "similarity")}
    assert len(rows) == 3 + 2 * 9  # DTW, UTW, OE-DTW, 9 FP-DTW with and without Type V
    r = rows["Mc w40"]
    assert r["median"] == pytest.approx(0.30)
    assert r["q1"] == pytest.approx(0.29) and r["q3"] == pytest.approx(0.31)
    assert r["n"] == 5 and r["n_missing"] == 0
    assert r["benchmark"] == pytest.approx(0.24)  # UTW's median
    assert r["passes_benchmark"] and not rows["Mc w20"]["passes_benchmark"]
    assert not rows["UTW"]["passes_benchmark"]  # equal to the benchmark is not above it
    assert rows["Ma + Type V"]["type_v"] and not rows["Ma"]["type_v"]
    assert set(scores.passing(rows.values(), online_only=True)) == {
        "Mc w40",
        "Ma + Type V",
        "Mc w80 + Type V",
    }
    dev = {r["algorithm"]: r for r in scores.score_summary(fake, "deviation")}
    assert dev["Mc w40"]["median"] == pytest.approx(10.0)
    assert dev["Mc w40"]["benchmark"] == 18.0
    assert dev["DTW"]["passes_benchmark"] and dev["Mc w40"]["passes_benchmark"]
    assert not dev["Mb w80"]["passes_benchmark"]


def test_score_summary_leaves_out_and_counts_nan(tmp_path, monkeypatch):
    from fpdtw.paper.runner.run import load_results

    monkeypatch.setenv("FPDTW_RESULTS_DIR", str(tmp_path))
    algos = {
        "UTW": dict(similarity=[0.1, 0.2, 0.3], deviation=[5.0, 5.0, 5.0]),
        "Ma": dict(similarity=[np.nan, 0.5, 0.7], deviation=[1.0, 2.0, 30.0]),
    }
    write_fake_results(tmp_path / "nan", algos, n_pairs=3)
    rows = scores.score_summary(load_results("nan"), "similarity", names=["Ma"])
    assert rows[0]["n"] == 2 and rows[0]["n_missing"] == 1
    assert rows[0]["median"] == pytest.approx(0.6)  # median of 0.5 and 0.7
    assert rows[0]["passes_benchmark"]  # 0.6 > UTW's 0.2


@pytest.mark.parametrize(("metric", "y", "colour"), [("similarity", 0.24, "red"),
                                                      ("deviation", 18.0, "blue")])  # fmt: skip
def test_box_plot_has_one_box_per_algorithm_and_the_benchmark_line(fake, metric, y, colour):
    fig, ax = scores.plot_score_boxes(fake, metric)
    boxes = [p for p in ax.patches if p.get_gid() != "benchmark_ci"]
    assert len(boxes) == 3 + 2 * 9
    # every median with its 95 % interval beside its box; UTW's interval around the red line
    bars = [c for c in ax.collections if c.get_gid() == "median_ci"]
    assert len(bars) == len(boxes)
    row = scores.score_summary(fake, metric, names=["Mc w40"])[0]
    ends = [tuple(np.ravel(c.get_segments()[0])[[1, 3]]) for c in bars]
    assert (row["ci_low"], row["ci_high"]) in ends
    assert row["ci_low"] <= row["median"] <= row["ci_high"]
    band = [p for p in ax.patches if p.get_gid() == "benchmark_ci"]
    assert len(band) == (1 if metric == "similarity" else 0)
    pink = matplotlib.colors.to_rgba(scores.COLOURS["typev"])
    assert sum(np.allclose(b.get_facecolor(), pink) for b in boxes) == 9
    lines = [ln for ln in ax.lines if ln.get_gid() == "benchmark"]
    assert len(lines) == 1
    assert lines[0].get_ydata()[0] == pytest.approx(y)
    assert matplotlib.colors.same_color(lines[0].get_color(), colour)
    # names without results (OPW, OLTW in this fake run) are left out
    present = [n for n in scores.BASE_NAMES if n in fake.algorithms]
    assert "OPW" not in present and len(present) == 12
    assert [t.get_text() for t in ax.get_xticklabels()] == present
    # the median line of the Mc w40 box (no Type V) sits at its median
    medians = [ln for ln in ax.lines if ln.get_gid() == "median"]
    assert len(medians) == len(boxes)
    want = 0.30 if metric == "similarity" else 10.0
    x_mc40 = present.index("Mc w40") - 0.2
    hit = [ln for ln in medians if np.mean(ln.get_xdata()) == pytest.approx(x_mc40)]
    assert len(hit) == 1 and hit[0].get_ydata()[0] == pytest.approx(want)
    plt.close(fig)


def test_score_summary_of_one_dataset(fake):
    # fake pairs 0-2 are authors_fbx, 3-4 hdm05; per-pair offsets SPREAD = -2, -1, 0, 1, 2 steps
    rows = {r["algorithm"]: r for r in scores.score_summary(fake, "similarity", dataset="hdm05")}
    assert rows["Mc w40"]["n"] == 2
    assert rows["Mc w40"]["median"] == pytest.approx(0.315)  # mean of 0.31 and 0.32
    assert rows["Mc w40"]["benchmark"] == pytest.approx(0.255)  # UTW over the same pairs
    rows = scores.score_summary(fake, "deviation", names=["Mc w40"], dataset="authors_fbx")
    assert rows[0]["n"] == 3 and rows[0]["median"] == pytest.approx(9.0)  # 8, 9, 10
    with pytest.raises(ValueError, match="no pairs"):
        scores.scores(fake, "Ma", "similarity", dataset="cmu")


def test_deviation_box_plot_is_linear_and_counts_what_it_cuts(tmp_path, monkeypatch):
    """Fig. 6: a linear axis cut above the highest whisker (at least twice 18 frames), never
    symlog; each value above the cut is counted over its box and in the legend."""
    from fpdtw.paper.runner.run import load_results

    monkeypatch.setenv("FPDTW_RESULTS_DIR", str(tmp_path))
    algos = {
        "DTW": dict(similarity=[0.6] * 5, deviation=[0.0] * 5),
        "UTW": dict(similarity=[0.2] * 5, deviation=[5.0, 6.0, 7.0, 8.0, 9.0]),
        "Mc w40": dict(similarity=[0.3] * 5, deviation=[1.0, 2.0, 3.0, 4.0, 500.0]),
    }
    write_fake_results(tmp_path / "cut", algos)
    res = load_results("cut")
    kw = dict(names=("DTW", "UTW", "Mc w40"), typev=False, intervals=False)
    fig, ax = scores.plot_score_boxes(res, "deviation", **kw)
    assert ax.get_yscale() == "linear"
    # whiskers: UTW's top 9, Mc w40's 4 (500 is beyond 1.5 IQR); twice 18 is higher: 36
    assert ax.get_ylim() == pytest.approx((0.0, 1.08 * 36.0))
    counts = [t for t in ax.texts if t.get_gid() == "clipped_count"]
    assert [(t.get_text(), t.get_position()[0]) for t in counts] == [("\u25b21", 2.0)]
    legend = [t.get_text() for t in ax.get_legend().get_texts()]
    assert any("above 39 frames, not drawn (1 of 15)" in t for t in legend), legend
    plt.close(fig)
    fig, ax = scores.plot_score_boxes(res, "deviation", clip=600.0, **kw)
    assert ax.get_ylim()[1] == 600.0 and not [t for t in ax.texts if t.get_gid()]
    plt.close(fig)
    fig, ax = scores.plot_score_boxes(res, "similarity", **kw)
    assert ax.get_yscale() == "linear" and not ax.texts
    plt.close(fig)


def test_fig5_draws_the_papers_utw_level_beside_ours(fake):
    from fpdtw.paper import numbers

    fig, ax = scores.plot_score_boxes(fake, "similarity")
    paper = [ln for ln in ax.lines if ln.get_gid() == "paper_benchmark"]
    ours = [ln for ln in ax.lines if ln.get_gid() == "benchmark"]
    assert len(paper) == 1 and len(ours) == 1
    assert paper[0].get_ydata()[0] == pytest.approx(numbers.TABLE1[120]["UTW"]) == 0.240
    legend = [t.get_text() for t in ax.get_legend().get_texts()]
    assert "paper's UTW median = 0.240 (Table 1)" in legend
    assert any(t.startswith("our UTW median (benchmark) = 0.240") for t in legend)
    plt.close(fig)
    fig, ax = scores.plot_score_boxes(fake, "deviation")
    assert not [ln for ln in ax.lines if ln.get_gid() == "paper_benchmark"]
    plt.close(fig)


def test_beyond_the_paper_rule():
    from fpdtw.paper.figures.plotting import beyond_paper

    for name in PAPER_NAMES + ("Mc w40@60Hz", "UTW@60Hz", "Mc w40 (literal window)",
                               "Mc w80 (literal window) + Type V"):  # fmt: skip
        assert not beyond_paper(name), name
    for name in ("OPW", "OLTW", "OLTW c60", "Mc auto", "OPW adaptive", "Mc w30",
                 "Mc w40 (band 1 s)", "Mc w40 (derivative)", "OLTW (weighted joints)",
                 "Mb w40 (weighted joints)", "no such method"):  # fmt: skip
        assert beyond_paper(name), name


@pytest.fixture
def fake_beyond(tmp_path, monkeypatch):
    """The fake run of :func:`fake` with OPW and OLTW added (diagonal maps)."""
    from fpdtw.paper.runner.run import load_results

    monkeypatch.setenv("FPDTW_RESULTS_DIR", str(tmp_path))
    sim, dev = paper_like_medians()
    algos = paper_like_algos(sim, dev)
    for name, (s_, d_) in {"OPW": (0.15, 30.0), "OLTW": (0.26, 12.0)}.items():
        algos[name] = dict(similarity=s_ + 0.01 * SPREAD, deviation=d_ + SPREAD)
    write_fake_results(tmp_path / "beyond", algos)
    return load_results("beyond")


def _box_at(ax, x):
    """The box patch whose centre is at x."""
    boxes = [p for p in ax.patches if p.get_gid() != "benchmark_ci"]
    xs = [b.get_path().vertices[:, 0] for b in boxes]
    hit = [b for b, v in zip(boxes, xs) if (v.min() + v.max()) / 2 == pytest.approx(x)]
    assert len(hit) == 1
    return hit[0]


@pytest.mark.parametrize("metric", ["similarity", "deviation"])
def test_box_plot_sets_apart_the_methods_beyond_the_paper(fake_beyond, metric):
    from fpdtw.paper.figures.plotting import BEYOND_PAPER_LABEL, BEYOND_PAPER_PATCH

    fig, ax = scores.plot_score_boxes(fake_beyond, metric)
    names = [t.get_text() for t in ax.get_xticklabels()]
    assert names[-2:] == ["OPW", "OLTW"]
    grey = matplotlib.colors.to_rgba(BEYOND_PAPER_PATCH["facecolor"])
    for name in ("OPW", "OLTW"):
        box = _box_at(ax, names.index(name))
        assert box.get_hatch() == BEYOND_PAPER_PATCH["hatch"]
        assert np.allclose(box.get_facecolor(), grey)
    for x in (names.index("Mc w40") - 0.2, names.index("Mc w40") + 0.2, names.index("UTW")):
        box = _box_at(ax, x)
        assert not box.get_hatch()
        assert not np.allclose(box.get_facecolor(), grey)
    ticks = {t.get_text(): t for t in ax.get_xticklabels()}
    assert ticks["OPW"].get_fontstyle() == "italic" and ticks["Mc w40"].get_fontstyle() == "normal"
    sep = [ln for ln in ax.lines if ln.get_gid() == "beyond_paper_separator"]
    assert len(sep) == 1 and sep[0].get_xdata()[0] == pytest.approx(names.index("OPW") - 0.5)
    assert [t.get_text().strip() for t in ax.texts if t.get_gid() == "beyond_paper_label"] == [
        BEYOND_PAPER_LABEL + " \u2192"
    ]
    assert BEYOND_PAPER_LABEL in [t.get_text() for t in ax.get_legend().get_texts()]
    plt.close(fig)


def test_box_plot_of_the_papers_methods_alone_has_no_beyond_style(fake):
    fig, ax = scores.plot_score_boxes(fake, "similarity")
    assert not any(p.get_hatch() for p in ax.patches)
    assert not [ln for ln in ax.lines if ln.get_gid() == "beyond_paper_separator"]
    assert "beyond the paper" not in [t.get_text() for t in ax.get_legend().get_texts()]
    plt.close(fig)


def test_box_plot_without_type_v(fake):
    fig, ax = scores.plot_score_boxes(
        fake, "similarity", names=("UTW", "Ma", "Mc w40"), typev=False, intervals=False
    )
    assert len(ax.patches) == 3
    assert not [c for c in ax.collections if c.get_gid() == "median_ci"]
    plt.close(fig)


# -- Table 1 -------------------------------------------------------------------------------------


def test_table1_best_windows_and_paper_rows(fake):
    rows = scores.table1_rows(fake)
    by = {(r["rate_hz"], r["source"]): r for r in rows}
    assert set(by) == {(60, "paper"), (60, "ours"), (120, "paper"), (120, "ours")}
    assert by[(120, "ours")]["best_w"] == 40 and by[(60, "ours")]["best_w"] == 20
    assert by[(120, "paper")]["best_w"] == 40 and by[(60, "paper")]["best_w"] == 20
    assert by[(60, "ours")]["w20"] == pytest.approx(0.3)
    assert by[(60, "ours")]["UTW"] == pytest.approx(0.2)
    assert by[(120, "ours")]["UTW"] == pytest.approx(0.24)
    assert by[(120, "ours")]["above_utw"] == "40"
    assert by[(60, "paper")]["above_utw"] == "20"  # 0.281 > 0.242 only
    fig, ax = scores.plot_table1(rows)
    assert len([ln for ln in ax.lines if len(ln.get_xdata()) == 4]) == 4
    plt.close(fig)


def test_table1_plot_is_titled_and_its_legend_covers_no_point(fake):
    fig, ax = scores.plot_table1(scores.table1_rows(fake))
    assert ax.get_title() == "Table 1"
    fig.canvas.draw()
    legend = ax.get_legend().get_window_extent()
    frame = ax.get_window_extent()
    assert legend.x0 >= frame.x1  # wholly right of the axes: over no point, no line
    assert not legend.overlaps(frame)
    plt.close(fig)


def test_best_window_rules():
    assert scores.best_window({10: 0.1, 20: 0.3, 40: 0.2, 80: 0.0, "UTW": 0.9}) == 20
    assert scores.best_window({10: 0.2, 20: 0.2, 40: 0.1}) == 10  # tie: the smaller window
    with pytest.raises(ValueError):
        scores.best_window({"UTW": 0.2})


# -- Figs. 7 and 10 ------------------------------------------------------------------------------


def test_heatmap_of_diagonal_maps_is_diagonal(fake):
    H = heatmaps.heatmap(fake, "DTW", bins=20)  # every fake map is the diagonal
    assert H.shape == (20, 20)
    assert H.sum() == pytest.approx(1.0)
    assert np.allclose(H, np.diag(np.diag(H)))
    assert np.allclose(np.diag(H), 1 / 20)  # 20 frames over 20 bins: one per bin
    fig, ax = heatmaps.plot_heatmap(H)
    img = ax.images[0]
    assert img.origin == "lower"
    assert tuple(img.get_extent()) == (0, 1, 0, 1)
    data = np.ma.filled(img.get_array(), 0.0)
    assert np.allclose(data, H)
    plt.close(fig)
    b = heatmaps.path_balance(fake, "DTW")
    assert b == {"diagonal": 1.0, "below": 0.0, "above": 0.0, "pairs": 5}


def test_heatmap_and_balance_of_sticking_and_skipping_maps(tmp_path, monkeypatch):
    from fpdtw.paper.runner.run import load_results

    monkeypatch.setenv("FPDTW_RESULTS_DIR", str(tmp_path))
    n = N120
    stick = [np.zeros(n + 1, dtype=np.int32)] * 2  # input stuck on frame 0
    skip = [np.full(n + 1, M120, dtype=np.int32)] * 2  # input at its end at once
    algos = {
        "UTW": dict(similarity=[0.0, 0.0], deviation=[0.0, 0.0]),
        "Ma": dict(similarity=[0.0, 0.0], deviation=[0.0, 0.0], maps=stick),
        "Mc w80": dict(similarity=[0.0, 0.0], deviation=[0.0, 0.0], maps=skip),
    }
    write_fake_results(tmp_path / "ss", algos, n_pairs=2)
    res = load_results("ss")
    H = heatmaps.heatmap(res, "Ma", bins=10)
    assert np.allclose(H[0], 0.1) and H[1:].sum() == 0  # bottom row: input time 0
    H = heatmaps.heatmap(res, "Mc w80", bins=10)
    assert np.allclose(H[-1], 0.1) and H[:-1].sum() == 0  # top row: input time 1
    # q / n <= 0.1 is within the band: frames 0 and 1 of 0..19 (q / 19 <= 0.1)
    b = heatmaps.path_balance(res, "Ma", band=0.1)
    assert b["diagonal"] == pytest.approx(2 / 20) and b["below"] == pytest.approx(18 / 20)
    b = heatmaps.path_balance(res, "Mc w80", band=0.1)
    assert b["diagonal"] == pytest.approx(2 / 20) and b["above"] == pytest.approx(18 / 20)


def test_heatmap_grids_have_a_panel_per_algorithm(fake):
    fig, axes = heatmaps.plot_heatmap_grid(fake, heatmaps.fig7_names(), ncols=4, bins=10)
    visible = [ax for ax in axes.flat if ax.get_visible()]
    present = [n for n in heatmaps.fig7_names() if n in fake.algorithms]  # no OPW/OLTW here
    assert axes.shape == (3, 4) and len(visible) == len(present) == 10
    assert [ax.get_title() for ax in visible] == present
    norms = {id(ax.images[0].norm) for ax in visible}
    assert len(norms) == 1  # one shared colour scale
    plt.close(fig)
    assert all(ax.get_gid() != "beyond_paper_panel" for ax in visible)
    fig, axes = heatmaps.plot_typev_heatmaps(fake, bins=10)
    assert axes.shape == (2, 3)
    assert [ax.get_title() for ax in axes[1]] == [n + " + Type V" for n in heatmaps.FIG10_NAMES]
    plt.close(fig)
    fig, axes = heatmaps.plot_typev_heatmaps(fake, bases=FPDTW_NAMES, bins=10, per_row=5)
    assert axes.shape == (4, 5)
    assert sum(ax.get_visible() for ax in axes.flat) == 18
    plt.close(fig)


def test_heatmap_grid_sets_apart_the_panels_beyond_the_paper(fake_beyond):
    fig, axes = heatmaps.plot_heatmap_grid(fake_beyond, heatmaps.fig7_names(), ncols=4, bins=10)
    visible = {ax.get_title().split("\n")[0]: ax for ax in axes.flat if ax.get_visible()}
    assert visible["OPW"].get_title() == "OPW\n(beyond the paper)"
    assert visible["OLTW"].get_gid() == "beyond_paper_panel"
    assert visible["OPW"].spines["left"].get_linestyle() == "--"
    assert visible["Mc w40"].get_title() == "Mc w40"
    assert visible["Mc w40"].get_gid() != "beyond_paper_panel"
    assert visible["Mc w40"].spines["left"].get_linestyle() != "--"
    plt.close(fig)


# -- Table 2 -------------------------------------------------------------------------------------


def test_time_per_frame_from_the_bench_and_exhausted_frames(tmp_path, monkeypatch):
    from fpdtw.paper.runner.run import load_results

    monkeypatch.setenv("FPDTW_RESULTS_DIR", str(tmp_path))
    sizes = [(9, 4, 4, 2), (9, 3, 4, 1)]  # pair 0: 5 target frames, pair 1: 4
    early = [np.array([0, 9, 9, 9, 9]), np.array([0, 3, 6, 9])]  # reaches m = 9 at q = 1 / q = 3
    algos = {
        "UTW": dict(similarity=[0.0, 0.0], deviation=[0.0, 0.0]),
        "Mb w10": dict(similarity=[0, 0], deviation=[0, 0], maps=early),
        "Mc w10": dict(similarity=[0, 0], deviation=[0, 0], maps=early),
    }
    write_fake_results(tmp_path / "t", algos, n_pairs=2, sizes=sizes)
    res = load_results("t")

    def row(name, med, mean):
        return dict(name=name, median_s=med * 1e-6, mean_s=mean * 1e-6, p95_s=2 * med * 1e-6,
                    frames=100)  # fmt: skip

    bench = {
        "online": [row("Mb w10", 7.0, 8.0), row("Mc w10", 5.0, 6.0),
                   row("Mc w10 (literal window)", 3.0, 3.5)],
        "oe_dtw": [row("OE-DTW", 11.0, 12.0)],
    }  # fmt: skip
    rows = {r["algorithm"]: r for r in timing.time_per_frame_rows(bench, res)}
    assert list(rows) == ["OE-DTW", "Mb w10", "Mc w10", "Mc w10 (literal window)"]
    b = rows["Mb w10"]
    assert (b["median_us"], b["mean_us"], b["p95_us"], b["frames"]) == pytest.approx(
        (7.0, 8.0, 14.0, 100)
    )
    # exhausted (M_{q-1} = 9): pair 0 frames q = 2, 3, 4; pair 1: none -> 3 of 7 frames q >= 1
    assert b["exhausted_fraction"] == pytest.approx(3 / 7)
    assert b["paper_mean_us"] == 856.0 and rows["Mc w10"]["paper_mean_us"] == 782.0
    assert rows["OE-DTW"]["exhausted_fraction"] is None  # not in the results
    assert rows["Mc w10 (literal window)"]["method"] == "C"
    ex = timing.exhausted_fraction(res, "Mb w10")
    assert ex == {"frames": 7, "exhausted": 3, "fraction": 3 / 7, "pairs_exhausted_early": 1}
    fig, ax = timing.plot_time_vs_w(list(rows.values()))
    assert ax.get_yscale() == "log"
    # paper B, C; ours B, C (w10 only; the literal window is not drawn); the 120 Hz budget
    assert len(ax.lines) == 2 + 2 + 1
    plt.close(fig)


def test_growth_ratio_and_slowest_window():
    rows = [
        dict(method="B", w=w, type_v=False, mean_us=t)
        for w, t in ((10, 2.0), (20, 5.0), (40, 10.0), (80, 40.0))
    ] + [dict(method="C", w=w, type_v=False, mean_us=t) for w, t in ((10, 2.0), (80, 1.0))]
    assert timing.growth_ratio(rows, "B") == pytest.approx(20.0)
    assert timing.growth_ratio(rows, "C") == pytest.approx(0.5)
    assert timing.growth_ratio(rows, "B", type_v=True) is None
    assert timing.slowest_window(rows, "B") == 80 and timing.slowest_window(rows, "C") == 10
    assert timing.paper_growth_ratio("B") == pytest.approx(16945 / 856)


def test_load_bench_missing_is_none(tmp_path):
    assert timing.load_bench(tmp_path / "bench.json") is None
    (tmp_path / "bench.json").write_text('{"online": []}')
    assert timing.load_bench(tmp_path / "bench.json") == {"online": []}
