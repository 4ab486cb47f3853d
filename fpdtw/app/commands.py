"""The reproduction's commands of ``fpdtw``: ``fpdtw data fetch|verify|cite`` and ``fpdtw
experiments run``.

:mod:`fpdtw.app.cli` adds them to its parser (:func:`add_data_commands`,
:func:`add_experiments_commands`) and carries them out (:func:`run_data_command`,
:func:`run_command`); what they run is the paper layer's (:mod:`fpdtw.paper.datasets`,
:func:`fpdtw.paper.runner.run.run_experiments`). ``make data`` runs ``python -m
fpdtw.app.cli data fetch``, ``make figures`` the grids with ``python -m fpdtw.app.cli
experiments run --mode MODE``.
"""

from __future__ import annotations

import argparse
import sys
import textwrap
import time
from dataclasses import dataclass, field
from pathlib import Path

from tqdm import tqdm

from fpdtw.app.argtypes import positive_float, positive_int
from fpdtw.errors import AlignmentError, ClusterError, FpdtwError
from fpdtw.paper import paths
from fpdtw.paper.datasets import (
    DataFetchError,
    Datasets,
    ManifestError,
    as_manifests,
    fetch,
    fetch_entry,
    file_hashes,
    hash_problems,
)
from fpdtw.paper.runner.parallel import (
    CONNECT_TIMEOUT,
    SCHEDULER_ENV,
    scheduler_address,
    scheduler_from_env,
)
from fpdtw.paper.runner.run import run_experiments
from fpdtw.paper.runner.selection import SELECTIONS

# -- fpdtw data ---------------------------------------------------------------------------


@dataclass
class FetchReport:
    """What :func:`fetch_all` did: the verified files in the cache, the (dataset, path) not
    tried (not in the local mirror), the (dataset, path, message) that failed, the time."""

    fetched: list[Path] = field(default_factory=list)
    skipped: list[tuple[str, str]] = field(default_factory=list)
    failed: list[tuple[str, str, str]] = field(default_factory=list)
    seconds: float = 0.0

    @property
    def ok(self) -> bool:
        """No file that was tried failed."""
        return not self.failed

    def summary(self) -> str:
        """A few human-readable lines."""
        lines = [f"{len(self.fetched)} files verified in the cache ({self.seconds:.1f} s)"]
        if self.skipped:
            lines.append(f"{len(self.skipped)} skipped (not available in the local mirror):")
            lines += [f"  {d}: {p}" for d, p in self.skipped]
        if self.failed:
            lines.append(f"{len(self.failed)} FAILED:")
            lines += [f"  {msg}" for _, _, msg in self.failed]
        return "\n".join(lines)


def fetch_all(
    datasets: Datasets = None, *, available_only=None, progress=True, strict=True
) -> FetchReport:
    """Fetch every file of some datasets (default: all), verified; report what could not be had.

    ``available_only`` (default: whether ``FPDTW_MIRROR`` is set; upstream has every file)
    skips the files the manifest marks as not in the local mirror; ``strict`` raises
    DataFetchError, with the report as its ``report``, if any file failed.
    """
    ms = as_manifests(datasets)
    if available_only is None:
        available_only = paths.mirror() is not None
    report = FetchReport()
    t0 = time.perf_counter()
    cache = paths.data_dir()
    todo = []
    for m in ms:
        for e in m.files:
            if available_only and not e.available_here:
                report.skipped.append((m.name, e.path))
            else:
                todo.append((m, e))
    with tqdm(total=len(todo), unit="file", desc="fetch", disable=not progress) as bar:
        for m, e in todo:
            bar.set_postfix_str(m.name, refresh=False)
            try:
                p = fetch_entry(m, e, cache, progress=False, archive_progress=progress)
                report.fetched.append(p)
            except DataFetchError as exc:
                report.failed.append((m.name, e.path, str(exc)))
            bar.update()
    report.seconds = time.perf_counter() - t0
    if strict and report.failed:
        exc = DataFetchError(report.summary())
        exc.report = report
        raise exc
    return report


@dataclass
class VerifyReport:
    """What :func:`verify` found, as cache-relative paths: ``verified``, ``corrupt`` (with
    what differs), ``missing``, ``skipped`` (missing but not in the local mirror, when only
    those are checked) and ``extra`` (in a dataset's folder, listed by no manifest)."""

    verified: list[str] = field(default_factory=list)
    corrupt: list[tuple[str, str]] = field(default_factory=list)
    missing: list[str] = field(default_factory=list)
    skipped: list[str] = field(default_factory=list)
    extra: list[str] = field(default_factory=list)

    @property
    def ok(self) -> bool:
        """Every file checked is in the cache and matches the manifest."""
        return not self.corrupt and not self.missing

    def summary(self, *, show: int = 10) -> str:
        """A few human-readable lines (at most ``show`` missing files listed)."""
        lines = [
            f"{len(self.verified)} verified, {len(self.corrupt)} corrupt, "
            f"{len(self.missing)} missing, {len(self.skipped)} skipped (not in the local "
            f"mirror), {len(self.extra)} unlisted"
        ]
        lines += [f"  CORRUPT {p}: {why}" for p, why in self.corrupt]
        lines += [f"  MISSING {p}" for p in self.missing[:show]]
        if len(self.missing) > show:
            lines.append(f"  ... and {len(self.missing) - show} more missing")
        lines += [f"  unlisted {p}" for p in self.extra]
        if not self.ok:
            bad = len(self.corrupt) + len(self.missing)
            checked = bad + len(self.verified)
            lines.append(
                f"FAILED: {bad} of {checked} files missing or wrong; `fpdtw data fetch` "
                "fetches them again"
            )
        return "\n".join(lines)


