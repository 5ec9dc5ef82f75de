"""Saved designs that cannot lie (issue 36, item 4).

* ``save_design(result, another_system)`` is refused: a file pairs a filter
  with the system it was certified on.
* ``recertify`` re-derives what the witness proves: a parameter-dependent
  design (one Lyapunov matrix per vertex) relabelled "common", its
  fingerprint recomputed so that the file looks untouched, is NOT recertified.
"""

import json
import re
from pathlib import Path

import numpy as np
import pytest

from hinfnav.core.exceptions import InputError
from hinfnav.design import design_from_system_file, recertify
from hinfnav.design.io import content_fingerprint, save_design
from hinfnav.design.polytopic import COVERS
from hinfnav.systems import read_system_file

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def two_mass(tmp_path_factory):
    result, rep = design_from_system_file(ROOT / "examples" / "two_mass_spring_30pct.toml")
    assert rep["lyapunov"] == "parameter-dependent"
    return result


def test_saving_with_another_system_is_refused(two_mass, tmp_path):
    other = read_system_file(ROOT / "examples" / "two_mass_spring_30pct.toml")
    path = save_design(two_mass, other, tmp_path / "same.json")  # the same matrices, another object: fine
    assert path.is_file()
    text = (ROOT / "examples" / "two_mass_spring_30pct.toml").read_text()
    f = tmp_path / "slower.toml"
    f.write_text(re.sub(r"(?m)^dt = 0\.1$", "dt = 0.2", text))  # the same plant sampled at 0.2 s
    slower = read_system_file(f)
    assert slower.dt == 0.2
    with pytest.raises(InputError, match="not the system this filter was designed for"):
        save_design(two_mass, slower, tmp_path / "wrong.json")
    assert not (tmp_path / "wrong.json").exists()


def test_relabelled_common_is_not_recertified(two_mass, tmp_path):
    path = save_design(two_mass, two_mass.system, tmp_path / "pd.json")
    rep = recertify(path)
    assert rep["ok"] and rep["lyapunov_proven"] == "parameter-dependent"
    d = json.loads(path.read_text())
    d["certificate"]["lyapunov"] = "common"
    d["certificate"]["covers"] = COVERS["common"]
    d["fingerprint"] = content_fingerprint(d)  # what an editor who knows the format would do
    forged = tmp_path / "forged.json"
    forged.write_text(json.dumps(d))
    rep = recertify(forged)
    assert not rep["ok"] and rep["lyapunov_proven"] == "parameter-dependent"
    assert any("proves 'parameter-dependent' only" in r for r in rep["reasons"])
    assert rep["covers"] == COVERS["parameter-dependent"]
    assert len({np.asarray(P).tobytes() for P in d["witness"]["P"]}) > 1  # indeed one matrix per vertex
