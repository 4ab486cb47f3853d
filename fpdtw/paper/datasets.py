"""Data manifests and verified fetching of the motion datasets (the guarantee: ``docs/data.md``).

One TOML manifest per dataset in ``data_manifest/`` (its README: the keys). :func:`fetch` puts
a verified file into the cache, ``<cache>/<mirror_prefix>/<path>``, from ``FPDTW_MIRROR`` (a
folder or base URL) if set, else from its ``url`` or its member of an archive (kept in
``<cache>/_archives/``). Command line: ``fpdtw data fetch|verify|cite``.
"""

from __future__ import annotations

import contextlib
import hashlib
import os
import re
import shutil
import tempfile
import tomllib
import urllib.parse
import zipfile
from collections.abc import Iterable, Iterator
from dataclasses import dataclass, field
from pathlib import Path, PurePosixPath

import jsonschema
import pooch
import requests

from fpdtw.errors import FpdtwError
from fpdtw.paper import paths

ARCHIVE_DIR = "_archives"  # cache sub-folder of downloaded archives
#: Prefix and suffix of temporary files (never left behind).
TMP_PREFIX, TMP_SUFFIX = ".fpdtw-", ".part"

MIRROR_HINT = (
    "no network here? set FPDTW_MIRROR to a folder or base URL holding a copy laid out as "
    "<mirror>/<dataset folder>/<path> (for example FPDTW_MIRROR=/path/to/a/copy)"
)


class DataFetchError(FpdtwError, RuntimeError):
    """A data file could not be fetched or failed verification against the manifest."""


class ManifestError(FpdtwError, ValueError):
    """A data manifest file is malformed."""


@dataclass(frozen=True)
class FileEntry:
    """One file of a dataset, as its manifest lists it (keys: ``data_manifest/README.md``)."""

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
        """File name without folders (``"Walk_01.fbx"``)."""
        return PurePosixPath(self.path).name


@dataclass(frozen=True)
class Archive:
    """An upstream archive some files are extracted from (the HDM05 cut library)."""

    name: str
    url: str
    sha256: str | None = None


@dataclass(frozen=True)
class Manifest:
    """A dataset's manifest: dataset-level metadata and its files."""

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
        """The entry with this path (or, if unique, this file name); DataFetchError if none."""
        if isinstance(path, FileEntry):
            return path
        p = PurePosixPath(str(path).replace("\\", "/")).as_posix()
        hits = [e for e in self.files if e.path == p] or [e for e in self.files if e.name == p]
        if len(hits) == 1:
            return hits[0]
        what = "matches several files" if hits else "is not a file of this dataset"
        raise DataFetchError(f"{self.name}: {p!r} {what} (see manifest {self.source})")


_DATASET_KEYS = ("name", "title", "mirror_prefix", "licence", "citation", "upstream", "notes")
_STR, _COUNT = {"type": "string"}, {"type": "integer", "minimum": 0}
_URL = {"type": "string", "pattern": "^https?://"}
_SHA256 = {"type": "string", "pattern": "^[0-9a-f]{64}$"}


def _table(required: list, properties: dict) -> dict:
    return {
        "type": "object",
        "additionalProperties": False,
        "required": required,
        "properties": properties,
    }


#: The manifest's JSON Schema; what it cannot say (clean paths, one source per file,
#: archives that exist) is checked in :func:`_parse_manifest`.
MANIFEST_SCHEMA = _table(["dataset", "files"], {
    "dataset": _table(list(_DATASET_KEYS), dict.fromkeys(_DATASET_KEYS, _STR)),
    "archives": {
        "type": "object",
        "additionalProperties": _table(
            ["url"], {"url": _URL, "sha256": _SHA256, "approx_size": _STR, "notes": _STR}
        ),
    },
    "files": {"type": "array", "minItems": 1, "items": _table(["path", "kind"], {
        "path": _STR, "kind": {"enum": ["motion", "skeleton"]}, "url": _URL, "archive": _STR,
        "member": _STR, "size": _COUNT, "sha256": _SHA256,
        "git_blob_sha1": {"type": "string", "pattern": "^[0-9a-f]{40}$"}, "movement": _STR,
        "take": _STR, "actor": _STR, "frames": _COUNT, "available_here": {"type": "boolean"},
    })},
})  # fmt: skip


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
    archives = {
        n: Archive(n, a["url"], a.get("sha256")) for n, a in raw.get("archives", {}).items()
    }
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
    """Read and check ``<manifest_dir>/<name>.toml`` (``"authors_fbx"``, ``"hdm05"``,
    ``"cmu"``); ManifestError, naming the file and key, if it is missing or malformed."""
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


#: One dataset or several, by name or manifest (None: every manifest).
Datasets = str | Manifest | Iterable[str | Manifest] | None


def _as_manifest(dataset: str | Manifest) -> Manifest:
    return dataset if isinstance(dataset, Manifest) else load_manifest(dataset)


def as_manifests(datasets: Datasets) -> list[Manifest]:
    if datasets is None:
        return manifests()
    if isinstance(datasets, str | Manifest):
        datasets = [datasets]
    return [_as_manifest(d) for d in datasets]


