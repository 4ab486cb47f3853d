"""Data manifests and verified fetching of the motion datasets.

Each dataset is described by one TOML manifest in ``data_manifest/`` (see its
README): every file's path, upstream URL (or archive member), size and hash, and
its labels (movement, take, actor). :func:`fetch` puts a file into the cache and
returns its path; nothing reaches the cache without matching its hash.

Cache layout (``fpdtw.paper.paths.data_dir()``, env ``FPDTW_DATA_DIR``)::

    <cache>/<mirror_prefix>/<path>     the dataset files, laid out like a mirror
    <cache>/_archives/<name>.zip       archives downloaded once (HDM05 cut library)

Sources, in order: if ``FPDTW_MIRROR`` is set, only the mirror is used (a folder:
copy ``<mirror>/<mirror_prefix>/<path>``; an ``http(s)://`` base URL: download
``<base>/<mirror_prefix>/<path>``). Otherwise the upstream source: the file's
``url``, or for HDM05 clips the member of the cut archive.

Every file is written to a temporary file next to its destination, verified
(sha256 when the manifest has one, else the git blob SHA-1; a file with neither is
refused) and only then renamed into place, so the cache never holds a
half-written or unverified file.

The cache cannot lie: :func:`fetch` hashes the cached file against the manifest
EVERY time it returns it (there is no index of sizes and modification times that a
file changed in place could fool; hashing all 341 cached files, 158 MiB, takes about
0.3 s, a 2 MB FBX take 7 ms against 190 ms to read it). A cached file that does not match
is dropped and fetched again. :func:`verify` re-hashes a whole cache and fails when a
listed file is missing or wrong. (What it cannot prevent: a file changed between
:func:`fetch` returning its path and the reader opening it.)

Command line (``make data`` runs the first with ``FPDTW_MIRROR`` set)::

    python -m fpdtw.paper.datasets fetch  [--dataset NAME ...] [--all] [--file PATH] [--quiet]
    python -m fpdtw.paper.datasets verify [--dataset NAME ...] [--all]
    python -m fpdtw.paper.datasets cite   [--dataset NAME ...]
"""

from __future__ import annotations

import argparse
import contextlib
import hashlib
import os
import re
import shutil
import sys
import tempfile
import time
import tomllib
import urllib.parse
import zipfile
from collections.abc import Iterable, Iterator
from dataclasses import dataclass, field
from pathlib import Path, PurePosixPath

import jsonschema
import pooch
import requests
from tqdm import tqdm

from fpdtw.errors import DataFetchError, ManifestError
from fpdtw.paper import paths

#: Cache sub-folder of downloaded archives.
ARCHIVE_DIR = "_archives"
#: Prefix and suffix of temporary files (never left behind).
TMP_PREFIX, TMP_SUFFIX = ".fpdtw-", ".part"

MIRROR_HINT = (
    "no network here? set FPDTW_MIRROR to a folder or base URL holding a copy laid out as "
    "<mirror>/<dataset folder>/<path> (for example FPDTW_MIRROR=/path/to/a/copy)"
)

_SHA256 = re.compile(r"^[0-9a-f]{64}$")
_SHA1 = re.compile(r"^[0-9a-f]{40}$")
_KINDS = ("motion", "skeleton")


# -- manifests -------------------------------------------------------------------------


@dataclass(frozen=True)
class FileEntry:
    """One file of a dataset, as listed in its manifest.

    Attributes
    ----------
    path : str
        Path relative to the dataset (POSIX, no ``..``); the cached copy is
        ``<cache>/<mirror_prefix>/<path>``.
    kind : str
        ``"motion"`` (a take / clip) or ``"skeleton"`` (an HDM05 ASF file).
    url : str or None
        Pinned upstream URL (None for archive members).
    archive, member : str or None
        Name of the manifest's archive holding the file and its path inside it.
    size : int or None
        Size in bytes (None when unknown).
    sha256, git_blob_sha1 : str or None
        Lower-case hex digests; at least one is needed to fetch the file.
    movement : str or None
        Movement label: the authors' movement name, the HDM05 class, the CMU
        take description.
    take, actor : str or None
        Take number (as in the file name) and HDM05 actor.
    frames : int or None
        Frame count where the listing gives it (HDM05, CMU).
    available_here : bool
        Whether the local mirror holds the file (False for the 15 missing FBX takes).
    """

    path: str
    kind: str
    url: str | None = None
    archive: str | None = None
    member: str | None = None
    size: int | None = None
    sha256: str | None = None
    git_blob_sha1: str | None = None
    movement: str | None = None
    take: str | None = None
    actor: str | None = None
    frames: int | None = None
    available_here: bool = True

    @property
    def name(self) -> str:
        """File name without folders (e.g. ``"Walk_01.fbx"``)."""
        return PurePosixPath(self.path).name


