"""``make bench`` and ``make bench-peers`` without timing anything that is asserted: the
limit kernels do the aligners' own work, the compiled replays reproduce the maps, the
report names every method and w with its ratios, the peers' report round-trips, and the
peers never run in the project's environment."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from reference.synthetic import synthetic_pair

from fpdtw.app import bench, bench_limit, bench_peers
from fpdtw.costs import geodesic_cost_matrix
from fpdtw.dtw import accumulate
from fpdtw.online.base import run_online
from fpdtw.paper.numbers import TABLE2_US
from fpdtw.registry import make_online

ROOT = Path(__file__).resolve().parents[1]
cycles = pytest.mark.skipif(not bench_limit.HAVE_CYCLES, reason="no cycle counter (x86-64 only)")


# ------------------------------------------------------------------------ limit kernels
def test_limit_window_is_the_geodesic_window_and_its_dtw_accumulation():
    I, T, _ = synthetic_pair(50, seed=4)
    start, nrows, ncols = 7, 11, 9
    F = bench_limit._soa(T.quats[3 : 3 + ncols])
    C = np.empty((nrows, ncols))
    D = np.empty((nrows, ncols))
    ev = bench_limit._limit_window(
        np.ascontiguousarray(I.quats), start, nrows, F, ncols, C, D, np.empty(ncols)
    )
    C_ref = geodesic_cost_matrix(I.quats[start : start + nrows], T.quats[3 : 3 + ncols])
    np.testing.assert_array_equal(C, C_ref)  # bit for bit, as the aligners' costs
    np.testing.assert_array_equal(D, accumulate(C_ref))
    assert ev == nrows * ncols * I.quats.shape[1]


@cycles
@pytest.mark.parametrize(
    "name",
    ["Ma", "Mb w10", "Mc w10 + Type V", "Mc w20 (literal window)", "OE-DTW", "OLTW c40",
     "Mb w40 (band w/2)", "Mc w40 (band w/2)"],
)  # fmt: skip
def test_replay_reproduces_the_map_and_the_limit_has_the_steps_costs(name):
    I, T, _ = synthetic_pair(90, seed=5)
    a = make_online(name, I)
    M, dt = run_online(a, T)
    rec = bench_limit.replay(a, T, M)
    assert rec.shape == (T.n_frames, bench_limit.N_REC)
    win = rec[:, bench_limit.R_KIND] == bench_limit.KIND_WINDOW
    assert win.sum() > T.n_frames // 2
    assert (rec[win, bench_limit.R_EVALS] > 0).all()
    same = rec[win, bench_limit.R_SAME]
    if name.startswith("OLTW"):
        assert (same == -1).all()  # OLTW keeps no costs to compare
    else:
        assert (same == 1).all()
    stats = bench.limit_stats(dt, rec)
    assert stats["window_frames"] == win.sum()
    assert stats["same_costs"] is (None if name.startswith("OLTW") else True)
    # the replay runs the aligner's own step: a map it did not produce is refused
    M_bad = M.copy()
    M_bad[len(M) // 2 :] += 1
    with pytest.raises(RuntimeError, match="left the map"):
        bench_limit.replay(a, T, M_bad)


def test_limit_stats_from_a_known_record(monkeypatch):
    monkeypatch.setattr(bench_limit, "ticks_per_second", lambda: 1e9)  # 1 tick = 1 ns
    B = bench_limit
    rec = np.zeros((3, B.N_REC), dtype=np.int64)
    rec[0, B.R_KIND] = B.W.STEP_FIRST  # not a window
    rec[1:, B.R_KIND] = B.KIND_WINDOW
    rec[1:, B.R_COMPILED] = [8000, 10000]
    rec[1:, B.R_FORECAST] = [2000, 2000]
    rec[1:, B.R_LIMIT] = [4000, 4000]
    rec[1:, B.R_EVALS] = [1000, 1000]
    rec[1:, B.R_SAME] = 1
    s = bench.limit_stats(np.array([1.0, 12e-6, 14e-6]), rec)
    assert s["window_frames"] == 2
    assert s["step_median_s"] == pytest.approx(13e-6)
    assert s["limit_median_s"] == pytest.approx(4e-6)
    assert s["step_over_limit"] == pytest.approx(13 / 4)
    assert s["forecast_median_s"] == pytest.approx(2e-6)
    assert s["other_median_s"] == pytest.approx(3e-6)  # compiled - forecast - limit
    assert s["python_median_s"] == pytest.approx(4e-6)  # step - compiled
    assert s["ns_per_eval"] == pytest.approx(4.0)
    assert s["same_costs"] is True
    gap = bench.explain_gap(s)
    assert gap.startswith("Python call 4.0 us") and "other compiled 3.0 us" in gap
    assert bench.explain_gap(dict(s, step_over_limit=1.4)) == ""


# ------------------------------------------------------------------------------ report
def _fake_report(peers):
    rows = []
    for i, name in enumerate(bench.bench_names() + ["OLTW", "OE-DTW"]):
        method, w, typev = bench._name_key(name)
        step = (5 + i) * 1e-6
        rows.append(
            dict(
                name=name, method=method, w=int(w), typev=bool(typev), frames=100,
                median_s=step, p95_s=2 * step, mean_s=step, step_median_s=step,
                limit_median_s=step / 2, step_over_limit=2.0, forecast_median_s=1e-6,
                python_median_s=1.5e-6, other_median_s=0.2e-6, ns_per_eval=2.0,
                evals_median=100,
            )
        )  # fmt: skip
    env = {
        "cpu": {"model": "Test CPU", "cores": 2, "simd": ["avx2"], "mhz": 2000.0,
                "llvm_cpu": "znver4"},
        "python": "3.11.7",
        "packages": {"numpy": "2.4", "numba": "0.68", "llvmlite": "0.50", "dtw-python": "1.9"},
        "fpdtw": {"commit": "abcdef1234567", "dirty": False},
    }  # fmt: skip
    return {
        "environment": env, "single_core": True, "loadavg": {"before": [0.5], "after": [0.7]},
        "cycle_counter_hz": 2.5e9, "pairs": ["a -> b (10 x 10)"], "online": rows[:-1],
        "oe_dtw": rows[-1:], "dtw": {"cells": 100, "median_s": 1e-4, "cells_per_s": 1e6},
        "peers": peers,
    }  # fmt: skip


def test_report_has_every_method_and_w_with_limit_paper_and_peer_ratios():
    oltw = {"peer": "pymatchmaker 0.3.0 OLTW-Dixon", "ours_median_s": 7e-6,
            "peer_median_s": 1.4e-3, "peer_over_ours": 200.0, "measured": "2026-01-01"}  # fmt: skip
    oe = {"peer": "dtw-python 1.9.0 open_end", "frames": 25, "ours_median_s": 20e-6,
          "peer_median_s": 4e-3, "peer_over_ours": 200.0, "same_end_points": True}  # fmt: skip
    report = _fake_report({"open_end": oe, "oltw": oltw})
    text = bench.format_report(report)
    lines = text.splitlines()
    for r in report["online"] + report["oe_dtw"]:
        (line,) = [x for x in lines if x[:34].rstrip() == r["name"]]
        assert f"{r['step_median_s'] * 1e6:.2f}" in line and "2.00" in line  # step, ratio
        paper = TABLE2_US.get((r["method"], r["w"]))
        if paper is not None and not r["typev"] and "(" not in r["name"]:
            assert f"{bench._ratio(paper / (r['step_median_s'] * 1e6))}x" in line
        if r["name"] in ("OLTW", "OE-DTW"):
            assert line.rstrip().endswith("200x")  # the peer's ratio
    for (method, w), paper in TABLE2_US.items():  # the cross-machine table, every w
        assert any(
            x.startswith(f"Method {method}") and f" {w} " in x and f" {paper:.0f} " in x
            for x in lines
        )
    assert "CROSS-MACHINE" in text and "Test CPU" in text and "avx2" in text
    assert "znver4" in text and "numba 0.68" in text and "llvmlite 0.50" in text
    assert "pymatchmaker 0.3.0 OLTW-Dixon" in text
    # without make bench-peers, the report says how to get the OLTW peer
    text = bench.format_report(_fake_report({"open_end": oe}))
    assert "run make bench-peers" in text


def test_report_shows_the_server_round_trip():
    stats = bench.round_trip_stats([1.0, 2.0, 3.0, 4.0], [0.5, 0.5, 0.5, 1.5])
    assert stats["answers"] == 4 and stats["round_trip_max_ms"] == 4.0
    assert stats["round_trip_p50_ms"] == 2.5 and stats["server_p50_ms"] == 0.5
    server = {"method": "-m c -w 40", "pair": "Walk_01 -> Walk_02", "streams": {"1": stats}}
    text = bench.format_report(dict(_fake_report({}), server=server))
    lines = text.splitlines()
    at = next(i for i, x in enumerate(lines) if x.startswith("Server round trip (fpdtw serve -m c"))
    assert lines[at + 1].split()[:3] == ["takes", "at", "once"]
    assert lines[at + 2].split() == ["1", "4", "2.500", "3.970", "4.000", "0.500", "1.470"]
    assert "Server round trip" not in bench.format_report(_fake_report({}))


# ------------------------------------------- the paper's algorithms without optimisation
def test_plain_step_times_has_a_row_per_name_with_positive_times():
    pairs = [synthetic_pair(120, seed=s)[:2] for s in (1, 2)]
    rows = bench.plain_step_times(pairs, frames=12, warmup=3)
    assert [r["name"] for r in rows] == list(bench.PLAIN_NAMES) == ["Mb w80", "Mc w80"]
    for r, method in zip(rows, "BC"):
        assert set(r) == {"name", "method", "w", "mean_us", "median_us", "frames", "pairs"}
        assert (r["method"], r["w"], r["frames"], r["pairs"]) == (method, 80, 24, 2)
        assert r["mean_us"] > 0 and r["median_us"] > 0
    json.dumps(rows)  # as bench.json stores them
    with pytest.raises(ValueError, match="plain step"):
        bench.time_plain_run("OLTW", *pairs[0])


@pytest.mark.parametrize("name", bench.PLAIN_NAMES)
def test_the_plain_step_timed_is_the_one_held_equal_to_the_kernels(name, monkeypatch):
    """time_plain_run times fpdtw.plain's step (the function tests/test_plain.py compares
    with the kernels, called once per timed frame) through fpdtw.plain.run, and its map is
    the compiled aligner's map on that prefix."""
    from fpdtw import plain
    from fpdtw.registry import align

    family = name[1].upper()
    step = getattr(plain, bench.PLAIN_STEPS[family])
    assert step is {"B": plain.method_b_step, "C": plain.method_c_step}[family]
    calls = []
    monkeypatch.setattr(
        plain, bench.PLAIN_STEPS[family], lambda *a, **k: calls.append(1) or step(*a, **k)
    )
    I, T, _ = synthetic_pair(200, seed=3)
    M, dt = bench.time_plain_run(name, I, T, frames=60)
    assert M.shape == (61,) and dt.shape == (60,) and len(calls) == 60 and (dt > 0).all()
    np.testing.assert_array_equal(M, align(name, I, T)[0][:61])
    monkeypatch.undo()
    np.testing.assert_array_equal(M, plain.run(step, I, T.slice(0, 61), 80))


