"""The questions beyond the papers (notebook 16): each variant on a hand-made case, and the
Q claims on invented runs giving each verdict."""

from __future__ import annotations

import numpy as np
import pytest
from reference.fake_run import FakeRun
from reference.synthetic import features_from_euler, random_walk_features

from fpdtw import registry
from fpdtw.errors import AlignmentError
from fpdtw.motion.features import MotionFeatures
from fpdtw.online import MethodC
from fpdtw.online.base import run_online
from fpdtw.paper import claims
from fpdtw.paper.claims import ClaimContext
from fpdtw.paper.claims.evidence import Evidence
from fpdtw.paper.edits import EDITS, edit_seed, edit_suffix, edit_target, fits, source_frames
from fpdtw.paper.pause import insert_pause, pause_plan, pause_seed
from fpdtw.paper.runner.grid import (
    EDIT_METHODS,
    EDIT_SUFFIXES,
    OPEN_ALGORITHMS,
    PAUSE_METHODS,
    PAUSE_SUFFIX,
    mode_algorithms,
)
from fpdtw.paper.runner.run import resolve_algorithm, transform_target
from fpdtw.paper.runner.selection import SELECTIONS, pair_selection
from fpdtw.period import auto_window, autocorrelation, dominant_period, window_from_period


def sine_motion(period_frames, n_frames=1200, fps=120.0, amp=30.0):
    """Every joint swings about x with the same period (phases differ): a cyclic motion."""
    t = np.arange(n_frames)[:, None]
    phase = np.linspace(0, np.pi, 8)[None, :]
    E = np.zeros((n_frames, 8, 3))
    E[:, :, 0] = amp * np.sin(2 * np.pi * t / period_frames + phase)
    return features_from_euler(E, orders=("XYZ",) * 8, fps=fps, name="sine")


# -- Q1: the period ---------------------------------------------------------------------------


@pytest.mark.parametrize("period", [60, 96, 131])
def test_the_period_of_a_sine_motion_is_its_period(period):
    I = sine_motion(period)
    r = autocorrelation(I.quats)
    assert r[0] == pytest.approx(1.0)
    assert dominant_period(I.quats, I.fps) == period
    # the largest integer below half the period
    assert auto_window(I) == (period - 1) // 2 if period % 2 else period // 2 - 1


def test_equal_weights_would_call_a_swinging_bone_acyclic():
    """Why the axes are weighted by their variance (fpdtw.period): with equal weights the
    second harmonic of the bone's other axis cancels the first at half the period."""
    from fpdtw.metrics import joint_trajectories

    P = 60
    X = joint_trajectories(sine_motion(P).quats).reshape(1200, -1)
    X = X - X.mean(axis=0)
    X = X[:, np.sum(X * X, axis=0) > 1e-12]
    acf = np.array([[np.dot(x[: x.size - k], x[k:]) / np.dot(x, x) for k in range(P + 2)]
                    for x in X.T]).mean(axis=0)  # fmt: skip
    k = P // 2
    assert acf[k - 1] < acf[k] >= acf[k + 1] and abs(acf[k]) < 0.2  # "acyclic" by the rule
    assert dominant_period(sine_motion(P).quats, 120.0) == P


def test_an_acyclic_motion_falls_back_to_the_papers_window_scaled_by_the_rate():
    E = np.zeros((600, 8, 3))
    E[:, :, 1] = np.linspace(0.0, 80.0, 600)[:, None]  # a slow turn, no cycle
    I = features_from_euler(E, orders=("XYZ",) * 8, name="turn")
    assert dominant_period(I.quats, 120.0) is None
    assert auto_window(I) == 40
    I60 = features_from_euler(E[::2], orders=("XYZ",) * 8, fps=60.0, name="turn60")
    assert auto_window(I60) == 20
    still = features_from_euler(np.zeros((100, 8, 3)), orders=("XYZ",) * 8)
    assert dominant_period(still.quats, 120.0) is None
    # periods outside 0.25-4 s are not periods
    assert dominant_period(sine_motion(20).quats, 120.0) != 20
    assert window_from_period(5, 120.0) == 2 and window_from_period(None, 60.0) == 20


def test_mc_auto_is_method_c_with_the_window_of_the_period():
    I = sine_motion(90, n_frames=400)
    T = sine_motion(80, n_frames=380)
    a = registry.resolve("Mc auto")
    assert a.family == "Cauto" and a.online
    M, _ = a.run(I, T)
    ref, _ = run_online(MethodC(I, auto_window(I)), T)
    assert auto_window(I) == 44
    np.testing.assert_array_equal(M, ref)
    with pytest.raises(AlignmentError):
        registry.resolve("Mc auto w40")


# -- Q6: pauses -------------------------------------------------------------------------------


def test_a_pause_is_inserted_at_a_known_frame():
    T = random_walk_features(50, seed=3)
    P = insert_pause(T, at=10, length=5)
    assert P.n_frames == 55
    np.testing.assert_array_equal(P.quats[:11], T.quats[:11])
    for f in range(11, 16):
        np.testing.assert_array_equal(P.quats[f], T.quats[10])
        np.testing.assert_array_equal(P.euler[f], T.euler[10])
    np.testing.assert_array_equal(P.quats[16:], T.quats[11:])
    assert P.name == T.name + "+pause"
    with pytest.raises(AlignmentError, match="outside"):
        insert_pause(T, at=50, length=3)


def test_the_pause_plan_lies_in_the_middle_and_lasts_half_a_second_to_two():
    for s in range(200):
        at, L = pause_plan(1001, 120.0, s)
        assert 200 <= at <= 800 and 60 <= L <= 240
    assert pause_plan(1001, 120.0, pause_seed("a")) == pause_plan(1001, 120.0, pause_seed("a"))
    assert pause_seed("a") != pause_seed("b")
    T = random_walk_features(300, seed=1)
    at, L = pause_plan(T.n_frames, T.fps, pause_seed(T.name))
    assert transform_target("pause", T).n_frames == 300 + L
    assert transform_target(None, T) is T


def test_the_runner_reads_the_pause_suffix():
    spec = resolve_algorithm("Mc w40@pause")
    assert (spec.algorithm.name, spec.fps, spec.transform) == ("Mc w40", 120.0, "pause")
    assert resolve_algorithm("Mc w40").transform is None
    assert "DTW@pause" in OPEN_ALGORITHMS
    assert all(n + PAUSE_SUFFIX in OPEN_ALGORITHMS for n in PAUSE_METHODS)


