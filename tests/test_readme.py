"""The README's and docs' examples run and print what they promise; every generated block of
README.md, ARTIFACT.md and docs/*.md is what figures/ gives, each in one place."""

from __future__ import annotations

import contextlib
import csv
import io
import re

from fpdtw.paper.paths import REPO_ROOT


def _snippet(section: str, page: str = "README.md") -> str:
    text = (REPO_ROOT / page).read_text()
    body = text.split(section, 1)[1]
    return re.search(r"```python\n(.*?)```", body, re.S).group(1)


def test_readme_load_example(mirror_root):
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        exec(compile(_snippet("## Load a motion", "docs/data.md"), "docs/data.md", "exec"), {})
    lines = out.getvalue().splitlines()
    assert len(lines) == 3
    assert lines[0].startswith("Walk_01: 649 frames at 120 Hz; 8 paper joints: ['LeftUpLeg'")
    assert lines[1].startswith("HDM_bd_squat1Reps_001_120: 140 frames at 120 Hz")
    assert lines[2].startswith("18_01: 303 frames at 30 Hz; 8 paper joints: ['lfemur', 'rfemur'")
    for line in lines:
        assert line.count("'") == 16  # 8 joint names


def test_readme_streaming_example(mirror_root):
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        exec(compile(_snippet("### Stream frames from Python"), "README.md", "exec"), {})
    line = out.getvalue().strip()
    # Walk_02 has 637 frames, Walk_01 649; the streamed map ends near the end of the input
    assert line.startswith("Ma + Type V: live frame 636 -> recorded frame ")
    m = int(line.split("recorded frame ")[1].split(" of ")[0])
    assert line.endswith("of 648") and 600 <= m <= 648


def test_readme_cluster_commands_parse():
    """Every `fpdtw experiments run` line of the cluster page is a valid command."""
    import shlex

    from fpdtw.app.cli import build_parser

    section = (REPO_ROOT / "docs" / "cluster.md").read_text()
    lines = [ln.split("#")[0] for ln in section.splitlines() if "fpdtw experiments run" in ln]
    lines = [ln for ln in lines if not ln.lstrip().startswith(("from", "run_experiments"))]
    assert len(lines) == 4
    parser = build_parser()
    for line in lines:
        argv = shlex.split(line.split("fpdtw", 1)[1])
        args = parser.parse_args(argv)
        assert args.command == "experiments"
    for placeholder in ("SCALING_TABLE", "FULL_ROWS"):
        assert placeholder not in section, "the scaling numbers are not filled in"


#: Every file with generated blocks: README.md, ARTIFACT.md and the pages of docs/.
def _files():
    return [REPO_ROOT / "README.md", REPO_ROOT / "ARTIFACT.md",
            *sorted((REPO_ROOT / "docs").glob("*.md"))]  # fmt: skip


def test_every_generated_block_is_what_the_committed_figures_give():
    """The generated blocks (fpdtw.app.readme) of README.md, ARTIFACT.md and docs/*.md
    match figures/: no stale numbers (the command the Makefile's readme-results runs)."""
    from fpdtw.app import readme

    stale = []
    for f in _files():
        text = f.read_text(encoding="utf-8")
        new = readme.blocks_for(f, text, REPO_ROOT / "figures")
        new = {n: b for n, b in new.items() if n not in readme.CHECKOUT_BLOCKS}
        if readme.render(text, new) != text:
            stale.append(f.relative_to(REPO_ROOT).as_posix())
    assert not stale, (
        f"generated blocks differ from figures/ in {stale}: run `python -m fpdtw.app.readme "
        "README.md ARTIFACT.md docs/*.md --update` (make readme-results; make figures does)"
    )
    files = " ".join(f.relative_to(REPO_ROOT).as_posix() for f in _files())
    assert readme.main([*files.split(), "--check"]) == 0


def test_the_claims_table_is_the_claims_packages():
    """figures/claims.csv has every column of the claims package (fails until make figures
    rewrites a table from before the claims were split into parts)."""
    import csv

    import pytest

    from fpdtw.app import readme

    with open(REPO_ROOT / "figures" / "claims.csv", newline="", encoding="utf-8") as f:
        if not readme.claims_regenerated(list(csv.DictReader(f))):
            pytest.fail(
                "figures/claims.csv predates the claims package (it lacks columns of "
                "fpdtw.paper.claims.COLUMNS): run make figures, which writes it and the generated "
                "blocks (ARTIFACT.md's time and memory then need tools/measure_steps.py)"
            )


