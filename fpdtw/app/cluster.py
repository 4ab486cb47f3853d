"""The experiment grid's tasks on a Dask cluster: the optional ``[cluster]`` part.

:class:`fpdtw.paper.runner.parallel.Executor` runs the grid with joblib on this machine; given
a scheduler address (``fpdtw experiments run --scheduler tcp://host:port`` or
``FPDTW_SCHEDULER``) it hands its tasks to :func:`map_on_cluster` here, which needs
``pip install fpdtw[cluster]`` (dask and distributed). What a task computes and the files it
writes do not depend on where it ran (``tests/test_cluster.py`` runs a real local cluster).
"""

from __future__ import annotations

import uuid

from distributed import Client, KilledWorker, as_completed

from fpdtw.errors import ClusterError


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


__all__ = ["connect", "map_on_cluster"]