def motion_files(dataset: str | Manifest, *, available_only: bool = False) -> list[FileEntry]:
    """Entries of the motion files (not skeletons) in manifest order (``available_only``: here).

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


def file_hashes(path: str | os.PathLike) -> dict:
    """``{"size", "sha256", "git_blob_sha1"}`` of a file from one read (the blob SHA-1 is
    git's id of the content, ``sha1(b"blob <size>\\0" + content)``)."""
    size = os.stat(path).st_size
    sha = hashlib.sha256()
    blob = hashlib.sha1(b"blob %d\0" % size)
    with open(path, "rb") as f:
        while chunk := f.read(1 << 20):
            sha.update(chunk)
            blob.update(chunk)
        n = f.tell()
    if n != size:
        raise DataFetchError(f"{path}: the file changed while it was being hashed")
    return {"size": n, "sha256": sha.hexdigest(), "git_blob_sha1": blob.hexdigest()}


def hash_problems(e: FileEntry, h: dict) -> list[str]:
    """How hashes ``h`` differ from the entry's (empty when they match)."""
    labels = {"size": "size", "sha256": "sha256", "git_blob_sha1": "git blob SHA-1"}
    return [
        f"{label} expected {getattr(e, k)}{' bytes' * (k == 'size')}, actual {h.get(k)}"
        for k, label in labels.items()
        if getattr(e, k) is not None and h.get(k) != getattr(e, k)
    ]


@contextlib.contextmanager
def _staging(dest: Path) -> Iterator[Path]:
    """A temporary file next to ``dest``, renamed to ``dest`` if the block ends without an
    error, else removed."""
    dest.parent.mkdir(parents=True, exist_ok=True)
    fd, name = tempfile.mkstemp(prefix=TMP_PREFIX, suffix=TMP_SUFFIX, dir=dest.parent)
    os.close(fd)
    tmp = Path(name)
    try:
        yield tmp
        os.replace(tmp, dest)
    finally:
        tmp.unlink(missing_ok=True)


def _download(url: str, tmp: Path, *, progress: bool, what: str, hint: str) -> None:
    """Download ``url`` into ``tmp`` with pooch; DataFetchError (ending in ``hint``) if not."""
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
    raise DataFetchError(f"{what}: cannot download {url} ({reason}){hint}")


def _mirror_hint(e: FileEntry) -> str:
    hint = (
        "set FPDTW_MIRROR to a folder or base URL that holds a copy, or unset it to fetch "
        "from upstream"
    )
    if not e.available_here:
        hint += (
            "; the manifest marks this file as not available in the local mirror "
            "(fetch_all(available_only=True) / `fpdtw data fetch` without --all skip such "
            "files)"
        )
    return hint


def _from_mirror(m: Manifest, e: FileEntry, tmp: Path, mirror: str, what: str, progress) -> str:
    if mirror.startswith(("http://", "https://")):
        rel = urllib.parse.quote(f"{m.mirror_prefix}/{e.path}")
        url = f"{mirror.rstrip('/')}/{rel}"
        hint = f" from FPDTW_MIRROR={mirror}; {_mirror_hint(e)}"
        _download(url, tmp, progress=progress, what=what, hint=hint)
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
    """The archive in ``<cache>/_archives/``, downloaded once (checked by its sha256 if given)."""
    name = PurePosixPath(urllib.parse.urlsplit(a.url).path).name or f"{a.name}.zip"
    dest = cache / ARCHIVE_DIR / name
    what = f"{m.name}: archive {a.name}"
    if dest.is_file():
        return dest
    with _staging(dest) as tmp:
        _download(a.url, tmp, progress=progress, what=what, hint=f"; {MIRROR_HINT}")
        h = file_hashes(tmp)
        if a.sha256 is not None and h["sha256"] != a.sha256:
            raise DataFetchError(
                f"{what} from {a.url} failed verification: sha256 expected {a.sha256}, "
                f"actual {h['sha256']}; the download was discarded"
            )
        if not zipfile.is_zipfile(tmp):
            raise DataFetchError(f"{what}: {a.url} is not a zip archive; discarded")
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


def _from_archive(m: Manifest, e: FileEntry, tmp: Path, cache: Path, what: str, progress) -> str:
    a = m.archives[e.archive]
    zpath = _archive_path(m, a, cache, progress=progress)
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


def fetch_entry(
    m: Manifest, e: FileEntry, cache: Path, *, progress: bool, archive_progress: bool
) -> Path:
    """Fetch one entry; ``progress``: per-file download bar, ``archive_progress``: archive
    bar. A cached copy is hashed on every call: returned if it matches, else fetched again."""
    if e.sha256 is None and e.git_blob_sha1 is None:
        raise DataFetchError(
            f"{m.name}: {e.path}: the manifest gives neither sha256 nor git_blob_sha1, "
            "so the file cannot be verified and is refused"
        )
    dest = cache / m.mirror_prefix / e.path
    if dest.is_file():
        if not hash_problems(e, file_hashes(dest)):
            return dest
        dest.unlink(missing_ok=True)  # stale or corrupt: fetch it again

    mirror = paths.mirror()
    what = f"{m.name}: {e.path}"
    with _staging(dest) as tmp:
        if mirror is not None:
            source = _from_mirror(m, e, tmp, mirror, what, progress)
        elif e.archive is not None:
            source = _from_archive(m, e, tmp, cache, what, archive_progress)
        else:
            _download(e.url, tmp, progress=progress, what=what, hint=f"; {MIRROR_HINT}")
            source = e.url
        problems = hash_problems(e, file_hashes(tmp))
        if problems:
            raise DataFetchError(
                f"{what} from {source} failed verification: {'; '.join(problems)}. "
                "The file was discarded."
            )
        os.chmod(tmp, 0o644)
    return dest


def fetch(
    dataset: str | Manifest, path: str | os.PathLike | FileEntry | None = None, *, progress=True
) -> Path:
    """The path of one file in the cache, fetched if not there yet, verified against the manifest.

    ``path``: its path in the manifest (``"MoCapData/Walk_01.fbx"``), its name if unique or its
    entry; omitted only for a dataset of one file. DataFetchError: not in the manifest, not
    available from the source tried (the message names ``FPDTW_MIRROR``) or not matching.
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
    return fetch_entry(m, e, paths.data_dir(), progress=progress, archive_progress=progress)
