"""The viewer as a person uses it: headless Chromium, driven by Selenium, opens the page of
``fpdtw serve REC --view`` while ``fpdtw stream TAKE`` plays a take to the server in real
time, and the page a recorded pair exports (``--view FILE.html``) from disk.

The screenshots are kept in build/view/ (the README's picture is one of them)."""

from __future__ import annotations

import io
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from fpdtw.app import browser
from fpdtw.app.view import export_html, take_payload
from fpdtw.io import load_motion
from fpdtw.motion.features import MotionFeatures
from fpdtw.registry import align

SHOTS = Path(__file__).resolve().parents[1] / "build" / "view"
STATS = "return window.fpdtwView && window.fpdtwView.ready ? window.fpdtwView.stats() : null"


@pytest.fixture(scope="module")
def chromium():
    why = browser.missing_browser()
    if why:
        if os.environ.get("CI", "").strip().lower() in {"1", "true", "yes"}:
            pytest.fail(f"viewer browser tests: {why} (CI=true: this fails instead of skipping)")
        pytest.skip(f"viewer browser tests: {why}")


def _wait(b, script, timeout=20.0):
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        got = b.execute_script(script)
        if got:
            return got
        time.sleep(0.1)
    raise AssertionError(f"the page never answered {script!r}")


def _pixels(b, name):
    from PIL import Image

    SHOTS.mkdir(parents=True, exist_ok=True)
    png = b.get_screenshot_as_png()
    (SHOTS / name).write_bytes(png)
    return np.asarray(Image.open(io.BytesIO(png)).convert("RGB"), dtype=np.int16)


def _both_visible(stats):
    """Both skeletons drawn with every bone, each a figure (taller than wide, some size),
    live to the left of recorded (side by side)."""
    (p,) = stats["performers"]
    for side in ("live", "rec"):
        x0, y0, x1, y1 = p[side]["bbox"]
        assert p[side]["segments"] >= 20 and y1 - y0 > 100 and x1 - x0 > 10, (side, p)
    assert p["live"]["bbox"][2] < p["rec"]["bbox"][0], p


def _no_errors(b):
    errors = browser.console_errors(b.get_log("browser"))
    assert not errors, errors


WALKS = "mocap_single_person_actions/MoCapData/Walk_0{}.fbx"  # Fig. 8's pair, 120 Hz


def test_a_streamed_take_moves_both_skeletons(chromium, data_path):
    """``fpdtw serve Walk_01 --view`` and ``fpdtw stream Walk_02`` in real time (5.3 s):
    both figures drawn, moving, the lag readout changing; no console error. Its second
    screenshot is the README's picture (docs/view.png)."""
    path, warp = data_path(WALKS.format(1)), data_path(WALKS.format(2))
    serve = subprocess.Popen(
        [sys.executable, "-m", "fpdtw.app.cli", "serve", str(path), "-m", "c", "-w", "40",
         "--listen", "127.0.0.1:0", "--view", "127.0.0.1:0"],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )  # fmt: skip
    stream = None
    try:
        view = serve.stdout.readline().split()[-1]
        listen = serve.stdout.readline().split()[-1]
        assert view.startswith("http://127.0.0.1:") and listen.startswith("127.0.0.1:"), view
        with browser.chromium() as b:
            b.get(view)
            assert b.execute_script("return document.querySelector('#status').textContent")
            stream = subprocess.Popen(
                [sys.executable, "-m", "fpdtw.app.cli", "stream", str(warp), "--to", listen],
                stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
            )  # fmt: skip
            _wait(b, STATS)
            time.sleep(0.5)
            first, a = b.execute_script(STATS), _pixels(b, "live-1.png")
            time.sleep(1.0)
            second, c = b.execute_script(STATS), _pixels(b, "live-2.png")
            for s in (first, second):
                _both_visible(s)
            p, q = first["performers"][0], second["performers"][0]
            assert q["n"] > p["n"] + 60, (p, q)  # a second of a 120 Hz take went by
            assert (np.abs(a - c).sum(-1) > 30).sum() > 500  # the figures moved
            lags = {p["lag"], q["lag"]}
            while stream.poll() is None and len(lags) < 2:  # the lag readout changes
                lags.add(b.execute_script(STATS)["performers"][0]["lag"])
                time.sleep(0.1)
            assert len(lags) >= 2, lags
            assert stream.wait(60) == 0, stream.stderr.read()
            _no_errors(b)
    finally:
        for proc in (stream, serve):
            if proc is not None and proc.poll() is None:
                proc.terminate()
                proc.wait(30)
        serve.stdout.close()
        serve.stderr.close()


def test_the_exported_page_plays_offline(chromium, cmu_retimed, tmp_path):
    path, FI, (warp, _) = cmu_retimed
    I, T = load_motion(path), load_motion(warp)
    FT = MotionFeatures.from_motion(T)
    M, _ = align("Mc w40", FI, FT)
    title = "CMU 18_01 and its take retimed by t^1.3, Mc w40"
    page = export_html(take_payload(I, T, M, FI, FT, title=title), tmp_path / "view.html")
    with browser.chromium() as b:
        b.get(page.as_uri())
        _wait(b, STATS)
        shown = "return window.fpdtwView.stats().performers[0].n === {} && window.fpdtwView.stats()"
        b.execute_script("window.fpdtwView.seek(40)")
        first = _wait(b, shown.format(40))  # drawn at the next animation frame
        a = _pixels(b, "take-40.png")
        b.execute_script("window.fpdtwView.seek(200)")
        second = _wait(b, shown.format(200))
        c = _pixels(b, "take-200.png")
        p, q = first["performers"][0], second["performers"][0]
        assert (p["n"], q["n"], p["m"], q["m"]) == (40, 200, int(M[40]), int(M[200]))
        _both_visible(first)
        _both_visible(second)
        assert (np.abs(a - c).sum(-1) > 30).sum() > 500
        assert b.execute_script("return document.querySelector('#slider').max") == str(
            T.n_frames - 1
        )
        _no_errors(b)
        facts = json.dumps(b.execute_script("return performance.getEntriesByType('resource')"))
        assert "http" not in facts  # nothing fetched
