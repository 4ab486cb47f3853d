"""The notebooks are committed thin and without outputs, in the shape the README promises."""

from __future__ import annotations

import ast

import nbformat
import pytest

from fpdtw.paper.paths import notebooks_dir

NOTEBOOKS = sorted(notebooks_dir().glob("[0-9][0-9]_*.ipynb"))


def test_there_are_notebooks():
    assert NOTEBOOKS, "no numbered notebooks in notebooks/"


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_notebook_is_stripped_and_thin(path):
    nb = nbformat.read(path, as_version=4)
    nbformat.validate(nb)
    assert nb.metadata.get("kernelspec", {}).get("name") == "fpdtw"
    cells = nb.cells
    assert cells[0].cell_type == "markdown", "first cell must say what the notebook makes"
    assert "Figure" in cells[0].source or "Table" in cells[0].source or "Data" in cells[0].source
    params = [c for c in cells if "parameters" in c.get("metadata", {}).get("tags", [])]
    assert len(params) == 1, "exactly one cell tagged 'parameters'"
    tree = ast.parse(params[0].source)
    names = set()
    for node in tree.body:
        assert isinstance(node, ast.Assign), "the parameters cell holds assignments only"
        ast.literal_eval(node.value)  # literals only
        names |= {t.id for t in node.targets}
    assert "SMOKE" in names
    for c in cells:
        if c.cell_type == "code":
            assert c.outputs == [], f"{path.name}: committed with outputs"
            assert c.execution_count is None
