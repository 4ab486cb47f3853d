"""Every ``Notebook:`` line of a docstring in fpdtw/ is true.

A docstring's ``Notebook:`` line sends a reader to the notebook where the function is seen at
work (libfmp's convention), so each one must name a notebook that exists and whose code
cells really use what the docstring documents:

* a function or a class: the notebook's code refers to that very object, through any import
  (``from fpdtw.online import MethodA``, ``plain.geo_distance``, ``oe.example_curve``).
  Names are resolved by importing what the notebook imports, so a plain function and a
  kernel of the same name (``fpdtw.plain.similarity``, ``fpdtw.metrics.similarity``) are
  told apart;
* a method: the notebook uses its class and calls ``.method``;
* a module (its own docstring): the notebook imports the module or something defined in it.
"""

from __future__ import annotations

import ast
import importlib
import json
import re
from functools import cache
from pathlib import Path

import pytest

from fpdtw.paper.paths import REPO_ROOT

PKG = REPO_ROOT / "fpdtw"
NOTEBOOKS = REPO_ROOT / "notebooks"
_TAG = re.compile(r"\s*Notebooks?:\s*(.*)")
_FIELD = re.compile(r"\s*[A-Z][\w ]*:\s")  # the next docstring field ("Paper: ...")
_NOTEBOOK = re.compile(r"\b(\d\d_\w+?)(?:\.ipynb)?\b")


def notebook_cells(path: Path) -> list:
    """The source of every code cell of a notebook."""
    cells = json.loads(path.read_text())["cells"]
    return ["".join(c["source"]) for c in cells if c["cell_type"] == "code"]


def _resolve(node, aliases):
    """The object an expression of names and attributes stands for, or None."""
    if isinstance(node, ast.Name):
        return aliases.get(node.id)
    if isinstance(node, ast.Attribute):
        base = _resolve(node.value, aliases)
        return None if base is None else getattr(base, node.attr, None)
    return None


def used_objects(cells) -> tuple:
    """What code refers to: the fpdtw objects (by id) and the attribute names it uses.

    Parameters
    ----------
    cells : list of str
        Code cells, in order.

    Returns
    -------
    objects : dict
        ``id(obj) -> obj`` for every fpdtw module, function and class the code imports
        and every attribute of them it reads.
    attributes : set of str
        Every ``.name`` the code reads (for methods).
    """
    aliases, objects, attributes = {}, {}, set()
    for source in cells:
        tree = ast.parse(source)
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom) and (node.module or "").startswith("fpdtw"):
                module = importlib.import_module(node.module)
                for a in node.names:
                    obj = getattr(module, a.name, None)
                    if obj is None:
                        obj = importlib.import_module(f"{node.module}.{a.name}")
                    aliases[a.asname or a.name] = obj
            elif isinstance(node, ast.Import):
                for a in node.names:
                    if a.name.startswith("fpdtw"):
                        module = importlib.import_module(a.name)
                        aliases[a.asname or "fpdtw"] = (
                            module if a.asname else importlib.import_module("fpdtw")
                        )
        for node in ast.walk(tree):
            if isinstance(node, ast.Attribute):
                attributes.add(node.attr)
            obj = _resolve(node, aliases)
            if obj is not None:
                objects[id(obj)] = obj
    for obj in aliases.values():
        objects[id(obj)] = obj
    return objects, attributes


@cache
def notebook_uses(name: str) -> tuple:
    """:func:`used_objects` of ``notebooks/<name>.ipynb``, or None if it does not exist."""
    path = NOTEBOOKS / f"{name}.ipynb"
    return used_objects(notebook_cells(path)) if path.is_file() else None