@dataclass(frozen=True)
class Archive:
    """An upstream archive some files are extracted from (the HDM05 cut library)."""

    name: str
    url: str
    sha256: str | None = None
    approx_size: str | None = None
    notes: str | None = None

    @property
    def filename(self) -> str:
        """Cache file name of the archive (last component of its URL)."""
        return PurePosixPath(urllib.parse.urlsplit(self.url).path).name or f"{self.name}.zip"


@dataclass(frozen=True)
class Manifest:
    """A dataset's manifest: dataset-level metadata and its files.

    Use :func:`dataclasses.replace` to derive a modified copy (e.g. another URL).
    """

    name: str
    title: str
    mirror_prefix: str
    licence: str
    citation: str
    upstream: str
    notes: str
    files: tuple[FileEntry, ...]
    archives: dict[str, Archive] = field(default_factory=dict, hash=False)
    source: Path | None = None

    def entry(self, path: str | os.PathLike | FileEntry) -> FileEntry:
        """The entry with this path (or, if unique, this file name).

        Raises
        ------
        DataFetchError
            No entry (or several) match.
        """
        if isinstance(path, FileEntry):
            return path
        p = PurePosixPath(str(path).replace("\\", "/")).as_posix()
        for e in self.files:
            if e.path == p:
                return e
        hits = [e for e in self.files if e.name == p]
        if len(hits) == 1:
            return hits[0]
        what = "matches several files" if hits else "is not a file of this dataset"
        raise DataFetchError(f"{self.name}: {p!r} {what} (see manifest {self.source})")


_DATASET_KEYS = ("name", "title", "mirror_prefix", "licence", "citation", "upstream", "notes")
_STR = {"type": "string"}
#: The manifest's schema (JSON Schema, checked by :mod:`jsonschema`); what a schema cannot
#: say (paths, one source per file, archives that exist) is checked in :func:`_parse_manifest`.
MANIFEST_SCHEMA = {
    "type": "object",
    "additionalProperties": False,
    "required": ["dataset", "files"],
    "properties": {
        "dataset": {
            "type": "object",
            "additionalProperties": False,
            "required": list(_DATASET_KEYS),
            "properties": dict.fromkeys(_DATASET_KEYS, _STR),
        },
        "archives": {
            "type": "object",
            "additionalProperties": {
                "type": "object",
                "additionalProperties": False,
                "required": ["url"],
                "properties": {
                    "url": {"type": "string", "pattern": "^https?://"},
                    "sha256": {"type": "string", "pattern": _SHA256.pattern},
                    "approx_size": _STR,
                    "notes": _STR,
                },
            },
        },
        "files": {
            "type": "array",
            "minItems": 1,
            "items": {
                "type": "object",
                "additionalProperties": False,
                "required": ["path", "kind"],
                "properties": {
                    "path": _STR,
                    "kind": {"enum": list(_KINDS)},
                    "url": {"type": "string", "pattern": "^https?://"},
                    "archive": _STR,
                    "member": _STR,
                    "size": {"type": "integer", "minimum": 0},
                    "sha256": {"type": "string", "pattern": _SHA256.pattern},
                    "git_blob_sha1": {"type": "string", "pattern": _SHA1.pattern},
                    "movement": _STR,
                    "take": _STR,
                    "actor": _STR,
                    "frames": {"type": "integer", "minimum": 0},
                    "available_here": {"type": "boolean"},
                },
            },
        },
    },
}


def _where(raw: dict, path) -> str:
    """Where a schema error is, in the manifest's own terms: ``[[files]] #3 (path 'x') key 'y'``."""
    path = list(path)
    if not path:
        return "top level"
    if path[0] == "files" and len(path) > 1:
        where = f"[[files]] #{path[1] + 1}"
        entry = raw["files"][path[1]]
        if isinstance(entry, dict) and isinstance(entry.get("path"), str):
            where += f" (path {entry['path']!r})"
        rest = path[2:]
    elif path[0] == "archives" and len(path) > 1:
        where, rest = f"[archives.{path[1]}]", path[2:]
    else:
        where, rest = f"[{path[0]}]", path[1:]
    return where + (f" key {rest[0]!r}" if rest else "")


def _check_relpath(p: str, file: Path, where: str) -> None:
    parts = p.split("/")
    if not p or p.startswith("/") or "\\" in p or any(x in ("", ".", "..") for x in parts):
        raise ManifestError(f"{file}: {where}: {p!r} is not a clean relative path")


