"""The latency of each capture source (notebook 20, make bench): every frame a source's
emulator sends is answered once for every performer, over real loopback sockets, and timed
from the wire to the answer."""

from __future__ import annotations

import pytest

from fpdtw.app.source_latency import WIRES, measure
from fpdtw.app.sources import SOURCES
from fpdtw.io import load_motion


def test_every_source_is_measured():
    assert set(WIRES) == set(SOURCES)


@pytest.mark.parametrize("scheme", sorted(WIRES))
def test_every_frame_of_every_performer_is_answered_and_timed(scheme, cmu_retimed):
    recording, _, takes = cmu_retimed
    take = load_motion(takes[0]).slice_frames(0, 45)  # 1.5 s at 30 Hz, in real time
    r = measure(scheme, recording, take, performers=2)
    assert r["source"] == scheme and r["performers"] == 2 and r["frames"] == 45
    assert r["answers"] == 2 * 45  # one answer per frame and performer, none lost or extra
    assert 0 < r["p50_ms"] <= r["p99_ms"] <= r["max_ms"] < 1000
    assert 0 < r["server_p50_ms"] <= r["server_p99_ms"]
