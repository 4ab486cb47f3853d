"""The book: one static HTML site of the executed notebooks, the claims on its front page.

``make book`` (and, last, ``make figures``) turns the notebooks that papermill executed
into ``build/notebooks/`` into a website in ``build/book/`` (open ``build/book/index.html``);
``make test`` builds the same site from the smoke notebooks into ``build/smoke/book/`` and
checks it in headless Chromium (:mod:`fpdtw.app.browser`).

The site is built by Sphinx with MyST-NB (the Jupyter ecosystem's notebook reader for
Sphinx) and the Sphinx Book Theme. Nothing is executed again (``nb_execution_mode =
"off"``): the pages show the outputs papermill stored. Nothing is fetched either: math is
written as MathML by this module (a Sphinx extension, :func:`setup`), which browsers draw
themselves, instead of by MathJax from the web.

What this module writes into the Sphinx source folder (``build/book-src/``), from the one
figure map (:mod:`fpdtw.app.figure_map`), the claims JSON of notebook 12
(:func:`fpdtw.paper.claims.save_claims`) and the tables of notebooks 01 and 05:

``index.md``
    The front page (:func:`front_page`): the claims table (id, claim, paper, ours,
    holds, holds with Method C's literal window and with OPW's plugin reading, each claim
    linked to the notebook pages that show it: :func:`claim_notebooks`), the data used and
    what is missing, how to rerun, and every notebook page with what it reproduces.
``figures.md``
    Every figure (PNG, GIF) by notebook, with its PDF and the tables (CSV, Markdown) as
    downloads (:func:`figures_page`).
``<page>.md``
    A copy of every page of the repository's ``docs/`` folder (:data:`DOCS`,
    :func:`doc_pages`): the pages behind the README (the claims and their reasons, the data,
    the environment, the live server, ...), *How this analysis was made* (``docs/history.md``,
    :data:`HISTORY`: when each analysis default and verdict rule was chosen, and which results
    had been committed by then) and *Which rotation turns eq. 2's unit vector?*
    (``docs/eq2_reading.md``). The front page lists them all and links the history where the
    rules are named. The pages link each other by file name, so their links resolve both in
    the repository and in the book.
``notebooks/<stem>.ipynb``
    The executed notebooks, one page each, in the order of their numbers.
``conf.py``, ``_static/book.css``
    The Sphinx configuration (:func:`sphinx_conf`) and a little CSS.

Run ``python -m fpdtw.app.book --notebooks DIR --figures DIR --claims FILE --out DIR
[--mode full|smoke]`` (the Makefile does; ``--help`` lists the defaults).
"""

from __future__ import annotations

import argparse
import csv
import html
import json
import re
import shutil
import sys
import time
from dataclasses import dataclass
from pathlib import Path

from fpdtw.app import figure_map
from fpdtw.paper.paths import REPO_ROOT

#: Words for the verdicts of the claims table (the ``holds`` column).
HOLDS = ("yes", "partly", "no", "inconclusive", "not comparable", "n/a")
#: Figure files shown as images, and files offered as downloads, by extension.
IMAGE_SUFFIXES = (".png", ".gif")
DOWNLOAD_SUFFIXES = (".pdf", ".csv", ".md")
#: Tables of at most this many Markdown lines are shown on the figures page (all are
#: downloads).
TABLE_MAX_LINES = 40
#: The folder whose Markdown pages are copied into the book, one page each (:func:`doc_pages`).
DOCS = REPO_ROOT / "docs"
#: The page "How this analysis was made" (MyST Markdown), one of them: ``history.md``.
HISTORY = DOCS / "history.md"
#: The front page's link to it.
HISTORY_LINK = "[How this analysis was made](history.md)"

