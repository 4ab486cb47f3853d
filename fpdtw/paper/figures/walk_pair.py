"""Fig. 8: one walk pair aligned by DTW and the FP-DTW methods, and the pair itself.

The paper's Fig. 8 aligns two walks (its "sample 3239", not identified) with DTW, Mb w80,
Mc w20, Mc w40 and Mc w80, unconstrained, and shows (a) the paths over the heat map of
DTW's accumulated cost, (b) the right hip's motion curves, target on top and each aligned
input below, (c) poses in side elevation at a few target frames. We use the authors' own
walk pair ``Walk_01 -> Walk_02`` (input -> target), the paper's "walking" example type,
chosen in 578ff6e (2026-11-21) with the notebooks that draw these figures, before any
alignment figure or claims table was committed (docs/history.md); the same pair draws
Figs. 1, 2 and 4.

:func:`fig8_statements` tests the paper's three words about its walk pair (Section 5:
Mc w20 "complete[ly] fails", Mc w80 "skips a walk cycle", Mb w80 within the benchmark) on
every walk pair we have (:func:`walk_pairs`: the six ordered pairs of the authors' three
``Walk`` takes), each by a rule fixed in its docstring from the paper's words (written on
2026-11-24, before any walk pair was aligned by it).
"""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np

from fpdtw.metrics import deviation, similarity
from fpdtw.motion.features import MotionFeatures
from fpdtw.paper.catalog import load, motion_records
from fpdtw.paper.figures.plotting import new_axes, plot_skeleton
from fpdtw.paper.numbers import DEVIATION_BENCHMARK_FRAMES, FIG8_DEVIATIONS, WALK_GAIT_HZ
from fpdtw.period import dominant_period
from fpdtw.registry import align

#: (dataset, path) of the input and the target motion of the walk pair.
WALK_PAIR = (
    ("authors_fbx", "MoCapData/Walk_01.fbx"),
    ("authors_fbx", "MoCapData/Walk_02.fbx"),
)
#: Seconds kept of each motion in smoke runs.
SMOKE_SECONDS = 2.0
#: The algorithms of the paper's Fig. 8, unconstrained.
FIG8_ALGORITHMS = ("DTW", "Mb w80", "Mc w20", "Mc w40", "Mc w80")
#: Method C's literal window on the same pair (notebook 15; the claims table's second column).
FIG8_LITERAL = ("Mc w20 (literal window)", "Mc w40 (literal window)", "Mc w80 (literal window)")
#: One colour per algorithm, shared by every panel.
ALGORITHM_COLORS = {
    "DTW": "black",
    "UTW": "tab:gray",
    "Ma": "tab:brown",
    "Mb w80": "tab:blue",
    "Mc w20": "tab:orange",
    "Mc w40": "tab:green",
    "Mc w80": "tab:red",
}
#: The maps :func:`fig8_statements` reads: DTW's and the three algorithms it judges.
FIG8_STATEMENT_ALGORITHMS = ("DTW", "Mb w80", "Mc w20", "Mc w80")
#: The rule of each statement of :func:`fig8_statements`, in one line (the table's note).
FIG8_STATEMENT_RULES = {
    "Mc w20 fails": "Mc w20's deviation from DTW (eq. 3) above the 18-frame benchmark",
    "Mc w20 sticks early": "Mc w20 holds one input frame (not the last) for at least one "
    "target gait cycle, in a hold starting in the first third of the target",
    "Mc w80 skips a walk cycle": "at some target frame Mc w80's map is ahead of DTW's by at "
    "least one input gait cycle (input frames)",
    "Mb w80 stays close to DTW": "Mb w80's deviation from DTW (eq. 3) below 18 frames",
}
#: The movement of the authors' FBX dataset whose takes give the walk pairs.
WALK_MOVEMENT = ("authors_fbx", "Walk")
#: Side elevation of the authors' FBX rig: y is up and the walk runs along z, so the
#: side view plots z horizontally and y vertically.
FBX_SIDE_VIEW = (2, 1)


def load_walk_pair(smoke: bool = False, seconds: float = SMOKE_SECONDS):
    """Load the walk pair, input first; in smoke runs only its first ``seconds``.

    Parameters
    ----------
    smoke : bool
        Crop both motions to ``[0, seconds]`` (:meth:`fpdtw.motion.Motion.crop`).
    seconds : float

    Returns
    -------
    I, T : Motion
        Input ``Walk_01`` and target ``Walk_02`` (120 Hz).

    Paper: FP-DTW Fig. 8 (a walk pair; ours is the authors' Walk_01 -> Walk_02).
    Notebook: 02_fig1_oedtw.ipynb, 10_fig8_walk_pair.ipynb
    """
    motions = [load(ds, path) for ds, path in WALK_PAIR]
    if smoke:
        motions = [m.crop(0.0, seconds) for m in motions]
    return motions[0], motions[1]


