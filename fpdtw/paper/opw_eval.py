"""The OPW poster's evaluation: a known example warp, OPW and smoothed DTW against it.

Protocol (poster Sections 4-5; the reading notes, ``notebooks/reading_notes.md``):

1. Crop a recorded motion A to its first 2.5 s (``Motion.crop(0, 2.5)``; the poster
   cropped every motion at 2.5 s "to eliminate any impact of variations in temporal
   length").
2. Warp it with the EXAMPLE curve (:func:`example_curve`), a piecewise Bezier through
   ``(0, 0)``, ``(1.25, 1.25 + offset)``, ``(2.5, 2.5)`` in (live time t, recording time
   t'): live time 1.25 s shows recording time 1.5 s for the poster's 0.25 s offset ("1.5
   seconds being warped to 1.25 seconds"); it starts steep (speeding time up) and ends
   shallow. The warped motion is ``B(t) = A(g(t))`` (:func:`warp_motion`), same duration.
3. Align A to B: OPW live (:class:`fpdtw.online.opw.OPW`) and offline DTW smoothed into
   a Bezier curve by the poster's Fig. 3 rule (:func:`dtw_curve`). A perfect aligner
   recovers ``f = g``.
4. Measure each curve against the example, sampled at 50 Hz over the live duration:
   deviation in ms (Fig. 4 middle row, Fig. 5, Fig. 6), change of slope between
   samples in percent of 90 degrees (Fig. 4 bottom row), and the share of the temporal
   difference removed (the poster's "approximately 70 %" / "77 %").

The poster's numbers: OPW mean deviation 69-79 ms, maximum 121 ms (< 150 ms, Hoyet et
al.), about 70 % of the temporal difference removed at gamma = 5 %, about 77 % at the
best gamma (15 %).

Two readings of the whole protocol (:data:`READINGS`): ``"poster"``, the poster's text
as :mod:`fpdtw.online.opw` reads it, with root-relative positions and the Fig. 3 DTW
curve as baseline; ``"plugin"``, as the authors' MotionBuilder plugin does it
(matRandall/realTimeDTW): OPW's plugin options (global-ratio reference times, the frame
clock), the effectors' world positions, and the plugin's own "standard DTW" baseline,
which is not DTW but a per-sample best match forced monotone (:func:`best_match_curve`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from fpdtw.costs import position_cost_matrix
from fpdtw.dtw import dtw
from fpdtw.motion.features import MotionFeatures
from fpdtw.motion.joints import OPW_JOINTS
from fpdtw.online.base import run_online
from fpdtw.online.opw import OPW
from fpdtw.paper import numbers
from fpdtw.paper.catalog import load
from fpdtw.warpcurve import WarpCurve

# The poster's protocol (values and sources in :mod:`fpdtw.paper.numbers`):
#: OPW's sample period (s): 25 steps per second.
OMEGA = numbers.OPW_OMEGA_S
#: The warp parameter of Figs. 4 and 5.
GAMMA = numbers.OPW_GAMMA
#: Every motion is cropped to its first CROP_S seconds.
CROP_S = numbers.OPW_CROP_S
#: Curves are compared at this rate (Hz), as the poster's exported curves.
SAMPLE_RATE = numbers.OPW_SAMPLE_RATE_HZ
#: The offset of the example curve's middle key (s).
OFFSET = numbers.OPW_OFFSET_S
#: Perceptual threshold of Hoyet et al. 2012 used by the poster (ms).
HOYET_MS = numbers.PERCEPTUAL_THRESHOLD_MS


@dataclass(frozen=True)
class OPWReading:
    """One reading of OPW and its evaluation: the aligner's options, the positions, the
    baseline.

    Attributes
    ----------
    name : str
    reference, clock, direction, read_at : str
        The options of :class:`fpdtw.online.opw.OPW`.
    root_relative : bool
        Positions relative to the root (the poster reading) or in world space (the
        plugin: its control rig's effectors relative to the rig's reference node).
    baseline : str
        The offline method this reading compares OPW with: ``"DTW"`` (:func:`dtw_curve`)
        or ``"best match"`` (:func:`best_match_curve`, the plugin's "standard DTW").
    """

    name: str
    reference: str = "curve"
    clock: str = "exact"
    direction: str = "code"
    root_relative: bool = True
    baseline: str = "DTW"
    read_at: str = "eq4"

    def options(self) -> dict:
        """The keyword arguments of :class:`fpdtw.online.opw.OPW`."""
        return dict(
            reference=self.reference, clock=self.clock, direction=self.direction,
            read_at=self.read_at,
        )  # fmt: skip


#: The two readings of the protocol (module doc).
READINGS = {
    "poster": OPWReading("poster"),
    "plugin": OPWReading("plugin", "ratio", "frames", "code", False, "best match"),
}

#: From the poster reading to the plugin's, one mechanism at a time, then the plugin
#: with its readme's direction: what each mechanism does to the deviation.
READING_STEPS = (
    READINGS["poster"],
    OPWReading("poster + ratio reference", reference="ratio"),
    OPWReading("poster + frame clock", clock="frames"),
    OPWReading("poster + world positions", root_relative=False),
    READINGS["plugin"],
    replace(READINGS["plugin"], name="plugin, readme direction", direction="readme"),
)


def as_reading(reading) -> OPWReading:
    """An :class:`OPWReading` from itself or the name of one of :data:`READINGS`."""
    if isinstance(reading, OPWReading):
        return reading
    if reading not in READINGS:
        raise ValueError(f"unknown OPW reading {reading!r}; known: {sorted(READINGS)}")
    return READINGS[reading]


@dataclass(frozen=True)
class OPWMotion:
    """A motion of the poster's Fig. 4 or our stand-in for it.

    Attributes
    ----------
    label : str
        The poster's motion this stands for.
    dataset, path : str
        Where it is in the catalog.
    why : str
        Why it was chosen (the rule, committed with the clips in 4d74569 before any OPW
        result was in the repository; docs/history.md).
    """

    label: str
    dataset: str
    path: str
    why: str


#: Fig. 4's three motions. Only the hand shake is the poster's own source (CMU 18_01,
#: subject A; B is A warped, so one partner suffices). The CMU conversation (18_08/18_09)
#: and arm-wrestle (22_17) takes are not obtainable here; the stand-ins follow a rule
#: committed with them in 4d74569 (2026-11-21), before any OPW result was in the
#: repository (docs/history.md): an upper-body, non-contact gesture clip of at least
#: 2.5 s, and a clip of sustained two-arm work in place.
FIG4_MOTIONS = (
    OPWMotion(
        "hand gestures",
        "hdm05",
        "HDM05_cut_amc/throwBasketball/HDM_bd_throwBasketball_002_120.amc",
        "stand-in: HDM05 throwBasketball is the only class here of non-contact arm "
        "gestures whose clips reach 2.5 s (rotateArmsBothBackward clips are < 2 s); "
        "its first clip in manifest order with >= 301 frames (120 Hz)",
    ),
    OPWMotion(
        "hand shake",
        "cmu",
        "18_01.bvh",
        "the poster's own source: CMU take 18_01 'walk, shake hands', subject A (30 fps); "
        "its first 2.5 s are the approach",
    ),
    OPWMotion(
        "arm wrestle",
        "authors_fbx",
        "MoCapData/Shelf_Stack_01.fbx",
        "stand-in: the authors' Shelf_Stack (continuous two-arm work handling objects, "
        "standing in place: prolonged upper-body effort with contact), take 01",
    ),
)


# -- the example curve and the warped motion ---------------------------------------------------


def example_curve(duration: float = CROP_S, offset: float = OFFSET) -> WarpCurve:
    """The poster's example warp: keys (0, 0), (D/2, D/2 + offset), (D, D) in (t, t').

    Parameters
    ----------
    duration : float
        Duration D of the motion (s).
    offset : float
        Offset of the middle key on the recording axis (s); 0.25 in Fig. 4.

    Returns
    -------
    g : WarpCurve
        Live time -> recording time; with the default, live 1.25 s shows recording 1.5 s.

    Paper: OPW poster Section 5, Figs. 4 and 5.
    Notebook: 13_opw_fig4.ipynb
    """
    d = float(duration)
    if not 0 <= offset < d / 2 or not d > 0:
        raise ValueError(f"need duration > 0 and 0 <= offset < duration / 2, got {d}, {offset}")
    return WarpCurve([0.0, d / 2, d], [0.0, d / 2 + offset, d])


def warp_motion(motion, curve: WarpCurve, fps=None, name=None):
    """The warped motion ``B(t) = A(curve(t))``, frames at ``k / fps`` over the curve's span.

    Parameters
    ----------
    motion : Motion
        The recording A.
    curve : WarpCurve
        Live time -> recording time (s).
    fps : float, optional
        Frame rate of B (default: A's).

    Returns
    -------
    B : Motion
        ``floor(x_last * fps) + 1`` frames; rotations by slerp (:meth:`Motion.retime`).

    Paper: OPW poster Section 4 ("warping a motion sequence (A) using a predefined
    example time warp curve, resulting in a warped motion (B)").
    Notebook: 13_opw_fig4.ipynb
    """
    fps = float(motion.fps if fps is None else fps)
    n = int(np.floor(curve.x[-1] * fps + 1e-9)) + 1
    t = np.arange(n) / fps
    return motion.retime(curve(t), fps=fps, name=name or f"{motion.name}_warped")


def opw_features(motion, root_relative: bool = True) -> MotionFeatures:
    """Features with the 16 OPW joint positions of a motion.

    Parameters
    ----------
    motion : Motion
    root_relative : bool
        True (the poster reading): positions relative to the root of each frame; False
        (the plugin): world positions, the root's travel included.

    Returns
    -------
    features : MotionFeatures
        ``positions`` of shape (F, 16, 3), float64 (:data:`fpdtw.motion.joints.OPW_JOINTS`).

    Paper: OPW poster Section 4 (16 joints), eq. 5.
    Notebook: 13_opw_fig4.ipynb
    """
    if root_relative:
        return MotionFeatures.from_motion(motion, position_joints=OPW_JOINTS)
    feats = MotionFeatures.from_motion(motion)
    P = motion.positions(OPW_JOINTS, root_relative=False)
    return replace(feats, positions=np.ascontiguousarray(P, dtype=np.float64))


def load_cropped(dataset: str, path: str, crop: float | None = CROP_S):
    """Load a motion through the catalog and crop it to its first ``crop`` seconds.

    Returns
    -------
    motion : Motion
        ``Motion.crop(0, crop)`` (None: uncropped).

    Paper: OPW poster Section 4 ("cropped at 2.5 seconds").
    Notebook: 13_opw_fig4.ipynb
    """

    m = load(dataset, path)
    return m if crop is None else m.crop(0.0, crop)


# -- offline DTW curve (poster Fig. 3) -----------------------------------------------------------


def fig3_key_points(path, max_run: int | None = 2) -> np.ndarray:
    """Indices of the path points the poster's Fig. 3 rule keeps as curve keys.

    A step between consecutive path cells (i, j) (i: recording A, j: live B) is
    *sequential* (diagonal, (1, 1)), a *deletion* ((1, 0): several samples of A map to
    one of B) or an *insertion* ((0, 1): one sample of A maps to several of B). Point k
    is kept when the steps just before it are a run of 1..``max_run`` insertions and/or
    deletions and the step after it is sequential ("only aligning time steps after 1 or
    2 consecutive steps have resulted in either a sample being inserted or deleted and
    where the next time step is a sequential substitution"). The two end points are
    always kept.

    Parameters
    ----------
    path : ndarray of int, shape (L, 2)
        DTW path, forward order, cells (i, j).
    max_run : int or None
        Longest run of insertions/deletions that still gets a key (the poster: 2);
        None: any length.

    Returns
    -------
    idx : ndarray of int64, shape (K,)
        Increasing indices into ``path``, first 0 and last L - 1.

    Paper: OPW poster Section 4, Fig. 3.
    """
    path = np.asarray(path, dtype=np.int64)
    L = path.shape[0]
    if L == 1:
        return np.zeros(1, dtype=np.int64)
    steps = np.diff(path, axis=0)
    diag = (steps[:, 0] == 1) & (steps[:, 1] == 1)
    keep = [0]
    run = 0  # insertions/deletions just before the current point
    for k in range(1, L - 1):
        run = 0 if diag[k - 1] else run + 1
        if diag[k] and run >= 1 and (max_run is None or run <= max_run):
            keep.append(k)
    keep.append(L - 1)
    return np.asarray(keep, dtype=np.int64)


def dtw_curve(
    A, B, omega: float = OMEGA, max_run: int | None = 2, root_relative: bool = True
) -> WarpCurve:
    """Offline DTW of A against B at OPW's rate, smoothed into a Bezier curve (Fig. 3).

    Both motions are resampled to ``1 / omega`` Hz (25 Hz): the rate OPW steps at, so
    both methods see the motions on the same time grid and their curves are keyed at
    the same resolution (the poster does not state DTW's rate; "during all tests" it
    ran at 25 steps per second). Cost: poster eq. 5 (sum of the 16 joints' Euclidean
    distances, root-relative positions); classic symmetric DTW
    (:func:`fpdtw.dtw.dtw`, ``symmetric1``), rows = A, columns = B. Keys: the path
    points of :func:`fig3_key_points` at ``(t, t') = (j omega, i omega)``; where two kept
    points share a live time (only possible next to the start) the earlier is kept;
    the last key is the true end ``(D_B, D_A)`` (DTW's boundary condition: the ends
    match; the 25 Hz grid may stop up to ``omega`` short of them).

    Parameters
    ----------
    A, B : Motion
        Recording and live motion.
    omega : float
        Sample period (s).
    max_run : int or None
        See :func:`fig3_key_points`.
    root_relative : bool
        Positions relative to the root (default) or in world space.

    Returns
    -------
    f : WarpCurve
        Live time -> recording time.

    Paper: OPW poster Section 4, Fig. 3, eq. 5.
    """
    rate = 1.0 / omega
    PA = A.resample(rate).positions(OPW_JOINTS, root_relative=root_relative)
    PB = B.resample(rate).positions(OPW_JOINTS, root_relative=root_relative)
    res = dtw(position_cost_matrix(PA, PB))
    idx = fig3_key_points(res.path, max_run)
    pts = res.path[idx]
    xs, ys = [], []
    for i, j in pts[:-1]:
        x = j * omega
        if xs and x <= xs[-1]:
            continue
        xs.append(x)
        ys.append(i * omega)
    DA, DB = A.duration, B.duration
    while xs and xs[-1] >= DB:
        xs.pop()
        ys.pop()
    xs.append(DB)
    ys.append(DA)
    if len(xs) < 2:
        xs, ys = [0.0, DB], [0.0, DA]
    return WarpCurve(xs, ys)


# -- the plugin's "standard DTW" baseline -----------------------------------------------------


def plugin_period(fps: float) -> float:
    """The plugin's sample period for its baseline: one frame, in whole milliseconds (s).

    The plugin sets it to ``1000 / fps`` ms through ``FBTime::SetMilliSeconds``, which
    takes an integer: 8 ms at 120 Hz, 33 ms at 30 Hz.
    """
    return math.floor(1000.0 / float(fps) + 1e-9) / 1000.0


def _positions_at(P, fps: float, times) -> np.ndarray:
    """Positions (F, p, 3) at ``times`` (s), linear between frames, clamped to the ends."""
    x = np.clip(np.asarray(times, dtype=float) * fps, 0.0, P.shape[0] - 1)
    i0 = np.minimum(np.floor(x + 1e-9).astype(np.int64), P.shape[0] - 1)
    i1 = np.minimum(i0 + 1, P.shape[0] - 1)
    a = np.clip(x - i0, 0.0, 1.0)[:, None, None]
    return (1.0 - a) * P[i0] + a * P[i1]


def best_match_map(C) -> np.ndarray:
    """The plugin's baseline map: each recording sample's best live sample, forced monotone.

    Row ``i`` of ``C`` (a recording sample) takes the column of its smallest cost (the
    first on ties), then ``M_0`` is that column and ``M_i = min(max(best_i, M_{i-1}),
    M_{i-1} + 2)``: a best match behind the previous one repeats it, one more than two
    samples ahead is cut to two.

    Parameters
    ----------
    C : ndarray of float, shape (N_A, N_B)
        Costs between the recording's and the live motion's samples.

    Returns
    -------
    M : ndarray of int64, shape (N_A,)
        Live sample of each recording sample, non-decreasing, steps of 0, 1 or 2.

    Paper: the authors' MotionBuilder plugin (``EventButtonRunStandardDTW``), the
    baseline of the OPW poster's Figs. 4-5 under the plugin reading.
    """
    best = np.argmin(np.asarray(C, dtype=float), axis=1)
    M = np.empty(best.size, dtype=np.int64)
    M[0] = best[0]
    for i in range(1, best.size):
        M[i] = min(max(int(best[i]), M[i - 1]), M[i - 1] + 2)
    return M


def best_match_keys(M) -> np.ndarray:
    """The samples of a :func:`best_match_map` the plugin turns into curve keys.

    Sample ``i >= 1`` is kept when its step is not sequential (``M_i != M_{i-1} + 1``: a
    repeat or a jump of two) and the next sample does not repeat it (``M_{i+1} !=
    M_i``; the last sample has no next). The last sample is always kept.

    Returns
    -------
    idx : ndarray of int64, shape (K,)
        Increasing sample indices, ending with ``len(M) - 1``.

    Paper: the authors' MotionBuilder plugin (``EventButtonRunStandardDTW``).
    """
    M = np.asarray(M, dtype=np.int64)
    n = M.size
    keep = [i for i in range(1, n) if M[i] != M[i - 1] + 1 and (i == n - 1 or M[i + 1] != M[i])]
    if not keep or keep[-1] != n - 1:
        keep.append(n - 1)
    return np.asarray(keep, dtype=np.int64)


def best_match_curve(A, B, period=None, root_relative: bool = False) -> WarpCurve:
    """The plugin's "standard DTW" baseline: a monotone per-sample best match as a curve.

    Both motions are sampled every ``period`` seconds (times strictly before each one's
    last frame time, as the plugin's loops); the cost of a pair of samples is eq. 5 over
    the 16 joints' positions. :func:`best_match_map` maps each recording sample ``i`` to
    a live sample ``M_i``; :func:`best_match_keys` picks the samples that become keys
    ``(t, t') = (M_i period, i period)``, added to a curve that starts with the key
    ``(0, 0)`` (a key at ``t = 0`` replaces it). The plugin adds them to a MotionBuilder
    F-curve; ours is a :class:`~fpdtw.warpcurve.WarpCurve` through the same keys. The
    plugin's minimum search starts from a cost of 1000 (a sample with no cheaper match
    maps to 0, then the clamp repeats the previous one); that cap depends on its scene's
    units and is not applied here.

    Parameters
    ----------
    A, B : Motion
        Recording and live motion.
    period : float, optional
        Sample period (s); default :func:`plugin_period` of A's frame rate.
    root_relative : bool
        Positions relative to the root, or in world space (the plugin's control rig: the
        default).

    Returns
    -------
    f : WarpCurve
        Live time -> recording time.

    Paper: the authors' MotionBuilder plugin (``EventButtonRunStandardDTW``); OPW
    poster eq. 5, Figs. 4-5.
    """
    P = plugin_period(A.fps) if period is None else float(period)
    if not P > 0:
        raise ValueError(f"period must be positive, got {P}")
    tA = np.arange(max(1, int(np.ceil(A.duration / P - 1e-9)))) * P
    tB = np.arange(max(1, int(np.ceil(B.duration / P - 1e-9)))) * P
    PA = _positions_at(A.positions(OPW_JOINTS, root_relative=root_relative), A.fps, tA)
    PB = _positions_at(B.positions(OPW_JOINTS, root_relative=root_relative), B.fps, tB)
    return best_match_warp(best_match_map(position_cost_matrix(PA, PB)), P, B.duration)


def best_match_warp(M, period: float, span: float | None = None) -> WarpCurve:
    """The plugin's baseline curve from its map: keys ``(M_i period, i period)``.

    The curve starts with the key ``(0, 0)``; each sample ``i`` of :func:`best_match_keys`
    adds the key ``(M_i period, i period)`` (a key at a time that has one already replaces
    it, as MotionBuilder's ``KeyAdd`` does). Key times increase with ``i`` because a kept
    sample is never followed by a repeat.

    Parameters
    ----------
    M : ndarray of int, shape (N,)
        :func:`best_match_map`.
    period : float
        Sample period (s).
    span : float, optional
        Live duration: where a curve left with one key (every kept sample at live time 0)
        ends; it then holds that key's value. Default ``period``.

    Returns
    -------
    f : WarpCurve
        Live time -> recording time.

    Paper: the authors' MotionBuilder plugin (``EventButtonRunStandardDTW``).
    """
    M = np.asarray(M, dtype=np.int64)
    keys = {0.0: 0.0}
    for i in best_match_keys(M):
        keys[float(M[i] * period)] = float(i * period)
    xs = sorted(keys)
    if len(xs) == 1:  # one key: the curve holds its value
        xs.append(max(period, span or period))
        keys[xs[1]] = keys[xs[0]]
    return WarpCurve(xs, [keys[x] for x in xs])


# -- measures -------------------------------------------------------------------------------------


def sample_times(duration: float, rate: float = SAMPLE_RATE) -> np.ndarray:
    """Sample times ``0, 1/rate, ...`` up to ``duration`` (included when on the grid).

    Returns
    -------
    t : ndarray of float64, shape (floor(duration * rate) + 1,)

    Paper: OPW poster Section 4 ("the curves were sampled at 50Hz").
    """
    n = int(np.floor(duration * rate + 1e-9)) + 1
    return np.arange(n) / rate


def deviation_ms(curve: WarpCurve, example: WarpCurve, rate: float = SAMPLE_RATE) -> dict:
    """|curve(t) - example(t)| in milliseconds at ``rate`` Hz over the example's span.

    Returns
    -------
    dev : dict
        ``t`` (N,) sample times (s), ``ms`` (N,) deviations, ``mean`` and ``max`` (ms).

    Paper: OPW poster Fig. 4 (middle row), Figs. 5 and 6.
    """
    t = sample_times(example.x[-1], rate)
    ms = 1000.0 * np.abs(curve(t) - example(t))
    return {"t": t, "ms": ms, "mean": float(ms.mean()), "max": float(ms.max())}


def slope_change_percent(curve: WarpCurve, rate: float = SAMPLE_RATE, duration=None) -> dict:
    """Change of the curve's slope angle between consecutive samples, in % of 90 degrees.

    The curve is sampled at ``rate`` Hz over ``[0, duration]`` (default: up to its last
    key); the angle of the chord between samples k and k+1 is
    ``atan2(dt', dt)``; the change at sample k (interior samples) is
    ``|angle_k - angle_{k-1}| / 90 deg * 100`` ("a 100 % change represents a 90 degree
    change in angle").

    Returns
    -------
    slope : dict
        ``t`` (N - 2,) the interior sample times, ``pct`` (N - 2,), ``mean``, ``max``.

    Paper: OPW poster Fig. 4 (bottom row).
    """
    duration = curve.x[-1] if duration is None else duration
    t = sample_times(duration, rate)
    y = curve(t)
    ang = np.degrees(np.arctan2(np.diff(y), np.diff(t)))
    pct = np.abs(np.diff(ang)) / 90.0 * 100.0
    return {
        "t": t[1:-1],
        "pct": pct,
        "mean": float(pct.mean()) if pct.size else 0.0,
        "max": float(pct.max()) if pct.size else 0.0,
    }


def temporal_difference_removed(
    curve: WarpCurve, example: WarpCurve, rate: float = SAMPLE_RATE
) -> float:
    """Share of the temporal difference between A and B that the curve removes.

    ``1 - mean_t |curve(t) - g(t)| / mean_t |t - g(t)|`` at ``rate`` Hz (g the example):
    the identity curve (no alignment) removes 0, the example itself 1. Our definition
    of the poster's "reduced the temporal difference between the motion sequences by
    approximately 70 %". NaN when the example is the identity (nothing to remove).

    Paper: OPW poster Section 5.
    """
    t = sample_times(example.x[-1], rate)
    g = example(t)
    base = np.abs(t - g).mean()
    if base <= 1e-12:
        return float("nan")
    return float(1.0 - np.abs(curve(t) - g).mean() / base)


# -- one motion, one configuration --------------------------------------------------------------


#: The methods every :func:`evaluate` result holds, besides the example curve.
METHODS = ("DTW", "best match", "OPW")


def run_opw(A, B, omega: float = OMEGA, gamma: float = GAMMA, reading="poster") -> OPW:
    """Run OPW aligning recording A to live motion B, frame by frame.

    Parameters
    ----------
    A, B : Motion
        Recording and live motion (any frame rates).
    reading : str or OPWReading
        ``"poster"`` or ``"plugin"`` (:data:`READINGS`), or a reading of its own.

    Returns
    -------
    aligner : OPW
        After the last frame of B: ``curve``, ``decisions``, ``M``.

    Paper: OPW poster Algorithm 1.
    """
    rd = as_reading(reading)
    I, T = opw_features(A, rd.root_relative), opw_features(B, rd.root_relative)
    aligner = OPW(I, omega=omega, gamma=gamma, fps=B.fps, **rd.options())
    run_online(aligner, T)
    return aligner


def evaluate(
    motion,
    offset: float = OFFSET,
    gamma: float = GAMMA,
    omega: float = OMEGA,
    crop: float | None = CROP_S,
    rate: float = SAMPLE_RATE,
    reading="poster",
) -> dict:
    """The poster's test on one motion: example warp, OPW and the baselines' curves, their
    measures.

    Parameters
    ----------
    motion : Motion
        The recording A (cropped here to ``[0, crop]`` s unless ``crop`` is None).
    offset, gamma, omega : float
        Example curve's middle offset (s), OPW's warp parameter and sample period (s).
    rate : float
        Sampling rate of the measures (Hz).
    reading : str or OPWReading
        How OPW is read and which positions every method compares (:data:`READINGS`).

    Returns
    -------
    result : dict
        ``name``, ``reading``, ``reference`` (OPW's), ``baseline`` (the reading's), ``offset``,
        ``gamma``,
        ``omega``, ``duration``; ``curves``: dict of WarpCurve ``"example"`` and one per
        method of :data:`METHODS` (``"DTW"``: :func:`dtw_curve`, ``"best match"``:
        :func:`best_match_curve`, ``"OPW"``); ``deviation`` and ``slope``: per method the
        dicts of :func:`deviation_ms` / :func:`slope_change_percent`; ``removed``: per
        method :func:`temporal_difference_removed`; ``decisions``: OPW's
        :meth:`~fpdtw.online.opw.OPW.decision_table`; ``M``: OPW's online map (frames).

    Paper: OPW poster Sections 4-5, Figs. 4-6.
    Notebook: 13_opw_fig4.ipynb
    """
    rd = as_reading(reading)
    A = motion if crop is None else motion.crop(0.0, crop)
    g = example_curve(A.duration, offset)
    B = warp_motion(A, g)
    base = _baselines(A, B, omega, rd)
    return _evaluate(motion.name, A, B, g, base, offset, gamma, omega, rate, rd)


def _baselines(A, B, omega, rd) -> dict:
    """The offline curves of a pair (they do not depend on gamma)."""
    return {
        "DTW": dtw_curve(A, B, omega, root_relative=rd.root_relative),
        "best match": best_match_curve(A, B, root_relative=rd.root_relative),
    }


def _evaluate(name, A, B, g, base, offset, gamma, omega, rate, rd) -> dict:
    opw = run_opw(A, B, omega, gamma, rd)
    curves = {"example": g, **base, "OPW": opw.curve}
    return {
        "name": name,
        "reading": rd.name,
        "reference": rd.reference,
        "baseline": rd.baseline,
        "offset": float(offset),
        "gamma": float(gamma),
        "omega": float(omega),
        "duration": float(A.duration),
        "curves": curves,
        "deviation": {k: deviation_ms(curves[k], g, rate) for k in METHODS},
        "slope": {
            k: slope_change_percent(curves[k], rate, duration=B.duration)
            for k in ("example",) + METHODS
        },
        "removed": {k: temporal_difference_removed(curves[k], g, rate) for k in METHODS},
        "decisions": opw.decision_table(),
        "M": opw.M.copy(),
    }


def reference_lag(result: dict) -> dict:
    """Where OPW read the recording at each step, and where its curve was, against the example.

    At a step at live time ``t`` OPW compares the forecast with the recording from the
    *reference time* on: ``f(t)`` (the poster reading: through the curve) or
    ``t D_A / x_last`` (the plugin: the global ratio, ``x_last`` before the step). Both are
    set against the example ``g(t)``, the time a perfect alignment would show.

    Parameters
    ----------
    result : dict
        An :func:`evaluate` result.

    Returns
    -------
    lag : dict
        ``t`` (N,) step times (s); ``reference_ms`` (N,) reference time minus ``g(t)`` and
        ``curve_ms`` (N,) ``f(t) - g(t)`` (the curve's value when the step was taken), in
        ms; ``reference_mean_abs_ms`` and ``curve_mean_abs_ms``, their mean magnitudes.

    Paper: OPW poster eq. 4; the authors' MotionBuilder plugin.
    Notebook: 13_opw_fig4.ipynb
    """
    dec = result["decisions"]
    g = result["curves"]["example"]
    t, tw = dec["t"], dec["t_warped"]
    if result.get("reference", "curve") == "ratio":
        before = np.r_[result["duration"], dec["x_last"][:-1]]
        ref = t * result["duration"] / before
    else:
        ref = tw
    ref_ms = 1000.0 * (ref - g(t))
    curve_ms = 1000.0 * (tw - g(t))
    return {
        "t": t,
        "reference_ms": ref_ms,
        "curve_ms": curve_ms,
        "reference_mean_abs_ms": float(np.abs(ref_ms).mean()) if t.size else 0.0,
        "curve_mean_abs_ms": float(np.abs(curve_ms).mean()) if t.size else 0.0,
    }


def summary_row(result: dict, label: str = "") -> list[dict]:
    """Per method one flat row of an :func:`evaluate` result (for tables and sweeps).

    Returns
    -------
    rows : list of dict
        For each method of :data:`METHODS`: ``motion, reading, method, offset_s, gamma,
        mean_ms, max_ms, slope_mean_pct, slope_max_pct, removed``.

    Paper: OPW poster Fig. 4.
    Notebook: 13_opw_fig4.ipynb
    """
    rows = []
    for k in METHODS:
        rows.append(
            {
                "motion": label or result["name"],
                "reading": result.get("reading", "poster"),
                "method": k,
                "offset_s": result["offset"],
                "gamma": result["gamma"],
                "mean_ms": result["deviation"][k]["mean"],
                "max_ms": result["deviation"][k]["max"],
                "slope_mean_pct": result["slope"][k]["mean"],
                "slope_max_pct": result["slope"][k]["max"],
                "removed": result["removed"][k],
            }
        )
    return rows


def sweep(
    motions: dict, offsets=(OFFSET,), gammas=(GAMMA,), omega: float = OMEGA, reading="poster"
) -> list:
    """:func:`evaluate` over every motion, offset and gamma.

    Parameters
    ----------
    motions : dict of str to Motion
        Label -> recording (already cropped or not; cropped to 2.5 s here).
    offsets, gammas : sequence of float
    reading : str or OPWReading
        See :func:`evaluate`.

    Returns
    -------
    rows : list of dict
        :func:`summary_row` rows plus ``ms``: the deviation samples (ndarray).

    Paper: OPW poster Figs. 5 and 6.
    Notebook: 14_opw_fig5_fig6.ipynb
    """
    rd = as_reading(reading)
    rows = []
    for label, motion in motions.items():
        A = motion.crop(0.0, CROP_S)
        for off in offsets:
            g = example_curve(A.duration, off)
            B = warp_motion(A, g)
            base = _baselines(A, B, omega, rd)  # once for every gamma
            for gam in gammas:
                res = _evaluate(motion.name, A, B, g, base, off, gam, omega, SAMPLE_RATE, rd)
                for row in summary_row(res, label):
                    row["ms"] = res["deviation"][row["method"]]["ms"]
                    rows.append(row)
    return rows


def pooled(rows: list, method: str, **match) -> dict:
    """Pool the :func:`sweep` rows of one method whose fields equal ``match``.

    Returns
    -------
    stats : dict
        ``mean_ms`` and ``max_ms`` over all the rows' deviation samples pooled, ``removed``
        the mean share removed, ``n`` the number of rows (motions) pooled.

    Paper: OPW poster Figs. 5 and 6 ("each offset value was applied to all three motions
    and the results combined").
    """
    sel = [
        r
        for r in rows
        if r["method"] == method and all(np.isclose(r[k], v) for k, v in match.items())
    ]
    if not sel:
        raise ValueError(f"no {method} rows with {match}")
    ms = np.concatenate([r["ms"] for r in sel])
    return {
        "mean_ms": float(ms.mean()),
        "max_ms": float(ms.max()),
        "removed": float(np.mean([r["removed"] for r in sel])),
        "n": len(sel),
    }


# -- for the experiment runner and the benchmark ---------------------------------------------


def opw_align(I: MotionFeatures, T: MotionFeatures, omega: float = OMEGA, gamma: float = GAMMA):
    """OPW over a pair, for the experiment runner's ``register_algorithm``.

    Parameters
    ----------
    I, T : MotionFeatures
        Input (recording) and target (live) motions, both WITH ``positions``.

    Returns
    -------
    M : ndarray of int64, shape (n + 1,)
        Input frame mapped to each target frame.
    seconds : ndarray of float64, shape (n + 1,)
        Wall time of each ``step`` (not deterministic).

    Paper: OPW poster Algorithm 1.
    """
    return run_online(OPW(I, omega=omega, gamma=gamma, fps=T.fps), T)


def opw_pair(I: MotionFeatures, T: MotionFeatures, pair_info=None):
    """OPW with the poster's parameters (omega 0.04 s, gamma 5 %) over one pair.

    The experiment runner's hook (:func:`fpdtw.paper.runner.run.register_algorithm`):
    ``(M, seconds)`` as :func:`opw_align`.
    """
    return opw_align(I, T)


def _r(v, digits=3):
    return None if v is None else round(float(v), digits)


def fig4_facts(rows: list, motions: dict, baseline: str = "DTW") -> dict:
    """The facts of poster Fig. 4 (notebook 13, and the claims table): ours and the poster's.

    Parameters
    ----------
    rows : list of dict
        :func:`summary_row` rows of every motion (one reading).
    motions : dict of str to OPWMotion
        Label -> the motion's entry (:data:`FIG4_MOTIONS`).
    baseline : str
        The method standing for the poster's DTW: ``"DTW"`` (the poster reading) or
        ``"best match"`` (the plugin's).

    Returns
    -------
    facts : dict
        ``opw_mean_ms_range``, ``opw_max_ms``, ``dtw_mean_ms_range`` (ms: the baseline's),
        ``opw_removed_mean``, ``dtw_better_everywhere`` (the baseline's mean deviation below
        OPW's on every motion), ``opw_smoother_everywhere`` (OPW's largest slope change
        below the baseline's), ``baseline``, ``per_motion`` and ``poster`` (the poster's
        numbers, from :mod:`fpdtw.paper.numbers`).

    Paper: OPW poster Section 5 and Fig. 4.
    Notebook: 13_opw_fig4.ipynb
    """
    opw = [r for r in rows if r["method"] == "OPW"]
    dtw = [r for r in rows if r["method"] == baseline]
    if not opw or len(dtw) != len(opw):
        raise ValueError(f"need one OPW and one {baseline!r} row per motion")
    keys = ("mean_ms", "max_ms", "slope_mean_pct", "slope_max_pct", "removed")
    return {
        "motions": {lab: {"dataset": m.dataset, "path": m.path} for lab, m in motions.items()},
        "per_motion": {
            f"{r['motion']} {r['method']}": {k: _r(r[k], 4) for k in keys} for r in rows
        },
        "opw_mean_ms_range": [_r(min(r["mean_ms"] for r in opw), 1),
                              _r(max(r["mean_ms"] for r in opw), 1)],
        "opw_max_ms": _r(max(r["max_ms"] for r in opw), 1),
        "dtw_mean_ms_range": [_r(min(r["mean_ms"] for r in dtw), 1),
                              _r(max(r["mean_ms"] for r in dtw), 1)],
        "opw_removed_mean": _r(np.mean([r["removed"] for r in opw])),
        "dtw_better_everywhere": all(d["mean_ms"] < o["mean_ms"] for d, o in zip(dtw, opw)),
        "opw_smoother_everywhere": all(
            o["slope_max_pct"] < d["slope_max_pct"] for d, o in zip(dtw, opw)
        ),
        "baseline": baseline,
        "poster": {
            "opw_mean_ms_range": list(numbers.OPW_MEAN_DEVIATION_MS),
            "opw_max_ms": numbers.OPW_MAX_DEVIATION_MS,
        },
    }  # fmt: skip


def fig5_fig6_facts(
    rows5: list, offsets, rows6: list, gammas, gamma=GAMMA, baseline: str = "DTW"
) -> dict:
    """The facts of poster Figs. 5 and 6 (notebook 14, and the claims table).

    Parameters
    ----------
    rows5 : list of dict
        :func:`sweep` rows over ``offsets`` at ``gamma`` (Fig. 5).
    rows6 : list of dict
        :func:`sweep` rows over ``gammas`` at the poster's offset (Fig. 6).
    baseline : str
        The method beside OPW in the Fig. 5 table (``"DTW"`` or ``"best match"``).

    Returns
    -------
    facts : dict
        ``largest_offset_max_below_150ms_s`` and ``..._mean_...`` (the largest offset whose
        pooled maximum / mean deviation stays below 150 ms; None if none),
        ``removed_gamma5_range_over_offsets``, ``removed_gamma5_mean_over_offsets``,
        ``removed_gamma5_at_offset`` (at the poster's 0.25 s, if swept), ``best_gamma``
        (lowest pooled mean deviation), ``removed_best_gamma``,
        ``max_ms_at_offset_best_gamma``, the tables ``fig5`` and ``fig6``, and ``poster``
        (from :mod:`fpdtw.paper.numbers`).

    Paper: OPW poster Section 5, Figs. 5 and 6.
    Notebook: 14_opw_fig5_fig6.ipynb
    """
    opw5 = {o: pooled(rows5, "OPW", offset_s=o) for o in offsets}
    ok_max = [o for o in offsets if opw5[o]["max_ms"] < HOYET_MS]
    ok_mean = [o for o in offsets if opw5[o]["mean_ms"] < HOYET_MS]
    removed5 = [opw5[o]["removed"] for o in offsets]
    table5 = [
        {"offset_s": o, "method": k, **pooled(rows5, k, offset_s=o)}
        for o in offsets
        for k in (baseline, "OPW")
    ]
    table6 = [{"gamma": g, **pooled(rows6, "OPW", gamma=g)} for g in gammas]
    best = min(table6, key=lambda r: r["mean_ms"])
    at = next((o for o in offsets if np.isclose(o, OFFSET)), None)

    def plain(rows):
        return [{k: _r(v) if isinstance(v, float) else v for k, v in r.items()} for r in rows]

    return {
        "baseline": baseline,
        "gamma_fig5": gamma,
        "fig5": plain(table5),
        "fig6": plain(table6),
        "largest_offset_max_below_150ms_s": max(ok_max) if ok_max else None,
        "largest_offset_mean_below_150ms_s": max(ok_mean) if ok_mean else None,
        "removed_gamma5_range_over_offsets": [_r(min(removed5)), _r(max(removed5))],
        "removed_gamma5_mean_over_offsets": _r(np.mean(removed5)),
        "removed_gamma5_at_offset": None if at is None else _r(opw5[at]["removed"]),
        "best_gamma": _r(best["gamma"]),
        "removed_best_gamma": _r(best["removed"]),
        "max_ms_at_offset_best_gamma": _r(best["max_ms"]),
        "poster": {
            "removed_gamma5": numbers.OPW_REMOVED_GAMMA5,
            "removed_best": numbers.OPW_REMOVED_BEST_GAMMA,
            "best_gamma": numbers.OPW_BEST_GAMMA,
            "largest_offset_max_below_150ms_s": numbers.OPW_OFFSET_MAX_OK_S,
            "largest_offset_mean_below_150ms_s": numbers.OPW_OFFSET_MEAN_OK_S,
        },
    }


#: Columns of the readings table (:func:`readings_table`, ``figures/opw_readings``).
#: The two readings of where OPW reads the recording (:func:`fpdtw.plain.opw_times`).
READ_AT_READINGS = (
    OPWReading("poster, eq. 4: f(t) + i omega"),
    OPWReading("poster, listing: f(t + i omega)", read_at="listing"),
)


def read_at_table(motions=None, offset: float = OFFSET, gamma: float = GAMMA) -> list[dict]:
    """Both readings of where OPW reads the recording, on the poster's protocol.

    Each of Fig. 4's motions (cropped to 2.5 s) is warped by the example curve (middle
    key offset by ``offset``) and aligned by OPW under each of :data:`READ_AT_READINGS`;
    everything else is the poster reading.

    Parameters
    ----------
    motions : sequence of OPWMotion, optional
        Default :data:`FIG4_MOTIONS`.
    offset, gamma : float

    Returns
    -------
    rows : list of dict
        One per motion and reading: ``read_at``, ``motion``, ``opw_mean_ms`` and
        ``opw_max_ms`` (deviation from the example curve, :func:`deviation_ms`),
        ``opw_removed`` (:func:`temporal_difference_removed`) and ``steps_changed`` (OPW's
        steps with ``s != 1``).

    Paper: OPW poster eq. 4 and Algorithm 1, lines 2-3; Section 4's protocol (Fig. 4).
    Notebook: 13_opw_fig4.ipynb
    """
    rows = []
    for mo in motions or FIG4_MOTIONS:
        A = load_cropped(mo.dataset, mo.path)
        g = example_curve(A.duration, offset)
        B = warp_motion(A, g)
        for rd in READ_AT_READINGS:
            opw = run_opw(A, B, OMEGA, gamma, rd)
            dev = deviation_ms(opw.curve, g)
            rows.append({
                "read_at": rd.read_at,
                "motion": mo.label,
                "opw_mean_ms": dev["mean"],
                "opw_max_ms": dev["max"],
                "opw_removed": temporal_difference_removed(opw.curve, g),
                "steps_changed": int(sum(d.s != 1 for d in opw.decisions)),
            })  # fmt: skip
    return rows


READINGS_COLUMNS = ("reading", "motion", "opw_mean_ms", "opw_max_ms", "opw_removed",
                    "best_gamma", "best_gamma_mean_ms", "best_gamma_removed", "baseline",
                    "baseline_mean_ms", "baseline_max_ms", "baseline_removed")  # fmt: skip


def readings_table(sweeps, gamma: float = GAMMA) -> list[dict]:
    """Per reading and motion, and all motions pooled: OPW at ``gamma``, OPW at its best
    gamma, and the reading's baseline.

    Parameters
    ----------
    sweeps : sequence of (OPWReading, list of dict)
        Each reading with its :func:`sweep` rows over gammas at one offset (the Fig. 6
        sweep); ``gamma`` must be among the gammas.
    gamma : float
        The gamma of the first columns (the poster's Figs. 4-5: 5 %).

    Returns
    -------
    rows : list of dict
        Keys :data:`READINGS_COLUMNS`; ``motion`` ``"all"`` pools the motions as
        :func:`pooled` (mean and max over every 50 Hz sample, mean of the shares removed).
        The best gamma has the lowest mean deviation (the first on ties); the baseline
        does not depend on gamma.

    Paper: OPW poster Section 5, Figs. 4-6; the authors' MotionBuilder plugin.
    Notebook: 14_opw_fig5_fig6.ipynb
    """
    out = []
    for rd, rows in sweeps:
        rd = as_reading(rd)
        gammas = sorted({r["gamma"] for r in rows})
        if not any(np.isclose(g, gamma) for g in gammas):
            raise ValueError(f"reading {rd.name!r}: gamma {gamma} is not among {gammas}")
        labels = list(dict.fromkeys(r["motion"] for r in rows))
        for label in labels + ["all"]:
            sel = [r for r in rows if label in ("all", r["motion"])]
            opw = pooled(sel, "OPW", gamma=gamma)
            per_gamma = [(pooled(sel, "OPW", gamma=g), g) for g in gammas]
            best, g_best = min(per_gamma, key=lambda x: x[0]["mean_ms"])
            base = pooled(sel, rd.baseline, gamma=gamma)
            out.append(
                {
                    "reading": rd.name,
                    "motion": label,
                    "opw_mean_ms": _r(opw["mean_ms"], 1),
                    "opw_max_ms": _r(opw["max_ms"], 1),
                    "opw_removed": _r(opw["removed"]),
                    "best_gamma": _r(g_best),
                    "best_gamma_mean_ms": _r(best["mean_ms"], 1),
                    "best_gamma_removed": _r(best["removed"]),
                    "baseline": rd.baseline,
                    "baseline_mean_ms": _r(base["mean_ms"], 1),
                    "baseline_max_ms": _r(base["max_ms"], 1),
                    "baseline_removed": _r(base["removed"]),
                }
            )
    return out


__all__ = [
    "METHODS",
    "READINGS",
    "READINGS_COLUMNS",
    "READING_STEPS",
    "OPWReading",
    "as_reading",
    "best_match_curve",
    "best_match_keys",
    "best_match_map",
    "best_match_warp",
    "plugin_period",
    "readings_table",
    "reference_lag",
    "fig4_facts",
    "fig5_fig6_facts",
    "CROP_S",
    "FIG4_MOTIONS",
    "READ_AT_READINGS",
    "read_at_table",
    "GAMMA",
    "HOYET_MS",
    "OFFSET",
    "OMEGA",
    "SAMPLE_RATE",
    "OPWMotion",
    "deviation_ms",
    "dtw_curve",
    "evaluate",
    "example_curve",
    "fig3_key_points",
    "load_cropped",
    "opw_align",
    "opw_features",
    "pooled",
    "run_opw",
    "sample_times",
    "slope_change_percent",
    "summary_row",
    "sweep",
    "temporal_difference_removed",
    "warp_motion",
]
