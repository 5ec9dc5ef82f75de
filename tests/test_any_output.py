"""Issue 30, item 2: any nonzero output L (partial, mixing states) in both forms, on every path; L = 0 refused."""

import json
from pathlib import Path

import control
import numpy as np
import pytest

import hinfnav as hn
from hinfnav.analysis.norms import hinf_norm_bisection
from hinfnav.cli import main
from hinfnav.core.exceptions import InputError
from hinfnav.design import design_from_system_file

ROOT = Path(__file__).resolve().parents[1]
T = 0.1
A_DI = np.block([[np.eye(2), T * np.eye(2)], [np.zeros((2, 2)), np.eye(2)]])
B_DI = np.vstack([T * T / 2 * np.eye(2), T * np.eye(2)])
C_DI = np.hstack([np.eye(2), np.zeros((2, 2))])
D_DI = 0.1 * np.eye(2)


def _observer_error_norm(A, B, C, D, L, B_F):
    """Independent H∞ norm (bisection, not SLICOT) of e⁺ = (A + B_F C) e + [B, B_F D] τ, output L e."""
    return hinf_norm_bisection(control.ss(A + B_F @ C, np.hstack([B, B_F @ D]), L, 0, T))


def test_position_only_double_integrator_from_the_cli_designs_saves_and_recertifies(tmp_path, capsys):
    save = tmp_path / "pos.json"
    rc = main(["design", "--system", str(ROOT / "examples" / "double_integrator_position.toml"), "--form", "observer",
               "--json", "--save", str(save)])
    out = capsys.readouterr()
    assert rc == 0, out.err
    rep = json.loads(out.out)
    C_F = np.array(rep["C_F"])
    assert C_F.shape == (2, 4) and np.array_equal(C_F, -C_DI)  # z_f = −L x_f: the position estimate only
    nrm = _observer_error_norm(A_DI, B_DI, C_DI, D_DI, C_DI, np.array(rep["B_F"]))
    # the certified γ bounds the independently computed norm, and the nominal extended BRL is tight (1e-5: solver)
    assert nrm <= rep["gamma"] * (1 + 1e-9) and rep["gamma"] <= nrm * (1 + 1e-5)
    again = hn.recertify(save)
    assert again["ok"], again["reasons"]


def test_position_only_output_is_never_worse_than_the_full_state_output():
    # ‖L e‖ ≤ ‖e‖ for L = [I 0]: the optimal level for the position alone is at most the full-state one
    full = hn.synthesize(hn.UncertainSystem(A_DI, B_DI, C_DI, D_DI, np.eye(4), dt=T), form="observer")
    pos = hn.synthesize(hn.UncertainSystem(A_DI, B_DI, C_DI, D_DI, C_DI, dt=T), form="observer")
    assert pos.gamma <= full.gamma * (1 + 1e-6)


@pytest.mark.parametrize("form", ["general", "observer"])
@pytest.mark.parametrize("L", [[[0.0, 1.0]], [[1.0, 1.0]], [[1.0, 0.0], [1.0, -1.0], [0.0, 2.0]]],
                         ids=["partial", "mixing", "tall"])
def test_norm_bounded_any_output_both_forms(form, L):
    A = np.array([[0.9, 0.1], [0.0, 0.8]])
    s = hn.UncertainSystem(A, 0.1 * np.eye(2), [[1.0, 0.0]], [[0.1]], L, H=[[0.0], [0.1]], E=[[0.0, 1.0]], dt=T)
    res = hn.synthesize(s, form=form)
    L = np.asarray(L)
    assert res.C_F.shape == L.shape
    # independent dense grid over the scalar F ∈ [−1, 1] (bisection norm of the full error system (13)–(14))
    worst = 0.0
    for f in np.linspace(-1, 1, 41):
        Ab = np.block([[A + f * s.H @ s.E, np.zeros((2, 2))], [res.B_F @ s.C, res.A_F]])
        Bb = np.block([[s.B, np.zeros((2, 1))], [np.zeros((2, 2)), res.B_F @ s.D]])
        worst = max(worst, hinf_norm_bisection(control.ss(Ab, Bb, np.hstack([L, -res.C_F]), 0, T)))
    assert worst <= res.gamma * (1 + 1e-9)


def test_zero_output_is_refused_in_every_path(tmp_path):
    f = tmp_path / "zero.toml"
    f.write_text((ROOT / "examples" / "double_integrator_position.toml").read_text().replace(
        "L = [[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0]]", "L = [[0.0, 0.0, 0.0, 0.0]]"), encoding="utf-8")
    for form in ("general", "observer"):
        with pytest.raises(InputError, match=r"\bL\b.*nothing to estimate"):
            design_from_system_file(f, form=form)
    with pytest.raises(InputError, match=r"\bL\b.*nothing to estimate"):
        hn.synthesize_polytopic(hn.PolytopicSystem((hn.UncertainSystem(A_DI, B_DI, C_DI, D_DI, 0 * C_DI, dt=T),), T),
                                form="observer")