def walk_pair_features(smoke: bool = False, seconds: float = SMOKE_SECONDS):
    """The walk pair as :class:`~fpdtw.motion.features.MotionFeatures` (the paper's 8 joints).

    Returns
    -------
    I, T : MotionFeatures
    """
    mI, mT = load_walk_pair(smoke, seconds)
    return MotionFeatures.from_motion(mI), MotionFeatures.from_motion(mT)


def align_all(I: MotionFeatures, T: MotionFeatures, names=FIG8_ALGORITHMS) -> dict:
    """Maps of every algorithm over one pair (:func:`fpdtw.registry.align`).

    Returns
    -------
    maps : dict of str to ndarray of int64, shape (n + 1,)
        In the order of ``names``.

    Paper: FP-DTW Fig. 8.
    Notebook: 10_fig8_walk_pair.ipynb
    """
    return {name: align(name, I, T)[0] for name in names}


def pair_scores(I: MotionFeatures, T: MotionFeatures, maps: dict, reference: str = "DTW"):
    """Deviation from DTW (eq. 3) and similarity (eq. 2) of each map, with the paper's.

    Parameters
    ----------
    I, T : MotionFeatures
    maps : dict of str to ndarray of int, shape (n + 1,)
        Must hold ``reference``.
    reference : str

    Returns
    -------
    rows : list of dict
        Keys ``algorithm, deviation, paper_deviation, similarity`` (paper_deviation is
        None where the paper gives none).

    Paper: FP-DTW eqs. 2 and 3, Section 5 (Fig. 8 deviations 8, 177, 62, 6 frames).
    Notebook: 10_fig8_walk_pair.ipynb
    """
    ref = maps[reference]
    rows = []
    for name, M in maps.items():
        rows.append(
            {
                "algorithm": name,
                "deviation": deviation(ref, M),
                "paper_deviation": FIG8_DEVIATIONS.get(name),
                "similarity": similarity(I.quats, T.quats, M),
            }
        )
    return rows


def pose_frames(n_frames: int, k: int = 5) -> np.ndarray:
    """``k`` evenly spaced target frames from the first to the last, int64 (k,)."""
    return np.unique(np.round(np.linspace(0, n_frames - 1, k)).astype(np.int64))


def plot_paths_over_cost(D, maps: dict, ax=None, colors=None, names=("", "")):
    """Panel (a): each algorithm's map over the heat map of DTW's accumulated cost.

    Parameters
    ----------
    D : ndarray of float, shape (m + 1, n + 1)
        Accumulated cost of DTW over the full cost matrix (rows input, columns target).
    maps : dict of str to ndarray of int, shape (n + 1,)
    ax : matplotlib Axes, optional
    colors : dict of str to colour, optional
    names : pair of str
        Input and target motion names for the axis labels.

    Returns
    -------
    fig, ax
        One line per map (``ax.lines`` in the order of ``maps``) and one image.

    Paper: FP-DTW Fig. 8 (paths over the accumulated cost heat map).
    Notebook: 10_fig8_walk_pair.ipynb
    """
    fig, ax = new_axes(ax, figsize=(5.5, 5))
    colors = {**ALGORITHM_COLORS, **(colors or {})}
    D = np.asarray(D, dtype=float)
    im = ax.imshow(D, origin="lower", aspect="auto", cmap="viridis", interpolation="nearest")
    fig.colorbar(im, ax=ax, label="accumulated cost D (DTW)", fraction=0.046, pad=0.04)
    q = np.arange(D.shape[1])
    for name, M in maps.items():
        lw = 2.2 if name == "DTW" else 1.4
        ax.plot(q, np.asarray(M), color=colors.get(name), lw=lw, label=name)
    ax.set_xlim(-0.5, D.shape[1] - 0.5)
    ax.set_ylim(-0.5, D.shape[0] - 0.5)
    ax.set_xlabel(f"target frame {names[1]}".strip())
    ax.set_ylabel(f"input frame {names[0]}".strip())
    ax.legend(loc="upper left", fontsize=8, framealpha=0.9)
    return fig, ax


