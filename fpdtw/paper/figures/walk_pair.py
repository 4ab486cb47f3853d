"""Fig. 8: one walk pair aligned by DTW and the FP-DTW methods, and the pair itself.

The paper's pair is its unidentified "sample 3239"; we use the authors' ``Walk_01 ->
Walk_02``, chosen in 578ff6e (2026-11-21) before any alignment figure or claims table was
committed (docs/history.md); the same pair draws Figs. 1, 2 and 4.
"""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np

from fpdtw.metrics import deviation, similarity
from fpdtw.motion.features import MotionFeatures
from fpdtw.paper.catalog import load, motion_records
from fpdtw.paper.figures.plotting import image, new_axes, plot_skeleton
from fpdtw.paper.numbers import DEVIATION_BENCHMARK_FRAMES, FIG8_DEVIATIONS, WALK_GAIT_HZ
from fpdtw.period import dominant_period
from fpdtw.registry import align

#: (dataset, path) of the input and the target motion of the walk pair.
WALK_PAIR = (("authors_fbx", "MoCapData/Walk_01.fbx"), ("authors_fbx", "MoCapData/Walk_02.fbx"))
#: Seconds kept of each motion in smoke runs.
SMOKE_SECONDS = 2.0
#: The algorithms of the paper's Fig. 8, unconstrained.
FIG8_ALGORITHMS = ("DTW", "Mb w80", "Mc w20", "Mc w40", "Mc w80")
#: Method C's literal window on the same pair (notebook 15; the claims table's second column).
FIG8_LITERAL = ("Mc w20 (literal window)", "Mc w40 (literal window)", "Mc w80 (literal window)")
#: One colour per algorithm, shared by every panel.
ALGORITHM_COLORS = {
    "DTW": "black", "UTW": "tab:gray", "Ma": "tab:brown", "Mb w80": "tab:blue",
    "Mc w20": "tab:orange", "Mc w40": "tab:green", "Mc w80": "tab:red",
}  # fmt: skip
#: The rule of each statement of :func:`fig8_statements`, in one line (the table's note).
FIG8_STATEMENT_RULES = {
    "Mc w20 fails": "Mc w20's deviation from DTW (eq. 3) above the 18-frame benchmark",
    "Mc w20 sticks early": "Mc w20 holds one input frame (not the last) for at least one "
    "target gait cycle, in a hold starting in the first third of the target",
    "Mc w80 skips a walk cycle": "at some target frame Mc w80's map is ahead of DTW's by at "
    "least one input gait cycle (input frames)",
    "Mb w80 stays close to DTW": "Mb w80's deviation from DTW (eq. 3) below 18 frames",
}
#: Side elevation of the authors' FBX rig: y is up and the walk runs along z.
FBX_SIDE_VIEW = (2, 1)


def load_walk_pair(smoke: bool = False, seconds: float = SMOKE_SECONDS, pair=WALK_PAIR):
    """The walk pair's motions (or ``pair``'s, ``(dataset, path)``), input first (120 Hz);
    cropped to ``seconds`` in smoke runs.

    Paper: FP-DTW Fig. 8 (a walk pair; ours is the authors' Walk_01 -> Walk_02).
    Notebook: 02_fig1_oedtw.ipynb, 10_fig8_walk_pair.ipynb
    """
    motions = [load(ds, path) for ds, path in pair]
    if smoke:
        motions = [m.crop(0.0, seconds) for m in motions]
    return motions[0], motions[1]


def walk_pair_features(smoke: bool = False, seconds: float = SMOKE_SECONDS, pair=WALK_PAIR):
    """The walk pair (or ``pair``) as :class:`~fpdtw.motion.features.MotionFeatures` ``(I, T)``."""
    mI, mT = load_walk_pair(smoke, seconds, pair)
    return MotionFeatures.from_motion(mI), MotionFeatures.from_motion(mT)