def test_the_runner_reads_the_edit_suffixes():
    """Q7's names: each edit's suffix gives its edit of fpdtw.paper.edits, on a relocating
    method as on a plain one; the target is the edited one; a target too short for an edit
    (hand-checked bounds) has no result under it."""
    assert set(EDIT_SUFFIXES.values()) == set(EDITS)
    spec = resolve_algorithm("OLTW (relocate)@cut1s")
    assert (spec.algorithm.name, spec.fps, spec.transform) == ("OLTW (relocate)", 120.0, "cut 1 s")
    assert resolve_algorithm("Mc w40@restart").transform == "restart"
    T = random_walk_features(n_frames=600, seed=3)
    for edit in EDITS:
        E, idx, _ = edit_target(T, edit)
        got = transform_target(edit, T)
        assert got.name == E.name and np.array_equal(got.quats, T.quats[idx])
    assert len(EDIT_METHODS) == 2 * len(PAUSE_METHODS)
    q7 = [n + s for n in EDIT_METHODS for s in ("", *EDIT_SUFFIXES)]
    assert all(n in OPEN_ALGORITHMS for n in q7)
    assert mode_algorithms("smoke-open") == OPEN_ALGORITHMS
    assert fits(401, 120.0, "cut 2 s") and not fits(400, 120.0, "cut 2 s")  # 0.6 * 400 >= 240
    assert fits(7, 120.0, "restart") and not fits(100, 120.0, "cut 0.5 s")


def test_the_open_selection_is_a_subsample_of_the_paper_shaped_one():
    study = pair_selection(SELECTIONS["study"])
    sub = pair_selection(SELECTIONS["open"])
    takes = {(r.path) for r in study.motions}
    assert {r.path for r in sub.motions} <= takes
    assert sub.counts["total"]["pairs"] < study.counts["total"]["pairs"]
    assert "subsample_takes" not in SELECTIONS["study"].as_dict()


# -- the Q claims on invented runs ----------------------------------------------------------


def open_run(centres, spread=None, seed=0, n_frames=40):
    run = FakeRun({"authors_fbx": 4, "hdm05": 4}, takes=4, seed=seed, n_frames=n_frames)
    for name, (s, d) in centres.items():
        sd = (spread or {}).get(name, 0.0)
        run.add(name, run.scores(s, motion_sd=sd, noise_sd=0.002),
                np.abs(run.scores(d, motion_sd=100 * sd, noise_sd=0.2)))  # fmt: skip
    return run


def q_table(run, ids, bench=None):
    ctx = ClaimContext(mode="smoke", open_ev=Evidence(run, n_resamples=300), bench=bench)
    rows, parts = claims.evaluate_claims(claims.claims_by_id(ids), claims.claim_contexts(ctx))
    return {r["id"]: r for r in rows}, parts


def q1_centres(auto120, auto60):
    c = {"UTW": (0.25, 60.0), "UTW@60Hz": (0.25, 30.0)}
    for w, s in ((10, 0.1), (20, 0.2), (40, 0.3), (80, 0.15)):
        c[f"Mc w{w}"] = (s, 15.0)
    for w, s in ((10, 0.15), (20, 0.3), (40, 0.2), (80, 0.1)):
        c[f"Mc w{w}@60Hz"] = (s, 8.0)
    return c | {"Mc auto": auto120, "Mc auto@60Hz": auto60}


def test_q1_holds_when_mc_auto_clears_every_bar():
    rows, parts = q_table(open_run(q1_centres((0.4, 10.0), (0.4, 5.0))), ["Q1"])
    assert rows["Q1"]["holds"] == "yes"
    assert [p["part"] for p in parts] == [f"Q1({c})" for c in "abcdef"]
    assert rows["Q1"]["holds_hdm05"] == "n/a"  # decided on the open run's pairs only
    assert "beats the per-movement best w in 8 of 8 movements" in rows["Q1"]["ours"]


def test_q1_is_contradicted_when_mc_auto_fails_and_partly_when_only_60_hz_fails():
    rows, _ = q_table(open_run(q1_centres((0.05, 40.0), (0.05, 30.0))), ["Q1"])
    assert rows["Q1"]["holds"] == "no"
    rows, parts = q_table(open_run(q1_centres((0.4, 10.0), (0.05, 30.0))), ["Q1"])
    assert rows["Q1"]["holds"] == "partly"
    by = {p["part"]: p["verdict"] for p in parts}
    assert by["Q1(a)"] == "holds" and by["Q1(b)"] == "contradicted"


def test_q1_is_inconclusive_when_the_intervals_straddle_every_bar():
    c = q1_centres((0.3, 15.0), (0.3, 8.0))
    c["Mc auto"] = (0.25, 18.0)
    c["Mc auto@60Hz"] = (0.25, 9.0)
    run = open_run(c, spread={"Mc auto": 0.05, "Mc auto@60Hz": 0.05})
    _, parts = q_table(run, ["Q1"])
    by = {p["part"]: p["verdict"] for p in parts}
    # straddling: inconclusive, or on the threshold where the second seed decides it
    assert {by["Q1(a)"], by["Q1(b)"]} <= {"inconclusive", "on the threshold"}


def pause_centres(without, with_pause):
    c = {n: (0.3, without) for n in PAUSE_METHODS}
    return c | {n + PAUSE_SUFFIX: (0.3, with_pause) for n in PAUSE_METHODS}


def test_q6_decides_the_posters_remark_on_opw_alone():
    # the pause lowers every method's deviation: the remark ("may not work") is contradicted
    rows, parts = q_table(open_run(pause_centres(12.0, 8.0)), ["Q6"])
    assert rows["Q6"]["holds"] == "no"
    assert [p["text"] for p in parts] == [
        "the pause raises OPW's median deviation (with minus without, paired, above 0)"
    ]
    # raised: the remark holds; the other methods are findings in our value, not parts
    rows, parts = q_table(open_run(pause_centres(12.0, 40.0)), ["Q6"])
    assert rows["Q6"]["holds"] == "yes" and len(parts) == 1
    assert rows["Q6"]["ours"].startswith("median deviation without -> with a pause (frames): Ma ")
    assert "OE-DTW 12.0 -> 40.0 (raised)" in rows["Q6"]["ours"]
    # only OPW decides it: the others raised, OPW lowered -> no
    c = pause_centres(12.0, 40.0) | {"OPW" + PAUSE_SUFFIX: (0.3, 8.0)}
    rows, _ = q_table(open_run(c), ["Q6"])
    assert rows["Q6"]["holds"] == "no"


# -- Q7: edits and relocating -----------------------------------------------------------------


def edit_run(off, short_cut=False):
    """An open run of 36 pairs of 600-frame takes whose maps are the true map of each edit
    with the first ``off(edit, relocate)`` share of frames (about; per pair and method) 60
    frames (500 ms) late; ``short_cut``: the targets ``*_0`` too short for the 2 s cut."""
    run = FakeRun({"authors_fbx": 3, "hdm05": 3}, takes=3, n_frames=600)
    run.add("DTW", 0.0)  # its maps: the diagonal, so the true map is each frame's source
    rng = np.random.default_rng(1)
    for edit in (None, *EDITS):
        for name in EDIT_METHODS:
            maps = []
            for p in run.pairs:
                if short_cut and edit == "cut 2 s" and p["target"].endswith("_0"):
                    maps.append(np.zeros(0, np.int64))
                    continue
                truth = np.arange(600) if edit is None else source_frames(
                    600, 120.0, edit, edit_seed(edit, p["target"]))[0]  # fmt: skip
                q = np.clip(off(edit, "(relocate)" in name) + rng.normal(0.0, 0.05), 0.0, 1.0)
                M = truth.copy()
                M[: int(q * M.size)] += 60
                maps.append(M)
            run.add(name + ("" if edit is None else edit_suffix(edit)), 0.0, maps=maps)
    return run


