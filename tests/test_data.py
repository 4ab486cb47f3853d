"""Data manifests and verified fetching (fpdtw.paper.datasets).

No network: HTTP is served from 127.0.0.1 by a thread of this process, and every
test uses its own cache folder under tmp_path.
"""

from __future__ import annotations

import contextlib
import dataclasses
import functools
import hashlib
import os
import re
import socket
import threading
import time
import zipfile
from http.server import SimpleHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path

import pytest

from fpdtw.app import cli, commands
from fpdtw.paper import datasets as data

AUTHORS_URL = (
    "https://raw.githubusercontent.com/matRandall/Mocap_SinglePersonActions/"
    "534d0172f4a424194aced7d3b45bd17012b2e3a9/"
)
CMU_URL = (
    "https://raw.githubusercontent.com/414Group/Rotate/"
    "faaaffc37b3a8f68439cd88456400ad30cd00e69/18_01.bvh"
)
MISSING_MOVEMENTS = {
    "Jaunty_Style_Walk",
    "Slow_Walk",
    "Sneaky_Style_Walk",
    "Stepping_Stones_Walks",
    "Stiff_Style_Walk",
}
CLIP_A = "HDM05_cut_amc/squat1Reps/HDM_bd_squat1Reps_001_120.amc"
CLIP_B = "HDM05_cut_amc/kickLFront1Reps/HDM_bd_kickLFront1Reps_001_120.amc"
CLIP_JUNK = "HDM05_cut_amc/squat1Reps/HDM_bk_squat1Reps_013_120.amc"


# -- helpers --------------------------------------------------------------------------


@pytest.fixture
def cache(tmp_path, monkeypatch) -> Path:
    """An empty cache folder; FPDTW_MIRROR unset (tests set it when they want it)."""
    c = tmp_path / "cache"
    monkeypatch.setenv("FPDTW_DATA_DIR", str(c))
    monkeypatch.delenv("FPDTW_MIRROR", raising=False)
    monkeypatch.delenv("FPDTW_MANIFEST_DIR", raising=False)
    return c


@contextlib.contextmanager
def serve(directory: Path):
    """Serve ``directory`` over HTTP on 127.0.0.1; yields (base URL, list of GET paths)."""
    hits: list[str] = []

    class Handler(SimpleHTTPRequestHandler):
        def log_message(self, *args):  # keep the test output clean
            pass

        def do_GET(self):
            hits.append(self.path)
            super().do_GET()

    server = ThreadingHTTPServer(
        ("127.0.0.1", 0), functools.partial(Handler, directory=str(directory))
    )
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    try:
        yield f"http://127.0.0.1:{server.server_address[1]}", hits
    finally:
        server.shutdown()
        server.server_close()
        thread.join()


def files_under(folder: Path) -> list[str]:
    """Every file under ``folder``, as sorted POSIX paths relative to it."""
    if not folder.exists():
        return []
    return sorted(p.relative_to(folder).as_posix() for p in folder.rglob("*") if p.is_file())


def sha256_of(path: Path) -> str:
    with open(path, "rb") as f:
        return hashlib.file_digest(f, "sha256").hexdigest()


def flip_byte(path: Path, offset: int = 100) -> None:
    """Change one byte in place (same size)."""
    b = bytearray(path.read_bytes())
    b[offset] ^= 0x01
    path.write_bytes(bytes(b))


def tampered_copy(src: Path, dst: Path) -> None:
    dst.parent.mkdir(parents=True, exist_ok=True)
    dst.write_bytes(src.read_bytes())
    flip_byte(dst)


def count_hashing(monkeypatch) -> list[str]:
    """Make fpdtw.paper.datasets.file_hashes record every file it hashes."""
    calls: list[str] = []
    real = data.file_hashes

    def counting(path):
        calls.append(str(path))
        return real(path)

    monkeypatch.setattr(data, "file_hashes", counting)
    return calls


def no_temp_files(folder: Path) -> bool:
    return not any(p.name.startswith(data.TMP_PREFIX) for p in folder.rglob("*"))


# -- manifests ------------------------------------------------------------------------