_CSS = """\
/* fpdtw book: the claims table and the verdicts */
table.claims { font-size: 0.85em; }
table.claims td, table.claims th { vertical-align: top; }
.holds { font-weight: 600; padding: 0 0.35em; border-radius: 0.25em; white-space: nowrap; }
.holds-yes { background: #d5f0d5; color: #135c13; }
.holds-partly { background: #fbeccc; color: #7a4b00; }
.holds-no { background: #f7d4d4; color: #8a1414; }
.holds-na { background: #e6e6e6; color: #444; }
.holds-inconclusive { background: #dde6f5; color: #1f3f73; }
.holds-not-comparable { background: #ece0f3; color: #56306b; }
.holds-holds { background: #d5f0d5; color: #135c13; }
.holds-contradicted { background: #f7d4d4; color: #8a1414; }
.claims td { vertical-align: top; }
.claims .reason { font-size: 0.85em; }
.smoke-banner { border-left: 0.3em solid #c77d00; padding: 0.4em 0.8em; background: #fff6e5; }
math[display="block"] { margin: 0.5em 0; }
/* the front page (no right-hand contents column): the claims table may use the width */
.bd-main .bd-content .bd-article-container:has(table.claims) { max-width: none; }
table.claims td:nth-child(2) { min-width: 16em; }
table.claims td:nth-child(4) { min-width: 12em; }
"""
#: The site's icon (a warping path on a grid), so that browsers ask for no /favicon.ico.
_FAVICON = """\
<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 16 16">
<rect width="16" height="16" rx="3" fill="#1f4e79"/>
<path d="M2 14 L5 11 L6 7 L10 5 L14 2" stroke="#ffd34d" stroke-width="2" fill="none"/>
</svg>
"""


# -- pages ---------------------------------------------------------------------------------

#: The order of the pages of ``docs/`` in the book (pages not named here follow, by name).
DOCS_ORDER = ("claims", "findings", "eq2_reading", "history", "notebooks", "book", "data",
              "environment", "align", "live", "performance", "limits", "cluster", "layout",
              "citing", "releasing")  # fmt: skip
#: Names the book's own pages take: a page of ``docs/`` may not have them.
RESERVED = ("index", "figures", "conf", "genindex", "search")


@dataclass(frozen=True)
class DocPage:
    """One page of ``docs/`` in the book.

    Attributes
    ----------
    stem : str
        The file name without ``.md`` (also the page's name in the book).
    title : str
        Its first heading.
    path : Path
        The file.
    """

    stem: str
    title: str
    path: Path


def doc_pages(docs_dir=DOCS) -> list[DocPage]:
    """The Markdown pages of ``docs_dir``, in :data:`DOCS_ORDER` ([] when it is None or
    missing).

    Raises
    ------
    ValueError
        A page has no ``# `` heading on its first line, or takes the name of one of the
        book's own pages (:data:`RESERVED`).
    """
    if docs_dir is None or not Path(docs_dir).is_dir():
        return []
    out = []
    for f in sorted(Path(docs_dir).glob("*.md")):
        first = f.read_text(encoding="utf-8").split("\n", 1)[0]
        if not first.startswith("# "):
            raise ValueError(f"{f}: a page of the book starts with its '# ' heading")
        if f.stem in RESERVED:
            raise ValueError(f"{f}: {f.stem!r} is the name of one of the book's own pages")
        out.append(DocPage(f.stem, first[2:].strip(), f))
    rank = {stem: i for i, stem in enumerate(DOCS_ORDER)}
    return sorted(out, key=lambda d: (rank.get(d.stem, len(rank)), d.stem))


def docs_section(docs) -> str:
    """The front page's list of the pages of ``docs/`` (MyST Markdown), and their toctree."""
    if not docs:
        return ""
    out = ["## About this reproduction", ""]
    out += [f"- [{_cell(d.title)}]({d.stem}.md)" for d in docs]
    out += ["", "```{toctree}", ":hidden:", ":caption: About", ""]
    out += [d.stem for d in docs]
    return "\n".join([*out, "```", ""])


@dataclass(frozen=True)
class Page:
    """One notebook page of the book.

    Attributes
    ----------
    stem : str
        The notebook's file name without ``.ipynb`` (also the page's name).
    title : str
        The notebook's first heading (the figure map's words when it has none).
    paper : str
        What it reproduces (:attr:`fpdtw.app.figure_map.Notebook.paper`).
    makes : tuple of str
        The figures and tables it writes.
    executed : bool
        Whether the executed notebook exists (pages of notebooks not run yet are left out
        of the site and marked on the front page).
    """

    stem: str
    title: str
    paper: str
    makes: tuple
    executed: bool


def notebook_title(path) -> str | None:
    """The text of the first Markdown heading of a notebook, or None.

    Parameters
    ----------
    path : str or Path
        An ``.ipynb`` file.
    """
    cells = json.loads(Path(path).read_text(encoding="utf-8")).get("cells", [])
    for cell in cells:
        if cell.get("cell_type") != "markdown":
            continue
        src = cell["source"] if isinstance(cell["source"], str) else "".join(cell["source"])
        for line in src.splitlines():
            m = re.match(r"#{1,6}\s+(.+?)\s*#*\s*$", line)
            if m:
                return m.group(1)
    return None


