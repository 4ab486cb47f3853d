"""The experiment runner (fpdtw.paper.runner.run) and its result files (fpdtw.paper.runner.results).

Runs use a tiny real selection (the authors' Twirls and Walk, first two takes, cropped
to 1 s: 4 ordered pairs, 2 per movement) in a temporary results folder, and a few
algorithms at 120 Hz and 60 Hz. Checked: the pair selection on the real manifests,
deterministic file bytes, equal results for 1 and 2 worker processes, resuming after
lost files and after a run killed half way (only what is missing is recomputed), a
re-run that computes nothing, adding an algorithm, and the invariants of the results.
"""

from __future__ import annotations

import io
import json
import zipfile
from collections import Counter
from pathlib import Path

import numpy as np
import pytest

from fpdtw.dtw import utw_map
from fpdtw.errors import AlignmentError
from fpdtw.metrics import in_range, is_monotonic
from fpdtw.online.typev import is_legal_typev
from fpdtw.paper.numbers import FPDTW_NAMES, FPDTW_TYPEV_NAMES
from fpdtw.paper.runner import run as E
from fpdtw.paper.runner.grid import DEFAULT_ALGORITHMS
from fpdtw.paper.runner.results import ZIP_DATE, aggregate_heatmap, load_npz, npz_bytes, save_npz

TINY = E.Selection(
    datasets=("authors_fbx",), movements=("Twirls", "Walk"), takes_per_movement=2, crop_seconds=1.0
)
ALGOS = ["DTW", "UTW", "OE-DTW", "Ma", "Mb w10", "Mc w10 + Type V", "DTW@60Hz", "Mc w10@60Hz"]
N_PAIRS = 4  # 2 movements x 2 ordered pairs


class Killed(Exception):
    """Stands for the process being killed in the middle of a run."""


def file_bytes(folder: Path) -> dict:
    """Bytes of every deterministic output: algorithms/*.npz and the pairs list."""
    out = {p.name: p.read_bytes() for p in sorted((folder / "algorithms").glob("*.npz"))}
    out["pairs"] = json.dumps(json.loads((folder / "pairs.json").read_text())["pairs"])
    return out


def det_summary(folder: Path) -> dict:
    return json.loads((folder / "summary.json").read_text())


@pytest.fixture(scope="module")
def results_root(tmp_path_factory):
    root = tmp_path_factory.mktemp("results")
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("FPDTW_RESULTS_DIR", str(root))
        yield root


@pytest.fixture(scope="module")
def reference(results_root):
    """The tiny selection run once in this process (n_jobs=1)."""
    res = E.run_experiments("ref", ALGOS, n_jobs=1, progress=False, selection=TINY)
    return res


@pytest.fixture
def counting(monkeypatch):
    """Count (and optionally fail) the (algorithm, pair) alignments of runs in this process."""
    state = {"calls": 0, "fail_after": None}
    real = E._pair_maps

    def wrapper(specs, I, T, info):
        after = state["calls"] + len(specs)
        if state["fail_after"] is not None and after > state["fail_after"]:
            raise Killed("simulated kill")
        state["calls"] = after
        return real(specs, I, T, info)

    monkeypatch.setattr(E, "_pair_maps", wrapper)
    return state


# -- pairs -------------------------------------------------------------------------------------


def test_pairs_of_the_real_manifests_are_ordered_distinct_and_same_movement():
    plan = E.pair_selection()
    authors = [p for p in plan.pairs if p["dataset"] == "authors_fbx"]
    assert len(authors) == 96  # 16 movements x 3 takes x 2 others
    assert plan.counts["authors_fbx"] == {"motions": 48, "movements": 16, "pairs": 96}
    hdm = Counter(r.movement for r in plan.motions if r.dataset == "hdm05")
    assert plan.counts["hdm05"]["pairs"] == sum(k * (k - 1) for k in hdm.values())
    assert plan.counts["hdm05"]["motions"] == 287 and len(hdm) == 11
    assert plan.counts["total"]["pairs"] == len(plan.pairs) == 96 + plan.counts["hdm05"]["pairs"]
    assert [p["id"] for p in plan.pairs] == list(range(len(plan.pairs)))
    seen = set()
    for p in plan.pairs:
        I, T = plan.motions[p["input_index"]], plan.motions[p["target_index"]]
        assert I.path == p["input_path"] != p["target_path"] == T.path
        assert I.movement == T.movement == p["movement"]
        assert I.dataset == T.dataset == p["dataset"]
        seen.add((p["input_path"], p["target_path"]))
    assert len(seen) == len(plan.pairs)
    assert all((b, a) in seen for a, b in seen)  # both directions
    # deterministic order: dataset, movement, input, target in manifest order
    key = [(p["dataset"] != "authors_fbx", p["input_index"], p["target_index"]) for p in plan.pairs]
    assert key == sorted(key)
    walk = [(p["input"], p["target"]) for p in authors if p["movement"] == "Walk"]
    assert walk == [
        ("Walk_01", "Walk_02"),
        ("Walk_01", "Walk_03"),
        ("Walk_02", "Walk_01"),
        ("Walk_02", "Walk_03"),
        ("Walk_03", "Walk_01"),
        ("Walk_03", "Walk_02"),
    ]


