"""LICENSE and CITATION.cff agree with pyproject.toml and with the datasets' citations."""

from __future__ import annotations

import contextlib
import copy
import io
import json
import re
import tomllib

import jsonschema
import pytest
import yaml

from fpdtw.app import cli
from fpdtw.paper import datasets as data
from fpdtw.paper.paths import REPO_ROOT

MIT_GRANT = (
    "Permission is hereby granted, free of charge, to any person obtaining a copy of this "
    'software and associated documentation files (the "Software"), to deal in the Software '
    "without restriction"
)


def _project():
    return tomllib.loads((REPO_ROOT / "pyproject.toml").read_text())["project"]


def _cff():
    return yaml.safe_load((REPO_ROOT / "CITATION.cff").read_text(encoding="utf-8"))


def _cff_errors(doc) -> list[str]:
    schema = json.loads((REPO_ROOT / "tests" / "cff" / "schema-1.2.0.json").read_text())
    validator = jsonschema.Draft7Validator(schema)
    return [f"{list(e.absolute_path)}: {e.message}" for e in validator.iter_errors(doc)]


def _printed_citations() -> dict[str, str]:
    """Dataset name -> the citation `fpdtw data cite` prints for it."""
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        assert cli.main(["data", "cite"]) == 0
    blocks = out.getvalue().strip().split("\n\n")
    cites = {}
    for block in blocks:
        name = block.split(":", 1)[0]
        m = re.search(r"^  Cite: (.+)$", block, re.M)
        assert m, block
        cites[name] = m.group(1)
    return cites


def test_license_is_mit_as_pyproject_says():
    assert _project()["license"] == {"text": "MIT"}
    text = (REPO_ROOT / "LICENSE").read_text()
    assert text.startswith("MIT License\n")
    assert "Copyright (c) 2026 fpdtw developers" in text
    assert MIT_GRANT in " ".join(text.split())
    assert 'THE SOFTWARE IS PROVIDED "AS IS", WITHOUT WARRANTY OF ANY KIND' in text


def test_citation_cff_is_valid_cff_1_2_0():
    doc = _cff()
    assert doc["cff-version"] == "1.2.0"
    assert not _cff_errors(doc), _cff_errors(doc)


@pytest.mark.parametrize(
    "path, value",
    [
        (("license",), "MIT License"),  # not an SPDX identifier
        (("preferred-citation", "doi"), "https://doi.org/10.1002/cav.2166"),  # a URL, not a DOI
        (("references", 0, "type"), "poster"),  # not a CFF reference type
        (("authors",), []),
        (("version_",), "0.1.0"),  # an unknown key
    ],
)
def test_schema_check_rejects(path, value):
    doc = copy.deepcopy(_cff())
    target = doc
    for key in path[:-1]:
        target = target[key]
    target[path[-1]] = value
    assert _cff_errors(doc)


def test_citation_cff_matches_pyproject():
    doc, project = _cff(), _project()
    assert doc["type"] == "software"
    assert str(doc["version"]) == project["version"]
    assert doc["license"] == project["license"]["text"]
    assert [a["name"] for a in doc["authors"]] == [a["name"] for a in project["authors"]]
    assert doc["title"].startswith(project["name"] + ":")
    assert doc["abstract"] == project["description"]


def test_preferred_citation_is_the_fpdtw_paper():
    pc = _cff()["preferred-citation"]
    assert pc["type"] == "article"
    assert pc["doi"] == "10.1002/cav.2166"
    assert [(a["family-names"], a["given-names"]) for a in pc["authors"]] == [
        ("Randall", "M."),
        ("Harvey", "C."),
        ("Williams", "I."),
    ]
    assert pc["title"] == (
        "Online alignment of human motion using forward plotting-dynamic time warping"
    )
    assert (pc["journal"], pc["year"], pc["volume"], str(pc["issue"]), pc["start"]) == (
        "Computer Animation and Virtual Worlds",
        2023,
        34,
        "3",
        "e2166",
    )


def test_references_hold_the_opw_poster():
    titles = [r["title"] for r in _cff()["references"]]
    assert "A Predictive Approach to On-line Time Warping of Motion" in titles


def test_every_dataset_citation_that_fpdtw_data_cite_prints_is_in_citation_cff():
    printed = _printed_citations()
    assert set(printed) == set(data.dataset_names()) == {"authors_fbx", "cmu", "hdm05"}
    refs = _cff()["references"]
    for name, citation in printed.items():
        holders = [r for r in refs if citation in " ".join(r.get("notes", "").split())]
        assert len(holders) == 1, f"{name}: {citation!r} is not in one reference's notes"
        # the reference's persons are the citation's (CMU's acknowledgement names none)
        for author in holders[0]["authors"]:
            assert "family-names" not in author or author["family-names"] in citation