def _parse_manifest(file: Path) -> Manifest:

    try:
        raw = tomllib.loads(file.read_text(encoding="utf-8"))
    except OSError as exc:
        raise ManifestError(f"{file}: cannot read manifest: {exc}") from exc
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise ManifestError(f"{file}: not valid TOML: {exc}") from exc
    error = jsonschema.exceptions.best_match(
        jsonschema.Draft202012Validator(MANIFEST_SCHEMA).iter_errors(raw)
    )
    if error is not None:
        raise ManifestError(f"{file}: {_where(raw, error.absolute_path)}: {error.message}")
    ds = raw["dataset"]
    if ds["name"] != file.stem:
        raise ManifestError(
            f"{file}: [dataset]: key 'name' is {ds['name']!r} but the file is {file.name}"
        )
    _check_relpath(ds["mirror_prefix"], file, "[dataset] key 'mirror_prefix'")
    archives = {n: Archive(name=n, **a) for n, a in raw.get("archives", {}).items()}
    entries, seen = [], set()
    for i, f in enumerate(raw["files"]):
        where = _where(raw, ["files", i])
        _check_relpath(f["path"], file, f"{where} key 'path'")
        if f["path"] in seen:
            raise ManifestError(f"{file}: {where}: key 'path' repeats an earlier entry")
        seen.add(f["path"])
        if ("url" in f) == ("archive" in f):
            raise ManifestError(f"{file}: {where}: give exactly one of the keys 'url', 'archive'")
        if "url" in f and "member" in f:
            raise ManifestError(f"{file}: {where}: key 'member' needs key 'archive'")
        if "archive" in f:
            if f["archive"] not in archives:
                raise ManifestError(
                    f"{file}: {where}: key 'archive' names {f['archive']!r}, "
                    f"which is not an [archives.*] table"
                )
            if "member" not in f:
                raise ManifestError(f"{file}: {where}: key 'member' is needed with 'archive'")
            _check_relpath(f["member"], file, f"{where} key 'member'")
        entries.append(FileEntry(**f))
    return Manifest(**ds, files=tuple(entries), archives=archives, source=file)


def dataset_names() -> list[str]:
    """Names of the datasets that have a manifest (sorted)."""
    return sorted(p.stem for p in paths.manifest_dir().glob("*.toml"))


def load_manifest(name: str) -> Manifest:
    """Read and check one dataset's manifest.

    Parameters
    ----------
    name : str
        Dataset name (``"authors_fbx"``, ``"hdm05"``, ``"cmu"``): the manifest is
        ``<manifest_dir>/<name>.toml`` (env ``FPDTW_MANIFEST_DIR``).

    Returns
    -------
    Manifest

    Raises
    ------
    ManifestError
        No such manifest, or it is malformed (the message names the file and key).
    """
    if not isinstance(name, str) or not re.fullmatch(r"[A-Za-z0-9_.-]+", name):
        raise ManifestError(f"{name!r} is not a dataset name")
    file = paths.manifest_dir() / f"{name}.toml"
    if not file.is_file():
        raise ManifestError(
            f"{file}: no manifest for dataset {name!r} (known: {', '.join(dataset_names())})"
        )
    return _parse_manifest(file)


def manifests() -> list[Manifest]:
    """Every dataset's manifest, sorted by name."""
    return [load_manifest(n) for n in dataset_names()]


def _as_manifest(dataset: str | Manifest) -> Manifest:
    return dataset if isinstance(dataset, Manifest) else load_manifest(dataset)


def _as_manifests(datasets) -> list[Manifest]:
    if datasets is None:
        return manifests()
    if isinstance(datasets, str | Manifest):
        datasets = [datasets]
    return [_as_manifest(d) for d in datasets]


def dataset_file_list(dataset: str | Manifest, *, available_only: bool = False) -> list[str]:
    """Paths (relative to the dataset) of every file in a manifest.

    Parameters
    ----------
    dataset : str or Manifest
    available_only : bool
        Leave out the files the manifest marks as not in the local mirror.
    """
    m = _as_manifest(dataset)
    return [e.path for e in m.files if e.available_here or not available_only]


