"""Every value quoted from the two papers, with where it is printed, and the paper's pass rule.

FP-DTW: Randall, Harvey, Williams, "Online alignment of human motion using forward
plotting-dynamic time warping", Computer Animation and Virtual Worlds 34(3) e2166, 2023.
OPW: Randall, Harvey, Williams, "A Predictive Approach to On-line Time Warping of Motion"
(poster).

Notebook: 05_run_experiments.ipynb
"""

from __future__ import annotations

# -- FP-DTW: the evaluation (Section 4) ---------------------------------------------------------

#: Section 4: "333 recorded motions of 44 different movements ... 3248 pairs".
DATA = {"motions": 333, "movements": 44, "pairs": 3248}
#: Section 4: "Fifty seven from Reference 8 and 267 from widely used HDM05 dataset" (the
#: authors' takes and HDM05's motions; as printed they add up to 324, not 333).
DATA_SOURCES = {"authors_fbx": 57, "hdm05": 267}
#: Section 4: the motions were sampled at 120 Hz.
SAMPLE_RATE_HZ = 120
#: Section 4: "the period of a typical walking gait is between 0.82 and 0.9 Hz" (a gait
#: frequency: one cycle of 133-146 frames at 120 Hz, half a cycle "67-73 frames").
WALK_GAIT_HZ = (0.82, 0.9)
#: Section 4: "Methods B and C were each implemented with forecast window sizes of 10, 20,
#: 40, and 80 frames".
WINDOWS = (10, 20, 40, 80)
#: Section 3.1: Method A's window, "a small window size of two".
METHOD_A_WINDOW = 2
#: Section 3.2 (Fig. 3): "a pilot study showed basing the forecast on only the last two
#: frames, to be optimal": the smoothing level s of Algorithms 2 and 3.
FORECAST_LEVEL = 2
#: Algorithm 2: "D_{0,0} = 10,000" before the path is back-tracked.
METHOD_B_CORNER = 10000.0
#: Section 4: the deviation benchmark, "150 ms ... 18 frames".
DEVIATION_BENCHMARK_MS = 150.0
DEVIATION_BENCHMARK_FRAMES = 18

# -- FP-DTW: the algorithms it evaluates (Figs. 5-7, 10) -------------------------------------------

#: The suffix of the constrained variants (Figs. 5, 6: "+ Type V").
TYPE_V = " + Type V"
#: The online FP-DTW configurations of Figs. 5-7 and 10, unconstrained.
FPDTW_NAMES = ("Ma",) + tuple(f"Mb w{w}" for w in WINDOWS) + tuple(f"Mc w{w}" for w in WINDOWS)
#: The same with the Type V constraint (Section 6).
FPDTW_TYPEV_NAMES = tuple(n + TYPE_V for n in FPDTW_NAMES)
#: Every algorithm of the paper's evaluation (DTW and UTW: the offline baselines, Section 4).
PAPER_NAMES = ("DTW", "UTW", "OE-DTW") + FPDTW_NAMES + FPDTW_TYPEV_NAMES

# -- FP-DTW: results ---------------------------------------------------------------------------

#: Table 1: median similarity of Method C per window, and UTW's, at 60 and 120 Hz.
TABLE1 = {
    60: {10: 0.133, 20: 0.281, 40: 0.178, 80: 0.068, "UTW": 0.242},
    120: {10: 0.053, 20: 0.200, 40: 0.285, 80: 0.146, "UTW": 0.240},
}
#: Section 5 and Table 1: Method C's best window at each rate.
BEST_WINDOW = {120: 40, 60: 20}
#: Table 2: mean microseconds per frame, one core at 3.58-3.95 GHz.
TABLE2_US = {
    ("B", 10): 856.0, ("B", 20): 1654.0, ("B", 40): 4806.0, ("B", 80): 16945.0,
    ("C", 10): 782.0, ("C", 20): 1583.0, ("C", 40): 4764.0, ("C", 80): 10106.0,
}  # fmt: skip
#: Table 2's machine: one core clocked at 3.58-3.95 GHz (GHz; the notebooks' prose quotes it).
TABLE2_CPU_GHZ = (3.58, 3.95)
#: Section 5 (Table 2's text): the real-time budget at 120 Hz, "(1 x 10^6)/120 or 8333 us".
BUDGET_120HZ_US = 1e6 / 120
#: Section 5: "Method C with a window size of 40, Mc w40, is the only online FP-DTW
#: algorithm to exceed either of the benchmarks, without a constraint".
PASS_EITHER_UNCONSTRAINED = ("Mc w40",)
#: Section 7: "Three of the FP-DTW algorithms ... satisfied both ... Ma + Type V, Mc w40,
#: and Mc w80 + Type V".
PASS_BOTH = ("Ma + Type V", "Mc w40", "Mc w80 + Type V")
#: Section 6: "the performance of all algorithms based on Methods A and B, are improved by
#: the implementation of a constraint, Mc w80 was the only Method C algorithm that improved".
TYPEV_IMPROVED = ("Ma", "Mb w10", "Mb w20", "Mb w40", "Mb w80", "Mc w80")
#: Section 5, the Fig. 8 walk pair ("sample number 3239"): deviations from DTW, frames.
FIG8_DEVIATIONS = {"Mb w80": 8.0, "Mc w20": 177.0, "Mc w40": 62.0, "Mc w80": 6.0}
#: Section 5, the sentence after those numbers: "only algorithms Mb w80 and Mc w40 with
#: errors ... below the 18 frame benchmark" (it contradicts the numbers: 62 > 18, 6 < 18).
FIG8_TEXT_BELOW_BENCHMARK = ("Mb w80", "Mc w40")
#: Section 5 on Fig. 7: "Mb w10 and Mb w80 ... a tendency to incorrectly stick input frames";
#: "Mc w10, causes Method C to incorrectly stick on input frames, while ... Mc w80, causes
#: Method C to incorrectly skip input frames"; "Mc w40 is a more optimal balance between
#: skipping and sticking".
FIG7_TENDENCY = {"Mb w10": "sticks", "Mb w80": "sticks", "Mc w10": "sticks", "Mc w40": "balanced",
                 "Mc w80": "skips"}  # fmt: skip