def test_each_block_is_in_exactly_one_file():
    """Every block of fpdtw.app.readme.BLOCKS sits in exactly one of README.md and
    docs/*.md, and ARTIFACT.md holds its own blocks once each; only the outcome is in two
    places, the README and ARTIFACT.md."""
    from fpdtw.app import readme

    where = {}
    for f in _files():
        for name in readme.block_names(f.read_text(encoding="utf-8")):
            key = ("ARTIFACT" if f.name == "ARTIFACT.md" else "pages", name)
            where.setdefault(key, []).append(f.relative_to(REPO_ROOT).as_posix())
    for name in readme.BLOCKS:
        assert len(where.get(("pages", name), [])) == 1, (name, where.get(("pages", name)))
    for name in readme.ARTIFACT_BLOCKS:
        assert where.get(("ARTIFACT", name)) == ["ARTIFACT.md"], name
    assert where[("pages", "outcome")] == ["README.md"]


def _block(text: str, name: str) -> str:
    from fpdtw.app import readme

    return text.split(readme.BEGIN.format(name=name), 1)[1].split(readme.END.format(name=name))[0]


def test_the_outcome_follows_the_two_commands_and_opens_the_abstract():
    """The same outcome block right after the README's two commands (the first screen) and at
    the top of ARTIFACT.md's abstract."""
    readme_text = (REPO_ROOT / "README.md").read_text(encoding="utf-8")
    artifact = (REPO_ROOT / "ARTIFACT.md").read_text(encoding="utf-8")
    assert _block(readme_text, "outcome") == _block(artifact, "outcome")
    after = readme_text.split("## Two commands", 1)[1]
    assert "make figures" in after.split("\n## ", 1)[0] and "make test" in after
    nxt = after.split("\n## ", 1)[1]
    assert nxt.startswith("The outcome\n")
    assert readme_text.index("generated by make figures: outcome") < len(
        "\n".join(readme_text.splitlines()[:60])
    ), "the outcome starts within the first 60 lines"
    abstract = artifact.split("\n## Abstract\n", 1)[1].lstrip("\n")
    assert abstract.startswith("<!-- generated by make figures: outcome -->")


def test_the_readme_is_short():
    lines = (REPO_ROOT / "README.md").read_text(encoding="utf-8").splitlines()
    assert len(lines) <= 220, f"README.md has {len(lines)} lines: move a section into docs/"


def _rows(n_fp=13, questions=True, **extra):
    """Made-up claims rows in the claims package's columns."""
    verdicts = ["yes", "partly", "inconclusive", "no", "not comparable"]
    ids = ["1", "2", "2b", "3", "4", "4b", "4c", "5", "5b", "6", "7", "8", "9", "8b"][:n_fp]
    rows = []
    for k, cid in enumerate([*ids, "P1", "P2", "P3", "P4", "B1"]):
        rows.append(dict(
            id=cid, claim=f"claim {cid} " + "word " * 20, short=f"short {cid} | piped",
            paper=f"paper {cid}", ours=f"ours {cid}",
            holds=verdicts[k % 5] if cid != "B1" else "n/a",
            holds_same_movements="yes" if cid in ("3", "5b") else verdicts[k % 5],
            holds_authors_fbx="yes", holds_hdm05="no", holds_paper_shaped="n/a",
            eq2_other="local", holds_eq2_other="no", **extra,
        ))  # fmt: skip
    if questions:
        rows += [dict(id=f"Q{i}", claim="q", short="q", paper="-", ours="-", holds="no",
                      holds_same_movements="n/a") for i in range(1, 7)]  # fmt: skip
    return rows


