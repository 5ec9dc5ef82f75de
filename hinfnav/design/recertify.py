"""Re-check a saved design without a solver: its LMI in float64 at the saved witness, and sampled norms.

:func:`recertify` loads a design file (refused if edited: the fingerprint
covers the filter, the certificate, the system and the witness), evaluates
the LMI the certificate was given by at the saved Lyapunov/slack variables
(eigenvalue test, :func:`hinfnav.analysis.certificates.schur_gamma`) and
computes the H∞ norms of the error system at the uncertainty samples (a
dense grid of the simplex for a polytope). It passes when the LMI level
recomputed is at most the stored γ (relative 1e-6) and no sampled norm
exceeds it.
"""

from __future__ import annotations

import os
from typing import Any

import numpy as np

from ..analysis.certificates import brl_matrix, schur_gamma
from ..analysis.error_system import error_system_matrices, worst_case_norm
from ..core.exceptions import InputError
from ..lmi.blocks import gamma_index, lmi20_matrix
from ..systems.polytopic import PolytopicSystem
from .io import load_design
from .polytopic import COVERS, certify_polytopic, sampled_norms
from .samples import default_uncertainty_samples

__all__ = ["recertify"]

_RTOL = 1e-6


def _lmi_levels(result, system):
    """LMI levels certifiable from the saved witness of a norm-bounded/nominal design: {name: γ}."""
    w, out = result.witness, {}
    if "G" in w and "P" in w:  # nominal observer form in error coordinates
        poly = PolytopicSystem((system,), system.dt)
        out["extended BRL (E1), error coordinates"] = certify_polytopic(poly, result.A_F, result.B_F, result.C_F,
                                                                       {"P": w["P"], "G": w["G"]}, "observer")[0]
    if "R" in w and "S" in w and result.A_F.shape[0] == system.n:
        H, E = w.get("H"), w.get("E")
        H = None if H is None or np.size(H) == 0 else np.asarray(H, dtype=float)
        E = None if H is None else np.asarray(E, dtype=float)
        R, S = np.asarray(w["R"], dtype=float), np.asarray(w["S"], dtype=float)
        M0 = lmi20_matrix(system.A, system.B, system.C, system.D, system.L, H, E, R, S, S @ result.A_F,
                          S @ result.B_F, result.C_F, float(w.get("lam", 0.0)), 0.0)
        out["LMI (20)"] = schur_gamma(M0, gamma_index(system.n, system.B.shape[1], system.D.shape[1]))[0]
    if "lyapunov_full" in w:
        Ab, Bb, Cb = error_system_matrices(system.A, system.B, system.C, system.D, system.L, result.A_F, result.B_F,
                                           result.C_F)
        H = None if w.get("H") is None else np.asarray(w["H"], dtype=float)
        Hb = None if H is None else np.vstack([H, np.zeros((result.A_F.shape[0], H.shape[1]))])
        E = None if H is None else np.asarray(w["E"], dtype=float)
        Eb = None if H is None else np.hstack([E, np.zeros((E.shape[0], result.A_F.shape[0]))])
        M0 = brl_matrix(Ab, Bb, Cb, np.asarray(w["lyapunov_full"], dtype=float), 0.0, Hb, Eb,
                        float(w.get("lam_full", 0.0)))
        N = Ab.shape[0]
        out["robust bounded real LMI, full Lyapunov matrix"] = schur_gamma(M0, np.arange(2 * N, 2 * N + Bb.shape[1]))[0]
    return out


def _lyapunov_proven(witness):
    """"common" when the witness holds one Lyapunov matrix for every vertex (equal to 1e-12), else "parameter-dependent"."""
    Ps = [np.asarray(P, dtype=float) for P in witness.get("P", [])]
    if not Ps:
        return "common"
    scale = max(float(np.max(np.abs(Ps[0]))), np.finfo(float).tiny)
    same = all(P.shape == Ps[0].shape and np.allclose(P, Ps[0], rtol=0, atol=1e-12 * scale) for P in Ps[1:])
    return "common" if same else "parameter-dependent"


def recertify(path: str | os.PathLike[str]) -> dict[str, Any]:
    """Re-check a saved design in float64 without a solver and report.

    Parameters
    ----------
    path : str or Path
        A design file (``save_design`` / ``design --save``).

    Returns
    -------
    dict
        ``ok`` (bool), ``gamma`` (stored), ``lmi_levels`` (level recomputed
        from each saved LMI witness), ``lmi_gamma_recomputed`` (the smallest),
        ``sampled_worst_norm``, ``n_samples``, ``covers``, ``reasons`` (why
        not ok).

    Raises
    ------
    InputError
        The file is missing, not a design, or was edited (fingerprint).
    """
    result, system, d = load_design(path)
    reasons = []
    polytopic = result.uncertainty == "polytope"
    if polytopic:
        name = "extended H2 LMIs (E2)" if result.objective == "h2" else "extended BRL (E1)"
        levels = {f"{name} at every vertex": certify_polytopic(system, result.A_F, result.B_F, result.C_F,
                                                               result.witness, result.form)[0]}
        proven = _lyapunov_proven(result.witness)
        if result.lyapunov != proven:  # the label must be what the witness proves (issue 36)
            reasons.append(f"the file says lyapunov = {result.lyapunov!r} but its witness holds "
                           f"{'one Lyapunov matrix for every vertex' if proven == 'common' else 'a different Lyapunov matrix per vertex'}"
                           f": it proves {proven!r} only (covers {COVERS[proven]})")
        alphas = result.alphas if np.size(result.alphas) else None
        norms, radii, _ = sampled_norms(system, result.A_F, result.B_F, result.C_F, result.form, alphas,
                                        result.objective, witness=result.witness)
    else:
        levels = _lmi_levels(result, system)
        if "G" in result.witness:
            poly = PolytopicSystem((system,), system.dt)
            norms, radii, _ = sampled_norms(poly, result.A_F, result.B_F, result.C_F, "observer")
        else:
            samples = default_uncertainty_samples(system, result.structure if result.structure in ("full", "diagonal")
                                                  else "full")
            wc = worst_case_norm(system, result.A_F, result.B_F, result.C_F, samples)
            norms, radii = wc.norms, wc.spectral_radii
    if not levels:
        raise InputError(f"design file {path} holds no LMI witness to re-check (saved by an older version?)")
    best = min(levels.values())
    worst = float(np.max(norms))
    if not best <= result.gamma * (1 + _RTOL):
        reasons.append(f"the saved LMI witness certifies γ = {best:.10g} only, above the stored γ = {result.gamma:.10g}")
    if not np.all(np.asarray(radii) < 1.0):
        reasons.append("the error system is not Schur stable at some sample")
    if worst > result.gamma * (1 + 1e-9):
        reasons.append(f"a sampled norm {worst:.10g} exceeds the stored bound {result.gamma:.10g}")
    return {
        "ok": not reasons,
        "path": str(path),
        "gamma": result.gamma,
        "lmi_levels": {k: float(v) for k, v in levels.items()},
        "lmi_gamma_recomputed": float(best),
        "sampled_worst_norm": worst,
        "n_samples": int(np.size(norms)),
        "covers": (COVERS[proven] if polytopic and proven != result.lyapunov
                   else d["certificate"].get("covers", "")),
        "lyapunov_proven": proven if polytopic else "common",
        "objective": result.objective,
        "reasons": reasons,
    }
