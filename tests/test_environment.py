"""environment.yml (conda users), requirements.lock (the Makefile) and pyproject.toml agree."""

from __future__ import annotations

import importlib.metadata
import re
import sys
import tomllib
from pathlib import Path

import pytest
import yaml
from packaging.markers import default_environment
from packaging.requirements import Requirement
from packaging.specifiers import SpecifierSet
from packaging.utils import canonicalize_name
from packaging.version import Version

from fpdtw.paper.paths import REPO_ROOT


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
    (editable,) = [p for p in pip_section if p.replace(" ", "").startswith("-e.")]
    named = set(editable.split("[", 1)[1].rstrip("]").split(","))
    assert named == set(_pyproject()["project"]["optional-dependencies"])  # every extra


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


# -- requirements.lock ----------------------------------------------------------------
#
# `make lock` writes requirements.lock with uv (`uv pip compile pyproject.toml --extra ...
# --generate-hashes --python-version 3.11 --python-platform x86_64-unknown-linux-gnu`);
# `make env` installs it with `pip install --require-hashes`. These tests fail when the lock
# has fallen behind pyproject.toml or environment.yml: rerun `make lock`.

LOCK = REPO_ROOT / "requirements.lock"
_REFRESH = "run `make lock` to refresh requirements.lock"
_PIN = re.compile(r"^(?P<name>[A-Za-z0-9][A-Za-z0-9._-]*)==(?P<version>[^\s;\\]+)$")
_HASH = re.compile(r"^--hash=sha256:[0-9a-f]{64}$")


def _makefile_var(name: str) -> str:
    m = re.search(rf"^{name}\s*:?=\s*(\S+)\s*$", (REPO_ROOT / "Makefile").read_text(), re.M)
    assert m, f"Makefile defines no {name}"
    return m.group(1)


def _parse_lock(text: str):
    """(pins, header, problems): pins maps a canonical name to (version, hashes)."""
    pins, problems = {}, []
    header = "\n".join(line for line in text.splitlines()[:3] if line.startswith("#"))
    for raw in text.replace("\\\n", " ").splitlines():
        line = raw.strip()
        if not line or line.startswith("#"):
            continue
        head, *options = line.split()
        m = _PIN.match(head)
        if not m:
            problems.append(f"not an exact `name==version` pin: {line[:80]!r}")
            continue
        name = canonicalize_name(m["name"])
        bad = [o for o in options if not _HASH.match(o)]
        if bad or not options:
            problems.append(f"{name}: needs one or more --hash=sha256:<hex> and nothing else")
        if name in pins:
            problems.append(f"{name}: pinned twice")
        pins[name] = (Version(m["version"]), [o.split(":", 1)[1] for o in options])
    return pins, header, problems


def _lock_target() -> dict:
    """Marker environment of the lock's platform (CPython 3.11 on Linux x86_64)."""
    py = _makefile_var("LOCK_PYTHON")
    env = dict(default_environment())
    env.update(
        python_version=py,
        python_full_version=f"{py}.0",
        sys_platform="linux",
        platform_system="Linux",
        platform_machine="x86_64",
        os_name="posix",
        implementation_name="cpython",
        platform_python_implementation="CPython",
    )
    return env


def _locked_extras(header: str) -> list[str]:
    return re.findall(r"--extra[ =](\S+)", header)


def _lock_problems(text: str, pyproject: dict) -> list[str]:
    """Everything that makes this lock text unfit for this parsed pyproject.toml."""
    pins, header, problems = _parse_lock(text)
    project = pyproject["project"]
    extras = _locked_extras(header)
    if "uv pip compile pyproject.toml" not in header or "--generate-hashes" not in header:
        problems.append("the header does not say `uv pip compile pyproject.toml --generate-hashes`")
    missing_extras = set(project.get("optional-dependencies", {})) - set(extras)
    if missing_extras:
        problems.append(f"extras not locked: {sorted(missing_extras)}")
    reqs = list(project["dependencies"])
    for extra in extras:
        reqs += project.get("optional-dependencies", {}).get(extra, [])
    target = _lock_target()
    for text_req in reqs:
        req = Requirement(text_req)
        if req.marker is not None and not req.marker.evaluate(target | {"extra": ""}):
            continue
        name = canonicalize_name(req.name)
        if name == canonicalize_name(project["name"]):
            continue
        if name not in pins:
            problems.append(f"{req}: in pyproject.toml, not pinned in the lock")
        elif not req.specifier.contains(pins[name][0], prereleases=True):
            problems.append(f"{req}: pyproject.toml's range excludes the locked {pins[name][0]}")
    if canonicalize_name(project["name"]) in pins:
        problems.append(f"the package itself ({project['name']}) is pinned")
    m = re.search(r"--python-version[ =](\S+)", header)
    if not m or not SpecifierSet(project["requires-python"]).contains(m.group(1)):
        problems.append(f"locked for Python {m and m.group(1)}, not {project['requires-python']}")
    return problems


