"""Tables are saved by one helper, as CSV (for machines) and Markdown (for people)."""

from __future__ import annotations

import csv
import io

from fpdtw.paper.atomic import write_atomic
from fpdtw.paper.paths import figures_dir


def _fmt(v, floatfmt):
    if isinstance(v, float):
        return format(v, floatfmt)
    return "" if v is None else str(v)


def to_markdown(rows: list[dict], columns=None, floatfmt=".3f") -> str:
    """Render rows (dicts with the same keys) as a GitHub Markdown table."""
    columns = list(columns or (rows[0].keys() if rows else []))
    lines = ["| " + " | ".join(map(str, columns)) + " |", "|" + "---|" * len(columns)]
    for r in rows:
        lines.append("| " + " | ".join(_fmt(r.get(c), floatfmt) for c in columns) + " |")
    return "\n".join(lines) + "\n"


def save_table(rows: list[dict], name: str, columns=None, floatfmt=".3f", note="", csvfmt=".6g"):
    """Write ``<name>.csv`` and ``<name>.md`` atomically in :func:`fpdtw.paper.paths.figures_dir`.

    ``columns``: their order (default the first row's keys); ``note``: a paragraph under the
    Markdown table; ``csvfmt``: the CSV's floats (``".17g"`` for files verdicts are
    recomputed from). Returns the two paths.
    """
    folder = figures_dir()
    columns = list(columns or (rows[0].keys() if rows else []))
    buf = io.StringIO()
    w = csv.DictWriter(buf, fieldnames=columns, lineterminator="\n", extrasaction="ignore")
    w.writeheader()
    for r in rows:
        w.writerow({c: _fmt(r.get(c), csvfmt) for c in columns})
    md = to_markdown(rows, columns, floatfmt) + (f"\n{note}\n" if note else "")
    return [
        write_atomic(folder / f"{name}.{ext}", text.encode())
        for ext, text in (("csv", buf.getvalue()), ("md", md))
    ]
