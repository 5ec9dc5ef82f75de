"""Issue 19: design files that cannot lie, and designs for a system of one's own from a TOML file."""

import json
from pathlib import Path

import numpy as np
import pytest

import hinfnav as hn
from hinfnav.papers import sun2011
from hinfnav.cli import main
from hinfnav.core.exceptions import InputError
from hinfnav.design import design_from_system_file

ROOT = Path(__file__).resolve().parents[1]
T = 0.1
A_DI = np.block([[np.eye(2), T * np.eye(2)], [np.zeros((2, 2)), np.eye(2)]])
B_DI = np.vstack([T * T / 2 * np.eye(2), T * np.eye(2)])
C_DI = np.hstack([np.eye(2), np.zeros((2, 2))])


def run_cli(capsys, *args):
    """The command line in-process (no interpreter start-up): (exit status, stdout, stderr)."""
    rc = main(list(args))
    out = capsys.readouterr()
    return rc, out.out, out.err


@pytest.fixture(scope="module")
def di_file(tmp_path_factory):
    res = hn.synthesize(hn.UncertainSystem(A_DI, B_DI, C_DI, 0.1 * np.eye(2), np.eye(4), dt=T), form="observer")
    return sun2011.save_design(res, tmp_path_factory.mktemp("d") / "di.json"), res


def _edited(src, tmp_path, edit):
    d = json.loads(Path(src).read_text())
    edit(d)
    out = tmp_path / "edited.json"
    out.write_text(json.dumps(d))
    return out


def test_user_design_is_saved_with_its_own_system(di_file):
    path, res = di_file
    d = json.loads(Path(path).read_text())
    # the user's 4-state plant, not Sun 2011's 6-state one
    assert np.array_equal(np.array(d["system"]["A"]), A_DI) and d["extra"] == {}
    back = sun2011.load_design(path)
    assert np.array_equal(back.B_F, res.B_F) and back.gamma == res.gamma


def test_recertify_passes_on_an_untouched_file(di_file):
    rep = hn.recertify(di_file[0])
    assert rep["ok"], rep["reasons"]
    # the level recomputed in float64 from the saved witness reproduces the stored γ (same arithmetic: 1e-12)
    assert abs(rep["lmi_gamma_recomputed"] - rep["gamma"]) <= 1e-12 * rep["gamma"]
    assert rep["sampled_worst_norm"] <= rep["gamma"]


@pytest.mark.parametrize("edit", [
    lambda d: (d["filter"].__setitem__("B_F", (3 * np.array(d["filter"]["B_F"])).tolist()),
               d["certificate"].__setitem__("gamma", 0.001)),
    lambda d: d["filter"].__setitem__("B_F", (3 * np.array(d["filter"]["B_F"])).tolist()),
    lambda d: d["certificate"].__setitem__("gamma", 0.001),
    lambda d: d["certificate"].__setitem__("verified_norm", 0.0),
    lambda d: d["witness"].__setitem__("G", (2 * np.array(d["witness"]["G"])).tolist()),
    lambda d: d["system"]["A"][0].__setitem__(2, 0.2),
], ids=["B_F-x3-and-gamma", "B_F-x3", "gamma", "verified-norm", "witness", "system"])
def test_an_edited_file_is_refused(di_file, tmp_path, edit, capsys):
    bad = _edited(di_file[0], tmp_path, edit)
    for load in (sun2011.load_design, hn.recertify):
        with pytest.raises(InputError, match="edited"):
            load(bad)
    rc, _, err = run_cli(capsys, "design", "--recertify", str(bad))
    assert rc != 0 and "edited" in err


def test_design_system_double_integrator_observer_json(tmp_path, capsys):
    save = tmp_path / "di.json"
    rc, out, err = run_cli(capsys, "design", "--system", str(ROOT / "examples" / "double_integrator.toml"), "--form", "observer",
                  "--json", "--save", str(save))
    assert rc == 0, err
    rep = json.loads(out)
    for key in ("gamma", "lmi_gamma", "verified_worst_norm", "lyapunov", "form", "covers", "A_F", "B_F", "C_F",
                "provenance"):
        assert key in rep
    assert rep["form"] == "observer" and rep["verified_worst_norm"] <= rep["gamma"]
    rc, out, err = run_cli(capsys, "design", "--recertify", str(save), "--json")
    assert rc == 0 and json.loads(out)["ok"], err


