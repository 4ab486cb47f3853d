"""Where the grid's work runs: joblib on this machine's cores, or the workers of a Dask cluster
(through the tools' optional part :mod:`fpdtw.app.cluster`, imported only then). What a task
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
    """Runs a function over tasks with joblib on this machine or on a Dask cluster.

    ``n_jobs``: joblib processes (1: this process). ``scheduler``: a Dask scheduler address
    (:func:`scheduler_address`) or a connected ``distributed.Client`` (the caller closes it);
    None or ``"local"``: joblib. ``say`` prints what it does. It connects when first there is
    something to compute; :meth:`close` (or a ``with`` block) closes.
    """

    def __init__(
        self, n_jobs: int = 2, scheduler=None, *, connect_timeout: float = CONNECT_TIMEOUT, say=None
    ):
        self.n_jobs = int(n_jobs)
        self.connect_timeout = float(connect_timeout)
        self._say = say or (lambda *a, **k: None)
        self._client = None
        self._own = False
        self._cluster: dict = {}
        if scheduler is None or isinstance(scheduler, str):
            self.address = scheduler_address(scheduler)
        elif hasattr(scheduler, "submit") and hasattr(scheduler, "scheduler_info"):
            self._client = scheduler
            self.address = str(getattr(scheduler.scheduler, "address", "") or "client")
        else:
            raise TypeError(
                f"scheduler must be an address string or a distributed.Client, got {scheduler!r}"
            )

    @staticmethod
    def progress_bar(total: int, desc: str, progress: bool):
        """The progress bar of a map (stderr; a no-op bar when ``progress`` is False)."""
        kw = dict(disable=not progress, file=sys.stderr, mininterval=1.0, smoothing=0.05)
        return tqdm(total=total, desc=desc, **kw)

    @property
    def kind(self) -> str:
        """``"dask"`` or ``"joblib"``."""
        return "joblib" if self.address is None else "dask"

    def __enter__(self) -> Executor:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def close(self) -> None:
        """Close the connection this executor opened (a client given to it stays open)."""
        if self._own:
            _cluster().close(self)

    def describe(self) -> dict:
        """What ran the tasks, for ``run.json``: ``{"backend": "joblib", "n_jobs"}`` or
        ``{"backend": "dask", "scheduler", "workers", "threads"}`` (the last two once connected)."""
        if self.kind == "joblib":
            return {"backend": "joblib", "n_jobs": self.n_jobs}
        return {"backend": "dask", "scheduler": self.address, **self._cluster}

    @property
    def slots(self) -> int:
        """Tasks that run at once: n_jobs, or the cluster's threads when connected."""
        if self.kind == "joblib":
            return self.n_jobs
        return int(self._cluster.get("threads", 0))

    def client(self):
        """The :class:`distributed.Client` (connecting first if needed): see
        :func:`fpdtw.app.cluster.connect`."""
        if self.kind != "dask":
            raise RuntimeError("a joblib executor has no Dask client")
        return _cluster().connect(self)

    def map(
        self, fn: Callable, tasks: Sequence[tuple], *, desc: str, progress=True, keys=None
    ) -> Iterator:
        """Yield ``fn(*task)`` (``fn`` module-level) for every task, in the order they finish.

        ``tasks``: the arguments of each call, most expensive first; ``keys`` name the Dask
        tasks. ClusterError: the scheduler cannot be reached, lost a task's workers too often
        or cancelled a task; ``fn``'s own errors are raised as they are.
        """
        if not tasks:
            return
        if self.kind == "dask":
            yield from _cluster().map_on_cluster(self, fn, tasks, desc, progress, keys)
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