def _lock():
    return _parse_lock(LOCK.read_text())


def test_lock_pins_every_package_exactly_with_hashes():
    pins, _, problems = _lock()
    assert not problems, "\n".join(problems)
    assert len(pins) > 50  # the whole transitive closure, not just the direct requirements
    for name, (_, hashes) in pins.items():
        assert len(set(hashes)) == len(hashes), f"{name}: a hash repeats"
    # the two FBX bindings come as sdists only: their sdists' hashes are locked too
    for sdist_only in ("pufbx", "pyufbx"):
        assert sdist_only in pins and pins[sdist_only][1], sdist_only


def test_lock_satisfies_pyproject():
    problems = _lock_problems(LOCK.read_text(), _pyproject())
    assert not problems, _REFRESH + ":\n" + "\n".join(problems)


def test_lock_is_for_the_makefile_target_and_extras():
    _, header, _ = _lock()
    assert f"--python-version {_makefile_var('LOCK_PYTHON')} " in header
    assert f"--python-platform {_makefile_var('LOCK_PLATFORM')} " in header
    # `make env LOCKED=0` installs the same extras as the lock holds
    assert _locked_extras(header) == _makefile_var("EXTRAS").split(","), _REFRESH
    assert set(_locked_extras(header)) == set(_pyproject()["project"]["optional-dependencies"])


@pytest.mark.parametrize(
    "mutate, expected",
    [
        # a requirement added to pyproject.toml, not yet locked
        (
            lambda t, p: p["project"]["dependencies"].append("not-yet-locked[extra]>=2024.1"),
            "not-yet-locked[extra]>=2024.1: in",
        ),
        # a range raised past the locked version
        (lambda t, p: p["project"]["dependencies"].append("numpy>=999"), "excludes the locked"),
        # an extra added to pyproject.toml that the lock was not made with
        (lambda t, p: p["project"]["optional-dependencies"].update(new=["sphinx"]), "'new'"),
        # a newer Python required than the lock was made for
        (lambda t, p: p["project"].update({"requires-python": ">=3.99"}), "locked for Python"),
        # a pin dropped from the lock, a hash dropped, a range instead of a pin
        (lambda t, p: re.sub(r"(?m)^scipy==", "scipy-gone==", t), "scipy>=1.11: in"),
        (
            lambda t, p: re.sub(r"(?m)^(seaborn==\S+) \\\n(\s+--hash=\S+ ?\\?\n)+", r"\1\n", t),
            "--hash",
        ),
        (lambda t, p: re.sub(r"(?m)^tqdm==", "tqdm>=", t), "not an exact"),
    ],
)
def test_lock_check_catches(mutate, expected):
    text, pyproject = LOCK.read_text(), _pyproject()
    assert not _lock_problems(text, pyproject)
    changed = mutate(text, pyproject)
    if isinstance(changed, str):
        text = changed
    problems = _lock_problems(text, pyproject)
    assert any(expected in p for p in problems), problems


def _installed():
    return {canonicalize_name(d.metadata["Name"]): d for d in importlib.metadata.distributions()}


