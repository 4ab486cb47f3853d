"""Side-by-side stick-figure animation of an alignment (GIF or MP4).

Left: the target ("live") motion at frame ``q``; right: the recorded input at the
frame the alignment chose, ``M[q]``, so the right figure follows the left one. Poses
come from forward kinematics (:meth:`fpdtw.motion.Motion.forward_kinematics`), drawn as
in :func:`fpdtw.paper.figures.plotting.plot_skeleton`: bones as lines, projected on a side view.

View: each motion is seen from its own side, as it stands in its first frame: the
vertical axis is the skeleton's up axis (the axis along which the head sits furthest from
the root, on average), the horizontal axis its facing direction in the first frame
(perpendicular to the line through both hips), so both figures face right. Each figure is
centred on its root horizontally in every frame (it moves on the spot); heights are kept.

Only every ``stride``-th target frame is drawn, and the animation plays at
``fps / stride`` frames per second, i.e. in real time.

Notebook: 20_align_a_live_performance.ipynb
"""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np

from fpdtw.errors import FpdtwError


class WriterUnavailable(FpdtwError, RuntimeError):
    """The animation format needs a tool that is not installed (ffmpeg for MP4)."""


def ffmpeg_path() -> str | None:
    """Path of an ffmpeg executable (``imageio_ffmpeg``'s, else one on PATH), or None."""
    try:
        import imageio_ffmpeg  # optional, never a dependency of fpdtw

        return imageio_ffmpeg.get_ffmpeg_exe()
    except Exception:  # noqa: BLE001 - not installed or no binary: fall back to PATH
        return shutil.which("ffmpeg")


def check_writer(out) -> str:
    """The writer for an output file name: ``"pillow"`` (.gif) or ``"ffmpeg"`` (.mp4).

    Raises
    ------
    WriterUnavailable
        ``.mp4`` without ffmpeg, or another extension.
    """
    ext = Path(out).suffix.lower()
    if ext == ".gif":
        return "pillow"
    if ext == ".mp4":
        if ffmpeg_path() is None:
            raise WriterUnavailable(
                f"{out}: writing .mp4 needs ffmpeg (an ffmpeg binary on PATH or the "
                "imageio-ffmpeg package); neither was found. Write a .gif instead."
            )
        return "ffmpeg"
    raise WriterUnavailable(f"{out}: unknown animation type {ext!r}; use .gif or .mp4")


def _joint(motion, canonical):
    own = motion.joint_map.get(canonical)
    return motion.skeleton.index(own) if own in motion.skeleton.joint_names else None


def _view(motion, pos):
    """Unit vectors (forward, up) of a side view of a motion, from its first frame.

    Up: the world axis along which the head sits furthest from the root on average (y
    when there is no head). Forward: ``up x right``, ``right`` the vector from the left
    to the right hip in the first frame (without its vertical part): the figure faces
    right in the picture. Without hips: the horizontal axis along which the root travels
    most.
    """
    root = pos[:, 0]
    up = np.zeros(3)
    up[1] = 1.0
    head = _joint(motion, "head")
    if head is not None:
        d = (pos[:, head] - root).mean(axis=0)
        a = int(np.argmax(np.abs(d)))
        up = np.zeros(3)
        up[a] = 1.0 if d[a] >= 0 else -1.0
    lh, rh = _joint(motion, "left_hip"), _joint(motion, "right_hip")
    if lh is not None and rh is not None:
        right = pos[0, rh] - pos[0, lh]
        right = right - (right @ up) * up
        if np.linalg.norm(right) > 1e-9:
            fwd = np.cross(up, right)
            return fwd / np.linalg.norm(fwd), up
    others = [a for a in range(3) if up[a] == 0]
    fwd = np.zeros(3)
    fwd[others[int(np.argmax([np.ptp(root[:, a]) for a in others]))]] = 1.0
    return fwd, up


def _projected(motion):
    """Side-view 2-D joint positions, root-centred horizontally: (F, J, 2)."""
    pos, _ = motion.forward_kinematics()
    fwd, up = _view(motion, pos)
    P = np.empty(pos.shape[:2] + (2,))
    P[..., 0] = (pos - pos[:, :1]) @ fwd
    P[..., 1] = pos @ up
    return P


def _segments(P, parents):
    kids = np.flatnonzero(parents >= 0)
    return np.stack([P[parents[kids]], P[kids]], axis=1)  # (bones, 2, 2)


