"""Golden-file regression of every online algorithm on one real pair.

Regenerate (only after a deliberate change, and review the diff) with
``.venv/bin/python tests/golden/make_online_golden.py``.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
import pytest

from fpdtw.metrics import is_monotonic
from fpdtw.motion.features import MotionFeatures
from fpdtw.paper import catalog
from fpdtw.registry import align

sys.path.insert(0, str(Path(__file__).parent / "golden"))
from make_online_golden import golden_names  # noqa: E402

GOLDEN = json.loads(
    (Path(__file__).parent / "golden" / "online_squat1Reps_bd001_bd002.json").read_text()
)
ONLINE = golden_names()


@pytest.fixture(scope="module")
def pair(mirror_root):
    return tuple(
        MotionFeatures.from_motion(catalog.load("hdm05", GOLDEN[k])) for k in ("input", "target")
    )


def test_golden_covers_every_online_algorithm():
    assert set(ONLINE) <= set(GOLDEN)


@pytest.mark.parametrize("name", ONLINE)
def test_online_map_matches_golden(pair, name):
    I, T = pair
    M, seconds = align(name, I, T)
    np.testing.assert_array_equal(M, GOLDEN[name])
    assert seconds.shape == M.shape
    assert M.min() >= 0 and M.max() <= I.n_frames - 1
    if name != "OE-DTW":
        assert is_monotonic(M)
