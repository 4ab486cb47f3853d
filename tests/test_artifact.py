"""ARTIFACT.md, the artifact appendix: every claim has a row, every command it gives runs.

The claim ids come from two places, and both must be covered: the committed claims table
(``figures/claims.csv``, what ``make figures`` last wrote) and the claims the code checks
(:data:`fpdtw.paper.claims.CLAIMS`). Each row's verdict is the committed table's, and so
is its quoted value for the deterministic claims (``stable``); each command is a make
target that make can resolve (``make -n``) or an ``fpdtw`` command line the real parser
accepts.
"""

from __future__ import annotations

import csv
import os
import re
import shlex
import subprocess

import pytest

from fpdtw.app.cli import build_parser
from fpdtw.paper import claims
from fpdtw.paper.paths import REPO_ROOT

ARTIFACT = REPO_ROOT / "ARTIFACT.md"
#: The sections of the artifact-appendix form, in order.
SECTIONS = ["Abstract", "Checklist", "Description", "Installation", "Workflow", "Steps",
            "Claims", "Notes"]  # fmt: skip
#: What the checklist must cover.
CHECKLIST = ["Algorithms", "Data", "Licences", "Environment", "Hardware", "Metrics", "Outputs",
             "Disk", "Preparation time", "Run time"]  # fmt: skip


def _text() -> str:
    return ARTIFACT.read_text(encoding="utf-8")


def _section(name: str) -> str:
    return _text().split(f"\n## {name}", 1)[1].split("\n## ", 1)[0]


def _cells(line: str) -> list[str]:
    return [c.strip() for c in line.strip().strip("|").split("|")]


def artifact_rows() -> dict[str, dict]:
    """The claims table of ARTIFACT.md: id -> its cells by column name."""
    lines = [ln for ln in _section("Claims").splitlines() if ln.startswith("|")]
    header = [h.lower() for h in _cells(lines[0])]
    assert header[:3] == ["id", "claim", "command"], header
    rows = {}
    for line in lines[2:]:
        cells = dict(zip(header, _cells(line), strict=True))
        assert cells["id"] not in rows, f"claim {cells['id']} has two rows"
        rows[cells["id"]] = cells
    return rows


def committed_claims() -> dict[str, dict]:
    with open(REPO_ROOT / "figures" / "claims.csv", newline="", encoding="utf-8") as f:
        return {r["id"]: r for r in csv.DictReader(f)}


def _commands(text: str) -> list[str]:
    """The commands in a cell or block: its code spans that start with make or fpdtw."""
    spans = re.findall(r"`([^`]+)`", text)
    return [s for s in spans if re.match(r"(\.venv/bin/)?(make|fpdtw)( |$)", s)]


def check_command(command: str) -> str | None:
    """None if the command runs here (make resolves its targets, argparse takes the fpdtw
    line), else why not."""
    argv = shlex.split(command)
    if argv[0].endswith("fpdtw"):
        try:
            build_parser().parse_args(argv[1:])
        except SystemExit:
            return f"{command!r}: fpdtw's parser refuses it"
        return None
    targets = [a for a in argv[1:] if not a.startswith("-") and "=" not in a]
    if not targets:
        return f"{command!r}: names no make target"
    env = {k: v for k, v in os.environ.items() if k not in ("MAKEFLAGS", "MFLAGS", "MAKELEVEL")}
    r = subprocess.run(
        ["make", "-n", *argv[1:]], cwd=REPO_ROOT, capture_output=True, text=True, env=env
    )
    if r.returncode != 0:
        return f"{command!r}: make -n fails: {r.stderr.strip()[-300:]}"
    return None


def test_the_appendix_has_every_section_and_checklist_item():
    headings = re.findall(r"^## (\w+)", _text(), re.M)
    assert headings == SECTIONS, headings
    checklist = _section("Checklist")
    items = re.findall(r"^- \*\*([^*]+)\*\*", checklist, re.M)
    assert items == CHECKLIST, items


def test_every_claim_has_a_row():
    rows = artifact_rows()
    in_code = [c.id for c in claims.CLAIMS]
    committed = list(committed_claims())
    assert not [i for i in in_code if i not in rows], "claims of CLAIMS without a row"
    assert not [i for i in committed if i not in rows], "claims of claims.csv without a row"
    assert not [i for i in rows if i not in set(in_code) | set(committed)], "rows of no claim"


def test_each_row_gives_the_committed_verdict_and_value():
    committed = committed_claims()
    for cid, row in artifact_rows().items():
        if cid not in committed:
            continue
        c = committed[cid]
        verdict = re.match(r"\*\*(yes|no|partly|n/a)\*\*", row["expected result"])
        assert verdict, f"claim {cid}: the expected result starts with its verdict in bold"
        assert verdict.group(1) == c["holds"], f"claim {cid}: claims.csv says {c['holds']}"
        if c["stable"] == "True":
            quoted = re.search(r'ours "([^"]*)"', row["expected result"])
            assert quoted and quoted.group(1) == c["ours"], (
                f'claim {cid}: quote ours as claims.csv has it: ours "{c["ours"]}"'
            )


def test_each_row_has_a_command_a_time_and_a_peak_memory():
    for cid, row in artifact_rows().items():
        assert _commands(row["command"]), f"claim {cid}: no make or fpdtw command"
        assert re.search(r"\d+(\.\d+)? min", row["time, 2 cores"]), (cid, row["time, 2 cores"])
        assert re.search(r"\d+(\.\d+)? GiB|\d+ MiB", row["peak memory"]), (cid, row["peak memory"])


def test_every_command_in_the_appendix_runs_here():
    commands = sorted(set(_commands(_text())))
    assert len(commands) >= 10
    problems = [why for c in commands if (why := check_command(c))]
    assert not problems, "\n".join(problems)


@pytest.mark.parametrize(
    "command",
    ["make figures/no_such_figure.pdf", "make no-such-target", "fpdtw align --no-such-option",
     "fpdtw experiments run --mode nonsense", "make"],
)  # fmt: skip
def test_the_command_check_refuses(command):
    assert check_command(command) is not None
