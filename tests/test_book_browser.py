"""The smoke book in a real browser (headless Chromium driven by Selenium through Debian's
chromedriver, fpdtw.app.browser), and the check itself on a site broken on purpose.

``make test`` builds the smoke book (``build/smoke/book``) before pytest runs. Without the
browser or its driver the tests skip, saying which Debian packages to install; under
``CI=true`` they fail instead, so that CI cannot pass without having looked. A screenshot of
every page is kept for a person to look at: ``build/book/screenshots/smoke-front.png`` (and
``smoke-front-full.png``, the whole front page), ``smoke-pages/<page>.png`` for the others.
"""

from __future__ import annotations

import json
import os
import struct
import time

import pytest

from fpdtw.app import browser
from fpdtw.paper import claims
from fpdtw.paper.paths import REPO_ROOT

SMOKE_BOOK = REPO_ROOT / "build" / "smoke" / "book"
SMOKE_NOTEBOOKS = REPO_ROOT / "build" / "smoke"
SMOKE_CLAIMS = REPO_ROOT / "build" / "smoke" / "results" / "smoke" / "claims.json"
SCREENSHOTS = REPO_ROOT / "build" / "book" / "screenshots"


def _in_ci() -> bool:
    return os.environ.get("CI", "").strip().lower() in {"1", "true", "yes"}


def _skip_or_fail(msg: str) -> None:
    if _in_ci():
        pytest.fail(f"{msg} (CI=true: this fails instead of skipping)")
    pytest.skip(msg)


@pytest.fixture(scope="module")
def chromium():
    why = browser.missing_browser()
    if why:
        _skip_or_fail(f"browser tests: {why}")


@pytest.fixture(scope="module")
def smoke_report(chromium):
    if not (SMOKE_BOOK / "index.html").is_file():
        _skip_or_fail(f"no smoke book in {SMOKE_BOOK}: `make test` or `make smoke-book` builds it")
    t0 = time.perf_counter()
    report = browser.check_site(SMOKE_BOOK, screenshots=SCREENSHOTS, prefix="smoke-")
    print(f"\nsmoke book in Chromium: {report.summary()} ({time.perf_counter() - t0:.1f} s)")
    return report


def _png_size(path) -> tuple[int, int]:
    head = path.read_bytes()[:24]
    assert head[:8] == b"\x89PNG\r\n\x1a\n", path
    return struct.unpack(">II", head[16:24])


def _image_outputs(path) -> int:
    cells = json.loads(path.read_text())["cells"]
    return sum(
        any(k.startswith("image/") for k in o.get("data", {}))
        for c in cells
        for o in c.get("outputs", [])
    )


def test_every_page_loads_without_console_errors_images_and_links_resolve(smoke_report):
    assert not smoke_report.problems, "\n".join(smoke_report.problems)
    assert smoke_report.links > 50  # the check did look at links


def test_every_notebook_has_a_page_reached_from_the_front_page(smoke_report):
    stems = sorted(p.stem for p in SMOKE_NOTEBOOKS.glob("[0-9]*.ipynb") if ".part" not in p.name)
    assert len(stems) >= 16
    reached = set(smoke_report.pages) - set(smoke_report.orphans)
    for stem in stems:
        page = f"notebooks/{stem}.html"
        assert page in reached, f"{page} is not linked from the front page"
        # every image output of the notebook is on its page, and loaded (checked above)
        assert smoke_report.pages[page].images >= _image_outputs(SMOKE_NOTEBOOKS / f"{stem}.ipynb")
        assert smoke_report.pages[page].title.startswith(stem[:2])
    assert "figures.html" in reached and smoke_report.pages["figures.html"].images >= 20
    assert "history.html" in reached  # How this analysis was made


def test_the_claims_table_has_every_claim_linked_to_its_notebook(smoke_report):
    rows = smoke_report.pages["index.html"].claims
    written = json.loads(SMOKE_CLAIMS.read_text())["claims"]
    assert [r["id"] for r in rows] == [r["id"] for r in written] == [c.id for c in claims.CLAIMS]
    for row, w in zip(rows, written):
        assert row["holds"] == w["holds"]
        assert row["links"], f"claim {row['id']} links to no notebook"
        assert all("/notebooks/" in u and u.endswith(".html") for u in row["links"]), row


