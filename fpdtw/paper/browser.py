"""Check the book in a real browser: headless Chromium, driven over the DevTools protocol.

:func:`check_site` serves a built site (``build/book``, ``build/smoke/book``) from a
loopback HTTP server (127.0.0.1, a free port, this process only), opens its front page in
headless Chromium and follows every link inside the site. On every page it records the
console errors (uncaught exceptions, ``console.error``, resources that failed to load:
the DevTools ``Runtime`` and ``Log`` events), the images that did not load (natural width
0) and the element ids; then every link inside the site is checked (the file is served;
a ``#fragment`` names an element of that page), and a screenshot of the front page is
written for a person to look at.

The browser is Debian's ``chromium`` package (``apt-get install chromium``; ``.ci/run``
installs it), found on ``PATH`` or given by ``FPDTW_CHROMIUM``; nothing is downloaded (no
driver, no browser build). The protocol goes over a WebSocket to 127.0.0.1 with
``websocket-client``. Every wait has a time limit; the browser and the server are stopped
however the check ends.

Run ``python -m fpdtw.paper.browser build/book [--screenshots DIR]`` (``make book-check``).
"""

from __future__ import annotations

import argparse
import base64
import contextlib
import functools
import http.server
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time
import urllib.error
import urllib.parse
import urllib.request
from collections import deque
from dataclasses import dataclass, field
from pathlib import Path

#: Names tried on ``PATH`` (Debian's package installs ``/usr/bin/chromium``).
CHROMIUM_NAMES = ("chromium", "chromium-browser")
#: The Debian packages that provide it.
APT_PACKAGES = "chromium"
#: Seconds allowed for the browser to start, and for one page to load.
START_TIMEOUT = 60.0
PAGE_TIMEOUT = 30.0
#: The window (CSS pixels) of the screenshots.
WINDOW = (1280, 1000)

# every <img> eager, waited for (decode() settles when the image has loaded or failed), then
# reported; every <a href> resolved against the page; every element id; the rows of the
# book's claims table (first cell, first verdict, links of the last cell)
_PAGE_FACTS_JS = """
(async () => {
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
})()
"""


def find_chromium() -> str | None:
    """The Chromium executable: ``FPDTW_CHROMIUM`` if set, else the first on ``PATH``."""
    env = os.environ.get("FPDTW_CHROMIUM")
    if env:
        return env if Path(env).is_file() else shutil.which(env)
    for name in CHROMIUM_NAMES:
        path = shutil.which(name)
        if path:
            return path
    return None


class BrowserError(RuntimeError):
    """The browser did not start, did not answer in time, or reported a protocol error."""


def _remove_tree(path: Path, tries: int = 40, pause: float = 0.25) -> None:
    """Remove a folder a process that just ended may still be writing into: retry while
    files keep appearing (about 10 s), then raise the last error."""
    for attempt in range(tries):
        try:
            shutil.rmtree(path)
            return
        except FileNotFoundError:
            return
        except OSError:
            if attempt == tries - 1:
                raise
            time.sleep(pause)


