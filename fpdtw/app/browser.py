"""Check the book in a real browser: headless Chromium driven by Selenium.

:func:`check_site` serves a built site (``build/book``, ``build/smoke/book``) from a
loopback HTTP server (127.0.0.1, a free port, this process only), opens its front page in
headless Chromium and follows every link inside the site. On every page it records the
browser's log entries of level error (uncaught exceptions, ``console.error``, resources
that failed to load), the images that did not load (natural width 0), the element ids and
the rows of the book's claims table, and keeps a screenshot; then every link inside the
site is checked (the file is served; a ``#fragment`` names an element of that page).

The browser is Debian's ``chromium`` and its WebDriver is Debian's ``chromium-driver``
(``apt-get install chromium chromium-driver``; ``.ci/run`` installs both), found on
``PATH`` or given by ``FPDTW_CHROMIUM`` and ``FPDTW_CHROMEDRIVER``. Selenium 4 drives
them through that driver, named explicitly, so Selenium Manager never runs and nothing is
downloaded (``SE_OFFLINE=true`` as well, should anything ask it). Every wait has a time
limit; the browser and the server are stopped however the check ends.

Run ``python -m fpdtw.app.browser build/book [--screenshots DIR]`` (``make book-check``).
"""

from __future__ import annotations

import argparse
import contextlib
import functools
import http.server
import json
import os
import re
import shutil
import subprocess
import sys
import threading
import time
import urllib.error
import urllib.parse
import urllib.request
from collections import deque
from dataclasses import dataclass, field
from pathlib import Path

#: Names tried on ``PATH`` (Debian's packages install ``/usr/bin/chromium`` and
#: ``/usr/bin/chromedriver``).
CHROMIUM_NAMES = ("chromium", "chromium-browser")
CHROMEDRIVER_NAMES = ("chromedriver",)
#: The Debian packages that provide them.
APT_PACKAGES = "chromium chromium-driver"
#: Seconds allowed for one page to load (and for a script in it to finish).
PAGE_TIMEOUT = 30.0
#: The window (CSS pixels) of the screenshots.
WINDOW = (1280, 1000)

# every <img> eager, waited for (decode() settles when the image has loaded or failed), then
# reported; every <a href> resolved against the page; every element id; the rows of the
# book's claims table (first cell, first verdict, links of the last cell)
_PAGE_FACTS_JS = """
return (async () => {
  const imgs = Array.from(document.images);
  imgs.forEach(i => { i.loading = 'eager'; });
  await Promise.all(imgs.map(i => i.decode().catch(() => null)));
  return {
    title: document.title,
    images: imgs.map(i => ({src: i.currentSrc || i.src, width: i.naturalWidth,
                            complete: i.complete})),
    links: Array.from(document.querySelectorAll('a[href]')).map(a => a.href),
    ids: Array.from(document.querySelectorAll('[id]')).map(e => e.id),
    claims: Array.from(document.querySelectorAll('table.claims tbody tr')).map(tr => ({
      id: tr.cells[0].innerText.trim(),
      holds: tr.querySelector('.holds') ? tr.querySelector('.holds').innerText.trim() : '',
      links: Array.from(tr.cells[tr.cells.length - 1].querySelectorAll('a')).map(a => a.href),
    })),
  };
})();
"""
# the number of resources the page has requested: the network is quiet once it stops growing
_RESOURCES_JS = "return performance.getEntriesByType('resource').length;"


def _find(env: str, names) -> str | None:
    value = os.environ.get(env)
    if value:
        return value if Path(value).is_file() else shutil.which(value)
    for name in names:
        path = shutil.which(name)
        if path:
            return path
    return None


def find_chromium() -> str | None:
    """The Chromium executable: ``FPDTW_CHROMIUM`` if set, else the first on ``PATH``."""
    return _find("FPDTW_CHROMIUM", CHROMIUM_NAMES)