def book_pages(notebooks_dir) -> list[Page]:
    """Every notebook of the figure map as a :class:`Page`, in the order of their numbers.

    Parameters
    ----------
    notebooks_dir : str or Path
        Folder of the executed notebooks (``build/notebooks`` or ``build/smoke``).
    """
    out = []
    for nb in sorted(figure_map.NOTEBOOKS, key=lambda n: n.stem):
        path = Path(notebooks_dir) / f"{nb.stem}.ipynb"
        title = notebook_title(path) if path.is_file() else None
        out.append(Page(nb.stem, title or nb.paper, nb.paper, tuple(nb.makes), path.is_file()))
    return out


def claim_notebooks(evidence: str, notebooks=figure_map.NOTEBOOKS) -> tuple:
    """The notebooks that show a claim, read from its evidence text.

    The evidence of a claim (:attr:`fpdtw.paper.claims.Claim.evidence`) names notebooks
    (``"Fig. 1 (02_fig1_oedtw)"``), the files they make (``"table1_method_c_60_120hz"``),
    JSON files named after a notebook (``"10_fig8_walk_pair.json"``) or a family of
    figures (``"fig5/fig6 summaries"``: every file starting ``fig5_``). Each is mapped to
    its notebook through the figure map.

    Parameters
    ----------
    evidence : str
    notebooks : sequence of fpdtw.app.figure_map.Notebook

    Returns
    -------
    stems : tuple of str
        In order of first mention, without repeats; empty when nothing is named.
    """
    stems = {nb.stem for nb in notebooks}
    owner = {m: nb.stem for nb in notebooks for m in nb.makes}
    out = []
    for tok in re.findall(r"[A-Za-z0-9_]+", evidence):
        if tok in stems:
            hits = [tok]
        elif tok in owner:
            hits = [owner[tok]]
        elif re.fullmatch(r"[a-z]+\d+", tok):  # a family: fig5 -> fig5_*
            hits = sorted({s for m, s in owner.items() if m.startswith(tok + "_")})
        else:
            hits = []
        out += [h for h in hits if h not in out]
    return tuple(out)


# -- the front page ----------------------------------------------------------------------


def _cell(text) -> str:
    """Text for one cell of a Markdown table (no line breaks, pipes escaped)."""
    return " ".join(str(text).split()).replace("|", "\\|")


def _holds(verdict: str) -> str:
    v = str(verdict)
    known = HOLDS + ("holds", "contradicted")
    cls = {"n/a": "na"}.get(v, v.replace(" ", "-") if v in known else "na")
    return f'<span class="holds holds-{cls}">{html.escape(v)}</span>'


def _plugin_cell(row: dict) -> str:
    """The OPW plugin reading's value and verdict of a claims row ("" where n/a)."""
    verdict = row.get("holds_plugin")
    if verdict in (None, "", "n/a"):
        return ""
    return f"{_cell(row.get('ours_plugin', ''))}<br>{_holds(verdict)}"


def _read_csv(path) -> list[dict] | None:
    path = Path(path)
    if not path.is_file():
        return None
    with path.open(newline="", encoding="utf-8") as f:
        return list(csv.DictReader(f))