def plot_joint_curves(
    I: MotionFeatures,
    T: MotionFeatures,
    maps: dict,
    joint=1,
    axes=None,
    colors=None,
    joint_name="right hip",
):
    """Panel (b): a joint's Euler angles over target frames, target and each aligned input.

    Parameters
    ----------
    I, T : MotionFeatures
    maps : dict of str to ndarray of int, shape (n + 1,)
    joint : int
        Index of the joint in the features (1 = ``right_hip`` in
        :data:`fpdtw.motion.joints.PAPER_JOINTS`).
    axes : sequence of Axes, optional
        ``len(maps) + 1`` axes, target first.
    colors : dict, optional
    joint_name : str

    Returns
    -------
    fig, axes
        Each axes has 3 lines (x, y, z Euler angles in degrees, unwrapped); the input's
        angles are warped by the map (``I.euler[M]``).

    Paper: FP-DTW Fig. 8 (right-hip motion curves).
    Notebook: 10_fig8_walk_pair.ipynb
    """
    rows = len(maps) + 1
    if axes is None:
        fig, axes = plt.subplots(rows, 1, figsize=(7, 1.25 * rows + 0.6), sharex=True)
    else:
        fig = axes[0].figure
    axes = list(np.ravel(axes))
    colors = {**ALGORITHM_COLORS, **(colors or {})}
    series = [(f"target {T.name}".strip(), T.euler[:, joint])]
    series += [
        (f"input aligned by {name}", I.euler[np.asarray(M), joint]) for name, M in maps.items()
    ]
    q = np.arange(T.n_frames)
    lo = min(s[1].min() for s in series)
    hi = max(s[1].max() for s in series)
    pad = 0.05 * (hi - lo + 1e-9)
    for ax, (label, E), key in zip(axes, series, [None] + list(maps)):
        for a, style in zip(range(3), ("-", "--", ":")):
            ax.plot(q, E[:, a], style, color=colors.get(key, "black"), lw=1.1, label="xyz"[a])
        ax.set_ylim(lo - pad, hi + pad)
        ax.set_title(label, fontsize=8, loc="left", pad=2)
        ax.tick_params(labelsize=7)
    axes[0].legend(
        loc="lower right",
        bbox_to_anchor=(1.0, 1.0),
        fontsize=7,
        ncol=4,
        title=f"{joint_name} Euler angle",
        title_fontsize=7,
        frameon=False,
    )
    axes[len(series) - 1].set_xlabel("target frame")
    fig.supylabel("degrees", fontsize=8)
    return fig, axes


def plot_aligned_poses(mI, mT, maps: dict, frames, axes=None, view=FBX_SIDE_VIEW, colors=None):
    """Panel (c): poses at a few target frames, target on top, each aligned input below.

    Positions come from forward kinematics; each pose is drawn relative to its root's
    horizontal position (the vertical coordinate is kept), in side elevation.

    Parameters
    ----------
    mI, mT : Motion
        Input and target motions (the ones the maps were computed on).
    maps : dict of str to ndarray of int, shape (n + 1,)
    frames : sequence of int
        Target frames to show.
    axes : 2-D array of Axes, optional
        ``(len(maps) + 1, len(frames))``.
    view : tuple of int
        Coordinates plotted (horizontal, vertical); default the FBX rig's side view.
    colors : dict, optional

    Returns
    -------
    fig, axes
        ``axes[r, c]`` shows row r (0 = target) at ``frames[c]``.

    Paper: FP-DTW Fig. 8 (character poses, side elevation).
    Notebook: 10_fig8_walk_pair.ipynb
    """

    frames = [int(f) for f in frames]
    rows = len(maps) + 1
    if axes is None:
        fig, axes = plt.subplots(rows, len(frames), figsize=(1.5 * len(frames) + 1, 1.9 * rows))
    fig = np.ravel(axes)[0].figure
    axes = np.asarray(axes).reshape(rows, len(frames))
    colors = {**ALGORITHM_COLORS, **(colors or {})}
    PT, _ = mT.forward_kinematics()
    PI, _ = mI.forward_kinematics()
    h, v = view
    flat = np.ones(3)
    flat[v] = 0.0  # subtract the root's horizontal coordinates only

    def centred(P, f):
        return P[f] - P[f, 0] * flat

    all_pts = [centred(PT, f) for f in frames]
    entries = [("target", None, [centred(PT, f) for f in frames])]
    for name, M in maps.items():
        M = np.asarray(M)
        pts = [centred(PI, int(M[f])) for f in frames]
        entries.append((name, name, pts))
        all_pts += pts
    stack = np.concatenate(all_pts)
    lim_h = np.abs(stack[:, h]).max() * 1.05
    lim_v = (stack[:, v].min() - 5, stack[:, v].max() + 5)
    for r, (label, key, pts) in enumerate(entries):
        for c, f in enumerate(frames):
            ax = axes[r, c]
            skel = mT.skeleton if key is None else mI.skeleton
            plot_skeleton(
                pts[c], skel.parents, ax=ax, view=view, color=colors.get(key, "black"), lw=1.2
            )
            ax.set_xlim(-lim_h, lim_h)
            ax.set_ylim(*lim_v)
            ax.set_xticks([])
            ax.set_yticks([])
            for s in ax.spines.values():
                s.set_visible(False)
            if key is None:
                ax.set_title(f"T {f}", fontsize=8)
            else:
                ax.set_title(f"I {int(np.asarray(maps[key])[f])}", fontsize=7, pad=1)
            if c == 0:
                ax.set_ylabel(label, fontsize=8)
    return fig, axes