def verify(dataset: Datasets = None, *, available_only: bool | None = None) -> VerifyReport:
    """Re-hash every cached file of some datasets (default: all) against the manifests.

    Corrupt files are reported, not deleted (the next :func:`fetch` replaces them).
    ``available_only`` (default: whether ``FPDTW_MIRROR`` is set) counts an uncached file
    that is not in the local mirror as skipped, not missing.
    """
    cache = paths.data_dir()
    if available_only is None:
        available_only = paths.mirror() is not None
    report = VerifyReport()
    for m in as_manifests(dataset):
        listed = set()
        for e in m.files:
            key = f"{m.mirror_prefix}/{e.path}"
            listed.add(key)
            p = cache / key
            if not p.is_file():
                skip = available_only and not e.available_here
                (report.skipped if skip else report.missing).append(key)
                continue
            problems = hash_problems(e, file_hashes(p))
            if e.sha256 is None and e.git_blob_sha1 is None:
                problems = ["the manifest gives no hash to verify it by"]
            if problems:
                report.corrupt.append((key, "; ".join(problems)))
            else:
                report.verified.append(key)
        root = cache / m.mirror_prefix
        if root.is_dir():
            for p in sorted(root.rglob("*")):
                key = p.relative_to(cache).as_posix()
                if p.is_file() and key not in listed:
                    report.extra.append(key)
    return report


def cite(dataset: Datasets = None) -> str:
    """Title, licence, citation and source of some datasets (default: all), as plain text."""
    return "\n\n".join(
        f"{m.name}: {m.title}\n  Licence: {m.licence}\n  Cite: {m.citation}\n  Source: {m.upstream}"
        for m in as_manifests(dataset)
    )


def add_data_commands(sub) -> None:
    """Add ``fetch``, ``verify`` and ``cite`` to argparse subparsers (``fpdtw data``)."""
    help_ds = "dataset name, repeatable (authors_fbx, hdm05, cmu; default: all)"
    help_all = (
        "files the manifest marks as not in the local mirror "
        "(the default when FPDTW_MIRROR is unset)"
    )
    f = sub.add_parser("fetch", help="fetch files into the cache, verified by hash")
    f.add_argument("--dataset", action="append", help=help_ds)
    f.add_argument("--all", action="store_true", help="also try the " + help_all)
    f.add_argument("--file", help="fetch only this file (needs one --dataset)")
    f.add_argument("--quiet", action="store_true", help="no progress bars")
    v = sub.add_parser(
        "verify",
        help="re-hash every cached file; exit 1 if any listed file is missing or wrong",
    )
    v.add_argument("--dataset", action="append", help=help_ds)
    v.add_argument("--all", action="store_true", help="also require the " + help_all)
    c = sub.add_parser("cite", help="print licences and citations")
    c.add_argument("--dataset", action="append", help=help_ds)


def run_data_command(args, prog: str) -> int:
    """Carry out ``args.data_command``; the exit code: 0 on success, 1 when a file is
    missing, wrong or cannot be fetched, 2 for ``--file`` without exactly one ``--dataset``."""
    command = args.data_command
    if command == "fetch" and args.file is not None and len(args.dataset or []) != 1:
        print(f"{prog}: error: fetch --file needs exactly one --dataset", file=sys.stderr)
        return 2
    try:
        if command == "cite":
            print(cite(args.dataset))
            return 0
        if command == "verify":
            report = verify(args.dataset, available_only=None if not args.all else False)
            print(f"cache {paths.data_dir()}: {report.summary()}")
            return 0 if report.ok else 1
        mirror = paths.mirror()
        print(
            f"cache {paths.data_dir()}; source: "
            + (f"FPDTW_MIRROR={mirror}" if mirror else "upstream URLs"),
            file=sys.stderr,
        )
        if args.file is not None:
            print(fetch(args.dataset[0], args.file, progress=not args.quiet))
            return 0
        report = fetch_all(
            args.dataset,
            available_only=None if not args.all else False,
            progress=not args.quiet,
            strict=False,
        )
        print(report.summary())
        return 0 if report.ok else 1
    except (DataFetchError, ManifestError) as exc:
        print(f"{prog}: error: {exc}", file=sys.stderr)
        return 1


# -- fpdtw experiments ----------------------------------------------------------------------


