"""Count the size of each layer of the package (docs/layout.md, "Size of each layer").

Usage (from the checkout)::

    .venv/bin/python tools/layer_sizes.py

A layer's size is its lines of code: the physical lines of its ``.py`` files that are
neither blank, nor comments only, nor docstrings (module, class and function docstrings);
its total lines are given beside them. The numbers are printed for the checkout the tool
runs in, never typed into the documentation.
"""

from __future__ import annotations

import ast
import io
import tokenize
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

#: Layer -> (description, files).
LAYERS = {
    "library": "fpdtw/ without paper/ and app/ (what you import to align motions)",
    "plain": "fpdtw/plain.py alone (the papers' algorithms in plain NumPy; part of the library)",
    "paper": "fpdtw/paper/ (the reproduction: data, runner, claims, figures, book, bench)",
    "apps": "fpdtw/app/ (command line, live replay, animation, export)",
    "tests": "tests/ (the test suite and its test-only helpers)",
}


def layer_files(layer: str, root: Path = ROOT) -> list:
    """The ``.py`` files of a layer, sorted."""
    pkg = root / "fpdtw"
    if layer == "library":
        files = [
            p for p in pkg.rglob("*.py") if p.relative_to(pkg).parts[0] not in ("paper", "app")
        ]
    elif layer == "plain":
        files = [pkg / "plain.py"]
    elif layer == "paper":
        files = list((pkg / "paper").rglob("*.py"))
    elif layer == "apps":
        files = list((pkg / "app").rglob("*.py"))
    elif layer == "tests":
        files = list((root / "tests").rglob("*.py"))
    else:
        raise ValueError(f"unknown layer {layer!r}; known: {', '.join(LAYERS)}")
    return sorted(files)


def code_lines(source: str) -> int:
    """Lines that hold code: not blank, not only a comment, not part of a docstring."""
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


def sizes(root: Path = ROOT) -> dict:
    """``{layer: {"files": n, "code": lines of code, "lines": all lines}}``."""
    out = {}
    for layer in LAYERS:
        files = layer_files(layer, root)
        texts = [f.read_text() for f in files]
        out[layer] = {
            "files": len(files),
            "code": sum(code_lines(t) for t in texts),
            "lines": sum(len(t.splitlines()) for t in texts),
        }
    return out


def table(counts: dict) -> str:
    """The sizes as a Markdown table."""
    rows = ["| layer | files | lines of code | all lines |", "|---|---:|---:|---:|"]
    for layer, c in counts.items():
        rows.append(f"| {layer}: {LAYERS[layer]} | {c['files']} | {c['code']} | {c['lines']} |")
    return "\n".join(rows)


if __name__ == "__main__":
    print(table(sizes()))