def test_report_shows_the_plain_steps_beside_the_compiled_ones():
    report = _fake_report({})
    plain = [
        dict(name="Mb w80", method="B", w=80, mean_us=20000.0, median_us=19000.0, frames=720,
             pairs=3),
        dict(name="Mc w80", method="C", w=80, mean_us=8000.0, median_us=7900.0, frames=720,
             pairs=3),
    ]  # fmt: skip
    text = bench.format_report(dict(report, plain=plain))
    lines = text.splitlines()
    assert any(x.startswith("Without further optimization (Section 5): PLAIN") for x in lines)
    assert "COMPILED = our numba kernels" in text and "8333 us" in text
    by = {r["name"]: r for r in report["online"]}
    (b,) = [x for x in lines if x.startswith("Mb w80 ") and "20000" in x]
    assert b.split() == ["Mb", "w80", "20000", "19000", "720",
                         f"{by['Mb w80']['mean_s'] * 1e6:.1f}",
                         f"{20000 / (by['Mb w80']['mean_s'] * 1e6):.0f}x", "no"]  # fmt: skip
    (c,) = [x for x in lines if x.startswith("Mc w80 ") and "8000" in x]
    assert c.split()[-1] == "yes"  # within the 8333 us budget
    assert "PLAIN" not in bench.format_report(report)  # no plain rows: no section