def test_smoke_selection_two_takes_both_directions():
    plan = E.pair_selection(E.SELECTIONS["smoke"])
    per_movement = Counter((p["dataset"], p["movement"]) for p in plan.pairs)
    assert set(per_movement.values()) == {2}
    assert plan.counts["total"] == {"motions": 54, "movements": 27, "pairs": 54}
    twirls = [(p["input"], p["target"]) for p in plan.pairs if p["movement"] == "Twirls"]
    assert twirls == [("Twirls_02", "Twirls_03"), ("Twirls_03", "Twirls_02")]


@pytest.mark.parametrize("mode", ["smoke-study", "smoke-open"])
def test_smoke_runs_of_notebooks_15_and_16_take_the_first_movements(mode):
    """max_movements keeps the first movements of each dataset, each with all its pairs."""
    from fpdtw.paper.runner.selection import SMOKE_MOVEMENTS

    smoke = E.pair_selection(E.SELECTIONS["smoke"])
    plan = E.pair_selection(E.SELECTIONS[mode])
    for ds in ("authors_fbx", "hdm05"):
        first = list(dict.fromkeys(p["movement"] for p in smoke.pairs if p["dataset"] == ds))
        kept = list(dict.fromkeys(p["movement"] for p in plan.pairs if p["dataset"] == ds))
        assert kept == first[:SMOKE_MOVEMENTS]
    kept = {(p["dataset"], p["movement"]) for p in plan.pairs}

    def key(pairs):
        return [(p["dataset"], p["input"], p["target"]) for p in pairs]

    assert key(plan.pairs) == key(p for p in smoke.pairs if (p["dataset"], p["movement"]) in kept)
    assert plan.counts["total"]["movements"] == 2 * SMOKE_MOVEMENTS
    assert "max_movements" not in E.SELECTIONS["smoke"].as_dict()


def test_slugs_and_names():
    assert E.slug("Mc w40 + Type V") == "Mc_w40_TypeV"
    assert E.slug("Mc w40@60Hz") == "Mc_w40_60Hz"
    assert E.slug("OE-DTW") == "OE-DTW"
    # 21 paper + 6 at 60 Hz + OPW, OLTW + Method C's literal window (8 + 4 at 60 Hz)
    assert len(DEFAULT_ALGORITHMS) == 41
    assert DEFAULT_ALGORITHMS[27:29] == ("OPW", "OLTW")
    assert DEFAULT_ALGORITHMS[-1] == "Mc w80 (literal window)@60Hz"
    assert E.slug(DEFAULT_ALGORITHMS[-1]) == "Mc_w80_literal_window_60Hz"
    spec = E.resolve_algorithm("Mc w20@60Hz")
    assert (spec.algorithm.family, spec.algorithm.w, spec.fps) == ("C", 20, 60.0)
    with pytest.raises(AlignmentError, match="unknown algorithm"):
        E.resolve_algorithm("Md w10")


def test_the_computation_is_keyed_by_the_library_source():
    """A chunk stays valid while the library does not change: the files outside
    fpdtw/paper and fpdtw/app, the catalogue that loads the motions and the pause inserted
    into targets."""
    files = E.compute_files()
    for f in ("online/method_c.py", "metrics.py", "io/fbx.py", "registry.py", "paper/catalog.py"):
        assert f in files
    assert not [f for f in files if f.startswith("app/")]
    paper = {f for f in files if f.startswith("paper/")}
    assert paper == {"paper/catalog.py", "paper/pause.py", "paper/edits.py"}
    assert E.source_hash(files) != E.source_hash()


# -- deterministic files -----------------------------------------------------------------------


def test_npz_writer_is_deterministic(tmp_path):
    arrays = {"a": np.arange(5, dtype=np.int32), "b": np.linspace(0, 1, 7), "c": np.array("x")}
    p1 = save_npz(tmp_path / "one.npz", **arrays)
    p2 = save_npz(tmp_path / "two.npz", **arrays)
    assert p1.read_bytes() == p2.read_bytes() == npz_bytes(arrays)
    with zipfile.ZipFile(p1) as zf:
        assert [i.filename for i in zf.infolist()] == ["a.npy", "b.npy", "c.npy"]
        assert all(i.date_time == ZIP_DATE for i in zf.infolist())
    back = load_npz(p1)
    assert list(back) == ["a", "b", "c"]
    with np.load(io.BytesIO(p1.read_bytes())) as z:  # numpy reads it as any npz
        np.testing.assert_array_equal(z["b"], arrays["b"])
    assert back["a"].dtype == np.int32 and str(back["c"]) == "x"
    assert not list(tmp_path.glob(".*part"))  # no temporary file left


