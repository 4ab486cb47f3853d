"""Which motions exist, which are here, and loading them by dataset and path.

The manifests (``data_manifest/``) list every file; this module turns them into
motions with labels (dataset, movement, take) and loads them through the
verified cache (:func:`fpdtw.paper.datasets.fetch`).
"""

from __future__ import annotations

from collections import OrderedDict
from dataclasses import dataclass

from fpdtw.io import load_motion
from fpdtw.paper import datasets as data


@dataclass(frozen=True)
class MotionRecord:
    """One motion file of a dataset, with its labels.

    Attributes
    ----------
    dataset : str
        Manifest name (``"authors_fbx"``, ``"hdm05"``, ``"cmu"``).
    path : str
        Path inside the dataset.
    movement : str
        Authors' movement name, HDM05 class, or CMU take description.
    take : str
        Take label (authors' ``01``.., HDM05 clip number, CMU take).
    available : bool
        Whether the local mirror holds it (the manifest's ``available_here``).
    frames : int or None
        Frame count where the manifest knows it.
    """

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


def motion_records(datasets=("authors_fbx", "hdm05", "cmu"), available_only=False):
    """All motion files of the given datasets, in manifest order.

    Returns
    -------
    records : list of MotionRecord

    Notebook: 04_fig3_forecast.ipynb
    """
    out = []
    for ds in datasets:
        for e in data.motion_files(ds, available_only=available_only):
            out.append(
                MotionRecord(ds, e.path, e.movement or "", e.take or "", e.available_here, e.frames)
            )
    return out


def load(record_or_dataset, path=None, **kwargs):
    """Fetch (verified, cached) and read one motion.

    Parameters
    ----------
    record_or_dataset : MotionRecord or str
        A record, or a dataset name with ``path``.
    path : str, optional
        Path inside the dataset.
    **kwargs
        Passed to :func:`fpdtw.io.load_motion`.

    Returns
    -------
    motion : Motion

    Notebook: 01_data_and_motions.ipynb
    """
    if isinstance(record_or_dataset, MotionRecord):
        dataset, path = record_or_dataset.dataset, record_or_dataset.path
    else:
        dataset = record_or_dataset
    skeleton = data.skeleton_file(dataset, path)
    if skeleton is not None:
        kwargs.setdefault("skeleton", data.fetch(dataset, skeleton, progress=False))
    return load_motion(data.fetch(dataset, path, progress=False), **kwargs)


def summary_rows(datasets=("authors_fbx", "hdm05", "cmu")):
    """One row per dataset and movement: takes listed, takes available here.

    Returns
    -------
    rows : list of dict
        Keys ``dataset, movement, listed, available, missing``.

    Notebook: 01_data_and_motions.ipynb
    """
    groups = OrderedDict()
    for r in motion_records(datasets):
        g = groups.setdefault((r.dataset, r.movement), [0, 0])
        g[0] += 1
        g[1] += int(r.available)
    return [
        {"dataset": ds, "movement": mv, "listed": n, "available": a, "missing": n - a}
        for (ds, mv), (n, a) in groups.items()
    ]