def motion_files(dataset: str | Manifest, *, available_only: bool = False) -> list[FileEntry]:
    """Manifest entries of the motion files (takes / clips, not skeletons), in manifest order.

    Each entry carries its label: ``movement`` (authors' movement name, HDM05
    class, CMU take description), ``take`` and, for HDM05, ``actor`` and ``frames``.

    Parameters
    ----------
    dataset : str or Manifest
    available_only : bool
        Leave out the files the manifest marks as not in the local mirror.

    Returns
    -------
    list of FileEntry

    Paper: Section 4 (the authors' 21 movements x 3 takes; whole HDM05 classes).
    """
    m = _as_manifest(dataset)
    return [e for e in m.files if e.kind == "motion" and (e.available_here or not available_only)]


def skeleton_file(dataset: str | Manifest, entry: FileEntry | str) -> FileEntry | None:
    """The skeleton entry a motion file needs (HDM05: the actor's ASF), or None."""
    m = _as_manifest(dataset)
    e = m.entry(entry)
    if e.actor is None:
        return None
    hits = [s for s in m.files if s.kind == "skeleton" and s.actor == e.actor]
    return hits[0] if len(hits) == 1 else None


def cache_path(dataset: str | Manifest, path: str | FileEntry) -> Path:
    """Where a file is (or would be) cached: ``<cache>/<mirror_prefix>/<path>``."""
    m = _as_manifest(dataset)
    return paths.data_dir() / m.mirror_prefix / m.entry(path).path


# -- hashing -------------------------------------------------------------------------


def file_hashes(path: str | os.PathLike) -> dict:
    """Size, sha256 and git blob SHA-1 of a file, from one read.

    The git blob SHA-1 is ``sha1(b"blob <size>\\0" + content)``, the id git gives
    the file's content.

    Returns
    -------
    dict
        ``{"size": int, "sha256": str, "git_blob_sha1": str}`` (hex digests).
    """
    size = os.stat(path).st_size
    sha = hashlib.sha256()
    blob = hashlib.sha1(b"blob %d\0" % size)
    n = 0
    with open(path, "rb") as f:
        while chunk := f.read(1 << 20):
            sha.update(chunk)
            blob.update(chunk)
            n += len(chunk)
    if n != size:
        raise DataFetchError(f"{path}: the file changed while it was being hashed")
    return {"size": n, "sha256": sha.hexdigest(), "git_blob_sha1": blob.hexdigest()}


def _problems(e: FileEntry, h: dict) -> list[str]:
    """How hashes ``h`` differ from the entry's (empty when they match)."""
    out = []
    if e.size is not None and h.get("size") != e.size:
        out.append(f"size expected {e.size} bytes, actual {h.get('size')}")
    if e.sha256 is not None and h.get("sha256") != e.sha256:
        out.append(f"sha256 expected {e.sha256}, actual {h.get('sha256')}")
    if e.git_blob_sha1 is not None and h.get("git_blob_sha1") != e.git_blob_sha1:
        out.append(f"git blob SHA-1 expected {e.git_blob_sha1}, actual {h.get('git_blob_sha1')}")
    return out


def _check_verifiable(m: Manifest, e: FileEntry) -> None:
    if e.sha256 is None and e.git_blob_sha1 is None:
        raise DataFetchError(
            f"{m.name}: {e.path}: the manifest gives neither sha256 nor git_blob_sha1, "
            "so the file cannot be verified and is refused"
        )


@contextlib.contextmanager
def _staging(dest: Path) -> Iterator[Path]:
    """A temporary file next to ``dest``, removed on exit unless renamed into place."""
    dest.parent.mkdir(parents=True, exist_ok=True)
    fd, name = tempfile.mkstemp(prefix=TMP_PREFIX, suffix=TMP_SUFFIX, dir=dest.parent)
    os.close(fd)
    tmp = Path(name)
    try:
        yield tmp
    finally:
        tmp.unlink(missing_ok=True)


# -- sources --------------------------------------------------------------------------


def _download(url: str, tmp: Path, *, progress: bool, what: str) -> None:
    """Download ``url`` into ``tmp`` with pooch; DataFetchError if unavailable."""

    downloader = pooch.HTTPDownloader(progressbar=bool(progress), chunk_size=1 << 20)
    try:
        downloader(url, str(tmp), None)
    except requests.exceptions.HTTPError as exc:
        code = exc.response.status_code if exc.response is not None else "error"
        reason = f"HTTP {code}"
    except requests.exceptions.RequestException as exc:
        reason = f"{type(exc).__name__}: {exc}"
    else:
        return
    raise DataFetchError(f"{what}: cannot download {url} ({reason})")


def _mirror_hint(e: FileEntry) -> str:
    hint = (
        "set FPDTW_MIRROR to a folder or base URL that holds a copy, or unset it to fetch "
        "from upstream"
    )
    if not e.available_here:
        hint += (
            "; the manifest marks this file as not available in the local mirror "
            "(fetch_all(available_only=True) / `python -m fpdtw.paper.datasets fetch` "
            "without --all skip such files)"
        )
    return hint


