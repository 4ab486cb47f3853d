"""The book (fpdtw.app.book): pages from the figure map, claims linked to their notebooks,
the front page, a real Sphinx build of a hand-made executed notebook (nothing re-executed,
math as MathML, nothing fetched), and the notebook runner that prints start and end
(fpdtw.app.execute)."""

from __future__ import annotations

import base64
import csv
import io
import json
import re

import matplotlib
import pytest

matplotlib.use("Agg")

from fpdtw.app import book, figure_map  # noqa: E402
from fpdtw.app.execute import execute, part_path  # noqa: E402
from fpdtw.paper import claims  # noqa: E402


def _png() -> bytes:
    import matplotlib.pyplot as plt

    buf = io.BytesIO()
    plt.imsave(buf, [[0.0, 1.0], [1.0, 0.0]], format="png")
    return buf.getvalue()


def _notebook(path, title="01 · Data and motions", outputs=None, code="print(1)"):
    """A hand-made executed notebook: a heading with math, one code cell with stored outputs."""
    nb = {
        "nbformat": 4,
        "nbformat_minor": 5,
        "metadata": {"kernelspec": {"name": "python3", "display_name": "Python 3",
                                    "language": "python"}},  # fmt: skip
        "cells": [
            {"cell_type": "markdown", "id": "a", "metadata": {},
             "source": f"# {title}\n\nThe window $w_i + 1$ rows, and $$x^2 + y_n$$\n"},
            {"cell_type": "code", "id": "b", "metadata": {}, "execution_count": 1,
             "source": code, "outputs": outputs or []},
        ],
    }  # fmt: skip
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(nb))
    return path


def _claim_rows():
    return [
        {"id": "1", "claim": "Mc w40 | passes", "paper": "Mc w40", "ours": "Mc w20, Mc w40",
         "holds": "partly", "ours_literal": "none", "holds_literal": "no",
         "reason": "no other passes one: contradicted (Mc w20 deviation 13.5 [12.1, 14.9] < 18)",
         "interval": "1(a): +0.048 [+0.031, +0.066] vs 0", "holds_authors_fbx": "yes",
         "holds_hdm05": "partly", "holds_paper_shaped": "inconclusive",
         "holds_same_movements": "partly", "robustness": "stands under 9 of 12 readings",
         "evidence": "Figs. 5, 6; fig5_similarity_summary", "stable": True},
        {"id": "7", "claim": "OE-DTW jumps back", "paper": "yes", "ours": "88%",
         "holds": "yes", "ours_literal": "88%", "holds_literal": "yes",
         "evidence": "Fig. 1 (02_fig1_oedtw); OE-DTW maps", "stable": True},
        {"id": "B1", "claim": "beyond", "paper": "-", "ours": "not computed (x)",
         "holds": "n/a", "ours_literal": "", "holds_literal": "n/a",
         "evidence": "nothing we know", "stable": True},
    ]  # fmt: skip


# -- claims -> notebooks ------------------------------------------------------------------


@pytest.mark.parametrize(
    "evidence, stems",
    [
        ("Fig. 1 (02_fig1_oedtw); OE-DTW maps", ("02_fig1_oedtw",)),
        ("Figs. 5, 6; fig5_similarity_summary, fig6_deviation_summary", ("06_fig5_fig6_scores",)),
        ("Figs. 5, 6 (with/without Type V); fig5/fig6 summaries", ("06_fig5_fig6_scores",)),
        ("Table 1; table1_method_c_60_120hz", ("07_table1_60hz",)),
        ("pairs.json; 05_run_experiments", ("05_run_experiments",)),
        ("Fig. 8 (10_fig8_walk_pair); 10_fig8_walk_pair.json", ("10_fig8_walk_pair",)),
        ("poster Fig. 5 (14_opw_fig5_fig6); 14_opw_fig5_fig6.json", ("14_opw_fig5_fig6",)),
        ("table2_time_per_frame (exhausted_fraction)", ("09_table2_timing",)),
        ("fig1_oedtw_endpoints, fig10_typev_heatmaps", ("02_fig1_oedtw", "08_fig7_fig10_heatmaps")),
        ("nothing we know", ()),
    ],
)
def test_claim_evidence_names_its_notebooks(evidence, stems):
    assert book.claim_notebooks(evidence) == stems


