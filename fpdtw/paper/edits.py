"""Targets edited as performers edit a passage on stage, and followers' scores in ms (Q7).

Open question Q7 (issue 34): an online method that only looks a window ahead cannot find a
performer who skips a passage, repeats one or starts again. To measure it, the TARGET (the
live take) is edited and the input left unchanged, as Q6 inserts a pause
(:mod:`fpdtw.paper.pause`). Each edited frame IS a frame of the unedited target
(:func:`source_frames`), so its true input frame is the unedited target's reference map at
that frame (:func:`true_map`; the reference is offline DTW's map, as in the papers).

The rule, written on 2026-11-26 before any aligner was run on an edited target (and so before
any result under it was seen): a target of ``F`` frames at ``fps`` is edited at frame ``a``,
drawn uniformly from the middle 60 % of the target, ``[ceil(0.2 (F - 1)), floor(0.8 (F -
1))]``, by a generator seeded with :data:`EDIT_SEED`, the edit's name and the target's name
(a take gets the same edit in every pair). With ``L = round(s * fps)``:

* ``cut s`` (s = 0.5, 1, 2): frames ``a .. a + L - 1`` are left out (``a`` drawn so that at
  least one frame follows the cut);
* ``repeat``: frames ``a - L .. a - 1`` (s = 1; from frame 0 if ``a < L``) are played again
  after frame ``a - 1``, before frame ``a``;
* ``restart``: after frame ``a - 1`` the take starts again from frame 0 and plays to its end.

Followers are scored as pymatchmaker scores score followers: the share of target frames whose
input frame is within 50, 100, 300, 500, 1000 and 2000 ms of the true one
(:func:`within_ms`), an error over 2 s counted as lost; and the time an aligner takes to come
back after the edit (:func:`recovery_s`).

Q7's decision, written on 2026-11-26 before any method had been run on the open run's
edited targets. Its methods are Q6's nine online methods, each without and with
``(relocate)`` (:data:`fpdtw.paper.runner.grid.EDIT_METHODS`); a method's frames within
300 ms are counted over every target frame of a pair, summed over the nine methods, and the
share pooled over pairs (with vs without relocating, paired by pair), with the movement
cluster bootstrap of every other claim. A pair whose target is too short for an edit
(:func:`fits`) has no result under it and is left out of that edit's part:

* one part per edit (five): relocating raises the share of target frames within 300 ms of
  the true map (the difference's interval above 0);
* one part on the unedited pairs: relocating does not lower that share (the difference's
  interval not below 0; straddling 0 is not a pass).

Shown beside them and not tested: every method's shares at each tolerance, its lost share and
its median recovery time, per edit, with and without relocating. 300 ms is the recovery
tolerance above. What had been seen when this was written: one pair (``Walk_01`` against
``Walk_02``) through ``python -m fpdtw.paper.edits``, where relocating raised the restart's
share within 300 ms from about 44 % to about 80 % and left the unedited pair unchanged.

Paper: neither (beyond the papers, Q7).
"""

from __future__ import annotations

import argparse
import hashlib
import math
from dataclasses import replace

import numpy as np

from fpdtw.dtw import dtw_pair
from fpdtw.errors import AlignmentError
from fpdtw.motion.features import MotionFeatures
from fpdtw.motion.joints import OPW_JOINTS
from fpdtw.online.base import run_online
from fpdtw.paper.catalog import load
from fpdtw.registry import resolve, with_option

#: Seed of every edit (with the edit's and the target's names).
EDIT_SEED = 2026
#: The edits: name -> (kind, seconds).
EDITS = {"cut 0.5 s": ("cut", 0.5), "cut 1 s": ("cut", 1.0), "cut 2 s": ("cut", 2.0),
         "repeat 1 s": ("repeat", 1.0), "restart": ("restart", 0.0)}  # fmt: skip
#: The edit point lies inside this fraction of the target (the middle 60 %).
EDIT_SPAN = (0.2, 0.8)
#: Tolerances of :func:`within_ms` (ms) and the error beyond which a frame is lost.
MS_TOLERANCES = (50, 100, 300, 500, 1000, 2000)
LOST_MS = 2000.0
#: :func:`recovery_s`: back when the error stays within this many ms for this many seconds.
RECOVERED_MS, RECOVERED_S = 300.0, 1.0


def edit_seed(edit: str, name: str) -> int:
    """The generator seed of an edit of a target: sha256 of ``"<EDIT_SEED>/<edit>/<name>"``."""
    key = f"{EDIT_SEED}/{edit}/{name}".encode()
    return int.from_bytes(hashlib.sha256(key).digest()[:8], "little")


