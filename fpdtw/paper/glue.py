"""Numbers for the notebooks' prose: computed from the results and shown by a code cell.

A notebook's markdown never types a result. Where its prose needs a count of the data, a
code cell shows it as a sentence built here from the run's pair list
(``Markdown(data_sentence(results.pairs))``), so the number is seen in plain Jupyter and in
the book (:mod:`fpdtw.app.book` renders the cell's Markdown output) alike.
``tests/test_notebook_numbers.py`` checks that no markdown cell types a result number.
"""

from __future__ import annotations

import numpy as np

from fpdtw.paper.claims import data_counts
from fpdtw.paper.numbers import DATA

#: The names :func:`data_numbers` returns.
DATA_NUMBERS = ("motions", "movements", "pairs", "pairs_authors_fbx", "pairs_hdm05",
                "hdm05_share", "hdm05_clips_min", "hdm05_clips_max", "largest_movement",
                "largest_movement_share")  # fmt: skip


def _plain(value):
    """Python int, float or str (a numpy scalar's text would be ``np.int64(5)``)."""
    if isinstance(value, bool | np.bool_):
        return bool(value)
    if isinstance(value, int | np.integer):
        return int(value)
    if isinstance(value, float | np.floating):
        return float(value)
    if isinstance(value, str):
        return value
    raise TypeError(f"a number or a string, not {type(value).__name__}: {value!r}")


def data_numbers(pairs) -> dict:
    """The data behind a run, as the notebooks' prose quotes them.

    Parameters
    ----------
    pairs : list of dict
        ``Results.pairs`` (``dataset``, ``movement``, ``input``, ``target``).

    Returns
    -------
    numbers : dict
        ``motions``, ``movements``, ``pairs``; ``pairs_authors_fbx``, ``pairs_hdm05``;
        ``hdm05_share`` (fraction of the pairs from HDM05); ``hdm05_clips_min``,
        ``hdm05_clips_max`` (clips per HDM05 class); ``largest_movement`` and
        ``largest_movement_share`` (the movement with most pairs, its fraction of them).
    """

    counts = data_counts(pairs)
    total = counts["total"]
    out = {k: total[k] for k in ("motions", "movements", "pairs")}
    for ds in ("authors_fbx", "hdm05"):
        out[f"pairs_{ds}"] = counts.get(ds, {}).get("pairs", 0)
    out["hdm05_share"] = out["pairs_hdm05"] / total["pairs"] if total["pairs"] else 0.0
    clips: dict = {}
    per_movement: dict = {}
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
    return {k: _plain(out[k]) for k in DATA_NUMBERS}


def _pairs_by_dataset(n: dict) -> str:
    return (
        f"{n['pairs']} ordered pairs ({n['pairs_authors_fbx']} from the authors' FBX takes, "
        f"{n['pairs_hdm05']} from HDM05)"
    )


def data_sentence(pairs) -> str:
    """The data of a run against the paper's, as Markdown (what the prose's data paragraph
    leaves to the run).

    Parameters
    ----------
    pairs : list of dict
        ``Results.pairs``.

    Returns
    -------
    text : str
        Motions, movements and pairs (per dataset) of the run next to the paper's, and
        HDM05's share of the pairs.

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
    """The pairs of notebook 15's two runs, as Markdown.

    Parameters
    ----------
    study_pairs, full_pairs : list of dict
        ``Results.pairs`` of the paper-shaped selection and of the whole-class run.

    Returns
    -------
    text : str

    Notebook: 15_readings_of_algorithm_3.ipynb
    """
    study, full = data_numbers(study_pairs), data_numbers(full_pairs)
    return (
        f"**The runs' data:** the paper-shaped selection has {_pairs_by_dataset(study)}; "
        f"the whole-class run of notebook 05 has {_pairs_by_dataset(full)}."
    )


def selection_sentence(pairs) -> str:
    """How unevenly a run's pairs fall on its movements, as Markdown: the clips per HDM05
    class and the share of the movement with most pairs.

    Parameters
    ----------
    pairs : list of dict
        ``Results.pairs``.

    Returns
    -------
    text : str

    Notebook: 15_readings_of_algorithm_3.ipynb
    """
    n = data_numbers(pairs)
    lo, hi = n["hdm05_clips_min"], n["hdm05_clips_max"]
    clips = f"{lo}" if lo == hi else f"{lo}-{hi}"
    return (
        f"The HDM05 classes of this run hold {clips} clips each, and {n['largest_movement']} alone "
        f"gives {n['largest_movement_share']:.0%} of all {n['pairs']} pairs."
    )


__all__ = ["DATA_NUMBERS", "data_numbers", "data_sentence", "selection_sentence", "study_sentence"]