def test_manifest_names_and_counts():
    ms = {m.name: m for m in data.manifests()}
    assert sorted(ms) == ["authors_fbx", "cmu", "hdm05"]

    a = ms["authors_fbx"]
    assert a.mirror_prefix == "mocap_single_person_actions"
    assert len(a.files) == 63
    assert sum(e.sha256 is not None for e in a.files) == 48
    assert all(e.git_blob_sha1 is not None for e in a.files)
    # exactly the 15 takes without a sha256 are the ones not available here
    assert {e.path for e in a.files if not e.available_here} == {
        e.path for e in a.files if e.sha256 is None
    }
    assert {e.movement for e in a.files if not e.available_here} == MISSING_MOVEMENTS
    movements = {}
    for e in a.files:
        movements.setdefault(e.movement, []).append(e.take)
    assert len(movements) == 21 and all(len(t) == 3 for t in movements.values())
    assert a.entry("3_Jumps_02_.fbx").movement == "3_Jumps"
    assert a.entry("3_Jumps_02_.fbx").take == "02"
    assert movements["Twirls"] == ["02", "03", "04"]
    assert movements["1_Punch_1_Kick"] == ["01", "02", "03"]
    assert all(e.url == AUTHORS_URL + e.path for e in a.files)
    assert a.licence == "Open Data Commons Attribution (ODC-By)"

    h = ms["hdm05"]
    skel = [e for e in h.files if e.kind == "skeleton"]
    clips = [e for e in h.files if e.kind == "motion"]
    assert len(skel) == 5 and len(clips) == 287
    assert {e.actor for e in skel} == {"bd", "bk", "dg", "mm", "tr"}
    assert all(
        e.url == f"http://resources.mpi-inf.mpg.de/HDM05/asf/HDM_{e.actor}.asf"
        and e.path == f"HDM05_cut_amc/HDM_{e.actor}.asf"
        for e in skel
    )
    assert len({e.movement for e in clips}) == 11
    assert {e.actor for e in clips} == {"bd", "bk", "dg", "mm", "tr"}
    for e in clips:
        assert e.archive == "cut_amc" and e.url is None
        assert e.member == e.path == f"HDM05_cut_amc/{e.movement}/{e.name}"
        assert e.name == f"HDM_{e.actor}_{e.movement}_{e.take}_120.amc"
        assert e.frames > 0
    assert h.archives["cut_amc"].url == "http://resources.mpi-inf.mpg.de/HDM05/HDM05_cut_amc.zip"
    assert h.archives["cut_amc"].sha256 is None
    assert h.licence == "CC BY-SA 3.0 Unported"

    c = ms["cmu"]
    assert [e.path for e in c.files] == ["18_01.bvh"]
    assert c.files[0].url == CMU_URL
    assert "http://mocap.cs.cmu.edu/subjects/18/18_01.amc" in c.notes
    assert "NSF EIA-0196217" in c.citation


def test_every_hash_is_well_formed():
    for m in data.manifests():
        for e in m.files:
            assert e.sha256 is None or re.fullmatch(r"[0-9a-f]{64}", e.sha256), e.path
            assert e.git_blob_sha1 is None or re.fullmatch(r"[0-9a-f]{40}", e.git_blob_sha1)
            assert e.sha256 is not None or e.git_blob_sha1 is not None, e.path


def test_manifests_match_the_mirror(mirror_root):
    """Every mirror file's size and sha256 (independent hashlib) equal the manifest, and
    the mirror holds exactly the files the manifests mark as available."""
    for m in data.manifests():
        root = mirror_root / m.mirror_prefix
        for e in m.files:
            p = root / e.path
            assert p.is_file() == e.available_here, p
            if not e.available_here:
                continue
            assert p.stat().st_size == e.size, p
            assert sha256_of(p) == e.sha256, p
            if e.git_blob_sha1 is not None:
                content = p.read_bytes()
                blob = hashlib.sha1(b"blob %d\0" % len(content) + content).hexdigest()
                assert blob == e.git_blob_sha1, p
        on_disk = {f for f in files_under(root) if f.endswith((".fbx", ".amc", ".asf", ".bvh"))}
        assert on_disk == {e.path for e in m.files if e.available_here}


