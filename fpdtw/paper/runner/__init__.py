"""The experiment runner: every pair of a selection, every algorithm, in parallel, resumably.

* :mod:`.selection`: which motions and pairs (the modes' selections);
* :mod:`.grid`: which algorithms each mode runs;
* :mod:`.run`: the run (work units, workers, chunks, the result files);
* :mod:`.results`: reading and writing the result files (:class:`.results.Results`).
"""

# registers the rescoring of the other readings of eq. 2 (Results.get)
from fpdtw.paper import similarity_level as _similarity_level  # noqa: E402, F401
from fpdtw.paper.runner.grid import DEFAULT_ALGORITHMS
from fpdtw.paper.runner.results import load_results
from fpdtw.paper.runner.run import pair_features, run_experiments
from fpdtw.paper.runner.selection import SELECTIONS, format_counts, pair_selection

__all__ = [
    "DEFAULT_ALGORITHMS", "SELECTIONS", "format_counts", "load_results", "pair_features",
    "pair_selection", "run_experiments",
]  # fmt: skip
