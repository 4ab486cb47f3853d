"""The viewer (``--view``, fpdtw.app.view): its numbers, its page and its HTTP endpoint.

The browser itself is tested in tests/test_view_browser.py."""

from __future__ import annotations

import asyncio
import json
import re
import subprocess
import sys
import time

import numpy as np
import pytest

from fpdtw import plain
from fpdtw.app import cli
from fpdtw.app.serve import Server
from fpdtw.app.sources import Performers
from fpdtw.app.view import (
    MAX_REQUEST,
    Figure,
    Viewer,
    export_html,
    joint_costs,
    render,
    take_payload,
)
from fpdtw.io import load_motion
from fpdtw.io.bvh import bvh_lines
from fpdtw.motion.features import MotionFeatures
from fpdtw.registry import align, resolve


def test_joint_costs_hand_checked_and_summing_to_eq_1():
    """The same rotation costs 0, a half turn 1, a quarter turn 1/2; the terms sum to
    plain.geo_distance."""
    q = np.array([[1.0, 0, 0, 0], [1.0, 0, 0, 0], [1.0, 0, 0, 0]])
    r = np.array([[1.0, 0, 0, 0], [0.0, 1, 0, 0], [np.sqrt(0.5), 0, np.sqrt(0.5), 0]])
    np.testing.assert_allclose(joint_costs(q, r), [0.0, 1.0, 0.5], atol=1e-12)
    rng = np.random.default_rng(3)
    A, B = rng.normal(size=(2, 5, 8, 4))
    A /= np.linalg.norm(A, axis=-1, keepdims=True)
    B /= np.linalg.norm(B, axis=-1, keepdims=True)
    np.testing.assert_allclose(joint_costs(A, B).sum(-1), plain.geo_distance(A, B), atol=1e-12)


def test_a_figure_stands_on_the_ground_in_body_heights():
    """Z-up positions in cm: after the view, Y is up, the feet at 0, the head at 1 (the
    first frame's height), the root on the vertical axis in every frame."""
    first = np.array([[10.0, 5, 100], [10, 5, 180], [10, 5, 0]])  # root, head, foot
    zup = np.array([[1.0, 0, 0], [0, 0, 1], [0, -1, 0]])  # rows left, up, facing
    f = Figure(["root", "head", "foot"], [-1, 0, 0], zup, first)
    V = f.view(np.stack([first, first + [50.0, 20, 0]]))
    np.testing.assert_allclose(V[0], [[0, 100 / 180, 0], [0, 1, 0], [0, 0, 0]], atol=1e-4)
    np.testing.assert_allclose(V[1, :, [0, 2]], 0.0, atol=1e-12)  # the root moved: centred


@pytest.fixture(scope="module")
def pair(cmu_retimed):
    """CMU 18_01 (input) and its take retimed by t^1.3 (target), their features and
    fpdtw align's map (Mc w40)."""
    path, FI, (warp, _) = cmu_retimed
    I, T = load_motion(path), load_motion(warp)
    FT = MotionFeatures.from_motion(T)
    M, _ = align("Mc w40", FI, FT)
    return I, T, FI, FT, np.asarray(M, dtype=np.int64)


def test_a_take_payload_plays_the_input_by_the_map(pair):
    I, T, FI, FT, M = pair
    d = take_payload(I, T, M, FI, FT, title="t")
    p, f = d["performers"][0], d["frames"]["0"]
    assert (p["n_live"], p["n_rec"], len(p["cost_joints"])) == (T.n_frames, I.n_frames, 8)
    assert len(f["live"]) == len(f["rec"]) == len(f["m"]) == T.n_frames
    fi = Figure.of(I.skeleton, FI.rig, I.forward_kinematics()[0][0])
    n = 300
    np.testing.assert_array_equal(f["rec"][n], fi.view(I.forward_kinematics()[0][M[n]]))
    assert f["lag_ms"][n] == pytest.approx(round((n / T.fps - M[n] / I.fps) * 1e3, 1))
    # the input against itself by the identity map: no cost, no lag, the same figure
    same = take_payload(I, I, np.arange(I.n_frames), FI, FI)["frames"]["0"]
    assert np.max(same["cost"]) == 0 and np.max(np.abs(same["lag_ms"])) == 0
    np.testing.assert_array_equal(same["live"], same["rec"])
    with pytest.raises(ValueError, match="a map of"):
        take_payload(I, T, M[:-1], FI, FT)


def test_the_exported_page_is_one_offline_file(pair, tmp_path):
    """No address outside the file; a name holding ``</script>`` cannot end the data."""
    I, T, FI, FT, M = pair
    d = take_payload(I, T, M, FI, FT, title="</script><script>alert(1)</script>")
    out = export_html(d, tmp_path / "view.html")
    page = out.read_text(encoding="utf-8")
    assert not re.findall(r"(?:https?:)?//[a-z0-9]", page.replace("http://www.w3.org", ""))
    data = re.search(r'id="fpdtw-view-data">(.*?)</script>', page, re.S).group(1)
    assert json.loads(data)["title"] == d["title"]
    assert render(None).count('id="fpdtw-view-data">null</script>') == 1
    assert list(tmp_path.iterdir()) == [out]  # nothing half-written beside it