def find_chromedriver() -> str | None:
    """Chromium's WebDriver: ``FPDTW_CHROMEDRIVER`` if set, else ``chromedriver`` on ``PATH``."""
    return _find("FPDTW_CHROMEDRIVER", CHROMEDRIVER_NAMES)


def missing_browser() -> str | None:
    """Why the check cannot run here (no browser or no driver), or None."""
    found = {"Chromium": find_chromium(), "chromedriver": find_chromedriver()}
    missing = [what for what, path in found.items() if not path]
    if not missing:
        return None
    return (
        f"no {' and no '.join(missing)} found: install Debian's {APT_PACKAGES} packages "
        f"(apt-get install {APT_PACKAGES}) or set FPDTW_CHROMIUM and FPDTW_CHROMEDRIVER"
    )


class BrowserError(RuntimeError):
    """The browser or its driver is missing, did not start, or did not answer in time."""


@contextlib.contextmanager
def _environment(**values):
    """Environment variables set while the block runs (put back afterwards)."""
    old = {k: os.environ.get(k) for k in values}
    os.environ.update(values)
    try:
        yield
    finally:
        for k, v in old.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v


@contextlib.contextmanager
def chromium(executable: str | None = None, driver: str | None = None, window=WINDOW):
    """Headless Chromium under Selenium, through the given chromedriver, while the block runs.

    Parameters
    ----------
    executable, driver : str, optional
        The browser and its driver (default :func:`find_chromium`, :func:`find_chromedriver`).
    window : tuple of int
        Width and height of the page's viewport (CSS pixels).

    Yields
    ------
    selenium.webdriver.Chrome
        With the browser's log kept (``goog:loggingPrefs``) and the page and script time
        limits set to :data:`PAGE_TIMEOUT`.
    """
    from selenium import webdriver
    from selenium.common.exceptions import WebDriverException
    from selenium.webdriver.chrome.service import Service

    executable = executable or find_chromium()
    driver = driver or find_chromedriver()
    if not executable or not driver:
        raise BrowserError(missing_browser() or "no Chromium or chromedriver given")
    options = webdriver.ChromeOptions()
    options.binary_location = executable
    for arg in (
        "--headless",
        "--disable-gpu",
        "--no-first-run",
        "--no-default-browser-check",
        "--disable-extensions",
        "--disable-background-networking",
        "--disable-component-update",
        "--disable-sync",
        "--disable-default-apps",
        "--mute-audio",
        "--hide-scrollbars",
        f"--window-size={window[0]},{window[1]}",
        # no name resolves (no DNS query leaves the machine) but localhost's: the
        # site is on 127.0.0.1, and Chromium's own calls home (accounts, updates,
        # link prefetching) fail at once
        "--host-resolver-rules=MAP * ~NOTFOUND , EXCLUDE localhost , EXCLUDE 127.0.0.1",
    ):
        options.add_argument(arg)
    if hasattr(os, "geteuid") and os.geteuid() == 0:
        options.add_argument("--no-sandbox")  # Chromium refuses its sandbox to root
    options.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    service = Service(executable_path=driver, log_output=subprocess.DEVNULL)
    # Selenium Manager offline (it is not run: the driver is named); the driver, on
    # localhost, spoken to directly even when a proxy is configured
    no_proxy = ",".join(filter(None, [os.environ.get("no_proxy"), "localhost,127.0.0.1"]))
    with _environment(SE_OFFLINE="true", no_proxy=no_proxy):
        try:
            browser = webdriver.Chrome(options=options, service=service)
        except WebDriverException as e:
            raise BrowserError(f"{driver} did not start {executable}: {e.msg}") from e
    try:
        browser.set_page_load_timeout(PAGE_TIMEOUT)
        browser.set_script_timeout(PAGE_TIMEOUT)
        browser.execute_cdp_cmd(
            "Emulation.setDeviceMetricsOverride",
            {"width": window[0], "height": window[1], "deviceScaleFactor": 1, "mobile": False},
        )
        yield browser
    finally:
        browser.quit()