def _from_mirror(m: Manifest, e: FileEntry, tmp: Path, mirror: str, *, progress: bool) -> str:
    what = f"{m.name}: {e.path}"
    if mirror.startswith(("http://", "https://")):
        rel = urllib.parse.quote(f"{m.mirror_prefix}/{e.path}")
        url = f"{mirror.rstrip('/')}/{rel}"
        try:
            _download(url, tmp, progress=progress, what=what)
        except DataFetchError as exc:
            raise DataFetchError(f"{exc} from FPDTW_MIRROR={mirror}; {_mirror_hint(e)}") from None
        return url
    root = Path(mirror).expanduser()
    if not root.is_dir():
        raise DataFetchError(
            f"{what}: FPDTW_MIRROR={mirror} is neither an http(s):// URL nor an existing folder"
        )
    src = root / m.mirror_prefix / e.path
    if not src.is_file():
        raise DataFetchError(
            f"{what}: not found in the mirror folder FPDTW_MIRROR={mirror} (looked for {src}); "
            f"{_mirror_hint(e)}"
        )
    try:
        shutil.copyfile(src, tmp)
    except OSError as exc:
        raise DataFetchError(f"{what}: cannot copy {src}: {exc}") from exc
    return str(src)


def _archive_path(m: Manifest, a: Archive, cache: Path, *, progress: bool) -> Path:
    """The archive in ``<cache>/_archives/``, downloaded once (verified if it has a sha256;
    every member taken from it is verified against the manifest anyway)."""
    dest = cache / ARCHIVE_DIR / a.filename
    what = f"{m.name}: archive {a.name}"
    if dest.is_file():
        return dest
    with _staging(dest) as tmp:
        try:
            _download(a.url, tmp, progress=progress, what=what)
        except DataFetchError as exc:
            raise DataFetchError(f"{exc}; {MIRROR_HINT}") from None
        h = file_hashes(tmp)
        if a.sha256 is not None and h["sha256"] != a.sha256:
            raise DataFetchError(
                f"{what} from {a.url} failed verification: sha256 expected {a.sha256}, "
                f"actual {h['sha256']}; the download was discarded"
            )
        if not zipfile.is_zipfile(tmp):
            raise DataFetchError(f"{what}: {a.url} is not a zip archive; discarded")
        os.replace(tmp, dest)
    return dest


def _find_member(zf: zipfile.ZipFile, member: str, what: str) -> zipfile.ZipInfo:
    """The archive member ``member``, or the one member ending in its last two components."""
    infos = {i.filename.replace("\\", "/"): i for i in zf.infolist() if not i.is_dir()}
    if member in infos:
        return infos[member]
    suffix = "/".join(member.split("/")[-2:])
    hits = [n for n in infos if n == suffix or n.endswith("/" + suffix)]
    if len(hits) == 1:
        return infos[hits[0]]
    if not hits:
        raise DataFetchError(f"{what}: the archive has no member {member} (nor any */{suffix})")
    raise DataFetchError(f"{what}: several archive members end in {suffix}: {sorted(hits)}")


def _from_archive(m: Manifest, e: FileEntry, tmp: Path, cache: Path, *, progress: bool) -> str:
    a = m.archives[e.archive]
    zpath = _archive_path(m, a, cache, progress=progress)
    what = f"{m.name}: {e.path}"
    try:
        with zipfile.ZipFile(zpath) as zf:
            info = _find_member(zf, e.member, what)
            with zf.open(info) as src, open(tmp, "wb") as dst:
                shutil.copyfileobj(src, dst, 1 << 20)
    except zipfile.BadZipFile as exc:
        raise DataFetchError(
            f"{what}: cannot read it from the archive {zpath} ({exc}); delete the archive to "
            "download it again"
        ) from exc
    return f"{a.url} (member {info.filename})"


# -- fetching -------------------------------------------------------------------------


