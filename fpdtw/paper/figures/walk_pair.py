"""Fig. 8: one walk pair aligned by DTW and the FP-DTW methods, and the pair itself.

The paper's Fig. 8 aligns two walks (its "sample 3239", not identified) with DTW, Mb w80,
Mc w20, Mc w40 and Mc w80, unconstrained, and shows (a) the paths over the heat map of
DTW's accumulated cost, (b) the right hip's motion curves, target on top and each aligned
input below, (c) poses in side elevation at a few target frames. We use the authors' own
walk pair ``Walk_01 -> Walk_02`` (input -> target), the paper's "walking" example type,
chosen in 578ff6e (2026-11-21) with the notebooks that draw these figures, before any
alignment figure or claims table was committed (docs/history.md); the same pair draws
Figs. 1, 2 and 4.
"""

from __future__ import annotations

import numpy as np

from fpdtw.metrics import deviation, similarity
from fpdtw.motion.features import MotionFeatures
from fpdtw.paper.catalog import load
from fpdtw.paper.figures.plotting import new_axes, plot_skeleton
from fpdtw.paper.numbers import FIG8_DEVIATIONS
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
        import matplotlib.pyplot as plt

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
    import matplotlib.pyplot as plt

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


__all__ = [
    "ALGORITHM_COLORS",
    "FBX_SIDE_VIEW",
    "FIG8_ALGORITHMS",
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