def _limits(P):
    lo = P.reshape(-1, 2).min(axis=0)
    hi = P.reshape(-1, 2).max(axis=0)
    pad = 0.08 * (hi - lo).max()
    return (lo[0] - pad, hi[0] + pad), (lo[1] - pad, hi[1] + pad)


def animate_alignment(
    I_motion,
    T_motion,
    M,
    out,
    fps: float | None = None,
    stride: int | None = None,
    *,
    dpi: int = 72,
    size=(4.8, 3.2),
    labels=("live (target)", "recorded (input), aligned"),
) -> Path:
    """Render the target and the aligned input side by side as a GIF or MP4.

    Parameters
    ----------
    I_motion : Motion
        The recorded input (the frame rate the map refers to).
    T_motion : Motion
        The target.
    M : array_like of int, shape (T_motion.n_frames,)
        Input frame of each target frame.
    out : str or os.PathLike
        ``.gif`` (Pillow) or ``.mp4`` (needs ffmpeg).
    fps : float, optional
        Target frame rate (default ``T_motion.fps``).
    stride : int, optional
        Draw every ``stride``-th target frame (default: about 20 drawn frames per
        second of motion, ``round(fps / 20)``); the animation plays at ``fps / stride``.
    dpi : int
    size : (float, float)
        Figure size in inches.
    labels : (str, str)
        Panel titles.

    Returns
    -------
    out : Path

    Raises
    ------
    WriterUnavailable
        ``.mp4`` without ffmpeg, or an unknown extension.

    Paper: FP-DTW Fig. 8 (poses of an aligned pair), as an animation.
    Notebook: 20_align_a_live_performance.ipynb
    """
    import matplotlib
    import matplotlib.pyplot as plt
    from matplotlib import animation
    from matplotlib.collections import LineCollection

    from fpdtw.paper.figures import plotting  # noqa: F401 - headless backend outside Jupyter

    out = Path(out)
    writer_name = check_writer(out)
    M = np.asarray(M, dtype=np.int64)
    if M.shape != (T_motion.n_frames,):
        raise ValueError(f"map has {M.size} frames, the target {T_motion.n_frames}")
    if M.min() < 0 or M.max() >= I_motion.n_frames:
        raise ValueError("map values outside the input's frames")
    fps = float(T_motion.fps if fps is None else fps)
    if stride is None:
        stride = max(1, round(fps / 20.0))
    stride = int(stride)
    if stride < 1:
        raise ValueError(f"stride must be >= 1, got {stride}")
    qs = np.arange(0, T_motion.n_frames, stride)
    PT = _projected(T_motion)
    PI = _projected(I_motion)

    fig, axes = plt.subplots(1, 2, figsize=size, dpi=dpi)
    panels = []
    for ax, P, parents, color, title in (
        (axes[0], PT, T_motion.skeleton.parents, "k", labels[0]),
        (axes[1], PI, I_motion.skeleton.parents, "tab:blue", labels[1]),
    ):
        xl, yl = _limits(P)
        ax.set_xlim(*xl)
        ax.set_ylim(*yl)
        ax.set_aspect("equal")
        ax.set_xticks([])
        ax.set_yticks([])
        ax.set_title(title, fontsize=9)
        lc = LineCollection([], colors=color, linewidths=2)
        ax.add_collection(lc)
        text = ax.text(0.02, 0.02, "", transform=ax.transAxes, fontsize=8)
        panels.append((lc, text, P, parents))
    fig.tight_layout()

    def draw(k):
        q = int(qs[k])
        frames = (q, int(M[q]))
        rates = (fps, float(I_motion.fps))
        for (lc, text, P, parents), f, r in zip(panels, frames, rates):
            lc.set_segments(_segments(P[f], parents))
            text.set_text(f"frame {f}  ({f / r:.2f} s)")
        return [p[0] for p in panels] + [p[1] for p in panels]

    anim = animation.FuncAnimation(fig, draw, frames=len(qs), blit=False)
    out_fps = fps / stride
    if writer_name == "pillow":
        writer, rc = animation.PillowWriter(fps=out_fps), {}
    else:
        writer = animation.FFMpegWriter(fps=out_fps)
        rc = {"animation.ffmpeg_path": ffmpeg_path()}
    out.parent.mkdir(parents=True, exist_ok=True)
    try:
        with matplotlib.rc_context(rc):
            anim.save(str(out), writer=writer, dpi=dpi)
    finally:
        plt.close(fig)
    return out


__all__ = ["WriterUnavailable", "animate_alignment", "check_writer", "ffmpeg_path"]
