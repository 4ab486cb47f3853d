"""The small JSON of facts each figure notebook writes next to its figures (deterministic
except the key ``"environment"``).
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from fpdtw.paper.atomic import write_atomic
from fpdtw.paper.paths import results_dir
from fpdtw.paper.provenance import environment


def facts_path(notebook: str, smoke: bool) -> Path:
    """``results_dir()/<mode>/figs/<notebook>.json`` for a notebook stem (``"02_fig1_oedtw"``)."""
    return results_dir() / ("smoke" if smoke else "full") / "figs" / f"{notebook}.json"


def _plain(x):
    """JSON-ready copy of x: numpy -> Python, floats to 6 significant digits, NaN -> None."""
    if isinstance(x, dict):
        return {str(k): _plain(v) for k, v in x.items()}
    if isinstance(x, list | tuple):
        return [_plain(v) for v in x]
    if isinstance(x, np.ndarray):
        return _plain(x.tolist())
    if isinstance(x, np.generic):
        x = x.item()
    if isinstance(x, float):
        return float(f"{x:.6g}") if math.isfinite(x) else None
    return x


def save_facts(notebook: str, facts: dict, smoke: bool) -> Path:
    """Write a notebook's facts (numpy allowed; non-finite floats become null) as JSON.

    Notebook: 02_fig1_oedtw.ipynb, 03_fig2_fig4_windows.ipynb, 04_fig3_forecast.ipynb,
    10_fig8_walk_pair.ipynb, 11_fig9_typev.ipynb
    """
    record = {**_plain(facts), "environment": environment()}
    text = json.dumps(record, indent=1, sort_keys=True) + "\n"
    return write_atomic(facts_path(notebook, smoke), text.encode())