def test_q7_holds_when_relocating_raises_every_edit_and_the_unedited_share():
    rows, parts = q_table(edit_run(lambda e, r: 0.1 if r else (0.3 if e is None else 0.5)),
                          ["Q7"])  # fmt: skip
    assert rows["Q7"]["holds"] == "yes"
    assert [p["part"] for p in parts] == [f"Q7({c})" for c in "abcdef"]
    assert [p["text"].split(":")[0] for p in parts] == [*EDITS, "unedited"]
    assert rows["Q7"]["ours"].startswith(
        "frames within 300 ms, nine online methods, without -> with relocating: cut 0.5 s "
    )
    assert "(36 pairs)" in rows["Q7"]["ours"]


def test_q7_unedited_part_needs_an_interval_at_or_above_0():
    # relocating lowers the unedited share: contradicted; edits still raised: partly
    off = lambda e, r: (0.1 if r else 0.5) if e else (0.5 if r else 0.1)  # noqa: E731
    rows, parts = q_table(edit_run(off), ["Q7"])
    by = {p["part"]: p["verdict"] for p in parts}
    assert by["Q7(f)"] == "contradicted" and by["Q7(a)"] == "holds"
    assert rows["Q7"]["holds"] == "partly"
    # the same share with and without: the interval straddles 0, which is not a pass
    _, parts = q_table(edit_run(lambda e, r: 0.2), ["Q7"])
    assert {p["verdict"] for p in parts} <= {"inconclusive", "on the threshold"}


def test_q7_leaves_out_the_pairs_too_short_for_an_edit():
    run = edit_run(lambda e, r: 0.1 if r else 0.5, short_cut=True)
    rows, parts = q_table(run, ["Q7"])
    # 12 of the 36 pairs have a target *_0: the 2 s cut is scored on the other 24
    assert rows["Q7"]["ours"].count("(36 pairs)") == 5
    assert "(24 pairs)" in rows["Q7"]["ours"].split("cut 2 s")[1].split(",")[0]
    assert parts[2]["verdict"] == "holds"


def test_q_claims_without_the_open_run_are_not_computed():
    ctx = ClaimContext(mode="smoke")
    rows, _ = claims.evaluate_claims(
        claims.claims_by_id(["Q1", "Q2", "Q3", "Q4", "Q5", "Q6", "Q7"]), claims.claim_contexts(ctx)
    )
    assert [r["holds"] for r in rows] == ["n/a"] * 7
    assert all(r["ours"].startswith("not computed (no results of the open run") for r in rows)


# -- Q3: the global band ----------------------------------------------------------------------


def behind_pair():
    """A target that holds its first pose for 300 frames before the input's motion: an
    unconstrained Method C holds at the start and falls far behind the diagonal."""
    I = random_walk_features(500, seed=5)
    E = np.concatenate([np.repeat(I.euler[:1], 300, axis=0), I.euler])
    T = features_from_euler(E, orders=I.orders, name="still+I")
    return I, T


@pytest.mark.parametrize("label", ["band 1 s", "band w/2"])
@pytest.mark.parametrize("name", ["Mc w40", "Mb w40", "Mc w80"])
def test_the_band_keeps_the_map_within_its_half_width_of_the_diagonal(name, label):
    I, T = behind_pair()
    B = 120 if label == "band 1 s" else registry.resolve(name).w // 2
    free, _ = registry.align(name, I, T)
    band, _ = registry.align(f"{name} ({label})", I, T)
    q = np.arange(T.n_frames)
    assert np.min(free - q) < -120  # without the band the map leaves it
    inside = band < I.n_frames - 1  # before the input is exhausted (then it holds at m)
    assert np.all(np.abs(band - q)[inside] <= B)
    assert np.min((band - q)[inside]) == -B  # kept on its edge
    # streamed one frame at a time (bounded history off) gives the same map
    M, _ = run_online(registry.make_online(f"{name} ({label})", I), T)
    np.testing.assert_array_equal(M, band)


def test_the_band_changes_nothing_where_the_map_stays_inside_it():
    I = random_walk_features(300, seed=7)
    T = random_walk_features(300, seed=7)
    free, _ = registry.align("Mc w40", I, T)
    assert np.max(np.abs(free - np.arange(300))) <= 120
    np.testing.assert_array_equal(registry.align("Mc w40 (band 1 s)", I, T)[0], free)


def test_band_rows_masks_a_known_candidate_and_the_band_refuses_type_v():
    from fpdtw.online.band import band_rows

    # |100 + r - 221| <= 120: r = 0 is 121 away (out), r = 1..4 are 120..117 (in)
    np.testing.assert_array_equal(band_rows(100, 5, 221, 120), [False, True, True, True, True])
    np.testing.assert_array_equal(band_rows(0, 3, 0, 1), [True, True, False])
    with pytest.raises(AlignmentError, match="Type V"):
        registry.make_online("Mc w40 (band 1 s) + Type V", random_walk_features(50))
    with pytest.raises(AlignmentError, match="Type V"):
        registry.make_online("Mb w40 (band w/2) + Type V", random_walk_features(50))
    assert registry.resolve("Mb w40 (band 1 s)").options == {"band": "1s"}
    assert registry.resolve("Mc w80 (band w/2)").options == {"band": "half-w"}
    assert registry.make_online("Mc w80 (band w/2)", random_walk_features(50)).name == (
        "Mc w80 (band w/2)"
    )


def test_band_names_have_file_names_without_a_slash():
    from fpdtw.paper.runner.grid import BAND_NAMES, OPEN_ALGORITHMS
    from fpdtw.paper.runner.results import slug

    assert slug("Mc w40 (band w/2)") == "Mc_w40_band_w2"
    assert slug("Mc w40 (band 1 s)") == "Mc_w40_band_1_s"  # as before
    assert set(BAND_NAMES) <= set(OPEN_ALGORITHMS) and len(BAND_NAMES) == 6
    assert len({slug(n) for n in OPEN_ALGORITHMS}) == len(OPEN_ALGORITHMS)