def edit_suffix(edit: str) -> str:
    """The suffix of a name run on targets with ``edit`` (``"cut 0.5 s"`` -> ``"@cut0.5s"``;
    :mod:`fpdtw.paper.runner.grid`)."""
    return "@" + edit.replace(" ", "")


def edit_span(n_frames: int, fps: float, edit: str) -> tuple[int, int, int]:
    """The first and last frame where ``edit`` may start in a target of ``n_frames`` at
    ``fps`` (the module's rule; ``lo > hi`` when the target is too short for it) and the
    edit's length ``L`` in frames (0 for a restart)."""
    if edit not in EDITS:
        raise AlignmentError(f"unknown edit {edit!r}; one of {', '.join(EDITS)}")
    kind, seconds = EDITS[edit]
    L = max(1, int(round(seconds * fps))) if kind != "restart" else 0
    last = n_frames - 1
    lo = max(int(math.ceil(EDIT_SPAN[0] * last)), 1)
    hi = int(math.floor(EDIT_SPAN[1] * last)) - (L if kind == "cut" else 0)
    return (lo, hi, L) if n_frames >= 3 and fps > 0 else (1, 0, L)


def fits(n_frames: int, fps: float, edit: str) -> bool:
    """Whether a target of ``n_frames`` at ``fps`` is long enough for ``edit`` (a pair whose
    target is not has no result under it: the open run's shortest clips are 0.7 s)."""
    lo, hi, _ = edit_span(n_frames, fps, edit)
    return lo <= hi


def source_frames(n_frames: int, fps: float, edit: str, seed: int) -> tuple[np.ndarray, int]:
    """The frame of the unedited target each frame of the edited one is, and where the edit
    starts in the edited target (the module's rule).

    Returns
    -------
    idx : ndarray of int64, shape (F',)
    at : int
        The first edited frame whose source does not follow its predecessor's.
    """
    lo, hi, L = edit_span(n_frames, fps, edit)
    if hi < lo:
        raise AlignmentError(f"a target of {n_frames} frames at {fps} Hz is too short for {edit!r}")
    kind = EDITS[edit][0]
    a = int(np.random.default_rng(seed).integers(lo, hi + 1))
    F = np.arange(n_frames)
    if kind == "cut":
        idx = np.concatenate([F[:a], F[a + L :]])
    elif kind == "repeat":
        idx = np.concatenate([F[:a], F[max(0, a - L) : a], F[a:]])
    else:
        idx = np.concatenate([F[:a], F])
    return idx.astype(np.int64), a


def edit_target(T, edit: str, seed: int | None = None):
    """The target ``T`` (MotionFeatures) edited: ``(edited, idx, at)`` (:func:`source_frames`
    with ``seed``, default :func:`edit_seed` of the edit and ``T.name``); the edited target
    is named ``T.name + "+" + edit``."""
    idx, at = source_frames(T.n_frames, T.fps, edit, edit_seed(edit, T.name) if seed is None
                            else seed)  # fmt: skip
    take = lambda x: None if x is None else np.ascontiguousarray(np.asarray(x)[idx])  # noqa: E731
    edited = replace(T, quats=take(T.quats), euler=take(T.euler), positions=take(T.positions),
                     name=f"{T.name}+{edit}")  # fmt: skip
    return edited, idx, at


def true_map(P, idx) -> np.ndarray:
    """The true map of an edited target: the unedited target's reference map ``P`` (input
    frame per target frame) at each edited frame's source, ``P[idx]``."""
    return np.asarray(P, dtype=np.int64)[np.asarray(idx, dtype=np.int64)]


def errors_ms(M, P, fps: float) -> np.ndarray:
    """``|M - P|`` in ms of the input's time (``fps``: the input's rate), per target frame."""
    M, P = np.asarray(M, dtype=float), np.asarray(P, dtype=float)
    if M.shape != P.shape:
        raise ValueError(f"maps of {M.shape} and {P.shape} frames")
    return np.abs(M - P) * (1000.0 / fps)


def within_ms(M, P, fps: float, tolerances=MS_TOLERANCES) -> dict:
    """The share of target frames whose input frame is within each tolerance (ms) of the
    truth, and ``"lost"``: the share more than :data:`LOST_MS` away.

    Parameters
    ----------
    M, P : array_like of int, shape (n,)
        The map scored and the true map (input frame per target frame).
    fps : float
        The input's frame rate.

    Returns
    -------
    dict
        ``{tolerance_ms: share, ..., "lost": share}``, shares in [0, 1].
    """
    e = errors_ms(M, P, fps)
    out = {int(t): float(np.mean(e <= t)) for t in tolerances}
    out["lost"] = float(np.mean(e > LOST_MS))
    return out