def test_file_hashes_known_answers(tmp_path):
    empty = tmp_path / "empty"
    empty.write_bytes(b"")
    hello = tmp_path / "hello"
    hello.write_bytes(b"hello\n")
    # `git hash-object` of these two contents, and the published sha256 values
    assert data.file_hashes(empty) == {
        "size": 0,
        "sha256": "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855",
        "git_blob_sha1": "e69de29bb2d1d6434b8b29ae775ad8c2e48c5391",
    }
    assert data.file_hashes(hello) == {
        "size": 6,
        "sha256": "5891b5b522d5df086d0ff0b110fbd9d21bb4fc7163af34d08286a2e846f6be03",
        "git_blob_sha1": "ce013625030ba8dba906f756967f9e9ca394464a",
    }


def test_labels_and_helpers():
    clips = data.motion_files("hdm05")
    assert len(clips) == 287 and all(e.kind == "motion" and e.movement for e in clips)
    assert len(data.motion_files("authors_fbx")) == 63
    assert len(data.motion_files("authors_fbx", available_only=True)) == 48
    assert len(data.load_manifest("hdm05").files) == 292
    asf = data.skeleton_file("hdm05", CLIP_A)
    assert asf.path == "HDM05_cut_amc/HDM_bd.asf"
    assert data.skeleton_file("cmu", "18_01.bvh") is None
    text = commands.cite()
    for m in data.manifests():
        assert m.licence in text and m.citation in text
    assert commands.cite("cmu").count("Licence:") == 1


_GOOD = """
[dataset]
name = "toy"
title = "t"
mirror_prefix = "toy"
licence = "l"
citation = "c"
upstream = "u"
notes = "n"
[[files]]
path = "a/b.bvh"
url = "https://example.org/b.bvh"
kind = "motion"
sha256 = "%s"
""" % ("0" * 64)


@pytest.mark.parametrize(
    "text, needle",
    [
        (_GOOD.replace('notes = "n"', 'notes = "n'), "not valid TOML"),
        (_GOOD.replace('licence = "l"\n', ""), "'licence'"),
        (_GOOD.replace('"' + "0" * 64 + '"', '"abc"'), "'sha256'"),
        (_GOOD.replace('kind = "motion"', 'kind = "motion"\ncolour = "red"'), "'colour'"),
        (_GOOD.replace('kind = "motion"', 'kind = "motion"\narchive = "x"'), "'url'"),
        (_GOOD.replace('name = "toy"', 'name = "other"'), "'name'"),
        (_GOOD.replace('path = "a/b.bvh"', 'path = "../b.bvh"'), "'path'"),
        (_GOOD.replace('kind = "motion"', "kind = 3"), "'kind'"),
        (_GOOD.replace('kind = "motion"', 'kind = "motion"\nsize = true'), "'size'"),
        (_GOOD + _GOOD[_GOOD.index("[[files]]") :], "repeats"),
    ],
)
def test_malformed_manifest_names_file_and_key(tmp_path, monkeypatch, text, needle):
    monkeypatch.setenv("FPDTW_MANIFEST_DIR", str(tmp_path))
    (tmp_path / "toy.toml").write_text(text)
    with pytest.raises(data.ManifestError) as info:
        data.load_manifest("toy")
    assert "toy.toml" in str(info.value) and needle in str(info.value)


def test_good_toy_manifest_and_unknown_name(tmp_path, monkeypatch):
    monkeypatch.setenv("FPDTW_MANIFEST_DIR", str(tmp_path))
    (tmp_path / "toy.toml").write_text(_GOOD)
    m = data.load_manifest("toy")
    assert m.files[0].path == "a/b.bvh" and m.files[0].available_here
    with pytest.raises(data.ManifestError, match="no manifest for dataset 'nope'"):
        data.load_manifest("nope")


# -- fetching -------------------------------------------------------------------------