def test_the_band_of_w2_computes_fewer_cells_on_the_diagonal():
    """On a map along the diagonal, Mc w40's band of w/2 computes rows 0..21 of each window
    (q + 20 - M_n with M_n = q - 1), of 41 - q without it (the input ends at frame 39); the
    1 s band all of them."""
    from fpdtw.paper.claims.open import band_removed_share

    run = FakeRun({"authors_fbx": 1}, takes=2, n_frames=40)
    for n in ("UTW", "Mc w40 (band w/2)", "Mc w40 (band 1 s)", "Mb w40 (band w/2)"):
        run.add(n, 0.3, 10.0)
    ev = Evidence(run, n_resamples=10)
    q = np.arange(3, 40)  # window steps: n = q - 1 >= 2, M_n = q - 1 < m = 39
    full = np.minimum(39, 39 - (q - 1)) + 1
    expected = np.mean(1 - np.minimum(full, 22) / full)
    assert band_removed_share(ev, "Mc w40 (band w/2)") == pytest.approx(expected)
    assert 0.1 < expected < 0.5
    steps, cells, banded, _ = ev.band_cells("Mc w40 (band w/2)")
    np.testing.assert_array_equal(steps, [37, 37])
    np.testing.assert_array_equal(cells, [40 * full.sum()] * 2)
    np.testing.assert_array_equal(banded, [40 * np.minimum(full, 22).sum()] * 2)
    assert band_removed_share(ev, "Mc w40 (band 1 s)") == 0.0
    assert band_removed_share(ev, "Mb w40 (band w/2)") > 0.0
    with pytest.raises(ValueError, match="not a band variant"):
        ev.band_cells("UTW")


def variant_centres(bases, option, sim, dev):
    """UTW, the base methods at (0.3, 20) and their variants ``f"{n} ({option})"``."""
    c = {"UTW": (0.25, 60.0)} | {n: (0.3, 20.0) for n in bases}
    return c | {f"{n} ({option})": (sim, dev) for n in bases}


def band_centres(sim, dev):
    """The band of w/2 at (sim, dev); the 1 s band (the first reading) at its bases'."""
    from fpdtw.paper.runner.grid import BAND_1S, BAND_BASES, BAND_HALF_W

    c = variant_centres(BAND_BASES, BAND_HALF_W, sim, dev)
    return c | {f"{n} ({BAND_1S})": (0.3, 20.0) for n in BAND_BASES}


def band_bench(ratio):
    """A make bench report timing each base at 100 us and its band of w/2 at ``ratio`` x."""
    from fpdtw.paper.runner.grid import BAND_BASES

    online = []
    for n in BAND_BASES:
        online += [{"name": n, "median_s": 1e-4}, {"name": f"{n} (band w/2)",
                                                    "median_s": ratio * 1e-4}]  # fmt: skip
    return {"online": online}


def band_run(sim, dev):
    """An open run of 200-frame pairs mapped along the diagonal: every band of w/2 clips."""
    return open_run(band_centres(sim, dev), n_frames=200)


def test_q3_verdicts():
    rows, parts = q_table(band_run(0.4, 10.0), ["Q3"], band_bench(0.6))
    assert rows["Q3"]["holds"] == "yes" and len(parts) == 12
    assert [p["part"] for p in parts[:4]] == ["Q3(a)", "Q3(b)", "Q3(c)", "Q3(d)"]
    assert "Mb w40 (band w/2) computes fewer cells" in parts[2]["text"]
    assert "time per frame is lower" in parts[3]["text"]
    ours = rows["Q3"]["ours"]
    assert "with the band of w/2" in ours and "cells removed" in ours and "time x0.60" in ours
    assert "(first reading, a 1 s band: Mb w40 similarity 0.3" in ours
    rows, parts = q_table(band_run(0.1, 40.0), ["Q3"], band_bench(1.2))
    by = {p["part"]: p["verdict"] for p in parts}
    assert [by[f"Q3({c})"] for c in "abcd"] == ["contradicted", "contradicted", "holds",
                                                "contradicted"]  # fmt: skip
    assert rows["Q3"]["holds"] == "partly"  # it removes cells, and that is all
    rows, parts = q_table(band_run(0.35, 19.0), ["Q3"], band_bench(0.6))
    by = {p["part"]: p["verdict"] for p in parts}
    assert by["Q3(a)"] == "contradicted" and by["Q3(b)"] == "holds"  # better, yet not both
    assert rows["Q3"]["holds"] == "partly"
    # without make bench's report the time parts cannot be decided
    rows, parts = q_table(band_run(0.4, 10.0), ["Q3"])
    by = {p["part"]: p["verdict"] for p in parts}
    assert by["Q3(c)"] == "holds" and by["Q3(d)"] == "inconclusive"
    assert rows["Q3"]["holds"] == "partly"
    assert "no make bench report" in rows["Q3"]["reason"]


# -- Q2: joint weights from the recorded motion ------------------------------------------------


def turning_quats(steps_rad, n_frames=11):
    """Joint j turns about x by ``steps_rad[j]`` every frame: quaternions (n_frames, k, 4)."""
    theta = np.arange(n_frames)[:, None] * np.asarray(steps_rad)[None, :]
    Q = np.zeros((n_frames, len(steps_rad), 4))
    Q[..., 0], Q[..., 1] = np.cos(theta / 2), np.sin(theta / 2)
    return Q


def test_joint_weights_are_each_joints_travel_over_the_mean():
    from fpdtw import joint_weights

    # 10 steps of 0.1 and 0.3 rad: travel (2/pi) * 10 * step / 2 -> ratio 1 : 3, mean 1
    np.testing.assert_allclose(joint_weights(turning_quats([0.1, 0.3])), [0.5, 1.5], rtol=1e-12)
    # a joint that never moves gets 0 (no floor); a still input gets 1 everywhere
    np.testing.assert_allclose(joint_weights(turning_quats([0.2, 0.0])), [2.0, 0.0], rtol=1e-12)
    np.testing.assert_array_equal(joint_weights(turning_quats([0.0, 0.0, 0.0])), np.ones(3))
    # q and -q are the same rotation: a sign flip is no travel
    Q = turning_quats([0.1, 0.1])
    Q[1::2, 1] *= -1
    np.testing.assert_allclose(joint_weights(Q), [1.0, 1.0], rtol=1e-12)
    I = random_walk_features(200, seed=3)
    w = joint_weights(I)
    assert w.shape == (8,) and w.dtype == np.float64 and w.mean() == pytest.approx(1.0)
    with pytest.raises(AlignmentError, match=r"quaternions \(frames, k, 4\)"):
        joint_weights(np.zeros((5, 3)))
    with pytest.raises(AlignmentError, match="finite"):
        joint_weights(np.full((5, 2, 4), np.nan))