def test_a_screenshot_of_every_page_is_kept(smoke_report):
    front = SCREENSHOTS / "smoke-front.png"
    assert smoke_report.pages["index.html"].screenshot == front
    assert smoke_report.screenshots[:2] == [front, SCREENSHOTS / "smoke-front-full.png"]
    assert front.stat().st_size > 20_000  # a page with text, not a blank one
    width, height = _png_size(SCREENSHOTS / "smoke-front-full.png")
    assert width == browser.WINDOW[0] and height > browser.WINDOW[1]  # the whole long page
    for path, page in smoke_report.pages.items():
        if path != "index.html":
            assert page.screenshot == SCREENSHOTS / "smoke-pages" / path.replace(".html", ".png")
        assert page.screenshot in smoke_report.screenshots and page.screenshot.is_file(), path
        assert _png_size(page.screenshot) == browser.WINDOW, path
    assert len(smoke_report.screenshots) == len(smoke_report.pages) + 1


@pytest.mark.parametrize("page", ["10_fig8_walk_pair", "20_align_a_live_performance"])
def test_the_notebooks_embedded_view_plays_in_the_book(smoke_report, page):
    """The viewer a notebook embeds (fpdtw.app.view.embed: the page inside an iframe, its
    data inline) is drawn in the book: both skeletons, the lag, a slider that moves them."""
    with browser.serve(SMOKE_BOOK) as base, browser.chromium() as b:
        b.get(f"{base}notebooks/{page}.html")
        frame = b.find_element("css selector", "div.fpdtw-view iframe")
        b.execute_script("arguments[0].scrollIntoView()", frame)
        b.switch_to.frame(frame)
        stats = None
        for _ in range(100):
            stats = b.execute_script(
                "return window.fpdtwView && window.fpdtwView.ready && window.fpdtwView.stats()"
            )
            if stats:
                break
            time.sleep(0.1)
        assert stats, "the embedded view never drew"
        (p,) = stats["performers"]
        assert p["live"]["segments"] >= 20 and p["rec"]["segments"] >= 20, p
        assert p["lag"].startswith("lag "), p
        b.execute_script("window.fpdtwView.seek(100)")
        time.sleep(0.2)
        q = b.execute_script("return window.fpdtwView.stats()")["performers"][0]
        assert q["n"] == 100 and q["live"]["bbox"] != p["live"]["bbox"], (p, q)
        b.switch_to.default_content()
        (SCREENSHOTS / "smoke-view").mkdir(parents=True, exist_ok=True)
        b.save_screenshot(str(SCREENSHOTS / "smoke-view" / f"{page}.png"))
        errors = browser.console_errors(b.get_log("browser"))
        assert not errors, errors


def _forbid_selenium_manager(monkeypatch):
    """Selenium Manager (which may download drivers and browsers) must never be asked."""
    from selenium.webdriver.common.selenium_manager import SeleniumManager

    def called(*args, **kwargs):
        raise AssertionError(f"Selenium Manager was asked: {args}")

    monkeypatch.setattr(SeleniumManager, "binary_paths", called)
    monkeypatch.delenv("SE_OFFLINE", raising=False)


