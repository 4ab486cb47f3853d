"""The experiment grid on a Dask cluster (fpdtw.paper.runner.parallel): the same bytes as joblib.

The smoke grid (54 pairs) with :data:`ALGORITHMS` (one algorithm of each kind: offline,
Methods A, B and C, Type V, 60 Hz, Method C's literal window, OE-DTW, OLTW, OPW: the
scheduling and the bytes do not depend on how many algorithms a unit holds, and ``make test``
stays short) runs once with joblib (2 processes), then on
real clusters on the loopback address only: a ``distributed.LocalCluster`` (2 worker
processes, 1 thread each) and a ``dask scheduler`` with two ``dask worker`` processes,
started as subprocesses with random ports and always stopped by the fixture. Checked:
every ``algorithms/*.npz``, ``pairs.json`` and ``summary.json`` byte for byte equal to the
joblib run's; one chunk file per work unit, each delivered once; a worker killed in the
middle of a run loses no chunk and duplicates none; a run whose client process is killed
resumes from the chunks already written; and the errors of a malformed or unreachable
scheduler address (one line, the right exit code). Each cluster run takes about as long
as the joblib run (tens of seconds on 2 cores).
"""

from __future__ import annotations

import contextlib
import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from fpdtw.app import cluster as C
from fpdtw.paper.runner import parallel as P
from fpdtw.paper.runner import run as E
from fpdtw.paper.runner.results import load_npz

N_UNITS = 54  # the smoke selection: 54 motions, each the input of one unit (one pair)
#: The algorithms of every run here (a subset of the smoke grid's DEFAULT_ALGORITHMS).
ALGORITHMS = (
    "DTW", "UTW", "Ma + Type V", "Mb w40", "Mc w40", "Mc w80@60Hz", "Mc w40 (literal window)",
    "OE-DTW", "OLTW", "OPW",
)  # fmt: skip
N_ALGORITHMS = len(ALGORITHMS)
SMOKE_PAIRS = 54
START_TIMEOUT = 90  # seconds for a scheduler or a worker to come up
RUN_TIMEOUT = 600  # seconds for one smoke run through the command line


# -- helpers -----------------------------------------------------------------------------------


def result_bytes(folder: Path) -> dict:
    """Bytes of every deterministic result file of a run folder."""
    out = {f"algorithms/{p.name}": p.read_bytes() for p in (folder / "algorithms").glob("*.npz")}
    for name in ("pairs.json", "summary.json"):
        out[name] = (folder / name).read_bytes()
    return out


def assert_same_results(folder: Path, reference: Path) -> None:
    got, want = result_bytes(folder), result_bytes(reference)
    assert len(want) == N_ALGORITHMS + 2
    assert sorted(got) == sorted(want)
    differ = [name for name in want if got[name] != want[name]]
    assert not differ, f"not byte-identical to the joblib run: {differ}"


def assert_clean_chunks(folder: Path) -> None:
    """One chunk per unit, each named after the unit it holds, every algorithm, no leftovers."""
    run = json.loads((folder / "run.json").read_text())
    chunks = sorted((folder / "chunks").glob("*.npz"))
    assert len(chunks) == N_UNITS
    ids = []
    for c in chunks:
        meta = json.loads(bytes(load_npz(c, ["__meta__"])["__meta__"]).decode())
        assert meta["unit"] == c.stem and meta["base_key"] == run["base_key"]
        assert len(meta["algorithms"]) == N_ALGORITHMS
        ids += meta["pair_ids"]
    assert sorted(ids) == list(range(SMOKE_PAIRS))  # every pair in exactly one chunk
    assert not list(folder.rglob("*.part")), "temporary files left behind"


def seed_features(reference: Path, folder: Path) -> None:
    """Give a run the feature files of the reference run (the same names: the same bytes);
    the local cluster test builds them on the cluster's workers, the others need not."""
    shutil.copytree(reference / "features", folder / "features")


def computed(folder: Path) -> dict:
    return json.loads((folder / "run.json").read_text())["computed"]


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def wait_for(predicate, timeout: float, what: str, poll: float = 0.1):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        value = predicate()
        if value:
            return value
        time.sleep(poll)
    pytest.fail(f"timed out after {timeout} s waiting for {what}")


def n_chunks(folder: Path) -> int:
    return len(list((folder / "chunks").glob("*.npz")))


def stop(proc: subprocess.Popen) -> None:
    """Stop a process started in its own session, and its children; wait for it."""
    if proc.poll() is None:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(proc.pid, signal.SIGTERM)
        try:
            proc.wait(timeout=15)
        except subprocess.TimeoutExpired:
            with contextlib.suppress(ProcessLookupError):
                os.killpg(proc.pid, signal.SIGKILL)
            proc.wait(timeout=15)
    with contextlib.suppress(ProcessLookupError):  # a nanny's worker left behind
        os.killpg(proc.pid, signal.SIGKILL)


