"""Numbers recorded by the smoke notebooks, asserted from the JSON and npz they write.

``make test`` first executes every notebook in SMOKE mode with papermill (results
under ``build/smoke/results/smoke``), then runs this suite. The assertions here are
about what those runs recorded: pair counts, invariants of every stored map,
agreement of the summary with the stored arrays, and the facts of the figure
notebooks.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from fpdtw.dtw import utw_map
from fpdtw.metrics import deviation
from fpdtw.online.typev import is_legal_typev
from fpdtw.paper.numbers import FPDTW_NAMES, FPDTW_TYPEV_NAMES, PAPER_NAMES
from fpdtw.paper.paths import REPO_ROOT
from fpdtw.paper.runner.grid import DEFAULT_ALGORITHMS
from fpdtw.paper.runner.results import Results
from fpdtw.paper.runner.run import load_results

SMOKE_RESULTS = REPO_ROOT / "build" / "smoke" / "results"


@pytest.fixture(scope="module")
def smoke(monkeypatch_module):
    if not (SMOKE_RESULTS / "smoke" / "summary.json").is_file():
        pytest.fail(
            f"no smoke results in {SMOKE_RESULTS}: run `make test` (it executes the smoke "
            "notebooks before the test suite)"
        )
    monkeypatch_module.setenv("FPDTW_RESULTS_DIR", str(SMOKE_RESULTS))
    return load_results("smoke")


@pytest.fixture(scope="module")
def monkeypatch_module():
    mp = pytest.MonkeyPatch()
    yield mp
    mp.undo()


def _facts(name):
    path = SMOKE_RESULTS / "smoke" / "figs" / f"{name}.json"
    if not path.is_file():
        pytest.fail(f"notebook {name} did not record its facts at {path}")
    return json.loads(path.read_text())


def test_smoke_selection_counts(smoke):
    # SMOKE: the first two takes of every movement, both directions
    assert smoke.counts["authors_fbx"] == {"motions": 32, "movements": 16, "pairs": 32}
    assert smoke.counts["hdm05"] == {"motions": 22, "movements": 11, "pairs": 22}
    assert smoke.counts["total"]["pairs"] == 54
    assert list(smoke.algorithms) == list(DEFAULT_ALGORITHMS)  # literal window included


def test_every_map_is_in_range_and_fpdtw_maps_are_monotonic(smoke):
    for name in smoke.algorithms:
        r = smoke.get(name)
        ms, ns = smoke.frames(name)
        for k in range(len(smoke.pairs)):
            M = r.map(k)
            m, n = int(ms[k]), int(ns[k])
            assert M.shape == (n + 1,), (name, k)
            assert M.min() >= 0 and M.max() <= m, (name, k)
            if name.split("@")[0] in FPDTW_NAMES + FPDTW_TYPEV_NAMES + ("OPW", "OLTW"):
                assert np.all(np.diff(M) >= 0), (name, k)


def test_type_v_maps_are_legal(smoke):
    for name in FPDTW_TYPEV_NAMES:
        r = smoke.get(name)
        ms, _ = smoke.frames(name)
        for k in range(len(smoke.pairs)):
            assert is_legal_typev(r.map(k), int(ms[k])), (name, k)


def test_utw_and_dtw_are_what_they_say(smoke):
    utw, dtw = smoke.get("UTW"), smoke.get("DTW")
    ms, ns = smoke.frames("UTW")
    for k in range(len(smoke.pairs)):
        np.testing.assert_array_equal(utw.map(k), utw_map(int(ms[k]), int(ns[k])))
        # DTW's path runs from (0, 0) to (m, n); the map keeps the lowest input frame of
        # each target frame, so it starts at 0, never decreases and ends at or below m
        M = dtw.map(k)
        assert M[0] == 0 and np.all(np.diff(M) >= 0) and M[-1] <= ms[k]
    np.testing.assert_array_equal(dtw["deviation"], 0.0)


def test_summary_agrees_with_the_stored_arrays(smoke):
    # the summary is scored under the run's reading of eq. 2 (make test: the default)
    scored = Results(smoke.folder, eq2=smoke.summary["eq2"])
    assert smoke.summary["eq2"] == "transform"
    dtw = scored.get("DTW")
    for name in PAPER_NAMES:
        r = scored.get(name)
        s = smoke.summary["algorithms"][name]
        assert s["n_pairs"] == len(smoke.pairs)
        assert s["similarity_median"] == pytest.approx(float(np.median(r["similarity"])))
        assert s["deviation_median"] == pytest.approx(float(np.median(r["deviation"])))
        # deviation (eq. 3) recomputed from the maps
        k = len(smoke.pairs) // 2
        assert r["deviation"][k] == pytest.approx(deviation(dtw.map(k), r.map(k)))
        assert np.all(np.abs(r["similarity"]) <= 1.0)
    utw_median = smoke.summary["benchmarks"]["utw_median_similarity_120hz"]
    assert utw_median == pytest.approx(float(np.median(scored.get("UTW")["similarity"])))


def test_figure_notebooks_recorded_their_facts():
    fig1 = _facts("02_fig1_oedtw")["symmetric1"]
    assert fig1["jumps"] >= 1  # OE-DTW end points move backwards on the walk pair
    q = fig1["first_jump"]["q"]
    assert fig1["first_jump"]["e_q1"] < fig1["first_jump"]["e_q"] and 0 < q < fig1["n_frames"]
    fig9 = _facts("11_fig9_typev")
    assert fig9["ma_free_legal"] is False  # unconstrained Method A breaks Type V on the walk pair
    # the forward Type V table: a hold only right after an advance of 1, at most two holds
    assert fig9["table"] == [
        ["state", "0", "1", "2", "3"],
        ["N", "-", "A1", "N", "N"],
        ["A1", "H1", "A1", "N", "N"],
        ["H1", "N", "A1", "N", "N"],
    ]
    opw4 = _facts("13_opw_fig4")
    lo, hi = opw4["opw_mean_ms_range"]
    assert 0 <= lo <= hi < 2500
    claims = json.loads((SMOKE_RESULTS / "smoke" / "claims.json").read_text())["claims"]
    ids = [c["id"] for c in claims]
    assert {"1", "2", "3", "7", "9", "P1", "P2", "P3", "P4", "B1"} <= set(ids)
    from fpdtw.paper.claims.rules import CLAIM_VERDICTS

    assert all(c["holds"] in CLAIM_VERDICTS for c in claims), [c["holds"] for c in claims]
    # every claim of the papers was decided on its parts: a reason, and its parts' verdicts
    parts = json.loads((SMOKE_RESULTS / "smoke" / "claims.json").read_text())["parts"]
    for c in claims:
        if c["holds"] != "n/a":
            assert c["reason"], c["id"]
            assert [p for p in parts if p["claim"] == c["id"]], c["id"]
    assert next(c for c in claims if c["id"] == "P1")["holds"] != "n/a"  # 13_opw_fig4 ran


def test_readings_notebook_recorded_every_reading():
    """Notebook 15 (smoke-study run): every reading's signature, the mechanism and the
    silent choices were recorded; the literal window's hold carries its extra cell."""
    from fpdtw.paper.runner.selection import SELECTIONS, pair_selection
    from fpdtw.registry import C_READINGS

    facts = _facts("15_readings_of_algorithm_3")
    assert facts["pairs"] == len(pair_selection(SELECTIONS["smoke-study"]).pairs) == 32
    assert [s["reading"] for s in facts["signature"]] == list(C_READINGS)
    for s in facts["signature"]:
        assert s["best_w_120"] in (10, 20, 40, 80) and s["best_w_60"] in (10, 20, 40, 80)
    mech = facts["mechanism"]
    assert mech["literal"]["steps"] > 0 and mech["square"]["steps"] > 0
    assert mech["literal"]["excess"] > 10 * mech["literal"]["neighbour"]
    assert mech["square"]["excess"] < mech["literal"]["excess"]
    assert mech["square"]["hold"] > mech["literal"]["hold"]
    choices = {c["choice"] for c in facts["silent_choices"]}
    assert {"ties", "backtrack", "forecast", "start", "flat_axis", "after_input"} <= choices
    claims = json.loads((SMOKE_RESULTS / "smoke" / "claims.json").read_text())["claims"]
    from fpdtw.paper.claims.rules import CLAIM_VERDICTS

    assert all(c["holds_literal"] in CLAIM_VERDICTS for c in claims)
