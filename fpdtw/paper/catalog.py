"""The manifests' motions as labelled records (dataset, movement, take), and loading them
through the verified cache (:func:`fpdtw.paper.datasets.fetch`)."""

from __future__ import annotations

from dataclasses import dataclass

from fpdtw.io import load_motion
from fpdtw.paper import datasets as data

_DATASETS = ("authors_fbx", "hdm05", "cmu")


@dataclass(frozen=True)
class MotionRecord:
    """One motion file of a dataset with its labels, whether it is ``available`` here and its
    ``frames`` (where the manifest knows it)."""

    dataset: str
    path: str
    movement: str
    take: str
    available: bool
    frames: int | None = None

    @property
    def name(self) -> str:
        """File stem, e.g. ``"Walk_01"``."""
        return self.path.rsplit("/", 1)[-1].rsplit(".", 1)[0]


def motion_records(datasets=_DATASETS, available_only=False):
    """All motion files of the given datasets, in manifest order, as MotionRecords.

    Notebook: 04_fig3_forecast.ipynb
    """
    return [
        MotionRecord(ds, e.path, e.movement or "", e.take or "", e.available_here, e.frames)
        for ds in datasets
        for e in data.motion_files(ds, available_only=available_only)
    ]


def load(record_or_dataset, path=None):
    """Fetch and read one motion: a MotionRecord, or a dataset name and the path inside it.

    Notebook: 01_data_and_motions.ipynb
    """
    if isinstance(record_or_dataset, MotionRecord):
        dataset, path = record_or_dataset.dataset, record_or_dataset.path
    else:
        dataset = record_or_dataset
    skeleton = data.skeleton_file(dataset, path)
    kwargs = {} if skeleton is None else {"skeleton": data.fetch(dataset, skeleton, progress=False)}
    return load_motion(data.fetch(dataset, path, progress=False), **kwargs)


def summary_rows():
    """One row per dataset and movement: ``dataset, movement, listed, available, missing``.

    Notebook: 01_data_and_motions.ipynb
    """
    groups = {}
    for r in motion_records():
        g = groups.setdefault((r.dataset, r.movement), [0, 0])
        g[0] += 1
        g[1] += int(r.available)
    return [
        {"dataset": ds, "movement": mv, "listed": n, "available": a, "missing": n - a}
        for (ds, mv), (n, a) in groups.items()
    ]
