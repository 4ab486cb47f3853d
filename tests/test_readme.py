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
