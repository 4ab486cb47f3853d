"""Edited targets and followers' scores in ms (fpdtw.paper.edits, open question Q7)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from reference.synthetic import synthetic_pair

from fpdtw.dtw import dtw_pair
from fpdtw.errors import AlignmentError
from fpdtw.paper.edits import (
    EDITS,
    MS_TOLERANCES,
    edit_rows,
    edit_seed,
    edit_target,
    errors_ms,
    format_edit_rows,
    main,
    ms_rows,
    ms_table,
    open_run_rows,
    open_run_scores,
    recovery_s,
    source_frames,
    true_map,
    within_ms,
)
from fpdtw.registry import align


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_each_edit_by_hand(seed):
    """100 frames at 10 Hz: the edit point in [20, 79] (a cut leaves a frame after it); a
    1 s cut drops 10 frames, a repeat plays the 10 before the point again, a restart plays
    all 100 again after the point; every other frame follows its predecessor."""
    F = 100
    for edit, (kind, s) in EDITS.items():
        idx, a = source_frames(F, 10.0, edit, seed)
        L = round(10 * s)
        assert 20 <= a <= (79 - L if kind == "cut" else 79), (edit, a)
        np.testing.assert_array_equal(idx[:a], np.arange(a))
        if kind == "cut":
            assert idx.size == F - L and idx[a] == a + L
            np.testing.assert_array_equal(idx[a:], np.arange(a + L, F))
        elif kind == "repeat":
            assert idx.size == F + L
            np.testing.assert_array_equal(idx[a:], np.r_[np.arange(a - L, a), np.arange(a, F)])
        else:
            assert idx.size == F + a and idx[a] == 0
            np.testing.assert_array_equal(idx[a:], np.arange(F))
        steps = np.diff(idx)
        assert set(np.flatnonzero(steps != 1) + 1) == {a}, edit


def test_an_edit_is_the_same_for_a_take_in_every_pair_and_its_seed_decides_it():
    _, T, _ = synthetic_pair(n_frames=300, seed=1)
    a1 = edit_target(T, "cut 1 s")
    a2 = edit_target(T, "cut 1 s")
    np.testing.assert_array_equal(a1[1], a2[1])
    edited, idx, at = a1
    assert edited.name == f"{T.name}+cut 1 s" and edited.n_frames == idx.size
    np.testing.assert_array_equal(edited.quats, T.quats[idx])
    np.testing.assert_array_equal(edited.euler, T.euler[idx])
    other = edit_target(T, "cut 1 s", seed=12345)
    assert other[2] != at or not np.array_equal(other[1], idx)
    with pytest.raises(AlignmentError, match="unknown edit"):
        source_frames(100, 10.0, "skip", 0)
    with pytest.raises(AlignmentError, match="too short"):
        source_frames(12, 10.0, "cut 2 s", 0)


def test_scores_in_ms_by_hand():
    """Input at 100 Hz: errors 0, 10, 20, 100 and 2500 ms."""
    P = np.zeros(5, dtype=int)
    M = np.array([0, 1, 2, 10, 250])
    np.testing.assert_allclose(errors_ms(M, P, 100.0), [0, 10, 20, 100, 2500])
    got = within_ms(M, P, 100.0)
    assert got == {50: 0.6, 100: 0.8, 300: 0.8, 500: 0.8, 1000: 0.8, 2000: 0.8, "lost": 0.2}
    np.testing.assert_array_equal(true_map([5, 6, 7, 8], [0, 1, 1, 3, 0]), [5, 6, 6, 8, 5])


def test_recovery_by_hand():
    """Target and input at 10 Hz, edit at frame 2; back when the error stays within 300 ms
    for 1 s (10 frames), or to the end."""
    P = np.zeros(30, dtype=int)
    M = np.zeros(30, dtype=int)
    M[2:7] = 50  # 5 s off for frames 2-6, then right to the end
    assert recovery_s(M, P, 10.0, 10.0, 2) == pytest.approx(0.5)
    M[12] = 50  # a blip: the 5 good frames 7-11 are not enough, 13-29 are
    assert recovery_s(M, P, 10.0, 10.0, 2) == pytest.approx(1.1)
    M[:] = 50
    assert recovery_s(M, P, 10.0, 10.0, 2) == math.inf
    M[25:] = 0  # good to the end (5 frames, shorter than 1 s): back at frame 25
    assert recovery_s(M, P, 10.0, 10.0, 2) == pytest.approx(2.3)


def test_edit_rows_score_each_method_with_and_without_relocating(cmu_retimed, capsys):
    """CMU 18_01 against itself restarted from the top: the rows of Mc w40 and Mc w40
    (relocate), as it is and restarted; each row's shares are within_ms of that run's map;
    the command prints the same table."""
    _, I, _ = cmu_retimed
    rows = edit_rows(I, I, names=("Mc w40",), edits=("restart",))
    assert [(r["edit"], r["name"]) for r in rows] == [
        ("none", "Mc w40"), ("none", "Mc w40 (relocate)"),
        ("restart", "Mc w40"), ("restart", "Mc w40 (relocate)")]  # fmt: skip
    E, idx, at = edit_target(I, "restart")
    truth = true_map(dtw_pair(I, I).map, idx)
    M, _ = align("Mc w40 (relocate)", I, E)
    assert {t: rows[3][t] for t in (*MS_TOLERANCES, "lost")} == within_ms(M, truth, I.fps)
    assert rows[3]["jumps"] >= 1 and rows[2]["jumps"] == 0 and rows[0]["recovery_s"] is None
    assert rows[3]["recovery_s"] == recovery_s(M, truth, I.fps, E.fps, at)
    assert len(format_edit_rows(rows).splitlines()) == 5
    assert main(["cmu", "18_01.bvh", "18_01.bvh"]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[1].split()[:2] == ["edit", "method"] and len(out) == 2 + 6 * 6


def test_ms_rows_by_hand():
    """At 10 Hz a frame is 100 ms: a map 3 frames off on half its frames is within 300 ms
    everywhere, within 100 ms on half; 25 frames off (2.5 s) is lost."""
    P = np.arange(10)
    off = P + np.array([0, 3] * 5)
    rows = ms_rows({"half": off, "lost": P + 25}, P, 10.0)
    assert rows[0]["method"] == "half" and rows[0]["deviation_frames"] == 1.5
    assert rows[0]["within_100ms"] == 0.5 and rows[0]["within_300ms"] == 1.0
    assert rows[0]["lost"] == 0.0 and rows[1]["lost"] == 1.0 and rows[1]["within_2000ms"] == 0.0
    text = ms_table({"half": off}, P, 10.0).splitlines()
    assert text[1].split() == ["half", "1.5", "50.0%", "50.0%", "100.0%", "100.0%", "100.0%",
                               "100.0%", "0.0%"]  # fmt: skip


class _Stored:
    def __init__(self, maps):
        self.maps = [np.asarray(m, np.int32) for m in maps]

    def map(self, k):
        return self.maps[k]


class _Run:
    """A run of two pairs (targets 'a' of 300 frames and 'b' of 60) at 120 Hz."""

    pairs = [{"id": 0, "target": "a"}, {"id": 1, "target": "b"}]

    def __init__(self, stored):
        self.stored = stored

    def get(self, name):
        return self.stored[name]

    def fps(self, name):
        return 120.0


def test_open_run_scores_by_hand():
    """The true map of an edited pair is the unedited DTW map at each frame's source: a map
    equal to it is within every tolerance and back at once; a map stuck at frame 0 is lost
    where the truth is over 2 s on; a pair the edit did not fit (empty map) has no result."""
    P = [np.arange(300) // 2 + 40, np.arange(60)]
    idx, at = source_frames(300, 120.0, "restart", edit_seed("restart", "a"))
    truth = P[0][idx]
    stuck = np.zeros(idx.size, np.int64)
    maps = {"DTW": P, "Mc w40@restart": [truth, []], "OLTW@restart": [stuck, []],
            "OLTW": [P[0] * 0, P[1]]}  # fmt: skip
    run = _Run({name: _Stored(m) for name, m in maps.items()})
    best, none = open_run_scores(run, "Mc w40", "restart")
    assert none is None and best["frames"] == idx.size and best["recovery_s"] == 0.0
    assert all(best["within"][t] == idx.size for t in MS_TOLERANCES) and best["lost"] == 0
    worst = open_run_scores(run, "OLTW", "restart")[0]
    assert worst["lost"] == int(np.sum(truth > 240)) and worst["within"][50] == 0
    assert worst["recovery_s"] == math.inf
    plain = open_run_scores(run, "OLTW", None)
    assert plain[1]["within"][50] == 60 and plain[1]["recovery_s"] is None
    rows = open_run_rows(run, ["Mc w40"], edits=("restart",))
    assert rows[0]["pairs"] == 1 and rows[0][50] == 1.0 and rows[0]["never"] == 0.0