def test_every_claim_links_to_a_notebook_of_the_map():
    known = set(figure_map.by_stem())
    for c in claims.CLAIMS:
        stems = book.claim_notebooks(c.evidence)
        assert stems, f"claim {c.id}: no notebook in its evidence {c.evidence!r}"
        assert set(stems) <= known


# -- pages and the front page ---------------------------------------------------------------


def test_pages_follow_the_figure_map_in_number_order(tmp_path):
    _notebook(tmp_path / "02_fig1_oedtw.ipynb", title="02 · Figure 1: jumps")
    pages = book.book_pages(tmp_path)
    assert [p.stem for p in pages] == sorted(nb.stem for nb in figure_map.NOTEBOOKS)
    by = {p.stem: p for p in pages}
    assert by["02_fig1_oedtw"].executed and by["02_fig1_oedtw"].title == "02 · Figure 1: jumps"
    assert not by["05_run_experiments"].executed
    assert by["05_run_experiments"].title == figure_map.by_stem()["05_run_experiments"].paper
    assert by["06_fig5_fig6_scores"].makes == figure_map.by_stem()["06_fig5_fig6_scores"].makes


def _write_csv(path, rows):
    with path.open("w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)


def test_claims_section_shows_the_opw_plugin_reading(tmp_path):
    rows = _claim_rows() + [
        {"id": "P1", "claim": "OPW 69-79 ms", "paper": "69-79 ms", "ours": "22-36 ms",
         "holds": "partly", "ours_plugin": "60-64 ms", "holds_plugin": "no",
         "evidence": "poster Fig. 4 (13_opw_fig4)", "stable": True},
    ]  # fmt: skip
    text = book.claims_section(rows, book.book_pages(tmp_path))
    assert "| OPW plugin | notebook |" in text
    rows = {ln.split("|")[1].strip(): ln.split("|") for ln in text.splitlines()
            if ln.startswith("| ") and "holds-" in ln}  # fmt: skip
    assert rows["P1"][-3].strip() == '60-64 ms<br><span class="holds holds-no">no</span>'
    assert rows["7"][-3].strip() == ""  # n/a: an empty cell
    assert len(rows["P1"]) == len(rows["7"])


def test_front_page_holds_every_claim_the_data_and_how_to_rerun(tmp_path):
    nbs, figs = tmp_path / "nbs", tmp_path / "figs"
    figs.mkdir()
    _notebook(nbs / "06_fig5_fig6_scores.ipynb", title="06 · Scores")
    _write_csv(figs / "data_summary.csv", [
        {"dataset": "authors_fbx", "movement": "Walk", "listed": 3, "available": 0, "missing": 3},
        {"dataset": "authors_fbx", "movement": "Squat", "listed": 3, "available": 3, "missing": 0},
        {"dataset": "hdm05", "movement": "squat", "listed": 9, "available": 9, "missing": 0},
    ])  # fmt: skip
    _write_csv(figs / "experiment_pairs.csv", [
        {"dataset": "authors_fbx", "movement": "Squat", "motions": 3, "pairs": 6},
        {"dataset": "hdm05", "movement": "squat", "motions": 9, "pairs": 72},
    ])  # fmt: skip
    pages = book.book_pages(nbs)
    text = book.front_page(_claim_rows(), pages, figs, mode="full", built_from="tests")
    rows = [ln for ln in text.splitlines() if ln.startswith("| ") and "holds-" in ln]
    assert [r.split("|")[1].strip() for r in rows] == ["1", "7", "B1"]
    assert "Mc w40 \\| passes" in text  # a pipe inside a cell does not split it
    assert "[06](notebooks/06_fig5_fig6_scores.ipynb)" in rows[0]
    assert "02 (not run)" in rows[1]  # notebook 02 was not executed: no dead link
    assert "nothing we know" in rows[2]  # no notebook named: the evidence in words
    assert '<span class="holds holds-partly">partly</span>' in rows[0]
    assert '<span class="holds holds-na">n/a</span>' in rows[2]
    # verdict, reason with its interval, per dataset (coloured), robustness
    assert "contradicted (Mc w20 deviation 13.5 [12.1, 14.9] < 18)" in rows[0]
    assert "95 %: 1(a): +0.048 [+0.031, +0.066] vs 0" in rows[0]
    assert 'paper-shaped: <span class="holds holds-inconclusive">inconclusive</span>' in rows[0]
    assert "stands under 9 of 12 readings" in rows[0]
    assert "How a verdict is decided" in text
    assert "{.claims}" in text
    # the data: here / listed, what is missing, what the experiments ran on
    assert "| `authors_fbx` | 1 / 2 | 3 / 6 | Walk (3) |  |" in text
    assert "| `hdm05` | 1 / 1 | 9 / 9 | nothing | Not obtainable here: the walking" in text
    assert "12 motions of 2 movements, 78 ordered pairs" in text
    for command in ("make figures", "make book", "make test"):
        assert command in text
    assert "notebooks/06_fig5_fig6_scores\n" in text  # in the toctree
    assert "notebooks/05_run_experiments\n" not in text  # not executed: no page
    assert "smoke" not in text.split("## The claims")[0]
    assert "(history.md)" not in text and "\nhistory\n" not in text  # no page: no link
    smoke = book.front_page(None, pages, tmp_path / "none", mode="smoke")
    assert "smoke-banner" in smoke and "No claims table yet" in smoke
    assert "No data summary yet" in smoke


def test_front_page_links_how_this_analysis_was_made(tmp_path):
    pages = book.book_pages(tmp_path)
    docs = book.doc_pages()
    text = book.front_page(_claim_rows(), pages, tmp_path, mode="full", docs=docs)
    intro, claims_part = text.split("## The claims, checked")[:2]
    assert book.HISTORY_LINK == "[How this analysis was made](history.md)"
    assert book.HISTORY_LINK in intro  # above the claims
    assert book.HISTORY_LINK in claims_part.split("{.claims}")[0]  # where the rules are named
    assert "never tuned" not in text and "fixed before" not in text
    toc = "```{toctree}\n:hidden:\n:caption: About\n\n" + "\n".join(d.stem for d in docs)
    assert toc + "\n```" in text and "history" in [d.stem for d in docs]
    for d in docs:  # every page of docs/ listed on the front page, by its title
        assert f"- [{d.title}]({d.stem}.md)" in text


def test_the_source_holds_every_page_of_docs(tmp_path):
    nbs, figs = tmp_path / "nbs", tmp_path / "figs"
    figs.mkdir()
    _notebook(nbs / "02_fig1_oedtw.ipynb", title="02 · Figure 1")
    src = tmp_path / "src"
    book.write_source(src, nbs, figs, tmp_path / "none.json")  # the repository's pages
    assert book.HISTORY == book.REPO_ROOT / "docs" / "history.md"
    pages = sorted((book.REPO_ROOT / "docs").glob("*.md"))
    assert {p.name for p in pages} >= {"history.md", "eq2_reading.md"}
    for p in pages:
        assert (src / p.name).read_bytes() == p.read_bytes(), p.name
    index = (src / "index.md").read_text(encoding="utf-8")
    assert book.HISTORY_LINK in index
    assert "- [Which rotation turns eq. 2's unit vector?](eq2_reading.md)" in index
    book.write_source(src, nbs, figs, tmp_path / "none.json", docs=None)
    assert not (src / "history.md").exists()  # left from the earlier build: removed
    assert not (src / "claims.md").exists()
    assert "(history.md)" not in (src / "index.md").read_text(encoding="utf-8")


def test_doc_pages_in_order_with_their_titles(tmp_path):
    (tmp_path / "zeta.md").write_text("# Zeta\n")
    (tmp_path / "history.md").write_text("# How this analysis was made\n\ntext\n")
    (tmp_path / "claims.md").write_text("# The claims, checked\n")
    got = [(d.stem, d.title) for d in book.doc_pages(tmp_path)]
    assert got == [("claims", "The claims, checked"), ("history", "How this analysis was made"),
                   ("zeta", "Zeta")]  # fmt: skip
    assert book.doc_pages(None) == [] and book.doc_pages(tmp_path / "none") == []
    (tmp_path / "index.md").write_text("# Index\n")
    with pytest.raises(ValueError, match="book's own pages"):
        book.doc_pages(tmp_path)
    (tmp_path / "index.md").unlink()
    (tmp_path / "bad.md").write_text("no heading\n")
    with pytest.raises(ValueError, match="starts with its"):
        book.doc_pages(tmp_path)


def test_docs_link_only_each_other_or_the_web():
    """A page of docs/ is also a page of the book: its links name another page of docs/ (by
    file name) or a web address, so that they resolve in both places."""
    pages = {p.name for p in (book.REPO_ROOT / "docs").glob("*.md")}
    bad = []
    for p in sorted((book.REPO_ROOT / "docs").glob("*.md")):
        text = re.sub(r"^```.*?^```", "", p.read_text(encoding="utf-8"), flags=re.S | re.M)
        text = re.sub(r"`[^`]*`", "", text)
        for target in re.findall(r"\]\(([^)\s]+)\)", text):
            if not (target.startswith(("http://", "https://")) or target.split("#")[0] in pages):
                bad.append(f"{p.name}: {target}")
    assert not bad, bad


def test_what_the_manifests_say_is_not_obtainable():
    class M:
        def __init__(self, name, notes):
            self.name, self.notes = name, notes

    said = book.unlisted_missing([
        M("a", "All takes. The 15 takes of X are not (available_here = false)."),
        M("b", "Every clip. Not obtainable here: the walking\n  classes. Upstream: a zip."),
        M("c", "Take 1. The poster's other clips (19_01, 18_02) are not obtainable here."),
    ])  # fmt: skip
    assert said == {
        "b": "Not obtainable here: the walking classes.",
        "c": "The poster's other clips (19_01, 18_02) are not obtainable here.",
    }
    real = book.unlisted_missing()  # the manifests of data_manifest/
    assert "sitting" in real["hdm05"] and "22_17" in real["cmu"]


def test_figures_page_shows_images_tables_and_downloads(tmp_path):
    figs = tmp_path / "figs"
    figs.mkdir()
    (figs / "fig1_oedtw_endpoints.png").write_bytes(_png())
    (figs / "fig1_oedtw_endpoints.pdf").write_bytes(b"%PDF-1.4\n")
    (figs / "experiment_pairs.md").write_text("| a |\n|---|\n| 1 |\n")
    (figs / "readings_table.md").write_text("| a |\n|---|\n" + "| 1 |\n" * 60)
    pages = book.book_pages(tmp_path)
    text = book.figures_page(pages, figs)
    assert "```{image} figures/fig1_oedtw_endpoints.png" in text
    assert "{download}`pdf <figures/fig1_oedtw_endpoints.pdf>`" in text
    assert "```{include} figures/experiment_pairs.md" in text
    assert "{include} figures/readings_table.md" not in text  # too long: download only
    assert "{download}`md <figures/readings_table.md>`" in text
    assert "## 03" not in text  # no files of notebook 03: no section


# -- a real build -----------------------------------------------------------------------------


@pytest.mark.filterwarnings("ignore")  # the theme's and MyST's deprecation notices of Sphinx 9
def test_build_shows_stored_outputs_without_running_or_fetching_anything(tmp_path):
    nbs, figs, out = tmp_path / "nbs", tmp_path / "figs", tmp_path / "site"
    figs.mkdir()
    png = base64.b64encode(_png()).decode()
    outputs = [
        {"output_type": "stream", "name": "stdout", "text": "stored output 42\n"},
        {"output_type": "display_data", "metadata": {}, "data": {"image/png": png,
                                                                  "text/plain": "<Figure>"}},
    ]  # fmt: skip
    _notebook(nbs / "01_data_and_motions.ipynb", outputs=outputs,
              code='raise SystemExit("executed again")')  # fmt: skip
    _notebook(nbs / "02_fig1_oedtw.ipynb", title="02 · Figure 1")
    (figs / "fig1_oedtw_endpoints.png").write_bytes(_png())
    claims_json = tmp_path / "claims.json"
    claims_json.write_text(json.dumps({"mode": "smoke", "claims": _claim_rows()}))
    (out / "screenshots").mkdir(parents=True)
    (out / "screenshots" / "front.png").write_bytes(b"kept")
    (out / "stale.html").write_text("from an older build")

    info = book.build(out, nbs, figs, claims_json, mode="smoke")
    assert info["index"] == out / "index.html" and info["index"].is_file()
    assert info["notebooks"] == 2
    # index, figures, the pages of docs/, two notebooks, genindex, search
    assert info["pages"] == 6 + len(book.doc_pages())
    src = out.with_name(out.name + "-src")
    assert (src / "history.md").read_bytes() == book.HISTORY.read_bytes()
    history = (out / "history.html").read_text()
    assert "How this analysis was made" in history and "f88f748" in history
    assert (out / "screenshots" / "front.png").read_bytes() == b"kept"
    assert not (out / "stale.html").exists()

    page = (out / "notebooks" / "01_data_and_motions.html").read_text()
    assert "stored output 42" in page  # the stored output, not a new run
    assert re.search(r'<img[^>]+src="[^"]+\.png"', page)
    assert "<math" in page and "<msub>" in page  # math as MathML, drawn by the browser
    index = (out / "index.html").read_text()
    assert 'class="claims' in index and "holds-partly" in index
    assert 'href="notebooks/02_fig1_oedtw.html"' in index
    assert 'href="history.html"' in index  # linked from the front page
    assert "smoke-banner" in index
    assert (out / "figures.html").is_file()
    # nothing is loaded from another host: every src and stylesheet is inside the site
    for f in out.rglob("*.html"):
        text = f.read_text()
        assert not re.search(r'<script[^>]+src="(https?:)?//', text), f
        assert not re.search(r'<link[^>]+href="(https?:)?//', text), f
        assert not re.search(r'<img[^>]+src="(https?:)?//', text), f
        assert not re.search(r"<script[^>]*mathjax", text, re.I), f
        assert "MathJax" not in text, f


# -- the notebook runner --------------------------------------------------------------------


def test_part_path():
    assert str(part_path("build/notebooks/05_x.ipynb")) == "build/notebooks/05_x.part.ipynb"


def _code_nb(path, cells):
    nb = {
        "nbformat": 4,
        "nbformat_minor": 5,
        "metadata": {"kernelspec": {"name": "fpdtw", "display_name": "fpdtw",
                                    "language": "python"}},  # fmt: skip
        "cells": [
            {"cell_type": "code", "id": f"c{i}", "metadata": {"tags": tags},
             "execution_count": None, "source": src, "outputs": []}
            for i, (src, tags) in enumerate(cells)
        ],
    }  # fmt: skip
    path.write_text(json.dumps(nb))
    return path


def test_execute_says_start_and_end_and_keeps_only_finished_notebooks(tmp_path, capsys):
    pytest.importorskip("papermill")
    src = _code_nb(tmp_path / "07_ok.ipynb", [("SMOKE = False", ["parameters"]),
                                              ("print('smoke', SMOKE)", [])])  # fmt: skip
    out = tmp_path / "out" / "07_ok.ipynb"
    seconds = execute(src, out, smoke=True, cwd=tmp_path, progress=False)
    said = capsys.readouterr().out
    assert re.search(r"^\[\d\d:\d\d:\d\d\] start 07_ok \(smoke\)$", said, re.M), said
    assert re.search(r"^\[\d\d:\d\d:\d\d\] done 07_ok in \d+\.\d s$", said, re.M), said
    assert seconds > 0 and out.is_file() and not part_path(out).exists()
    cells = json.loads(out.read_text())["cells"]
    printed = ["".join(o.get("text", "")) for c in cells for o in c["outputs"]]
    assert "smoke True\n" in printed

    bad = _code_nb(tmp_path / "08_bad.ipynb", [("raise ValueError('no')", [])])
    out = tmp_path / "out" / "08_bad.ipynb"
    with pytest.raises(Exception, match="ValueError"):
        execute(bad, out, cwd=tmp_path, progress=False)
    said = capsys.readouterr().out
    assert re.search(r"FAILED 08_bad after \d+\.\d s", said), said
    assert not out.exists() and part_path(out).is_file()