def _fetch_entry(
    m: Manifest, e: FileEntry, cache: Path, *, progress: bool, archive_progress: bool
) -> Path:
    """Fetch one entry; ``progress``: per-file download bar, ``archive_progress``: archive bar.

    A cached copy is hashed on every call (no index of sizes and times that a file
    changed in place could fool): returned if it matches the manifest, else dropped and
    fetched again.
    """
    _check_verifiable(m, e)
    dest = cache / m.mirror_prefix / e.path
    if dest.is_file():
        if not _problems(e, file_hashes(dest)):
            return dest
        dest.unlink(missing_ok=True)  # stale or corrupt: fetch it again

    mirror = paths.mirror()
    with _staging(dest) as tmp:
        if mirror is not None:
            source = _from_mirror(m, e, tmp, mirror, progress=progress)
        elif e.archive is not None:
            source = _from_archive(m, e, tmp, cache, progress=archive_progress)
        else:
            try:
                _download(e.url, tmp, progress=progress, what=f"{m.name}: {e.path}")
            except DataFetchError as exc:
                raise DataFetchError(f"{exc}; {MIRROR_HINT}") from None
            source = e.url
        h = file_hashes(tmp)
        problems = _problems(e, h)
        if problems:
            raise DataFetchError(
                f"{m.name}: {e.path} from {source} failed verification: "
                f"{'; '.join(problems)}. The file was discarded."
            )
        os.chmod(tmp, 0o644)
        os.replace(tmp, dest)
    return dest


def fetch(
    dataset: str | Manifest,
    path: str | os.PathLike | FileEntry | None = None,
    *,
    progress: bool = True,
) -> Path:
    """Fetch one file into the cache (if not there yet), verified, and return its path.

    Parameters
    ----------
    dataset : str or Manifest
        Dataset name, or a manifest (e.g. one modified with :func:`dataclasses.replace`).
    path : str or os.PathLike or FileEntry, optional
        The file: its path in the manifest (``"MoCapData/Walk_01.fbx"``), its file
        name if unique (``"Walk_01.fbx"``) or its entry. May be omitted only for a
        dataset of one file (``"cmu"``).
    progress : bool
        Show a download progress bar (tqdm) for HTTP downloads.

    Returns
    -------
    Path
        ``<cache>/<mirror_prefix>/<path>``, holding exactly the manifest's content.

    Raises
    ------
    DataFetchError
        The file is not in the manifest, not available from the source tried
        (the message says how to set ``FPDTW_MIRROR``), or its content does not
        match the manifest (the message names both hashes; nothing is kept).
    """
    m = _as_manifest(dataset)
    if path is None:
        if len(m.files) != 1:
            raise DataFetchError(
                f"{m.name}: the dataset has {len(m.files)} files; name one (path=...) "
                "or use fetch_all()"
            )
        path = m.files[0]
    e = m.entry(path)
    return _fetch_entry(m, e, paths.data_dir(), progress=progress, archive_progress=progress)


@dataclass
class FetchReport:
    """What :func:`fetch_all` did.

    Attributes
    ----------
    fetched : list of Path
        Verified files now in the cache (whether copied now or already there).
    skipped : list of (str, str)
        (dataset, path) of files not tried because the manifest marks them as not
        available in the local mirror (``available_only=True``).
    failed : list of (str, str, str)
        (dataset, path, error message) of files that could not be fetched.
    seconds : float
        Wall-clock time taken.
    """

    fetched: list[Path] = field(default_factory=list)
    skipped: list[tuple[str, str]] = field(default_factory=list)
    failed: list[tuple[str, str, str]] = field(default_factory=list)
    seconds: float = 0.0

    @property
    def ok(self) -> bool:
        """True when no file that was tried failed."""
        return not self.failed

    def summary(self) -> str:
        """A few human-readable lines."""
        lines = [f"{len(self.fetched)} files verified in the cache ({self.seconds:.1f} s)"]
        if self.skipped:
            lines.append(f"{len(self.skipped)} skipped (not available in the local mirror):")
            lines += [f"  {d}: {p}" for d, p in self.skipped]
        if self.failed:
            lines.append(f"{len(self.failed)} FAILED:")
            lines += [f"  {msg}" for _, _, msg in self.failed]
        return "\n".join(lines)


