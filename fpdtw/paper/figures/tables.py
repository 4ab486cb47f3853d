"""Tables are saved by one helper, as CSV (for machines) and Markdown (for people)."""

from __future__ import annotations

import csv
import io
from pathlib import Path

from fpdtw.paper.atomic import write_atomic
from fpdtw.paper.paths import figures_dir


def _fmt(v, floatfmt):
    if isinstance(v, float):
        return format(v, floatfmt)
    return "" if v is None else str(v)


def to_markdown(rows: list[dict], columns=None, floatfmt=".3f") -> str:
    """Render rows (dicts with the same keys) as a GitHub Markdown table."""
    columns = list(columns or (rows[0].keys() if rows else []))
    lines = ["| " + " | ".join(columns) + " |", "|" + "---|" * len(columns)]
    for r in rows:
        lines.append("| " + " | ".join(_fmt(r.get(c), floatfmt) for c in columns) + " |")
    return "\n".join(lines) + "\n"


def save_table(
    rows: list[dict],
    name: str,
    folder=None,
    columns=None,
    floatfmt=".3f",
    note: str = "",
    csvfmt: str = ".6g",
):
    """Write ``<name>.csv`` and ``<name>.md`` atomically.

    Parameters
    ----------
    rows : list of dict
        One dict per row; keys are column names.
    name : str
        File stem, e.g. ``"table1_method_c_60hz"``.
    folder : path-like, optional
        Default :func:`fpdtw.paper.paths.figures_dir`.
    columns : sequence of str, optional
        Column order (default: keys of the first row).
    note : str, optional
        A paragraph put under the Markdown table.
    csvfmt : str
        Format of the CSV's floats (``".17g"``: every digit, for files that verdicts are
        recomputed from).

    Returns
    -------
    paths : list of Path
        The CSV and Markdown files written.
    """
    folder = Path(folder) if folder is not None else figures_dir()
    folder.mkdir(parents=True, exist_ok=True)
    columns = list(columns or (rows[0].keys() if rows else []))
    buf = io.StringIO()
    w = csv.DictWriter(buf, fieldnames=columns, lineterminator="\n", extrasaction="ignore")
    w.writeheader()
    for r in rows:
        w.writerow({c: _fmt(r.get(c), csvfmt) for c in columns})
    out = []
    md = to_markdown(rows, columns, floatfmt) + (f"\n{note}\n" if note else "")
    for ext, text in (("csv", buf.getvalue()), ("md", md)):
        out.append(write_atomic(folder / f"{name}.{ext}", text.encode()))
    return out
