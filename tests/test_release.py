"""Release hygiene: make help lists every target, the changelog names this version, and the
sdist holds the whole reproduction (every file git tracks), as MANIFEST.in says."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
import tarfile
import tomllib

import pytest

from fpdtw.paper.paths import REPO_ROOT

#: Keep a Changelog's kinds of change.
CHANGE_KINDS = {"Added", "Changed", "Deprecated", "Removed", "Fixed", "Security"}


#: Phony targets that are parts of make test, run by it (not listed by make help).
PARTS = {"test-suite", "test-smoke", "test-nbval-1", "test-nbval-2"}


def _phony_targets() -> list[str]:
    text = (REPO_ROOT / "Makefile").read_text().replace("\\\n", " ")
    lines = [ln for ln in text.splitlines() if ln.startswith(".PHONY:")]
    return [t for ln in lines for t in ln.split(":", 1)[1].split()]


def test_make_help_lists_every_target():
    env = {k: v for k, v in os.environ.items() if k not in ("MAKEFLAGS", "MFLAGS", "MAKELEVEL")}
    out = subprocess.run(
        ["make", "-s", "help"], cwd=REPO_ROOT, capture_output=True, text=True, check=True, env=env
    ).stdout
    listed = set(re.findall(r"make ([a-z][\w-]*)", out))
    targets = _phony_targets()
    assert {"test", "test-all", "dist", "figures", "help"} | PARTS <= set(targets)
    assert not [t for t in targets if t not in listed and t not in PARTS], out


def test_changelog_is_keep_a_changelog_for_this_version():
    text = (REPO_ROOT / "CHANGELOG.md").read_text()
    assert text.startswith("# Changelog\n") and "keepachangelog.com" in text
    versions = re.findall(r"^## \[([^\]]+)\] - (\S+)$", text, re.M)
    project = tomllib.loads((REPO_ROOT / "pyproject.toml").read_text())["project"]
    assert versions and versions[0][0] == project["version"], versions
    assert all(re.fullmatch(r"\d{4}-\d{2}-\d{2}|Unreleased", date) for _, date in versions)
    kinds = re.findall(r"^### (.+)$", text, re.M)
    assert kinds and set(kinds) <= CHANGE_KINDS, kinds


def _tracked() -> set[str]:
    out = subprocess.run(
        ["git", "ls-files", "-z"], cwd=REPO_ROOT, capture_output=True, text=True, check=True
    ).stdout
    return {p for p in out.split("\0") if p and (REPO_ROOT / p).is_file()}


def test_the_sdist_holds_every_tracked_file(tmp_path):
    """The sdist of the tracked files (as they are in the working tree), built offline
    (setuptools of .venv, no isolation) in a copy, holds every one of them: the notebooks,
    tests, manifests, figures and the lock included."""
    if shutil.which("git") is None or not (REPO_ROOT / ".git").exists():
        pytest.skip("not a git checkout (an unpacked sdist): nothing to compare with")
    tracked = _tracked()
    src = tmp_path / "src"
    for rel in tracked:
        (src / rel).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(REPO_ROOT / rel, src / rel)
    subprocess.run(
        [sys.executable, "-m", "build", "--sdist", "--no-isolation", "--outdir", str(tmp_path),
         str(src)],
        check=True, capture_output=True, text=True,
    )  # fmt: skip
    (sdist,) = tmp_path.glob("fpdtw-*.tar.gz")
    with tarfile.open(sdist) as tar:
        names = {n.split("/", 1)[1] for n in tar.getnames() if "/" in n}
    missing = sorted(tracked - names)
    assert not missing, f"the sdist lacks {len(missing)} tracked files: {missing[:20]}"
    for needed in ("Makefile", "requirements.lock", "MANIFEST.in", "CHANGELOG.md",
                   "ARTIFACT.md", ".zenodo.json", "data_manifest/hdm05.toml",
                   "notebooks/12_claims.ipynb", "figures/claims.csv", "PKG-INFO"):  # fmt: skip
        assert needed in names, needed
    assert not [n for n in names if "__pycache__" in n or n.startswith(("build/", ".venv/"))]
