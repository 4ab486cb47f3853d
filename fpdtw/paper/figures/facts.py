"""The small JSON of facts each figure notebook writes next to its figures.

Every figure notebook records the facts it shows (counts, chosen steps, rounded scores)
in ``results_dir()/<mode>/figs/<notebook>.json``, ``mode`` = ``"smoke"`` or ``"full"``;
the claims notebook and the tests read them back. Content is deterministic (keys are
sorted, numpy scalars and arrays become plain JSON numbers and lists, floats are written
with 6 significant digits; the file is replaced atomically) except the one key
``"environment"``, which records what computed them
(:func:`fpdtw.paper.provenance.environment`: versions, commit, CPU).
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from fpdtw.paper.atomic import write_atomic
from fpdtw.paper.paths import results_dir
from fpdtw.paper.provenance import environment


def mode_name(smoke: bool) -> str:
    """``"smoke"`` or ``"full"``."""
    return "smoke" if smoke else "full"


def facts_path(notebook: str, smoke: bool) -> Path:
    """Path of a notebook's facts: ``results_dir()/<mode>/figs/<notebook>.json``.

    Parameters
    ----------
    notebook : str
        Notebook stem, e.g. ``"02_fig1_oedtw"``.
    smoke : bool
    """
    return results_dir() / mode_name(smoke) / "figs" / f"{notebook}.json"


def _plain(x):
    """JSON-ready copy of x: numpy -> Python, floats to 6 significant digits."""
    if isinstance(x, dict):
        return {str(k): _plain(v) for k, v in x.items()}
    if isinstance(x, list | tuple):
        return [_plain(v) for v in x]
    if isinstance(x, np.ndarray):
        return _plain(x.tolist())
    if isinstance(x, bool | np.bool_):
        return bool(x)
    if isinstance(x, int | np.integer):
        return int(x)
    if isinstance(x, float | np.floating):
        v = float(x)
        if not math.isfinite(v):
            return None
        return float(f"{v:.6g}")
    return x


def save_facts(notebook: str, facts: dict, smoke: bool) -> Path:
    """Write a notebook's facts as JSON (atomic, deterministic).

    Parameters
    ----------
    notebook : str
        Notebook stem, e.g. ``"02_fig1_oedtw"``.
    facts : dict
        JSON-able content (numpy scalars and arrays allowed); non-finite floats are
        written as null.
    smoke : bool
        Smoke run (``results_dir()/smoke``) or full run (``results_dir()/full``).

    Returns
    -------
    path : Path

    Notebook: 02_fig1_oedtw.ipynb, 03_fig2_fig4_windows.ipynb, 04_fig3_forecast.ipynb,
    10_fig8_walk_pair.ipynb, 11_fig9_typev.ipynb
    """

    path = facts_path(notebook, smoke)
    record = {**_plain(facts), "environment": environment()}
    return write_atomic(path, (json.dumps(record, indent=1, sort_keys=True) + "\n").encode())


def load_facts(notebook: str, smoke: bool) -> dict:
    """Read the facts a notebook wrote (see :func:`save_facts`)."""
    return json.loads(facts_path(notebook, smoke).read_text())


__all__ = ["facts_path", "load_facts", "mode_name", "save_facts"]