def fetch_all(
    datasets: str | Manifest | Iterable[str | Manifest] | None = None,
    *,
    available_only: bool | None = None,
    progress: bool = True,
    strict: bool = True,
) -> FetchReport:
    """Fetch every file of some datasets, verified; report what could not be had.

    Parameters
    ----------
    datasets : str, Manifest or iterable of them, optional
        Datasets to fetch (default: every manifest).
    available_only : bool, optional
        Skip (and list in the report) the files the manifest marks as not available
        in the local mirror. Default: True when ``FPDTW_MIRROR`` is set, False
        otherwise (upstream has every file).
    progress : bool
        Show a tqdm progress bar over the files (and for archive downloads).
    strict : bool
        After trying every file, raise DataFetchError if any failed (the report
        is attached as the exception's ``report`` attribute). With False, return
        the report and let the caller look at ``report.failed``.

    Returns
    -------
    FetchReport
    """
    ms = _as_manifests(datasets)
    if available_only is None:
        available_only = paths.mirror() is not None
    report = FetchReport()
    t0 = time.perf_counter()
    cache = paths.data_dir()
    todo = []
    for m in ms:
        for e in m.files:
            if available_only and not e.available_here:
                report.skipped.append((m.name, e.path))
            else:
                todo.append((m, e))
    bar = None
    if progress:
        bar = tqdm(total=len(todo), unit="file", desc="fetch", leave=True)
    try:
        for m, e in todo:
            if bar is not None:
                bar.set_postfix_str(m.name, refresh=False)
            try:
                p = _fetch_entry(m, e, cache, progress=False, archive_progress=progress)
                report.fetched.append(p)
            except DataFetchError as exc:
                report.failed.append((m.name, e.path, str(exc)))
            if bar is not None:
                bar.update()
    finally:
        if bar is not None:
            bar.close()
    report.seconds = time.perf_counter() - t0
    if strict and report.failed:
        exc = DataFetchError(report.summary())
        exc.report = report
        raise exc
    return report


# -- verification and citation --------------------------------------------------------


@dataclass
class VerifyReport:
    """What :func:`verify` found in the cache.

    Attributes
    ----------
    verified : list of str
        Cache-relative paths whose content matches the manifest.
    corrupt : list of (str, str)
        Cache-relative path and what differs (expected and actual hashes).
    missing : list of str
        Manifest files that should be in the cache and are not.
    skipped : list of str
        Manifest files not in the cache that the manifest marks as not available in
        the local mirror, when only the available ones are checked (as ``fetch`` without
        ``--all`` fetches only those).
    extra : list of str
        Files in a dataset's cache folder that no manifest lists (e.g. stray
        temporary files).
    """

    verified: list[str] = field(default_factory=list)
    corrupt: list[tuple[str, str]] = field(default_factory=list)
    missing: list[str] = field(default_factory=list)
    skipped: list[str] = field(default_factory=list)
    extra: list[str] = field(default_factory=list)

    @property
    def ok(self) -> bool:
        """True when every file checked is in the cache and matches the manifest."""
        return not self.corrupt and not self.missing

    def summary(self, *, show: int = 10) -> str:
        """A few human-readable lines (at most ``show`` missing files listed)."""
        lines = [
            f"{len(self.verified)} verified, {len(self.corrupt)} corrupt, "
            f"{len(self.missing)} missing, {len(self.skipped)} skipped (not in the local "
            f"mirror), {len(self.extra)} unlisted"
        ]
        lines += [f"  CORRUPT {p}: {why}" for p, why in self.corrupt]
        lines += [f"  MISSING {p}" for p in self.missing[:show]]
        if len(self.missing) > show:
            lines.append(f"  ... and {len(self.missing) - show} more missing")
        lines += [f"  unlisted {p}" for p in self.extra]
        if not self.ok:
            bad = len(self.corrupt) + len(self.missing)
            checked = bad + len(self.verified)
            lines.append(
                f"FAILED: {bad} of {checked} files missing or wrong; `fpdtw data fetch` "
                "fetches them again"
            )
        return "\n".join(lines)


def verify(
    dataset: str | Manifest | Iterable[str | Manifest] | None = None,
    *,
    available_only: bool | None = None,
) -> VerifyReport:
    """Re-hash every cached file of some datasets and compare with the manifests.

    Reads every file. Corrupt files are reported, not deleted (the next :func:`fetch`
    replaces them); files that should be cached and are not are reported as missing.
    The report is :attr:`~VerifyReport.ok` only when nothing is missing or wrong.

    Parameters
    ----------
    dataset : str, Manifest or iterable of them, optional
        Default: every manifest.
    available_only : bool, optional
        Count a file the manifest marks as not available in the local mirror as
        skipped, not missing, when it is not cached. Default: True when
        ``FPDTW_MIRROR`` is set, False otherwise (as :func:`fetch_all`).

    Returns
    -------
    VerifyReport
    """
    cache = paths.data_dir()
    if available_only is None:
        available_only = paths.mirror() is not None
    report = VerifyReport()
    for m in _as_manifests(dataset):
        listed = set()
        for e in m.files:
            key = f"{m.mirror_prefix}/{e.path}"
            listed.add(key)
            p = cache / key
            if not p.is_file():
                skip = available_only and not e.available_here
                (report.skipped if skip else report.missing).append(key)
                continue
            problems = _problems(e, file_hashes(p))
            if e.sha256 is None and e.git_blob_sha1 is None:
                problems = ["the manifest gives no hash to verify it by"]
            if problems:
                report.corrupt.append((key, "; ".join(problems)))
            else:
                report.verified.append(key)
        root = cache / m.mirror_prefix
        if root.is_dir():
            for p in sorted(root.rglob("*")):
                key = p.relative_to(cache).as_posix()
                if p.is_file() and key not in listed:
                    report.extra.append(key)
    return report