def test_the_weighted_kernels_on_a_hand_checked_case_and_against_the_plain_twin():
    from fpdtw import plain
    from fpdtw.costs import _geo_frame, _geo_frame_w, _geo_line, _geo_line_w

    a = np.array([[1.0, 0, 0, 0], [1.0, 0, 0, 0]])
    # joint 0 turned by pi/2: (2/pi) acos(cos(pi/4)) = 0.5; joint 1 by pi: 1
    b = np.array([[np.cos(np.pi / 4), np.sin(np.pi / 4), 0, 0], [0.0, 1, 0, 0]])
    w = np.array([0.5, 1.5])
    assert _geo_frame_w(a, b, w) == pytest.approx(0.5 * 0.5 + 1.5 * 1.0, abs=1e-15)
    assert plain.geo_distance(a, b, w) == pytest.approx(1.75, abs=1e-15)
    assert plain.geo_distance(a, b) == pytest.approx(1.5, abs=1e-15)
    out, acc = np.empty(1), np.empty(1)
    _geo_line_w(a, b[:, :, None].copy(), 0, 1, acc, out, w)
    assert out[0] == pytest.approx(1.75, abs=1e-15)
    # random frames and weights: numba == plain; empty weights == the unweighted kernels, bit
    # for bit
    rng = np.random.default_rng(4)
    A = random_walk_features(30, seed=8).quats
    B = random_walk_features(25, seed=9).quats
    Bsoa = np.ascontiguousarray(B.transpose(1, 2, 0))
    w = rng.uniform(0, 3, 8)
    none = np.empty(0)
    got, ref = np.empty(25), np.empty(25)
    acc = np.empty(25)
    for i in range(A.shape[0]):
        _geo_line_w(A[i], Bsoa, 0, 25, acc, got, w)
        np.testing.assert_allclose(got, plain.cost_matrix(A[i : i + 1], B, w)[0], atol=1e-12)
        assert _geo_frame_w(A[i], B[3], w) == got[3]
        _geo_line_w(A[i], Bsoa, 0, 25, acc, got, none)
        _geo_line(A[i], Bsoa, 0, 25, acc, ref)
        np.testing.assert_array_equal(got, ref)
        assert _geo_frame_w(A[i], B[3], none) == _geo_frame(A[i], B[3])


WEIGHTED = ["Mb w40", "Mc w40", "OLTW"]


@pytest.mark.parametrize("name", WEIGHTED)
def test_weights_of_one_give_the_unweighted_map(name):
    from reference.synthetic import synthetic_pair

    I, T, _ = synthetic_pair(260, seed=21)
    free, _ = registry.align(name, I, T)
    a = registry.make_online(f"{name} (weighted joints)", I)
    assert a.name == f"{name} (weighted joints)"
    a._wts[:] = 1.0  # the weighted kernels, multiplying every joint's arccos by exactly 1
    M, _ = run_online(a, T)
    np.testing.assert_array_equal(M, free)
    assert not np.array_equal(registry.align(f"{name} (weighted joints)", I, T)[0], free)


def one_joint_pair():
    """Only joint 0 moves in the input (weights (8, 0, ..., 0)); the target's joint 0 is the
    input's, time-warped, and its other joints move at random (``noisy``) or stay at the
    identity (``clean``, where they cost exactly 0)."""
    E = np.zeros((300, 8, 3))
    E[:, 0] = random_walk_features(300, k=1, seed=6).euler[:, 0]
    I = features_from_euler(E, orders=("XYZ",) * 8, name="joint0")
    t = np.clip(np.cumsum(np.r_[0, np.where(np.arange(1, 320) % 3 == 0, 0.6, 1.0)]), 0, 299)
    Et = np.zeros((len(t), 8, 3))
    Et[:, 0] = E[np.round(t).astype(int), 0]
    clean = features_from_euler(Et, orders=("XYZ",) * 8, name="clean")
    Et[:, 1:] = random_walk_features(len(t), seed=7).euler[:, 1:]
    noisy = features_from_euler(Et, orders=("XYZ",) * 8, name="noisy")
    return I, clean, noisy


@pytest.mark.parametrize("name", WEIGHTED)
def test_weights_that_zero_every_joint_but_one_follow_that_joint_only(name):
    from fpdtw import joint_weights

    I, clean, noisy = one_joint_pair()
    np.testing.assert_array_equal(joint_weights(I), [8.0] + [0.0] * 7)
    # weighted on the noisy target == unweighted on the clean one (costs x 8, a power of 2:
    # every comparison the same); the noise moves the unweighted map
    weighted, _ = registry.align(f"{name} (weighted joints)", I, noisy)
    np.testing.assert_array_equal(weighted, registry.align(name, I, clean)[0])
    assert not np.array_equal(registry.align(name, I, noisy)[0], weighted)


def test_weighted_aligners_in_a_group_with_a_cache_give_their_streamed_maps():
    from reference.synthetic import synthetic_pair

    from fpdtw.online.window import WindowCache, run_group

    I, T, _ = synthetic_pair(200, seed=22)
    names = ["Mb w40", "Mb w40 (weighted joints)", "Mc w40 (weighted joints)", "Mc w40"]
    cache = WindowCache(I, 40)
    aligners = [registry.make_online(n, I, cache=cache) for n in names]
    assert [a.cache is None for a in aligners] == [False, True, True, False]
    for n, M in zip(names, run_group(aligners, T)):
        np.testing.assert_array_equal(M, run_online(registry.make_online(n, I), T)[0], err_msg=n)


def test_the_one_call_streaming_kernel_refuses_weights_instead_of_ignoring_them():
    from fpdtw.online.window import _stream_step

    I = random_walk_features(60, seed=2)
    a = registry.make_online("Mc w40 (weighted joints)", I)
    assert not a._lean  # its step() takes the general path, which weights (tested above)
    f = I.frame(0)
    args = (a._Iq, a._Tq, a._Te, a._M, 0, f.quats, f.euler, a._work, a._iwork)
    assert _stream_step(*args) == -2  # nothing stored, nothing computed
    b = registry.make_online("Mc w40", I)
    assert _stream_step(b._Iq, b._Tq, b._Te, b._M, 0, f.quats, f.euler, b._work, b._iwork) == 0


def test_weighted_names_resolve_and_unknown_options_are_refused():
    assert registry.resolve("OLTW (weighted joints)").options == {"weights": "travel"}
    assert registry.resolve("Mc w40 (band 1 s, weighted joints)").options == {
        "band": "1s", "weights": "travel"
    }  # fmt: skip
    with pytest.raises(AlignmentError, match="unknown option 'band 1 s'"):
        registry.resolve("OLTW (band 1 s)")
    with pytest.raises(AlignmentError, match="has no options"):
        registry.resolve("Mc auto (weighted joints)")
    with pytest.raises(AlignmentError, match="weights="):
        from fpdtw.online import OLTW

        OLTW(random_walk_features(50), weights="equal")


def weight_centres(sim, dev):
    from fpdtw.paper.runner.grid import WEIGHT_BASES, WEIGHT_SUFFIX

    c = {"UTW": (0.25, 60.0)} | {n: (0.3, 20.0) for n in WEIGHT_BASES}
    return c | {n + WEIGHT_SUFFIX: (sim, dev) for n in WEIGHT_BASES}