# -- runs --------------------------------------------------------------------------------------


def test_results_of_the_tiny_run(reference):
    res = reference
    assert res.algorithms == ALGOS
    assert len(res.pairs) == N_PAIRS
    assert res.counts["total"] == {"motions": 4, "movements": 2, "pairs": 4}
    for p in res.pairs:  # 1 s at 120 Hz and 60 Hz
        assert (p["m"], p["n"], p["m60"], p["n60"]) == (120, 120, 60, 60)
    for name in ALGOS:
        r = res.get(name)
        m, n = res.frames(name)
        assert r["pair_id"].dtype == np.int32 and r["offsets"].dtype == np.int64
        assert r["maps"].dtype == np.int32
        np.testing.assert_array_equal(r["pair_id"], np.arange(N_PAIRS))
        np.testing.assert_array_equal(np.diff(r["offsets"]), n + 1)
        assert np.all((r["similarity"] >= -1) & (r["similarity"] <= 1))
        assert np.all(r["deviation"] >= 0)
        for k in range(N_PAIRS):
            M = r.map(k)
            assert np.array_equal(M, r["map"](k)) and in_range(M, m[k])
            base = name.split("@")[0]
            if base in FPDTW_NAMES + FPDTW_TYPEV_NAMES:
                assert is_monotonic(M)
            if base in FPDTW_TYPEV_NAMES:
                assert is_legal_typev(M, m[k])
        assert res.is_online(name) == (name not in ("DTW", "UTW", "DTW@60Hz"))
    # DTW is its own reference; UTW is uniform
    assert np.all(res.get("DTW")["deviation"] == 0) and np.all(
        res.get("DTW@60Hz")["deviation"] == 0
    )
    u = res.get("UTW")
    for k, p in enumerate(res.pairs):
        np.testing.assert_array_equal(u.map(k), utw_map(p["m"], p["n"]))
    s = res.summary
    assert s["benchmarks"]["utw_median_similarity_120hz"] == pytest.approx(
        np.median(u["similarity"])
    )
    assert s["benchmarks"]["utw_median_similarity_60hz"] is None  # no UTW@60Hz in this run
    assert s["algorithms"]["DTW"]["deviation_median"] == 0.0
    assert s["algorithms"]["DTW"]["passes_deviation_benchmark"] is True
    assert set(s) == {"eq2", "benchmarks", "algorithms"}  # no timings: make bench measures those
    assert not (res.folder / "timings").exists()
    assert s["algorithms"]["Mb w10"]["n_pairs"] == N_PAIRS


def test_grid_maps_equal_separate_runs(reference):
    """B and C share a WindowCache in the grid: their maps are those of separate runs."""
    features = {fps: E.pair_features(reference, fps) for fps in (120.0, 60.0)}
    for name in ALGOS:
        spec = E.resolve_algorithm(name)
        if not spec.algorithm.online:
            continue
        for k in range(N_PAIRS):
            I, T = features[spec.fps](k)
            np.testing.assert_array_equal(
                reference.get(name).map(k), spec.algorithm.run(I, T)[0], err_msg=name
            )


def test_aggregate_heatmap_sums_to_pairs_and_diagonal_stays_diagonal(reference):
    # cropped to 1 s, every motion has 121 frames: UTW maps q -> q, the diagonal
    H = aggregate_heatmap(reference, "UTW", bins=10)
    assert H.shape == (10, 10)
    assert H.sum() == pytest.approx(N_PAIRS)
    assert np.trace(H) == pytest.approx(N_PAIRS)
    H = aggregate_heatmap(reference, "Ma", bins=20)
    assert H.sum() == pytest.approx(N_PAIRS)


def test_aggregate_heatmap_by_hand():
    class Fake:
        def get(self, name):
            return {"offsets": np.array([0, 3]), "maps": np.array([0, 0, 1], dtype=np.int32)}

        def frames(self, name):
            return np.array([1]), np.array([2])

    # points (q/n, M/m) = (0, 0), (0.5, 0), (1, 1): weights 1/3 each
    H = aggregate_heatmap(Fake(), "x", bins=2)
    np.testing.assert_allclose(H, [[1 / 3, 1 / 3], [0, 1 / 3]])


def test_one_and_two_workers_give_identical_files(reference, results_root):
    E.run_experiments("two_jobs", ALGOS, n_jobs=2, progress=False, selection=TINY)
    a, b = results_root / "ref", results_root / "two_jobs"
    assert file_bytes(a) == file_bytes(b)
    assert det_summary(a) == det_summary(b)


