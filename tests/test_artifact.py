"""ARTIFACT.md, the artifact appendix: every claim has a row, every command it gives runs.

The claim ids come from two places, and both must be covered: the committed claims table
(``figures/claims.csv``, what ``make figures`` last wrote) and the claims the code checks
(:data:`fpdtw.paper.claims.CLAIMS`). The claims and steps tables are generated
(:func:`fpdtw.app.readme.artifact_blocks`) and must be what the committed files give; each
row's verdict and value are the committed table's; each command is a make target that make
can resolve (``make -n``) or an ``fpdtw`` command line the real parser accepts.
"""

from __future__ import annotations

import csv
import os
import re
import shlex
import subprocess

import pytest

from fpdtw.app import readme
from fpdtw.app.cli import build_parser
from fpdtw.paper import claims
from fpdtw.paper.claims.rules import CLAIM_VERDICTS
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
    """The cells of a table row (an escaped ``\\|`` stays inside its cell)."""
    return [c.strip() for c in re.split(r"(?<!\\)\|", line.strip()[1:-1])]


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
    """The commands in a text: the lines of its code blocks and its code spans that start
    with make or fpdtw."""
    blocks = re.findall(r"^```\w*\n(.*?)^```", text, re.S | re.M)
    lines = [ln.split("#")[0].strip() for b in blocks for ln in b.splitlines()]
    spans = re.findall(r"`([^`\n]+)`", re.sub(r"^```.*?^```", "", text, flags=re.S | re.M))
    return [s for s in lines + spans if re.match(r"(\.venv/bin/)?(make|fpdtw) \S", s)]


def _prose(text: str) -> str:
    """The text without its code blocks and code spans."""
    return re.sub(r"`[^`\n]*`", "", re.sub(r"^```.*?^```", "", text, flags=re.S | re.M))


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


def test_the_generated_blocks_are_what_the_committed_figures_give():
    """The steps and claims tables are generated (fpdtw.app.readme.artifact_blocks) from
    figures/ and the measurements kept in the steps block: nothing in them is typed."""
    text = _text()
    assert readme.render(text, readme.artifact_blocks(REPO_ROOT / "figures", text)) == text, (
        "ARTIFACT.md's generated blocks differ from figures/: run "
        "`python -m fpdtw.app.readme ARTIFACT.md --update` (make figures does)"
    )


def test_no_placeholder_is_left():
    left = re.findall(r"\b[A-Z]{3,}_[A-Z_]{3,}\b", _prose(_text()))
    assert not left, f"placeholders left in ARTIFACT.md: {left}"


def test_each_row_gives_the_committed_verdict_and_value():
    committed = committed_claims()
    verdicts = "|".join(re.escape(v) for v in CLAIM_VERDICTS)
    for cid, row in artifact_rows().items():
        c = committed[cid]
        verdict = re.match(rf"\*\*({verdicts})\*\*", row["expected result"])
        assert verdict, f"claim {cid}: the expected result starts with its verdict in bold"
        assert verdict.group(1) == c["holds"], f"claim {cid}: claims.csv says {c['holds']}"
        quoted = re.search(r'ours "([^"]*)"', row["expected result"])
        assert quoted and quoted.group(1) == c["ours"].replace("|", "\\|"), cid


def test_time_and_memory_are_measured():
    """Every claim's time is the sum of the measured steps its command runs and its memory
    the largest of their peaks; with nothing measured, this fails once figures/claims.csv
    is the claims package's (the lead measures after make figures), and says so before."""
    record = readme.steps_record(_text())
    steps = {s["name"]: s for s in record.get("steps") or []}
    if not steps:
        rows = list(committed_claims().values())
        msg = "ARTIFACT.md has no measured steps: run tools/measure_steps.py"
        if readme.claims_regenerated(rows):
            pytest.fail(msg)
        pytest.skip(f"{msg} (after make figures: figures/claims.csv predates the claims package)")
    for cid, row in artifact_rows().items():
        m = re.fullmatch(r"([\d.]+) min: (.+)", row["time, 2 cores"])
        assert m, f"claim {cid}: time as '<minutes> min: <step>, <step>'"
        chain = [x.strip() for x in m.group(2).split(",")]
        assert set(chain) <= set(steps), (cid, chain)
        assert abs(float(m.group(1)) * 60 - sum(steps[x]["seconds"] for x in chain)) <= 3, cid
        peak = max(steps[x]["peak_rss_mib"] for x in chain)
        assert row["peak memory"] == readme.memory(peak), cid


def _fake_record():
    """Every step of tools/measure_steps.py, step k taking k minutes and k x 100 MiB."""
    import importlib.util

    spec = importlib.util.spec_from_file_location(
        "measure_steps", REPO_ROOT / "tools" / "measure_steps.py"
    )
    M = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(M)
    steps = [dict(name=n, command=c, target=c.split()[-1], seconds=60.0 * k,
                  peak_rss_mib=100 * k, load_before=1.0, load_after=2.0)
             for k, (n, c) in enumerate(M.STEPS, 1)]  # fmt: skip
    return {"date": "2026-01-01", "commit": "abc1234", "cpus": 2, "steps": steps,
            "disk": {"results": 2048}}  # fmt: skip


