"""Rescoring a run's stored maps under a reading of eq. 2 (fpdtw.paper.similarity_level).

A tiny real run (one authors' FBX movement and one HDM05 class, two takes each, cropped to
1 s: 4 ordered pairs) at 120 Hz, 60 Hz and with a pause inserted. Checked: the ``ours``
reading gives back the stored scores; the ``transform`` reading changes the HDM05 pairs
only (the authors' takes have no pre-rotations, an ASF bone has its axis frame); the
``values`` contract of :class:`fpdtw.paper.claims.evidence.Evidence`; the disk cache, reused
and invalidated by a changed run. And, by hand: eq. 1 does not see a constant per-joint
pre/post rotation, eq. 2 does.
"""

from __future__ import annotations

import math
import shutil

import numpy as np
import pytest

from fpdtw import costs, plain
from fpdtw.dtw import utw_map
from fpdtw.io import load_motion
from fpdtw.metrics import similarity
from fpdtw.motion.rig import trajectory_rotations
from fpdtw.paper import similarity_level as SL
from fpdtw.paper.claims.evidence import Evidence
from fpdtw.paper.runner import run as E
from fpdtw.paper.runner.results import Results, load_npz, save_npz

TINY = E.Selection(
    datasets=("authors_fbx", "hdm05"),
    movements=("Walk", "depositFloorR"),
    takes_per_movement=2,
    crop_seconds=1.0,
)
ALGOS = ["DTW", "UTW", "Mc w10", "UTW@60Hz", "Mc w10@60Hz", "UTW@pause"]


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    """The tiny run, made once in a temporary results folder."""
    root = tmp_path_factory.mktemp("results")
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("FPDTW_RESULTS_DIR", str(root))
        res = E.run_experiments("level", ALGOS, n_jobs=1, progress=False, selection=TINY)
    assert [p["dataset"] for p in res.pairs] == ["authors_fbx"] * 2 + ["hdm05"] * 2
    return res


@pytest.fixture
def fresh_run(run, tmp_path):
    """A copy of the tiny run without its rescored cache."""
    folder = tmp_path / "run"
    shutil.copytree(run.folder, folder, ignore=shutil.ignore_patterns("rescored"))
    return Results(folder)


def test_ours_gives_back_the_stored_scores_at_every_rate(fresh_run):
    values = SL.reading_values(fresh_run, "ours", progress=False)
    for name in ALGOS:
        want = fresh_run.get(name)["similarity"]
        np.testing.assert_allclose(values(name, "similarity"), want, rtol=0, atol=1e-12)


def test_transform_changes_the_hdm05_pairs_only(fresh_run):
    ours = SL.reading_values(fresh_run, "ours", progress=False)
    transform = SL.reading_values(fresh_run, "transform", progress=False)
    for name in ("UTW", "Mc w10@60Hz"):
        a, b = ours(name, "similarity"), transform(name, "similarity")
        np.testing.assert_allclose(b[:2], a[:2], rtol=0, atol=1e-12)  # no pre-rotations
        assert np.all(np.abs(b[2:] - a[2:]) > 1e-6)  # C M C^-1 against M


def test_values_contract_at_120_and_60_hz(fresh_run):
    values = SL.reading_values(fresh_run, progress=False)
    P = len(fresh_run.pairs)
    for name in ALGOS:
        assert values(name, "deviation") is None
        v = values(name, "similarity")
        assert v.shape == (P,) and v.dtype == np.float64 and np.all(np.abs(v) <= 1)
    assert fresh_run.fps("UTW@60Hz") == 60.0
    ev = Evidence(fresh_run, values=values)
    assert ev.values("UTW@60Hz", "similarity").tolist() == values("UTW@60Hz", "similarity").tolist()
    want = fresh_run.get("Mc w10")["deviation"]
    assert ev.values("Mc w10", "deviation").tolist() == want.tolist()
    with pytest.raises(KeyError, match="unknown reading"):
        SL.reading_values(fresh_run, "sideways")


def test_disk_cache_is_reused_and_a_changed_run_invalidates_it(fresh_run, monkeypatch):
    first = SL.reading_values(fresh_run, progress=False)("Mc w10", "similarity")
    files = sorted((fresh_run.folder / "rescored" / "transform").glob("Mc_w10.*.npy"))
    assert len(files) == 1

    def boom(*args, **kwargs):
        raise AssertionError("recomputed")

    monkeypatch.setattr(SL, "_algorithm_scores", boom)
    again = SL.reading_values(fresh_run, progress=False)("Mc w10", "similarity")
    assert again.tolist() == first.tolist()

    # a changed map (pair 0 held at its first input frame) is another key: recomputed
    monkeypatch.undo()
    path = fresh_run.folder / "algorithms" / "Mc_w10.npz"
    arrays = load_npz(path)
    o = arrays["offsets"]
    arrays["maps"][o[0] : o[1]] = 0
    save_npz(path, **arrays)
    changed = SL.reading_values(Results(fresh_run.folder), progress=False)("Mc w10", "similarity")
    assert changed[0] != first[0] and changed[1:].tolist() == first[1:].tolist()
    after = sorted((fresh_run.folder / "rescored" / "transform").glob("Mc_w10.*.npy"))
    assert len(after) == 1 and after != files  # the stale file is gone


def test_bvh_transform_is_local(data_path):
    mo = load_motion(data_path("cmu/18_01.bvh"))
    local, transform = (trajectory_rotations(mo, f) for f in ("local", "transform"))
    np.testing.assert_allclose(transform, local, rtol=0, atol=1e-15)
    I, T = slice(0, 120), slice(120, None)
    M = utw_map(119, mo.n_frames - 121)
    assert similarity(transform[I], transform[T], M) == similarity(local[I], local[T], M)