def test_q2_verdicts():
    from fpdtw.paper.runner.grid import OPEN_Q2, OPEN_Q7

    assert all(n in OPEN_ALGORITHMS for n in OPEN_Q2)
    # appended after Q4, before Q5's derivative variants, then Q7's names Q6 did not have
    q7 = tuple(n for n in OPEN_Q7 if n not in PAUSE_METHODS)
    assert OPEN_ALGORITHMS[-len(q7) :] == q7
    assert OPEN_ALGORITHMS[-len(q7) - 3 : -len(q7)] == (
        "OLTW (weighted joints)",
        "Mc w40 (derivative)",
        "OPW (derivative)",
    )
    rows, parts = q_table(open_run(weight_centres(0.4, 10.0)), ["Q2"])
    assert rows["Q2"]["holds"] == "yes" and len(parts) == 6
    assert rows["Q2"]["ours"].startswith("without -> with weighted joints: Mb w40: similarity")
    rows, _ = q_table(open_run(weight_centres(0.1, 40.0)), ["Q2"])
    assert rows["Q2"]["holds"] == "no"
    rows, parts = q_table(open_run(weight_centres(0.35, 19.0)), ["Q2"])
    by = {p["part"]: p["verdict"] for p in parts}
    assert by["Q2(a)"] == "contradicted" and by["Q2(b)"] == "holds"  # better, yet not both
    assert rows["Q2"]["holds"] == "partly"


# -- Q4: adaptive gamma -------------------------------------------------------------------------


def test_the_gamma_feedback_follows_a_scripted_decision_list():
    from fpdtw.online.opw_adaptive import next_gamma

    g = 0.05
    seen = []
    decisions = []
    # speed up x3 (grow), keep (nothing), speed up again (run of 3 non-keep? no: the keep
    # breaks the run), slow down (opposite sign: shrink), slow x2 (run incomplete, last two
    # non-zero agree: nothing), slow (run of 3: grow)
    for s in (2, 2, 2, 1, 2, 0, 0, 0):
        decisions.append(s)
        g = next_gamma(g, decisions)
        seen.append(round(g, 6))
    assert seen == [0.05, 0.05, 0.075, 0.075, 0.075, 0.05, 0.05, 0.075]
    assert next_gamma(0.29, [2, 2, 2]) == 0.30 and next_gamma(0.011, [2, 0]) == 0.01
    assert next_gamma(0.05, []) == 0.05


def test_opw_adaptive_changes_gamma_as_its_decisions_go():
    from fpdtw.online.opw_adaptive import GAMMA_START, AdaptiveOPW, next_gamma

    rng = np.random.default_rng(0)
    P = np.cumsum(rng.normal(0, 0.01, (400, 16, 3)), axis=0)
    I = random_walk_features(400, seed=2)
    I = type(I)(I.quats, I.euler, I.orders, I.fps, P, "rw")
    T = type(I)(I.quats[::2].copy(), I.euler[::2].copy(), I.orders, I.fps, P[::2].copy(), "fast")
    a = AdaptiveOPW(I)
    run_online(a, T)
    assert a.gammas[0] == GAMMA_START and len(a.gammas) == len(a.decisions)
    g = GAMMA_START
    for k in range(len(a.decisions)):
        assert a.gammas[k] == pytest.approx(g)
        g = next_gamma(g, [d.s for d in a.decisions[: k + 1]][-8:])
    assert max(a.gammas) > GAMMA_START  # a target twice as fast: it keeps speeding up
    assert registry.resolve("OPW adaptive").family == "OPWa"


def q4_centres(sim, dev):
    return {"UTW": (0.25, 60.0), "OPW": (0.3, 20.0), "OPW adaptive": (sim, dev)}


def test_q4_verdicts():
    assert q_table(open_run(q4_centres(0.4, 10.0)), ["Q4"])[0]["Q4"]["holds"] == "yes"
    assert q_table(open_run(q4_centres(0.1, 40.0)), ["Q4"])[0]["Q4"]["holds"] == "no"


# -- Q5: derivative costs ------------------------------------------------------------------------


def spinning_joint(step_deg=2.5, n_frames=50, flip_signs=True):
    """Joint 0 turns about a fixed axis by ``step_deg`` per frame from a tilted start (left
    multiplied: ``q_t = r^t q_0``); the other joints are still. With ``flip_signs`` every
    other frame's quaternion is negated (the same rotations)."""
    from fpdtw.motion.rotations import quat_mul

    axis = np.array([1.0, 2.0, 3.0]) / np.sqrt(14.0)
    half = np.deg2rad(step_deg) * np.arange(n_frames)[:, None] / 2
    r = np.concatenate([np.cos(half), np.sin(half) * axis], axis=1)
    q0 = np.array([np.cos(0.4), np.sin(0.4), 0.0, 0.0])
    Q = np.tile(np.array([1.0, 0.0, 0.0, 0.0]), (n_frames, 3, 1))
    Q[:, 0] = quat_mul(r, q0)
    if flip_signs:
        Q[1::2] *= -1.0
    return MotionFeatures.from_arrays(Q, orders=("XYZ", "ZXY", "YZX"), name="spin"), axis


def test_constant_angular_velocity_has_constant_derivative_quaternions():
    from fpdtw import derivative_features

    F, axis = spinning_joint(2.5)
    D = derivative_features(F)
    h = np.deg2rad(2.5) / 2
    want = np.array([np.cos(h), *(np.sin(h) * axis)])
    np.testing.assert_allclose(D.quats[1:, 0], np.tile(want, (49, 1)), atol=1e-12)
    # the angle of each derivative rotation is the step, whatever the quaternions' signs
    angle = np.rad2deg(2 * np.arccos(np.clip(D.quats[1:, 0, 0], -1, 1)))
    np.testing.assert_allclose(angle, 2.5, atol=1e-6)
    np.testing.assert_array_equal(D.quats[0], np.tile([1.0, 0.0, 0.0, 0.0], (3, 1)))
    np.testing.assert_allclose(D.quats[1:, 1:], np.tile([1.0, 0, 0, 0], (49, 2, 1)), atol=1e-12)
    assert np.all(D.quats[..., 0] >= 0)
    np.testing.assert_array_equal(D.euler[0], 0.0)
    assert D.orders == F.orders and D.fps == F.fps and D.n_frames == F.n_frames
    assert D.name == "spin (derivative)"


def test_the_derivative_euler_angles_of_a_turn_about_z_are_the_step():
    from fpdtw import derivative_features

    E = np.zeros((30, 2, 3))
    E[:, 0, 2] = 170.0 + 7.0 * np.arange(30)  # wraps past 180 degrees on the way
    D = derivative_features(features_from_euler(E, orders=("XYZ", "ZYX")))
    np.testing.assert_allclose(D.euler[1:, 0], np.tile([0.0, 0.0, 7.0], (29, 1)), atol=1e-9)
    np.testing.assert_allclose(D.euler[:, 1], 0.0, atol=1e-12)


def test_derivative_positions_are_backward_differences_and_zero_first():
    from fpdtw import derivative_features

    rng = np.random.default_rng(4)
    F = random_walk_features(20, seed=4)
    P = rng.normal(size=(20, 5, 3))
    D = derivative_features(type(F)(F.quats, F.euler, F.orders, F.fps, P, "p", None, 1.7))
    np.testing.assert_array_equal(D.positions[0], 0.0)
    np.testing.assert_allclose(D.positions[7], P[7] - P[6])
    assert D.body_size == 1.7 and D.rig is None
    with pytest.raises(AlignmentError, match="MotionFeatures"):
        derivative_features(F.quats)


