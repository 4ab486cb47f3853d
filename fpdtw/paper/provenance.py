"""What made a result: package versions, Python, the package's git commit, the machine.

Every run's ``run.json``, ``results/bench.json``, the figure notebooks' facts and
``figures/ENVIRONMENT.md`` carry :func:`environment`; figures and the claims table carry no
commit and no machine, so they stay byte-stable.

Run ``python -m fpdtw.paper.provenance [--markdown OUT | --compare-figures]``.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import platform
import subprocess
import sys
from importlib import metadata
from pathlib import Path

import numba
from llvmlite import binding

from fpdtw import __version__
from fpdtw.paper.atomic import write_atomic
from fpdtw.paper.paths import REPO_ROOT, results_dir

#: The distributions whose versions can change a number we report, and those that draw.
COMPUTE_PACKAGES = ("numpy", "scipy", "numba", "llvmlite", "pufbx", "dtw-python")
DRAW_PACKAGES = ("matplotlib", "seaborn", "jupyterlab", "papermill", "nbval")
#: CPU flags that decide which SIMD code numba/LLVM emits.
SIMD_FLAGS = ("sse4_2", "avx", "avx2", "fma", "avx512f", "avx512bw", "avx512vl")


def package_versions(names=COMPUTE_PACKAGES + DRAW_PACKAGES) -> dict:
    """``{distribution: version}`` of the installed distributions (None: not installed)."""
    out = dict.fromkeys(names)
    for n in names:
        with contextlib.suppress(metadata.PackageNotFoundError):
            out[n] = metadata.version(n)
    return out


#: What ``make figures`` rewrites in the checkout (:func:`git_commit` leaves them out).
OUTPUTS = ("figures", "README.md", "ARTIFACT.md", "docs")


def git_commit(root: Path = REPO_ROOT) -> dict:
    """``{"commit": sha, "dirty": bool}`` of the source checkout (None, None outside one).

    ``dirty``: a tracked file other than :data:`OUTPUTS` (what ``make figures`` rewrites
    while it runs; none of them changes a figure) differs from the commit.
    """
    try:
        sha = subprocess.run(
            ["git", "-C", str(root), "rev-parse", "HEAD"],
            capture_output=True, text=True, timeout=10, check=True,
        ).stdout.strip()  # fmt: skip
        status = subprocess.run(
            ["git", "-C", str(root), "status", "--porcelain", "--untracked-files=no",
             "--", ".", *(f":(exclude){p}" for p in OUTPUTS)],
            capture_output=True, text=True, timeout=10, check=True,
        ).stdout  # fmt: skip
    except (OSError, subprocess.SubprocessError):
        return {"commit": None, "dirty": None}
    return {"commit": sha, "dirty": bool(status.strip())}


def cpu_info() -> dict:
    """The CPU: ``model``, ``cores`` (logical), ``simd`` (its flags of :data:`SIMD_FLAGS`),
    ``mhz`` (core 0's clock, or None), ``machine``, ``llvm_cpu`` (what numba compiles for)."""
    model, flags, mhz = platform.processor() or None, set(), None
    try:
        text = Path("/proc/cpuinfo").read_text()
    except OSError:
        text = ""
    for line in text.splitlines():
        key, _, value = line.partition(":")
        key = key.strip()
        if key == "model name" and (model is None or model == platform.machine()):
            model = value.strip()
        elif key == "flags" and not flags:
            flags = set(value.split())
        elif key == "cpu MHz" and mhz is None:
            try:
                mhz = round(float(value), 0)
            except ValueError:
                pass
    return {
        "model": model,
        "cores": os.cpu_count(),
        "simd": [f for f in SIMD_FLAGS if f in flags],
        "mhz": mhz,
        "machine": platform.machine(),
        "llvm_cpu": numba.config.CPU_NAME or binding.get_host_cpu_name(),
    }


def environment(machine: bool = True) -> dict:
    """The whole record: ``python``, ``platform``, ``fpdtw`` (version, commit, dirty),
    ``packages`` and, with ``machine``, ``cpu`` (:func:`cpu_info`)."""
    env = {
        "python": platform.python_version(),
        "implementation": platform.python_implementation(),
        "platform": f"{platform.system()} {platform.machine()}",
        "fpdtw": {"version": __version__, **git_commit()},
        "packages": package_versions(),
    }
    if machine:
        env["cpu"] = cpu_info()
    return env


def versions_line(env: dict | None = None) -> str:
    """One line of the computing packages' versions (no commit, no machine), stable while
    the lock file is: ``"Python 3.11.2; numpy 2.1.3, scipy ..."``."""
    env = env or environment(machine=False)
    pk = env["packages"]
    names = [n for n in COMPUTE_PACKAGES if pk.get(n)]
    return f"Python {env['python']}; " + ", ".join(f"{n} {pk[n]}" for n in names)


def environment_markdown(env: dict | None = None, results: dict | None = None) -> str:
    """``figures/ENVIRONMENT.md``: what made the figures (``env``, default now), and the
    experiment runs' environments (``{label: environment}``) where their versions differ."""
    env = env or environment()
    fp = env["fpdtw"]
    commit = fp["commit"] or "unknown (not a git checkout)"
    if fp["dirty"]:
        commit += " with uncommitted changes"
    cpu = env.get("cpu") or {}
    lines = [
        "# The environment that made these figures",
        "",
        "Written by `make figures` (`python -m fpdtw.paper.provenance --markdown`). The",
        "figures and tables are byte-stable for a given set of package versions; this page",
        "also names the commit and the machine, which change only timings.",
        "",
        f"- fpdtw {fp['version']}, commit {commit}",
        f"- Python {env['python']} ({env['implementation']}), {env['platform']}",
    ]
    if cpu:
        simd = ", ".join(cpu["simd"]) or "none of " + ", ".join(SIMD_FLAGS)
        mhz = f", {cpu['mhz']:.0f} MHz" if cpu.get("mhz") else ""
        lines.append(f"- CPU: {cpu['model']}, {cpu['cores']} logical cores{mhz}; SIMD: {simd}")
    lines += ["", "| package | version | role |", "|---|---|---|"]
    for n, v in env["packages"].items():
        role = "computes results" if n in COMPUTE_PACKAGES else "draws / runs notebooks"
        lines.append(f"| {n} | {v or 'not installed'} | {role} |")
    for label, other in (results or {}).items():
        if other.get("packages") != env["packages"] or other.get("python") != env["python"]:
            lines += ["", f"**{label}** was computed with different versions:", ""]
            lines.append("    " + versions_line(other))
    lines.append("")
    return "\n".join(lines)


#: Outputs of ``figures/`` that hold timings (or name the commit and machine; the claims
#: table's claims 4 and 4b are about time per frame). Every other file of ``figures/`` is
#: byte-identical for the same lock, code and data.
TIMING_OUTPUTS = (
    "table2_time_per_frame.csv", "table2_time_per_frame.md", "table2_time_vs_w.pdf",
    "table2_time_vs_w.png", "live_latency.pdf", "live_latency.png", "live_network_latency.csv",
    "live_network_latency.md", "claims.csv", "claims.md", "ENVIRONMENT.md",
)  # fmt: skip


def compare_figures(root: Path = REPO_ROOT) -> dict:
    """Compare ``figures/`` in the working tree with HEAD's, byte for byte (after ``make
    figures``: did the run reproduce the committed outputs?).

    Returns sorted file names: ``same``, ``differ`` (deterministic files that differ: a
    failed reproduction), ``timing`` (:data:`TIMING_OUTPUTS` that differ, expected) and
    ``missing`` (committed, not written).
    """

    def git(*args):
        return subprocess.run(
            ["git", "-C", str(root), *args], capture_output=True, check=True, timeout=60
        ).stdout

    names = git("ls-tree", "--name-only", "HEAD:figures").decode().split()
    out = {"same": [], "differ": [], "timing": [], "missing": []}
    for name in names:
        path = root / "figures" / name
        if not path.is_file():
            out["missing"].append(name)
        elif path.read_bytes() == git("show", f"HEAD:figures/{name}"):
            out["same"].append(name)
        else:
            out["timing" if name in TIMING_OUTPUTS else "differ"].append(name)
    return {k: sorted(v) for k, v in out.items()}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m fpdtw.paper.provenance", description=__doc__)
    ap.add_argument("--markdown", metavar="OUT", help="write the Markdown page to OUT")
    ap.add_argument(
        "--compare-figures",
        action="store_true",
        help="compare figures/ with the committed ones (after make figures); exit 1 if a "
        "deterministic file differs",
    )
    args = ap.parse_args(argv)
    if args.compare_figures:
        res = compare_figures()
        print(
            f"figures/: {len(res['same'])} files byte-identical to the commit; "
            f"{len(res['timing'])} timing outputs differ (expected): "
            f"{', '.join(res['timing']) or 'none'}"
        )
        for key, what in (("differ", "DIFFERS (deterministic)"), ("missing", "MISSING")):
            for name in res[key]:
                print(f"  {what}: figures/{name}")
        return 1 if res["differ"] or res["missing"] else 0
    if args.markdown:
        runs = {}
        for mode in ("full", "study", "smoke", "smoke-study"):
            f = results_dir() / mode / "run.json"
            env = json.loads(f.read_text()).get("environment") if f.is_file() else None
            if env:
                runs[f"results/{mode}"] = env
        out = write_atomic(args.markdown, environment_markdown(results=runs).encode())
        print(f"wrote {out}")
    else:
        print(json.dumps(environment(), indent=1, sort_keys=True))
    return 0


if __name__ == "__main__":
    sys.exit(main())
