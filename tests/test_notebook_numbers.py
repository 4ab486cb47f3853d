"""No notebook types a result number into its prose: a code cell shows it (fpdtw.paper.glue).

Where the prose needs a count of the data, a code cell prints it or shows it as Markdown
(``Markdown(data_sentence(results.pairs))``), so the number is seen in plain Jupyter as in the
book; MyST-NB's ``{glue}`` roles, which only the book fills in, are not used.

What counts as a typed result number, in a markdown cell's prose (code blocks, code spans
and math left out): a decimal with two or more digits after the point
(``0.478``) or a percentage (``88 %``, ``99%``). It is allowed only when it is a constant,
not a result: one of the papers' own numbers (:mod:`fpdtw.paper.numbers`), a constant of the
claims' rules (:mod:`fpdtw.paper.claims.bootstrap`: the interval level and its tails, the
stability target), a frame period, or a value of the notebook's own ``parameters`` cell (an
input). Each may appear scaled as prose writes it: a fraction as a percentage, microseconds
as milliseconds. Integers are not checked (counts of the data are shown by a code cell where a
run gives them; the papers' counts are typed as the papers' own). What is prose:
:func:`reference.prose.prose` (shared with the check of README.md and ARTIFACT.md,
``tests/test_prose_numbers.py``).
"""

from __future__ import annotations

import ast
import json
import math
import re

import pytest
from reference.prose import prose

from fpdtw.paper.paths import REPO_ROOT

#: Notebooks another branch edits at the same time (issue 24 leaves their prose to it).
ELSEWHERE = ("13_", "14_", "16_", "17_")
ALL_NOTEBOOKS = sorted((REPO_ROOT / "notebooks").glob("*.ipynb"))
NOTEBOOKS = [p for p in ALL_NOTEBOOKS if not p.name.startswith(ELSEWHERE)]
NUMBER = re.compile(r"(?<![\w.])(\d+\.\d{2,}|\d+(?:\.\d+)? ?%)")


def _values(x):
    """Every number inside a constant (dicts, tuples, lists), recursively."""
    if isinstance(x, bool):
        return
    if isinstance(x, int | float):
        yield float(x)
    elif isinstance(x, dict):
        for v in x.values():
            yield from _values(v)
    elif isinstance(x, list | tuple | set | frozenset):
        for v in x:
            yield from _values(v)


def constants() -> list[float]:
    """The numbers prose may type: the papers', the rules', frame periods (ms)."""
    from fpdtw.paper import numbers
    from fpdtw.paper.claims import bootstrap

    out = [v for k, x in vars(numbers).items() if k.isupper() for v in _values(x)]
    level = bootstrap.LEVEL
    out += [level, (1 - level) / 2, (1 + level) / 2, bootstrap.STABILITY]
    out += [1000 / f for f in (120, 60, 30)]
    return out


def parameters(nb: dict) -> list[float]:
    """The values of a notebook's ``parameters`` cell (literals only)."""
    cells = [c for c in nb["cells"] if "parameters" in c.get("metadata", {}).get("tags", [])]
    out = []
    for c in cells:
        for node in ast.walk(ast.parse("".join(c["source"]))):
            if isinstance(node, ast.Assign):
                try:
                    out += list(_values(ast.literal_eval(node.value)))
                except ValueError:
                    continue
    return out


def allowed(token: str, values: list[float]) -> bool:
    """Whether a typed number is one of ``values`` as prose writes it (to its precision)."""
    percent = token.endswith("%")
    number = token.rstrip("% ")
    x = float(number)
    digits = len(number.split(".")[1]) if "." in number else 0
    tol = 0.5 * 10**-digits + 1e-9
    for v in values:
        shown = [100 * v, v] if percent else [v, v / 1000, 1000 * v]
        if any(math.isclose(x, s, abs_tol=tol) or abs(x - s) <= tol for s in shown):
            return True
    return False


def typed_numbers(nb: dict) -> list[tuple[int, str, str]]:
    """(cell index, number, its line) for each typed result number of a notebook."""
    values = constants() + parameters(nb)
    out = []
    for i, c in enumerate(nb["cells"]):
        if c["cell_type"] != "markdown":
            continue
        for line in prose("".join(c["source"])).splitlines():
            for token in NUMBER.findall(line):
                if not allowed(token, values):
                    out.append((i, token, line.strip()))
    return out


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.stem)
def test_no_markdown_cell_types_a_result_number(path):
    nb = json.loads(path.read_text(encoding="utf-8"))
    found = typed_numbers(nb)
    assert not found, (
        f"{path.name}: result numbers typed into markdown; show them from a code cell "
        "(print them, or Markdown(sentence) built by fpdtw.paper.glue):\n"
        + "\n".join(f"  cell {i}: {tok!r} in {line!r}" for i, tok, line in found)
    )


@pytest.mark.parametrize("path", ALL_NOTEBOOKS, ids=lambda p: p.stem)
def test_no_notebook_has_glue_roles(path):
    """MyST-NB's ``{glue}`` roles and directives show a number only in the book (plain Jupyter
    shows the placeholder): a code cell shows it instead."""
    nb = json.loads(path.read_text(encoding="utf-8"))
    found = [i for i, c in enumerate(nb["cells"]) if "{glue" in "".join(c["source"])]
    assert not found, f"{path.name}: glue roles in cells {found}; show the numbers from code"