class CLICluster:
    """``dask scheduler`` and ``dask worker`` subprocesses on 127.0.0.1 (random ports)."""

    def __init__(self, folder: Path):
        self.folder = folder
        self.procs: list = []
        self.workers: dict = {}  # name -> Popen
        self.address = None

    def _start(self, name: str, module: str, *args) -> subprocess.Popen:
        log = open(self.folder / f"{name}.log", "wb")  # noqa: SIM115 (closed with the process)
        proc = subprocess.Popen(
            [sys.executable, "-m", module, *args],
            stdout=log,
            stderr=subprocess.STDOUT,
            stdin=subprocess.DEVNULL,
            cwd=self.folder,
            start_new_session=True,  # its own process group: the nanny and its worker
        )
        log.close()
        self.procs.append(proc)
        return proc

    def start(self, n_workers: int = 2) -> CLICluster:
        sched_file = self.folder / "scheduler.json"
        self._start(
            "scheduler",
            "distributed.cli.dask_scheduler",
            "--host",
            "127.0.0.1",
            "--port",
            "0",
            "--no-dashboard",
            "--scheduler-file",
            str(sched_file),
        )

        def address():
            try:
                return json.loads(sched_file.read_text())["address"]
            except (OSError, ValueError, KeyError):
                return None

        self.address = wait_for(address, START_TIMEOUT, "the dask scheduler")
        assert self.address.startswith("tcp://127.0.0.1:")
        for i in range(n_workers):
            self.add_worker(f"w{i}")
        self.wait_for_workers(n_workers)
        return self

    def add_worker(self, name: str) -> None:
        self.workers[name] = self._start(
            name,
            "distributed.cli.dask_worker",
            self.address,
            "--host",
            "127.0.0.1",
            "--name",
            name,
            "--nthreads",
            "1",
            "--no-dashboard",
            "--local-directory",
            str(self.folder / f"{name}-space"),
        )

    def wait_for_workers(self, n: int) -> None:
        from distributed import Client

        with Client(self.address, timeout=30, set_as_default=False) as c:
            c.wait_for_workers(n, timeout=START_TIMEOUT)

    def kill_worker(self, name: str) -> None:
        """SIGKILL the worker and its nanny: the machine is gone."""
        os.killpg(self.workers[name].pid, signal.SIGKILL)
        self.workers[name].wait(timeout=15)

    def stop(self) -> None:
        for proc in reversed(self.procs):
            stop(proc)


@pytest.fixture
def cli_cluster(tmp_path):
    cluster = CLICluster(tmp_path)
    try:
        yield cluster.start(2)
    finally:
        cluster.stop()


@pytest.fixture(scope="module")
def root(tmp_path_factory):
    return tmp_path_factory.mktemp("grid")


@pytest.fixture(scope="module")
def joblib_run(root):
    """The smoke grid with joblib, 2 processes: the reference."""
    E.run_experiments(
        "smoke", n_jobs=2, progress=False, results=root / "joblib", algorithms=ALGORITHMS
    )
    folder = root / "joblib" / "smoke"
    assert computed(folder)["units"] == N_UNITS
    return folder


@pytest.fixture
def delivered(monkeypatch):
    """Every result a run's executor yields, in this process (unit id, worker)."""
    got = []

    def spy(real):
        def map_(self, fn, tasks, **kw):
            for r in real(self, fn, tasks, **kw):
                if isinstance(r, dict) and "unit" in r:
                    got.append((r["unit"], r["worker"]))
                yield r

        return map_

    for cls in (P.Executor, C.DaskExecutor):
        monkeypatch.setattr(cls, "map", spy(cls.map))
    return got


# -- cluster runs ------------------------------------------------------------------------------


def test_local_cluster_gives_the_joblib_bytes(joblib_run, root, delivered):
    from distributed import Client, LocalCluster

    with (
        LocalCluster(
            n_workers=2,
            threads_per_worker=1,
            processes=True,
            host="127.0.0.1",
            dashboard_address=None,
        ) as cluster,
        Client(cluster, set_as_default=False) as client,
    ):
        E.run_experiments(
            "smoke", progress=False, results=root / "local", scheduler=client,
            algorithms=ALGORITHMS,
        )  # fmt: skip
        pids = {str(pid) for pid in client.run(os.getpid).values()}
    folder = root / "local" / "smoke"
    assert_same_results(folder, joblib_run)
    assert_clean_chunks(folder)
    run = json.loads((folder / "run.json").read_text())
    assert run["backend"]["backend"] == "dask" and run["backend"]["workers"] == 2
    assert run["computed"]["units"] == N_UNITS == sum(run["computed"]["workers"].values())
    assert {w.split(":")[-1] for w in run["computed"]["workers"]} <= pids
    assert sorted(u for u, _ in delivered) == sorted(p.stem for p in (folder / "chunks").glob("*"))


