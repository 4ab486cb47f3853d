"""Execute one notebook with papermill and say in the terminal when it starts and ends.

``make figures`` and ``make test`` run every notebook through this module::

    python -m fpdtw.app.execute [--smoke] [--kernel fpdtw] [--cwd notebooks] SOURCE OUTPUT

It prints ``[12:03:04] start 06_fig5_fig6_scores (full)`` and then ``[12:03:41] done
06_fig5_fig6_scores in 37.2 s`` (or ``FAILED ... after``, and exits 1), executes
``SOURCE`` with the parameter ``SMOKE`` into ``<OUTPUT stem>.part.ipynb`` and renames
that to ``OUTPUT`` only when every cell ran, so a failed run never leaves a finished-looking
notebook behind (the ``.part`` file shows where it stopped). The source is never edited.
papermill's cell-by-cell progress bar shows when the terminal is interactive.

The long experiment grids (notebooks 05 and 15) are run by the Makefile before their
notebooks, in the terminal, with the runner's own progress bar (``python -m fpdtw.app.cli
experiments run --mode full``); the notebooks then load the finished results.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path


def _say(msg: str) -> None:
    print(f"[{time.strftime('%H:%M:%S')}] {msg}", flush=True)


def part_path(output) -> Path:
    """Where a notebook is written while it runs: ``<stem>.part.ipynb`` beside ``output``."""
    output = Path(output)
    return output.with_name(output.stem + ".part" + output.suffix)


def execute(
    source,
    output,
    smoke: bool = False,
    kernel: str = "fpdtw",
    cwd="notebooks",
    progress: bool | None = None,
) -> float:
    """Execute a notebook with papermill into ``output``, printing its start and end.

    Parameters
    ----------
    source, output : str or Path
        The notebook and where its executed copy goes (the folder is made).
    smoke : bool
        The notebook's ``SMOKE`` parameter.
    kernel : str
        The Jupyter kernel (``make env`` installs ``fpdtw``).
    cwd : str or Path
        The working directory of the kernel.
    progress : bool, optional
        papermill's progress bar (default: when standard error is a terminal).

    Returns
    -------
    seconds : float

    Raises
    ------
    Exception
        Whatever papermill raised (a cell's error: ``PapermillExecutionError``); the
        ``.part`` notebook is left for a look.
    """
    import papermill

    source, output = Path(source), Path(output)
    name = source.stem
    part = part_path(output)
    output.parent.mkdir(parents=True, exist_ok=True)
    if progress is None:
        progress = sys.stderr.isatty()
    _say(f"start {name} ({'smoke' if smoke else 'full'})")
    t0 = time.perf_counter()
    try:
        papermill.execute_notebook(
            str(source),
            str(part),
            parameters={"SMOKE": bool(smoke)},
            kernel_name=kernel,
            cwd=str(cwd),
            progress_bar=progress,
        )
    except BaseException as e:
        seconds = time.perf_counter() - t0
        _say(f"FAILED {name} after {seconds:.1f} s ({type(e).__name__}; see {part})")
        raise
    os.replace(part, output)
    seconds = time.perf_counter() - t0
    _say(f"done {name} in {seconds:.1f} s")
    return seconds


def main(argv=None) -> int:
    """``python -m fpdtw.app.execute [--smoke] [--kernel K] [--cwd DIR] SOURCE OUTPUT``."""
    ap = argparse.ArgumentParser(
        prog="python -m fpdtw.app.execute", description=__doc__.split("\n")[0]
    )
    ap.add_argument("source", type=Path)
    ap.add_argument("output", type=Path)
    ap.add_argument("--smoke", action="store_true", help="run with SMOKE = True")
    ap.add_argument("--kernel", default="fpdtw", help="Jupyter kernel (default fpdtw)")
    ap.add_argument("--cwd", default="notebooks", help="kernel's working directory")
    a = ap.parse_args(argv)
    try:
        execute(a.source, a.output, a.smoke, a.kernel, a.cwd)
    except Exception as e:
        print(f"{a.source}: {type(e).__name__}: {e}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