# the browser's log: "<url> <line>:<column> <text>" (console messages, exceptions) or
# "<url> - <text>" (network); console.error's text is the JSON of its first argument
_LOG_PREFIX = re.compile(r"^\S+ (?:\d+:\d+|-) ")
_LOG_SOURCES = {"console-api": "console.error", "javascript": "exception"}


def console_errors(entries: list) -> list[str]:
    """The errors among the browser's log entries (``driver.get_log("browser")``), one line
    each: ``console.error: ...`` (also failed ``console.assert``), ``exception: ...``
    (uncaught), ``network: <url> - ...`` (a resource that failed to load) and the like."""
    out = []
    for e in entries:
        if e.get("level") != "SEVERE":
            continue
        source, text = e.get("source", "log"), e.get("message", "")
        if source == "network":
            out.append(f"network: {text}")
            continue
        text = _LOG_PREFIX.sub("", text, count=1)
        with contextlib.suppress(ValueError):
            text = str(json.loads(text)) if text.startswith('"') else text
        out.append(f"{_LOG_SOURCES.get(source, source)}: {text}")
    return out


# -- the loopback server ---------------------------------------------------------------------


class _QuietHandler(http.server.SimpleHTTPRequestHandler):
    def log_message(self, *args) -> None:
        pass


class _Server(http.server.ThreadingHTTPServer):
    daemon_threads = True

    def handle_error(self, request, client_address) -> None:
        if not isinstance(sys.exc_info()[1], ConnectionError):  # the browser hung up: fine
            super().handle_error(request, client_address)


@contextlib.contextmanager
def serve(root):
    """Serve a folder over HTTP on 127.0.0.1 (a free port) while the block runs.

    Yields
    ------
    base : str
        ``http://127.0.0.1:<port>/``.
    """
    handler = functools.partial(_QuietHandler, directory=str(root))
    server = _Server(("127.0.0.1", 0), handler)
    thread = threading.Thread(target=server.serve_forever, kwargs={"poll_interval": 0.1})
    thread.daemon = True
    thread.start()
    try:
        yield f"http://127.0.0.1:{server.server_address[1]}/"
    finally:
        server.shutdown()
        server.server_close()
        thread.join(timeout=10)


# -- the check -------------------------------------------------------------------------------


@dataclass
class PageReport:
    """What one page showed in the browser.

    Attributes
    ----------
    path : str
        The page's path inside the site (``"index.html"``).
    title : str
    errors : list of str
        Console errors (:func:`console_errors`).
    images : int
        Images on the page.
    broken_images : list of str
        Their URLs where the image did not load (natural width 0).
    ids : set of str
        Element ids (link fragments must name one).
    claims : list of dict
        The rows of a claims table on the page (``table.claims``, the book's front page):
        ``id``, ``holds`` (the first verdict), ``links`` (URLs of its last cell).
    screenshot : Path or None
        The PNG of its viewport, when screenshots were asked for.
    """

    path: str
    title: str = ""
    errors: list = field(default_factory=list)
    images: int = 0
    broken_images: list = field(default_factory=list)
    ids: set = field(default_factory=set)
    claims: list = field(default_factory=list)
    screenshot: Path | None = None


@dataclass
class SiteReport:
    """The result of :func:`check_site`.

    Attributes
    ----------
    pages : dict of str to PageReport
        Every HTML page of the site: those reached from the front page, then the others.
    broken_links : list of str
        ``"<page> -> <link>: <why>"`` for links inside the site that do not resolve.
    links : int
        Distinct links inside the site checked.
    orphans : list of str
        Pages of the site (HTML files outside ``_*`` folders) that no link from the front
        page reaches; they are checked too.
    screenshots : list of Path
        One per page (the front page's first), and the whole front page.
    seconds : float
    """

    pages: dict = field(default_factory=dict)
    broken_links: list = field(default_factory=list)
    links: int = 0
    orphans: list = field(default_factory=list)
    screenshots: list = field(default_factory=list)
    seconds: float = 0.0

    @property
    def problems(self) -> list[str]:
        """Every problem found, one line each (empty: the site is fine)."""
        out = []
        for p in self.pages.values():
            out += [f"{p.path}: {e}" for e in p.errors]
            out += [f"{p.path}: image did not load: {s}" for s in p.broken_images]
        return out + self.broken_links

    def summary(self) -> str:
        imgs = sum(p.images for p in self.pages.values())
        return (
            f"{len(self.pages)} pages, {imgs} images, {self.links} internal links, "
            f"{len(self.problems)} problems, {len(self.screenshots)} screenshots, "
            f"{self.seconds:.1f} s"
        )


