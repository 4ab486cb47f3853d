"""``--view``: both performances, the map and each joint's cost, in a browser page (issue 33).

One page (``view.html``, beside this module: canvas drawing, no library, nothing fetched
from elsewhere) shows, for each performer, the live skeleton and the recorded one played by
the map (side by side or overlaid), the lag in ms, the map so far and the eq. 1 term of every
cost joint for the current frame. It works two ways:

* **a recorded take** (``fpdtw align|live ... --view FILE.html``, notebooks 10 and 20, the
  book): :func:`take_payload` computes every frame once and :func:`export_html` writes the
  page with the data inside it: one file that opens offline, with a time slider;
  :func:`embed` shows it in a notebook cell;
* **live** (``fpdtw serve ... --view [HOST:PORT]``): a :class:`Viewer` serves the page over
  HTTP in ``serve``'s own asyncio loop. A session hands each answer to its :class:`Slot`,
  which only keeps a reference to the latest frame (no copy, no drawing data, no I/O on the
  aligner's path); the page asks for a frame only after it has drawn the previous one, at
  most 30 times a second, and the positions are computed then, for the frames shown. A page
  that is slow or closed costs the aligner nothing.

Positions are shown in each skeleton's body axes (:func:`fpdtw.motion.rig.world_axes`: left,
up, facing), in body heights (the extent along up of its first frame), feet on the ground
and the root on the vertical axis, so figures of any world, unit or size stand side by side.

Nothing in ``fpdtw`` imports this module; ``fpdtw[view]`` declares the feature (it needs no
package beyond fpdtw's own).
"""

from __future__ import annotations

import array
import asyncio
import contextlib
import json
import urllib.parse
from pathlib import Path

import numpy as np

from fpdtw import plain
from fpdtw.motion.joints import PAPER_JOINTS
from fpdtw.motion.kinematics import frame_positions
from fpdtw.motion.rig import cost_input
from fpdtw.motion.rotations import euler_to_quat
from fpdtw.paper.atomic import write_atomic

#: The page.
PAGE = Path(__file__).with_name("view.html")
_DATA = '<script type="application/json" id="fpdtw-view-data">null</script>'
#: Where ``--view`` serves without an address.
DEFAULT_VIEW = "127.0.0.1:7448"
#: Seconds a page's request for a frame waits for one before the answer "nothing new" (204).
WAIT_S = 0.5
#: Bytes of a request's head; performers (slots) kept; map points sent in one answer.
MAX_REQUEST, MAX_SLOTS, MAX_MAP_SENT = 8192, 16, 20000


def joint_costs(Q_a, Q_b) -> np.ndarray:
    """Each joint's term of eq. 1, ``(2/pi) arccos |Q_j^a . Q_j^b|``, in [0, 1].

    Parameters
    ----------
    Q_a, Q_b : ndarray of float, shape (..., k, 4)

    Returns
    -------
    ndarray of float64, shape (..., k)
        Summed over the last axis: :func:`fpdtw.plain.geo_distance`.

    Paper: FP-DTW eq. 1.
    Notebook: 10_fig8_walk_pair.ipynb
    """
    return plain.geo_distance(np.asarray(Q_a)[..., None, :], np.asarray(Q_b)[..., None, :])


class Figure:
    """How the page draws one skeleton: joint names, parents, and the map of its world
    positions into body axes (``axes`` (3, 3), rows left, up, facing) and body heights, from
    its first frame's positions ``first`` (J, 3)."""

    def __init__(self, names, parents, axes, first):
        self.names, self.parents = [str(n) for n in names], [int(p) for p in parents]
        self.axes = np.eye(3) if axes is None else np.asarray(axes, dtype=float)
        up = np.asarray(first, dtype=float) @ self.axes[1]
        self.ground, self.height = float(up.min()), float(np.ptp(up)) or 1.0

    @classmethod
    def of(cls, skeleton, rig, first) -> Figure:
        """A skeleton's figure, in the body axes of its ``rig`` (None: the world's)."""
        return cls(skeleton.joint_names, skeleton.parents, rig and rig.axes, first)

    def hello(self) -> dict:
        return {"names": self.names, "parents": self.parents}

    def view(self, P) -> np.ndarray:
        """World positions (..., J, 3) as the page draws them (rounded to 1e-4 heights)."""
        V = np.asarray(P, dtype=float) @ self.axes.T
        V[..., 1] -= self.ground
        V[..., 0] -= V[..., :1, 0]
        V[..., 2] -= V[..., :1, 2]
        return np.round(V / self.height, 4)


def _cost_names(k: int) -> list:
    return list(PAPER_JOINTS) if k == len(PAPER_JOINTS) else [f"joint {j}" for j in range(k)]


