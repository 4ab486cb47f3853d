"""The OPW poster's evaluation: a known example warp, OPW and offline baselines against it.

Protocol (poster Sections 4-5; ``notebooks/reading_notes.md``): motion A cropped to 2.5 s,
warped by the example curve g into ``B(t) = A(g(t))``, aligned to B by OPW and by offline
DTW smoothed by the poster's Fig. 3 rule; each curve measured against g at 50 Hz.

Two readings of the whole protocol (:data:`READINGS`): ``"poster"``, the poster's text as
:mod:`fpdtw.online.opw` reads it, and ``"plugin"``, as the authors' MotionBuilder plugin
(matRandall/realTimeDTW) runs it (:class:`OPWReading`: what differs). Where OPW reads the
recording is a switch of its own: ``read_at="eq4"`` (default) or ``"listing"``
(:data:`READ_AT_READINGS`, :func:`read_at_table`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from fpdtw.costs import position_cost_matrix
from fpdtw.dtw import dtw
from fpdtw.motion.features import MotionFeatures
from fpdtw.motion.joints import OPW_JOINTS
from fpdtw.motion.motion import sample_points
from fpdtw.online.base import run_online
from fpdtw.online.opw import OPW
from fpdtw.paper import numbers
from fpdtw.paper.catalog import load
from fpdtw.warpcurve import WarpCurve

# The poster's protocol (what each is, and where printed: fpdtw.paper.numbers).
OMEGA, GAMMA, CROP_S = numbers.OPW_OMEGA_S, numbers.OPW_GAMMA, numbers.OPW_CROP_S
SAMPLE_RATE, OFFSET = numbers.OPW_SAMPLE_RATE_HZ, numbers.OPW_OFFSET_S
HOYET_MS = numbers.PERCEPTUAL_THRESHOLD_MS


@dataclass(frozen=True)
class OPWReading:
    """One reading of OPW and its evaluation: ``reference``, ``clock``, ``direction`` and
    ``read_at`` are :class:`fpdtw.online.opw.OPW`'s options; ``root_relative``: positions
    relative to the root (poster) or world (plugin); ``baseline``: ``"DTW"`` (the poster's
    Fig. 3 curve) or ``"best match"`` (the plugin's "standard DTW": :func:`best_match_curve`).
    The plugin reads with global-ratio reference times, the frame clock and world positions.
    """

    name: str
    reference: str = "curve"
    clock: str = "exact"
    direction: str = "code"
    root_relative: bool = True
    baseline: str = "DTW"
    read_at: str = "eq4"


#: The two readings of the protocol (module doc).
READINGS = {
    "poster": OPWReading("poster"),
    "plugin": OPWReading("plugin", "ratio", "frames", "code", False, "best match"),
}

#: From the poster reading to the plugin's, one mechanism at a time, then the plugin with
#: its readme's direction.
READING_STEPS = (
    READINGS["poster"],
    OPWReading("poster + ratio reference", reference="ratio"),
    OPWReading("poster + frame clock", clock="frames"),
    OPWReading("poster + world positions", root_relative=False),
    READINGS["plugin"],
    replace(READINGS["plugin"], name="plugin, readme direction", direction="readme"),
)

#: The two readings of where OPW reads the recording (:func:`fpdtw.plain.opw_times`).
READ_AT_READINGS = (
    OPWReading("poster, eq. 4: f(t) + i omega"),
    OPWReading("poster, listing: f(t + i omega)", read_at="listing"),
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
    """A motion of the poster's Fig. 4 or our stand-in: label, catalog place, why chosen."""

    label: str
    dataset: str
    path: str
    why: str


#: Fig. 4's three motions. Only the hand shake is the poster's own source (CMU 18_01,
#: subject A); the stand-ins follow a rule committed with them in 4d74569, before any OPW
#: result (docs/history.md): an upper-body, non-contact gesture clip of at least 2.5 s,
#: and a clip of sustained two-arm work in place.
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


def example_curve(duration: float = CROP_S, offset: float = OFFSET) -> WarpCurve:
    """The poster's example warp g (live -> recording): keys (0, 0), (D/2, D/2 + offset), (D, D).

    Paper: OPW poster Section 5, Figs. 4 and 5.
    Notebook: 13_opw_fig4.ipynb
    """
    d = float(duration)
    if not 0 <= offset < d / 2 or not d > 0:
        raise ValueError(f"need duration > 0 and 0 <= offset < duration / 2, got {d}, {offset}")
    return WarpCurve([0.0, d / 2, d], [0.0, d / 2 + offset, d])


def warp_motion(motion, curve: WarpCurve):
    """The warped motion ``B(t) = A(curve(t))``, at A's rate (:meth:`Motion.retime`).

    Paper: OPW poster Section 4.
    Notebook: 13_opw_fig4.ipynb
    """
    fps = float(motion.fps)
    t = sample_times(curve.x[-1], fps)
    return motion.retime(curve(t), fps=fps, name=f"{motion.name}_warped")


def opw_features(motion, root_relative: bool = True) -> MotionFeatures:
    """Features with the 16 OPW joints' positions, (F, 16, 3) float64, root-relative or world.

    Paper: OPW poster Section 4 (16 joints), eq. 5.
    Notebook: 13_opw_fig4.ipynb
    """
    if root_relative:
        return MotionFeatures.from_motion(motion, position_joints=OPW_JOINTS)
    feats = MotionFeatures.from_motion(motion)
    P = motion.positions(OPW_JOINTS, root_relative=False)
    return replace(feats, positions=np.ascontiguousarray(P, dtype=np.float64))


def load_cropped(dataset: str, path: str):
    """A motion of the catalog cropped to its first :data:`CROP_S` seconds.

    Paper: OPW poster Section 4 ("cropped at 2.5 seconds").
    Notebook: 13_opw_fig4.ipynb
    """
    return load(dataset, path).crop(0.0, CROP_S)


def fig3_key_points(path, max_run: int | None = 2) -> np.ndarray:
    """Indices (int64, increasing) into a DTW path (L, 2) of the points the poster's Fig. 3
    rule keeps as curve keys: those after a run of 1..``max_run`` non-diagonal steps (the
    poster: "1 or 2"; None: any) and before a diagonal one, and both end points.

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


def dtw_curve(A, B, omega: float = OMEGA, root_relative: bool = True) -> WarpCurve:
    """Offline DTW of recording A against live B at ``1 / omega`` Hz (the poster does not
    state DTW's rate), smoothed into a curve (live -> recording time) by the Fig. 3 rule:
    keys :func:`fig3_key_points` at ``(j omega, i omega)``, then the true end ``(D_B, D_A)``.

    Paper: OPW poster Section 4, Fig. 3, eq. 5.
    """
    P = [M.resample(1.0 / omega).positions(OPW_JOINTS, root_relative=root_relative) for M in (A, B)]
    res = dtw(position_cost_matrix(*P))
    xs, ys = [], []
    for i, j in res.path[fig3_key_points(res.path)][:-1]:
        if (not xs or j * omega > xs[-1]) and j * omega < B.duration:
            xs.append(j * omega)
            ys.append(i * omega)
    if not xs:
        xs, ys = [0.0], [0.0]
    return WarpCurve(xs + [B.duration], ys + [A.duration])


def plugin_period(fps: float) -> float:
    """The plugin's sample period (s): one frame in whole milliseconds (8 ms at 120 Hz)."""
    return math.floor(1000.0 / float(fps) + 1e-9) / 1000.0


def _plugin_positions(motion, period: float, root_relative: bool) -> np.ndarray:
    """OPW joints' positions (F, 16, 3) every ``period`` s, linear between frames, clamped."""
    times = np.arange(max(1, int(np.ceil(motion.duration / period - 1e-9)))) * period
    P = motion.positions(OPW_JOINTS, root_relative=root_relative)
    i0, i1, a = sample_points(np.clip(times * motion.fps, 0.0, P.shape[0] - 1), P.shape[0])
    a = a[:, None, None]
    return (1.0 - a) * P[i0] + a * P[i1]


def best_match_map(C) -> np.ndarray:
    """The plugin's baseline map, int64 (N_A,), from costs ``C`` (N_A, N_B): ``M_0 =
    best_0``, ``M_i = min(max(best_i, M_{i-1}), M_{i-1} + 2)``, ``best_i`` row i's argmin.

    Paper: the authors' MotionBuilder plugin (``EventButtonRunStandardDTW``).
    """
    best = np.argmin(np.asarray(C, dtype=float), axis=1)
    M = np.empty(best.size, dtype=np.int64)
    M[0] = best[0]
    for i in range(1, best.size):
        M[i] = min(max(int(best[i]), M[i - 1]), M[i - 1] + 2)
    return M


def best_match_keys(M) -> np.ndarray:
    """The samples (int64, increasing) of a :func:`best_match_map` the plugin makes keys:
    ``i >= 1`` with ``M_i != M_{i-1} + 1`` whose next sample does not repeat it, and the last.

    Paper: the authors' MotionBuilder plugin (``EventButtonRunStandardDTW``).
    """
    M = np.asarray(M, dtype=np.int64)
    n = M.size
    keep = [i for i in range(1, n - 1) if M[i] != M[i - 1] + 1 and M[i + 1] != M[i]]
    return np.asarray(keep + [n - 1], dtype=np.int64)


def best_match_curve(A, B, root_relative: bool = False) -> WarpCurve:
    """The plugin's "standard DTW" baseline: a monotone per-sample best match as a curve,
    both motions sampled every :func:`plugin_period` (eq. 5, world positions by default).
    The plugin's minimum search starts from a cost of 1000, a cap not applied here.

    Paper: the authors' MotionBuilder plugin (``EventButtonRunStandardDTW``); OPW poster
    eq. 5, Figs. 4-5.
    """
    P = plugin_period(A.fps)
    if not P > 0:
        raise ValueError(f"period must be positive, got {P}")
    C = position_cost_matrix(*(_plugin_positions(M, P, root_relative) for M in (A, B)))
    return best_match_warp(best_match_map(C), P, B.duration)


def best_match_warp(M, period: float, span: float | None = None) -> WarpCurve:
    """The plugin's baseline curve: key (0, 0), then ``(M_i period, i period)`` for each
    :func:`best_match_keys` sample (a later key at the same time replaces it, as ``KeyAdd``);
    one key alone holds up to ``span`` (default ``period``).

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


def sample_times(duration: float, rate: float = SAMPLE_RATE) -> np.ndarray:
    """Times ``k / rate`` from 0 up to ``duration`` (included on the grid), float64.

    Paper: OPW poster Section 4 ("the curves were sampled at 50Hz").
    """
    n = int(np.floor(duration * rate + 1e-9)) + 1
    return np.arange(n) / rate


def deviation_ms(curve: WarpCurve, example: WarpCurve, rate: float = SAMPLE_RATE) -> dict:
    """|curve - example| in ms at ``rate`` Hz over the example's span: ``t``, ``ms``, mean, max.

    Paper: OPW poster Fig. 4 (middle row), Figs. 5 and 6.
    """
    t = sample_times(example.x[-1], rate)
    ms = 1000.0 * np.abs(curve(t) - example(t))
    return {"t": t, "ms": ms, "mean": float(ms.mean()), "max": float(ms.max())}


def slope_change_percent(curve: WarpCurve, duration=None) -> dict:
    """Change of the chord angle between 50 Hz samples over ``[0, duration]`` (default: to
    the last key), in % of 90 degrees: ``t`` and ``pct`` (N - 2,), ``mean``, ``max``.

    Paper: OPW poster Fig. 4 (bottom row).
    """
    t = sample_times(curve.x[-1] if duration is None else duration)
    y = curve(t)
    ang = np.degrees(np.arctan2(np.diff(y), np.diff(t)))
    pct = np.abs(np.diff(ang)) / 90.0 * 100.0
    return {
        "t": t[1:-1],
        "pct": pct,
        "mean": float(pct.mean()) if pct.size else 0.0,
        "max": float(pct.max()) if pct.size else 0.0,
    }


def temporal_difference_removed(curve: WarpCurve, example: WarpCurve) -> float:
    """Share of the temporal difference the curve removes, ``1 - mean |curve(t) - g(t)| /
    mean |t - g(t)|`` at 50 Hz (NaN when g is the identity): our reading of the poster's
    "reduced the temporal difference ... by approximately 70 %".

    Paper: OPW poster Section 5.
    """
    t = sample_times(example.x[-1])
    g = example(t)
    base = np.abs(t - g).mean()
    if base <= 1e-12:
        return float("nan")
    return float(1.0 - np.abs(curve(t) - g).mean() / base)


#: The methods every :func:`evaluate` result holds, besides the example curve.
METHODS = ("DTW", "best match", "OPW")


def run_opw(A, B, omega: float = OMEGA, gamma: float = GAMMA, reading="poster") -> OPW:
    """OPW aligning recording A to live B under a reading (:func:`as_reading`); the aligner.

    Paper: OPW poster Algorithm 1.
    """
    rd = as_reading(reading)
    I, T = opw_features(A, rd.root_relative), opw_features(B, rd.root_relative)
    aligner = OPW(
        I, omega=omega, gamma=gamma, fps=B.fps, reference=rd.reference, clock=rd.clock,
        direction=rd.direction, read_at=rd.read_at,
    )  # fmt: skip
    run_online(aligner, T)
    return aligner


def evaluate(
    motion, offset: float = OFFSET, gamma: float = GAMMA, omega: float = OMEGA, reading="poster"
) -> dict:
    """The poster's test on one motion cropped to 2.5 s: the parameters, ``curves`` (``"example"``,
    :data:`METHODS`), per method ``deviation``, ``slope``, ``removed``; OPW's ``decisions``, ``M``.

    Paper: OPW poster Sections 4-5, Figs. 4-6.
    Notebook: 13_opw_fig4.ipynb
    """
    return next(_runs({"": motion}, (offset,), (gamma,), omega, as_reading(reading)))[1]


def _runs(motions: dict, offsets, gammas, omega, rd):
    """``(label, result)`` of :func:`evaluate` per motion, offset and gamma."""
    for label, motion in motions.items():
        A = motion.crop(0.0, CROP_S)
        for offset in offsets:
            g = example_curve(A.duration, offset)
            B = warp_motion(A, g)
            base = {
                "DTW": dtw_curve(A, B, omega, root_relative=rd.root_relative),
                "best match": best_match_curve(A, B, root_relative=rd.root_relative),
            }
            for gamma in gammas:
                opw = run_opw(A, B, omega, gamma, rd)
                curves = {"example": g, **base, "OPW": opw.curve}
                res = {
                    "name": motion.name,
                    "reading": rd.name,
                    "reference": rd.reference,
                    "baseline": rd.baseline,
                    "offset": float(offset),
                    "gamma": float(gamma),
                    "omega": float(omega),
                    "duration": float(A.duration),
                    "curves": curves,
                    "deviation": {k: deviation_ms(curves[k], g) for k in METHODS},
                    "slope": {
                        k: slope_change_percent(curves[k], duration=B.duration)
                        for k in ("example",) + METHODS
                    },
                    "removed": {k: temporal_difference_removed(curves[k], g) for k in METHODS},
                    "decisions": opw.decision_table(),
                    "M": opw.M.copy(),
                }
                yield label, res


def reference_lag(result: dict) -> dict:
    """Where OPW read the recording at each step (``f(t)``, or the plugin's ``t D_A /
    x_last``) and where its curve was, against g: ``t`` (s), ``reference_ms``,
    ``curve_ms`` and their mean magnitudes ``*_mean_abs_ms``.

    Paper: OPW poster eq. 4; the authors' MotionBuilder plugin.
    Notebook: 13_opw_fig4.ipynb
    """
    dec = result["decisions"]
    t, tw = dec["t"], dec["t_warped"]
    ref = tw
    if result["reference"] == "ratio":
        ref = t * result["duration"] / np.r_[result["duration"], dec["x_last"][:-1]]
    g = result["curves"]["example"](t)
    out = {"t": t}
    for name, times in (("reference", ref), ("curve", tw)):
        ms = 1000.0 * (times - g)
        out[f"{name}_ms"] = ms
        out[f"{name}_mean_abs_ms"] = float(np.abs(ms).mean()) if t.size else 0.0
    return out


def summary_row(result: dict, label: str) -> list[dict]:
    """One flat row per method of an :func:`evaluate` result.

    Paper: OPW poster Fig. 4.
    Notebook: 13_opw_fig4.ipynb
    """
    return [
        {
            "motion": label,
            "reading": result["reading"],
            "method": k,
            "offset_s": result["offset"],
            "gamma": result["gamma"],
            "mean_ms": result["deviation"][k]["mean"],
            "max_ms": result["deviation"][k]["max"],
            "slope_mean_pct": result["slope"][k]["mean"],
            "slope_max_pct": result["slope"][k]["max"],
            "removed": result["removed"][k],
        }
        for k in METHODS
    ]


def sweep(
    motions: dict, offsets=(OFFSET,), gammas=(GAMMA,), omega: float = OMEGA, reading="poster"
) -> list:
    """:func:`summary_row` rows of :func:`evaluate` per motion, offset and gamma, with ``ms``.

    Paper: OPW poster Figs. 5 and 6.
    Notebook: 14_opw_fig5_fig6.ipynb
    """
    rows = []
    for label, res in _runs(motions, offsets, gammas, omega, as_reading(reading)):
        for row in summary_row(res, label):
            rows.append(row | {"ms": res["deviation"][row["method"]]["ms"]})
    return rows


def pooled(rows: list, method: str, **match) -> dict:
    """The :func:`sweep` rows of one method matching ``match``, pooled: ``mean_ms``,
    ``max_ms``, ``removed`` (mean) and ``n``.

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


def _r(v, digits=3):
    return round(float(v), digits)


def _range(rows, key, digits):
    return [_r(min(r[key] for r in rows), digits), _r(max(r[key] for r in rows), digits)]


def fig4_facts(rows: list, motions: dict, baseline: str = "DTW") -> dict:
    """The facts of poster Fig. 4, ours and the poster's, from the :func:`summary_row` rows
    of every motion (one reading; ``baseline`` stands for the poster's DTW).

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
        "opw_mean_ms_range": _range(opw, "mean_ms", 1),
        "opw_max_ms": _r(max(r["max_ms"] for r in opw), 1),
        "dtw_mean_ms_range": _range(dtw, "mean_ms", 1),
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
    }


def fig5_fig6_facts(
    rows5: list, offsets, rows6: list, gammas, gamma=GAMMA, baseline: str = "DTW"
) -> dict:
    """The facts of poster Figs. 5 and 6, ours and the poster's, from the :func:`sweep` rows
    over ``offsets`` at ``gamma`` (Fig. 5) and over ``gammas`` at the poster's offset (Fig. 6).

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
        "largest_offset_max_below_150ms_s": max(ok_max, default=None),
        "largest_offset_mean_below_150ms_s": max(ok_mean, default=None),
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


def read_at_table(offset: float = OFFSET, gamma: float = GAMMA) -> list[dict]:
    """Both :data:`READ_AT_READINGS` on each of Fig. 4's motions: per motion and reading
    OPW's deviation, share removed and ``steps_changed`` (steps with ``s != 1``).

    Paper: OPW poster eq. 4 and Algorithm 1, lines 2-3; Section 4's protocol (Fig. 4).
    Notebook: 13_opw_fig4.ipynb
    """
    rows = []
    for mo in FIG4_MOTIONS:
        motion = load(mo.dataset, mo.path)
        for rd in READ_AT_READINGS:
            res = evaluate(motion, offset, gamma, OMEGA, rd)
            rows.append({
                "read_at": rd.read_at,
                "motion": mo.label,
                "opw_mean_ms": res["deviation"]["OPW"]["mean"],
                "opw_max_ms": res["deviation"]["OPW"]["max"],
                "opw_removed": res["removed"]["OPW"],
                "steps_changed": int(np.sum(res["decisions"]["s"] != 1)),
            })  # fmt: skip
    return rows


#: Columns of :func:`readings_table` (``figures/opw_readings``).
READINGS_COLUMNS = ("reading", "motion", "opw_mean_ms", "opw_max_ms", "opw_removed",
                    "best_gamma", "best_gamma_mean_ms", "best_gamma_removed", "baseline",
                    "baseline_mean_ms", "baseline_max_ms", "baseline_removed")  # fmt: skip


def readings_table(sweeps, gamma: float = GAMMA) -> list[dict]:
    """Rows (:data:`READINGS_COLUMNS`) per reading and motion and pooled (``"all"``): OPW at
    ``gamma`` and at its best gamma, and the baseline, from ``(reading, sweep rows)`` pairs.

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
            values = (rd.name, label, _r(opw["mean_ms"], 1), _r(opw["max_ms"], 1),
                      _r(opw["removed"]), _r(g_best), _r(best["mean_ms"], 1),
                      _r(best["removed"]), rd.baseline, _r(base["mean_ms"], 1),
                      _r(base["max_ms"], 1), _r(base["removed"]))  # fmt: skip
            out.append(dict(zip(READINGS_COLUMNS, values, strict=True)))
    return out