def test_rerun_with_nothing_changed_computes_nothing(reference, counting, capsys):
    # (while the package source is being edited, this first re-run rewrites run.json only)
    E.run_experiments("ref", ALGOS, n_jobs=1, progress=False, selection=TINY)
    assert counting["calls"] == 0
    before = (reference.folder / "run.json").read_bytes()
    capsys.readouterr()
    res = E.run_experiments("ref", ALGOS, n_jobs=1, progress=True, selection=TINY)
    assert counting["calls"] == 0
    assert "nothing to do" in capsys.readouterr().out
    assert (reference.folder / "run.json").read_bytes() == before
    assert res.algorithms == ALGOS


def test_resume_after_losing_a_chunk_and_a_file(reference, results_root, counting):
    folder = results_root / "lost"
    E.run_experiments("lost", ALGOS, n_jobs=1, progress=False, selection=TINY)
    chunks = sorted((folder / "chunks").glob("*.npz"))
    assert len(chunks) == N_PAIRS  # one unit per input motion, each with one pair here
    chunks[1].unlink()
    (folder / "algorithms" / "Mb_w10.npz").unlink()
    counting["calls"] = 0
    E.run_experiments("lost", ALGOS, n_jobs=1, progress=False, selection=TINY)
    assert counting["calls"] == len(ALGOS)  # one unit (one pair) x every algorithm
    run = json.loads((folder / "run.json").read_text())
    assert run["computed"]["units"] == 1 and run["computed"]["units_total"] == N_PAIRS
    assert file_bytes(folder) == file_bytes(reference.folder)
    assert det_summary(folder) == det_summary(reference.folder)


def test_killed_run_resumes_from_finished_chunks(reference, results_root, counting):
    folder = results_root / "killed"
    counting["fail_after"] = 2 * len(ALGOS) + 3  # two units done, the third half way
    with pytest.raises(Killed):
        E.run_experiments("killed", ALGOS, n_jobs=1, progress=False, selection=TINY)
    assert len(list((folder / "chunks").glob("*.npz"))) == 2
    assert not (folder / "run.json").exists()
    counting.update(calls=0, fail_after=None)
    E.run_experiments("killed", ALGOS, n_jobs=1, progress=False, selection=TINY)
    assert counting["calls"] == 2 * len(ALGOS)  # only the two missing units
    assert file_bytes(folder) == file_bytes(reference.folder)
    assert det_summary(folder) == det_summary(reference.folder)
    assert not list(folder.rglob(".*.part"))


def test_adding_an_algorithm_computes_only_it(reference, results_root, counting):
    folder = results_root / "added"
    E.run_experiments("added", ALGOS[:-1], n_jobs=1, progress=False, selection=TINY)
    counting["calls"] = 0
    E.run_experiments("added", ALGOS, n_jobs=1, progress=False, selection=TINY)
    assert counting["calls"] == N_PAIRS  # Mc w10@60Hz on every pair, nothing else
    assert file_bytes(folder) == file_bytes(reference.folder)
    # any registry name joins the same way, and the others stay in the results
    counting["calls"] = 0
    res = E.run_experiments("added", ["OLTW c30"], n_jobs=1, progress=False, selection=TINY)
    assert counting["calls"] == N_PAIRS
    assert res.algorithms == ALGOS + ["OLTW c30"]
    assert res.summary["algorithms"]["OLTW c30"]["online"] is True
    assert (folder / "algorithms" / "OLTW_c30.npz").is_file()
    counting["calls"] = 0
    E.run_experiments("added", ["OLTW c30"], n_jobs=1, progress=False, selection=TINY)
    assert counting["calls"] == 0


def test_load_results_without_a_run_says_what_to_do(results_root):
    with pytest.raises(FileNotFoundError, match="fpdtw experiments run --smoke"):
        E.load_results("smoke")


def test_a_mode_copies_the_features_another_mode_of_its_results_folder_built(tmp_path, monkeypatch):
    plan = E.pair_selection(TINY)
    built = E.build_features(plan, tmp_path / "smoke" / "features", n_jobs=1, progress=False)

    def never(*a, **k):
        raise AssertionError("a feature file was built again")

    monkeypatch.setattr(E, "_build_feature_file", never)
    again = E.build_features(plan, tmp_path / "smoke-open" / "features", n_jobs=1, progress=False)
    assert [p.name for p in again] == [p.name for p in built]
    assert all(a.read_bytes() == b.read_bytes() for a, b in zip(again, built))
    assert not list((tmp_path / "smoke-open").rglob("*.part"))
    # another crop is another file: built, never copied
    other = E.pair_selection(E.Selection(**{**TINY.as_dict(), "crop_seconds": 1.5}))
    with pytest.raises(AssertionError, match="built again"):
        E.build_features(other, tmp_path / "x" / "features", n_jobs=1, progress=False)
