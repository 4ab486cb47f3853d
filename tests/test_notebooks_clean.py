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


def _paper_results() -> set:
    """The papers' reported results (not their protocol parameters), as numbers."""
    from fpdtw.paper import numbers as N

    vals = [v for rate in N.TABLE1.values() for v in rate.values()]
    vals += list(N.TABLE2_US.values()) + list(N.FIG8_DEVIATIONS.values())
    vals += list(N.OPW_MEAN_DEVIATION_MS) + [N.OPW_MAX_DEVIATION_MS]
    vals += [N.OPW_REMOVED_GAMMA5, N.OPW_REMOVED_BEST_GAMMA] + list(N.DATA.values())
    vals += list(N.DATA_SOURCES.values())
    # small whole numbers (6, 8, 62 frames) are too common in code to flag
    return {float(v) for v in vals if float(v) != int(v) or v >= 100}


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_notebook_reads_as_a_companion(path):
    """Each notebook shows the equation or algorithm it reproduces, and after its figures
    prints the paper's values next to ours (``fpdtw.paper.figures.paper_vs_ours``) or the
    claims' verdicts and parts (``fpdtw.paper.claims``), in a cell nbval checks; its code never
    retypes a paper result."""
    nb = nbformat.read(path, as_version=4)
    md = "".join(c.source for c in nb.cells if c.cell_type == "markdown")
    assert md.count("$$") >= 2, "no display equation ($$ ... $$) in the markdown"
    code = [c for c in nb.cells if c.cell_type == "code"]
    printers = ("format_side_by_side(", "format_claims(", "format_parts(", "claims_summary(")
    checked = [c for c in code if any(p in c.source for p in printers)]
    assert checked, "no cell prints paper | ours or the claims"
    assert any("# NBVAL_CHECK_OUTPUT" in c.source for c in checked), (
        "no comparison cell is checked by nbval"
    )
    results = _paper_results()
    for c in code:
        if "parameters" in c.get("metadata", {}).get("tags", []):
            continue
        for node in ast.walk(ast.parse(c.source)):
            if isinstance(node, ast.Constant) and type(node.value) in (int, float):
                assert float(node.value) not in results, (
                    f"{path.name}: the paper's {node.value} typed into a code cell; read it "
                    "from fpdtw.paper.numbers"
                )
