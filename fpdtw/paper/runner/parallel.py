"""Where the grid's work runs: joblib on this machine's cores, or the workers of a Dask cluster
(the tools' optional part :mod:`fpdtw.app.cluster`, imported only then). What a task
computes and writes does not depend on where it ran; what the workers need: ``docs/cluster.md``.
"""

from __future__ import annotations

import os
import sys
from collections.abc import Callable, Iterator, Sequence

from joblib import Parallel, delayed
from tqdm import tqdm

from fpdtw.errors import ClusterError

#: Environment variable naming the Dask scheduler (``tcp://host:port``) of a run.
SCHEDULER_ENV = "FPDTW_SCHEDULER"
#: The scheduler value that means "joblib on this machine" (overrides ``FPDTW_SCHEDULER``).
LOCAL = "local"
#: Seconds to wait for the scheduler to answer.
CONNECT_TIMEOUT = 20.0


def _cluster():
    """The optional ``[cluster]`` part (:mod:`fpdtw.app.cluster`), imported only when a run
    is given a scheduler: the reproduction runs without dask installed."""
    try:
        import fpdtw.app.cluster as cluster
    except ImportError as e:
        raise ClusterError(
            f"running on a Dask cluster needs dask and distributed ({e}): "
            "pip install 'fpdtw[cluster]', or run without --scheduler and "
            f"{SCHEDULER_ENV} to use this machine's cores"
        ) from None
    return cluster


def scheduler_address(text) -> str | None:
    """A Dask scheduler address in full (``tcp://host:port``), or None for no cluster (None,
    ``""``, ``"local"``); other text: :func:`fpdtw.app.cluster.scheduler_address` checks it."""
    if text is None or str(text).strip() in ("", LOCAL):
        return None
    return _cluster().scheduler_address(text)


def scheduler_from_env() -> str | None:
    """The scheduler named by ``FPDTW_SCHEDULER`` (checked), or None when it is unset."""
    value = os.environ.get(SCHEDULER_ENV, "")
    try:
        return scheduler_address(value)
    except ClusterError as e:
        raise ClusterError(f"{SCHEDULER_ENV}: {e}") from None


class Executor:
    """Runs a function over tasks with ``n_jobs`` joblib processes on this machine (1: this
    process). When a run names a scheduler, :func:`make_executor` gives a Dask cluster's
    (:class:`fpdtw.app.cluster.DaskExecutor`) instead. A ``with`` block closes it."""

    kind = "joblib"

    def __init__(self, n_jobs: int = 2):
        self.n_jobs = int(n_jobs)

    @staticmethod
    def progress_bar(total: int, desc: str, progress: bool):
        """The progress bar of a map (stderr; a no-op bar when ``progress`` is False)."""
        kw = dict(disable=not progress, file=sys.stderr, mininterval=1.0, smoothing=0.05)
        return tqdm(total=total, desc=desc, **kw)

    def __enter__(self) -> Executor:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def close(self) -> None:
        """Nothing to close on this machine."""

    def describe(self) -> dict:
        """What ran the tasks, for ``run.json``: ``{"backend": "joblib", "n_jobs"}``."""
        return {"backend": "joblib", "n_jobs": self.n_jobs}

    @property
    def slots(self) -> int:
        """Tasks that run at once."""
        return self.n_jobs

    def map(
        self, fn: Callable, tasks: Sequence[tuple], *, desc: str, progress=True, keys=None
    ) -> Iterator:
        """Yield ``fn(*task)`` (``fn`` module-level) for every task, in the order they finish.

        ``tasks``: the arguments of each call, most expensive first; ``keys`` name the tasks
        on a cluster. ``fn``'s own errors are raised as they are.
        """
        if not tasks:
            return
        gen = Parallel(n_jobs=self.n_jobs, return_as="generator_unordered", batch_size=1)(
            delayed(fn)(*t) for t in tasks
        )
        bar = self.progress_bar(len(tasks), desc, progress)
        try:
            for r in gen:
                bar.update(1)
                yield r
        finally:
            bar.close()

    def settle(self, paths: list, ready: Callable, what: str, folder) -> None:
        """Wait until the files the tasks wrote are here: on this machine they are."""


def make_executor(
    n_jobs: int = 2, scheduler=None, *, connect_timeout: float = CONNECT_TIMEOUT, say=None
) -> Executor:
    """The executor of a run: joblib with ``n_jobs`` processes, or the cluster of
    ``scheduler``: a Dask scheduler address (:func:`scheduler_address`) or a connected
    ``distributed.Client`` (the caller closes it); None or ``"local"``: joblib. ``say``
    prints what a cluster executor does; it connects when first there is something to compute.
    """
    if scheduler is None or isinstance(scheduler, str):
        address = scheduler_address(scheduler)
        if address is None:
            return Executor(n_jobs)
        return _cluster().DaskExecutor(address, connect_timeout=connect_timeout, say=say)
    if hasattr(scheduler, "submit") and hasattr(scheduler, "scheduler_info"):
        return _cluster().DaskExecutor(scheduler, connect_timeout=connect_timeout, say=say)
    raise TypeError(
        f"scheduler must be an address string or a distributed.Client, got {scheduler!r}"
    )
