"""What made a result: package versions, Python, the package's git commit, the machine.

Runs' ``run.json``, ``results/bench.json`` and the figure notebooks' facts carry
:func:`environment`; figures and the claims table carry no commit and no machine (byte-stable).
"""

from __future__ import annotations

import contextlib
import os
import platform
import subprocess
from importlib import metadata
from pathlib import Path

import numba
from llvmlite import binding

from fpdtw import __version__
from fpdtw.paper.paths import REPO_ROOT

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
    """``{"commit": sha, "dirty": bool}`` of the source checkout (None, None outside one);
    dirty: a tracked file other than :data:`OUTPUTS` (none changes a figure) differs."""

    def git(*args: str) -> str:
        cmd = ["git", "-C", str(root), *args]
        return subprocess.run(cmd, capture_output=True, text=True, timeout=10, check=True).stdout

    try:
        sha = git("rev-parse", "HEAD").strip()
        excluded = (f":(exclude){p}" for p in OUTPUTS)
        status = git("status", "--porcelain", "--untracked-files=no", "--", ".", *excluded)
    except (OSError, subprocess.SubprocessError):
        return {"commit": None, "dirty": None}
    return {"commit": sha, "dirty": bool(status.strip())}


def cpu_info() -> dict:
    """The CPU: ``model``, ``cores`` (logical), ``simd`` (its flags of :data:`SIMD_FLAGS`),
    ``mhz`` (core 0's clock, or None), ``machine``, ``llvm_cpu`` (what numba compiles for)."""
    model, flags, mhz, text = platform.processor() or None, set(), None, ""
    with contextlib.suppress(OSError):
        text = Path("/proc/cpuinfo").read_text()
    for line in text.splitlines():
        key, _, value = line.partition(":")
        key = key.strip()
        if key == "model name" and (model is None or model == platform.machine()):
            model = value.strip()
        elif key == "flags" and not flags:
            flags = set(value.split())
        elif key == "cpu MHz" and mhz is None:
            with contextlib.suppress(ValueError):
                mhz = round(float(value), 0)
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
