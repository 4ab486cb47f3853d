"""Measure the wall time and peak memory of each step that regenerates the claims' evidence.

ARTIFACT.md's tables of steps and claims quote these numbers. Each step is a command run
from the checkout in order (make's own dependencies make each step do only its new part,
when the steps run in this order from a checkout without results); while it runs, the
resident memory of its whole process tree (make, Python, the notebook kernel, the joblib
workers) is summed from /proc every 0.5 s, and the largest sum is its peak. The load
average before and after is recorded: on a shared machine the times are upper bounds.

Usage (from the checkout, after ``make env``, with no ``results/`` or ``build/``; Linux only,
it reads /proc)::

    .venv/bin/python tools/measure_steps.py [--out build/artifact_steps.json] [STEP ...]
    .venv/bin/python tools/measure_steps.py --no-run

With no STEP names, every step of :data:`STEPS` runs, in order (a step already in the JSON
file is measured again; the others are kept). The measurements then go into ARTIFACT.md
(``--artifact``): the record into its steps block, from which
:func:`fpdtw.app.readme.artifact_blocks` writes the steps table and each claim's time and
peak memory (the sum of the times and the largest peak of the steps its command runs, by
make's dependencies); ``--no-run`` only writes (from the JSON file).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import threading
import time
from pathlib import Path

#: (name, command) in the order that builds each one's prerequisites first (the notebooks
#: that print claims need both grids: the Makefile's CLAIM_NBS).
STEPS = [
    ("data", "make data"),
    ("full grid", "make build/grids/full.done"),
    ("study grid", "make build/grids/study.done"),
    ("nb 05", "make build/notebooks/05_run_experiments.ipynb"),
    ("nb 02", "make build/notebooks/02_fig1_oedtw.ipynb"),
    ("nb 06", "make build/notebooks/06_fig5_fig6_scores.ipynb"),
    ("nb 07", "make build/notebooks/07_table1_60hz.ipynb"),
    ("nb 08", "make build/notebooks/08_fig7_fig10_heatmaps.ipynb"),
    ("bench", "make results/bench.json"),
    ("nb 09", "make build/notebooks/09_table2_timing.ipynb"),
    ("nb 10", "make build/notebooks/10_fig8_walk_pair.ipynb"),
    ("nb 13", "make build/notebooks/13_opw_fig4.ipynb"),
    ("nb 14", "make build/notebooks/14_opw_fig5_fig6.ipynb"),
    ("nb 15", "make build/notebooks/15_readings_of_algorithm_3.ipynb"),
    ("open grid", "make build/grids/open.done"),
    ("nb 16", "make build/notebooks/16_open_questions.ipynb"),
    ("nb 12", "make build/notebooks/12_claims.ipynb"),
]

_PAGE = os.sysconf("SC_PAGE_SIZE")


def _tree_rss(root: int) -> int:
    """Resident bytes of ``root`` and all its descendants (a snapshot of /proc)."""
    parent, rss = {}, {}
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            stat = Path(f"/proc/{entry}/stat").read_text()
            statm = Path(f"/proc/{entry}/statm").read_text().split()
        except OSError:  # ended meanwhile
            continue
        pid = int(entry)
        parent[pid] = int(stat.rsplit(")", 1)[1].split()[1])
        rss[pid] = int(statm[1]) * _PAGE
    children = {}
    for pid, ppid in parent.items():
        children.setdefault(ppid, []).append(pid)
    total, todo = 0, [root]
    while todo:
        pid = todo.pop()
        total += rss.get(pid, 0)
        todo += children.get(pid, [])
    return total


def measure(command: str, every: float = 0.5) -> dict:
    """Run a shell command; its wall seconds, exit code and peak summed RSS (bytes)."""
    load = os.getloadavg()[0]
    t0 = time.perf_counter()
    proc = subprocess.Popen(command, shell=True)
    peak, done = [0], threading.Event()

    def sample():
        while not done.is_set():
            peak[0] = max(peak[0], _tree_rss(proc.pid))
            done.wait(every)

    sampler = threading.Thread(target=sample, daemon=True)
    sampler.start()
    code = proc.wait()
    done.set()
    sampler.join()
    return {
        "command": command,
        "seconds": round(time.perf_counter() - t0, 1),
        "peak_rss_mib": round(peak[0] / 2**20),
        "exit_code": code,
        "load_before": round(load, 2),
        "load_after": round(os.getloadavg()[0], 2),
    }


def disk_mib(folders) -> dict:
    """MiB used by each folder that exists (du)."""
    out = {}
    for d in folders:
        if Path(d).is_dir():
            kib = subprocess.run(["du", "-sk", d], capture_output=True, text=True).stdout.split()
            out[d] = round(int(kib[0]) / 1024)
    return out


def write_artifact(path: Path, record: dict) -> None:
    """Keep the measurements in ARTIFACT.md's steps block and regenerate its blocks."""
    from fpdtw.app import readme
    from fpdtw.paper.paths import figures_dir

    text = path.read_text(encoding="utf-8")
    text = readme.render(text, {"steps": readme.steps_block(record)})
    new = readme.render(text, readme.artifact_blocks(figures_dir(), text))
    path.write_text(new, encoding="utf-8")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("steps", nargs="*", help="step names (default: all, in order)")
    ap.add_argument("--out", type=Path, default=Path("build/artifact_steps.json"))
    ap.add_argument(
        "--artifact",
        type=Path,
        default=Path("ARTIFACT.md"),
        help="write the measurements into this file (default: ARTIFACT.md)",
    )
    ap.add_argument("--no-run", action="store_true", help="measure nothing, only write")
    a = ap.parse_args(argv)
    known = dict(STEPS)
    unknown = [s for s in a.steps if s not in known]
    if unknown:
        ap.error(f"unknown steps {unknown}; known: {', '.join(known)}")
    record = {"cpus": os.cpu_count(), "steps": {}}
    if a.out.is_file():
        record = json.loads(a.out.read_text())
    from fpdtw.app.readme import memory, minutes

    code = 0
    if not a.no_run:
        commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True,
                                text=True).stdout.strip()  # fmt: skip
        record.update(cpus=os.cpu_count(), date=time.strftime("%Y-%m-%d"), commit=commit)
        for name in a.steps or [name for name, _ in STEPS]:
            r = measure(known[name])
            print(f"{name}: {minutes(r['seconds'])}, {memory(r['peak_rss_mib'])}", flush=True)
            if r["exit_code"]:
                print(f"{name} failed (exit {r['exit_code']})", file=sys.stderr)
                code = r["exit_code"]
                break
            record["steps"][name] = r
        record["disk"] = disk_mib([".venv", "data_cache", "results", "build"])
        a.out.parent.mkdir(parents=True, exist_ok=True)
        a.out.write_text(json.dumps(record, indent=1) + "\n")
    steps = [{"name": n, "target": c.split()[-1], **record["steps"][n]}
             for n, c in STEPS if n in record["steps"]]  # fmt: skip
    write_artifact(a.artifact, {**record, "steps": steps})
    return code


if __name__ == "__main__":
    sys.exit(main())