def test_outcome_block_from_made_up_rows():
    from fpdtw.app import readme

    rows = _rows()
    block = readme.outcome_block(rows)
    lines = block.splitlines()
    assert len(lines) <= readme.OUTCOME_MAX_LINES
    table = [ln for ln in lines if ln.startswith("| ") and not ln.startswith("| id ")]
    paper = [r for r in rows if readme.is_paper_claim(r)]
    assert [ln.split(" | ")[0][2:] for ln in table] == [r["id"] for r in paper]
    assert "| 2b | short 2b \\| piped | paper 2b | ours 2b |" in block
    assert "| yes / no / n/a |" in block and "B1" not in block.split("- FP-DTW")[0]
    # the counts add up, per paper
    for label, part in (("FP-DTW paper", [r for r in paper if r["id"][0] != "P"]),
                        ("OPW poster", [r for r in paper if r["id"][0] == "P"])):  # fmt: skip
        line = next(ln for ln in lines if ln.startswith(f"- {label} ("))
        assert line.startswith(f"- {label} ({len(part)} claims): yes ")
        counts = [int(n) for n in re.findall(r" (\d+)(?=[,.])", line.split(": ", 1)[1])]
        assert sum(counts) == len(part), line
        for v in readme.OUTCOME_VERDICTS:
            assert f"{v} {sum(r['holds'] == v for r in part)}" in line
    beyond = "- Beyond the papers (`docs/claims.md`): " + ", ".join(f"Q{i} no" for i in range(1, 7))
    assert beyond + "." in lines
    why = lines[-1]
    assert "other movements like these, recorded again?" in why
    assert "other takes of these movements?" in why
    differ = [r["id"] for r in paper if r["holds_same_movements"] != r["holds"]]
    assert "3" in differ and "5b" in differ
    assert "claims 3 and 5b hold (yes) with the movements fixed but not with them resampled" in why
    assert "Eq. 2 is read as each joint's whole local transform (`docs/eq2_reading.md`)" in why
    assert "the other reading, local," in why
    for where in ("figures/claims.md", "figures/claims_checks.csv", "docs/history.md",
                  "python -m fpdtw.paper.claims verify figures/"):  # fmt: skip
        assert where in why
    # a fourteenth FP-DTW claim (8b) still fits: the questions share the last line
    big = readme.outcome_block(_rows(n_fp=14))
    assert len(big.splitlines()) <= readme.OUTCOME_MAX_LINES and "| 8b |" in big
    assert "Q6 no." in big


def test_outcome_block_of_a_table_from_before_the_short_column():
    """A claims.csv without ``short`` and ``eq2_other`` (written before they existed): the
    claim cut to 12 words, and the eq. 2 sentence says the table predates the readings."""
    from fpdtw.app import readme

    rows = [{k: v for k, v in r.items() if k not in ("short", "eq2_other", "holds_eq2_other")}
            for r in _rows(questions=False)]  # fmt: skip
    block = readme.outcome_block(rows)
    assert "| 1 | claim 1 word word word word word word word word word word ... |" in block
    assert "predates the verdicts under both readings of eq. 2" in block
    assert "Beyond the papers" not in block


def test_counts_times_and_data_blocks(tmp_path):
    from fpdtw.app import readme
    from fpdtw.app.publish import TIMING_OUTPUTS

    root, figs = tmp_path / "root", tmp_path / "figs"
    (root / "notebooks").mkdir(parents=True)
    figs.mkdir()
    for n in ("01_a", "02_b", "03_c"):
        (root / "notebooks" / f"{n}.ipynb").write_text("{}")
    for name in ("a.pdf", "b.csv", TIMING_OUTPUTS[0], TIMING_OUTPUTS[1], ".hidden"):
        (figs / name).write_text("x")
    counts = readme.counts_block(root, figs)
    assert "runs the 3 notebooks of `notebooks/` and writes the 4 files of `figures/`" in counts
    assert "Of these, 2 are timing outputs" in counts
    record = {"date": "2026-01-01", "commit": "abc1234", "cpus": 2, "steps": [
        dict(name="data", seconds=6.0), dict(name="full grid", seconds=420.0),
        dict(name="nb 12", seconds=54.0), dict(name="study grid", seconds=120.0)]}  # fmt: skip
    times = readme.times_block(record)
    assert "they feed) took 10.0 min, most of it in the steps *full grid* (7.0 min) and" in times
    assert readme.NOT_MEASURED in readme.times_block({})
    (figs / "data_summary.csv").write_text(
        "dataset,movement,listed,available,missing\nauthors_fbx,Walk,3,3,0\n"
        "authors_fbx,Slow_Walk,3,0,3\nhdm05,squat,5,5,0\nhdm05,kick,4,4,0\ncmu,x,1,1,0\n"
    )
    (figs / "experiment_pairs.csv").write_text(
        "dataset,movement,motions,pairs\nauthors_fbx,Walk,3,6\nhdm05,squat,5,20\nhdm05,kick,4,12\n"
    )
    data = readme.data_block(figs).splitlines()
    assert len(data) == 2
    assert data[0].startswith("The results in `figures/` used 3 of the authors' 6 FBX takes "
                              "(1 of their 2 movements; not available here: Slow_Walk), 9 HDM05 "
                              "clips in 2 classes and 1 CMU BVH take: 38 ordered pairs of 12 "
                              "motions of 3 movements")  # fmt: skip
    assert data[1].startswith("The FP-DTW paper used 333 motions of 44 movements, 3248 ordered")
    assert "HDM05's walking, turning, punching, jumping and sitting classes" in data[1]


