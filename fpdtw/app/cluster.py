"""The experiment grid's tasks on a Dask cluster: the optional ``[cluster]`` part.

:class:`fpdtw.paper.runner.parallel.Executor` runs the grid with joblib on this machine; given
a scheduler address (``fpdtw experiments run --scheduler tcp://host:port`` or
``FPDTW_SCHEDULER``), :func:`fpdtw.paper.runner.parallel.make_executor` checks it with
:func:`scheduler_address` and runs the grid on a :class:`DaskExecutor`, which needs
``pip install fpdtw[cluster]`` (dask and distributed).
What a task computes and the files it writes do not depend on where it ran
(``tests/test_cluster.py`` runs a real local cluster).
"""

from __future__ import annotations

import re
import sys
import time
import uuid
from pathlib import Path

from distributed import Client, KilledWorker, as_completed
from tqdm import tqdm

from fpdtw.errors import ClusterError

#: Protocols of a scheduler address.
SCHEMES = ("tcp", "tls")
_HOST = re.compile(r"^(\[[0-9A-Fa-f:.%a-zA-Z]+\]|[A-Za-z0-9]([A-Za-z0-9._-]*[A-Za-z0-9])?)$")


def scheduler_address(text) -> str:
    """A Dask scheduler address in full (``tcp://host:port``).

    ``text``: ``tcp://host:port``, ``tls://host:port`` or ``host:port`` (TCP), IPv6 hosts in
    brackets (``tcp://[::1]:8786``); "no cluster" (None, ``""``, ``"local"``) is the caller's
    (:func:`fpdtw.paper.runner.parallel.scheduler_address`). A malformed address raises
    ClusterError naming what is wrong.
    """
    s = str(text).strip()
    where = f"scheduler address {str(text)!r}"
    example = "e.g. tcp://10.0.0.5:8786 (8786 is the port `dask scheduler` listens on by default)"
    scheme, sep, rest = s.partition("://")
    if not sep:
        scheme, rest = "tcp", s
    if scheme not in SCHEMES:
        raise ClusterError(
            f"{where}: unknown protocol {scheme!r}; use tcp://host:port or tls://host:port"
        )
    if not rest or any(c in rest for c in "/?#@ "):
        raise ClusterError(f"{where}: expected {scheme}://host:port and nothing else, {example}")
    if rest.startswith("["):  # an IPv6 host
        host, _, after = rest.partition("]")
        host += "]"
        if not after.startswith(":"):
            raise ClusterError(f"{where}: no port, expected {scheme}://[host]:port, {example}")
        port = after[1:]
    elif rest.count(":") > 1:
        raise ClusterError(f"{where}: IPv6 hosts go in brackets, e.g. {scheme}://[::1]:8786")
    else:
        host, colon, port = rest.partition(":")
        if not colon:
            raise ClusterError(f"{where}: no port, expected {scheme}://host:port, {example}")
    if not host:
        raise ClusterError(f"{where}: no host, expected {scheme}://host:port, {example}")
    if not _HOST.match(host):
        raise ClusterError(f"{where}: {host!r} is not a host name or IP address")
    if not port.isdigit() or not 1 <= int(port) <= 65535:
        raise ClusterError(f"{where}: the port {port!r} is not a number from 1 to 65535")
    return f"{scheme}://{host}:{int(port)}"


#: Seconds to wait for files that cluster workers wrote to appear here (network filesystems).
VISIBLE_TIMEOUT = 60.0