def _split(url: str, base: str):
    """(path inside the site, fragment) of a URL under ``base``, or None outside it."""
    if not url.startswith(base):
        return None
    parsed = urllib.parse.urlsplit(url)
    path = urllib.parse.unquote(parsed.path)[len(urllib.parse.urlsplit(base).path) :]
    if path == "" or path.endswith("/"):
        path += "index.html"
    return path, urllib.parse.unquote(parsed.fragment)


def _status(url: str) -> str | None:
    """None if the URL serves a file (HTTP 200), else why not."""
    opener = urllib.request.build_opener(urllib.request.ProxyHandler({}))  # loopback: no proxy
    try:
        with opener.open(url, timeout=PAGE_TIMEOUT) as r:
            return None if r.status == 200 else f"HTTP {r.status}"
    except urllib.error.HTTPError as e:
        return f"HTTP {e.code}"
    except OSError as e:
        return str(e)


def _quiet(browser, timeout: float = 5.0, still: float = 0.3) -> None:
    """Wait (at most ``timeout`` s) until the page has requested nothing new for ``still`` s."""
    deadline = time.monotonic() + timeout
    seen, since = -1, time.monotonic()
    while time.monotonic() < deadline:
        n = browser.execute_script(_RESOURCES_JS)
        if n != seen:
            seen, since = n, time.monotonic()
        elif time.monotonic() - since >= still:
            return
        time.sleep(0.05)


def _screenshot(browser, path: Path, full_page: bool = False) -> Path:
    """A PNG of the viewport (or of the whole page, through the DevTools protocol)."""
    import base64

    path.parent.mkdir(parents=True, exist_ok=True)
    if not full_page:
        path.write_bytes(browser.get_screenshot_as_png())
        return path
    size = browser.execute_cdp_cmd("Page.getLayoutMetrics", {})["cssContentSize"]
    clip = {"x": 0, "y": 0, "width": size["width"], "height": size["height"], "scale": 1}
    shot = browser.execute_cdp_cmd(
        "Page.captureScreenshot", {"format": "png", "clip": clip, "captureBeyondViewport": True}
    )
    path.write_bytes(base64.b64decode(shot["data"]))
    return path


def _shot_path(folder: Path, prefix: str, page: str, start: str) -> Path:
    """``<prefix>front.png`` for the front page, ``<prefix>pages/<page>.png`` for the others."""
    if page == start:
        return folder / f"{prefix}front.png"
    return folder / f"{prefix}pages" / Path(page).with_suffix(".png")