def align_all(I: MotionFeatures, T: MotionFeatures, names) -> dict:
    """Map of each algorithm of ``names`` over one pair (:func:`fpdtw.registry.align`).

    Paper: FP-DTW Fig. 8.
    Notebook: 10_fig8_walk_pair.ipynb
    """
    return {name: align(name, I, T)[0] for name in names}


def pair_scores(I: MotionFeatures, T: MotionFeatures, maps: dict):
    """Per map: ``algorithm``, ``deviation`` from DTW's, ``paper_deviation``, ``similarity``.

    Paper: FP-DTW eqs. 2 and 3, Section 5 (Fig. 8 deviations 8, 177, 62, 6 frames).
    Notebook: 10_fig8_walk_pair.ipynb
    """
    ref = maps["DTW"]
    return [
        dict(algorithm=name, deviation=deviation(ref, M), paper_deviation=FIG8_DEVIATIONS.get(name),
             similarity=similarity(I.quats, T.quats, M))
        for name, M in maps.items()
    ]  # fmt: skip


def pose_frames(n_frames: int, k: int = 5) -> np.ndarray:
    """``k`` evenly spaced target frames from the first to the last, int64 (k,)."""
    return np.unique(np.round(np.linspace(0, n_frames - 1, k)).astype(np.int64))


def plot_paths_over_cost(D, maps: dict, ax=None, names=("", "")):
    """Fig. 8 (a): each map over DTW's accumulated cost ``D`` (m + 1, n + 1).

    Paper: FP-DTW Fig. 8 (paths over the accumulated cost heat map).
    Notebook: 10_fig8_walk_pair.ipynb
    """
    fig, ax = new_axes(ax, figsize=(5.5, 5))
    D = np.asarray(D, dtype=float)
    image(ax, D, "accumulated cost D (DTW)")
    q = np.arange(D.shape[1])
    for name, M in maps.items():
        lw = 2.2 if name == "DTW" else 1.4
        ax.plot(q, np.asarray(M), color=ALGORITHM_COLORS.get(name), lw=lw, label=name)
    ax.set(xlim=(-0.5, D.shape[1] - 0.5), ylim=(-0.5, D.shape[0] - 0.5))
    ax.set(xlabel=f"target frame {names[1]}".strip(), ylabel=f"input frame {names[0]}".strip())
    ax.legend(loc="upper left", fontsize=8, framealpha=0.9)
    return fig, ax


def plot_joint_curves(I: MotionFeatures, T: MotionFeatures, maps: dict, joint=1):
    """Fig. 8 (b): a joint's Euler angles (degrees; joint 1 the right hip) over target
    frames, the target's on top, then the input's warped by each map.

    Paper: FP-DTW Fig. 8 (right-hip motion curves).
    Notebook: 10_fig8_walk_pair.ipynb
    """
    rows = len(maps) + 1
    fig, axes = plt.subplots(rows, 1, figsize=(7, 1.25 * rows + 0.6), sharex=True)
    axes = list(np.ravel(axes))
    series = [(f"target {T.name}".strip(), T.euler[:, joint])]
    series += [
        (f"input aligned by {name}", I.euler[np.asarray(M), joint]) for name, M in maps.items()
    ]
    q = np.arange(T.n_frames)
    lo = min(s[1].min() for s in series)
    hi = max(s[1].max() for s in series)
    pad = 0.05 * (hi - lo + 1e-9)
    for ax, (label, E), key in zip(axes, series, [None] + list(maps)):
        colour = ALGORITHM_COLORS.get(key, "black")
        for a, style in enumerate(("-", "--", ":")):
            ax.plot(q, E[:, a], style, color=colour, lw=1.1, label="xyz"[a])
        ax.set_ylim(lo - pad, hi + pad)
        ax.set_title(label, fontsize=8, loc="left", pad=2)
        ax.tick_params(labelsize=7)
    axes[0].legend(loc="lower right", bbox_to_anchor=(1.0, 1.0), fontsize=7, ncol=4,
                   title="right hip Euler angle", title_fontsize=7, frameon=False)  # fmt: skip
    axes[-1].set_xlabel("target frame")
    fig.supylabel("degrees", fontsize=8)
    return fig, axes


