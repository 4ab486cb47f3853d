"""The relocating search (fpdtw.online.relocate, ``"<method> (relocate)"``): its kernel
against the plain NumPy twin and by hand, the wrapper on an unedited pair, the registry."""

from __future__ import annotations

import time

import numpy as np
import pytest
from reference.synthetic import synthetic_pair

from fpdtw import plain, registry
from fpdtw.app import cli
from fpdtw.app.serve import Session
from fpdtw.app.stream import session_map
from fpdtw.dtw import dtw_pair
from fpdtw.errors import AlignmentError
from fpdtw.io import load_motion
from fpdtw.io.bvh import bvh_lines, read_bvh, write_bvh
from fpdtw.motion.features import MotionFeatures
from fpdtw.motion.joints import OPW_JOINTS
from fpdtw.online.base import run_online
from fpdtw.online.relocate import Relocating, _search_step, input_from
from fpdtw.paper.edits import edit_target, recovery_s, true_map, within_ms
from fpdtw.registry import align, resolve, with_option


def _unit(x):
    return x / np.linalg.norm(x, axis=-1, keepdims=True)


def _search(q, Iq, G, lam):
    """The kernel on an input (N, k, 4) as the aligner holds it: joint-major, with scratch."""
    Isoa = np.ascontiguousarray(np.transpose(Iq, (1, 2, 0)))
    return _search_step(q, Isoa, G, lam, np.empty(G.size), np.empty(G.size))


def test_the_search_step_by_hand():
    """Three input frames, one joint: a target equal to frame 2 costs 0 there, a half turn
    from frames 0 and 1 costs 1; the next frame adds lam times the cheapest of the row's
    j, j - 1, j - 2."""
    e, x = np.array([1.0, 0, 0, 0]), np.array([0.0, 1, 0, 0])
    Iq = np.array([[x], [x], [e]])
    G = np.zeros(3)
    j, g = _search(e[None].copy(), Iq, G, 0.5)
    np.testing.assert_allclose(G, [1.0, 1.0, 0.0], atol=1e-15)
    assert (j, g) == (2, 0.0)
    j, g = _search(x[None].copy(), Iq, G, 0.5)  # min over (j, j-1, j-2): 1, 1, 0
    np.testing.assert_allclose(G, [0.5, 0.5, 1.0], atol=1e-15)
    assert (j, g) == (0, 0.5)  # the first of equal ones


def test_the_search_step_equals_its_plain_twin(cmu_retimed):
    """Over 200 frames of a real take against its recording: the same row (to rounding) and
    the same best end at every frame."""
    _, I, _ = cmu_retimed
    Iq = np.ascontiguousarray(I.quats)
    G, Gp = np.zeros(I.n_frames), np.zeros(I.n_frames)
    for n in range(0, 200):
        q = np.ascontiguousarray(I.quats[(7 * n) % I.n_frames])
        j, g = _search(q, Iq, G, 0.99)
        Gp, jp = plain.relocate_step(q, Iq, Gp, 0.99)
        assert j == jp and g == G[j]
        np.testing.assert_allclose(G, Gp, rtol=1e-12, atol=1e-12)


def test_on_the_same_motion_it_never_jumps(cmu_retimed):
    """The recording against itself: the inner map, no jump (the global path is never half
    as cheap as a perfect inner one)."""
    _, I, _ = cmu_retimed
    inner = resolve("Mc w40")
    M0, _ = inner.run(I, I)
    aligner = resolve("Mc w40 (relocate)").make(I)
    assert isinstance(aligner, Relocating) and aligner.name == "Mc w40 (relocate)"
    M, _ = run_online(aligner, I)
    np.testing.assert_array_equal(M, M0)
    assert aligner.jumps == []
    M2, _ = run_online(aligner, I)  # reset: a fresh inner aligner
    np.testing.assert_array_equal(M2, M0)


@pytest.fixture(scope="module")
def real_pair(cmu_retimed):
    """CMU 18_01 and its take retimed by t^1.3, with OPW's positions."""
    path, _, (warp, _) = cmu_retimed
    return tuple(MotionFeatures.from_motion(load_motion(p), position_joints=OPW_JOINTS)
                 for p in (path, warp))  # fmt: skip


ONLINE = ["OE-DTW", "Ma", "Mb w40", "Mc w40 + Type V", "Mc auto", "OPW", "OPW adaptive", "OLTW",
          "Mc w40 (derivative)"]  # fmt: skip


@pytest.mark.parametrize("name", ONLINE)
def test_every_online_method_relocates(name, real_pair):
    """Each online method, wrapped, maps every frame of a real pair into the input."""
    I, T = real_pair
    relocating = with_option(name, "relocate")
    M, seconds = align(relocating, I, T)
    assert M.shape == (T.n_frames,) and M.min() >= 0 and M.max() < I.n_frames
    assert resolve(relocating).relocate and not resolve(name).relocate