def cite(dataset: str | Manifest | Iterable[str | Manifest] | None = None) -> str:
    """Title, licence, citation and source of some datasets, as plain text.

    Parameters
    ----------
    dataset : str, Manifest or iterable of them, optional
        Default: every manifest.
    """
    blocks = []
    for m in _as_manifests(dataset):
        blocks.append(
            f"{m.name}: {m.title}\n"
            f"  Licence: {m.licence}\n"
            f"  Cite: {m.citation}\n"
            f"  Source: {m.upstream}"
        )
    return "\n\n".join(blocks)


# -- command line ---------------------------------------------------------------------


class _Parser(argparse.ArgumentParser):
    def error(self, message):  # exit code 1 (not argparse's 2) on bad usage
        self.print_usage(sys.stderr)
        self.exit(1, f"{self.prog}: error: {message}\n")


def add_data_commands(sub) -> None:
    """Add the actions ``fetch``, ``verify`` and ``cite`` to an argparse subparsers object.

    Used by this module's own command line and by ``fpdtw data`` (one set of options).
    """
    help_ds = "dataset name, repeatable (authors_fbx, hdm05, cmu; default: all)"
    help_all = (
        "files the manifest marks as not in the local mirror "
        "(the default when FPDTW_MIRROR is unset)"
    )
    f = sub.add_parser("fetch", help="fetch files into the cache, verified by hash")
    f.add_argument("--dataset", action="append", help=help_ds)
    f.add_argument("--all", action="store_true", help="also try the " + help_all)
    f.add_argument("--file", help="fetch only this file (needs one --dataset)")
    f.add_argument("--quiet", action="store_true", help="no progress bars")
    v = sub.add_parser(
        "verify",
        help="re-hash every cached file; exit 1 if any listed file is missing or wrong",
    )
    v.add_argument("--dataset", action="append", help=help_ds)
    v.add_argument("--all", action="store_true", help="also require the " + help_all)
    c = sub.add_parser("cite", help="print licences and citations")
    c.add_argument("--dataset", action="append", help=help_ds)


def run_data_command(args, prog: str) -> int:
    """Carry out ``fetch``, ``verify`` or ``cite`` (``args.data_command``); the exit code.

    0 on success; 1 when a file is missing, fails its hash or cannot be fetched; 2 on a
    usage error argparse cannot express (``--file`` without exactly one ``--dataset``).
    Errors are printed to stderr, each line starting with ``prog``.
    """
    command = args.data_command
    if command == "fetch" and args.file is not None and len(args.dataset or []) != 1:
        print(f"{prog}: error: fetch --file needs exactly one --dataset", file=sys.stderr)
        return 2
    try:
        if command == "cite":
            print(cite(args.dataset))
            return 0
        if command == "verify":
            report = verify(args.dataset, available_only=None if not args.all else False)
            print(f"cache {paths.data_dir()}: {report.summary()}")
            return 0 if report.ok else 1
        mirror = paths.mirror()
        print(
            f"cache {paths.data_dir()}; source: "
            + (f"FPDTW_MIRROR={mirror}" if mirror else "upstream URLs"),
            file=sys.stderr,
        )
        if args.file is not None:
            print(fetch(args.dataset[0], args.file, progress=not args.quiet))
            return 0
        report = fetch_all(
            args.dataset,
            available_only=None if not args.all else False,
            progress=not args.quiet,
            strict=False,
        )
        print(report.summary())
        return 0 if report.ok else 1
    except (DataFetchError, ManifestError) as exc:
        print(f"{prog}: error: {exc}", file=sys.stderr)
        return 1


def main(argv: list[str] | None = None, prog: str = "python -m fpdtw.paper.datasets") -> int:
    """Command line: ``python -m fpdtw.paper.datasets fetch|verify|cite``; returns the exit code.

    The same actions as ``fpdtw data`` (see :func:`add_data_commands`).
    """
    ap = _Parser(prog=prog, description="Fetch, verify and cite the datasets.")
    sub = ap.add_subparsers(dest="data_command", required=True, parser_class=_Parser)
    add_data_commands(sub)
    return run_data_command(ap.parse_args(argv), prog)


if __name__ == "__main__":
    sys.exit(main())