def test_claim_times_follow_the_makefile(tmp_path):
    """Hand-checked chains: the walk pair's table (notebook 10) runs both grids (it prints a
    claim: the Makefile's CLAIM_NBS) but neither notebook 05 nor the benchmark; Table 2
    runs the benchmark and notebooks 05 and 09; a claim whose evidence names no figure is
    checked by notebook 12, which needs every step but the data."""
    record = _fake_record()
    rows = [dict(id="8", claim="c", paper="p", ours="o", holds="partly",
                 evidence="Fig. 8; fig8_walk_pair_scores", stable="True"),
            dict(id="4", claim="c", paper="p", ours="o", holds="yes",
                 evidence="Table 2; table2_time_per_frame", stable="False"),
            dict(id="6", claim="c", paper="p", ours="o", holds="no",
                 evidence="fig5/fig6 summaries", stable="True"),
            dict(id="7", claim="c", paper="p", ours="o", holds="yes",
                 evidence="Fig. 1 (02_fig1_oedtw); OE-DTW maps", stable="True")]  # fmt: skip
    parts = [dict(claim="8", part="8(a)", text="x below 18", verdict="holds",
                  quantity="deviation of x, frames", threshold="18")]  # fmt: skip
    block = readme.artifact_claims_block(rows, parts, record, REPO_ROOT / "figures", REPO_ROOT)
    lines = {ln.split(" | ")[0][2:]: ln for ln in block.splitlines() if ln.startswith("| ")}
    assert "`make figures/fig8_walk_pair_scores.csv`" in lines["8"]
    assert "8(a) x below 18 (deviation of x, frames vs 18)" in lines["8"]
    minutes = {s["name"]: s["seconds"] / 60 for s in record["steps"]}
    want = ["full grid", "study grid", "nb 10"]
    assert f"{sum(minutes[n] for n in want):.1f} min: {', '.join(want)} |" in lines["8"]
    assert lines["8"].endswith(f"| {readme.memory(100 * 11)} |")  # nb 10, the 11th step
    want = ["full grid", "study grid", "nb 05", "bench", "nb 09"]
    assert f"{sum(minutes[n] for n in want):.1f} min: {', '.join(want)} |" in lines["4"]
    assert "a timing" in lines["4"]
    assert "`make figures/claims.csv`" in lines["6"]
    want = [n for n in minutes if n != "data"]
    assert f"{sum(minutes[n] for n in want):.1f} min: {', '.join(want)} |" in lines["6"]
    # claim 7's number (every pair of the full grid) comes from notebook 12, not from Fig. 1's
    # one pair: the command is the claims table's, and it runs the full grid
    assert "`make figures/claims.csv`" in lines["7"] and "fig1_oedtw" not in lines["7"]
    assert f"{sum(minutes[n] for n in want):.1f} min: {', '.join(want)} |" in lines["7"]
    assert "full grid" in want and "nb 12" in want
    steps = readme.steps_block(record)
    assert readme.steps_record(f"{readme.BEGIN.format(name='steps')}\n{steps}\n"
                               f"{readme.END.format(name='steps')}") == record  # fmt: skip
    n = len(record["steps"])  # step k: k minutes, k x 100 MiB; nb 12 is the last
    assert record["steps"][-1]["name"] == "nb 12"
    total, peak = n * (n + 1) / 2, readme.memory(100 * n)
    assert f"All steps: {total:.1f} min; the largest peak, {peak}, is that of nb 12." in steps
    assert "`results` 2.0 GiB" in steps
    empty = readme.artifact_claims_block(rows, [], {}, REPO_ROOT / "figures", REPO_ROOT)
    assert empty.count(readme.NOT_MEASURED) == len(rows)


def _notebooks_deciding() -> dict[str, set[str]]:
    """Claim id -> the notebooks whose code computes its row (claim_rows, open_claim_rows),
    notebook 12 (every claim) aside."""
    import json

    out = {}
    for f in sorted((REPO_ROOT / "notebooks").glob("*.ipynb")):
        cells = json.loads(f.read_text(encoding="utf-8"))["cells"]
        code = "\n".join("".join(c["source"]) for c in cells if c["cell_type"] == "code")
        for m in re.finditer(r"claim_rows\(\s*(\[[^\]]*\])", code):
            for cid in re.findall(r"\"([^\"]+)\"", m.group(1)):
                out.setdefault(cid, set()).add(f.stem)
    return out


def test_each_command_regenerates_its_claims_number():
    """Each row's command runs a notebook that computes that claim's row: notebook 12 (the
    claims table, over the full grid) for a claim decided on the experiment pairs, else a
    notebook that prints the claim after its figure (never a figure alone, such as Fig. 1's one
    pair for claim 7, whose number counts every pair)."""
    from fpdtw.app.figure_map import NOTEBOOKS

    deciding = _notebooks_deciding()
    made_by = {m: nb.stem for nb in NOTEBOOKS for m in nb.makes}
    by_id = {c.id: c for c in claims.CLAIMS}
    for cid, row in artifact_rows().items():
        targets = re.findall(r"figures/([\w]+)\.\w+", row["command"])
        assert targets, (cid, row["command"])
        notebooks = {made_by[t] for t in targets}
        if cid in by_id and by_id[cid].pairs:
            assert notebooks == {"12_claims"}, (cid, row["command"])
        else:
            assert notebooks & (deciding.get(cid, set()) | {"12_claims"}), (cid, notebooks)


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