def test_blocks_for_refuses_an_unknown_block(tmp_path):
    import pytest

    from fpdtw.app import readme

    text = "<!-- generated by make figures: nonsense -->\n<!-- end of generated nonsense -->\n"
    with pytest.raises(ValueError, match="no generated block is named"):
        readme.blocks_for(tmp_path / "docs" / "x.md", text, REPO_ROOT / "figures")
    page = tmp_path / "page.md"
    page.write_text("# A page\n\nNo blocks.\n")
    assert readme.main([str(page), "--check"]) == 0
    page.write_text(f"# A page\n\n{readme.BEGIN.format(name='notebooks')}\nold\n"
                    f"{readme.END.format(name='notebooks')}\n")  # fmt: skip
    assert readme.main([str(page), "--check"]) == 1
    assert readme.main([str(page), "--update"]) == 0
    assert "| `12_claims` |" in page.read_text() and readme.main([str(page), "--check"]) == 0


def test_findings_are_what_the_committed_figures_give():
    """The numbers of "What we find" are generated from figures/ (and none is typed around
    them: the paragraph before the block holds no decimal or percentage)."""
    from fpdtw.app import readme

    text = (REPO_ROOT / "docs" / "findings.md").read_text()
    new = readme.render(text, {"findings": readme.findings_block(REPO_ROOT / "figures")})
    assert new == text, "docs/findings.md's findings differ from figures/: make readme-results"
    prose = text.split("**What we find**")[1].split(readme.BEGIN.format(name="findings"))[0]
    prose = re.sub(r"`[^`]*`", "", prose)
    assert not re.findall(r"\d+\.\d+|\d+ ?%", prose)


