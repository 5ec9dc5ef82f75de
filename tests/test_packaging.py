"""The package as others receive it: licence, citation, changelog, version from git, lint, typing marker."""

import json
import re
import shutil
import subprocess
import sys
import tomllib
from pathlib import Path

import jsonschema
import pytest
import yaml

from hinfnav.io.provenance import git_commit, package_version, provenance

ROOT = Path(__file__).resolve().parents[1]


def test_license_file_is_the_declared_mit_licence():
    declared = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]["license"]
    text = (ROOT / "LICENSE").read_text(encoding="utf-8")
    assert declared == "MIT"
    assert text.startswith("MIT License") and "WITHOUT WARRANTY OF ANY KIND" in text


def test_citation_file_is_valid_against_the_cff_1_2_0_schema():
    # Schema: the Citation File Format 1.2.0 JSON schema (citation-file-format.github.io, CC-BY-4.0),
    # as shipped in cffconvert 2.0.0 (cffconvert/schemas/1.2.0/schema.json), copied to tests/data.
    schema = json.loads((ROOT / "tests" / "data" / "cff_schema_1.2.0.json").read_text(encoding="utf-8"))
    citation = yaml.safe_load((ROOT / "CITATION.cff").read_text(encoding="utf-8"))
    jsonschema.validate(citation, schema, cls=jsonschema.Draft7Validator)
    dois = {ref.get("doi") for ref in citation["references"]}
    # the two DOIs printed on the papers themselves (../shared/REFERENCE.md)
    assert {"10.3873/j.issn.1000-1328.2011.07.005", "10.16383/j.aas.c190515"} <= dois


def test_citation_file_schema_check_can_fail():
    schema = json.loads((ROOT / "tests" / "data" / "cff_schema_1.2.0.json").read_text(encoding="utf-8"))
    citation = yaml.safe_load((ROOT / "CITATION.cff").read_text(encoding="utf-8"))
    del citation["authors"]
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate(citation, schema, cls=jsonschema.Draft7Validator)


def test_changelog_has_an_unreleased_section_and_the_released_versions():
    text = (ROOT / "CHANGELOG.md").read_text(encoding="utf-8")
    assert "## Unreleased" in text
    assert re.search(r"^## 0\.2\.0 ", text, re.M) and re.search(r"^## 0\.1\.0 ", text, re.M)


@pytest.mark.skipif(not (ROOT / ".git").exists() or shutil.which("git") is None, reason="not a git checkout")
def test_version_in_provenance_names_the_commit():
    commit = git_commit()
    version = package_version()
    assert provenance()["hinfnav"] == version
    tagged = subprocess.run(["git", "describe", "--tags", "--exact-match", "--match", "v*"], cwd=ROOT,
                            capture_output=True, text=True).returncode == 0
    if not tagged or commit.endswith("+dirty"):
        # a commit after the last tag: X.Y.Z.devN+g<short hash>, so two commits never share a version
        assert re.search(r"\.dev\d+\+g" + commit[:7], version), (version, commit)


def test_package_ships_the_typing_marker():
    assert (ROOT / "hinfnav" / "py.typed").exists()
    data = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["tool"]["setuptools"]["package-data"]
    assert "py.typed" in data["hinfnav"]


def test_ruff_check_passes():
    exe = shutil.which("ruff") or str(Path(sys.executable).with_name("ruff"))
    if not Path(exe).exists() and shutil.which(exe) is None:
        pytest.skip("ruff is not installed (pip install -r requirements.txt installs it)")
    proc = subprocess.run([exe, "check", "hinfnav", "tests", "benchmarks"], cwd=ROOT, capture_output=True,
                          text=True, timeout=120)
    assert proc.returncode == 0, proc.stdout[-4000:] + proc.stderr[-1000:]
