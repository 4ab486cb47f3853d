"""docs/history.md ("How this analysis was made") against the git history it is read from.

Every commit hash on the page must name a commit of this repository, and every table row's
date (and time, UTC) must be its commit's author date; so must every hash that a paragraph
of the sources citing the page names (README, docstrings, notebooks' prose). Outside a git
checkout (an unpacked sdist) there is no history to check against, and the test says so.
"""

from __future__ import annotations

import json
import re
import shutil
import subprocess
from datetime import UTC, datetime

import pytest

from fpdtw.paper.paths import REPO_ROOT

PAGE = REPO_ROOT / "docs" / "history.md"
#: A commit hash as the page writes it: 7 to 40 hex digits standing alone.
HASH = re.compile(r"(?<![0-9A-Za-z])[0-9a-f]{7,40}(?![0-9A-Za-z])")
#: A choice dated by its commit in prose: "committed in 578ff6e", "chosen in f88f748".
DATED = re.compile(r"\b(?:committed|chosen)\b[^.]{0,40}?(?<![0-9A-Za-z])[0-9a-f]{7,40}\b")
#: A table row: | YYYY-MM-DD HH:MM | `hash` | ...
ROW = re.compile(r"^\|\s*(\d{4}-\d{2}-\d{2})(?:\s+(\d{2}:\d{2}))?\s*\|\s*`?([0-9a-f]{7,40})`?\s*\|")


def _git(*args) -> str:
    return subprocess.run(
        ["git", "-C", str(REPO_ROOT), *args], capture_output=True, text=True, check=True
    ).stdout.strip()


@pytest.fixture(scope="module")
def checkout():
    if shutil.which("git") is None:
        pytest.skip("git is not installed: docs/history.md cannot be checked against history")
    try:
        top = _git("rev-parse", "--show-toplevel")
    except subprocess.CalledProcessError:
        pytest.skip(f"{REPO_ROOT} is not a git checkout (e.g. an unpacked sdist): no history")
    if top and not REPO_ROOT.samefile(top):
        pytest.skip(f"{REPO_ROOT} lies inside another repository ({top}), not its own checkout")
    return top


def _exists(h: str) -> bool:
    r = subprocess.run(
        ["git", "-C", str(REPO_ROOT), "cat-file", "-e", f"{h}^{{commit}}"], capture_output=True
    )
    return r.returncode == 0


def _shallow_hint() -> str:
    shallow = _git("rev-parse", "--is-shallow-repository") == "true"
    return " (this clone is shallow: git fetch --unshallow)" if shallow else ""


def test_page_exists_with_its_title():
    text = PAGE.read_text(encoding="utf-8")
    assert text.startswith("# How this analysis was made\n")


def test_every_hash_on_the_page_is_a_commit_of_this_repository(checkout):
    hashes = sorted(set(HASH.findall(PAGE.read_text(encoding="utf-8"))))
    assert len(hashes) >= 10, hashes
    missing = [h for h in hashes if not _exists(h)]
    assert not missing, f"not commits of this repository: {missing}{_shallow_hint()}"


def test_every_row_is_dated_by_its_commit(checkout):
    rows = [m for ln in PAGE.read_text(encoding="utf-8").splitlines() if (m := ROW.match(ln))]
    assert len(rows) >= 15, "the page's tables lost their rows"
    wrong = []
    for m in rows:
        day, hhmm, h = m.groups()
        assert _exists(h), f"{h} is not a commit of this repository{_shallow_hint()}"
        at = datetime.fromtimestamp(int(_git("log", "-1", "--format=%at", h)), tz=UTC)
        if day != at.strftime("%Y-%m-%d") or (hhmm and hhmm != at.strftime("%H:%M")):
            wrong.append(f"{h}: page {day} {hhmm or ''}, author date {at:%Y-%m-%d %H:%M} UTC")
    assert not wrong, "\n".join(wrong)


def _citing_paragraphs():
    """(file, paragraph) for every paragraph that cites docs/history.md or dates a choice by
    its commit ("committed in <hash>"), in README, ARTIFACT, the other pages of docs/, the
    package, the tests and the notebooks' Markdown, of the files that cite the page."""
    files = [REPO_ROOT / "README.md", REPO_ROOT / "ARTIFACT.md"]
    files += [f for f in sorted((REPO_ROOT / "docs").glob("*.md")) if f != PAGE]
    for folder, pattern in (("fpdtw", "*.py"), ("tests", "*.py"), ("notebooks", "*.ipynb")):
        files += sorted((REPO_ROOT / folder).rglob(pattern))
    for f in files:
        if not f.is_file() or f.name == "test_history.py":
            continue
        text = f.read_text(encoding="utf-8")
        if "docs/history.md" not in text:
            continue
        if f.suffix == ".ipynb":
            cells = json.loads(text)["cells"]
            text = "\n\n".join("".join(c["source"]) for c in cells if c["cell_type"] == "markdown")
        for para in re.split(r"\n\s*\n", text):
            if "docs/history.md" in para or DATED.search(para):
                yield f.relative_to(REPO_ROOT).as_posix(), para


def test_hashes_cited_beside_the_page_are_commits(checkout):
    cited = [(f, h) for f, para in _citing_paragraphs() for h in HASH.findall(para)]
    assert len({f for f, _ in cited}) >= 10, "fewer sources cite docs/history.md than expected"
    missing = sorted({f"{f}: {h}" for f, h in cited if not _exists(h)})
    assert not missing, f"not commits of this repository{_shallow_hint()}: {missing}"
