"""environment.yml (conda users) must agree with pyproject.toml (pip, the Makefile)."""

from __future__ import annotations

import re
import tomllib

import yaml
from packaging.requirements import Requirement

from fpdtw.paths import REPO_ROOT


def _pyproject():
    return tomllib.loads((REPO_ROOT / "pyproject.toml").read_text())


def _pyproject_requirements():
    project = _pyproject()["project"]
    reqs = list(project["dependencies"])
    for extra in project["optional-dependencies"].values():
        reqs += extra
    return {Requirement(r).name.lower(): Requirement(r) for r in reqs}


def _conda_requirements():
    env = yaml.safe_load((REPO_ROOT / "environment.yml").read_text())
    out = {}
    pip_section = []
    for dep in env["dependencies"]:
        if isinstance(dep, dict):
            pip_section += dep.get("pip", [])
            continue
        name = re.split(r"[<>=!~ ]", dep, maxsplit=1)[0]
        spec = dep[len(name) :].strip()
        if spec.startswith("=") and not spec.startswith("=="):
            spec = "==" + spec[1:] + ".*"  # conda "=3.11" means 3.11.*
        out[name.lower()] = Requirement(name + spec)
    for dep in pip_section:
        if dep.startswith("-e") or dep.startswith("."):
            continue
        r = Requirement(dep)
        out[r.name.lower()] = r
    return env, pip_section, out


def test_environment_has_conda_forge_and_installs_the_package_editable():
    env, pip_section, _ = _conda_requirements()
    assert env["channels"] == ["conda-forge"]
    assert any(p.replace(" ", "").startswith("-e.") for p in pip_section)
    assert "[test,notebooks]" in " ".join(pip_section)


def test_same_python():
    _, _, conda = _conda_requirements()
    requires = _pyproject()["project"]["requires-python"]
    assert str(conda["python"].specifier) == requires


def test_same_dependencies_and_versions():
    _, _, conda = _conda_requirements()
    conda = {k: v for k, v in conda.items() if k not in {"python", "pip"}}
    pip = _pyproject_requirements()
    assert set(conda) == set(pip), (
        f"only in environment.yml: {sorted(set(conda) - set(pip))}; "
        f"only in pyproject.toml: {sorted(set(pip) - set(conda))}"
    )
    for name, req in pip.items():
        assert str(conda[name].specifier) == str(req.specifier), name


def test_extras_named_in_environment_exist():
    extras = set(_pyproject()["project"]["optional-dependencies"])
    assert {"test", "notebooks"} <= extras