def _closure(pins: dict, installed: dict):
    """Walk pyproject's requirements through the installed packages' metadata.

    Every requirement reached (with its extras, markers evaluated for the lock's platform)
    must be pinned within its range. Only packages installed at their locked version are
    walked into (their metadata is the locked one's). Returns (problems, reached, walked).
    """
    versions = {n: Version(d.version) for n, d in installed.items()}
    walked = {n for n, (v, _) in pins.items() if versions.get(n) == v}
    own = canonicalize_name(_pyproject()["project"]["name"])
    todo = list(_pyproject_requirements().values())
    target, seen, reached, problems = _lock_target(), set(), set(), []
    while todo:
        req = todo.pop()
        name = canonicalize_name(req.name)
        if name == own:
            continue
        if name not in pins:
            problems.append(f"{req}: needed, not pinned")
            continue
        reached.add(name)
        if not req.specifier.contains(pins[name][0], prereleases=True):
            problems.append(f"{req}: needed, the lock has {pins[name][0]}")
        extras = frozenset({""} | {canonicalize_name(e) for e in req.extras})
        if name not in walked or (name, extras) in seen:
            continue
        seen.add((name, extras))
        for dep in installed[name].requires or []:
            d = Requirement(dep)
            if d.marker is None or any(d.marker.evaluate(target | {"extra": e}) for e in extras):
                todo.append(d)
    return problems, reached, walked


def _walkable(pins, installed):
    _, _, walked = _closure(pins, installed)
    if len(walked) < len(pins) // 2:
        pytest.skip("the running environment was not installed from requirements.lock")


def test_lock_holds_every_dependency_of_what_it_pins():
    """Every requirement of pyproject and of every locked package is pinned in range, and,
    when the whole lock is installed, every pin is needed (no leftover of a removed
    dependency)."""
    pins, installed = _lock()[0], _installed()
    _walkable(pins, installed)
    problems, reached, walked = _closure(pins, installed)
    assert not problems, _REFRESH + ":\n" + "\n".join(problems)
    if walked == set(pins):
        assert reached == set(pins), f"pinned, needed by nothing: {sorted(set(pins) - reached)}"


def test_lock_closure_check_catches_a_missing_transitive_pin_and_a_leftover():
    pins, installed = _lock()[0], _installed()
    _walkable(pins, installed)
    # pycparser is needed by cffi (argon2-cffi-bindings), not by pyproject.toml itself
    assert "pycparser" in pins and "pycparser" not in _pyproject_requirements()
    assert installed["cffi"].version == str(pins["cffi"][0]), "cffi not installed as locked"
    without = {n: pin for n, pin in pins.items() if n != "pycparser"}
    problems, _, _ = _closure(without, installed)
    assert any(p.startswith("pycparser") and "not pinned" in p for p in problems), problems
    leftover = dict(pins, **{"no-longer-needed": (Version("1.0"), ["0" * 64])})
    _, reached, _ = _closure(leftover, installed)
    assert "no-longer-needed" not in reached and "pycparser" in reached


def test_locked_env_is_exactly_the_lock():
    """`make env` (LOCKED=1) installed every pin at its version and nothing else."""
    venv = REPO_ROOT / ".venv"
    if Path(sys.prefix).resolve() != venv.resolve() or not (venv / ".installed-locked").exists():
        pytest.skip("not running in a .venv that `make env` built from requirements.lock")
    pins, _, _ = _lock()
    installed = _installed()
    wrong = {
        n: (str(v), installed[n].version if n in installed else None)
        for n, (v, _) in pins.items()
        if n not in installed or Version(installed[n].version) != v
    }
    assert not wrong, f"locked vs installed: {wrong}"
    # the venv's own installer tools and the package itself are the only others
    extra = set(installed) - set(pins) - {"fpdtw", "pip", "setuptools", "wheel"}
    assert not extra, f"installed, not in the lock: {sorted(extra)}"


def test_environment_yml_ranges_admit_the_locked_versions():
    pins, _, _ = _lock()
    _, _, conda = _conda_requirements()
    py = Version(_makefile_var("LOCK_PYTHON"))
    assert conda["python"].specifier.contains(py), "environment.yml excludes the lock's Python"
    for name, req in conda.items():
        if name in {"python", "pip"}:
            continue
        key = canonicalize_name(name)
        assert key in pins, f"{name}: in environment.yml, not in requirements.lock ({_REFRESH})"
        assert req.specifier.contains(pins[key][0], prereleases=True), (
            f"{name}: environment.yml's {req.specifier} excludes the locked {pins[key][0]}"
        )
