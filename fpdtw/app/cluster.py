"""The experiment grid's tasks on a Dask cluster: the optional ``[cluster]`` part.

:class:`fpdtw.paper.runner.parallel.Executor` runs the grid with joblib on this machine; given
a scheduler address (``fpdtw experiments run --scheduler tcp://host:port`` or
``FPDTW_SCHEDULER``) it checks it with :func:`scheduler_address`, connects with
:func:`connect`, hands its tasks to :func:`map_on_cluster` and disconnects with
:func:`close`, all here, which needs ``pip install fpdtw[cluster]`` (dask and distributed).
What a task computes and the files it writes do not depend on where it ran
(``tests/test_cluster.py`` runs a real local cluster).
"""

from __future__ import annotations

import re
import uuid

from distributed import Client, KilledWorker, as_completed

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


def connect(ex):
    """The executor's :class:`distributed.Client`, connecting first if needed.

    Parameters
    ----------
    ex : fpdtw.paper.runner.parallel.Executor
        An executor with a scheduler address (``ex.kind == "dask"``).

    Returns
    -------
    client : distributed.Client

    Raises
    ------
    ClusterError
        The scheduler does not answer within ``ex.connect_timeout`` seconds.

    Paper: none (how the grid of FP-DTW Section 5 is spread over machines).
    Notebook: none (tests/test_cluster.py runs it on a real local Dask cluster)
    """
    if ex._client is None:
        try:
            ex._client = Client(ex.address, timeout=ex.connect_timeout, set_as_default=False)
        except (OSError, TimeoutError) as e:
            raise ClusterError(
                f"cannot reach the Dask scheduler at {ex.address} within "
                f"{ex.connect_timeout:g} s ({e}); start one there with "
                f"`dask scheduler` and workers with `dask worker {ex.address}`, or run "
                "without --scheduler and FPDTW_SCHEDULER to use this machine's cores"
            ) from None
        ex._own = True
    if not ex._cluster:
        workers = ex._client.scheduler_info(n_workers=-1).get("workers", {})
        threads = sum(int(w.get("nthreads", 0)) for w in workers.values())
        ex._cluster = {"workers": len(workers), "threads": threads}
        if workers:
            ex._say(f"Dask scheduler {ex.address}: {len(workers)} workers, {threads} threads")
        else:
            ex._say(
                f"Dask scheduler {ex.address} has no workers yet: the tasks wait for "
                f"`dask worker {ex.address}` (Ctrl-C to stop)"
            )
    return ex._client


def map_on_cluster(ex, fn, tasks, desc, progress, keys):
    """Yield ``fn(*task)`` for every task as the cluster's workers finish them.

    Parameters are those of :meth:`fpdtw.paper.runner.parallel.Executor.map`.

    Raises
    ------
    ClusterError
        The scheduler lost a task's workers too often or cancelled a task.

    Paper: none (how the grid of FP-DTW Section 5 is spread over machines).
    Notebook: none (tests/test_cluster.py runs it on a real local Dask cluster)
    """
    client = connect(ex)
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
    bar = ex.progress_bar(n, desc, progress)
    done = 0
    try:
        for fut in as_completed(futures, loop=client.loop):
            try:
                result = fut.result()
            except KilledWorker as e:
                raise ClusterError(
                    f"task {fut.key} of the scheduler at {ex.address}: its workers died "
                    f"too often ({e}); see the workers' logs (memory limit? killed?)"
                ) from None
            except Exception as e:
                if fut.status != "cancelled":
                    raise
                raise ClusterError(
                    f"the scheduler at {ex.address} cancelled task {fut.key} "
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


def close(ex) -> None:
    """Close the connection the executor ``ex`` opened (:func:`connect`)."""
    if ex._client is not None:
        try:
            ex._client.close(timeout=10)
        except Exception:  # closing a connection the cluster already dropped
            pass
    ex._client = None
    ex._own = False


__all__ = ["close", "connect", "map_on_cluster", "scheduler_address"]
