"""``reproduce`` for Yang et al. (2020) at a reduced length: every figure and summary field is written.

The numbers of the full-length run are in the notebooks and summary.json; here
the structure is checked, and the claims' verdicts against their own numbers.
"""

import json

import numpy as np
import pytest

import hinfnav as hn
from hinfnav.papers.yang2020 import Scenario, reproduce
from hinfnav.papers.yang2020.claims import VERDICTS
from hinfnav.plotting.save import read_provenance


@pytest.fixture(scope="module")
def summary(tmp_path_factory):
    out = tmp_path_factory.mktemp("yang2020")
    sc = Scenario(n_steps=800, step_on=300, step_off=600, settle_s=10.0)
    s = reproduce(out, scenario=sc, progress=False, open_loop_steps=200, reading_steps=800, integral_steps=200,
                  formats=("png",))  # the default also writes PDFs: Matplotlib takes ~1 s a file

    return out, s


def test_writes_figures_5_to_12_and_summary(summary):
    out, s = summary
    for n in range(5, 13):
        assert (out / f"fig{n}.png").stat().st_size > 0
    assert json.loads((out / "summary.json").read_text()) == s
    # issue 22: a table file like the other papers' (the claims, CSV and Markdown)
    assert (out / "claims.csv").read_text().startswith("id,figure,claim,") and (out / "claims.md").is_file()
    # issue 22: every reading of the 3e-14 claim at one record length, with the statistic's sensitivity
    assert {v["n_steps"] for v in s["asd"]["by_reading"].values()} == {s["asd"]["record_steps"]}
    assert s["asd"]["sensitivity"]["rows"] and set(s["estimation"]["theta_readings"]) >= {"theta_star",
                                                                                          "kalman_prediction"}


def test_summary_fields(summary):
    _, s = summary
    assert s["table2"]["m_sc"]["value"] == 1050.0 and s["requirement"] == 3e-14
    assert s["theta_star"]["algorithm1"] > 0 and len(s["theta_star"]["algorithm2"]) == 3
    for k in ("L1", "L2", "L3"):
        e = s["estimation"][k]
        assert np.isfinite(e["disturbance_rms"]) and np.isfinite(e["disturbance_bias"])
    for k in ("adrc_max_1_30mHz", "pid_max_1_30mHz"):
        assert s["asd"][k] > 0
    readings = {"default", "noise_two_sided", "noise_per_sample", "omega_d_rad_s", "timing_prior"}
    assert readings <= set(s["asd"]["by_reading"])
    assert set(s["integral_readings"]) == {"printed", "dt"}


def test_claims_have_statistic_number_verdict(summary):
    _, s = summary
    assert len(s["claims"]) >= 8
    for c in s["claims"]:
        assert c["verdict"] in VERDICTS and c["statistic"] and c["number"] is not None
    by = {c["figure"]: c for c in s["claims"]}
    # the verdict follows from the numbers it reports
    asd = by["Figs 9, 12"]
    assert (asd["verdict"] == "holds") == (asd["number"]["adrc"] < asd["number"]["pid"])


def test_too_many_runs_is_refused_before_any_work(tmp_path):
    with pytest.raises(hn.InputError, match="runs"):
        reproduce(tmp_path / "x", runs=9, progress=False)
    assert not (tmp_path / "x").exists()


def test_every_figure_file_carries_the_summarys_provenance(summary):
    # issue 23: this run's files read back (PNG text chunk, PDF Info) hold summary.json's provenance
    prov = json.loads((summary[0] / "summary.json").read_text())["provenance"]
    files = sorted(summary[0].glob("*.p[nd][gf]"))  # every figure of the run, each format
    assert prov["paper"] == "yang2020" and len(files) >= 8 and [read_provenance(f) for f in files] == [prov] * len(files)