def plot_aligned_poses(mI, mT, maps: dict, frames):
    """Fig. 8 (c): poses at target ``frames`` (columns), the target's on top, then the
    input's at each map's frame (rows), in side elevation, root-centred horizontally.

    Paper: FP-DTW Fig. 8 (character poses, side elevation).
    Notebook: 10_fig8_walk_pair.ipynb
    """
    frames = [int(f) for f in frames]
    rows = len(maps) + 1
    fig, axes = plt.subplots(rows, len(frames), figsize=(1.5 * len(frames) + 1, 1.9 * rows))
    axes = np.asarray(axes).reshape(rows, len(frames))
    PT, _ = mT.forward_kinematics()
    PI, _ = mI.forward_kinematics()
    h, v = FBX_SIDE_VIEW
    flat = np.ones(3)
    flat[v] = 0.0  # subtract the root's horizontal coordinates only

    def centred(P, f):
        return P[f] - P[f, 0] * flat

    entries = [("target", None, [centred(PT, f) for f in frames])]
    for name, M in maps.items():
        entries.append((name, name, [centred(PI, int(np.asarray(M)[f])) for f in frames]))
    stack = np.concatenate([p for _, _, pts in entries for p in pts])
    lim_h = np.abs(stack[:, h]).max() * 1.05
    lim_v = (stack[:, v].min() - 5, stack[:, v].max() + 5)
    for r, (label, key, pts) in enumerate(entries):
        for c, f in enumerate(frames):
            ax = axes[r, c]
            skel = mT.skeleton if key is None else mI.skeleton
            colour = ALGORITHM_COLORS.get(key, "black")
            plot_skeleton(pts[c], skel.parents, ax=ax, view=FBX_SIDE_VIEW, color=colour, lw=1.2)
            ax.set(xlim=(-lim_h, lim_h), ylim=lim_v, xticks=[], yticks=[])
            for sp in ax.spines.values():
                sp.set_visible(False)
            if key is None:
                ax.set_title(f"T {f}", fontsize=8)
            else:
                ax.set_title(f"I {int(np.asarray(maps[key])[f])}", fontsize=7, pad=1)
            if c == 0:
                ax.set_ylabel(label, fontsize=8)
    return fig, axes


def walk_pairs() -> list:
    """Every ordered pair (input, target) of distinct takes of the authors' ``Walk``
    movement (six pairs, ``Walk_01 -> Walk_02`` first).

    Paper: FP-DTW Section 5, Fig. 8.
    """
    takes = [
        r for r in motion_records(("authors_fbx",), available_only=True) if r.movement == "Walk"
    ]
    return [(a, b) for a in takes for b in takes if a.path != b.path]


def gait_cycle(F: MotionFeatures) -> tuple[int, str]:
    """One gait cycle of a walk in its own frames, and its source: ``"autocorrelation"``
    (:func:`fpdtw.period.dominant_period`, committed in cbb3316 for Q1) or, where it finds
    none, ``"paper's gait"`` (the middle of 0.82-0.9 Hz).

    Paper: FP-DTW Section 4 (walking gait 0.82-0.9 Hz).
    """
    P = dominant_period(F.quats, F.fps)
    if P is not None:
        return int(P), "autocorrelation"
    return int(round(F.fps / float(np.mean(WALK_GAIT_HZ)))), "paper's gait"