def test_findings_name_their_files_and_the_papers_numbers(tmp_path):
    """A hand-made figures folder: each bullet carries its file's number."""
    import shutil

    from fpdtw.app import readme

    for name in ("experiment_pairs", "fig5_similarity_summary", "fig6_deviation_summary",
                 "fig7_path_balance", "table1_method_c_60_120hz", "table2_time_per_frame",
                 "claims", "opw_fig4_summary"):  # fmt: skip
        shutil.copy(REPO_ROOT / "figures" / f"{name}.csv", tmp_path)
    summary = tmp_path / "fig5_similarity_summary.csv"
    rows = list(csv.DictReader(summary.open()))
    for r in rows:  # a hand-made median for Mc w40 (unconstrained)
        if r["algorithm"] == "Mc w40" and r["type_v"] == "False":
            r["median"] = "0.5"
    with summary.open("w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]), lineterminator="\n")
        w.writeheader()
        w.writerows(rows)
    block = readme.findings_block(tmp_path)
    assert "median similarity 0.500, median deviation" in block
    assert "(the paper: 3248)" in block and "(the paper: 0.24)" in block
    assert block.count("\n- ") == 8


def test_live_drop_block_is_what_the_committed_figures_give(tmp_path):
    """The lost-frames table and its sentence come from figures/live_drop_rate.csv; a
    hand-made file gives hand-checked numbers."""
    from fpdtw.app import readme

    text = (REPO_ROOT / "docs" / "live.md").read_text()
    new = readme.render(text, {"live-drop": readme.live_drop_block(REPO_ROOT / "figures")})
    assert new == text, "docs/live.md's live-drop block differs from figures/: make readme-results"
    (tmp_path / "live_drop_rate.csv").write_text(
        "method,condition,gap,runs,lost_per_run,deviation_frames,deviation_max_frames\n"
        "A,drop 0 %,-,6,0,1.0,2\nA,drop 5 %,slerp,18,3,1.1,2\nA,drop 5 %,hold,18,3,2.5,3\n"
        "A,30 Hz target,-,6,0,0.8,2\nB,drop 0 %,-,6,0,2.0,2\nB,drop 5 %,slerp,18,3,1.97,2\n"
        "B,drop 5 %,hold,18,3,2.2,3\nB,30 Hz target,-,6,0,2.05,2\n"
    )
    block = readme.live_drop_block(tmp_path)
    assert "| A | hold | 1.00 | 2.50 | 0.80 |" in block
    assert "| method | gap rule | no loss | 5 % lost | 30 Hz take |" in block
    assert "up to 5 % of the frames at random moves no method by more than 0.10 frames" in block
    assert "costs A and B up to 1.5 and 0.2 frames" in block
    assert "(within 0.20 frames)" in block


def test_readme_blocks_are_replaced_between_their_markers(tmp_path):
    from fpdtw.app import readme

    text = (
        "a\n<!-- generated by make figures: claims -->\nold\n<!-- end of generated claims -->\nb\n"
    )
    new = readme.render(text, {"claims": "new line"})
    assert new == text.replace("old", "new line")
    assert readme.render(new, {"claims": "new line"}) == new
    import pytest

    with pytest.raises(ValueError, match="no markers"):
        readme.render("nothing here", {"claims": "x"})
    rows = [dict(id="1", claim="c | d", holds="partly", reason="1b: contradicted (x)",
                 holds_authors_fbx="yes", holds_hdm05="partly", holds_paper_shaped="n/a",
                 robustness="yes on the selection; stands under 9 of 12 readings")]  # fmt: skip
    block = readme.claims_block(rows)
    assert "| 1 | c \\| d | partly | 1b: contradicted (x) | yes / partly / n/a | 9 of 12 |" in block


def _layer_sizes():
    from fpdtw.app import layers

    return layers


def test_the_layout_names_files_that_exist():
    """Every file and folder the tree of docs/layout.md names exists where it says."""
    text = (REPO_ROOT / "docs" / "layout.md").read_text()
    tree = re.search(r"^```\n(fpdtw/.*?)^```", text, re.S | re.M).group(1)
    parents, missing, named = {}, [], 0
    for line in tree.splitlines():
        m = re.match(r"( *)((?:[\w.]+/?, )*[\w.]+/?)(?:\s{2,}|$)", line)
        indent = len(m.group(1)) if m else 99
        if not m or indent >= 20:
            continue  # a description's continuation
        base = parents.get(indent - 2, REPO_ROOT)
        for name in m.group(2).split(", "):
            named += 1
            path = base / name.rstrip("/")
            if not path.exists():
                missing.append(path.relative_to(REPO_ROOT).as_posix())
            if name.endswith("/"):
                parents[indent] = path
    assert named >= 30 and not missing, (named, missing)


def test_the_layout_names_every_module_and_folder():
    """The other way round: every module and folder of fpdtw/, fpdtw/paper/ and fpdtw/app/
    is an entry of the tree of docs/layout.md (a new module cannot go unlisted)."""
    text = (REPO_ROOT / "docs" / "layout.md").read_text()
    tree = re.search(r"^```\n(fpdtw/.*?)^```", text, re.S | re.M).group(1)
    entries = set()
    for line in tree.splitlines():
        m = re.match(r"( *)((?:[\w.]+/?, )*[\w.]+/?)(?:\s{2,}|$)", line)
        if m and len(m.group(1)) < 20:
            entries.update(n.rstrip("/") for n in m.group(2).split(", "))
    unlisted = []
    for folder in ("fpdtw", "fpdtw/paper", "fpdtw/app"):
        for p in sorted((REPO_ROOT / folder).iterdir()):
            if p.name.startswith(("_", ".")):
                continue
            if (p.suffix == ".py" or p.is_dir()) and p.name not in entries:
                unlisted.append(f"{folder}/{p.name}")
    assert not unlisted, unlisted


def test_layer_sizes_count_code_not_docstrings_or_comments():
    L = _layer_sizes()
    source = '''"""Module docstring,
two lines."""

# a comment
x = 1  # code


def f(a):
    """One line."""
    return (a +
            1)
'''
    assert L.code_lines(source) == 4  # x = 1, def f, return over two lines


def test_layer_sizes_count_imports_inside_functions_only():
    L = _layer_sizes()
    source = """import os


def f():
    import json
    from pathlib import Path

    def g():
        import re
    return json, Path


class C:
    def m(self):
        from fpdtw import plain
"""
    assert L.inner_imports(source) == 4  # json, Path, re (g inside f counts once), plain


def test_layer_table_marks_a_layer_over_its_budget():
    L = _layer_sizes()
    counts = {n: {"files": 1, "code": 10, "lines": 20, "inner_imports": 0} for n in L.LAYERS}
    counts["paper"]["code"] = L.BUDGET["paper"] + 1
    counts["library"]["lines"] = L.BUDGET["library"] + 1
    text = L.table(counts)
    assert f"| {L.BUDGET['library']}: code within, all lines OVER |" in text
    assert f"| {L.BUDGET['paper']}: code OVER, all lines within |" in text


def test_the_library_and_the_reproduction_are_within_their_budgets():
    """The layers' sizes (the table make figures writes into docs/layout.md) within budget."""
    L = _layer_sizes()
    counts = L.sizes()
    over = {n: counts[n]["code"] for n, cap in L.BUDGET.items() if counts[n]["code"] > cap}
    assert not over, f"lines of code over budget {L.BUDGET}: {over}"