def walk_pairs() -> list:
    """Every ordered pair of distinct takes of the authors' ``Walk`` movement available here.

    The experiment runner's rule for pairs (both directions of every two takes of one
    movement), on the movement the paper's Fig. 8 is an example of. The authors' dataset
    lists three ``Walk`` takes, all here, so six pairs. (Its five walk styles, Jaunty, Slow,
    Sneaky, Stepping Stones and Stiff, are not here; the paper's own pair, "sample 3239",
    is one we do not have.)

    Returns
    -------
    pairs : list of (MotionRecord, MotionRecord)
        (input, target), in catalog order: ``Walk_01 -> Walk_02``, ``Walk_01 -> Walk_03``, ...

    Paper: FP-DTW Section 5, Fig. 8.
    """

    ds, movement = WALK_MOVEMENT
    takes = [r for r in motion_records((ds,), available_only=True) if r.movement == movement]
    return [(a, b) for a in takes for b in takes if a.path != b.path]


def gait_cycle(F: MotionFeatures) -> tuple[int, str]:
    """One gait cycle of a walk, in its own frames, and how it was found.

    The dominant period of the motion's joint trajectories
    (:func:`fpdtw.period.dominant_period`: the first peak of their autocorrelation after
    its first zero crossing, 0.25-4 s, committed in cbb3316 for Q1); when that finds none
    (e.g. a smoke run's 2 s hold too few cycles), the paper's walking gait: the middle of
    its 0.82-0.9 Hz (:data:`fpdtw.paper.numbers.WALK_GAIT_HZ`), 140 frames at 120 Hz.

    Returns
    -------
    frames : int
    source : str
        ``"autocorrelation"`` or ``"paper's gait"``.

    Paper: FP-DTW Section 4 (walking gait 0.82-0.9 Hz).
    """

    P = dominant_period(F.quats, F.fps)
    if P is not None:
        return int(P), "autocorrelation"
    return int(round(F.fps / float(np.mean(WALK_GAIT_HZ)))), "paper's gait"


def walk_pair_cases(smoke: bool = False, seconds: float = SMOKE_SECONDS,
                    names=FIG8_STATEMENT_ALGORITHMS) -> list:  # fmt: skip
    """Every walk pair (:func:`walk_pairs`) aligned by ``names``, with each motion's gait cycle.

    Parameters
    ----------
    smoke : bool
        Crop both motions of each pair to ``[0, seconds]``.
    seconds : float
    names : sequence of str

    Returns
    -------
    cases : list of dict
        The input of :func:`fig8_statements`: keys ``pair`` (``"Walk_01 -> Walk_02"``),
        ``maps``, ``input_cycle``, ``target_cycle`` (frames), ``cycle_source`` (input's,
        target's: see :func:`gait_cycle`), ``m``, ``n``.

    Notebook: 10_fig8_walk_pair.ipynb
    """

    cases = []
    for a, b in walk_pairs():
        motions = [load(a), load(b)]
        if smoke:
            motions = [x.crop(0.0, seconds) for x in motions]
        I, T = (MotionFeatures.from_motion(x) for x in motions)
        (ci, si), (ct, st) = gait_cycle(I), gait_cycle(T)
        cases.append(
            dict(pair=f"{a.name} -> {b.name}", maps=align_all(I, T, names), input_cycle=ci,
                 target_cycle=ct, cycle_source=f"{si}, {st}", m=I.n_frames - 1,
                 n=T.n_frames - 1)
        )  # fmt: skip
    return cases


def _longest_early_hold(M, m: int, before: float) -> tuple[int, int]:
    """``(length, start)`` of the longest run of one input frame (other than the last, m)
    over consecutive target frames, among the runs starting before target frame ``before``;
    ``(0, -1)`` when there is none. Length in target frames: a frame mapped once is a run of
    1, an input frame held over 5 target frames a run of 5."""
    M = np.asarray(M)
    edges = np.flatnonzero(np.diff(M) != 0) + 1
    starts = np.concatenate([[0], edges])
    ends = np.concatenate([edges, [M.size]])
    best = (0, -1)
    for s0, e0 in zip(starts, ends):
        if s0 < before and M[s0] != m and e0 - s0 > best[0]:
            best = (int(e0 - s0), int(s0))
    return best


