"""Regenerate the data manifests (``data_manifest/*.toml``) from a mirror's ``files.csv``.

Maintainer tool, not part of the library: it reads the ``files.csv`` listings of a
local mirror laid out like ``../shared/data`` (``mocap_single_person_actions/``,
``hdm05/``, ``cmu/``) and writes one TOML manifest per dataset. The dataset-level
texts (licence, citation, upstream, notes) are constants below; the per-file
entries (paths, sizes, sha256, git blob SHA-1, labels) come from the CSV files.

Usage::

    python tools/make_manifests.py /work/shared/data [--out data_manifest]

The output is deterministic (same CSV in, same bytes out), so ``git diff`` after a
rerun shows exactly what changed.
"""

from __future__ import annotations

import argparse
import csv
import json
import re
import sys
from pathlib import Path

AUTHORS_COMMIT = "534d0172f4a424194aced7d3b45bd17012b2e3a9"
AUTHORS_RAW = (
    f"https://raw.githubusercontent.com/matRandall/Mocap_SinglePersonActions/{AUTHORS_COMMIT}"
)
HDM05_BASE = "http://resources.mpi-inf.mpg.de/HDM05"
HDM05_COPY = "zhangchi8620/JointLearning-HDM05 at commit b252ad65598e052c38f49490c1ac9dbadc283fd3"
CMU_COMMIT = "faaaffc37b3a8f68439cd88456400ad30cd00e69"

DATASETS = {
    "authors_fbx": {
        "title": (
            "Mocap_SinglePersonActions: single-person motion capture by Randall, Harvey and "
            "Williams (Birmingham City University), 21 movements x 3 takes, FBX, 120 Hz"
        ),
        "mirror_prefix": "mocap_single_person_actions",
        "licence": "Open Data Commons Attribution (ODC-By)",
        "citation": (
            'Randall, Harvey, Williams, "Correlation as a measure for alignment and similarity '
            'of human motions", CAVW, e2157'
        ),
        "upstream": (
            "https://github.com/matRandall/Mocap_SinglePersonActions at commit "
            f"{AUTHORS_COMMIT}, folder MoCapData/"
        ),
        "notes": (
            "All 63 takes (21 movements x 3 takes) of the authors' dataset, the data of the "
            "FP-DTW paper's experiments. Every url is pinned to the commit above, so it never "
            "changes. 48 takes are in the local mirror (available_here = true) and carry a "
            "sha256; the 15 takes of Jaunty_Style_Walk, Slow_Walk, Sneaky_Style_Walk, "
            "Stepping_Stones_Walks and Stiff_Style_Walk are not (available_here = false): "
            "their sha256 is unknown, and their content is pinned by the git blob SHA-1 of "
            "the upstream tree (sha1 of b'blob <size>\\0' + content), which a connected "
            "machine verifies. movement = the take name without its trailing _NN take "
            "number (and without the stray trailing underscore of 3_Jumps_02_.fbx). "
            "Twirls is numbered 02..04 upstream (there is no Twirls_01)."
        ),
    },
    "hdm05": {
        "title": "HDM05 motion capture database, cut library (ASF/AMC, 120 Hz)",
        "mirror_prefix": "hdm05",
        "licence": "CC BY-SA 3.0 Unported",
        "citation": (
            'Mueller, Roeder, Clausen, Eberhardt, Krueger, Weber, "Documentation Mocap '
            'Database HDM05", Tech. Rep. CG-2007-2, Universitaet Bonn, 2007'
        ),
        "upstream": (
            f"{HDM05_BASE} (skeletons under asf/, clips in the cut archive "
            f"HDM05_cut_amc.zip); the mirror copy came from github.com/{HDM05_COPY}, which "
            "holds the files unchanged"
        ),
        "notes": (
            "The 5 actor skeletons (ASF) and all 287 clips of the 11 HDM05 cut-library "
            "motion classes obtainable here ({classes}), every clip of each class, all five "
            "actors (bd, bk, dg, mm, tr). These are whole HDM05 classes: the FP-DTW paper "
            "used 267 HDM05 motions but did not publish which, so the experiments use every "
            "clip listed here. Not obtainable here: the walking, turning, punching, jumping "
            "and sitting classes. Upstream the clips come in one archive (HDM05_cut_amc.zip, "
            "about 150 MB, no published checksum): the fetcher downloads it once and "
            "extracts only the listed members, each verified by its sha256. The sha256 "
            "values are those of the mirror copy."
        ),
    },
    "cmu": {
        "title": "CMU Graphics Lab Motion Capture Database, take 18_01 (BVH, 30 fps)",
        "mirror_prefix": "cmu",
        "licence": "free for all uses, not to be resold",
        "citation": (
            "The data used in this project was obtained from mocap.cs.cmu.edu. The database "
            "was created with funding from NSF EIA-0196217."
        ),
        "upstream": (
            f"http://mocap.cs.cmu.edu (this BVH copy: github.com/414Group/Rotate at commit "
            f"{CMU_COMMIT}, path 18_01.bvh)"
        ),
        "notes": (
            "Take 18_01, 'walk, shake hands', subject A of the two-person pair 18/19, as a "
            "BVH at 30 fps that keeps the ASF joint names. Its url is pinned to the BVH copy "
            "the mirror was made from. The official CMU files of this take are AMC/ASF, "
            "http://mocap.cs.cmu.edu/subjects/18/18_01.amc with "
            "http://mocap.cs.cmu.edu/subjects/18/18.asf; they are a different format (not "
            "byte-identical to this BVH), so they are not used as its url. The OPW poster's "
            "other clips (19_01, 18_02/19_02, 18_08/19_08, 18_09/19_09, 22_17/23_17) are not "
            "obtainable here and are not listed."
        ),
    },
}