#: Section 6 on Fig. 10: with Type V "the alignment paths of Ma algorithm are improved, with
#: a stronger highlight along the 1:1 diagonal slope"; "The performance of the Mc w10
#: algorithm was not improved"; "Mc w80 ... improved considerably ... a stronger highlight
#: along the 1:1 diagonal slope, fewer time warps are incorrectly skipping".
FIG10_TYPEV_IMPROVES = {"Ma": True, "Mc w10": False, "Mc w80": True}
#: Section 6: "The Mc w80 + Type V algorithm is exhibiting that same balance between sticking
#: and skipping input frames during alignment, as shown by Mc w40".
FIG10_BALANCED_LIKE = ("Mc w80 + Type V", "Mc w40")
#: Fig. 1: the example of OE-DTW's end point moving backwards, target frames 15 -> 16.
FIG1_FRAMES = (15, 16)

# -- OPW poster ----------------------------------------------------------------------------------

#: Section 3: OPW steps at 25 Hz, a sample period omega of 0.04 s.
OPW_OMEGA_S = 0.04
#: Figs. 4 and 5: the warp parameter gamma, 5 %.
OPW_GAMMA = 0.05
#: Section 4: motions "cropped at 2.5 seconds".
OPW_CROP_S = 2.5
#: Section 4: the example curve's middle key is offset by 0.25 s (1.5 s of A at 1.25 s of B).
OPW_OFFSET_S = 0.25
#: Section 4: curves compared at 50 Hz (the exported F-curves' rate).
OPW_SAMPLE_RATE_HZ = 50.0
#: Section 5 (Hoyet et al. 2012): mistimings below 150 ms are imperceptible.
PERCEPTUAL_THRESHOLD_MS = 150.0
#: Section 5 and Fig. 4: OPW's mean deviation over the three motions, ms.
OPW_MEAN_DEVIATION_MS = (69.0, 79.0)
#: Section 5 and Fig. 4: OPW's largest deviation, ms.
OPW_MAX_DEVIATION_MS = 121.0
#: Section 5 and Fig. 4: OPW "did not perform as well as the off-line DTW process".
OPW_DTW_BETTER = True
#: Section 5 and Fig. 4: "The OPW approach produces smoother curves" (than DTW's).
OPW_SMOOTHER = True
#: Section 5 and Fig. 5: share of the temporal difference OPW removes at gamma 5 %.
OPW_REMOVED_GAMMA5 = 0.70
#: Section 5 and Fig. 6: the best gamma and the share it removes.
OPW_BEST_GAMMA = 0.15
OPW_REMOVED_BEST_GAMMA = 0.77
#: Section 5 and Fig. 5: the largest offset OPW copes with, by its maximum deviation and by
#: its mean deviation staying below 150 ms, s.
OPW_OFFSET_MAX_OK_S = 0.3
OPW_OFFSET_MEAN_OK_S = 0.5


# -- the pass rule ---------------------------------------------------------------------------------


def passes_similarity(median: float, utw_median: float) -> bool:
    """The similarity benchmark: the MEDIAN similarity strictly above UTW's median.

    Paper: FP-DTW Section 5 ("the median result ... needs to be above the similarity
    results achieved by UTW").
    """
    return bool(median > utw_median)


def deviation_benchmark_frames(fps: float) -> float:
    """150 ms in frames of a rate: 18 at 120 Hz, 9 at 60 Hz."""
    return DEVIATION_BENCHMARK_MS * float(fps) / 1000.0


def passes_deviation(median_frames: float, fps: float = SAMPLE_RATE_HZ) -> bool:
    """The deviation benchmark: the MEDIAN deviation from DTW strictly below 150 ms.

    Paper: FP-DTW Section 5 ("or below the perceptible deviation from the DTW alignment
    path (average of 18 frames)").
    """
    return bool(median_frames * 1000.0 / float(fps) < DEVIATION_BENCHMARK_MS)