def walk_pair_cases(smoke: bool = False, seconds: float = SMOKE_SECONDS) -> list:
    """Every walk pair aligned by the algorithms :func:`fig8_statements` judges, with
    each motion's gait cycle.

    Notebook: 10_fig8_walk_pair.ipynb
    """
    cases = []
    for a, b in walk_pairs():
        I, T = walk_pair_features(smoke, seconds, [(r.dataset, r.path) for r in (a, b)])
        (ci, si), (ct, st) = gait_cycle(I), gait_cycle(T)
        maps = align_all(I, T, ("DTW", "Mb w80", "Mc w20", "Mc w80"))
        cases.append(
            dict(pair=f"{a.name} -> {b.name}", maps=maps, input_cycle=ci, target_cycle=ct,
                 cycle_source=f"{si}, {st}", m=I.n_frames - 1, n=T.n_frames - 1)
        )  # fmt: skip
    return cases


def _longest_early_hold(M, m: int, before: float) -> int:
    """Length of the longest hold on an input frame other than m starting before target
    frame ``before``; 0 if none."""
    M = np.asarray(M)
    starts = np.flatnonzero(np.diff(M, prepend=M[0] - 1) != 0)
    lengths = np.where((starts < before) & (M[starts] != m), np.diff(starts, append=M.size), 0)
    return int(lengths.max())


def fig8_statements(cases) -> list[dict]:
    """The paper's statements about its Fig. 8 walk pair, measured on each of our pairs.

    Section 5: "*Mc w80* skips a walk cycle, while the *Mc w20* complete fails, sticking on
    an input frame early in the alignment", and only *Mb w80* and *Mc w40* below 18 frames.
    Each is measured against DTW's map by its rule in :data:`FIG8_STATEMENT_RULES`, fixed
    from those words before any walk pair was aligned ("early": starting before ``n / 3``).

    Parameters
    ----------
    cases : iterable of dict
        :func:`walk_pair_cases`; ``m`` (the input's last frame) defaults to the largest
        frame any map reaches.

    Returns
    -------
    rows : list of dict
        Per pair and statement: ``pair``, ``statement``, ``value``, ``threshold``, ``unit``,
        ``holds``.

    Paper: FP-DTW Section 5 (the text on Fig. 8) and eq. 3.
    Notebook: 10_fig8_walk_pair.ipynb
    """
    benchmark = DEVIATION_BENCHMARK_FRAMES
    rows = []
    for c in cases:
        maps = {k: np.asarray(v, dtype=np.int64) for k, v in c["maps"].items()}
        P = maps["DTW"]
        m = int(c.get("m", max(int(v.max()) for v in maps.values())))
        n = P.size - 1
        d20 = deviation(P, maps["Mc w20"])
        hold = _longest_early_hold(maps["Mc w20"], m, n / 3.0)
        lead = int(np.max(maps["Mc w80"] - P))
        db80 = deviation(P, maps["Mb w80"])
        ci, ct = int(c["input_cycle"]), int(c["target_cycle"])
        for statement, value, threshold, unit, holds in (
            ("Mc w20 fails", d20, benchmark, "frames (eq. 3) > threshold", d20 > benchmark),
            ("Mc w20 sticks early", hold, ct, "target frames held >= threshold", hold >= ct),
            ("Mc w80 skips a walk cycle", lead, ci, "input frames ahead >= threshold",
             lead >= ci),
            ("Mb w80 stays close to DTW", db80, benchmark, "frames (eq. 3) < threshold",
             db80 < benchmark),
        ):  # fmt: skip
            rows.append(dict(pair=c["pair"], statement=statement, value=float(value),
                             threshold=float(threshold), unit=unit, holds=bool(holds)))  # fmt: skip
    return rows


def statement_counts(rows) -> dict:
    """Per statement of :func:`fig8_statements`: ``{"holds": k, "pairs": n}``, in row order.

    Notebook: 10_fig8_walk_pair.ipynb
    """
    out = {}
    for r in rows:
        c = out.setdefault(r["statement"], {"holds": 0, "pairs": 0})
        c["holds"] += int(r["holds"])
        c["pairs"] += 1
    return out
