"""An experiment run made up in memory: pairs of takes that share motions, per-pair scores.

Claims are decided on per-pair values, so their tests need runs whose pairs share motions as
the real ones do (every ordered pair of distinct takes of a movement). :class:`FakeRun`
answers what :class:`fpdtw.paper.claims.evidence.Evidence` asks of a
:class:`fpdtw.paper.runner.run.Results`: ``pairs``, ``algorithms``, ``get(name)`` (arrays
``pair_id``, ``similarity``, ``deviation``, maps) and ``frames(name)``.
"""

from __future__ import annotations

import numpy as np


class _Arrays(dict):
    def map(self, k):
        o = self["offsets"]
        return self["maps"][o[k] : o[k + 1]]


class FakeRun:
    """Pairs of ``k`` takes in each movement, with scores ``centre + motion effects + noise``.

    Parameters
    ----------
    movements : dict
        Dataset -> number of movements.
    takes : int
        Takes per movement (all ordered pairs of distinct takes are pairs).
    seed : int
    """

    def __init__(self, movements=None, takes=4, seed=0, n_frames=50):
        movements = movements or {"authors_fbx": 4, "hdm05": 4}
        self.pairs = []
        for ds, G in movements.items():
            for g in range(G):
                for a in range(takes):
                    for b in range(takes):
                        if a != b:
                            self.pairs.append(
                                dict(id=len(self.pairs), dataset=ds, movement=f"mv{g}",
                                     input=f"{ds}{g}_{a}", target=f"{ds}{g}_{b}",
                                     m=n_frames - 1, n=n_frames - 1, m60=n_frames // 2 - 1,
                                     n60=n_frames // 2 - 1)
                            )  # fmt: skip
        self.counts = None
        self.algorithms = []
        self._arrays = {}
        self._rng = np.random.default_rng(seed)
        self.n_frames = n_frames

    def fps(self, name: str) -> float:
        """The frame rate a name ran at: 60 for ``"@60Hz"`` names, else 120."""
        return 60.0 if name.endswith("@60Hz") else 120.0

    @property
    def n_pairs(self) -> int:
        return len(self.pairs)

    def scores(self, centre: float, motion_sd: float = 0.0, noise_sd: float = 0.0):
        """Per-pair values: ``centre`` + input's and target's effects + pair noise."""
        motions = sorted({p[k] for p in self.pairs for k in ("input", "target")})
        eff = dict(zip(motions, self._rng.normal(0.0, motion_sd, len(motions))))
        return np.array(
            [centre + eff[p["input"]] + eff[p["target"]] for p in self.pairs]
        ) + self._rng.normal(0.0, noise_sd, self.n_pairs)

    def add(self, name, similarity, deviation=None, maps=None):
        """Results of one algorithm (``deviation`` default 0; ``maps`` default diagonal)."""
        P = self.n_pairs
        sim = np.broadcast_to(np.asarray(similarity, dtype=np.float64), (P,)).copy()
        dev = np.zeros(P) if deviation is None else np.asarray(deviation, dtype=np.float64)
        dev = np.broadcast_to(dev, (P,)).copy()
        if maps is None:
            n = self.n_frames // 2 if name.endswith("@60Hz") else self.n_frames
            maps = [np.arange(n, dtype=np.int32)] * P
        offsets = np.concatenate([[0], np.cumsum([len(M) for M in maps])]).astype(np.int64)
        self._arrays[name] = _Arrays(
            pair_id=np.arange(P, dtype=np.int32), similarity=sim, deviation=dev,
            offsets=offsets, maps=np.concatenate(maps).astype(np.int32),
        )  # fmt: skip
        if name not in self.algorithms:
            self.algorithms.append(name)
        return self

    def get(self, name):
        if name not in self._arrays:
            raise KeyError(f"no results for {name!r}")
        return self._arrays[name]

    def frames(self, name):
        low = name.endswith("@60Hz")
        m = np.array([p["m60" if low else "m"] for p in self.pairs], dtype=np.int64)
        n = np.array([p["n60" if low else "n"] for p in self.pairs], dtype=np.int64)
        return m, n
