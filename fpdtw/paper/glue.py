"""Numbers for the notebooks' prose: computed from the results and glued, never typed.

A notebook's markdown never types a result: a code cell computes the numbers and glues them
with MyST-NB (:func:`glue_numbers`), and the markdown refers to them by name,
``{glue:text}`hdm05_share:.0%```, which the book (:mod:`fpdtw.paper.book`, MyST-NB) replaces
by the value of the run it shows. Gluing only displays a mime bundle that Jupyter keeps in
the cell's outputs, so it works under papermill and in any kernel; outside a kernel
(plain Python) nothing is shown and the numbers are still returned.
``tests/test_notebook_numbers.py`` checks that no markdown cell types a result number.
"""

from __future__ import annotations

import numpy as np

#: The names :func:`data_numbers` glues.
DATA_NUMBERS = ("motions", "movements", "pairs", "pairs_authors_fbx", "pairs_hdm05",
                "hdm05_share", "hdm05_clips_min", "hdm05_clips_max", "largest_movement",
                "largest_movement_share")  # fmt: skip


def _plain(value):
    """Python int, float or str: what MyST-NB's ``glue:text`` formats (numpy scalars' text
    would be ``np.int64(5)``)."""
    if isinstance(value, bool | np.bool_):
        return bool(value)
    if isinstance(value, int | np.integer):
        return int(value)
    if isinstance(value, float | np.floating):
        return float(value)
    if isinstance(value, str):
        return value
    raise TypeError(f"glue a number or a string, not {type(value).__name__}: {value!r}")


def glue_numbers(numbers: dict, prefix: str = "") -> dict:
    """Glue every ``name: value`` for the notebook's markdown (not shown in the cell).

    Parameters
    ----------
    numbers : dict of str to int, float or str
    prefix : str
        Put before every name (``"study_"``: ``study_pairs``), to glue two runs' numbers.

    Returns
    -------
    numbers : dict
        The same names, values as plain Python numbers (what was glued).

    Notebook: 06_fig5_fig6_scores.ipynb
    """
    from myst_nb import glue

    out = {prefix + name: _plain(v) for name, v in numbers.items()}
    for name, v in out.items():
        glue(name, v, display=False)
    return out


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

    Notebook: 06_fig5_fig6_scores.ipynb
    """
    from fpdtw.paper.claims import data_counts

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


__all__ = ["DATA_NUMBERS", "data_numbers", "glue_numbers"]
