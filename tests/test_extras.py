"""Each layer runs without the extras above it (pyproject.toml's optional-dependencies).

A subprocess refuses to import the packages of the extras a layer must not need, then uses
the layer: the library aligns a synthetic pair with the papers' methods and offline DTW; the
reproduction imports its runner, claims and figures and runs a grid's worth of nothing
without Dask, python-osc, Selenium or Sphinx. A layer that starts needing an extra at import
time fails here, with the import named.
"""

from __future__ import annotations

import subprocess
import sys
import textwrap

from fpdtw.paper.paths import REPO_ROOT

#: Import names of the packages of each extra (pyproject.toml).
PAPER = ("matplotlib", "seaborn", "pooch", "tqdm", "joblib", "jsonschema")
TOOLS = ("dask", "distributed", "pythonosc", "selenium", "sphinx", "myst_nb", "papermill")

_BLOCK = """
import sys
BLOCKED = {blocked!r}

class Refuse:
    def find_spec(self, name, path=None, target=None):
        if name.split(".")[0] in BLOCKED:
            raise ImportError(f"{{name}} is an extra this layer must not need")
        return None

sys.meta_path.insert(0, Refuse())
"""


def _run(blocked, body):
    code = _BLOCK.format(blocked=tuple(blocked)) + textwrap.dedent(body)
    return subprocess.run(
        [sys.executable, "-c", code], cwd=REPO_ROOT, capture_output=True, text=True, timeout=600
    )


def test_the_library_aligns_without_any_extra():
    r = _run(
        PAPER + TOOLS,
        """
        import numpy as np
        import fpdtw
        sys.path.insert(0, "tests")
        from reference.synthetic import synthetic_pair

        I, T, _ = synthetic_pair(n_frames=200, seed=3)
        for name in ("Ma + Type V", "Mb w20", "Mc w20", "OE-DTW", "OLTW", "DTW", "UTW"):
            M = fpdtw.align(name, I, T)[0]
            assert len(M) == T.n_frames and (np.diff(M) >= 0).all(), name
        res = fpdtw.dtw(fpdtw.geodesic_cost_matrix(I.quats, T.quats))
        assert np.isfinite(res.distance) and len(res.map) == T.n_frames
        print("ok")
        """,
    )
    assert r.returncode == 0 and r.stdout.strip().endswith("ok"), r.stderr


def test_the_reproduction_imports_without_the_tools():
    r = _run(
        TOOLS,
        """
        import fpdtw.paper.claims
        import fpdtw.paper.figures
        import fpdtw.paper.runner
        from fpdtw.paper.runner.parallel import ClusterError, make_executor

        with make_executor(1) as ex:
            assert list(ex.map(abs, [(-2,), (3,)], desc="x", progress=False)) in ([2, 3], [3, 2])
        try:
            make_executor(1, "tcp://127.0.0.1:1")
        except ClusterError as e:
            assert "fpdtw[cluster]" in str(e), e
        else:
            raise AssertionError("a scheduler without dask installed must say what to install")
        print("ok")
        """,
    )
    assert r.returncode == 0 and r.stdout.strip().endswith("ok"), r.stderr


def test_the_refusal_is_real():
    r = _run(("numpy",), "import fpdtw\n")
    assert r.returncode != 0 and "an extra this layer must not need" in r.stderr
