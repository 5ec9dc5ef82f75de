"""The README's lists are complete and its TOML example runs as written (issue 35 item 8).

Expected values: the package's own registries (``hinfnav.cli.FILTER_CHOICES``, ``PAPER_CHOICES``: what the
command line accepts) and the design command itself on the README's TOML block.
"""

import json
import re
from pathlib import Path

from hinfnav.cli import FILTER_CHOICES, PAPER_CHOICES, main

README = (Path(__file__).resolve().parents[1] / "README.md").read_text(encoding="utf-8")


def _section(title):
    return README.split(f"## {title}", 1)[1].split("\n## ", 1)[0]


def test_reproduce_paper_keys_listed():
    line = re.search(r"python -m hinfnav reproduce \[--paper ([a-z0-9|]+)\]", README).group(1)
    assert line.split("|") == list(PAPER_CHOICES)


def test_every_simulate_filter_listed():
    bullet = _section("Command line").split("* `simulate`", 1)[1].split("\n* ", 1)[0]
    listed = set(re.findall(r"`([a-z0-9_]+)`", bullet))
    missing = [name for name in FILTER_CHOICES if name not in listed]
    assert not missing, missing


def test_toml_example_runs_as_written(tmp_path, capsys):
    block = re.search(r"```toml\n(.*?)```", _section("Robust designs on your own plant"), re.S).group(1)
    path = tmp_path / "plant.toml"
    path.write_text(block, encoding="utf-8")
    # the double integrator of the block is marginally stable: the README says it designs in observer form
    assert main(["design", "--system", str(path), "--form", "observer", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["gamma"] > 0 and out["gamma"] < 1e3 and out["form"] == "observer"