def test_fetch_over_http_mirror(mirror_root, cache, monkeypatch):
    with serve(mirror_root) as (base, hits):
        monkeypatch.setenv("FPDTW_MIRROR", base)
        for name, path in [("authors_fbx", "Walk_01.fbx"), ("hdm05", CLIP_A), ("cmu", None)]:
            m = data.load_manifest(name)
            e = m.entry(path) if path else m.files[0]
            p = data.fetch(name, path, progress=False)
            assert p == cache / m.mirror_prefix / e.path
            assert sha256_of(p) == e.sha256
            assert p.read_bytes() == (mirror_root / m.mirror_prefix / e.path).read_bytes()
    assert len(hits) == 3
    assert no_temp_files(cache)


def test_fetch_from_mirror_folder_and_path_forms(mirror_root, cache, monkeypatch):
    monkeypatch.setenv("FPDTW_MIRROR", str(mirror_root))
    p = data.fetch("authors_fbx", "MoCapData/3_Jumps_02_.fbx", progress=False)
    assert p == cache / "mocap_single_person_actions" / "MoCapData" / "3_Jumps_02_.fbx"
    assert sha256_of(p) == data.load_manifest("authors_fbx").entry(p.name).sha256
    with pytest.raises(data.DataFetchError, match="292 files"):
        data.fetch("hdm05")
    with pytest.raises(data.DataFetchError, match="not a file of this dataset"):
        data.fetch("hdm05", "nothing.amc")


@pytest.mark.parametrize("over", ["folder", "http"])
def test_tampered_file_is_refused(mirror_root, cache, tmp_path, monkeypatch, over):
    fake = tmp_path / "fake_mirror"
    tampered_copy(mirror_root / "cmu" / "18_01.bvh", fake / "cmu" / "18_01.bvh")
    expected = data.load_manifest("cmu").files[0].sha256
    actual = sha256_of(fake / "cmu" / "18_01.bvh")
    assert actual != expected
    with contextlib.ExitStack() as stack:
        if over == "http":
            base, _ = stack.enter_context(serve(fake))
            monkeypatch.setenv("FPDTW_MIRROR", base)
        else:
            monkeypatch.setenv("FPDTW_MIRROR", str(fake))
        with pytest.raises(data.DataFetchError) as info:
            data.fetch("cmu", progress=False)
    msg = str(info.value)
    assert "cmu" in msg and "18_01.bvh" in msg and expected in msg and actual in msg
    assert files_under(cache) == []  # no file, no temp file, nothing recorded


def test_missing_file_names_file_and_mirror(mirror_root, cache, monkeypatch):
    monkeypatch.setenv("FPDTW_MIRROR", str(mirror_root))
    with pytest.raises(data.DataFetchError) as info:
        data.fetch("authors_fbx", "Slow_Walk_01.fbx", progress=False)
    msg = str(info.value)
    assert "Slow_Walk_01.fbx" in msg and "FPDTW_MIRROR" in msg and str(mirror_root) in msg
    with serve(mirror_root) as (base, _):
        monkeypatch.setenv("FPDTW_MIRROR", base)
        with pytest.raises(data.DataFetchError) as info:
            data.fetch("authors_fbx", "Slow_Walk_01.fbx", progress=False)
    msg = str(info.value)
    assert "HTTP 404" in msg and "FPDTW_MIRROR" in msg and "Slow_Walk_01.fbx" in msg
    monkeypatch.setenv("FPDTW_MIRROR", str(mirror_root / "no_such_folder"))
    with pytest.raises(data.DataFetchError, match="neither an http"):
        data.fetch("cmu", progress=False)
    assert files_under(cache) == []


def test_upstream_unreachable_says_how_to_set_mirror(cache):
    with socket.socket() as s:  # a port nobody listens on
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    m = data.load_manifest("cmu")
    m = dataclasses.replace(
        m, files=(dataclasses.replace(m.files[0], url=f"http://127.0.0.1:{port}/x.bvh"),)
    )
    with pytest.raises(data.DataFetchError) as info:
        data.fetch(m, progress=False)
    msg = str(info.value)
    assert "18_01.bvh" in msg and f"127.0.0.1:{port}" in msg and "set FPDTW_MIRROR" in msg
    assert files_under(cache) == []


def test_upstream_url_without_mirror(mirror_root, cache):
    m = data.load_manifest("cmu")
    with serve(mirror_root / "cmu") as (base, hits):
        e = dataclasses.replace(m.files[0], url=f"{base}/18_01.bvh")
        p = data.fetch(dataclasses.replace(m, files=(e,)), progress=False)
    assert hits == ["/18_01.bvh"]
    assert sha256_of(p) == e.sha256 and p == cache / "cmu" / "18_01.bvh"