def fig8_statements(cases, benchmark: float = DEVIATION_BENCHMARK_FRAMES) -> list[dict]:
    """The paper's statements about its Fig. 8 walk pair, measured on each of our walk pairs.

    Section 5, on a walk pair: "*Mc w80* skips a walk cycle, while the *Mc w20* complete
    fails, sticking on an input frame early in the alignment", and (with the deviations 8,
    177, 62, 6 frames) "only algorithms *Mb w80* and *Mc w40* with errors (or deviations)
    below the 18 frame benchmark". Each statement is measured against DTW's map ``P`` of
    the same pair (the paper's reference, eq. 3), by a rule fixed from those words before
    any walk pair was aligned:

    * **"Mc w20 fails"**: its deviation from DTW (eq. 3, frames) is above the 18-frame
      benchmark, the paper's line between an alignment that passes and one that does not.
    * **"Mc w20 sticks early"** (the paper's account of that failure): Mc w20's map holds one
      input frame over at least one gait cycle of the target, ``target_cycle`` consecutive
      target frames, in a hold that starts in the first third of the target
      (``q < n / 3``: "early in the alignment"). A hold on the input's last frame ``m`` does
      not count: that is the input run out (as for Mc w80 in the paper's Table 2 text), not
      a stick. Value: the longest such hold, in target frames.
    * **"Mc w80 skips a walk cycle"**: at some target frame Mc w80's map is ahead of DTW's by
      at least one gait cycle of the input: ``max_q (M_q - P_q) >= input_cycle`` input frames.
      Value: that largest lead, in input frames.
    * **"Mb w80 stays close to DTW"**: its deviation from DTW (eq. 3) is below 18 frames.

    A gait cycle is estimated from the motion itself (:func:`gait_cycle`: the
    autocorrelation's period, else the paper's 0.82-0.9 Hz gait).

    Parameters
    ----------
    cases : iterable of dict
        One per pair: ``pair`` (label), ``maps`` (name -> map, ndarray of int, shape
        (n + 1,); must hold DTW, Mb w80, Mc w20, Mc w80), ``input_cycle`` and
        ``target_cycle`` (frames); optional ``m`` (the input's last frame, default the
        largest input frame any map reaches). :func:`walk_pair_cases` gives them.
    benchmark : float
        The deviation benchmark in frames (18 at 120 Hz).

    Returns
    -------
    rows : list of dict
        Per pair, four rows in the order above; keys ``pair``, ``statement``, ``value``,
        ``threshold``, ``unit``, ``holds`` (bool).

    Paper: FP-DTW Section 5 (the text on Fig. 8) and eq. 3.
    Notebook: 10_fig8_walk_pair.ipynb
    """
    rows = []
    for c in cases:
        maps = {k: np.asarray(v, dtype=np.int64) for k, v in c["maps"].items()}
        P = maps["DTW"]
        m = int(c.get("m", max(int(v.max()) for v in maps.values())))
        n = P.size - 1
        d20 = deviation(P, maps["Mc w20"])
        hold, _ = _longest_early_hold(maps["Mc w20"], m, n / 3.0)
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
    """Per statement of :func:`fig8_statements`: on how many pairs it holds, of how many.

    Returns
    -------
    counts : dict
        ``{statement: {"holds": k, "pairs": n}}``, in the order of the rows.

    Notebook: 10_fig8_walk_pair.ipynb
    """
    out = {}
    for r in rows:
        c = out.setdefault(r["statement"], {"holds": 0, "pairs": 0})
        c["holds"] += int(r["holds"])
        c["pairs"] += 1
    return out


__all__ = [
    "ALGORITHM_COLORS",
    "FBX_SIDE_VIEW",
    "FIG8_ALGORITHMS",
    "FIG8_STATEMENT_ALGORITHMS",
    "FIG8_STATEMENT_RULES",
    "WALK_MOVEMENT",
    "fig8_statements",
    "gait_cycle",
    "statement_counts",
    "walk_pair_cases",
    "walk_pairs",
    "SMOKE_SECONDS",
    "WALK_PAIR",
    "align_all",
    "load_walk_pair",
    "pair_scores",
    "plot_aligned_poses",
    "plot_joint_curves",
    "plot_paths_over_cost",
    "pose_frames",
    "walk_pair_features",
]