def test_the_check_finds_what_is_broken(tmp_path, chromium, monkeypatch):
    """A site with every kind of fault the check looks for, and one good page; the browser
    found through its named driver, never through Selenium Manager."""
    import io

    import matplotlib.pyplot as plt

    _forbid_selenium_manager(monkeypatch)
    site = tmp_path / "site"
    site.mkdir()
    buf = io.BytesIO()
    plt.imsave(buf, [[0.0, 1.0], [1.0, 0.0]], format="png")
    (site / "ok.png").write_bytes(buf.getvalue())
    icon = '<link rel="icon" href="data:,">'
    (site / "index.html").write_text(
        f"<html><head>{icon}<title>front</title></head><body>"
        '<img src="ok.png"><img src="missing.png">'
        '<a href="good.html#here">good</a> <a href="nowhere.html">gone</a> '
        '<a href="good.html#nope">no anchor</a> <a href="https://example.org/">outside</a>'
        "<script>console.error('something broke')</script></body></html>"
    )
    (site / "good.html").write_text(
        f"<html><head>{icon}<title>good</title></head><body>"
        '<p id="here">fine</p><img src="ok.png"><a href="index.html">back</a></body></html>'
    )
    (site / "throws.html").write_text(
        f"<html><head>{icon}<title>throws</title></head><body>"
        "<script>null.boom()</script></body></html>"
    )
    report = browser.check_site(site, screenshots=tmp_path / "shots")
    problems = "\n".join(report.problems)
    assert "index.html: console.error: something broke" in problems
    assert "index.html: image did not load: " in problems and "missing.png" in problems
    assert "index.html: network: " in problems and "missing.png - " in problems  # logged
    assert "status of 404" in problems
    assert "index.html -> nowhere.html: HTTP 404" in problems
    assert "index.html -> good.html#nope: no element with id 'nope'" in problems
    assert "throws.html: exception: Uncaught TypeError" in problems  # reached although unlinked
    assert report.orphans == ["throws.html"]
    assert not [p for p in report.problems if p.startswith("good.html")]
    assert "example.org" not in problems  # outside links are not followed
    assert report.pages["good.html"].images == 1
    assert len(report.problems) == 6, problems
    shots = sorted(p.relative_to(tmp_path / "shots").as_posix() for p in report.screenshots)
    assert shots == ["front-full.png", "front.png", "pages/good.png", "pages/throws.png"]
    assert "SE_OFFLINE" not in os.environ  # set only while the driver starts


def test_console_errors_of_hand_written_log_entries():
    """The browser's log (``driver.get_log("browser")``) as chromedriver words it."""
    entries = [
        {"level": "SEVERE", "source": "console-api",
         "message": 'http://127.0.0.1:8000/index.html 3:14 "something broke"'},
        {"level": "SEVERE", "source": "console-api",
         "message": "http://127.0.0.1:8000/a.html 1:2 Object"},
        {"level": "SEVERE", "source": "javascript",
         "message": "http://127.0.0.1:8000/t.html 0:28 Uncaught TypeError: null"},
        {"level": "SEVERE", "source": "network",
         "message": "http://127.0.0.1:8000/x.png - Failed to load resource: the server "
                    "responded with a status of 404 (File not found)"},
        {"level": "WARNING", "source": "console-api",
         "message": 'http://127.0.0.1:8000/index.html 4:1 "only a warning"'},
        {"level": "INFO", "source": "console-api", "message": "http://h/p 1:1 \"log\""},
        {"level": "SEVERE", "source": "security", "message": "blocked something"},
    ]  # fmt: skip
    assert browser.console_errors(entries) == [
        "console.error: something broke",
        "console.error: Object",
        "exception: Uncaught TypeError: null",
        "network: http://127.0.0.1:8000/x.png - Failed to load resource: the server responded "
        "with a status of 404 (File not found)",
        "security: blocked something",
    ]


def test_without_a_driver_the_check_says_what_to_install(monkeypatch, tmp_path):
    monkeypatch.setenv("FPDTW_CHROMEDRIVER", str(tmp_path / "no-such-driver"))
    why = browser.missing_browser()
    assert (
        why.startswith("no chromedriver found")
        and "apt-get install chromium chromium-driver" in why
    )
    with pytest.raises(browser.BrowserError, match="no chromedriver found"):
        browser.check_site(tmp_path)
    assert browser.main([str(tmp_path)]) == 2


@pytest.mark.parametrize("ci, outcome", [("true", "failed"), ("", "skipped")])
def test_a_missing_browser_fails_under_ci_and_skips_otherwise(monkeypatch, ci, outcome):
    monkeypatch.setenv("CI", ci)
    with pytest.raises((pytest.fail.Exception, pytest.skip.Exception)) as info:
        _skip_or_fail("no browser")
    assert {"failed": pytest.fail.Exception, "skipped": pytest.skip.Exception}[outcome] is info.type
