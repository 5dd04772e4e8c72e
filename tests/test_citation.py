"""The software is citable as itself: CITATION.cff (Citation File Format 1.2.0) cites
filippov, not the paper it reproduces (that is under `references`); .zenodo.json says
the same for a deposit of `make archive`, which holds both files.

The CFF is validated against the format's JSON schema, vendored as
tests/reference/citation-file-format-1.2.0.schema.json: the file published as
https://citation-file-format.github.io/1.2.0/schema.json (its "$id"), byte for byte as
cffconvert 2.0.0 ships it (cffconvert/schemas/1.2.0/schema.json); Copyright 2017
Stephan Druskat, CC-BY-SA-4.0. The locked jsonschema validates it (cffconvert itself
is not installed: it pins an older jsonschema).
"""
import datetime
import json
import re
import shutil
import subprocess
import tomllib
from pathlib import Path

import jsonschema
import pytest
import yaml

from filippov.io import REFERENCE

ROOT = Path(__file__).resolve().parents[1]
SCHEMA = ROOT / "tests" / "reference" / "citation-file-format-1.2.0.schema.json"
PAPER_DOI = "10.1016/j.physd.2009.10.001"


@pytest.fixture(scope="module")
def cff():
    return yaml.safe_load((ROOT / "CITATION.cff").read_text(encoding="utf-8"))


@pytest.fixture(scope="module")
def zenodo():
    return json.loads((ROOT / ".zenodo.json").read_text(encoding="utf-8"))


@pytest.fixture(scope="module")
def project():
    return tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]


def _bibtex(cff: dict) -> dict:
    """The fields a BibTeX export of a CFF 1.2.0 file gets, as cffconvert 2.0.0 makes
    them (behavior_1_2_x/bibtex_object.py, bibtex_url.py): year from date-released,
    url from identifiers (type url), repository, repository-artifact,
    repository-code or url, doi from doi or identifiers (type doi)."""
    fields = {"title": cff.get("title")}
    if "date-released" in cff:
        fields["year"] = str(cff["date-released"])[:4]
    urls = [i["value"] for i in cff.get("identifiers", []) if i.get("type") == "url"]
    urls += [cff[k] for k in ("repository", "repository-artifact", "repository-code", "url")
             if k in cff]
    if urls:
        fields["url"] = urls[0]
    dois = [cff["doi"]] if "doi" in cff else []
    dois += [i["value"] for i in cff.get("identifiers", []) if i.get("type") == "doi"]
    if dois:
        fields["doi"] = dois[-1]
    return fields


def test_the_cff_is_valid_citation_file_format_1_2_0(cff):
    schema = json.loads(SCHEMA.read_text())
    assert schema["$id"] == "https://citation-file-format.github.io/1.2.0/schema.json"
    validator = jsonschema.Draft7Validator(schema,
                                           format_checker=jsonschema.Draft7Validator.FORMAT_CHECKER)
    errors = [f"{'.'.join(map(str, e.absolute_path)) or '<root>'}: {e.message}"
              for e in sorted(validator.iter_errors(cff), key=lambda e: list(e.absolute_path))]
    assert not errors, "\n".join(errors)


def test_the_schema_catches_what_it_should(cff):
    # the vendored schema really is checked: a CFF without authors, or with an unquoted
    # date (YAML reads it as a date, the format wants a string), is refused
    schema = json.loads(SCHEMA.read_text())
    broken = {k: v for k, v in cff.items() if k != "authors"}
    assert not jsonschema.Draft7Validator(schema).is_valid(broken)
    unquoted = {**cff, "date-released": datetime.date(2026, 1, 1)}
    assert not jsonschema.Draft7Validator(schema).is_valid(unquoted)


def test_the_software_is_cited_not_the_paper(cff, project):
    assert cff["cff-version"] == "1.2.0"
    assert cff["type"] == "software"
    # "cite this repository" uses preferred-citation when there is one: it must not be
    # the paper (that would credit the paper's authors for this software)
    preferred = cff.get("preferred-citation")
    if preferred is not None:
        assert preferred.get("type") == "software", preferred
        assert preferred.get("doi") != PAPER_DOI
    # title, version, licence and authors of the software, as pyproject.toml has them
    assert cff["title"].startswith(project["name"] + ":")
    assert cff["version"] == project["version"]
    assert cff["license"] == project["license"]["text"]
    assert "MIT License" in (ROOT / "LICENSE").read_text()
    assert [a["name"] for a in cff["authors"]] == [a["name"] for a in project["authors"]]
    datetime.date.fromisoformat(cff["date-released"])


def test_the_paper_is_listed_under_references(cff):
    papers = [r for r in cff.get("references", []) if r.get("doi") == PAPER_DOI]
    assert len(papers) == 1, cff.get("references")
    paper = papers[0]
    assert paper["type"] == "article"
    assert paper["title"] == "Small-scale instabilities in dynamical systems with sliding"
    assert [(a["family-names"], a["given-names"]) for a in paper["authors"]] == \
        [("Sieber", "Jan"), ("Kowalczyk", "Piotr")]
    assert "Physica D" in paper["journal"] and paper["year"] == 2010
    # the same volume, pages and DOI as every dataset's CF attribute `references`
    assert f"Physica D {paper['volume']} ({paper['year']}) {paper['start']}-{paper['end']}" \
        in REFERENCE
    assert f"doi:{paper['doi']}" in REFERENCE


def test_a_bibtex_export_has_a_year(cff):
    bib = _bibtex(cff)
    assert re.fullmatch(r"\d{4}", bib.get("year", "")), bib


@pytest.mark.xfail(strict=True, reason="no public URL of the repository is recorded in the "
                   "project (pyproject.toml, README): add repository-code to CITATION.cff "
                   "(and [project.urls] to pyproject.toml), then remove this mark")
def test_a_bibtex_export_has_a_url(cff):
    bib = _bibtex(cff)
    assert bib.get("url", "").startswith("https://"), bib


def test_zenodo_metadata_agrees_with_the_cff(cff, zenodo):
    assert zenodo["upload_type"] == "software"
    assert zenodo["title"] == cff["title"]
    assert zenodo["version"] == cff["version"]
    assert zenodo["license"].lower() == cff["license"].lower()
    assert [c["name"] for c in zenodo["creators"]] == [a["name"] for a in cff["authors"]]
    assert zenodo["publication_date"] == cff["date-released"]
    assert zenodo["description"] == cff["abstract"]  # a deposit needs one
    # the paper: cited (it is not this software's own publication)
    related = {(r["identifier"], r["relation"], r.get("scheme")) for r in
               zenodo["related_identifiers"]}
    assert (PAPER_DOI, "cites", "doi") in related
    assert zenodo.get("keywords") == cff.get("keywords")


@pytest.mark.skipif(shutil.which("make") is None or shutil.which("git") is None,
                    reason="needs make and git")
def test_the_archive_holds_the_citation_metadata():
    run = subprocess.run(["make", "-s", "--no-print-directory", "archive-files"], cwd=ROOT,
                         capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr
    files = set(run.stdout.split("\n"))
    assert {"CITATION.cff", ".zenodo.json", "LICENSE", "README.md"} <= files, sorted(files)[:20]
    assert not any(f.startswith(("logs/", ".venv/", ".snakemake/")) for f in files)