def test_authors_file_verified_by_git_blob_only(mirror_root, cache, monkeypatch):
    """A take without sha256 (as the 15 missing ones) is verified by its git blob SHA-1."""
    monkeypatch.setenv("FPDTW_MIRROR", str(mirror_root))
    m = data.load_manifest("authors_fbx")
    e = dataclasses.replace(m.entry("Walk_02.fbx"), sha256=None, size=None)
    assert data.fetch(m, e, progress=False).is_file()
    wrong = dataclasses.replace(m.entry("Walk_03.fbx"), sha256=None, git_blob_sha1="0" * 40)
    with pytest.raises(
        data.DataFetchError, match="git blob SHA-1 expected 0{40}, actual [0-9a-f]{40}"
    ):
        data.fetch(m, wrong, progress=False)
    neither = dataclasses.replace(wrong, git_blob_sha1=None)
    with pytest.raises(data.DataFetchError, match="refused"):
        data.fetch(m, neither, progress=False)
    assert files_under(cache / "mocap_single_person_actions") == ["MoCapData/Walk_02.fbx"]


def test_every_fetch_hashes_the_cached_file(mirror_root, cache, monkeypatch):
    monkeypatch.setenv("FPDTW_MIRROR", str(mirror_root))
    calls = count_hashing(monkeypatch)
    p = data.fetch("cmu", progress=False)
    assert len(calls) == 1  # the downloaded temporary file
    for _ in range(3):
        assert data.fetch("cmu", progress=False) == p
    assert calls[1:] == [str(p)] * 3  # proven against the manifest at every use
    assert files_under(cache) == ["cmu/18_01.bvh"]  # no index to trust


def test_file_changed_in_place_with_its_mtime_restored_is_not_trusted(
    mirror_root, cache, monkeypatch
):
    """Audit case: a cached file changed in place, same size, mtime put back.

    Before: fetch() trusted its index entry (size and mtime match) and returned the
    changed file unverified. After: fetch() hashes it, drops it, fetches it again.
    """
    monkeypatch.setenv("FPDTW_MIRROR", str(mirror_root))
    expected = data.load_manifest("cmu").files[0].sha256
    p = data.fetch("cmu", progress=False)
    st = p.stat()
    flip_byte(p, 1000)
    os.utime(p, ns=(st.st_atime_ns, st.st_mtime_ns))
    assert p.stat().st_size == st.st_size and p.stat().st_mtime_ns == st.st_mtime_ns
    assert sha256_of(p) != expected
    assert data.fetch("cmu", progress=False) == p
    assert sha256_of(p) == expected
    # and with no mirror to fetch it again from, the changed file is refused, not returned
    flip_byte(p, 1000)
    os.utime(p, ns=(st.st_atime_ns, st.st_mtime_ns))
    monkeypatch.setenv("FPDTW_MIRROR", str(cache / "nowhere"))
    with pytest.raises(data.DataFetchError, match="18_01.bvh"):
        data.fetch("cmu", progress=False)
    assert not p.exists()


def test_stale_cached_copy_is_replaced(mirror_root, cache, monkeypatch):
    monkeypatch.setenv("FPDTW_MIRROR", str(mirror_root))
    p = data.fetch("cmu", progress=False)
    flip_byte(p)  # size unchanged, mtime changes
    p2 = data.fetch("cmu", progress=False)
    assert p2 == p and sha256_of(p) == data.load_manifest("cmu").files[0].sha256


def _zip(path: Path, members: dict[str, bytes]) -> None:
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as zf:
        for name, content in members.items():
            zf.writestr(name, content)


def _hdm05_with_archive(url: str):
    m = data.load_manifest("hdm05")
    arch = dataclasses.replace(m.archives["cut_amc"], url=url)
    return dataclasses.replace(m, archives={"cut_amc": arch})