def test_killed_worker_loses_and_duplicates_no_chunk(joblib_run, root, cli_cluster, delivered):
    """dask scheduler + 2 dask workers; one worker (and its nanny) SIGKILLed mid-run."""
    from distributed import Client

    folder = root / "killed_worker" / "smoke"
    seed_features(joblib_run, folder)  # the units are what this test kills, not the features
    killed = {}

    with Client(cli_cluster.address, timeout=30, set_as_default=False) as watcher:
        pids = watcher.run(os.getpid)
        by_name = {w["name"]: a for a, w in watcher.scheduler_info()["workers"].items()}
        victim = by_name["w1"]
        victim_pid = pids[victim]

        def kill_when_busy():
            def busy():
                if n_chunks(folder) < 12:
                    return None
                keys = watcher.processing(workers=[victim]).get(victim, [])
                return [k for k in keys if str(k).startswith("fpdtw-unit-")]

            try:
                keys = wait_for(busy, 300, "worker w1 to be computing a unit", poll=0.05)
                cli_cluster.kill_worker("w1")
                killed.update(keys=keys, chunks=n_chunks(folder))
            except BaseException as e:  # reported by the test below
                killed["error"] = e

        thread = threading.Thread(target=kill_when_busy, daemon=True)
        thread.start()
        E.run_experiments(
            "smoke", progress=False, results=root / "killed_worker",
            scheduler=cli_cluster.address, algorithms=ALGORITHMS,
        )  # fmt: skip
        thread.join(timeout=30)
    assert "error" not in killed, killed.get("error")
    assert killed["keys"] and killed["chunks"] < N_UNITS, "the worker was not killed mid-run"

    assert_same_results(folder, joblib_run)
    assert_clean_chunks(folder)
    units = [u for u, _ in delivered]
    assert len(units) == len(set(units)) == N_UNITS  # each unit delivered once
    by_unit = dict(delivered)
    victim_name = f"{socket.gethostname()}:{victim_pid}"
    for key in killed["keys"]:  # what w1 held when it died was computed by the other worker
        unit = str(key)[len("fpdtw-unit-") :].rsplit("-", 1)[0]
        assert by_unit[unit] != victim_name
    workers = computed(folder)["workers"]
    assert sum(workers.values()) == N_UNITS
    assert workers.get(victim_name, 0) < N_UNITS


def test_killed_client_resumes_through_the_command_line(joblib_run, root, cli_cluster):
    """``fpdtw experiments run --scheduler``: the client SIGKILLed, then run again."""
    out = root / "killed_client"
    folder = out / "smoke"
    seed_features(joblib_run, folder)  # the units are what this test kills, not the features
    cmd = [
        sys.executable,
        "-m",
        "fpdtw.app.cli",
        "experiments",
        "run",
        "--smoke",
        "--quiet",
        "--results",
        str(out),
        "--scheduler",
        cli_cluster.address,
        "--algorithms",
        *ALGORITHMS,
    ]
    proc = subprocess.Popen(cmd, stdin=subprocess.DEVNULL, start_new_session=True)
    try:
        wait_for(lambda: n_chunks(folder) >= 12, RUN_TIMEOUT, "a dozen chunks", poll=0.05)
        os.killpg(proc.pid, signal.SIGKILL)
        proc.wait(timeout=15)
    finally:
        stop(proc)
    assert not (folder / "run.json").exists()
    before = n_chunks(folder)
    assert 12 <= before < N_UNITS

    again = subprocess.run(cmd, capture_output=True, text=True, timeout=RUN_TIMEOUT)
    assert again.returncode == 0, again.stderr
    done = computed(folder)
    # tasks that were running when the client died may still have finished since
    assert 0 < done["units"] <= N_UNITS - before
    assert done["units_total"] == N_UNITS
    assert_same_results(folder, joblib_run)
    assert_clean_chunks(folder)


# -- addresses and errors ----------------------------------------------------------------------


@pytest.mark.parametrize(
    "text, expected",
    [
        ("tcp://127.0.0.1:8786", "tcp://127.0.0.1:8786"),
        ("127.0.0.1:8786", "tcp://127.0.0.1:8786"),
        (" tls://node-01.cluster.example:8786 ", "tls://node-01.cluster.example:8786"),
        ("tcp://[::1]:8786", "tcp://[::1]:8786"),
        ("local", None),
        ("", None),
        (None, None),
    ],
)
def test_scheduler_addresses(text, expected):
    assert P.scheduler_address(text) == expected