def claims_section(claims: list[dict] | None, pages: list[Page], history: bool = False) -> str:
    """The front page's claims table (MyST Markdown).

    Parameters
    ----------
    claims : list of dict or None
        Rows of ``results/<mode>/claims.json`` (:data:`fpdtw.paper.claims.COLUMNS`); None
        when notebook 12 has not written them.
    pages : list of Page
    history : bool
        The book has the page :data:`HISTORY`: say where the rules' dates are.
    """
    out = ["## The claims, checked", ""]
    if not claims:
        out += ["No claims table yet: notebook `12_claims` writes it (`make figures`).", ""]
        return "\n".join(out)
    from fpdtw.paper.claims.rules import LEGEND

    counts = {v: sum(1 for r in claims if r.get("holds") == v) for v in HOLDS}
    extra = sum(1 for r in claims if r.get("holds") not in HOLDS)
    summary = ", ".join(f"{_holds(v)} {counts[v]}" for v in HOLDS if counts[v])
    when = ""
    if history:
        when = f" (when each rule was chosen, and what had been seen by then: {HISTORY_LINK})"
    out += [
        f"{len(claims)} claims of the FP-DTW paper and the OPW poster, each split into parts "
        "and decided by the rules in `fpdtw.paper.claims`"
        + when
        + ": "
        + summary
        + (f", other {extra}" if extra else "")
        + ".",
        "",
        f"*{LEGEND}*",
        "",
        "*Why*: the parts that do not hold and the numbers that make them fail, with their 95 % "
        "intervals. *Per dataset*: the verdict on the authors' takes alone, on HDM05 alone and "
        "on the paper-shaped selection (at most 8 takes per movement); *these movements*: only "
        "the motions resampled. *Robust*: under how many of the paper's open readings and "
        "silent choices (notebook 15) the verdict stands. *Literal window*: with Method C's "
        "literal `(w_i + 1) x w` window. *OPW plugin*: the OPW poster's claims with OPW read "
        "as the authors' MotionBuilder plugin does it (notebooks 13, 14). *Notebook*: the "
        "pages that show the evidence.",
        "",
        "{.claims}",
        "| # | claim | paper | ours | verdict | why | per dataset | robust | literal window "
        "| OPW plugin | notebook |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    executed = {p.stem for p in pages if p.executed}
    for r in claims:
        links = []
        for stem in claim_notebooks(str(r.get("evidence", ""))):
            if stem in executed:
                links.append(f"[{stem[:2]}](notebooks/{stem}.ipynb)")
            else:
                links.append(f"{stem[:2]} (not run)")
        shown = ", ".join(links) or _cell(r.get("evidence", ""))
        literal = r.get("holds_literal")
        per = "<br>".join(
            f"{label}: {_holds(r[key])}"
            for label, key in (("authors", "holds_authors_fbx"), ("HDM05", "holds_hdm05"),
                               ("paper-shaped", "holds_paper_shaped"),
                               ("these movements", "holds_same_movements"))
            if r.get(key) not in (None, "n/a")
        )  # fmt: skip
        why = _cell(r.get("reason", ""))
        if r.get("interval"):
            why += f" <br>95 %: {_cell(r['interval'])}"
        out.append(
            "| "
            + " | ".join(
                [
                    _cell(r.get("id", "")),
                    _cell(r.get("claim", "")),
                    _cell(r.get("paper", "")),
                    _cell(r.get("ours", "")),
                    _holds(r.get("holds", "n/a")),
                    f'<span class="reason">{why}</span>',
                    per or "-",
                    _cell(r.get("robustness", "")),
                    _holds(literal) if literal is not None else "",
                    _plugin_cell(r),
                    shown,
                ]
            )
            + " |"
        )
    out.append("")
    return "\n".join(out)


def unlisted_missing(manifests=None) -> dict:
    """What each dataset's manifest says is not obtainable here (and so is not listed).

    The sentences of a manifest's ``notes`` that say "not obtainable here" (HDM05's
    walking, turning, punching, jumping and sitting classes; the OPW poster's other CMU
    clips). What a manifest lists but this machine lacks is in notebook 01's table.

    Parameters
    ----------
    manifests : list of fpdtw.paper.datasets.Manifest, optional
        Default: every manifest of ``data_manifest/``.

    Returns
    -------
    dict of str to str
        ``{dataset: sentences}``, only datasets whose notes say so.
    """
    if manifests is None:
        from fpdtw.paper import datasets

        manifests = datasets.manifests()
    out = {}
    for m in manifests:
        sentences = re.split(r"(?<=\.)\s+(?=[A-Z])", " ".join(str(m.notes or "").split()))
        said = [x for x in sentences if "not obtainable here" in x.lower()]
        if said:
            out[m.name] = " ".join(said)
    return out


def data_section(figures_dir) -> str:
    """The front page's data statement: what was used, what is missing (MyST Markdown).

    Read from notebook 01's ``data_summary.csv`` (every movement: takes listed, available
    here, missing), the manifests' word on what is not obtainable at all
    (:func:`unlisted_missing`) and notebook 05's ``experiment_pairs.csv`` (motions and
    ordered pairs per movement), next to the paper's counts
    (:data:`fpdtw.paper.numbers.DATA`).

    Parameters
    ----------
    figures_dir : str or Path
    """
    from fpdtw.paper import numbers

    figures_dir = Path(figures_dir)
    out = ["## The data used, and what is missing", ""]
    summary = _read_csv(figures_dir / "data_summary.csv")
    pairs = _read_csv(figures_dir / "experiment_pairs.csv")
    d = numbers.DATA
    out += [
        f"The FP-DTW paper used {d['motions']} motions of {d['movements']} movements "
        f"({d['pairs']} ordered pairs): the authors' takes and HDM05 motions. The OPW poster "
        "used CMU two-person clips. Not all of that is available here, so our numbers differ "
        "from the papers' and every notebook shows both.",
        "",
    ]
    if summary is None:
        out += ["No data summary yet: notebook `01_data_and_motions` writes it.", ""]
    else:
        unlisted = unlisted_missing()
        out += [
            "| dataset | movements here / listed | motions here / listed | listed, not here "
            "| not obtainable here (not listed) |",
            "|---|---|---|---|---|",
        ]
        for ds in dict.fromkeys(r["dataset"] for r in summary):
            rows = [r for r in summary if r["dataset"] == ds]
            here = sum(int(r["available"]) for r in rows)
            listed = sum(int(r["listed"]) for r in rows)
            moves_here = sum(int(r["available"]) > 0 for r in rows)
            gone = [f"{r['movement']} ({r['missing']})" for r in rows if int(r.get("missing") or 0)]
            out.append(
                f"| `{ds}` | {moves_here} / {len(rows)} | {here} / {listed} | "
                + _cell(", ".join(gone) or "nothing")
                + " | "
                + _cell(unlisted.get(ds) or "")
                + " |"
            )
        out.append("")
    if pairs is not None:
        per = {}
        for r in pairs:
            per.setdefault(r["dataset"], [0, 0, 0])
            per[r["dataset"]][0] += int(r["motions"])
            per[r["dataset"]][1] += 1
            per[r["dataset"]][2] += int(r["pairs"])
        total = [sum(v[i] for v in per.values()) for i in range(3)]
        parts = ", ".join(f"`{ds}` {v[0]} motions, {v[2]} pairs" for ds, v in per.items())
        out += [
            f"The experiments ran on {total[0]} motions of {total[1]} movements, "
            f"{total[2]} ordered pairs ({parts}): every ordered pair of distinct takes of a "
            "movement ([05](notebooks/05_run_experiments.ipynb)).",
            "",
        ]
    out += [
        "Where the data come from, their licences and how to cite them: the page *Data, and "
        "working offline* (`docs/data.md`) and `fpdtw data cite`. Notebook "
        "[01](notebooks/01_data_and_motions.ipynb) lists every movement.",
        "",
    ]
    return "\n".join(out)


RERUN = """\
## How to rerun

On a machine with `python3` (CPython 3.11 on Linux x86_64 for the pinned environment) and
`make`, in a checkout of the repository:

```sh
make figures                     # environment, data, every notebook, figures/, then this book
make book                        # only this book, from the executed notebooks in build/notebooks
make test                        # lint, tests, the smoke notebooks, the smoke book in a browser
make figures/fig5_similarity.pdf # one figure and what it needs
```

Offline, point `FPDTW_MIRROR` at a copy of the data first (the page *Data, and working
offline*, `docs/data.md`). The experiment grids run in the terminal with a progress bar
before notebooks 05 and 15, and each notebook prints when it starts and ends.
"""


def notebooks_section(pages: list[Page]) -> str:
    """The front page's list of notebook pages (MyST Markdown), and the hidden toctree."""
    out = ["## The notebooks", "", "| notebook | reproduces | makes |", "|---|---|---|"]
    for p in pages:
        name = (
            f"[{_cell(p.title)}](notebooks/{p.stem}.ipynb)"
            if p.executed
            else (f"`{p.stem}` (not run yet)")
        )
        makes = ", ".join(f"`{m}`" for m in p.makes)
        out.append(f"| {name} | {_cell(p.paper)} | {makes} |")
    out += ["", "Every figure on one page: [Figures](figures.md).", ""]
    out += ["```{toctree}", ":hidden:", ":caption: Notebooks", ""]
    out += [f"notebooks/{p.stem}" for p in pages if p.executed]
    out += ["```", "", "```{toctree}", ":hidden:", ":caption: Figures", "", "figures", "```", ""]
    return "\n".join(out)


def front_page(
    claims: list[dict] | None,
    pages: list[Page],
    figures_dir,
    mode: str = "full",
    built_from: str | None = None,
    docs=(),
) -> str:
    """The book's front page, ``index.md`` (MyST Markdown).

    Parameters
    ----------
    claims : list of dict or None
        Rows of the claims JSON (:func:`fpdtw.paper.claims.save_claims`).
    pages : list of Page
    figures_dir : str or Path
        Where the notebooks wrote their figures and tables.
    mode : {"full", "smoke"}
        ``"smoke"`` says at the top that the numbers come from the short smoke runs.
    built_from : str, optional
        A line on what made it (versions, commit).
    docs : sequence of DocPage
        The pages of ``docs/`` in the book (:func:`doc_pages`): listed, and ``history.md``
        linked where the rules are named when it is one of them.
    """
    history = any(d.stem == HISTORY.stem for d in docs)
    title = "FP-DTW and OPW, reproduced" + (" (smoke run)" if mode == "smoke" else "")
    # no right-hand contents column on the front page: the claims table needs the width
    out = ["---", "html_theme.sidebar_secondary.remove: true", "---", "", f"# {title}", ""]
    if mode == "smoke":
        out += [
            '<p class="smoke-banner">The smoke book: every notebook run on 54 short pairs '
            "(<code>make test</code>), to test the site. Its numbers are not the "
            "reproduction; <code>make figures</code> builds the real book.</p>",
            "",
        ]
    out += [
        "Every figure and table of Randall, Harvey and Williams, *Online alignment of human "
        "motion using forward plotting-DTW* (CAVW 34(3) e2166, 2023) and of their OPW poster, "
        "made again by the numbered notebooks of `fpdtw`. Each page below is one notebook as "
        "it ran, outputs included.",
        "",
    ]
    if history:
        out += [
            f"{HISTORY_LINK}: when each analysis default and verdict rule was chosen, and "
            "which results had been seen by then.",
            "",
        ]
    if built_from:
        out += [f"*Built from* {built_from}.", ""]
    out += [
        claims_section(claims, pages, history),
        data_section(figures_dir),
        RERUN,
        notebooks_section(pages),
        docs_section(docs),
    ]
    return "\n".join(out)


def figures_page(pages: list[Page], figures_dir) -> str:
    """``figures.md``: every figure by notebook; the tables (up to :data:`TABLE_MAX_LINES`
    lines); the PDF, CSV and Markdown files as downloads.

    Image paths are relative to the Sphinx source folder, where :func:`write_source`
    copies the files (``figures/<name>``).

    Parameters
    ----------
    pages : list of Page
    figures_dir : str or Path
    """
    figures_dir = Path(figures_dir)
    out = [
        "# Figures",
        "",
        "Every figure and table the notebooks wrote, by notebook (PDF, CSV and Markdown "
        "files as downloads).",
        "",
    ]
    for p in pages:
        present = [
            (
                m,
                [
                    s
                    for s in IMAGE_SUFFIXES + DOWNLOAD_SUFFIXES
                    if (figures_dir / (m + s)).is_file()
                ],
            )
            for m in p.makes
        ]
        present = [(m, s) for m, s in present if s]
        if not present:
            continue
        link = f"[{_cell(p.title)}](notebooks/{p.stem}.ipynb)" if p.executed else p.stem
        out += [f"## {p.stem[:2]} · {_cell(p.paper)}", "", f"Notebook: {link}.", ""]
        for m, suffixes in present:
            downloads = " ".join(
                f"{{download}}`{s[1:]} <figures/{m}{s}>`"
                for s in suffixes
                if s in DOWNLOAD_SUFFIXES
            )
            images = [s for s in suffixes if s in IMAGE_SUFFIXES]
            out += [f"### `{m}`", ""]
            for s in images:
                out += [
                    f"```{{image}} figures/{m}{s}",
                    f":alt: {m} ({p.paper})",
                    ":width: 100%",
                    "```",
                    "",
                ]
            table = figures_dir / (m + ".md")
            if table.is_file() and len(table.read_text(encoding="utf-8").splitlines()) <= (
                TABLE_MAX_LINES
            ):
                out += [f"```{{include}} figures/{m}.md", "```", ""]
            if downloads:
                out += [downloads, ""]
    return "\n".join(out)


# -- Sphinx ----------------------------------------------------------------------------------


def sphinx_conf(mode: str = "full") -> str:
    """The ``conf.py`` of the book (the executed notebooks are never run again)."""
    conf = {
        "project": "fpdtw",
        "author": "fpdtw developers",
        "copyright": "fpdtw developers; figures from data under their own licences",
        "extensions": ["myst_nb", "fpdtw.app.book"],
        "html_theme": "sphinx_book_theme",
        "html_title": "fpdtw book" + (" (smoke)" if mode == "smoke" else ""),
        "html_static_path": ["_static"],
        "html_css_files": ["book.css"],
        "html_favicon": "_static/favicon.svg",
        "html_context": {"default_mode": "light"},
        "html_math_renderer": "mathml",
        "html_last_updated_fmt": None,
        "html_theme_options": {
            "home_page_in_toc": True,
            "show_toc_level": 2,
            "use_download_button": True,
            "use_fullscreen_button": False,
            "use_repository_button": False,
        },
        "exclude_patterns": ["_build", "figures/*.md"],
        "nb_execution_mode": "off",
        "nb_merge_streams": True,
        "myst_enable_extensions": ["dollarmath", "attrs_block", "attrs_inline"],
        "myst_heading_anchors": 3,
        "suppress_warnings": ["myst.header", "mystnb.unknown_mime_type"],
    }
    lines = ['"""Sphinx configuration of the fpdtw book, written by fpdtw.app.book."""', ""]
    lines += [f"{k} = {v!r}" for k, v in conf.items()]
    return "\n".join(lines) + "\n"


def _mathml(tex: str, block: bool) -> str:
    from docutils.utils.math import latex2mathml

    return latex2mathml.tex2mathml(tex, as_block=block)


def _visit_math(self, node) -> None:
    from docutils import nodes

    tex = node.astext()
    try:
        self.body.append(_mathml(tex, block=False))
    except Exception:  # docutils does not know a command: show the TeX
        self.body.append(f'<code class="math">{self.encode(tex)}</code>')
    raise nodes.SkipNode


def _visit_math_block(self, node) -> None:
    from docutils import nodes

    tex = node.astext()
    self.body.append(self.starttag(node, "div", CLASS="math"))
    try:
        self.body.append(_mathml(tex, block=True))
    except Exception:
        self.body.append(f'<pre class="math">{self.encode(tex)}</pre>')
    self.body.append("</div>\n")
    raise nodes.SkipNode


def setup(app) -> dict:
    """Sphinx extension: the math renderer ``"mathml"`` (no script, nothing fetched).

    LaTeX of ``$...$`` and ``$$...$$`` is converted to MathML by docutils; a command
    docutils does not know leaves the TeX as code.
    """
    app.add_html_math_renderer("mathml", (_visit_math, None), (_visit_math_block, None))
    return {"parallel_read_safe": True, "parallel_write_safe": True}


def _copy_if_changed(src: Path, dst: Path) -> None:
    if dst.is_file() and dst.read_bytes() == src.read_bytes():
        return
    dst.parent.mkdir(parents=True, exist_ok=True)
    shutil.copyfile(src, dst)


def _write_if_changed(path: Path, text: str) -> None:
    if path.is_file() and path.read_text(encoding="utf-8") == text:
        return
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text, encoding="utf-8")


