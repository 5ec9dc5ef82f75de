"""The package as others receive it: licence, citation, changelog, version, lint, typing marker."""

import importlib.metadata
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


def test_version_is_the_installed_distributions_everywhere():
    # Source of the expected value: importlib.metadata, i.e. what pip installed (issue 35 item 7: outputs
    # said 0.1.dev327 while pip said 0.2.1.dev327).
    import hinfnav

    installed = importlib.metadata.version("hinfnav")
    assert hinfnav.__version__ == installed == package_version() == provenance()["hinfnav"]


def test_a_checkout_without_tags_is_version_0_3_0():
    # pyproject.toml's setuptools-scm settings, evaluated as the build does (setuptools-scm is a build
    # requirement, present wherever the package was installed from a checkout).
    setuptools_scm = pytest.importorskip("setuptools_scm")
    config = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["tool"]["setuptools_scm"]
    assert config == {"version_scheme": "only-version", "local_scheme": "no-local-version", "fallback_version": "0.3.0"}
    if (ROOT / ".git").exists() and shutil.which("git") is not None:
        tags = subprocess.run(["git", "tag", "--list", "v*"], cwd=ROOT, capture_output=True, text=True).stdout
        if not tags.strip():
            assert setuptools_scm.get_version(root=str(ROOT), **config) == "0.3.0"


@pytest.mark.skipif(not (ROOT / ".git").exists() or shutil.which("git") is None, reason="not a git checkout")
def test_provenance_names_the_commit():
    commit = git_commit()
    head = subprocess.run(["git", "rev-parse", "HEAD"], cwd=ROOT, capture_output=True, text=True).stdout.strip()
    assert commit.split("+")[0] == head
    assert provenance()["commit"] == commit


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