def _value(v) -> str:
    """One TOML value (str, int or bool)."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, str):
        # A JSON string is a valid TOML basic string (same escapes).
        return json.dumps(v, ensure_ascii=False)
    raise TypeError(f"cannot write {v!r} as TOML")


def _write(path: Path, name: str, files: list[dict], archives: dict | None = None, **fmt) -> None:
    meta = dict(DATASETS[name])
    meta["notes"] = meta["notes"].format(**fmt) if fmt else meta["notes"]
    out = [
        f"# Data manifest of the {name!r} dataset: generated by tools/make_manifests.py",
        "# from the mirror's files.csv; see data_manifest/README.md. Edit the generator,",
        "# not this file.",
        "",
        "[dataset]",
        f"name = {_value(name)}",
    ]
    out += [f"{k} = {_value(v)}" for k, v in meta.items()]
    for aname, table in (archives or {}).items():
        out += ["", f"[archives.{aname}]"]
        out += [f"{k} = {_value(v)}" for k, v in table.items()]
    for entry in files:
        out += ["", "[[files]]"]
        out += [f"{k} = {_value(v)}" for k, v in entry.items() if v is not None]
    path.write_text("\n".join(out) + "\n", encoding="utf-8")


def _read_csv(path: Path) -> list[dict]:
    with open(path, newline="", encoding="utf-8") as f:
        return list(csv.DictReader(f))


_TAKE = re.compile(r"^(?P<movement>.+?)_(?P<take>\d+)_?$")


def authors_entries(rows: list[dict]) -> list[dict]:
    """Manifest entries of the authors' 63 FBX takes from their ``files.csv`` rows."""
    files = []
    for r in rows:
        stem = Path(r["path"]).stem
        m = _TAKE.match(stem)
        if m is None:
            raise ValueError(f"take name {stem!r} does not end in _NN")
        here = r["present_here"] == "yes"
        files.append(
            {
                "path": r["path"],
                "url": f"{AUTHORS_RAW}/{r['path']}",
                "kind": "motion",
                "size": int(r["size_bytes"]) if r["size_bytes"] else None,
                "sha256": r["sha256"] or None,
                "git_blob_sha1": r["git_blob_sha1"],
                "movement": m["movement"],
                "take": m["take"],
                "available_here": here,
            }
        )
    return files


def hdm05_entries(rows: list[dict]) -> list[dict]:
    """Manifest entries of the HDM05 skeletons and clips from their ``files.csv`` rows."""
    files = []
    for r in rows:
        path = r["path"]
        entry = {"path": path}
        if path.endswith(".asf"):
            entry |= {
                "url": f"{HDM05_BASE}/asf/{Path(path).name}",
                "kind": "skeleton",
                "actor": r["actor"],
            }
        else:
            entry |= {
                "archive": "cut_amc",
                "member": path,
                "kind": "motion",
                "movement": r["motion_class"],
                "take": r["take"],
                "actor": r["actor"],
                "frames": int(r["frames"]),
            }
        entry |= {"size": int(r["size_bytes"]), "sha256": r["sha256"]}
        files.append(entry)
    return files


def cmu_entries(rows: list[dict]) -> list[dict]:
    """Manifest entry of the CMU take from its ``files.csv`` row."""
    files = []
    for r in rows:
        files.append(
            {
                "path": r["path"],
                "url": (
                    "https://raw.githubusercontent.com/"
                    f"{r['source_repo']}/{r['source_commit']}/{r['source_path']}"
                ),
                "kind": "motion",
                "size": int(r["size_bytes"]),
                "sha256": r["sha256"],
                "movement": r["description"].split(" (")[0],
                "take": r["take"],
                "frames": int(r["frames"]),
            }
        )
    return files


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("mirror", type=Path, help="mirror folder holding the three files.csv")
    ap.add_argument(
        "--out", type=Path, default=Path(__file__).resolve().parent.parent / "data_manifest"
    )
    args = ap.parse_args(argv)
    mirror, out = args.mirror, args.out
    out.mkdir(parents=True, exist_ok=True)

    authors = authors_entries(_read_csv(mirror / "mocap_single_person_actions" / "files.csv"))
    _write(out / "authors_fbx.toml", "authors_fbx", authors)

    hdm = hdm05_entries(_read_csv(mirror / "hdm05" / "files.csv"))
    classes = sorted({e["movement"] for e in hdm if e["kind"] == "motion"})
    archives = {
        "cut_amc": {
            "url": f"{HDM05_BASE}/HDM05_cut_amc.zip",
            "approx_size": "about 150 MB",
            "notes": "no checksum is published for the archive; each extracted member is "
            "verified by its sha256",
        }
    }
    _write(out / "hdm05.toml", "hdm05", hdm, archives, classes=", ".join(classes))

    cmu = cmu_entries(_read_csv(mirror / "cmu" / "files.csv"))
    if cmu[0]["url"] != f"https://raw.githubusercontent.com/414Group/Rotate/{CMU_COMMIT}/18_01.bvh":
        raise ValueError(f"unexpected CMU source in files.csv: {cmu[0]['url']}")
    _write(out / "cmu.toml", "cmu", cmu)

    print(f"wrote {len(authors)} + {len(hdm)} + {len(cmu)} entries to {out}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