# ------------------------------------------------------------------------------- peers
class _FakeTracker:
    """pymatchmaker's interface; runs out of reference after ``stop`` calls."""

    def __init__(self, stop):
        self.stop, self.calls, self.best_ref = stop, 0, 0

    def __call__(self, frame, t):
        self.calls += 1
        self.best_ref = self.calls - 1

    def is_still_following(self):
        return self.calls < self.stop


def test_peers_export_compare_and_json_round_trip(tmp_path):
    pairs = [synthetic_pair(60, seed=s)[:2] for s in (1, 2)]
    meta = bench_peers.export(tmp_path / "pairs.npz", pairs, c=20)
    assert meta["c"] == 20 and meta["project_prefix"] == sys.prefix
    meta2, data = bench_peers.read_export(tmp_path / "pairs.npz")
    assert meta2 == meta and len(data) == 2
    I, T = pairs[0]
    np.testing.assert_array_equal(data[0]["ref"], I.quats.reshape(I.n_frames, -1))
    np.testing.assert_array_equal(data[0]["live"], T.quats.reshape(T.n_frames, -1))
    M, _ = run_online(make_online("OLTW c20", I), T)
    np.testing.assert_array_equal(data[0]["ours_map"], M)  # our OLTW, same parameters

    runs = [bench_peers.time_peer(lambda: _FakeTracker(41), d["live"], warmup=5) for d in data]
    assert [len(r[1]) for r in runs] == [40, 40]  # stops where the peer ran out
    env = {"numpy": "1.26.4", "pymatchmaker": "0.3.0"}
    report = bench_peers.compare(meta, data, runs, "fake OLTW", env)
    o = report["oltw"]
    assert o["frames"] == 80 and o["c"] == 20
    ours = np.concatenate([d["ours_s"][:40] for d in data])
    assert o["ours_median_s"] == np.median(ours)
    assert o["peer_over_ours"] == pytest.approx(o["peer_median_s"] / o["ours_median_s"])
    diff = np.concatenate([np.abs(d["ours_map"][:40] - np.arange(40)) for d in data])
    assert o["map_median_abs_diff"] == np.median(diff)
    path = bench_peers.write_report(report, tmp_path / "bench_peers.json")
    assert bench.load_peers(path) == json.loads(json.dumps(report))
    assert bench.load_peers(tmp_path / "absent.json") is None
    assert "fake OLTW" in bench.peers_table({"peers": {"oltw": o}})