def check_site(
    root,
    start: str = "index.html",
    screenshots=None,
    prefix: str = "",
    max_pages: int = 500,
    executable: str | None = None,
    driver: str | None = None,
) -> SiteReport:
    """Open a static site in headless Chromium, follow its links, report what is wrong.

    Parameters
    ----------
    root : str or Path
        The site's folder (``build/book``).
    start : str
        The front page, relative to ``root``.
    screenshots : str or Path, optional
        Where to write a screenshot of every page (none if None): ``<prefix>front.png``
        and ``<prefix>front-full.png`` (the whole front page), ``<prefix>pages/<page>.png``.
    prefix : str
        Put before the screenshots' names (``"smoke-"``).
    max_pages : int
        Stop following links after this many pages.
    executable, driver : str, optional
        The browser and its driver (default :func:`find_chromium`, :func:`find_chromedriver`).

    Returns
    -------
    SiteReport
        Its ``problems`` are empty when every page loaded without a console error, every
        image loaded and every link inside the site resolves.

    Raises
    ------
    BrowserError
        No browser or driver, or they did not start.
    """
    from selenium.common.exceptions import WebDriverException

    t0 = time.perf_counter()
    root = Path(root)
    report = SiteReport()
    links = {}  # (path, fragment) -> first page linking to it
    on_disk = sorted(
        p.relative_to(root).as_posix()
        for p in root.rglob("*.html")
        if not p.relative_to(root).parts[0].startswith("_")
    )
    with serve(root) as base, chromium(executable, driver) as browser:
        todo, seen = deque([start]), {start}
        while len(report.pages) < max_pages:
            if not todo:  # pages no link reaches (genindex.html, search.html): visit them too
                rest = [p for p in on_disk if p not in seen]
                if not rest:
                    break
                report.orphans.append(rest[0])
                seen.add(rest[0])
                todo.append(rest[0])
            path = todo.popleft()
            page = PageReport(path)
            report.pages[path] = page
            browser.get_log("browser")  # what an earlier page logged late is not this one's
            try:
                browser.get(base + urllib.parse.quote(path))
                facts = browser.execute_script(_PAGE_FACTS_JS)
                _quiet(browser)
            except WebDriverException as e:
                page.errors.append(f"did not load: {e.msg}")
                continue
            if screenshots is not None:
                shot = _shot_path(Path(screenshots), prefix, path, start)
                page.screenshot = _screenshot(browser, shot)
                report.screenshots.append(page.screenshot)
                if path == start:
                    full = shot.with_name(f"{shot.stem}-full.png")
                    report.screenshots.append(_screenshot(browser, full, full_page=True))
            page.errors = console_errors(browser.get_log("browser"))
            page.title = facts["title"]
            page.ids = set(facts["ids"])
            page.claims = facts["claims"]
            page.images = len(facts["images"])
            page.broken_images = [
                i["src"] for i in facts["images"] if not i["complete"] or i["width"] == 0
            ]
            for href in facts["links"]:
                target = _split(href, base)
                if target is None:
                    continue
                links.setdefault(target, path)
                if target[0].endswith(".html") and target[0] not in seen:
                    if (root / target[0]).is_file():
                        seen.add(target[0])
                        todo.append(target[0])
        checked = {}
        for (path, fragment), page in sorted(links.items()):
            if path not in checked:
                checked[path] = _status(base + urllib.parse.quote(path))
            why = checked[path]
            if why is None and fragment and path in report.pages:
                if fragment not in report.pages[path].ids:
                    why = f"no element with id {fragment!r}"
            if why is not None:
                link = path + (f"#{fragment}" if fragment else "")
                report.broken_links.append(f"{page} -> {link}: {why}")
        report.links = len(links)
    report.seconds = time.perf_counter() - t0
    return report


def main(argv=None) -> int:
    """``python -m fpdtw.app.browser SITE [--screenshots DIR] [--prefix P]``: exit 1 on
    any problem, 2 without a browser or its driver."""
    ap = argparse.ArgumentParser(
        prog="python -m fpdtw.app.browser", description=__doc__.split("\n")[0]
    )
    ap.add_argument("site", type=Path, help="the built site (e.g. build/book)")
    ap.add_argument("--screenshots", type=Path, help="folder for a screenshot of every page")
    ap.add_argument("--prefix", default="", help="before each screenshot's name (default none)")
    a = ap.parse_args(argv)
    why = missing_browser()
    if why:
        print(why, file=sys.stderr)
        return 2
    report = check_site(a.site, screenshots=a.screenshots, prefix=a.prefix)
    for line in report.problems:
        print(line)
    if report.screenshots:
        print(f"screenshots: {len(report.screenshots)} in {a.screenshots}")
    print(f"{a.site}: {report.summary()}")
    return 1 if report.problems else 0


if __name__ == "__main__":
    sys.exit(main())