def test_archive_flow_extracts_only_listed_members(mirror_root, cache, tmp_path):
    src = mirror_root / "hdm05"
    site = tmp_path / "site"
    site.mkdir()
    _zip(
        site / "HDM05_cut_amc.zip",
        {
            CLIP_A: (src / CLIP_A).read_bytes(),  # exact member path
            # under another top folder: found by its <class>/<file> suffix
            "cut/" + CLIP_B.split("/", 1)[1]: (src / CLIP_B).read_bytes(),
            CLIP_JUNK: (src / CLIP_JUNK).read_bytes(),  # in the archive, not requested
            "readme.txt": b"junk",
        },
    )
    with serve(site) as (base, hits):
        m = _hdm05_with_archive(f"{base}/HDM05_cut_amc.zip")
        pa = data.fetch(m, CLIP_A, progress=False)
        pb = data.fetch(m, CLIP_B, progress=False)
        assert data.fetch(m, CLIP_A, progress=False) == pa
    assert hits == ["/HDM05_cut_amc.zip"]  # downloaded once, then reused
    assert pa.read_bytes() == (src / CLIP_A).read_bytes()
    assert pb.read_bytes() == (src / CLIP_B).read_bytes()
    assert files_under(cache) == sorted(
        ["_archives/HDM05_cut_amc.zip", f"hdm05/{CLIP_A}", f"hdm05/{CLIP_B}"]
    )
    with pytest.raises(data.DataFetchError, match="has no member"):
        data.fetch(m, "HDM05_cut_amc/squat1Reps/HDM_bd_squat1Reps_002_120.amc", progress=False)
    assert no_temp_files(cache)


def test_archive_with_tampered_member_is_refused(mirror_root, cache, tmp_path):
    src = mirror_root / "hdm05"
    content = bytearray((src / CLIP_A).read_bytes())
    content[50] ^= 0x01
    site = tmp_path / "site"
    site.mkdir()
    _zip(site / "HDM05_cut_amc.zip", {CLIP_A: bytes(content), "readme.txt": b"junk"})
    expected = data.load_manifest("hdm05").entry(CLIP_A).sha256
    actual = hashlib.sha256(bytes(content)).hexdigest()
    with serve(site) as (base, _):
        m = _hdm05_with_archive(f"{base}/HDM05_cut_amc.zip")
        with pytest.raises(data.DataFetchError) as info:
            data.fetch(m, CLIP_A, progress=False)
    msg = str(info.value)
    assert CLIP_A in msg and expected in msg and actual in msg
    assert files_under(cache / "hdm05") == []
    assert no_temp_files(cache)


def test_verify_detects_corrupted_cached_file(mirror_root, cache, monkeypatch):
    monkeypatch.setenv("FPDTW_MIRROR", str(mirror_root))
    p = data.fetch("cmu", progress=False)
    data.fetch("hdm05", CLIP_A, progress=False)
    r = commands.verify(["cmu", "hdm05"])
    assert sorted(r.verified) == sorted(["cmu/18_01.bvh", f"hdm05/{CLIP_A}"])
    assert len(r.missing) == 291 and r.extra == [] and r.corrupt == []
    assert not r.ok and "FAILED: 291 of 293 files missing or wrong" in r.summary()
    assert commands.verify("cmu").ok

    flip_byte(p)
    st = p.stat()
    os.utime(p, ns=(st.st_atime_ns, st.st_mtime_ns + 1_000_000_000))
    expected = data.load_manifest("cmu").files[0].sha256
    r = commands.verify()
    assert not commands.verify("cmu").ok
    assert [k for k, _ in r.corrupt] == ["cmu/18_01.bvh"]
    assert expected in r.corrupt[0][1] and sha256_of(p) in r.corrupt[0][1]
    assert "CORRUPT cmu/18_01.bvh" in r.summary()

    (cache / "cmu" / "stray.bvh").write_bytes(b"x")
    assert commands.verify("cmu").extra == ["cmu/stray.bvh"]
    data.fetch("cmu", progress=False)  # replaces the corrupt copy
    assert commands.verify("cmu").ok