def load_claims(path) -> list[dict] | None:
    """The claim rows of a claims JSON (``{"mode", "claims": [...]}``), None if absent."""
    path = Path(path)
    if not path.is_file():
        return None
    return json.loads(path.read_text(encoding="utf-8"))["claims"]


def write_source(
    src,
    notebooks_dir,
    figures_dir,
    claims_path,
    mode: str = "full",
    built_from: str | None = None,
    docs=DOCS,
) -> list[Page]:
    """Write the book's Sphinx source folder (files unchanged since the last build are kept).

    Parameters
    ----------
    src : str or Path
        The source folder to write (e.g. ``build/book-src``).
    notebooks_dir, figures_dir : str or Path
        The executed notebooks, and the figures and tables they wrote.
    claims_path : str or Path
        ``results/<mode>/claims.json``.
    mode : {"full", "smoke"}
    built_from : str, optional
        Shown on the front page.
    docs : str or Path or None
        The folder of Markdown pages (default :data:`DOCS`), each copied as a page of the
        book and listed on the front page (:func:`doc_pages`); none when None or missing.

    Returns
    -------
    pages : list of Page
    """
    src, figures_dir = Path(src), Path(figures_dir)
    pages = book_pages(notebooks_dir)
    claims = load_claims(claims_path)
    wanted = {"conf.py", "index.md", "figures.md", "_static/book.css", "_static/favicon.svg"}
    extra = doc_pages(docs)
    _write_if_changed(src / "conf.py", sphinx_conf(mode))
    _write_if_changed(src / "_static" / "book.css", _CSS)
    _write_if_changed(src / "_static" / "favicon.svg", _FAVICON)
    _write_if_changed(
        src / "index.md", front_page(claims, pages, figures_dir, mode, built_from, extra)
    )
    for d in extra:
        _copy_if_changed(d.path, src / f"{d.stem}.md")
        wanted.add(f"{d.stem}.md")
    _write_if_changed(src / "figures.md", figures_page(pages, figures_dir))
    for p in pages:
        if p.executed:
            rel = f"notebooks/{p.stem}.ipynb"
            _copy_if_changed(Path(notebooks_dir) / f"{p.stem}.ipynb", src / rel)
            wanted.add(rel)
        for m in p.makes:
            for s in IMAGE_SUFFIXES + DOWNLOAD_SUFFIXES:
                f = figures_dir / (m + s)
                if f.is_file():
                    _copy_if_changed(f, src / "figures" / f.name)
                    wanted.add(f"figures/{f.name}")
    for f in sorted(src.rglob("*")):  # left from an earlier build
        if f.is_file() and f.relative_to(src).as_posix() not in wanted:
            f.unlink()
    return pages


