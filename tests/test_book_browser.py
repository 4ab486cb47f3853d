"""The smoke book in a real browser (headless Chromium over the DevTools protocol,
fpdtw.paper.browser), and the check itself on a site broken on purpose.

``make test`` builds the smoke book (``build/smoke/book``) before pytest runs. Without a
browser the tests skip, saying which Debian package to install; under ``CI=true`` they fail
instead, so that CI cannot pass without having looked. The front page's screenshot is kept in
``build/book/screenshots/smoke-front.png`` (and ``smoke-front-full.png``, the whole page)
for a person to look at.
"""

from __future__ import annotations

import json
import os
import struct
import time

import pytest

from fpdtw.paper import browser, claims
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
    exe = browser.find_chromium()
    if exe is None:
        _skip_or_fail(
            f"no Chromium found for the browser tests: install Debian's {browser.APT_PACKAGES} "
            f"package (apt-get install {browser.APT_PACKAGES}) or set FPDTW_CHROMIUM"
        )
    return exe


@pytest.fixture(scope="module")
def smoke_report(chromium):
    if not (SMOKE_BOOK / "index.html").is_file():
        _skip_or_fail(f"no smoke book in {SMOKE_BOOK}: `make test` or `make smoke-book` builds it")
    t0 = time.perf_counter()
    report = browser.check_site(
        SMOKE_BOOK, screenshots=SCREENSHOTS, shot_name="smoke-front.png", executable=chromium
    )
    print(f"\nsmoke book in Chromium: {report.summary()} ({time.perf_counter() - t0:.1f} s)")
    return report


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


def test_the_claims_table_has_every_claim_linked_to_its_notebook(smoke_report):
    rows = smoke_report.pages["index.html"].claims
    written = json.loads(SMOKE_CLAIMS.read_text())["claims"]
    assert [r["id"] for r in rows] == [r["id"] for r in written] == [c.id for c in claims.CLAIMS]
    for row, w in zip(rows, written):
        assert row["holds"] == w["holds"]
        assert row["links"], f"claim {row['id']} links to no notebook"
        assert all("/notebooks/" in u and u.endswith(".html") for u in row["links"]), row


def test_a_screenshot_of_the_front_page_is_kept(smoke_report):
    shot = SCREENSHOTS / "smoke-front.png"
    assert shot in smoke_report.screenshots and shot.is_file()
    head = shot.read_bytes()[:24]
    assert head[:8] == b"\x89PNG\r\n\x1a\n"
    width, height = struct.unpack(">II", head[16:24])
    assert (width, height) == browser.WINDOW
    assert shot.stat().st_size > 20_000  # a page with text, not a blank one


def test_the_check_finds_what_is_broken(tmp_path, chromium):
    """A site with every kind of fault the check looks for, and one good page."""
    import io

    import matplotlib.pyplot as plt

    buf = io.BytesIO()
    plt.imsave(buf, [[0.0, 1.0], [1.0, 0.0]], format="png")
    (tmp_path / "ok.png").write_bytes(buf.getvalue())
    icon = '<link rel="icon" href="data:,">'
    (tmp_path / "index.html").write_text(
        f"<html><head>{icon}<title>front</title></head><body>"
        '<img src="ok.png"><img src="missing.png">'
        '<a href="good.html#here">good</a> <a href="nowhere.html">gone</a> '
        '<a href="good.html#nope">no anchor</a> <a href="https://example.org/">outside</a>'
        "<script>console.error('something broke')</script></body></html>"
    )
    (tmp_path / "good.html").write_text(
        f"<html><head>{icon}<title>good</title></head><body>"
        '<p id="here">fine</p><img src="ok.png"><a href="index.html">back</a></body></html>'
    )
    (tmp_path / "throws.html").write_text(
        f"<html><head>{icon}<title>throws</title></head><body>"
        "<script>null.boom()</script></body></html>"
    )
    report = browser.check_site(tmp_path, executable=chromium)
    problems = "\n".join(report.problems)
    assert "index.html: console.error: something broke" in problems
    assert "index.html: image did not load: " in problems and "missing.png" in problems
    assert "missing.png" in problems and "404" in problems  # the failed request, logged
    assert "index.html -> nowhere.html: HTTP 404" in problems
    assert "index.html -> good.html#nope: no element with id 'nope'" in problems
    assert "throws.html: exception: TypeError" in problems  # reached although unlinked
    assert report.orphans == ["throws.html"]
    assert not [p for p in report.problems if p.startswith("good.html")]
    assert "example.org" not in problems  # outside links are not followed
    assert report.pages["good.html"].images == 1
    assert len(report.problems) == 6, problems


def test_the_profile_is_removed_while_a_straggler_still_writes_into_it(tmp_path):
    """Chromium's helper processes may outlive it and write into the profile for a
    moment: the removal retries until the folder is gone (CI once failed on this)."""
    import threading

    profile = tmp_path / "profile"
    (profile / "Default").mkdir(parents=True)
    stop = time.monotonic() + 0.6

    def straggler():
        k = 0
        while time.monotonic() < stop:
            try:
                (profile / "Default").mkdir(parents=True, exist_ok=True)
                (profile / "Default" / f"f{k}").write_text("x")
            except OSError:
                pass
            k += 1
            time.sleep(0.01)

    t = threading.Thread(target=straggler)
    t.start()
    time.sleep(0.05)
    browser._remove_tree(profile, tries=40, pause=0.05)
    t.join()
    browser._remove_tree(profile)  # whatever the straggler wrote after the first pass
    assert not profile.exists()