def take_payload(I, T, M, FI, FT, *, title: str = "", name: str = "take") -> dict:
    """The page's data for a recorded pair: every target frame with the input frame the map
    gives it.

    Parameters
    ----------
    I, T : Motion
        The recorded input and the target (the "live" side).
    M : array_like of int, shape (T.n_frames,)
        Input frame of each target frame (``fpdtw align``'s map).
    FI, FT : MotionFeatures
        Their features (the cost joints and rigs eq. 1 compares).
    title, name : str
        The page's title; the performer's name.

    Returns
    -------
    dict
        JSON-ready: ``mode`` "take", ``title``, ``performers`` (one) and ``frames``.

    Notebook: 10_fig8_walk_pair.ipynb, 20_align_a_live_performance.ipynb
    """
    M = np.asarray(M, dtype=np.int64)
    if M.shape != (T.n_frames,) or M.min() < 0 or M.max() >= I.n_frames:
        raise ValueError(f"a map of {T.n_frames} input frames in [0, {I.n_frames}) expected, "
                         f"got shape {M.shape}")  # fmt: skip
    PI, PT = I.forward_kinematics()[0], T.forward_kinematics()[0]
    fi, ft = Figure.of(I.skeleton, FI.rig, PI[0]), Figure.of(T.skeleton, FT.rig, PT[0])
    cost = joint_costs(FT.quats[: M.size], cost_input(FI.quats, FI.rig, FT.rig)[M])
    lag = (np.arange(M.size) / T.fps - M / I.fps) * 1e3
    performer = dict(key="0", name=name, fps=T.fps, live=ft.hello(), rec=fi.hello(),
                     cost_joints=_cost_names(cost.shape[1]), n_rec=I.n_frames,
                     n_live=M.size)  # fmt: skip
    frames = dict(live=ft.view(PT).tolist(), rec=fi.view(PI[M]).tolist(), m=M.tolist(),
                  lag_ms=np.round(lag, 1).tolist(), cost=np.round(cost, 3).tolist())  # fmt: skip
    return {"mode": "take", "title": title, "performers": [performer], "frames": {"0": frames}}


def render(payload=None) -> str:
    """The page, with ``payload`` inside it (None: a live page, which asks its server)."""
    page = PAGE.read_text(encoding="utf-8")
    data = json.dumps(payload, separators=(",", ":"), allow_nan=False).replace("</", "<\\/")
    return page.replace(_DATA, _DATA.replace(">null<", f">{data}<"), 1)


def export_html(payload, path) -> Path:
    """Write :func:`render` of ``payload`` to ``path`` (whole or not at all); return it
    (``--view FILE.html``)."""
    return write_atomic(path, render(payload).encode("utf-8"))


def embed(payload, height: int = 860):
    """The page of ``payload`` in a notebook cell: an ``<iframe srcdoc>`` (no server, no file).

    Notebook: 10_fig8_walk_pair.ipynb, 20_align_a_live_performance.ipynb
    """
    from html import escape

    from IPython.display import HTML

    page = escape(render(payload), quote=True)  # a <div> first: IPython warns of bare iframes
    return HTML(f'<div class="fpdtw-view"><iframe srcdoc="{page}" width="100%" '
                f'height="{int(height)}" style="border:0"></iframe></div>')  # fmt: skip


class Slot:
    """One performer's latest answer, as its session hands it over (:meth:`put`)."""

    def __init__(self, viewer, key, name, session):
        self.viewer, self.key, self.name, self.session = viewer, str(key), str(name), session
        self.seq, self.latest, self.figure, self._orders = -1, None, None, None
        self.map = array.array("q")  # index, m, index, m, ...

    def put(self, row, index, m, latency, frame) -> None:
        """The session's answer: kept by reference (the page computes what it draws)."""
        self.latest = (row, index, m, latency, frame)
        self.map.append(index)
        self.map.append(m)
        self.seq += 1

    def _positions(self, row) -> np.ndarray:
        s = self.session
        euler, trans = s.header.split(np.asarray(row, dtype=float)[None])
        sk = s.target.skeleton
        if self._orders is None:  # the joints of each rotation order
            orders = np.array(sk.rotation_orders)
            self._orders = [(o, np.flatnonzero(orders == o)) for o in sorted(set(orders))]
        q = np.empty((sk.n_joints, 4))
        for o, idx in self._orders:
            q[idx] = euler_to_quat(euler[0, idx], o)
        return frame_positions(sk, q, trans[0], root_relative=False)

    def hello(self) -> dict | None:
        if self.latest is None:
            return None
        if self.figure is None:
            target = self.session.target
            self.figure = Figure.of(target.skeleton, target.rig,
                                    self._positions(self.session._first))  # fmt: skip
        v = self.viewer
        k = self.latest[4].quats.shape[0]
        return dict(key=self.key, name=self.name, fps=v.FI.fps, live=self.figure.hello(),
                    rec=v.rec.hello(), cost_joints=_cost_names(k), n_rec=len(v.rec_P),
                    n_live=None)  # fmt: skip

    def frame(self, have: int) -> dict:
        """The latest frame as the page draws it, and the map's points from ``have`` on."""
        row, index, m, latency, frame = self.latest
        v = self.viewer
        Iq = cost_input(v.FI.quats[m : m + 1], v.FI.rig, frame.rig)[0]
        n = len(self.map) // 2
        have = min(max(have, n - MAX_MAP_SENT), n)
        pts = np.frombuffer(self.map, dtype=np.int64)[2 * have : 2 * n].reshape(-1, 2)
        return dict(key=self.key, seq=self.seq, n=int(index), m=int(m),
                    lag_ms=round((index - m) / v.FI.fps * 1e3, 1),
                    latency_us=round(latency * 1e6), have=have,
                    live=self.figure.view(self._positions(row)).tolist(),
                    rec=v.rec_P[m].tolist(),
                    cost=np.round(joint_costs(frame.quats, Iq), 3).tolist(),
                    map=pts.tolist())  # fmt: skip