def build(
    out,
    notebooks_dir,
    figures_dir,
    claims_path,
    mode: str = "full",
    quiet: bool = True,
) -> dict:
    """Build the book: write its source next to ``out`` and run Sphinx's HTML builder.

    ``out`` is emptied first (a ``screenshots/`` folder in it is kept: the browser check
    writes there); the source goes to ``<out>-src/`` and Sphinx's cache to
    ``<out>-src/.doctrees``.

    Parameters
    ----------
    out : str or Path
        The site's folder (``build/book``: ``build/book/index.html`` is the front page).
    notebooks_dir, figures_dir, claims_path, mode
        As for :func:`write_source`.
    quiet : bool
        Sphinx prints warnings and errors only.

    Returns
    -------
    dict
        ``index`` (Path of the front page), ``pages`` (HTML pages written), ``notebooks``
        (notebook pages), ``seconds``.

    Raises
    ------
    RuntimeError
        Sphinx failed.
    """
    from sphinx.cmd.build import build_main

    from fpdtw.paper.provenance import git_commit, versions_line

    t0 = time.perf_counter()
    out = Path(out)
    src = out.with_name(out.name + "-src")
    git = git_commit()
    built_from = versions_line()
    if git.get("commit"):
        built_from += f", commit `{git['commit'][:12]}`" + (
            " (with changes)" if git["dirty"] else ""
        )
    pages = write_source(src, notebooks_dir, figures_dir, claims_path, mode, built_from)
    if out.is_dir():
        for f in out.iterdir():
            if f.name == "screenshots":
                continue
            shutil.rmtree(f) if f.is_dir() and not f.is_symlink() else f.unlink()
    args = ["-b", "html", "-d", str(src / ".doctrees"), "-j", "1"]
    args += ["-q"] if quiet else []
    status = build_main([*args, str(src), str(out)])
    if status != 0:
        raise RuntimeError(f"sphinx-build failed with status {status} (source: {src})")
    html_pages = [p for p in out.rglob("*.html") if not p.relative_to(out).parts[0].startswith("_")]
    return {
        "index": out / "index.html",
        "pages": len(html_pages),
        "notebooks": sum(p.executed for p in pages),
        "seconds": time.perf_counter() - t0,
    }


