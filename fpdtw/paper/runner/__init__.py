"""The experiment runner: every pair of a selection, every algorithm, in parallel, resumably.

* :mod:`.selection`: which motions and pairs (the modes' selections);
* :mod:`.grid`: which algorithms each mode runs;
* :mod:`.run`: the run (work units, workers, chunks, the result files);
* :mod:`.results`: reading and writing the result files (:class:`Results`).
"""

# registers the rescoring of the other readings of eq. 2 (Results.get)
from fpdtw.paper import similarity_level as _similarity_level  # noqa: E402, F401
from fpdtw.paper.runner.grid import DEFAULT_ALGORITHMS, STUDY_ALGORITHMS, TABLE1_60HZ_NAMES
from fpdtw.paper.runner.results import AlgorithmResult, Results, aggregate_heatmap, slug
from fpdtw.paper.runner.run import (
    load_results,
    pair_features,
    resolve_algorithm,
    run_experiments,
    summarize,
)
from fpdtw.paper.runner.selection import (
    SELECTIONS,
    PairSelection,
    Selection,
    format_counts,
    pair_selection,
)

__all__ = [
    "DEFAULT_ALGORITHMS", "SELECTIONS", "STUDY_ALGORITHMS", "TABLE1_60HZ_NAMES", "AlgorithmResult",
    "PairSelection", "Results", "Selection", "aggregate_heatmap", "format_counts", "load_results",
    "pair_features", "pair_selection", "resolve_algorithm", "run_experiments", "slug", "summarize"
]  # fmt: skip