def test_the_derivative_rig_compares_the_derivatives_of_the_common_representations():
    """Differencing after the rig mapping (fpdtw.derivative): the input's derivative expressed
    in the target's rig, mapped to the common representation, equals the derivative of the
    input's common representation."""
    from fpdtw.derivative import derivative_quats, derivative_rig
    from fpdtw.motion.rig import RigTransform, cost_input

    rng = np.random.default_rng(9)

    def unit(n):
        q = rng.normal(size=(n, 4))
        return q / np.linalg.norm(q, axis=1, keepdims=True)

    rig_I, rig_T = RigTransform(unit(3), unit(3)), RigTransform(unit(3), unit(3))
    Q = random_walk_features(40, k=3, seed=1).quats
    dI = cost_input(derivative_quats(Q), derivative_rig(rig_I), derivative_rig(rig_T))
    got = derivative_rig(rig_T).to_common(dI)
    want = derivative_quats(rig_I.to_common(Q))
    dots = np.abs(np.sum(got * want, axis=-1))
    np.testing.assert_allclose(dots, 1.0, atol=1e-12)
    assert derivative_rig(None) is None


def with_positions(F, seed):
    rng = np.random.default_rng(seed)
    P = np.cumsum(rng.normal(0, 0.01, (F.n_frames, 16, 3)), axis=0)
    return type(F)(F.quats, F.euler, F.orders, F.fps, P, F.name, F.rig, 1.0)


def test_the_stream_wrapper_equals_the_batch_derivative():
    from fpdtw import derivative_features
    from fpdtw.derivative import DerivativeFrames

    F = with_positions(random_walk_features(300, seed=6), 6)
    D = derivative_features(F)
    diff = DerivativeFrames()
    for t in range(F.n_frames):
        f = diff(F.frame(t), F.orders)
        np.testing.assert_array_equal(f.quats, D.quats[t])
        np.testing.assert_array_equal(f.euler, D.euler[t])
        np.testing.assert_array_equal(f.positions, D.positions[t])


@pytest.mark.parametrize(
    "name, inner",
    [("Mc w40", "Mc w40"), ("OPW", "OPW"), ("Mc w40 (band 1 s)", "Mc w40 (band 1 s)")],
)
def test_a_derivative_aligner_is_the_method_on_both_derivative_motions(name, inner):
    """Streamed pose by pose through the wrapper == the unchanged method run on
    derivative_features of both motions (stream == batch), including a reset and rerun."""
    from fpdtw import derivative_features

    I = with_positions(random_walk_features(260, seed=11), 1)
    T = with_positions(random_walk_features(240, seed=12), 2)
    a = registry.make_online(name.replace(")", ", derivative)") if "(" in name
                             else f"{name} (derivative)", I)  # fmt: skip
    M, _ = run_online(a, T)
    ref, _ = run_online(registry.make_online(inner, derivative_features(I)),
                        derivative_features(T))  # fmt: skip
    np.testing.assert_array_equal(M, ref)
    np.testing.assert_array_equal(run_online(a, T)[0], ref)  # reset: the same again
    assert a.name.endswith("(derivative)")


def speed_pair(speed=1.5, n_frames=600):
    """A smooth input and the target = the input played ``speed`` times as fast (frame t of
    the target is input frame round(speed t))."""
    t = np.arange(n_frames)[:, None, None]
    k = np.arange(8)[None, :, None]
    ax = np.arange(3)[None, None, :]
    E = 40 * np.sin(2 * np.pi * t / (150 + 17 * k) + ax) + 15 * np.sin(2 * np.pi * t / 61 + k)
    I = with_positions(features_from_euler(E, orders=("XYZ",) * 8, name="smooth"), 3)
    idx = np.round(np.arange(0, n_frames - 1, speed)).astype(int)
    T = type(I)(I.quats[idx].copy(), I.euler[idx].copy(), I.orders, I.fps,
                I.positions[idx].copy(), "faster", None, 1.0)  # fmt: skip
    return I, T, idx


@pytest.mark.parametrize("name", ["Mc w40 (derivative)", "OPW (derivative)"])
def test_a_derivative_method_aligns_a_target_played_faster(name):
    """The map has the runner's shape and range and is monotone; on the input itself
    (speed 1) Method C recovers the diagonal. At another speed the frame-to-frame rotations
    are scaled by the speed (checked here), so the derivative costs no longer match frame
    for frame: how far the map then strays is measured (notebook 16), not asserted."""
    from fpdtw import derivative_features
    from fpdtw.paper.runner.run import _check_map

    for speed in (1.0, 1.5):
        I, T, idx = speed_pair(speed)
        M, _ = registry.align(name, I, T)
        np.testing.assert_array_equal(_check_map(resolve_algorithm(name), M, I, T, {"id": 0}), M)
        assert M.shape == (T.n_frames,) and M.min() >= 0 and M.max() <= I.n_frames - 1
        assert np.all(np.diff(M) >= 0)  # monotone
        if speed == 1.0 and name.startswith("Mc"):
            np.testing.assert_array_equal(M, idx)

    def step_angle(F):
        return np.rad2deg(2 * np.arccos(np.clip(derivative_features(F).quats[1:, :, 0], -1, 1)))

    assert np.mean(step_angle(T)) / np.mean(step_angle(I)) == pytest.approx(1.5, rel=0.05)


def test_the_runner_runs_derivative_methods_beside_their_pose_methods():
    from fpdtw.paper.runner.run import _pair_maps

    I = with_positions(random_walk_features(200, seed=21), 4)
    T = with_positions(random_walk_features(180, seed=22), 5)
    names = ["Mc w40", "Mc w40 (derivative)", "OPW", "OPW (derivative)"]
    specs = [resolve_algorithm(n) for n in names]
    assert [s.algorithm.shares_window for s in specs] == [True, False, False, False]
    maps = _pair_maps(specs, I, T, {"id": 0})
    for n in names:
        np.testing.assert_array_equal(maps[n], registry.align(n, I, T)[0])
    assert not np.array_equal(maps["Mc w40"], maps["Mc w40 (derivative)"])


def test_the_derivative_option_in_names():
    a = registry.resolve("Mc w40 (derivative)")
    assert a.derivative and a.options == {} and a.w == 40 and a.family == "C"
    b = registry.resolve("Mc w40 (derivative, band 1 s)")
    assert b.derivative and b.options == {"band": "1s"}
    assert registry.resolve("Mc w40 (band 1 s, derivative)").options == {"band": "1s"}
    assert registry.resolve("OPW (derivative)").derivative
    assert registry.resolve("Mc w40 (derivative) + Type V").typev
    assert not registry.resolve("Mc w40").derivative
    with pytest.raises(AlignmentError, match="offline"):
        registry.resolve("DTW (derivative)")
    with pytest.raises(AlignmentError, match="unknown option 'derivatives'"):
        registry.resolve("Mc w40 (derivatives)")
    with pytest.raises(AlignmentError, match="unknown option 'band 1 s'; OPW has no options but"):
        registry.resolve("OPW (derivative, band 1 s)")
    with pytest.raises(AlignmentError, match="'derivative', 'relocate'\\)$"):  # named, known
        registry.resolve("Mc w40 (derivatives)")
    with pytest.raises(AlignmentError, match="UTW has no options"):
        registry.resolve("UTW (literal window)")
    with pytest.raises(AlignmentError, match="twice"):
        registry.resolve("Mc w40 (derivative, derivative)")
    from fpdtw.paper.runner.grid import OPEN_Q5

    assert OPEN_Q5 == ("Mc w40", "Mc w40 (derivative)", "OPW", "OPW (derivative)")
    assert all(n in OPEN_ALGORITHMS for n in OPEN_Q5)