def test_names_and_refusals():
    assert with_option("Mc w40 + Type V", "relocate") == "Mc w40 (relocate) + Type V"
    assert with_option("Mc w40 (literal window)", "relocate") == "Mc w40 (literal window, relocate)"
    a = resolve("Mc w40 (literal window, relocate) + Type V")
    assert (a.relocate, a.typev, a.options) == (True, True, {"window": "literal"})
    with pytest.raises(AlignmentError, match="offline; option 'relocate'"):
        resolve("DTW (relocate)")
    with pytest.raises(AlignmentError, match="given twice"):
        resolve("Mc w40 (relocate, relocate)")
    I, _, _ = synthetic_pair(n_frames=100, seed=1)
    J = input_from(I, 30)
    assert J.n_frames == 70 and np.array_equal(J.quats[0], I.quats[30])
    assert registry.RELOCATE == "relocate"


def test_the_command_line_relocates(cmu_retimed, tmp_path, capsys):
    path, _, (warp, _) = cmu_retimed
    out = tmp_path / "m.csv"
    assert cli.main(["align", str(path), str(warp), "-m", "c", "-w", "40", "--relocate",
                     "--out", str(out)]) == 0  # fmt: skip
    assert "with Mc w40 (relocate)" in capsys.readouterr().out
    assert cli.main(["align", str(path), str(warp), "-m", "dtw", "--relocate",
                     "--out", str(out)]) == 2  # fmt: skip
    assert "--relocate: 'dtw' is offline" in capsys.readouterr().err


@pytest.fixture(scope="module")
def walks(data_path):
    """Fig. 8's pair (the authors' Walk_01 -> Walk_02, 120 Hz) and offline DTW's map."""
    I, T = (MotionFeatures.from_motion(load_motion(data_path(
        f"mocap_single_person_actions/MoCapData/Walk_0{k}.fbx"))) for k in (1, 2))  # fmt: skip
    return I, T, dtw_pair(I, T).map


def test_a_restart_is_found_again_and_the_unedited_take_left_alone(walks):
    """The live take restarted from the top (Q7's edit): Mc w40 relocating jumps back and is
    within 300 ms of the true map on more of the take, sooner; on the unedited take it gives
    Mc w40's map exactly."""
    I, T, P = walks
    E, idx, at = edit_target(T, "restart")
    truth = true_map(P, idx)
    M0, _ = align("Mc w40", I, E)
    aligner = resolve("Mc w40 (relocate)").make(I)
    M1, _ = run_online(aligner, E)
    assert any(after < before for n, before, after in aligner.jumps if n >= at)  # back
    assert np.any(np.diff(M1) < 0)  # the map is not monotone
    assert within_ms(M1, truth, I.fps)[300] > within_ms(M0, truth, I.fps)[300] + 0.2
    assert recovery_s(M1, truth, I.fps, E.fps, at) < recovery_s(M0, truth, I.fps, E.fps, at)
    np.testing.assert_array_equal(align("Mc w40 (relocate)", I, T)[0], align("Mc w40", I, T)[0])


def test_fpdtw_live_scores_its_map_in_ms(cmu_retimed, capsys):
    """``fpdtw live`` prints the share of frames within each tolerance of offline DTW's map,
    the numbers of fpdtw.paper.edits.within_ms."""
    path, FI, (warp, _) = cmu_retimed
    assert cli.main(["live", str(path), str(warp), "-m", "c", "-w", "40", "--fast",
                     "--relocate"]) == 0  # fmt: skip
    out = capsys.readouterr().out.splitlines()
    k = out.index(next(x for x in out if x.startswith("target frames within")))
    assert out[k + 1].split() == ["frames", "50", "ms", "100", "ms", "300", "ms", "500", "ms",
                                  "1000", "ms", "2000", "ms", "lost"]  # fmt: skip
    FT = MotionFeatures.from_motion(load_motion(warp))
    M, _ = align("Mc w40 (relocate)", FI, FT)
    P = dtw_pair(FI, FT).map
    want = within_ms(M, P, FI.fps)
    assert out[k + 2].split()[3] == f"{np.mean(np.abs(M - P)):.1f}"  # eq. 3, frames
    assert out[k + 2].split()[4:] == [f"{want[t]:.1%}" for t in (50, 100, 300, 500, 1000, 2000)
                                      ] + [f"{want['lost']:.1%}"]  # fmt: skip


def test_the_server_passes_jumps_on(data_path, walks, tmp_path):
    """Fig. 8's live take restarted from the top, streamed as BVH lines through a serve
    session of Mc w40 (relocate): every answer is the offline run's, the jump back included."""
    I, _, _ = walks
    T = load_motion(data_path("mocap_single_person_actions/MoCapData/Walk_02.fbx"))
    _, idx, _ = edit_target(MotionFeatures.from_motion(T), "restart")
    edited = T.replace(euler=T.euler[idx], root_translation=T.root_translation[idx], quats=None,
                       name="Walk_02+restart")  # fmt: skip
    edited = read_bvh(write_bvh(edited, tmp_path / "restart.bvh"))  # as streamed: BVH text
    M, _ = align("Mc w40 (relocate)", I, MotionFeatures.from_motion(edited))
    session = Session(I, resolve("Mc w40 (relocate)").make, record=True)
    header, lines = bvh_lines(edited)
    for line in header:
        session.feed(f"{line}\n".encode(), 0.0)
    for k, line in enumerate(lines):
        session.feed(f"{line}\n".encode(), time.perf_counter(), when=k / edited.fps)
    got = session_map(session)
    assert np.any(np.diff(got) < 0)
    np.testing.assert_array_equal(got, M)
