"""Publishing what made the figures: ``figures/ENVIRONMENT.md`` and ``make check-figures``.

The record itself (:func:`fpdtw.paper.provenance.environment`) belongs to the reproduction;
this module writes it as the Markdown page ``make figures`` commits and compares a fresh
``figures/`` with the committed one. Run ``python -m fpdtw.app.publish [--markdown OUT |
--compare-figures]`` (no option: print this machine's record as JSON).
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
from pathlib import Path

from fpdtw.paper.atomic import write_atomic
from fpdtw.paper.paths import REPO_ROOT, results_dir
from fpdtw.paper.provenance import COMPUTE_PACKAGES, SIMD_FLAGS, environment, versions_line


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
        "Written by `make figures` (`python -m fpdtw.app.publish --markdown`). The",
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
    "live_network_latency.md", "live_source_latency.csv", "live_source_latency.md", "claims.csv",
    "claims.md", "ENVIRONMENT.md",
    # the rows of the timing claims (4, 4b, Q3's time parts) and Q3's cost table: added on
    # 2026-11-26, when check-figures on a make figures at b36ff2e found these six differing
    # in those rows only
    "claims_checks.csv", "claims_checks.md", "claims_intervals.csv", "claims_intervals.md",
    "open_q3_cost.csv", "open_q3_cost.md",
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
    ap = argparse.ArgumentParser(prog="python -m fpdtw.app.publish", description=__doc__)
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