def test_align_and_live_write_the_page(pair, cmu_retimed, tmp_path, capsys):
    path, _, (warp, _) = cmu_retimed
    for cmd in ("align", "live"):
        out = tmp_path / f"{cmd}.html"
        extra = ["--out", str(tmp_path / f"{cmd}.csv")] + (["--fast"] if cmd == "live" else [])
        assert cli.main([cmd, str(path), str(warp), "-m", "c", "-w", "40", *extra,
                         "--view", str(out)]) == 0  # fmt: skip
        data = re.search(r'id="fpdtw-view-data">(.*?)</script>', out.read_text(), re.S).group(1)
        np.testing.assert_array_equal(json.loads(data)["frames"]["0"]["m"], pair[4])
    assert cli.main(["align", str(path), str(warp), "-m", "a", "--out", str(tmp_path / "m.csv"),
                     "--view", str(tmp_path / "no" / "v.html")]) == 1  # fmt: skip
    assert "no folder" in capsys.readouterr().err


async def _get(reader, writer, path: str, method="GET"):
    writer.write(f"{method} {path} HTTP/1.1\r\nHost: x\r\n\r\n".encode())
    await writer.drain()
    head = (await reader.readuntil(b"\r\n\r\n")).decode()
    status = int(head.split()[1])
    size = int(re.search(r"Content-Length: (\d+)", head).group(1))
    return status, await reader.readexactly(size)


def test_a_live_take_is_served_as_the_offline_pair(pair):
    """A session streamed the take over the live path (its BVH lines) hands its answers to
    the viewer; over HTTP on loopback, the latest frame is the take payload's frame of the
    same index: the same input frame, positions found by the other forward kinematics, the
    same costs; the map is sent from where the page has it."""
    I, T, FI, FT, M = pair
    ref = take_payload(I, T, M, FI, FT)["frames"]["0"]
    viewer = Viewer(I, FI, "127.0.0.1", 0)
    server = Server(FI, resolve("Mc w40").make, view=viewer)

    async def run():
        await viewer.start(open("/dev/null", "w"))
        port = viewer._server.sockets[0].getsockname()[1]
        reader, writer = await asyncio.open_connection("127.0.0.1", port)
        status, body = await _get(reader, writer, "/hello")
        assert (status, json.loads(body)["performers"]) == (200, [])
        assert (await _get(reader, writer, "/frame?key=1&since=-1&have=0"))[0] == 204
        session = server._session()
        session.watch = viewer.slot(1, "127.0.0.1:5000", session)
        header, lines = bvh_lines(T)
        for line in header:
            session.feed(f"{line}\n".encode(), 0.0)
        for k, line in enumerate(lines):
            session.feed(f"{line}\n".encode(), time.perf_counter(), when=k / T.fps)
        status, body = await _get(reader, writer, "/hello")
        (p,) = json.loads(body)["performers"]
        assert (p["key"], p["name"], p["n_rec"]) == ("1", "127.0.0.1:5000", I.n_frames)
        status, body = await _get(reader, writer, "/frame?key=1&since=-1&have=600")
        f = json.loads(body)
        n = T.n_frames - 1
        assert (status, f["n"], f["m"], f["seq"]) == (200, n, M[n], n)
        np.testing.assert_allclose(f["live"], ref["live"][n], atol=2e-4)
        np.testing.assert_array_equal(f["rec"], ref["rec"][n])
        np.testing.assert_allclose(f["cost"], ref["cost"][n], atol=2e-3)
        assert f["map"] == [[k, int(M[k])] for k in range(600, T.n_frames)]
        assert (await _get(reader, writer, f"/frame?key=1&since={n}&have=0"))[0] == 204
        # what a page should not send: each answered, the server goes on
        for path, method, code in (("/nowhere", "GET", 404), ("/hello", "POST", 405),
                                   ("/frame?key=1&since=x", "GET", 204)):  # fmt: skip
            assert (await _get(reader, writer, path, method))[0] == code
        writer.write(b"GET /" + b"a" * (MAX_REQUEST + 10) + b" HTTP/1.1\r\n\r\n")
        head = await reader.read(200)
        assert head.startswith(b"HTTP/1.1 431"), head
        writer.close()
        r2, w2 = await asyncio.open_connection("127.0.0.1", port)
        w2.write(b"\x00\xff garbage\r\n\r\n")
        await w2.drain()
        w2.close()
        r3, w3 = await asyncio.open_connection("127.0.0.1", port)
        status, page = await _get(r3, w3, "/")
        assert status == 200 and b'id="fpdtw-view-data">null<' in page
        w3.close()
        await viewer.stop()

    asyncio.run(run())


def test_the_aligners_never_import_the_viewer():
    code = ("import sys, fpdtw, fpdtw.app.serve, fpdtw.app.sources, fpdtw.app.cli; "
            "print('fpdtw.app.view' in sys.modules)")  # fmt: skip
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


def test_a_capture_sources_performers_are_watched_per_take(pair):
    """Through Performers (every --source): each performer of each take has its own slot
    (take 2's performer 0 is not take 1's), fed the channel values the source read."""
    I, T, FI, FT, M = pair
    ref = take_payload(I, T, M, FI, FT)["frames"]["0"]
    viewer = Viewer(I, FI, "127.0.0.1", 0)
    header, lines = bvh_lines(T)
    rows = [np.array(line.split(), dtype=float) for line in lines]
    for take in (1, 2):
        perf = Performers(FI, resolve("Mc w40").make, take=take, view=viewer, log=lambda m: None)
        p = perf.add(0, "actor", header, T.fps, "test")
        for row in rows[: 100 * take]:
            perf.feed(p, row, time.perf_counter())
    assert list(viewer.slots) == ["1.0", "2.0"]
    assert [s.seq for s in viewer.slots.values()] == [99, 199]
    f = asyncio.run(viewer._frame({"key": ["2.0"], "since": ["-1"], "have": ["0"]}))
    assert (f["n"], f["m"], len(f["map"])) == (199, M[199], 200)
    np.testing.assert_allclose(f["live"], ref["live"][199], atol=2e-4)