def hamilton(a, b):
    """Quaternion product (w, x, y, z), written out."""
    w1, x1, y1, z1 = np.moveaxis(a, -1, 0)
    w2, x2, y2, z2 = np.moveaxis(b, -1, 0)
    return np.stack(
        [
            w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2,
            w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
            w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2,
            w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2,
        ],
        axis=-1,
    )


def unit(rng, *shape):
    q = rng.normal(size=(*shape, 4))
    return q / np.linalg.norm(q, axis=-1, keepdims=True)


def test_eq1_does_not_see_a_constant_pre_and_post_rotation():
    rng = np.random.default_rng(5)
    k = 8
    q1, q2 = unit(rng, k), unit(rng, k)
    P, Q = unit(rng, k), unit(rng, k)  # per joint: FBX pre-rotation and post-rotation
    p1, p2 = hamilton(hamilton(P, q1), Q), hamilton(hamilton(P, q2), Q)
    d = costs.geo_distance(q1, q2)
    assert 0.5 < d < k  # not a degenerate pair
    assert costs.geo_distance(p1, p2) == pytest.approx(d, abs=1e-12)
    assert plain.geo_distance(p1, p2) == pytest.approx(d, abs=1e-12)
    A, B = unit(rng, 3, k), unit(rng, 4, k)  # distinct frames (arccos near 1 is ill-posed)
    CP = costs.geodesic_cost_matrix(hamilton(hamilton(P, A), Q), hamilton(hamilton(P, B), Q))
    np.testing.assert_allclose(CP, costs.geodesic_cost_matrix(A, B), rtol=0, atol=1e-12)
    # what it does see: a rotation on one motion only
    assert abs(costs.geo_distance(hamilton(P, q1), q2) - d) > 1e-3


def test_eq2_sees_a_constant_axis_frame_by_hand():
    # a joint turning 0..80 degrees about x; its axis frame C: 90 degrees about z, so
    # C R_x(a) C^-1 = R_y(a). Local: y -> (0, cos a, sin a); under a reversed map the y and
    # z axes rank backwards (-1 each), x is flat in both (1): -1/3. Transform: the vector
    # (0, 1, 0) lies on the turning axis and never moves: every axis flat, 1.
    a = np.radians(np.linspace(0, 80, 12))
    R = np.stack([np.cos(a / 2), np.sin(a / 2), 0 * a, 0 * a], axis=-1)[:, None]
    C = np.array([math.cos(math.pi / 4), 0, 0, math.sin(math.pi / 4)])
    CRC = hamilton(hamilton(C, R), C * [1, -1, -1, -1])
    rev = np.arange(12)[::-1]
    assert similarity(R, R, rev) == pytest.approx(-1 / 3)
    assert similarity(CRC, CRC, rev) == 1.0
    assert costs.geo_distance(CRC[0], CRC[-1]) == pytest.approx(costs.geo_distance(R[0], R[-1]))


def test_results_score_eq2_under_the_default_reading_and_keep_the_other_switchable(
    fresh_run, monkeypatch
):
    """Since 2026-11-24 a run's similarity is read under "transform" (docs/eq2_reading.md);
    FPDTW_EQ2=local gives the stored scores; the maps and deviations are the same."""
    monkeypatch.delenv("FPDTW_EQ2", raising=False)
    default = Results(fresh_run.folder)
    assert default.eq2 == "transform"
    transform = SL.reading_values(fresh_run, "transform", progress=False)
    for name in ("UTW", "Mc w10@60Hz"):
        got = default.get(name)
        np.testing.assert_array_equal(got["similarity"], transform(name, "similarity"))
        np.testing.assert_array_equal(got["deviation"], default.stored(name)["deviation"])
        np.testing.assert_array_equal(got.map(0), default.stored(name).map(0))
    monkeypatch.setenv("FPDTW_EQ2", "local")
    local = Results(fresh_run.folder)
    assert local.get("UTW")["similarity"] is local.stored("UTW")["similarity"]
    monkeypatch.setenv("FPDTW_EQ2", "sideways")
    with pytest.raises(ValueError, match="FPDTW_EQ2='sideways': not a reading of eq. 2"):
        Results(fresh_run.folder)


def test_claims_decide_under_the_other_reading_of_eq2(fresh_run):
    """Under the transform default the claims' other body reads the stored (local) scores."""
    from fpdtw.paper.claims import ClaimContext, claim_contexts

    default = Results(fresh_run.folder, eq2="transform")
    ctx = ClaimContext(mode="smoke", ev=Evidence(default, n_resamples=50))
    ctxs = claim_contexts(ctx)
    other = ctxs["eq2_other"].ev
    for name in ("UTW", "Mc w10@60Hz"):
        np.testing.assert_array_equal(
            other.values(name, "similarity"), default.stored(name)["similarity"]
        )
        np.testing.assert_array_equal(
            ctx.ev.values(name, "similarity"), default.get(name)["similarity"]
        )
    assert ctxs["eq2_other_hdm05"].ev.n_pairs == 2
    local = Results(fresh_run.folder, eq2="local")
    back = claim_contexts(ClaimContext(mode="smoke", ev=Evidence(local, n_resamples=50)))
    transform = SL.reading_values(fresh_run, "transform", progress=False)
    np.testing.assert_array_equal(
        back["eq2_other"].ev.values("UTW", "similarity"), transform("UTW", "similarity")
    )
