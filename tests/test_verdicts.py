"""One source of truth for the verdicts (issue 35): summary.json's status, the stored full run, the README, the notebooks.

Expected values: ``hinfnav/papers/status_seed0.json``, written by ``benchmarks/status_snapshot.py`` from the
``summary.json`` files of ``python -m hinfnav reproduce`` (seed 0, default runs); for yang2020 it is also
recomputed here from the stored full summary ``tests/data/yang2020_summary_seed0.json``.
"""

import json
import re
from pathlib import Path

import pytest

from hinfnav.core.exceptions import InputError
from hinfnav.papers.verdicts import LEVELS, format_status, level, paper_status, stored_status

ROOT = Path(__file__).resolve().parents[1]
KEYS = ("shi2018", "attitude2018", "yang2020")
VERDICT_WORDS = re.compile(r"reproduced|partly|holds|✓", re.I)


def _notebook_markdown(name):
    cells = json.loads((ROOT / "notebooks" / name).read_text(encoding="utf-8"))["cells"]
    return "\n".join("".join(c["source"]) for c in cells if c["cell_type"] == "markdown")


def _word_level(word):
    word = word.lower()
    return "partly" if word.startswith("partly") else "not reproduced" if word.startswith("not") else "reproduced"


@pytest.mark.parametrize("verdict, expected", [
    (True, "reproduced"), (False, "not reproduced"), ("holds", "reproduced"), ("does not hold", "not reproduced"),
    ("holds in part", "partly"), ("holds under some readings", "partly"), ("partly reproduced: x", "partly"),
    ("reproduced from Q = 1e-16 up", "reproduced"), ("not reproduced: y", "not reproduced"), ("partly", "partly"),
])
def test_level_maps_every_vocabulary(verdict, expected):
    assert level(verdict) == expected


def test_level_refuses_unknown_words():
    with pytest.raises(InputError, match="vocabularies"):
        level("maybe")
    with pytest.raises(InputError, match="bool or a text"):
        level(1.0)


def test_stored_status_is_well_formed_and_grouped():
    stored = stored_status()
    assert sorted(stored) == sorted(KEYS)
    for key, st in stored.items():
        assert all(c["verdict"] in LEVELS for c in st["claims"])
        # the line is the claims grouped by level, best level first: rebuilt here independently
        groups = [f"{lev}: " + ", ".join(c["label"] for c in st["claims"] if c["verdict"] == lev)
                  for lev in LEVELS if any(c["verdict"] == lev for c in st["claims"])]
        assert st["line"] == "; ".join(groups)
        assert st["line"] in format_status(key, st)


def test_yang_status_follows_from_the_stored_full_summary():
    from hinfnav.papers.yang2020.claims import evaluate_claims

    summary = json.loads((ROOT / "tests" / "data" / "yang2020_summary_seed0.json").read_text(encoding="utf-8"))
    assert summary["status"] == stored_status()["yang2020"]
    summary["claims"] = evaluate_claims(summary)  # the verdicts recomputed from the numbers beside them
    assert paper_status("yang2020", summary) == stored_status()["yang2020"]


def test_readme_status_table_quotes_the_stored_status():
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    stored = stored_status()
    for key in KEYS:
        rows = [r for r in text.splitlines() if r.startswith("|") and f"| `{key}` |" in r]
        assert len(rows) == 1, key
        cell = rows[0].rsplit("|", 2)[-2]
        assert stored[key]["line"] in cell, (key, cell)
        rest = cell.replace(stored[key]["line"], "")
        assert not VERDICT_WORDS.search(rest), (key, rest)  # no second, free-hand verdict beside it


def test_shi_notebook_verdicts_match():
    md = _notebook_markdown("12_shi2018_reproduction.ipynb")
    ids = {"1": "gaussian", "2": "mixture", "3": "maneuver"}
    stored = {c["id"]: c["verdict"] for c in stored_status()["shi2018"]["claims"]}
    heads = re.findall(r"^## Claim (\d) .*\*\*((?:partly |not )?reproduced)\*\*", md, re.M)
    assert len(heads) == 3
    for n, word in heads:
        assert _word_level(word) == stored[ids[n]], (n, word)
    rows = re.findall(r"^\| (Gaussian|mixture|maneuver) .*\*\*((?:partly |not )?reproduced)\*\*", md, re.M)
    assert len(rows) == 3
    for case, word in rows:
        assert _word_level(word) == stored[case.lower()], (case, word)


def test_attitude_notebook_verdicts_match():
    stored = {c["id"]: c["verdict"] for c in stored_status()["attitude2018"]["claims"]}
    found = 0
    for name in ("21_aekf_q_tradeoff.ipynb", "22_astekf_aaekf_claims.ipynb"):
        md = _notebook_markdown(name)
        for n, word in re.findall(r"\*\*Claims? (\d)[^*]*?((?:partly |not )?reproduced)", md):
            assert _word_level(word) == stored[n], (name, n, word)
            found += 1
    assert found >= 3


def test_every_printed_status_says_the_same(capsys):
    for key, st in stored_status().items():
        print(format_status(key, st))
    out = capsys.readouterr().out
    for key, st in stored_status().items():
        assert f"{key} status: {st['line']}" in out