def test_authors_dataset_reference_pins_the_manifest_commit():
    manifest = data.load_manifest("authors_fbx")
    (ref,) = [r for r in _cff()["references"] if r.get("repository", "").endswith("Actions")]
    assert ref["repository"] == "https://github.com/matRandall/Mocap_SinglePersonActions"
    assert ref["commit"] in manifest.upstream


def test_the_docs_point_at_the_citation_and_the_lock():
    readme = (REPO_ROOT / "README.md").read_text()
    assert "docs/citing.md" in readme and "docs/environment.md" in readme
    citing = (REPO_ROOT / "docs" / "citing.md").read_text()
    for needle in ("CITATION.cff", "10.1002/cav.2166", "fpdtw data cite", "LICENSE"):
        assert needle in citing, needle
    env = (REPO_ROOT / "docs" / "environment.md").read_text().split("\n## ", 1)[0]
    for needle in ("requirements.lock", "make lock", "LOCKED=0", "--require-hashes"):
        assert needle in env, needle


# ------------------------------------------------------------------------- .zenodo.json
#: Zenodo's upload types and relations (its deposit metadata, the subset used here).
ZENODO_RELATIONS = {"references", "isSupplementTo", "isDerivedFrom", "cites", "requires"}


def _zenodo():
    return json.loads((REPO_ROOT / ".zenodo.json").read_text(encoding="utf-8"))


def _cff_identifiers(doc) -> set[str]:
    """Every DOI, URL and repository CITATION.cff names (the package's and its references')."""
    out = set()
    for entry in [doc, doc["preferred-citation"], *doc["references"]]:
        for key in ("doi", "url", "repository", "repository-code"):
            if key in entry:
                out.add(str(entry[key]))
    return out


def _zenodo_errors(z, cff) -> list[str]:
    """Where .zenodo.json disagrees with CITATION.cff (empty: they agree)."""
    errors = []
    for zkey, ckey in (("title", "title"), ("description", "abstract"), ("version", "version"),
                       ("license", "license"), ("keywords", "keywords")):  # fmt: skip
        if str(z.get(zkey)) != str(cff.get(ckey)):
            errors.append(f"{zkey}: {z.get(zkey)!r} != CITATION.cff {ckey} {cff.get(ckey)!r}")
    names = [a.get("name") or f"{a['family-names']}, {a['given-names']}" for a in cff["authors"]]
    if [c.get("name") for c in z.get("creators", [])] != names:
        errors.append(f"creators {z.get('creators')} != CITATION.cff authors {names}")
    related = {r["identifier"] for r in z.get("related_identifiers", [])}
    if related != _cff_identifiers(cff):
        errors.append(f"related identifiers {sorted(related)} != {sorted(_cff_identifiers(cff))}")
    for r in z.get("related_identifiers", []):
        scheme = "doi" if r["identifier"].startswith("10.") else "url"
        if r.get("scheme") != scheme or r.get("relation") not in ZENODO_RELATIONS:
            errors.append(f"related identifier {r}: scheme {scheme} and a Zenodo relation")
    if z.get("upload_type") != "software" or z.get("access_right") != "open":
        errors.append("upload_type must be software, access_right open")
    return errors


def test_zenodo_json_agrees_with_citation_cff():
    z, cff = _zenodo(), _cff()
    assert not _zenodo_errors(z, cff), _zenodo_errors(z, cff)
    assert z["version"] == _project()["version"]


@pytest.mark.parametrize(
    "key, value",
    [
        ("version", "0.2.0"),
        ("license", "Apache-2.0"),
        ("keywords", ["dynamic time warping"]),
        ("creators", [{"name": "someone else"}]),
        ("related_identifiers", []),
        ("upload_type", "dataset"),
    ],
)
def test_zenodo_check_catches(key, value):
    z = copy.deepcopy(_zenodo())
    z[key] = value
    assert _zenodo_errors(z, _cff())


def test_zenodo_references_hold_the_papers_and_every_dataset_citation():
    refs = _zenodo()["references"]
    pc = _cff()["preferred-citation"]
    assert any(pc["title"] in r and pc["doi"] in r for r in refs)
    assert any("A Predictive Approach to On-line Time Warping of Motion" in r for r in refs)
    for name, citation in _printed_citations().items():
        assert citation in refs, f"{name}: {citation!r} is not among .zenodo.json's references"