def ms_rows(maps: dict, P, fps: float) -> list:
    """Each named map against the truth ``P``: ``method``, ``deviation_frames`` (FP-DTW eq.
    3, the mean ``|M - P|``), ``within_<t>ms`` for each of :data:`MS_TOLERANCES` and ``lost``
    (shares of :func:`within_ms`).

    Notebook: 20_align_a_live_performance.ipynb
    """
    rows = []
    for name, M in maps.items():
        s = within_ms(M, P, fps)
        dev = float(np.mean(np.abs(np.asarray(M, float) - np.asarray(P, float))))
        shares = {f"within_{t}ms": s[t] for t in MS_TOLERANCES}
        rows.append(dict(method=name, deviation_frames=dev, **shares, lost=s["lost"]))
    return rows


def ms_table(maps: dict, P, fps: float) -> str:
    """:func:`ms_rows` as text lines, shares in %.

    Notebook: 20_align_a_live_performance.ipynb
    """
    head = f"{'':<20}{'frames':>8}" + "".join(f"{f'{t} ms':>9}" for t in MS_TOLERANCES)
    lines = [head + f"{'lost':>9}"]
    for r in ms_rows(maps, P, fps):
        cells = [r[f"within_{t}ms"] for t in MS_TOLERANCES] + [r["lost"]]
        lines.append(f"{r['method']:<20}{r['deviation_frames']:>8.1f}"
                     + "".join(f"{c:>9.1%}" for c in cells))  # fmt: skip
    return "\n".join(lines)


def recovery_s(M, P, fps_input: float, fps_target: float, at: int) -> float:
    """Seconds from target frame ``at`` (the edit) until the map is back: the first frame
    from which its error stays within :data:`RECOVERED_MS` for :data:`RECOVERED_S` (or to the
    end of the take, if shorter); ``inf`` when it never is."""
    ok = errors_ms(M, P, fps_input)[at:] <= RECOVERED_MS
    need = max(1, int(round(RECOVERED_S * fps_target)))
    n = ok.size
    k = np.arange(n)
    # first bad frame at or after each k (n: none), so k starts a run of good frames to it
    bad = np.minimum.accumulate(np.where(ok, n, k)[::-1])[::-1]
    back = np.flatnonzero(ok & ((bad - k >= need) | (bad == n)))
    return float(back[0] / fps_target) if back.size else math.inf


#: The methods :func:`edit_rows` scores by default, each without and with ``(relocate)``.
EDIT_METHODS = ("Mc w40", "OLTW", "OPW")


def edit_rows(I, T, names=EDIT_METHODS, edits=tuple(EDITS)) -> list:
    """Every named online method without and with ``(relocate)`` on the target ``T`` as it
    is and under each edit, scored against the true map (the unedited pair's DTW map at each
    edited frame's source).

    Parameters
    ----------
    I, T : MotionFeatures
        Input and target (with OPW's positions if OPW is named).

    Returns
    -------
    rows : list of dict
        ``edit`` ("none" first), ``name``, ``at`` (the edit's frame), the shares of
        :func:`within_ms` and ``recovery_s`` (None without an edit), ``jumps``.
    """

    P = dtw_pair(I, T).map
    rows = []
    for edit in ("none", *edits):
        if edit == "none":
            E, idx, at = T, np.arange(T.n_frames), 0
        else:
            E, idx, at = edit_target(T, edit)
        truth = true_map(P, idx)
        for name in (n for base in names for n in (base, with_option(base, "relocate"))):
            aligner = resolve(name).make(I)
            M, _ = run_online(aligner, E)
            rec = None if edit == "none" else recovery_s(M, truth, I.fps, E.fps, at)
            row = dict(edit=edit, name=name, at=at, recovery_s=rec,
                       jumps=len(getattr(aligner, "jumps", ())))  # fmt: skip
            row.update(within_ms(M, truth, I.fps))
            rows.append(row)
    return rows