def test_peers_never_run_in_the_project_environment(tmp_path):
    with pytest.raises(bench_peers.SameEnvironmentError, match="own environment"):
        bench_peers.check_separate_environment(sys.prefix, sys.prefix)
    link = tmp_path / "venv-link"
    link.symlink_to(sys.prefix)
    with pytest.raises(bench_peers.SameEnvironmentError):
        bench_peers.check_separate_environment(link, sys.prefix)
    bench_peers.check_separate_environment(tmp_path, sys.prefix)  # another prefix: fine
    # the export records this interpreter's environment: run here, the peers' half refuses
    bench_peers.export(tmp_path / "p.npz", [synthetic_pair(30, seed=1)[:2]], c=10)
    with pytest.raises(bench_peers.SameEnvironmentError):
        bench_peers.run_peer(tmp_path / "p.npz", tmp_path / "out.json")
    assert not (tmp_path / "out.json").exists()
    # the Makefile's peers' venv is its own folder, not the project's .venv
    make = (ROOT / "Makefile").read_text()
    venvs = dict(
        line.split(":=", 1)
        for line in make.splitlines()
        if line.split(":=")[0].strip() in ("VENV", "PEERS_VENV")
    )
    venvs = {k.strip(): v.strip() for k, v in venvs.items()}
    assert venvs["PEERS_VENV"] == "build/peers-venv" != venvs["VENV"]
    assert bench_peers.PEERS_VENV == ROOT / venvs["PEERS_VENV"]
    assert "$(PEERS_PY) -P fpdtw/app/bench_peers.py peer" in make


def test_peers_half_imports_no_fpdtw():
    """The peers' half runs by path with -P (numpy < 2 there): no fpdtw import at load."""
    code = (
        "import runpy, sys; runpy.run_path(sys.argv[1]); "
        "sys.exit(any(m == 'fpdtw' or m.startswith('fpdtw.') for m in sys.modules))"
    )
    path = str(ROOT / "fpdtw" / "app" / "bench_peers.py")
    r = subprocess.run([sys.executable, "-P", "-c", code, path], cwd="/", capture_output=True)
    assert r.returncode == 0, r.stderr.decode()


def test_the_view_table_has_each_round_and_the_medians():
    """bench_view's rows, hand-made: one line per round and setting, then the medians of
    each setting over the rounds (ms)."""
    rows = [dict(round=r, view=v, round_trip_p50_ms=p50, round_trip_p99_ms=p50 * 2,
                 server_p50_ms=p50 / 2, server_p99_ms=p50, answers=10)
            for r, v, p50 in ((1, False, 1.0), (1, True, 1.5), (2, False, 3.0), (2, True, 1.1),
                              (3, False, 2.0), (3, True, 1.2))]  # fmt: skip
    lines = bench.view_table(rows).splitlines()
    assert len(lines) == 2 + 6 + 2
    assert lines[2].split() == ["1", "off", "1.000", "2.000", "0.500", "1.000"]
    assert lines[-2].split() == ["median", "off", "2.000", "4.000", "1.000", "2.000"]
    assert lines[-1].split() == ["median", "open", "1.200", "2.400", "0.600", "1.200"]


def test_bench_relocate_times_both_and_the_search_on_the_longest_take():
    I, T, _ = synthetic_pair(300, seed=2)
    got = bench.bench_relocate([(I, T)], names=("Mc w40",))
    (row,) = got["rows"]
    assert row["name"] == "Mc w40" and 0 < row["median_us"] <= row["p95_us"]
    assert 0 < row["relocate_median_us"] <= row["relocate_p95_us"]
    assert got["search"]["frames"] == 1202 and got["budget_us"] == pytest.approx(8333.33, 1e-5)
    lines = bench.relocate_table(got).splitlines()
    assert lines[2].split()[0] == "Mc" and "(1202 frames)" in lines[3]