def _scheduler_option(text):
    try:
        return scheduler_address(text) or "local"
    except ClusterError as e:
        raise argparse.ArgumentTypeError(str(e)) from None


_RUN_EPILOG = f"""\
where it runs:
  joblib worker processes on this machine (--jobs), unless a Dask scheduler is given
  (--scheduler tcp://host:port, or {SCHEDULER_ENV}=tcp://host:port): then every work unit
  is a task on that cluster. Workers need this package (the same commit), the data cache
  (FPDTW_DATA_DIR: a shared folder, or `fpdtw data fetch` on each) and the results folder
  at the same path (a shared filesystem). The result files are the same bytes either way.

resuming:
  a run stopped at any point (Ctrl-C, a killed process, a lost worker) goes on from the
  finished work units when run again; a run with nothing left to do returns at once.

examples:
  fpdtw experiments run --smoke
  fpdtw experiments run --jobs 8 --results /scratch/me/fpdtw-results
  dask scheduler --port 8786 &   dask worker tcp://HOST:8786 --nthreads 1 --nworkers 4 &
  fpdtw experiments run --scheduler tcp://HOST:8786 --results /shared/fpdtw-results"""


def add_run_arguments(ap: argparse.ArgumentParser) -> None:
    """Add the options of ``fpdtw experiments run``."""
    ap.add_argument(
        "--mode",
        choices=sorted(SELECTIONS),
        default="full",
        help="which selection and algorithm list (default full; study: notebook 15)",
    )
    ap.add_argument("--smoke", action="store_true", help="the same as --mode smoke")
    ap.add_argument(
        "--jobs",
        type=positive_int,
        default=2,
        metavar="N",
        help="worker processes on this machine (default 2; unused with --scheduler)",
    )
    ap.add_argument(
        "--algorithms",
        nargs="+",
        default=None,
        metavar="NAME",
        help="algorithm names (default: the mode's list)",
    )
    ap.add_argument(
        "--results",
        metavar="DIR",
        default=None,
        help="results root; the run writes DIR/<mode>/ (default: FPDTW_RESULTS_DIR, "
        "else results/ of the checkout)",
    )
    ap.add_argument(
        "--scheduler",
        type=_scheduler_option,
        default=None,
        metavar="ADDRESS",
        help=f"Dask scheduler, tcp://host:port: run the work units on that cluster "
        f"(default: {SCHEDULER_ENV} if set; 'local': this machine whatever it says)",
    )
    ap.add_argument(
        "--connect-timeout",
        type=positive_float,
        default=CONNECT_TIMEOUT,
        metavar="SECONDS",
        help=f"how long to wait for the scheduler to answer (default {CONNECT_TIMEOUT:g})",
    )
    ap.add_argument("--quiet", action="store_true", help="no progress output")


def add_experiments_commands(sub) -> None:
    """Add the action ``run`` to an argparse subparsers object (``fpdtw experiments run``)."""
    r = sub.add_parser(
        "run",
        help="run the experiment grid (resumable; on this machine or a Dask cluster)",
        description=textwrap.fill(
            "Run every algorithm of a mode over every pair of its selection and write the "
            "result files (algorithms/*.npz, pairs.json, summary.json, run.json) under the "
            "results folder, resumably.",
            88,
        ),
        formatter_class=argparse.RawDescriptionHelpFormatter,
        epilog=_RUN_EPILOG,
    )
    add_run_arguments(r)


def run_command(args, prog: str) -> int:
    """Carry out a run from parsed options; the exit code: 0 on success, 2 on a usage error
    (a malformed ``FPDTW_SCHEDULER``, an unknown algorithm), 1 when the run cannot go on, 130
    when interrupted (run again to resume). Errors: one line on stderr starting with ``prog``.
    """
    mode = "smoke" if args.smoke else args.mode
    scheduler = args.scheduler
    if scheduler is None:
        try:
            scheduler = scheduler_from_env() or "local"
        except ClusterError as e:
            print(f"{prog}: error: {e}", file=sys.stderr)
            return 2
    try:
        res = run_experiments(
            mode,
            args.algorithms,
            args.jobs,
            not args.quiet,
            results=args.results,
            scheduler=scheduler,
            connect_timeout=args.connect_timeout,
        )
    except KeyboardInterrupt:
        print(f"{prog}: interrupted; run the same command again to resume", file=sys.stderr)
        return 130
    except AlignmentError as e:  # an unknown algorithm name
        print(f"{prog}: error: {e}", file=sys.stderr)
        return 2
    except (FpdtwError, OSError) as e:
        print(f"{prog}: error: {' '.join(str(e).split())}", file=sys.stderr)
        return 1
    if not args.quiet:
        for name in res.algorithms:
            s = res.summary["algorithms"][name]
            if not s["n_pairs"]:
                print(f"{name:40s} no result: every target is too short for the edit")
                continue
            print(
                f"{name:40s} similarity median {s['similarity_median']:6.3f}  "
                f"deviation median {s['deviation_median']:7.2f} frames"
            )
    return 0
