"""Shared fixtures.

Tests never touch the internet. Real motion files come from the verified data
cache that ``make data`` fills from the manifest (``fpdtw.paper.paths.data_dir()``; its
layout is the same as a mirror's). When the cache does not hold a file, the local
mirror folder named by ``FPDTW_MIRROR`` is used instead.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest

from fpdtw.io import load_motion
from fpdtw.io.bvh import write_bvh
from fpdtw.motion.features import MotionFeatures

os.environ.setdefault("MPLBACKEND", "Agg")
# The unit tests read runs with the stored reading of eq. 2 (fake runs have no motions to
# rescore); the default reading ("transform") is tested on a real run in
# tests/test_similarity_level.py, and the smoke notebooks (outside this folder) run with it.
os.environ["FPDTW_EQ2"] = "local"


def _no_network():
    """Without a mirror, let the verified cache serve as the mirror: fetch() never goes online."""
    if not os.environ.get("FPDTW_MIRROR", "").strip():
        from fpdtw.paper.paths import data_dir

        os.environ["FPDTW_MIRROR"] = str(data_dir())


_no_network()


def _hypothesis_profiles():
    """Hypothesis profiles of the fuzz tests (tests/test_fuzz.py).

    ``fpdtw`` (loaded here, what ``make test`` runs): a small fixed budget, examples
    derived from each test's name (``derandomize``), so every run tests the same inputs.
    ``fuzz`` (``make fuzz``: ``--hypothesis-profile=fuzz --hypothesis-seed=N``): a budget
    15 times larger, random examples from the given seed. Neither keeps an example
    database (nothing is written under the repository).
    """
    from hypothesis import HealthCheck, settings

    common = dict(
        deadline=None,  # a per-example time bound is asserted by the tests themselves
        database=None,
        print_blob=True,
        suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
    )
    settings.register_profile("fpdtw", max_examples=40, derandomize=True, **common)
    settings.register_profile("fuzz", max_examples=600, derandomize=False, **common)
    settings.load_profile("fpdtw")


_hypothesis_profiles()


def pytest_configure(config):
    config.addinivalue_line(
        "markers",
        "long: minutes-long checks (the one-hour input) that make test leaves out "
        "(pytest -m 'not long') and make test-all runs",
    )
    config.addinivalue_line(
        "markers", "slow: long checks left out of make test (run them with pytest -m slow)"
    )


_PROBE = "cmu/18_01.bvh"


def _roots() -> list[Path]:
    from fpdtw.paper.paths import data_dir

    roots = []
    cache = data_dir()
    if (cache / _PROBE).is_file():
        roots.append(cache)
    value = os.environ.get("FPDTW_MIRROR", "").strip()
    if value and "://" not in value:
        p = Path(value).expanduser().resolve()
        if p.is_dir():
            roots.append(p)
    return roots


@pytest.fixture(scope="session")
def mirror_root() -> Path:
    """A local folder laid out like the upstream data (cache or mirror)."""
    roots = _roots()
    if not roots:
        pytest.fail(
            "these tests need the motion data: run `make data` (with FPDTW_MIRROR set to a "
            "folder or URL holding a copy when offline) or set FPDTW_MIRROR to a local folder"
        )
    return roots[0]


@pytest.fixture(scope="session")
def data_path():
    """``data_path("cmu/18_01.bvh")`` -> local path of that file (cache, else mirror)."""
    roots = _roots()

    def get(rel: str) -> Path:
        for root in roots:
            p = root / rel
            if p.is_file():
                return p
        pytest.fail(f"no local copy of {rel} (looked in {[str(r) for r in roots]}); run make data")

    return get


def pytest_collection_modifyitems(config, items):
    """Leave the tests marked ``slow`` out unless a marker expression (``-m``) is given."""
    if config.getoption("markexpr"):
        return
    slow = [item for item in items if item.get_closest_marker("slow")]
    if slow:
        config.hook.pytest_deselected(items=slow)
        items[:] = [item for item in items if not item.get_closest_marker("slow")]


@pytest.fixture(scope="session")
def cmu_retimed(data_path, tmp_path_factory):
    """CMU 18_01 (path, features) and two takes of it retimed by t^1.3 and t^0.8 (BVH paths):
    the recording and live takes of the capture-source tests."""
    path = data_path("cmu/18_01.bvh")
    m = load_motion(path)
    d = tmp_path_factory.mktemp("retimed")
    s = np.arange(m.n_frames) / m.fps
    warps = []
    for name, power in (("warpA", 1.3), ("warpB", 0.8)):
        t = m.duration * (s / s[-1]) ** power
        warps.append(write_bvh(m.retime(t, name=name), d / f"{name}.bvh"))
    return path, MotionFeatures.from_motion(m), warps