def test_fetch_all_from_local_mirror(mirror_root, cache, monkeypatch, capsys):
    """All 48 + 5 + 287 + 1 available files from the mirror folder; timing is printed."""
    monkeypatch.setenv("FPDTW_MIRROR", str(mirror_root))
    t0 = time.perf_counter()
    report = commands.fetch_all(progress=False)
    seconds = time.perf_counter() - t0
    with capsys.disabled():
        print(f"\n[test_data] fetch_all from the local mirror: 341 files in {seconds:.2f} s")
    assert report.ok and len(report.fetched) == 48 + 5 + 287 + 1
    assert sorted(report.skipped) == sorted(
        ("authors_fbx", e.path)
        for e in data.load_manifest("authors_fbx").files
        if not e.available_here
    )
    assert all(p.is_file() for p in report.fetched)
    assert no_temp_files(cache)

    calls = count_hashing(monkeypatch)
    t0 = time.perf_counter()
    again = commands.fetch_all(progress=False)
    seconds = time.perf_counter() - t0
    with capsys.disabled():
        print(f"[test_data] fetch_all again, every cached file hashed: {seconds:.2f} s")
    assert len(calls) == 341 and len(again.fetched) == 341  # each one proven again

    r = commands.verify()  # FPDTW_MIRROR is set: the 15 takes not in it are skipped
    assert r.ok and len(r.verified) == 341 and r.missing == [] and r.extra == []
    assert len(r.skipped) == 15
    r = commands.verify(available_only=False)
    assert not r.ok and len(r.missing) == 15

    # trying the 15 unavailable takes too: everything else is done, then they are reported
    report = commands.fetch_all("authors_fbx", available_only=False, progress=False, strict=False)
    assert len(report.fetched) == 48 and len(report.failed) == 15
    assert all("FPDTW_MIRROR" in msg for _, _, msg in report.failed)
    with pytest.raises(data.DataFetchError) as info:
        commands.fetch_all("authors_fbx", available_only=False, progress=False)
    assert len(info.value.report.failed) == 15 and "15 FAILED" in str(info.value)


def test_verify_fails_on_an_empty_cache_and_says_how_many(mirror_root, cache, monkeypatch, capsys):
    """Audit case: before, verify of an empty cache printed "0 verified" and exited 0."""
    monkeypatch.setenv("FPDTW_MIRROR", str(mirror_root))
    assert cli.main(["data", "verify"]) == 1
    out = capsys.readouterr().out
    assert "0 verified, 0 corrupt, 341 missing, 15 skipped" in out
    assert "FAILED: 341 of 341 files missing or wrong" in out
    assert cli.main(["data", "verify", "--all", "--dataset", "authors_fbx"]) == 1
    assert "63 missing, 0 skipped" in capsys.readouterr().out
    monkeypatch.delenv("FPDTW_MIRROR")  # upstream has every file: all 356 are required
    assert cli.main(["data", "verify"]) == 1
    assert "356 missing" in capsys.readouterr().out


def test_command_line(mirror_root, cache, monkeypatch, capsys):
    monkeypatch.setenv("FPDTW_MIRROR", str(mirror_root))
    assert cli.main(["data", "cite", "--dataset", "hdm05"]) == 0
    assert "CC BY-SA 3.0 Unported" in capsys.readouterr().out
    assert cli.main(["data", "fetch", "--dataset", "cmu", "--quiet"]) == 0
    assert "1 files verified" in capsys.readouterr().out
    assert cli.main(["data", "fetch", "--dataset", "cmu", "--file", "18_01.bvh", "--quiet"]) == 0
    assert capsys.readouterr().out.strip() == str(cache / "cmu" / "18_01.bvh")
    assert cli.main(["data", "verify", "--dataset", "cmu"]) == 0
    flip_byte(cache / "cmu" / "18_01.bvh")
    assert cli.main(["data", "verify", "--dataset", "cmu"]) == 1
    assert cli.main(["data", "fetch", "--dataset", "nope"]) == 1
    assert "no manifest for dataset 'nope'" in capsys.readouterr().err
    assert cli.main(["data", "fetch", "--dataset", "authors_fbx", "--all", "--quiet"]) == 1
    assert "15 FAILED" in capsys.readouterr().out
    assert cli.main(["data", "fetch", "--file", "x.bvh"]) == 2
    assert "--file needs exactly one --dataset" in capsys.readouterr().err