class Chromium:
    """Headless Chromium with one page, driven over the DevTools protocol.

    Use as a context manager: the browser runs in a fresh profile folder on
    ``--remote-debugging-port=0`` bound to 127.0.0.1 (the port it picked is read from the
    profile's ``DevToolsActivePort``); leaving the block ends the browser and removes the
    profile.

    Parameters
    ----------
    executable : str, optional
        Default :func:`find_chromium`.
    window : tuple of int
        Width and height of the page's viewport (CSS pixels).
    """

    def __init__(self, executable: str | None = None, window=WINDOW):
        self.executable = executable or find_chromium()
        if self.executable is None:
            raise BrowserError(
                f"no Chromium found: install Debian's {APT_PACKAGES} package "
                f"(apt-get install {APT_PACKAGES}) or set FPDTW_CHROMIUM"
            )
        self.window = window
        self._proc = None
        self._ws = None
        self._profile = None
        self._next_id = 0
        self._events = deque()

    # -- life cycle ------------------------------------------------------------------------

    def __enter__(self) -> Chromium:
        import websocket

        self._profile = tempfile.TemporaryDirectory(prefix="fpdtw-chromium-")
        profile = Path(self._profile.name)
        args = [
            self.executable,
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
            f"--window-size={self.window[0]},{self.window[1]}",
            "--remote-debugging-address=127.0.0.1",
            "--remote-debugging-port=0",
            f"--user-data-dir={profile}",
            "about:blank",
        ]
        if hasattr(os, "geteuid") and os.geteuid() == 0:
            args.insert(1, "--no-sandbox")  # Chromium refuses its sandbox to root
        self._proc = subprocess.Popen(
            args,
            stdin=subprocess.DEVNULL,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.PIPE,
            start_new_session=True,
        )
        try:
            port = self._wait_for_port(profile / "DevToolsActivePort")
            target = self._page_target(port)
            self._ws = websocket.create_connection(
                target, timeout=PAGE_TIMEOUT, suppress_origin=True
            )
            for method in ("Page.enable", "Runtime.enable", "Log.enable"):
                self.send(method)
            self.send("Page.setLifecycleEventsEnabled", enabled=True)
            self.send(
                "Emulation.setDeviceMetricsOverride",
                width=self.window[0],
                height=self.window[1],
                deviceScaleFactor=1,
                mobile=False,
            )
        except BaseException:
            self.__exit__(None, None, None)
            raise
        return self

    def __exit__(self, *exc) -> None:
        if self._ws is not None:
            with contextlib.suppress(Exception):
                self._ws.close()
            self._ws = None
        if self._proc is not None:
            if self._proc.poll() is None:
                self._proc.terminate()
                try:
                    self._proc.wait(timeout=10)
                except subprocess.TimeoutExpired:
                    self._proc.kill()
                    self._proc.wait(timeout=10)
            # Chromium's helpers (renderer, crashpad, ...) share its session and may
            # outlive it, still writing into the profile: end the whole process group
            if hasattr(os, "killpg"):
                with contextlib.suppress(OSError):
                    os.killpg(self._proc.pid, signal.SIGKILL)
            if self._proc.stderr is not None:
                self._proc.stderr.close()
            self._proc = None
        if self._profile is not None:
            _remove_tree(Path(self._profile.name))
            self._profile.cleanup()  # already gone: only marks the folder as removed
            self._profile = None

    def _wait_for_port(self, path: Path) -> int:
        deadline = time.monotonic() + START_TIMEOUT
        while time.monotonic() < deadline:
            if self._proc.poll() is not None:
                err = self._proc.stderr.read().decode(errors="replace")[-2000:]
                raise BrowserError(f"{self.executable} exited at start:\n{err}")
            if path.is_file():
                first = path.read_text().split("\n", 1)[0].strip()
                if first.isdigit():
                    return int(first)
            time.sleep(0.05)
        raise BrowserError(f"{self.executable} did not open its DevTools port in {START_TIMEOUT} s")

    def _page_target(self, port: int) -> str:
        url = f"http://127.0.0.1:{port}/json/list"
        deadline = time.monotonic() + START_TIMEOUT
        while time.monotonic() < deadline:
            with contextlib.suppress(OSError, ValueError):
                with urllib.request.urlopen(url, timeout=5) as r:
                    for t in json.load(r):
                        if t.get("type") == "page" and t.get("webSocketDebuggerUrl"):
                            return t["webSocketDebuggerUrl"]
            time.sleep(0.1)
        raise BrowserError(f"no page target at {url} in {START_TIMEOUT} s")

    # -- the protocol ------------------------------------------------------------------------

    def send(self, method: str, timeout: float = PAGE_TIMEOUT, **params) -> dict:
        """Call a DevTools method and return its result (events meanwhile are queued)."""
        self._next_id += 1
        msg_id = self._next_id
        self._ws.send(json.dumps({"id": msg_id, "method": method, "params": params}))
        deadline = time.monotonic() + timeout
        while True:
            msg = self._recv(deadline, f"the answer to {method}")
            if msg.get("id") == msg_id:
                if "error" in msg:
                    raise BrowserError(f"{method}: {msg['error']}")
                return msg.get("result", {})
            if "method" in msg:
                self._events.append(msg)

    def _recv(self, deadline: float, what: str) -> dict:
        import websocket

        left = deadline - time.monotonic()
        if left <= 0:
            raise BrowserError(f"timed out waiting for {what}")
        self._ws.settimeout(left)
        try:
            return json.loads(self._ws.recv())
        except websocket.WebSocketTimeoutException:
            raise BrowserError(f"timed out waiting for {what}") from None

    def wait_for(self, predicate, timeout: float = PAGE_TIMEOUT, what: str = "an event") -> dict:
        """Wait for the first event (queued or new) with ``predicate(event)`` true."""
        deadline = time.monotonic() + timeout
        while True:
            for ev in list(self._events):
                if predicate(ev):
                    self._events.remove(ev)
                    return ev
            msg = self._recv(deadline, what)
            if "method" in msg:
                self._events.append(msg)

    def drain(self) -> list:
        """The queued events (removed from the queue), after reading what has arrived."""
        import websocket

        self._ws.settimeout(0.05)
        with contextlib.suppress(websocket.WebSocketTimeoutException):
            while True:
                msg = json.loads(self._ws.recv())
                if "method" in msg:
                    self._events.append(msg)
        out = list(self._events)
        self._events.clear()
        return out

    # -- pages --------------------------------------------------------------------------------

    def open(self, url: str, timeout: float = PAGE_TIMEOUT) -> None:
        """Load a page and wait until its load event and its network are quiet."""
        self.drain()
        result = self.send("Page.navigate", url=url)
        if result.get("errorText"):
            raise BrowserError(f"{url}: {result['errorText']}")
        frame = result.get("frameId")
        self.wait_for(lambda e: e["method"] == "Page.loadEventFired", timeout, f"{url} to load")
        with contextlib.suppress(BrowserError):  # quiet network: best effort, 5 s at most
            self.wait_for(
                lambda e: (
                    e["method"] == "Page.lifecycleEvent"
                    and e["params"].get("name") == "networkIdle"
                    and e["params"].get("frameId") == frame
                ),
                min(timeout, 5.0),
                "network idle",
            )

    def evaluate(self, expression: str, timeout: float = PAGE_TIMEOUT):
        """The value of a JavaScript expression in the page (promises are awaited)."""
        r = self.send(
            "Runtime.evaluate",
            timeout=timeout,
            expression=expression,
            awaitPromise=True,
            returnByValue=True,
        )
        if "exceptionDetails" in r:
            raise BrowserError(f"script failed: {r['exceptionDetails'].get('text')}")
        return r["result"].get("value")

    def screenshot(self, path, full_page: bool = False) -> Path:
        """Write a PNG of the viewport (or of the whole page) to ``path``."""
        params = {"format": "png"}
        if full_page:
            size = self.send("Page.getLayoutMetrics")["cssContentSize"]
            params["clip"] = {
                "x": 0, "y": 0, "width": size["width"], "height": size["height"], "scale": 1,
            }  # fmt: skip
            params["captureBeyondViewport"] = True
        data = self.send("Page.captureScreenshot", **params)["data"]
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(base64.b64decode(data))
        return path