def docstring_tags(path: Path, root: Path = REPO_ROOT) -> list:
    """Every ``Notebook:`` tag of a module of fpdtw/.

    Returns
    -------
    tags : list of tuple
        ``(line, kind, qualified name, notebook)``; ``kind`` is ``"module"``,
        ``"function"``, ``"class"`` or ``"method"``; one entry per notebook named.
    """
    module = ".".join(path.relative_to(root).with_suffix("").parts)
    module = module.removesuffix(".__init__")
    tree = ast.parse(path.read_text())
    nodes = [(tree, "module", module, 1)]
    for top in tree.body:
        if isinstance(top, ast.FunctionDef | ast.ClassDef):
            kind = "class" if isinstance(top, ast.ClassDef) else "function"
            nodes.append((top, kind, f"{module}:{top.name}", top.lineno))
            if isinstance(top, ast.ClassDef):
                nodes += [
                    (f, "method", f"{module}:{top.name}.{f.name}", f.lineno)
                    for f in top.body
                    if isinstance(f, ast.FunctionDef)
                ]
    tags = []
    for node, kind, qualname, line in nodes:
        lines = (ast.get_docstring(node) or "").splitlines()
        for i, text in enumerate(lines):
            m = _TAG.match(text)
            if not m:
                continue
            names = m.group(1)
            for more in lines[i + 1 :]:  # a list continued on the next lines
                if not more.strip() or _FIELD.match(more):
                    break
                names += " " + more
            tags += [(line, kind, qualname, nb) for nb in _NOTEBOOK.findall(names)]
    return tags


def is_true(kind: str, qualname: str, notebook: str) -> bool:
    """Whether ``notebook``'s code uses the module, function, class or method."""
    uses = notebook_uses(notebook)
    if uses is None:
        return False
    objects, attributes = uses
    module_name, _, attr = qualname.partition(":")
    module = importlib.import_module(module_name)
    if kind == "module":
        return any(
            o is module or getattr(o, "__module__", None) == module_name for o in objects.values()
        )
    if kind == "method":
        cls_name, method = attr.split(".")
        return id(getattr(module, cls_name)) in objects and method in attributes
    return id(getattr(module, attr)) in objects


def all_tags() -> list:
    return [(p, *t) for p in sorted(PKG.rglob("*.py")) for t in docstring_tags(p)]


def test_every_notebook_tag_names_a_notebook_that_uses_it():
    tags = all_tags()
    assert len(tags) > 50  # the docstrings do carry tags
    false = [
        f"{p.relative_to(REPO_ROOT)}:{line} {kind} {qualname} -> {nb}"
        for p, line, kind, qualname, nb in tags
        if not is_true(kind, qualname, nb)
    ]
    assert not false, f"{len(false)} of {len(tags)} Notebook: tags are false:\n" + "\n".join(false)


def test_the_check_tells_a_plain_function_from_a_kernel_of_the_same_name():
    imports = "from fpdtw import plain\nimport fpdtw.paper.opw_eval as oe\n"
    imports += "from fpdtw.online import MethodA"
    code = "d = plain.geo_distance(a, b)\nr = results.get('x')\nMethodA(I).reset()\noe.run_opw"
    objects, attributes = used_objects([imports, code])
    from fpdtw import costs, plain
    from fpdtw.online import method_a
    from fpdtw.paper import opw_eval

    assert id(plain.geo_distance) in objects and id(costs.geo_distance) not in objects
    assert id(method_a.MethodA) in objects and id(opw_eval.run_opw) in objects
    assert {"get", "reset"} <= attributes


@pytest.mark.parametrize(
    "kind, qualname, notebook, expected",
    [
        ("function", "fpdtw.plain:method_c_step", "03_fig2_fig4_windows", True),
        ("function", "fpdtw.costs:geo_distance", "02_fig1_oedtw", False),  # plain's is used
        ("function", "fpdtw.plain:method_c_step", "01_data_and_motions", False),
        ("function", "fpdtw.plain:method_c_step", "99_no_such_notebook", False),
        ("class", "fpdtw.online.method_c:MethodC", "03_fig2_fig4_windows", True),
        ("module", "fpdtw.plain", "03_fig2_fig4_windows", True),
    ],
)
def test_is_true_on_known_cases(kind, qualname, notebook, expected):
    assert is_true(kind, qualname, notebook) is expected


def test_a_tag_list_may_continue_on_the_next_line(tmp_path):
    f = tmp_path / "fpdtw" / "x.py"
    f.parent.mkdir()
    f.write_text(
        'def f():\n    """Doc.\n\n    Notebook: 06_a.ipynb, 07_b.ipynb,\n    09_c.ipynb\n'
        '    Paper: eq. 2.\n    """\n'
    )
    tags = docstring_tags(f, root=tmp_path)
    assert [(t[1], t[2], t[3]) for t in tags] == [
        ("function", "fpdtw.x:f", nb) for nb in ("06_a", "07_b", "09_c")
    ]