def main(argv=None) -> int:
    """``python -m fpdtw.app.book [--mode full|smoke] [--notebooks DIR] [--figures DIR]
    [--claims FILE] [--out DIR]``."""
    ap = argparse.ArgumentParser(
        prog="python -m fpdtw.app.book", description=__doc__.split("\n")[0]
    )
    ap.add_argument("--mode", choices=("full", "smoke"), default="full")
    ap.add_argument("--notebooks", type=Path, help="executed notebooks (default build/notebooks)")
    ap.add_argument("--figures", type=Path, help="figures and tables (default: fpdtw's figures)")
    ap.add_argument("--claims", type=Path, help="claims JSON (default results/<mode>/claims.json)")
    ap.add_argument("--out", type=Path, help="the site (default build/book)")
    ap.add_argument("--verbose", action="store_true", help="Sphinx's progress too")
    a = ap.parse_args(argv)
    from fpdtw.paper.paths import executed_dir, figures_dir, results_dir

    out = a.out or REPO_ROOT / "build" / "book"
    info = build(
        out,
        a.notebooks or executed_dir(),
        a.figures or figures_dir(),
        a.claims or results_dir() / a.mode / "claims.json",
        a.mode,
        quiet=not a.verbose,
    )
    print(
        f"book: {info['index']} ({info['pages']} pages, {info['notebooks']} notebooks) "
        f"in {info['seconds']:.1f} s"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