def open_run_scores(results, name: str, edit: str | None, truth: str = "DTW") -> list:
    """Per pair of a run, one method's scores against the true map: ``None`` for a pair
    without a result (a target too short for the edit), else a dict of ``within`` (frames
    within each of :data:`MS_TOLERANCES`, ms -> count), ``lost``, ``frames`` and ``recovery_s``
    (None without an edit). ``name`` is the method's name without a suffix; the run holds it
    with the edit's suffix (:func:`edit_suffix`) and ``truth``, offline DTW on the unedited
    pairs."""
    suffix = "" if edit is None else edit_suffix(edit)
    got, ref = results.get(name + suffix), results.get(truth)
    fps = results.fps(truth)
    out = []
    for k, pair in enumerate(results.pairs):
        M, P = np.asarray(got.map(k), np.int64), np.asarray(ref.map(k), np.int64)
        if not M.size:
            out.append(None)
            continue
        idx, at = np.arange(P.size), 0
        if edit is not None:
            idx, at = source_frames(P.size, fps, edit, edit_seed(edit, pair["target"]))
        if idx.size != M.size:
            raise AlignmentError(f"{name + suffix} on pair {pair['id']}: a map of {M.size} "
                                 f"frames for an edited target of {idx.size}")  # fmt: skip
        truth_map = true_map(P, idx)
        e = errors_ms(M, truth_map, fps)
        out.append(dict(
            within={t: int(np.sum(e <= t)) for t in MS_TOLERANCES},
            lost=int(np.sum(e > LOST_MS)), frames=int(M.size),
            recovery_s=None if edit is None else recovery_s(M, truth_map, fps, fps, at),
        ))  # fmt: skip
    return out


def open_run_rows(results, names, edits=(None, *EDITS)) -> list:
    """:func:`open_run_scores` of each method under each edit (None: unedited), pooled over
    the pairs with a result (NaN shares without one): rows ``edit``, ``name``, ``pairs``, the
    share within each tolerance, ``lost``, the median recovery (s; inf when most never
    recover) and the share of pairs never recovered.

    Notebook: 16_open_questions.ipynb
    """
    rows = []
    for edit in edits:
        for name in names:
            got = [g for g in open_run_scores(results, name, edit) if g is not None]
            frames = sum(g["frames"] for g in got) or math.nan  # no pair: NaN shares
            row = dict(edit=edit or "none", name=name, pairs=len(got))
            row |= {t: sum(g["within"][t] for g in got) / frames for t in MS_TOLERANCES}
            row["lost"] = sum(g["lost"] for g in got) / frames
            rec = [g["recovery_s"] for g in got if g["recovery_s"] is not None]
            row["recovery_s"] = float(np.median(rec)) if rec else None
            row["never"] = float(np.mean(np.isinf(rec))) if rec else None
            rows.append(row)
    return rows


def format_edit_rows(rows) -> str:
    """:func:`edit_rows` or :func:`open_run_rows` as text lines: shares in %, recovery in s
    (inf: never), and the pairs, jumps and share never recovered where the rows have them.

    Notebook: 16_open_questions.ipynb
    """
    extra = [k for k in ("pairs", "jumps", "never") if k in rows[0]]
    head = (f"{'edit':<11}{'method':<30}" + "".join(f"{t:>6}" for t in MS_TOLERANCES)
            + f"{'lost':>6}{'back s':>8}" + "".join(f"{k:>7}" for k in extra))  # fmt: skip
    lines = [head]
    for r in rows:
        back = "" if r["recovery_s"] is None else f"{r['recovery_s']:.2f}"
        cells = {"pairs": f"{r.get('pairs')}", "jumps": f"{r.get('jumps')}",
                 "never": "" if r.get("never") is None else f"{100 * r['never']:.0f}%"}  # fmt: skip
        lines.append(f"{r['edit']:<11}{r['name']:<30}"
                     + "".join(f"{100 * r[t]:>6.1f}" for t in MS_TOLERANCES)
                     + f"{100 * r['lost']:>6.1f}{back:>8}"
                     + "".join(f"{cells[k]:>7}" for k in extra))  # fmt: skip
    return "\n".join(lines)


def main(argv=None) -> int:
    """``python -m fpdtw.paper.edits DATASET INPUT TARGET``: :func:`format_edit_rows` of a
    pair of the catalogue (e.g. ``authors_fbx MoCapData/Walk_01.fbx MoCapData/Walk_02.fbx``)."""

    ap = argparse.ArgumentParser(prog="python -m fpdtw.paper.edits", description=main.__doc__)
    ap.add_argument("dataset")
    ap.add_argument("input")
    ap.add_argument("target")
    args = ap.parse_args(argv)
    I, T = (MotionFeatures.from_motion(load(args.dataset, p), position_joints=OPW_JOINTS)
            for p in (args.input, args.target))  # fmt: skip
    print(f"{T.name} edited, aligned to {I.name}; shares of target frames within each "
          "tolerance (ms) of the true map, % (lost: beyond 2 s); back: seconds after the edit "
          "until within 300 ms for 1 s")  # fmt: skip
    print(format_edit_rows(edit_rows(I, T)))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