def q5_centres(sim, dev):
    from fpdtw.paper.runner.grid import DERIVATIVE_BASES

    return variant_centres(DERIVATIVE_BASES, "derivative", sim, dev)


def test_q5_verdicts():
    rows, parts = q_table(open_run(q5_centres(0.4, 10.0)), ["Q5"])
    assert rows["Q5"]["holds"] == "yes" and len(parts) == 4
    assert rows["Q5"]["ours"].startswith("poses -> derivatives: Mc w40: similarity 0.300 -> 0.400")
    rows, _ = q_table(open_run(q5_centres(0.1, 40.0)), ["Q5"])
    assert rows["Q5"]["holds"] == "no"
    rows, parts = q_table(open_run(q5_centres(0.35, 19.0)), ["Q5"])
    by = {p["part"]: p["verdict"] for p in parts}
    assert by["Q5(a)"] == "contradicted" and by["Q5(b)"] == "holds"
    assert rows["Q5"]["holds"] == "partly"


def test_band_cost_pairs_each_band_variant_with_its_base():
    from fpdtw.paper.figures.timing import band_cost

    report = {"online": [
        {"name": "Mb w40 (band w/2)", "median_s": 2e-5},
        {"name": "Mb w40", "median_s": 4e-5},
        {"name": "Mb w40 (band 1 s)", "median_s": 5e-5, "step_median_s": 3e-5},
        {"name": "Mc w40", "median_s": 8e-5, "step_median_s": 6e-5},
        {"name": "Mc w80 (band 1 s)", "median_s": 1e-4},  # its base was not timed: no row
    ]}  # fmt: skip
    rows = band_cost(report)
    assert [r["band"] for r in rows] == ["Mb w40 (band 1 s)", "Mb w40 (band w/2)"]  # 1 s first
    assert [r["name"] for r in rows] == ["Mb w40", "Mb w40"]
    assert rows[0]["base_us"] == pytest.approx(40.0) and rows[0]["band_us"] == pytest.approx(30.0)
    assert rows[0]["ratio"] == pytest.approx(0.75) and rows[1]["ratio"] == pytest.approx(0.5)
    assert band_cost({"online": []}) == []


# -- the global band's compiled steps, against the rule written out by hand ----------------


def band_snapshots(method, w, band, I, T):
    from fpdtw.online import MethodB

    cls = {"B": MethodB, "C": MethodC}[method]
    a = cls(I, w, band=band, record=True)
    a.reset()
    snaps = []
    for frame in T.frames():
        a.step(frame)
        snaps.append(a.window_snapshot())
    return snaps


@pytest.mark.parametrize("band", ["1s", "half-w"])
@pytest.mark.parametrize("method,w", [("B", 10), ("B", 40), ("C", 10), ("C", 40), ("C", 80)])
def test_the_compiled_band_keeps_the_rows_of_the_rule(method, w, band):
    """Every window step: the band binds (the map reaches the band's edge), the choice lies
    inside it, "1s" masks exactly the rows |M_n + r - q| > B of the choosing column and
    "half-w" computes exactly the rows inside (first = max(0, q - B - M_n))."""
    I, T = behind_pair()
    snaps = band_snapshots(method, w, band, I, T)
    B = w // 2 if band == "half-w" else 120  # the inputs are 120 fps
    M = np.array([f.M for f in snaps])
    inside = M < I.n_frames - 1
    assert np.abs(M - np.arange(T.n_frames))[inside].max() == B  # the band binds
    col = 1 if method == "B" else 0
    reach = w if method == "B" else w - 1
    for f in snaps[1:]:
        if f.kind != "window":
            continue
        assert abs(f.M - f.q) <= B
        w_i = min(reach, I.n_frames - 1 - f.start)
        rows = np.arange(f.first, f.w_i + 1)
        out = np.abs(f.start + rows - f.q) > B
        if band == "1s":
            assert (f.first, f.w_i) == (0, w_i)
            np.testing.assert_array_equal(np.isinf(f.C[:, col]), out)
        else:
            first = max(0, f.q - B - f.start)
            assert (f.first, f.w_i) == (first, min(w_i, f.q + B - f.start))
            assert not out.any()


def test_band_cells_are_the_rows_the_kernels_compute():
    """band_cells counts, from a band aligner's map alone, the cells its recorded windows
    hold, and those of the same steps without the band."""
    from fpdtw.online.band import band_cells

    I, T = behind_pair()
    for method, w in (("B", 40), ("C", 40), ("C", 80)):
        snaps = band_snapshots(method, w, "half-w", I, T)
        win = [f for f in snaps if f.kind == "window"]
        M = np.array([f.M for f in snaps])
        q, full, banded = band_cells(M, I.n_frames - 1, w, method)
        np.testing.assert_array_equal(q, [f.q for f in win])
        np.testing.assert_array_equal(banded, [f.C.size for f in win])
        rows = [min(w if method == "B" else w - 1, I.n_frames - 1 - f.start) + 1 for f in win]
        np.testing.assert_array_equal(full, np.array(rows) * win[0].C.shape[1])
        assert (banded < full).any() and (banded <= full).all()
        assert any(f.first == 1 for f in win)  # the map on the band's lower edge: row 0 out
        _, full1, banded1 = band_cells(M, I.n_frames - 1, w, method, band="1s")
        np.testing.assert_array_equal(banded1, full1)  # the 1 s band masks: computes all


def test_a_clipping_band_with_no_row_inside_raises_as_the_masking_band():
    """No row of the window inside the band (only possible from M_0 > B + 1: start="best"):
    the whole window is computed and masked and the step raises."""
    from fpdtw.online.band import band_half_width, band_window

    I = random_walk_features(200, seed=9)
    T = I.slice(30, 200)  # T_0 is I_30: M_0 = 30 with start="best", far above q = 3 + 20
    a = MethodC(I, 40, start="best", band="half-w")
    with pytest.raises(ValueError, match="no input frame of the window lies inside the band"):
        run_online(a, T)
    # by hand: rows from max(0, q - B - M_n) to min(w_i, q + B - M_n)
    assert band_window(32, 39, 3, 20) is None  # 0 .. -9
    assert band_window(0, 39, 3, 20) == (0, 23)
    assert band_window(10, 40, 55, 20) == (25, 40)
    assert band_half_width("half-w", 41, 120.0) == 20
    assert band_half_width("1s", 40, 60.0) == 60