def test_the_rule_finds_typed_numbers_and_allows_constants():
    nb = {
        "cells": [
            {"cell_type": "code", "metadata": {"tags": ["parameters"]},
             "source": ["DROP = 0.05  # lost frames\n", "SMOKE = False\n"]},
            {"cell_type": "markdown", "metadata": {},
             "source": ["Mc w40 reaches 0.478 and 12.7 frames; 88% of pairs, 7537 of 8610.\n",
                        "The paper's budget is 8333 us (8.33 ms), its 95 % interval; we drop ",
                        "5 % of the frames; $x = 0.25$, `0.125`."]},
        ]
    }  # fmt: skip
    found = [tok for _, tok, _ in typed_numbers(nb)]
    assert found == ["0.478", "88%"]


def _pairs(ds, mv, takes):
    return [dict(dataset=ds, movement=mv, input=a, target=b)
            for a in takes for b in takes if a != b]  # fmt: skip


#: Hand-counted: two HDM05 classes (3 clips: 6 pairs; 2 clips: 2 pairs) and one authors'
#: movement (2 takes: 2 pairs).
PAIRS = (
    _pairs("hdm05", "squat", "abc")
    + _pairs("hdm05", "kick", "de")
    + _pairs("authors_fbx", "Walk", "xy")
)


def test_data_numbers_count_a_pair_list():
    from fpdtw.paper.glue import data_numbers

    got = data_numbers(PAIRS)
    assert got == dict(motions=7, movements=3, pairs=10, pairs_authors_fbx=2, pairs_hdm05=8,
                       hdm05_share=0.8, hdm05_clips_min=2, hdm05_clips_max=3,
                       largest_movement="squat", largest_movement_share=0.6)  # fmt: skip
    assert all(type(v) in (int, float, str) for v in got.values())


def test_sentences_quote_the_counts():
    from fpdtw.paper.glue import data_sentence, selection_sentence, study_sentence

    assert data_sentence(PAIRS) == (
        "**This run's data:** 7 motions of 3 movements, 10 ordered pairs (2 from the authors' "
        "FBX takes, 8 from HDM05), against the paper's 333 motions of 44 movements and 3248 "
        "pairs. HDM05 gives 80% of our pairs."
    )
    assert selection_sentence(PAIRS) == (
        "The HDM05 classes of this run hold 2-3 clips each, and squat alone gives 60% of all "
        "10 pairs."
    )
    assert "hold 2 clips each" in selection_sentence(_pairs("hdm05", "kick", "de"))
    assert study_sentence(PAIRS[:2], PAIRS) == (
        "**The runs' data:** the paper-shaped selection has 2 ordered pairs (0 from the authors' "
        "FBX takes, 2 from HDM05); the whole-class run of notebook 05 has 10 ordered pairs "
        "(2 from the authors' FBX takes, 8 from HDM05)."
    )


def test_a_sentence_shown_by_a_code_cell_reaches_the_book_from_a_real_kernel(tmp_path):
    """A sentence a code cell shows as Markdown in a headless kernel (as papermill runs it)
    is stored in the cell's outputs as text/markdown, which plain Jupyter renders, and the
    book (MyST-NB) renders it as text of the page."""
    import html

    import nbclient
    import nbformat

    from fpdtw.app import book

    nb = nbformat.v4.new_notebook()
    nb.metadata["kernelspec"] = {"name": "python3", "display_name": "Python 3",
                                 "language": "python"}  # fmt: skip
    nb.cells = [
        nbformat.v4.new_markdown_cell("# 01 · Data and motions\n\nThe data of the run:"),
        nbformat.v4.new_code_cell(
            "from IPython.display import Markdown\n"
            "from fpdtw.paper.glue import data_sentence\n"
            f"Markdown(data_sentence({PAIRS!r}))"
        ),
    ]
    nbclient.NotebookClient(nb, timeout=120, kernel_name="python3").execute()
    shown = [o["data"]["text/markdown"] for o in nb.cells[1].outputs if "data" in o]
    assert shown and "10 ordered pairs" in shown[0]
    assert not typed_numbers(nb)
    nbs = tmp_path / "nbs"
    nbs.mkdir()
    nbformat.write(nb, nbs / "01_data_and_motions.ipynb")
    claims_json = tmp_path / "claims.json"
    claims_json.write_text(json.dumps({"mode": "smoke", "claims": []}))
    (tmp_path / "figs").mkdir()
    book.build(tmp_path / "site", nbs, tmp_path / "figs", claims_json, mode="smoke")
    page = (tmp_path / "site" / "notebooks" / "01_data_and_motions.html").read_text()
    text = html.unescape(re.sub(r"<[^>]+>", "", page)).replace("\u2019", "'")
    assert "This run's data: 7 motions of 3 movements, 10 ordered pairs" in text
    assert "HDM05 gives 80% of our pairs." in text
