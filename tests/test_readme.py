"""The README's examples run and print what they promise; its measured numbers still hold."""

from __future__ import annotations

import contextlib
import io
import re

from fpdtw.paper.paths import REPO_ROOT


def _snippet(section: str) -> str:
    text = (REPO_ROOT / "README.md").read_text()
    body = text.split(section, 1)[1]
    return re.search(r"```python\n(.*?)```", body, re.S).group(1)


def test_readme_load_example(mirror_root):
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        exec(compile(_snippet("## Load a motion"), "README.md", "exec"), {})
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
    """Every `fpdtw experiments run` line of the cluster section is a valid command."""
    import shlex

    from fpdtw.app.cli import build_parser

    section = (REPO_ROOT / "README.md").read_text().split("## Running the grid on a cluster")[1]
    section = section.split("\n## ", 1)[0]
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


def test_readme_result_blocks_are_what_the_committed_figures_give():
    """The README's generated blocks (fpdtw.paper.readme) match figures/: no stale numbers."""
    import csv

    import pytest

    from fpdtw.paper import readme

    with open(REPO_ROOT / "figures" / "claims.csv", newline="", encoding="utf-8") as f:
        if not readme.claims_regenerated(list(csv.DictReader(f))):
            pytest.fail(
                "figures/claims.csv predates the claims package (it lacks columns of "
                "fpdtw.paper.claims.COLUMNS): run make figures, which writes it and the README's "
                "block (ARTIFACT.md's time and memory then need tools/measure_steps.py)"
            )
    text = (REPO_ROOT / "README.md").read_text()
    assert readme.render(text, readme.blocks(REPO_ROOT / "figures")) == text, (
        "README.md's generated blocks differ from figures/: run "
        "`python -m fpdtw.paper.readme README.md --update` (make figures does)"
    )


def test_readme_findings_are_what_the_committed_figures_give():
    """The numbers of "What we find" are generated from figures/ (and none is typed around
    them: the paragraph before the block holds no decimal or percentage)."""
    from fpdtw.paper import readme

    text = (REPO_ROOT / "README.md").read_text()
    new = readme.render(text, {"findings": readme.findings_block(REPO_ROOT / "figures")})
    assert new == text, "README.md's findings differ from figures/: run make readme-results"
    prose = text.split("**What we find**")[1].split(readme.BEGIN.format(name="findings"))[0]
    prose = re.sub(r"`[^`]*`", "", prose)
    assert not re.findall(r"\d+\.\d+|\d+ ?%", prose)


def test_findings_name_their_files_and_the_papers_numbers(tmp_path):
    """A hand-made figures folder: each bullet carries its file's number."""
    import shutil

    from fpdtw.paper import readme

    for name in ("experiment_pairs", "fig5_similarity_summary", "fig6_deviation_summary",
                 "fig7_path_balance", "table1_method_c_60_120hz", "table2_time_per_frame",
                 "claims", "opw_fig4_summary"):  # fmt: skip
        shutil.copy(REPO_ROOT / "figures" / f"{name}.csv", tmp_path)
    summary = tmp_path / "fig5_similarity_summary.csv"
    summary.write_text(summary.read_text().replace("Mc w40,False,0.478467", "Mc w40,False,0.5"))
    block = readme.findings_block(tmp_path)
    assert "median similarity 0.500, median deviation" in block
    assert "(the paper: 3248)" in block and "(the paper: 0.24)" in block
    assert block.count("\n- ") == 8


def test_readme_live_drop_block_is_what_the_committed_figures_give(tmp_path):
    """The lost-frames table and its sentence come from figures/live_drop_rate.csv; a
    hand-made file gives hand-checked numbers."""
    from fpdtw.paper import readme

    text = (REPO_ROOT / "README.md").read_text()
    new = readme.render(text, {"live-drop": readme.live_drop_block(REPO_ROOT / "figures")})
    assert new == text, "README.md's live-drop block differs from figures/: make readme-results"
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
    from fpdtw.paper import readme

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
    import importlib.util

    spec = importlib.util.spec_from_file_location("layer_sizes", REPO_ROOT / "tools/layer_sizes.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_readme_layer_sizes_are_measured():
    """The "Size of each layer" table is what tools/layer_sizes.py counts, within 10 %."""
    L = _layer_sizes()
    section = (REPO_ROOT / "README.md").read_text().split("## Size of each layer")[1]
    rows = [ln for ln in section.split("\n## ", 1)[0].splitlines() if ln.startswith("| ")][1:]
    stated = {}
    for row in rows:
        cells = [c.strip() for c in row.strip("|").split("|")]
        stated[cells[0].split(":")[0]] = [int(c) for c in cells[1:]]
    measured = L.sizes()
    assert list(stated) == list(measured)
    for layer, (files, code, lines) in stated.items():
        m = measured[layer]
        for what, have, now in (("files", files, m["files"]), ("code", code, m["code"]),
                                ("lines", lines, m["lines"])):  # fmt: skip
            assert abs(now - have) <= 0.1 * have, (
                f"README: {layer} has {have} {what}, now {now}: run tools/layer_sizes.py and "
                "update the table"
            )


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
