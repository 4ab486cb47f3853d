"""The layout: the library below, the paper layer above it, the apps on top; one registry;
one figure map that the Makefile, the README and the notebooks agree with."""

from __future__ import annotations

import ast
import json
from pathlib import Path

import numpy as np
import pytest

from fpdtw import plain, registry
from fpdtw.app import figure_map
from fpdtw.online.base import OnlineAligner
from fpdtw.paper.paths import REPO_ROOT

PKG = REPO_ROOT / "fpdtw"


def _imports(path: Path, top_only: bool = False) -> set:
    """Every fpdtw module a file imports, at any depth (functions included), or with
    ``top_only`` only those imported at module level (not inside a function)."""
    tree = ast.parse(path.read_text())
    inner = set()
    if top_only:
        for node in ast.walk(tree):
            if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
                inner.update(id(n) for n in ast.walk(node) if n is not node)
    out = set()
    for node in ast.walk(tree):
        if id(node) in inner:
            continue
        if isinstance(node, ast.Import):
            out.update(a.name for a in node.names if a.name.startswith("fpdtw"))
        elif isinstance(node, ast.ImportFrom) and node.module and node.module.startswith("fpdtw"):
            out.add(node.module)
            out.update(f"{node.module}.{a.name}" for a in node.names)
    return out


def _layer(rel: Path) -> str:
    return rel.parts[0] if rel.parts[0] in ("paper", "app") else "library"


#: Optional parts of the tools a lower layer may reach, inside a function only, when a user
#: asks for them: the Dask cluster (``fpdtw experiments run --scheduler``).
OPTIONAL_PARTS = {"paper": ("fpdtw.app.cluster",)}


def test_nothing_below_imports_the_layers_above():
    """library <- paper <- app: the library imports neither; the paper layer imports no tool
    but the optional parts of OPTIONAL_PARTS, and those only inside a function."""
    above = {"library": ("fpdtw.paper", "fpdtw.app"), "paper": ("fpdtw.app",), "app": ()}
    bad = []
    for f in sorted(PKG.rglob("*.py")):
        layer = _layer(f.relative_to(PKG))
        optional = OPTIONAL_PARTS.get(layer, ())
        top = _imports(f, top_only=True)
        for mod in _imports(f):
            if not any(mod == a or mod.startswith(a + ".") for a in above[layer]):
                continue
            lazy_optional = mod in optional or any(mod.startswith(o + ".") for o in optional)
            if lazy_optional and mod not in top:
                continue
            bad.append(f"{f.relative_to(REPO_ROOT)} ({layer}) imports {mod}")
    assert not bad, "\n".join(bad)


def test_an_optional_part_imported_at_module_level_is_caught(tmp_path):
    f = tmp_path / "parallel.py"
    f.write_text("from fpdtw.app import cluster\n\ndef g():\n    from fpdtw.app import bench\n")
    assert "fpdtw.app.cluster" in _imports(f, top_only=True)
    assert "fpdtw.app.bench" not in _imports(f, top_only=True)
    assert "fpdtw.app.bench" in _imports(f)


def test_the_library_needs_only_its_own_dependencies():
    """The library (fpdtw without paper/ and app/) imports at module level nothing beyond the
    standard library and pyproject.toml's `dependencies` (numpy, scipy, numba, the FBX
    reader's binding): the reproduction's and the tools' packages are extras."""
    import sys
    import tomllib

    deps = tomllib.loads((REPO_ROOT / "pyproject.toml").read_text())["project"]["dependencies"]
    allowed = {d.split(">")[0].split("=")[0].split("<")[0].strip() for d in deps} | {"fpdtw"}
    bad = []
    for f in sorted(PKG.rglob("*.py")):
        if _layer(f.relative_to(PKG)) != "library":
            continue
        tree = ast.parse(f.read_text())
        for node in tree.body:
            names = []
            if isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom) and node.module and not node.level:
                names = [node.module]
            for name in names:
                top = name.split(".")[0]
                if top not in allowed and top not in sys.stdlib_module_names:
                    bad.append(f"{f.relative_to(REPO_ROOT)} imports {name}")
    assert not bad, "\n".join(bad)