def console_errors(events: list) -> list[str]:
    """The errors among DevTools events, one line each.

    Uncaught exceptions (``Runtime.exceptionThrown``), ``console.error`` and
    ``console.assert`` (``Runtime.consoleAPICalled``), and browser log entries of level
    error (``Log.entryAdded``: resources that failed to load, blocked content, ...).
    """
    out = []
    for ev in events:
        method, p = ev.get("method"), ev.get("params", {})
        if method == "Runtime.exceptionThrown":
            d = p.get("exceptionDetails", {})
            text = d.get("exception", {}).get("description") or d.get("text", "")
            out.append(f"exception: {text} ({d.get('url', '')}:{d.get('lineNumber', '')})")
        elif method == "Runtime.consoleAPICalled" and p.get("type") in ("error", "assert"):
            args = [str(a.get("value", a.get("description", ""))) for a in p.get("args", [])]
            out.append(f"console.{p['type']}: {' '.join(args)}")
        elif method == "Log.entryAdded" and p.get("entry", {}).get("level") == "error":
            e = p["entry"]
            out.append(f"{e.get('source', 'log')}: {e.get('text', '')} {e.get('url', '')}".strip())
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
    """

    path: str
    title: str = ""
    errors: list = field(default_factory=list)
    images: int = 0
    broken_images: list = field(default_factory=list)
    ids: set = field(default_factory=set)
    claims: list = field(default_factory=list)


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
            f"{len(self.problems)} problems, {self.seconds:.1f} s"
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
    try:
        with urllib.request.urlopen(url, timeout=PAGE_TIMEOUT) as r:
            return None if r.status == 200 else f"HTTP {r.status}"
    except urllib.error.HTTPError as e:
        return f"HTTP {e.code}"
    except OSError as e:
        return str(e)


def check_site(
    root,
    start: str = "index.html",
    screenshots=None,
    shot_name: str = "front.png",
    max_pages: int = 500,
    executable: str | None = None,
) -> SiteReport:
    """Open a static site in headless Chromium, follow its links, report what is wrong.

    Parameters
    ----------
    root : str or Path
        The site's folder (``build/book``).
    start : str
        The front page, relative to ``root``.
    screenshots : str or Path, optional
        Where to write the screenshot of the front page (none if None).
    shot_name : str
        Its file name; a second file ``<stem>-full.png`` holds the whole page.
    max_pages : int
        Stop following links after this many pages.
    executable : str, optional
        The browser (default :func:`find_chromium`).

    Returns
    -------
    SiteReport
        Its ``problems`` are empty when every page loaded without a console error, every
        image loaded and every link inside the site resolves.

    Raises
    ------
    BrowserError
        No browser, or it did not start or answer in time.
    """
    t0 = time.perf_counter()
    root = Path(root)
    report = SiteReport()
    links = {}  # (path, fragment) -> first page linking to it
    on_disk = sorted(
        p.relative_to(root).as_posix()
        for p in root.rglob("*.html")
        if not p.relative_to(root).parts[0].startswith("_")
    )
    with serve(root) as base, Chromium(executable) as browser:
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
            try:
                browser.open(base + urllib.parse.quote(path))
                facts = browser.evaluate(_PAGE_FACTS_JS)
            except BrowserError as e:
                page.errors.append(str(e))
                continue
            if path == start and screenshots is not None:
                shots = Path(screenshots)
                report.screenshots.append(browser.screenshot(shots / shot_name))
                full = shots / (Path(shot_name).stem + "-full.png")
                report.screenshots.append(browser.screenshot(full, full_page=True))
            page.errors = console_errors(browser.drain())
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
    """``python -m fpdtw.paper.browser SITE [--screenshots DIR] [--name FILE]``: exit 1 on
    any problem, 2 without a browser."""
    ap = argparse.ArgumentParser(
        prog="python -m fpdtw.paper.browser", description=__doc__.split("\n")[0]
    )
    ap.add_argument("site", type=Path, help="the built site (e.g. build/book)")
    ap.add_argument("--screenshots", type=Path, help="folder for the front page's screenshot")
    ap.add_argument("--name", default="front.png", help="its file name (default front.png)")
    a = ap.parse_args(argv)
    if find_chromium() is None:
        print(
            f"no Chromium found: apt-get install {APT_PACKAGES} (or set FPDTW_CHROMIUM)",
            file=sys.stderr,
        )
        return 2
    report = check_site(a.site, screenshots=a.screenshots, shot_name=a.name)
    for line in report.problems:
        print(line)
    for p in report.screenshots:
        print(f"screenshot: {p}")
    print(f"{a.site}: {report.summary()}")
    return 1 if report.problems else 0


if __name__ == "__main__":
    sys.exit(main())