class Viewer:
    """``fpdtw serve --view``: the page and its data over HTTP, in the server's loop.

    Parameters
    ----------
    I : Motion
        The recorded input.
    FI : MotionFeatures
        Its features (the cost joints and rig of eq. 1).
    host, port : str, int
        Where to listen (port 0: any free one).
    title : str
    """

    def __init__(self, I, FI, host: str, port: int, *, title: str = ""):
        P = I.forward_kinematics()[0]
        self.rec = Figure.of(I.skeleton, FI.rig, P[0])
        self.rec_P = self.rec.view(P)
        self.FI, self.host, self.port, self.title = FI, host, int(port), title
        self.slots = {}
        self._server = None
        self.page = render(None).encode("utf-8")

    def slot(self, key, name, session):
        """A performer's slot (the oldest dropped beyond :data:`MAX_SLOTS`); its ``put``."""
        s = Slot(self, key, name, session)
        self.slots.pop(s.key, None)
        self.slots[s.key] = s
        while len(self.slots) > MAX_SLOTS:
            self.slots.pop(next(iter(self.slots)))
        return s.put

    async def start(self, out) -> tuple:
        """Listen; print ``view at http://HOST:PORT/`` to ``out``; return (host, port)."""
        self._server = await asyncio.start_server(
            self._client, self.host, self.port, limit=MAX_REQUEST
        )
        host, port = self._server.sockets[0].getsockname()[:2]
        shown = f"[{host}]" if ":" in host else host
        print(f"view at http://{shown}:{port}/", file=out, flush=True)
        return host, port

    async def stop(self) -> None:
        if self._server is not None:
            self._server.close()
            with contextlib.suppress(Exception):
                await asyncio.wait_for(self._server.wait_closed(), 1.0)

    def hello(self) -> dict:
        found = [h for s in self.slots.values() if (h := s.hello()) is not None]
        return {"mode": "live", "title": self.title, "performers": found}

    async def _frame(self, query: dict):
        s = self.slots.get(query.get("key", [""])[0])
        if s is None:
            return None
        try:
            since, have = (int(query.get(k, ["-1"])[0]) for k in ("since", "have"))
        except ValueError:
            return None
        loop = asyncio.get_running_loop()
        end = loop.time() + WAIT_S
        while s.latest is None or s.seq <= since:
            if loop.time() >= end:
                return None
            await asyncio.sleep(1 / 60)
        s.hello()
        return s.frame(have)

    async def _client(self, reader, writer) -> None:
        """One browser connection (keep-alive): GET ``/``, ``/hello``, ``/frame?...``."""
        try:
            while True:
                try:
                    head = await asyncio.wait_for(reader.readuntil(b"\r\n\r\n"), 60.0)
                except asyncio.LimitOverrunError:
                    return await self._send(writer, 431, b"request head over 8 KiB")
                except (asyncio.IncompleteReadError, TimeoutError):
                    return
                method, target, *_ = head.split(b"\r\n", 1)[0].decode("latin-1").split(" ") + [""]
                url = urllib.parse.urlsplit(target)
                path = url.path.rsplit("/", 1)[-1]
                if method != "GET":
                    await self._send(writer, 405, b"GET only")
                elif path in ("", "index.html"):
                    await self._send(writer, 200, self.page, "text/html; charset=utf-8")
                elif path == "hello":
                    await self._send(writer, 200, json.dumps(self.hello()).encode())
                elif path == "frame":
                    got = await self._frame(urllib.parse.parse_qs(url.query))
                    if got is None:
                        await self._send(writer, 204, b"")
                    else:
                        await self._send(writer, 200, json.dumps(got).encode())
                else:
                    await self._send(writer, 404, b"not found")
        except (ConnectionError, OSError):
            pass
        except Exception as e:  # a bug of ours: this page's answer, never the server
            with contextlib.suppress(Exception):
                await self._send(writer, 500, f"{type(e).__name__}: {e}".encode())
        finally:
            writer.close()

    @staticmethod
    async def _send(writer, status: int, body: bytes, kind="application/json") -> None:
        reason = {200: "OK", 204: "No Content", 404: "Not Found", 405: "Method Not Allowed",
                  431: "Request Header Fields Too Large",
                  500: "Internal Server Error"}[status]  # fmt: skip
        head = (f"HTTP/1.1 {status} {reason}\r\nContent-Type: {kind}\r\nContent-Length: "
                f"{len(body)}\r\nCache-Control: no-store\r\n\r\n")  # fmt: skip
        writer.write(head.encode("latin-1") + body)
        await writer.drain()