def test_the_check_would_catch_an_upward_import(tmp_path):
    f = tmp_path / "costs.py"
    f.write_text("def f():\n    from fpdtw.paper.numbers import WINDOWS\n")
    assert "fpdtw.paper.numbers" in _imports(f)


def _import_cycles(pkg: Path) -> list:
    """The import circles among the modules of package folder ``pkg``, imports inside
    functions included: each as a sorted list of module names (a strongly connected
    component of more than one module, or a module importing itself)."""
    files = {}
    for f in pkg.rglob("*.py"):
        parts = f.relative_to(pkg.parent).with_suffix("").parts
        files[".".join(parts[:-1] if parts[-1] == "__init__" else parts)] = f
    graph = {}
    for mod, f in files.items():
        found = {m for m in _imports(f) if m in files}
        # ``from fpdtw.x import y`` with y a module: the edge is to y, not to fpdtw.x
        found -= {m for m in found if any(o.startswith(m + ".") for o in found)}
        graph[mod] = found
    index, low, stack, on, out = {}, {}, [], set(), []

    def visit(v):  # Tarjan's strongly connected components
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in graph[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while not comp or comp[-1] != v:
                comp.append(stack.pop())
                on.discard(comp[-1])
            if len(comp) > 1 or v in graph[v]:
                out.append(sorted(comp))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out


def test_no_import_circles():
    """No module of fpdtw reaches itself through its imports, at module level or inside a
    function (issue "a small library": the claims' circle was hidden by in-function
    imports)."""
    assert _import_cycles(PKG) == []


def test_the_circle_check_would_catch_one_hidden_in_a_function(tmp_path):
    pkg = tmp_path / "fpdtw"
    (pkg / "app").mkdir(parents=True)
    (pkg / "__init__.py").write_text("")
    (pkg / "app" / "__init__.py").write_text("")
    (pkg / "app" / "a.py").write_text("from fpdtw.app.b import X\n")
    (pkg / "app" / "b.py").write_text("X = 1\n\ndef f():\n    from fpdtw.app import a\n")
    assert _import_cycles(pkg) == [["fpdtw.app.a", "fpdtw.app.b"]]
    (pkg / "app" / "b.py").write_text("X = 1\n")
    assert _import_cycles(pkg) == []


def test_the_plain_algorithms_live_in_the_package():
    """fpdtw.plain holds the plain versions of the algorithms, the ones the tests compare
    the fast kernels with; tests/reference holds test data only (synthetic motions, edited
    files), no second implementation; the library holds no test data."""
    names = set(plain.__all__)
    for f in sorted((REPO_ROOT / "tests" / "reference").glob("*.py")):
        tree = ast.parse(f.read_text())
        defs = {n.name for n in ast.walk(tree) if isinstance(n, ast.FunctionDef | ast.ClassDef)}
        assert not defs & names, f"{f.name} re-implements {sorted(defs & names)}"
        assert not [d for d in defs if d.endswith("_step") or d.startswith("reference")], f
    for f in PKG.rglob("*.py"):
        assert "synthetic" not in f.name, f


def test_the_registry_names_every_method_of_the_command_line():
    from fpdtw.app import cli

    assert list(cli.METHODS) == [e.cli for e in registry.ENTRIES]
    for e in registry.ENTRIES:
        name = registry.name(e.key, e.default or (40 if e.param else None))
        a = registry.resolve(name)
        assert (a.entry, a.online) == (e, e.online)
    assert registry.resolve("Mc w40 (literal window) + Type V").options == {"window": "literal"}
    assert registry.name("OLTW", 60) == "OLTW c60" and registry.name("Ma") == "Ma"
    for bad in (
        "Md w10",
        "Mc",
        "DTW + Type V",
        "OLTW w40",
        "Mc w40 (wide)",
        "UTW (literal window)",
    ):
        with pytest.raises(Exception, match=r"\S"):
            registry.resolve(bad)


class Greedy(OnlineAligner):
    """A toy aligner for the test below: the best of the ``k + 1`` input frames from the
    last one matched (Method A with any window, without its Type V or options)."""

    name = "Greedy"
    history = 0

    def __init__(self, I, k=1):
        self.k = int(k)
        super().__init__(I)

    def _step(self, q):
        start = 0 if q == 0 else int(self.M[q - 1])
        rows = self.I.quats[start : start + self.k + 1]
        return start + int(np.argmin(plain.cost_matrix(rows, self.T_quats[q : q + 1])))


def test_adding_an_aligner_is_one_class_and_one_entry(monkeypatch):
    """The README's promise, walked through: the class above plus this one Entry line
    (in ENTRIES) make "Greedy k3" a name the registry resolves, builds, runs and the
    benchmark times."""
    from reference.synthetic import synthetic_pair

    from fpdtw.app.bench import bench_online

    entry = registry.Entry(
        "Greedy", "G", "greedy", True, registry.online("test_architecture:Greedy"), "k", 1
    )
    monkeypatch.setattr(registry, "ENTRIES", (*registry.ENTRIES, entry))
    monkeypatch.setitem(registry._BY_KEY, "Greedy", entry)

    I, T, _ = synthetic_pair(120)
    a = registry.resolve("Greedy k3")
    assert (a.entry, a.value, a.online) == (entry, 3, True)
    assert registry.name("Greedy", 3) == "Greedy k3" and registry.name("Greedy") == "Greedy"
    assert isinstance(registry.make_online("Greedy k3", I), Greedy)
    M, seconds = registry.align("Greedy k3", I, T)
    assert M.shape == seconds.shape == (T.n_frames,)
    assert M[0] == 0 and np.all(np.diff(M) >= 0) and np.all(np.diff(M) <= 3)
    # k = 2 is Method A's window: the same map (Greedy breaks ties the same way)
    np.testing.assert_array_equal(
        registry.align("Greedy k2", I, T)[0], registry.align("Ma", I, T)[0]
    )
    (row,) = bench_online([(I, T)], names=["Greedy k3"])
    assert row["frames"] == T.n_frames and row["median_s"] > 0
    with pytest.raises(Exception, match="Type V"):
        registry.resolve("Greedy k3 + Type V")


def test_a_baseline_in_one_entry_reaches_the_grid_figures_bench_and_claim_b1(monkeypatch, tmp_path):
    """The same toy aligner, its Entry marked ``baseline=True``: with no other edit it is in
    the grid's default list and runs there, gets a box in Figs. 5 and 6 and a panel in
    Fig. 7, is timed by make bench's baselines and is one of claim B1's algorithms."""
    from reference.synthetic import synthetic_pair

    from fpdtw.app.bench import bench_baselines
    from fpdtw.paper.claims import claims_by_id, load_context
    from fpdtw.paper.figures import heatmaps, scores, timing
    from fpdtw.paper.runner import grid
    from fpdtw.paper.runner import run as E

    entry = registry.Entry(
        "Greedy", "G", "greedy", True, registry.online("test_architecture:Greedy"), "k", 1,
        baseline=True,
    )  # fmt: skip
    monkeypatch.setattr(registry, "ENTRIES", (*registry.ENTRIES, entry))
    monkeypatch.setitem(registry._BY_KEY, "Greedy", entry)
    assert registry.baselines() == ("OPW", "OLTW", "Greedy")
    assert "Greedy" in grid.mode_algorithms("full") and "Greedy" in grid.default_algorithms()
    assert scores.base_names()[-1] == heatmaps.fig7_names()[-1] == "Greedy"
    assert "Greedy" in timing.timed_names()

    monkeypatch.setenv("FPDTW_RESULTS_DIR", str(tmp_path))
    tiny = E.Selection(
        datasets=("authors_fbx",), movements=("Walk",), takes_per_movement=2, crop_seconds=1.0
    )
    res = E.run_experiments("toy", ["DTW", "UTW", "Greedy"], n_jobs=1, progress=False,
                            selection=tiny)  # fmt: skip
    assert "Greedy" in res.algorithms
    fig, ax = scores.plot_score_boxes(res, "similarity", intervals=False)
    labels = [t.get_text() for t in ax.get_xticklabels()]
    assert any("Greedy" in t for t in labels), labels
    fig, axes = heatmaps.plot_heatmap_grid(res, ncols=3, bins=10)
    titles = [a.get_title() for a in axes.flat]
    assert any("Greedy" in t for t in titles), titles

    I, T, _ = synthetic_pair(80)
    rows = bench_baselines([(I, T)])  # synthetic: no joint positions, so no OPW
    assert [r["name"] for r in rows] == ["OLTW", "Greedy"]

    (b1_claim,) = claims_by_id(["B1"])
    b1 = b1_claim.assess(load_context(res, mode="toy"))
    assert b1.ours.startswith("Greedy: similarity "), b1.ours


def test_every_name_a_notebook_imports_from_fpdtw_exists():
    """Catches a notebook left behind by a move of modules, without running it."""
    import importlib

    missing = []
    for path in sorted((REPO_ROOT / "notebooks").glob("*.ipynb")):
        for cell in json.loads(path.read_text())["cells"]:
            if cell["cell_type"] != "code":
                continue
            src = "".join(cell["source"])
            src = "\n".join(x for x in src.splitlines() if not x.lstrip().startswith(("%", "!")))
            for node in ast.walk(ast.parse(src)):
                if isinstance(node, ast.ImportFrom) and (node.module or "").startswith("fpdtw"):
                    mod = importlib.import_module(node.module)
                    missing += [
                        f"{path.name}: {node.module}.{a.name}"
                        for a in node.names
                        if not hasattr(mod, a.name)
                        and importlib.util.find_spec(f"{node.module}.{a.name}") is None
                    ]
                elif isinstance(node, ast.Import):
                    for a in node.names:
                        if a.name.startswith("fpdtw"):
                            importlib.import_module(a.name)
    assert not missing, missing


def test_every_notebook_is_in_the_figure_map():
    on_disk = sorted(p.stem for p in (REPO_ROOT / "notebooks").glob("[0-9]*.ipynb"))
    assert sorted(figure_map.by_stem()) == on_disk


def test_every_notebook_says_what_it_makes():
    """Each notebook's opening cell names every file the map says it makes."""
    for nb in figure_map.NOTEBOOKS:
        cells = json.loads((REPO_ROOT / "notebooks" / f"{nb.stem}.ipynb").read_text())["cells"]
        first = "".join(cells[0]["source"])
        missing = [m for m in nb.makes if m not in first]
        assert not missing, f"{nb.stem} does not mention {missing}"


def test_the_notebook_table_is_the_figure_map():
    page = (REPO_ROOT / "docs" / "notebooks.md").read_text()
    assert figure_map.readme_table() in page


def test_committed_figures_are_in_the_map():
    made = {m for nb in figure_map.NOTEBOOKS for m in nb.makes}
    stems = {p.name.split(".")[0] for p in (REPO_ROOT / "figures").iterdir() if p.is_file()}
    stems -= {"ENVIRONMENT", "README"}
    assert stems <= made, sorted(stems - made)


def test_makefile_rules_come_from_the_map(tmp_path):
    text = figure_map.makefile()
    for nb in figure_map.NOTEBOOKS:
        for m in nb.makes:
            assert f"$(eval $(call FIGURE_RULE,{m},{nb.stem}))" in text
    assert (
        "build/notebooks/06_fig5_fig6_scores.ipynb: build/notebooks/05_run_experiments.ipynb"
        in text
    )
    makefile = (REPO_ROOT / "Makefile").read_text()
    assert "-include build/figure_map.mk" in makefile
    assert "$(call FIGURE_RULE" not in makefile.replace("define FIGURE_RULE", "")
