"""Issue 36: the polytopic route's γ does not depend on the units the plant's states are written in.

The examples are designed through :func:`hinfnav.design.from_file.design_from_system_file` (what ``design
--system`` calls), from a copy of the example file written in other state units: ``x' = diag(t)⁻¹ x`` gives
``A' = T⁻¹AT``, ``B' = T⁻¹B``, ``C' = CT``, ``L' = LT`` (D unchanged), the same estimation problem. The expected γ
is the design of the unchanged file; the certified γ must also bound the vertices' H∞ norms computed here with
python-control (an independent check, not the design's own).
"""

from __future__ import annotations

import functools
import tempfile
import tomllib
from pathlib import Path

import control
import numpy as np
import pytest

from hinfnav.design.from_file import design_from_system_file
from hinfnav.design.polytopic import certify_polytopic, error_coordinates
from hinfnav.systems.files import read_system_file
from hinfnav.systems.polytopic import PolytopicSystem

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
FACTORS = (1e-6, 1e-3, 1e3, 1e6)


def _toml_value(v):
    if isinstance(v, list):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    if isinstance(v, str):
        return '"' + v + '"'
    return repr(float(v)) if isinstance(v, float) else repr(v)


def _write_in_units(src: Path, dst: Path, t: np.ndarray) -> Path:
    """Copy of the system file ``src`` with the states in other units, x' = diag(t)⁻¹ x."""
    data = tomllib.loads(src.read_text())

    def scale(table):
        out = dict(table)
        for key, f in (("A", lambda M: M * t[None, :] / t[:, None]), ("B", lambda M: M / t[:, None]),
                       ("C", lambda M: M * t[None, :]), ("L", lambda M: M * t[None, :])):
            if key in table:
                out[key] = f(np.asarray(table[key], dtype=float)).tolist()
        return out

    lines = [f"dt = {_toml_value(data['dt'])}", "", "[nominal]"]
    lines += [f"{k} = {_toml_value(v)}" for k, v in scale(data["nominal"]).items()]
    unc = data.get("uncertainty")
    if unc is not None:
        lines += ["", "[uncertainty]"] + [f"{k} = {_toml_value(v)}" for k, v in unc.items() if k != "vertices"]
        for vert in unc.get("vertices", []):
            lines += ["", "[[uncertainty.vertices]]"] + [f"{k} = {_toml_value(v)}" for k, v in scale(vert).items()]
    dst.write_text("\n".join(lines) + "\n")
    return dst


def _vertex_norms(result, form):
    """H∞ norm of the error system at each vertex (python-control), the independent sampled worst case."""
    system = result.system
    verts = system.vertices if isinstance(system, PolytopicSystem) else (system,)
    norms = []
    for v in verts:
        Ab, Bb, Cb = error_coordinates((v.A, v.B, v.C, v.D, v.L), result.A_F, result.B_F, result.C_F, form)
        assert np.max(np.abs(np.linalg.eigvals(Ab))) < 1.0
        g = control.ss(Ab, Bb, Cb, np.zeros((Cb.shape[0], Bb.shape[1])), True)
        norms.append(float(control.norm(g, "inf")))
    return max(norms)


CASES = [("double_integrator", "observer", 4), ("double_integrator_position", "observer", 4),
         ("two_mass_spring_30pct", "general", 4), ("two_mass_spring_30pct", "observer", 4)]


@functools.cache
def _reference(name, form):
    return design_from_system_file(EXAMPLES / f"{name}.toml", form=form)[0]


# fast: the double integrator (~0.1 s a design) at every factor, the others (general form) at one; the rest slow
PARAMS = [pytest.param(name, form, n, which, factor,
                       marks=() if name == "double_integrator" or ((factor, which) == (1e-3, "positions") and form == "general")
                       else pytest.mark.slow)
          for name, form, n in CASES for which in ("all", "positions") for factor in FACTORS]
# the flexible attitude polytope (augmented observer on cells, ~6 s a design): two of the unit changes, slow;
# and the closed-loop one in the general form on cells (~14 s a design)
PARAMS += [pytest.param(name, form, 4, which, factor, marks=pytest.mark.slow)
           for name, form in (("flexible_attitude_20pct", "observer"), ("flexible_attitude_closed_loop_20pct", "general"))
           for which, factor in (("positions", 1e-6), ("all", 1e6))]


@pytest.mark.parametrize("name, form, n, which, factor", PARAMS)
def test_gamma_does_not_depend_on_the_state_units(tmp_path, name, form, n, which, factor):
    ref = _reference(name, form)
    t = np.full(n, factor) if which == "all" else np.array([factor] * (n // 2) + [1.0] * (n - n // 2))
    path = _write_in_units(EXAMPLES / f"{name}.toml", tmp_path / "scaled.toml", t)
    res, summary = design_from_system_file(path, form=form)
    # expected: the design of the file in its own units (same estimation problem), within 1e-6 relative (issue 36)
    assert res.gamma == pytest.approx(ref.gamma, rel=1e-6)
    assert summary["gamma"] == res.gamma
    # the certificate holds on the data of the scaled file (re-run from the witness alone) ...
    if "T" not in res.witness and "cells" not in res.witness:
        assert certify_polytopic(res.system if isinstance(res.system, PolytopicSystem)
                                 else PolytopicSystem((res.system,), res.system.dt),
                                 res.A_F, res.B_F, res.C_F, res.witness, form)[0] == pytest.approx(res.gamma, rel=1e-12)
    # ... and bounds the vertices' H∞ norms computed independently with python-control
    assert _vertex_norms(res, form) <= res.gamma * (1 + 1e-9)


def test_the_scaled_file_is_the_same_system():
    # guard on the test's own writer: the file in other units reads back as T⁻¹AT, T⁻¹B, CT, LT
    t = np.array([1e3, 1e3, 1.0, 1.0])
    src = EXAMPLES / "two_mass_spring_30pct.toml"
    with tempfile.TemporaryDirectory() as d:
        s2 = read_system_file(_write_in_units(src, Path(d) / "s.toml", t))
    s = read_system_file(src)
    for v, v2 in zip(s.vertices, s2.vertices):
        np.testing.assert_allclose(v2.A, v.A * t[None, :] / t[:, None], rtol=1e-15)
        np.testing.assert_allclose(v2.B, v.B / t[:, None], rtol=1e-15)
        np.testing.assert_allclose(v2.L, v.L * t[None, :], rtol=1e-15)
        np.testing.assert_array_equal(v2.D, v.D)