class DaskExecutor:
    """Runs a function over tasks on the workers of a Dask cluster: the interface of
    :class:`fpdtw.paper.runner.parallel.Executor`.

    ``scheduler``: a checked address (:func:`scheduler_address`) or a connected
    ``distributed.Client`` (the caller closes it); ``say`` prints what it does. It connects
    when first there is something to compute (:meth:`client`); :meth:`close` (or a ``with``
    block) closes the connection it opened.

    Paper: none (how the grid of FP-DTW Section 5 is spread over machines).
    Notebook: none (tests/test_cluster.py runs it on a real local Dask cluster)
    """

    kind = "dask"

    def __init__(self, scheduler, *, connect_timeout: float = 20.0, say=None):
        self.connect_timeout = float(connect_timeout)
        self._say = say or (lambda *a, **k: None)
        self._own = False
        self._cluster: dict = {}
        if isinstance(scheduler, str):
            self._client, self.address = None, scheduler
        else:
            self._client = scheduler
            self.address = str(getattr(scheduler.scheduler, "address", "") or "client")

    def __enter__(self) -> DaskExecutor:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def describe(self) -> dict:
        """``{"backend": "dask", "scheduler", "workers", "threads"}`` (the last two once
        connected), for ``run.json``."""
        return {"backend": "dask", "scheduler": self.address, **self._cluster}

    @property
    def slots(self) -> int:
        """The cluster's threads (0 before connecting)."""
        return int(self._cluster.get("threads", 0))

    def client(self):
        """The :class:`distributed.Client`, connecting first if needed (ClusterError: the
        scheduler does not answer within ``connect_timeout`` seconds)."""
        if self._client is None:
            try:
                self._client = Client(
                    self.address, timeout=self.connect_timeout, set_as_default=False
                )
            except (OSError, TimeoutError) as e:
                raise ClusterError(
                    f"cannot reach the Dask scheduler at {self.address} within "
                    f"{self.connect_timeout:g} s ({e}); start one there with "
                    f"`dask scheduler` and workers with `dask worker {self.address}`, or run "
                    "without --scheduler and FPDTW_SCHEDULER to use this machine's cores"
                ) from None
            self._own = True
        if not self._cluster:
            workers = self._client.scheduler_info(n_workers=-1).get("workers", {})
            threads = sum(int(w.get("nthreads", 0)) for w in workers.values())
            self._cluster = {"workers": len(workers), "threads": threads}
            if workers:
                say = f"Dask scheduler {self.address}: {len(workers)} workers, {threads} threads"
                self._say(say)
            else:
                self._say(
                    f"Dask scheduler {self.address} has no workers yet: the tasks wait for "
                    f"`dask worker {self.address}` (Ctrl-C to stop)"
                )
        return self._client

    def map(self, fn, tasks, *, desc: str, progress=True, keys=None):
        """Yield ``fn(*task)`` for every task as the cluster's workers finish them
        (:meth:`fpdtw.paper.runner.parallel.Executor.map`). ClusterError: the scheduler cannot
        be reached, lost a task's workers too often or cancelled a task."""
        if not tasks:
            return
        client = self.client()
        n = len(tasks)
        token = uuid.uuid4().hex[:8]
        if keys is None:
            keys = [f"{fn.__name__}-{i}" for i in range(n)]
        if len(set(keys)) != n:
            raise ValueError("keys must name every task once")
        keys = [f"{k}-{token}" for k in keys]
        futures = [
            client.submit(fn, *t, key=k, priority=n - i, retries=0)
            for i, (t, k) in enumerate(zip(tasks, keys))
        ]
        kw = dict(disable=not progress, file=sys.stderr, mininterval=1.0, smoothing=0.05)
        bar = tqdm(total=n, desc=desc, **kw)
        done = 0
        try:
            for fut in as_completed(futures, loop=client.loop):
                try:
                    result = fut.result()
                except KilledWorker as e:
                    raise ClusterError(
                        f"task {fut.key} of the scheduler at {self.address}: its workers died "
                        f"too often ({e}); see the workers' logs (memory limit? killed?)"
                    ) from None
                except Exception as e:
                    if fut.status != "cancelled":
                        raise
                    raise ClusterError(
                        f"the scheduler at {self.address} cancelled task {fut.key} "
                        f"(connection lost?): {e}"
                    ) from None
                fut.release()
                done += 1
                bar.update(1)
                yield result
        finally:
            bar.close()
            if done < n:  # stopped early: the cluster need not finish the rest
                try:
                    client.cancel([f for f in futures if not f.done()])
                except Exception:  # the connection is gone already
                    pass

    def settle(self, paths: list, ready, what: str, folder) -> None:
        """Wait until ``ready(path)`` holds for every path the workers wrote (ClusterError
        after :data:`VISIBLE_TIMEOUT` seconds: a folder this process does not see)."""
        deadline = time.monotonic() + VISIBLE_TIMEOUT
        missing = [p for p in paths if not ready(p)]
        while missing and time.monotonic() < deadline:
            time.sleep(min(1.0, max(0.0, deadline - time.monotonic())))
            missing = [p for p in missing if not ready(p)]
        if missing:
            raise ClusterError(
                f"{folder}: {len(missing)} {what} the cluster's workers wrote are not here "
                f"after {VISIBLE_TIMEOUT:g} s (e.g. {Path(missing[0]).name}): the results folder "
                "must be on a filesystem this machine and every worker share, at the same path "
                "(--results)"
            )

    def close(self) -> None:
        """Close the connection this executor opened (a client given to it stays open)."""
        if self._own and self._client is not None:
            try:
                self._client.close(timeout=10)
            except Exception:  # closing a connection the cluster already dropped
                pass
            self._client = None
        self._own = False


__all__ = ["DaskExecutor", "scheduler_address"]