@pytest.mark.parametrize(
    "text, why",
    [
        ("tcp://127.0.0.1", "no port"),
        ("127.0.0.1", "no port"),
        ("http://127.0.0.1:8786", "unknown protocol 'http'"),
        ("tcp://127.0.0.1:0", "port '0' is not a number from 1 to 65535"),
        ("tcp://127.0.0.1:99999", "from 1 to 65535"),
        ("tcp://127.0.0.1:87a6", "port '87a6'"),
        ("tcp://:8786", "no host"),
        ("tcp://::1:8786", "IPv6 hosts go in brackets"),
        ("tcp://127.0.0.1:8786/status", "nothing else"),
        ("tcp://bad_host!:8786", "not a host name"),
    ],
)
def test_malformed_scheduler_addresses_say_what_is_wrong(text, why):
    with pytest.raises(P.ClusterError, match="scheduler address") as info:
        P.scheduler_address(text)
    assert repr(text) in str(info.value) and why in str(info.value)


def test_malformed_fpdtw_scheduler_is_a_usage_error(monkeypatch, capsys, tmp_path):
    from fpdtw.app import cli

    monkeypatch.setenv("FPDTW_SCHEDULER", "tcp://127.0.0.1")
    code = cli.main(["experiments", "run", "--smoke", "--results", str(tmp_path)])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2
    assert err == [
        "fpdtw experiments run: error: FPDTW_SCHEDULER: scheduler address 'tcp://127.0.0.1': "
        "no port, expected tcp://host:port, e.g. tcp://10.0.0.5:8786 (8786 is the port "
        "`dask scheduler` listens on by default)"
    ]
    assert not list(tmp_path.iterdir())  # nothing written
    with pytest.raises(P.ClusterError, match="FPDTW_SCHEDULER"):
        E.run_experiments("smoke", progress=False, results=tmp_path)
    code = cli.main(["experiments", "run", "--smoke", "--scheduler", "tcp://x:1:2"])
    assert code == 2 and "IPv6 hosts go in brackets" in capsys.readouterr().err


def test_unreachable_scheduler_is_one_line_and_exit_1(tmp_path):
    address = f"tcp://127.0.0.1:{free_port()}"  # nothing listens there
    cmd = [sys.executable, "-m", "fpdtw.app.cli", "experiments", "run", "--smoke"]
    cmd += ["--results", str(tmp_path), "--scheduler", address, "--connect-timeout", "1"]
    t0 = time.monotonic()
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=300)
    assert r.returncode == 1
    lines = r.stderr.strip().splitlines()
    assert lines[-1].startswith(
        f"fpdtw experiments run: error: cannot reach the Dask scheduler at {address} within 1 s"
    )
    assert "Traceback" not in r.stderr and "dask worker" in lines[-1]
    assert time.monotonic() - t0 < 120


def test_nothing_to_do_never_connects(joblib_run, root, capsys):
    """A finished run returns at once, whatever the scheduler (it is not asked)."""
    address = f"tcp://127.0.0.1:{free_port()}"
    res = E.run_experiments(
        "smoke", results=root / "joblib", scheduler=address, algorithms=ALGORITHMS
    )
    assert "nothing to do" in capsys.readouterr().out
    assert len(res.algorithms) == N_ALGORITHMS


def test_a_worker_with_other_code_refuses(monkeypatch):
    E._check_code(E._code_key())  # this process runs the run's code
    with pytest.raises(P.ClusterError, match="runs other fpdtw code than the run"):
        E._check_code("0:" + "0" * 64)


def test_files_the_workers_wrote_must_be_visible_here(monkeypatch, tmp_path):
    monkeypatch.setattr(C, "VISIBLE_TIMEOUT", 0.2)
    (tmp_path / "a.npz").write_bytes(b"x")
    ex = P.make_executor(1, f"tcp://127.0.0.1:{free_port()}")  # connects only to compute
    ex.settle([tmp_path / "a.npz"], Path.is_file, "chunk files", tmp_path)
    with pytest.raises(P.ClusterError, match="filesystem this machine and every worker share"):
        ex.settle([tmp_path / "b.npz"], Path.is_file, "chunk files", tmp_path)


def test_executor_yields_every_result_once_with_either_backend():
    tasks = [(i,) for i in range(7)]
    with P.make_executor(1) as ex:
        assert ex.kind == "joblib" and ex.describe() == {"backend": "joblib", "n_jobs": 1}
        assert sorted(ex.map(abs, tasks, desc="t", progress=False)) == list(range(7))
    assert P.make_executor(2, "local").kind == "joblib"
    with pytest.raises(TypeError, match="address string or a distributed.Client"):
        P.make_executor(2, 8786)
