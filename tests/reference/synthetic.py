"""Synthetic motions for tests and benchmarks that must not depend on data files.

:func:`random_walk_features` makes smooth random-walk motions (Euler angles whose
velocity is a smoothed random walk); :func:`synthetic_pair` adds a time-warped, noisy
copy of one with its known warp.
"""

from __future__ import annotations

import numpy as np
from scipy.ndimage import gaussian_filter1d

from fpdtw.motion.features import MotionFeatures
from fpdtw.motion.rotations import ORDERS, euler_to_quat


def random_walk_euler(n_frames: int, k: int = 8, seed=0, speed: float = 1.5, smooth=12.0):
    """Smooth random-walk Euler angles.

    Parameters
    ----------
    n_frames : int
    k : int
        Number of joints.
    seed : int or numpy Generator
    speed : float
        Standard deviation of the per-frame change, degrees.
    smooth : float
        Gaussian smoothing (frames) of the velocity.

    Returns
    -------
    E : ndarray of float64, shape (n_frames, k, 3)
        Degrees.
    """
    rng = np.random.default_rng(seed)
    pad = int(4 * smooth)
    v = rng.normal(size=(n_frames + 2 * pad, k, 3))
    v = gaussian_filter1d(v, smooth, axis=0)[pad : pad + n_frames]
    v *= speed / v.std()
    return np.cumsum(v, axis=0) + rng.uniform(-40.0, 40.0, size=(1, k, 3))


def features_from_euler(E, orders=None, fps=120.0, name="") -> MotionFeatures:
    """MotionFeatures of Euler angles (degrees, (F, k, 3)); orders default to a mix of all six."""
    E = np.asarray(E, dtype=np.float64)
    k = E.shape[1]
    if orders is None:
        orders = tuple(ORDERS[j % len(ORDERS)] for j in range(k))
    Q = np.stack([euler_to_quat(E[:, j], orders[j]) for j in range(k)], axis=1)
    return MotionFeatures.from_arrays(Q, euler=E, orders=orders, fps=fps, name=name)


def random_walk_features(n_frames: int, k: int = 8, seed=0, **kwargs) -> MotionFeatures:
    """A random-walk motion (see :func:`random_walk_euler`) as MotionFeatures."""
    return features_from_euler(random_walk_euler(n_frames, k, seed, **kwargs), name=f"rw{seed}")


def synthetic_pair(n_frames: int = 600, k: int = 8, seed=0, warp: float = 0.35, noise=0.5):
    """A random-walk input and a randomly time-warped, noisy copy as target.

    Parameters
    ----------
    n_frames : int
        Frames of the input; the target has between 0.8 and 1.2 times as many.
    k : int
        Joints.
    seed : int
    warp : float
        Strength of the time warp (0: uniform).
    noise : float
        Standard deviation of the Gaussian noise added to the target, degrees.

    Returns
    -------
    I, T : MotionFeatures
    s : ndarray of float64, shape (n_T,)
        The true warp: target frame q shows input time ``s[q]`` (frames), increasing
        from 0 to ``n_frames - 1``.
    """
    rng = np.random.default_rng(seed)
    E = random_walk_euler(n_frames, k, rng)
    n_T = int(round(n_frames * rng.uniform(0.8, 1.2)))
    rate = np.exp(warp * gaussian_filter1d(rng.normal(size=n_T + 40), 10)[20:-20] * 4)
    s = np.concatenate([[0.0], np.cumsum(rate[1:])])
    s *= (n_frames - 1) / s[-1]
    ET = np.empty((n_T, k, 3))
    grid = np.arange(n_frames)
    for j in range(k):
        for a in range(3):
            ET[:, j, a] = np.interp(s, grid, E[:, j, a])
    ET += rng.normal(scale=noise, size=ET.shape)
    orders = tuple(ORDERS[j % len(ORDERS)] for j in range(k))
    I = features_from_euler(E, orders, name=f"syn{seed}_I")
    T = features_from_euler(ET, orders, name=f"syn{seed}_T")
    return I, T, s


def one_joint_motion(angles_deg, axis: str = "X", fps: float = 120.0) -> MotionFeatures:
    """A one-joint motion turning about one axis: hand-checkable geodesic costs.

    Frame f is a rotation by ``angles_deg[f]`` degrees about ``axis``, so the
    geodesic cost (eq. 1) between frames a and b is ``|angle_a - angle_b| / 180``
    (for differences up to 180 degrees).

    Parameters
    ----------
    angles_deg : array_like of float, shape (F,)
    axis : {"X", "Y", "Z"}

    Returns
    -------
    features : MotionFeatures
        quats (F, 1, 4), euler (F, 1, 3) with the angle in the axis' column, order "XYZ".
    """
    ang = np.asarray(angles_deg, dtype=float)
    col = "XYZ".index(axis.upper())
    E = np.zeros((ang.size, 1, 3))
    E[:, 0, col] = ang
    h = np.deg2rad(ang) / 2
    Q = np.zeros((ang.size, 1, 4))
    Q[:, 0, 0] = np.cos(h)
    Q[:, 0, 1 + col] = np.sin(h)
    return MotionFeatures.from_arrays(Q, euler=E, orders=("XYZ",), fps=fps)


def random_walk_quats(rng, frames: int, k: int = 8, step: float = 0.05) -> MotionFeatures:
    """Smooth synthetic motion: a random walk of k quaternions, normalised."""
    from fpdtw.motion.rotations import quat_normalize

    q = np.cumsum(step * rng.normal(size=(frames, k, 4)), axis=0) + rng.normal(size=(1, k, 4))
    return MotionFeatures.from_arrays(quat_normalize(q))


__all__ = [
    "one_joint_motion",
    "random_walk_quats",
    "features_from_euler",
    "random_walk_euler",
    "random_walk_features",
    "synthetic_pair",
]


def method_pairs() -> list:
    """The synthetic (input, target) pairs the FP-DTW method tests run on; in the third the
    input is the first 60 frames of a 150-frame target, so every method reaches the end of
    the input and must hold there."""
    I0, T0, _ = synthetic_pair(160, seed=11)
    I1, T1, _ = synthetic_pair(220, seed=12, warp=0.6)
    T2 = random_walk_features(150, seed=14)
    return [(I0, T0), (I1, T1), (T2.slice(0, 60), T2)]