def test_design_system_two_mass_spring_parameter_dependent(capsys):
    rc, out, err = run_cli(capsys, "design", "--system", str(ROOT / "examples" / "two_mass_spring_30pct.toml"), "--json")
    assert rc == 0, err
    rep = json.loads(out)
    assert rep["lyapunov"] == "parameter-dependent" and "constant in time" in rep["covers"]
    assert rep["verified_worst_norm"] <= rep["gamma"]


@pytest.mark.parametrize("text, match", [
    ("[nominal]\nA = [[1.0]]\n", "'dt'"),
    ("dt = 0.1\n[nominal]\nA = [[0.5]]\nB = [[1.0]]\nC = [[1.0]]\nD = [[1.0]]\n", "'L'"),
    ("dt = 0.1\n[nominal]\nA = [[0.5]]\nB = [[1.0]]\nC = [[1.0]]\nD = [[1.0]]\nL = [[1.0]]\n"
     "[uncertainty]\nkind = \"polytope\"\n[[uncertainty.vertices]]\nQ = [[0.4]]\n", r"vertices\[0\].*'Q'"),
    ("dt = 0.1\n[nominal]\nA = [[0.5]]\nB = [[1.0]]\nC = [[1.0]]\nD = [[1.0]]\nL = [[1.0]]\n"
     "[uncertainty]\nkind = \"cube\"\n", "kind"),
])
def test_system_file_errors_name_the_key(tmp_path, text, match):
    f = tmp_path / "s.toml"
    f.write_text(text, encoding="utf-8")
    with pytest.raises(InputError, match=match):
        design_from_system_file(f)


def test_latin1_system_file_is_a_clear_error(tmp_path, capsys):
    f = tmp_path / "latin1.toml"
    f.write_bytes("dt = 0.1 # café\n".encode("latin-1"))
    rc, _, err = run_cli(capsys, "design", "--system", str(f))
    assert rc == 2 and "UTF-8" in err and "latin1.toml" in err


def test_h2_design_from_file_saves_and_recertifies(tmp_path, capsys):
    save = tmp_path / "h2.json"
    rc, out, err = run_cli(capsys, "design", "--system", str(ROOT / "examples" / "double_integrator.toml"), "--form",
                           "observer", "--objective", "h2", "--json", "--save", str(save))
    assert rc == 0, err
    rep = json.loads(out)
    assert rep["objective"] == "h2" and rep["verified_worst_norm"] <= rep["gamma"]
    again = hn.recertify(save)
    assert again["ok"] and again["objective"] == "h2", again["reasons"]


def test_a_file_saved_before_the_generic_names_still_loads(tmp_path):
    # tests/data/designs/...98adc2f.json: saved by hinfnav at commit 98adc2f (certificate keys "delta_bar",
    # "deltas"); it loads, checks against the paper's scenario, and keeps its bound and grid (stored values)
    from hinfnav.papers.sun2011 import load_design

    path = ROOT / "tests" / "data" / "designs" / "sun2011_dbar0.3_design2_98adc2f.json"
    res = load_design(path)
    stored = json.loads(path.read_text())["certificate"]
    assert res.uncertainty_bound == stored["delta_bar"] == 0.3
    assert np.array_equal(res.sample_values, stored["deltas"]) and res.sample_values.size == 21
    assert res.worst_value == stored["deltas"][stored["worst_sample"]]
    assert hn.recertify(path)["ok"]
    # saved again, the file names them generically and loads the same
    from hinfnav.papers.sun2011 import save_design

    again = json.loads(save_design(res, tmp_path / "again.json").read_text())["certificate"]
    assert "delta_bar" not in again and again["uncertainty_bound"] == 0.3 and again["sample_values"] == stored["deltas"]
    assert np.array_equal(load_design(tmp_path / "again.json").A_F, res.A_F)
