"""Numbers for the notebooks' prose, built from a run's pair list and shown by a code cell
(a notebook's markdown never types a result: ``tests/test_notebook_numbers.py``)."""

from __future__ import annotations

from fpdtw.paper.claims import data_counts
from fpdtw.paper.numbers import DATA


def data_numbers(pairs) -> dict:
    """The data behind a run (``Results.pairs``) as plain Python values: ``motions``,
    ``movements``, ``pairs``, ``pairs_<dataset>``, ``hdm05_share``, ``hdm05_clips_min|max``
    (clips per class), ``largest_movement`` and ``largest_movement_share`` (of the pairs)."""
    counts = data_counts(pairs)
    total = counts["total"]
    out = {k: total[k] for k in ("motions", "movements", "pairs")}
    for ds in ("authors_fbx", "hdm05"):
        out[f"pairs_{ds}"] = counts.get(ds, {}).get("pairs", 0)
    out["hdm05_share"] = out["pairs_hdm05"] / total["pairs"] if total["pairs"] else 0.0
    clips, per_movement = {}, {}
    for p in pairs:
        key = (p["dataset"], p["movement"])
        per_movement[key] = per_movement.get(key, 0) + 1
        if p["dataset"] == "hdm05":
            clips.setdefault(p["movement"], set()).update((p["input"], p["target"]))
    sizes = [len(v) for v in clips.values()] or [0]
    out["hdm05_clips_min"], out["hdm05_clips_max"] = min(sizes), max(sizes)
    (_, name), n = max(per_movement.items(), key=lambda kv: (kv[1], kv[0]), default=(("", ""), 0))
    out["largest_movement"] = name
    out["largest_movement_share"] = n / total["pairs"] if total["pairs"] else 0.0
    return out


def _pairs_by_dataset(n: dict) -> str:
    return (
        f"{n['pairs']} ordered pairs ({n['pairs_authors_fbx']} from the authors' FBX takes, "
        f"{n['pairs_hdm05']} from HDM05)"
    )


def data_sentence(pairs) -> str:
    """A run's motions, movements and pairs next to the paper's, and HDM05's share, as Markdown.

    Notebook: 05_run_experiments.ipynb, 06_fig5_fig6_scores.ipynb, 07_table1_60hz.ipynb,
    08_fig7_fig10_heatmaps.ipynb, 09_table2_timing.ipynb
    """
    n = data_numbers(pairs)
    return (
        f"**This run's data:** {n['motions']} motions of {n['movements']} movements, "
        f"{_pairs_by_dataset(n)}, against the paper's {DATA['motions']} motions of "
        f"{DATA['movements']} movements and {DATA['pairs']} pairs. HDM05 gives "
        f"{n['hdm05_share']:.0%} of our pairs."
    )


def study_sentence(study_pairs, full_pairs) -> str:
    """The pairs of notebook 15's two runs (paper-shaped and whole-class), as Markdown.

    Notebook: 15_readings_of_algorithm_3.ipynb
    """
    study, full = data_numbers(study_pairs), data_numbers(full_pairs)
    return (
        f"**The runs' data:** the paper-shaped selection has {_pairs_by_dataset(study)}; "
        f"the whole-class run of notebook 05 has {_pairs_by_dataset(full)}."
    )


def selection_sentence(pairs) -> str:
    """How unevenly a run's pairs fall on its movements, as Markdown.

    Notebook: 15_readings_of_algorithm_3.ipynb
    """
    n = data_numbers(pairs)
    lo, hi = n["hdm05_clips_min"], n["hdm05_clips_max"]
    clips = f"{lo}" if lo == hi else f"{lo}-{hi}"
    return (
        f"The HDM05 classes of this run hold {clips} clips each, and {n['largest_movement']} alone "
        f"gives {n['largest_movement_share']:.0%} of all {n['pairs']} pairs."
    )
