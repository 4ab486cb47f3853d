"""Notebook 15's analysis (fpdtw.paper.readings): hand-made results folders with known answers."""

from __future__ import annotations

import numpy as np
import pytest
from reference.synthetic import one_joint_motion
from test_plots_results import write_fake_results

from fpdtw.paper import readings as R
from fpdtw.paper.numbers import WINDOWS
from fpdtw.paper.runner.grid import SILENT_CHOICES, choice_targets, choice_variant
from fpdtw.paper.runner.run import load_results
from fpdtw.registry import C_READINGS

N_PAIRS = 5
SIZES = [(19, 19, 9, 9)] * N_PAIRS  # m, n at 120 Hz; m60, n60


def _maps(kind, n=19, m=19):
    """A map per pair: 'diag' (the identity), 'stick' (half speed), 'skip' (double speed,
    then held at m)."""
    q = np.arange(n + 1)
    M = {"diag": q, "stick": q // 2, "skip": np.minimum(2 * q, m)}[kind]
    return [M.astype(np.int32)] * N_PAIRS


@pytest.fixture
def study(tmp_path, monkeypatch):
    """A fake study run: every reading at every w; DTW/UTW at both rates. The square
    window follows the diagonal and passes; the literal one skips; w10 sticks."""
    monkeypatch.setenv("FPDTW_RESULTS_DIR", str(tmp_path))
    algos = {
        "DTW": dict(similarity=[0.9] * 5, deviation=[0.0] * 5, maps=_maps("diag")),
        "UTW": dict(similarity=[0.4] * 5, deviation=[3.0] * 5, maps=_maps("diag")),
        "DTW@60Hz": dict(similarity=[0.9] * 5, deviation=[0.0] * 5, fps=60),
        "UTW@60Hz": dict(similarity=[0.4] * 5, deviation=[2.0] * 5, fps=60),
    }
    for reading in C_READINGS:
        for w in WINDOWS:
            for tv in (False, True):
                good = reading == "square"
                sim = (0.5 if w == 40 else 0.45) if good else 0.3
                kind = "stick" if w == 10 else ("diag" if good else "skip")
                algos[R.reading_name(reading, w, tv)] = dict(
                    similarity=[sim] * 5, deviation=[5.0 if good else 40.0] * 5, maps=_maps(kind)
                )
                sim60 = (0.5 if w == 20 else 0.45) if good else 0.3
                algos[R.reading_name(reading, w, tv, 60)] = dict(
                    similarity=[sim60] * 5, deviation=[4.0] * 5, fps=60
                )
    write_fake_results(tmp_path / "study", algos, n_pairs=N_PAIRS, sizes=SIZES)
    return load_results("study")


def test_readings_table_and_shape_metrics(study):
    rows = R.readings_table(study)
    assert len(rows) == 2 * (1 + len(C_READINGS) * len(WINDOWS) * 2)
    by = {(r["rate_hz"], r["algorithm"]): r for r in rows}
    dtw = by[(120, "DTW")]
    assert (dtw["reading"], dtw["hold"], dtw["exhausted"], dtw["stick_skip"]) == ("DTW", 0, 0, 0)
    sq = by[(120, "Mc w40")]
    assert sq["passes_similarity"] and sq["passes_deviation"] and sq["pairs"] == N_PAIRS
    # half speed: q // 2 holds on every other step while live (10 of 19) and never runs out
    st = by[(120, "Mc w10")]
    assert st["hold"] == pytest.approx(10 / 19) and st["exhausted"] == 0.0
    assert st["stick_skip"] == pytest.approx(
        np.median(np.arange(20) // 2 / 19 - np.arange(20) / 19)
    )
    assert st["stick_skip"] < 0
    # double speed: reaches m = 19 at q = 10; steps q = 11..19 are taken with the input exhausted
    sk = by[(120, "Mc w40 (literal window)")]
    assert sk["exhausted"] == pytest.approx(9 / 19) and sk["hold"] == 0.0 and sk["stick_skip"] > 0
    assert not sk["passes_similarity"] and not sk["passes_deviation"]
    # 60 Hz: deviation benchmark 9 frames, similarity against UTW@60Hz
    assert by[(60, "Mc w40 (literal window)@60Hz")]["passes_deviation"]  # 4 < 9


def test_reading_signature(study):
    sig = {s["reading"]: s for s in R.reading_signature(R.readings_table(study))}
    assert list(sig) == list(C_READINGS)
    sq = sig["square"]
    assert (sq["best_w_120"], sq["best_w_60"], sq["w40_passes_both"]) == (40, 20, True)
    assert sq["w10_stick_skip"] < 0 and sq["w80_stick_skip"] == 0.0
    assert (
        sq["pass_both"]
        == "w10, w20, w40, w80, w10 + Type V, w20 + Type V, w40 + Type V, w80 + Type V"
    )
    lit = sig["literal"]
    assert lit["pass_both"] == "none" and lit["w40_passes_both"] is False
    assert lit["best_w_120"] == 10  # all equal: ties go to the smallest window
    assert lit["w80_stick_skip"] > 0 and lit["exhausted"] > sq["exhausted"]


def test_mechanism_profile_on_a_window_of_equal_costs():
    """One pose against another: every cell costs c, f(r) counts cells: the literal
    window's row 0 needs one more than row 1, the square window's does not."""
    w = 6
    c = 2 / np.pi * np.radians(10.0)  # one joint, 20 degrees apart: (2/pi) * 10 deg
    I = one_joint_motion(np.full(40, 30.0), "X")
    T = one_joint_motion(np.full(12, 50.0), "X")
    prof = R.mechanism_profile([(I, T)], w, readings=("literal", "square"))
    lit, sq = prof["literal"], prof["square"]
    assert lit["steps"] == sq["steps"] == T.n_frames - 3  # every step after the warm-up
    assert lit["excess"] == pytest.approx(c, rel=1e-9) and sq["excess"] == pytest.approx(0.0)
    np.testing.assert_allclose(lit["mean_f"], c * np.array([w] + [w - 1] * w), rtol=1e-9)
    np.testing.assert_allclose(sq["mean_f"], c * np.full(w, w - 1), rtol=1e-9)
    assert lit["hold"] == 0.0 and sq["hold"] == 1.0  # the square window's tie keeps row 0
    assert lit["best_row0"] == 1.0 and lit["neighbour"] == 0.0


def test_silent_choices_and_selection_tables(tmp_path, monkeypatch):
    monkeypatch.setenv("FPDTW_RESULTS_DIR", str(tmp_path))
    base = dict(similarity=[0.5] * 5, deviation=[10.0] * 5, maps=_maps("diag"))
    algos = {"DTW": dict(base, deviation=[0.0] * 5), "UTW": dict(base, similarity=[0.4] * 5)}
    for key, choice in SILENT_CHOICES.items():
        for name in choice_targets(choice):
            algos[name] = dict(base)
            if choice.option is not None:
                worse = key == "forecast"  # the only alternative that moves anything here
                algos[choice_variant(name, choice)] = dict(
                    base, deviation=[30.0 if worse else 10.0] * 5
                )
    write_fake_results(tmp_path / "study", algos, n_pairs=N_PAIRS, sizes=SIZES)
    study = load_results("study")
    summary, detail = R.silent_choice_rows(study)  # without features: no eq. 2 rows
    by = {r["choice"]: r for r in summary}
    assert set(by) == {k for k, c in SILENT_CHOICES.items() if c.option} | {"deviation_frames"}
    assert by["forecast"]["max_d_deviation"] == 20.0
    assert by["forecast"]["verdicts_changed"] == ", ".join(
        choice_targets(SILENT_CHOICES["forecast"])
    )
    assert by["ties"]["max_d_deviation"] == 0.0 and by["ties"]["verdicts_changed"] == "none"
    # the identity map against DTW's identity: 0 over n + 1 and over n frames alike
    dev_rows = [r for r in detail if r["choice"] == "deviation_frames"]
    assert {r["deviation_alternative"] for r in dev_rows} == {0.0}
    rows = R.selection_rows(study, study, names=("UTW", "Ma"))
    assert rows[0]["passes_full"] == "deviation"  # UTW: 0.4 is its own median, not above it
    assert rows[1]["passes_paper_shaped"] == "both" and rows[1]["similarity_full"] == 0.5
