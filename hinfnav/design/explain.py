"""Why a robust design is impossible or infeasible, in numbers and in generic terms.

:func:`small_gain_number` is ``‖E(zI − A)⁻¹H‖∞``: with one common Lyapunov
matrix and one multiplier (Corollary 1, quadratic stability of
``A + H F E`` for every time-varying contraction F), the γ-free part of the
robust LMI is feasible only if it is < 1 (small-gain theorem / bounded real
lemma), whatever the filter. :func:`infeasibility_hint` turns it into advice;
:func:`unstable_plant_message` says why a plant that is not robustly stable
cannot be handled in the general form.
"""

from __future__ import annotations

import control
import numpy as np
from numpy.typing import ArrayLike

from ..analysis.norms import hinf_norm
from ..core.linalg import spectral_radius

__all__ = ["small_gain_number", "infeasibility_hint", "unstable_plant_message"]


def small_gain_number(A: ArrayLike, H: ArrayLike | None, E: ArrayLike | None) -> float:
    """``‖E(zI − A)⁻¹H‖∞`` (dimensionless; ``inf`` if A is not Schur stable, ``0`` without H, E)."""
    if H is None or E is None or not (np.any(H) and np.any(E)):
        return 0.0
    A = np.asarray(A, dtype=float)
    if not spectral_radius(A) < 1.0:
        return float("inf")
    sys = control.ss(A, np.asarray(H, float), np.asarray(E, float), np.zeros((np.shape(E)[0], np.shape(H)[1])), True)
    return float(hinf_norm(sys))


def infeasibility_hint(A, H, E, structure="full", form="general"):
    """Advice for an infeasible norm-bounded robust design (text, generic)."""
    gain = small_gain_number(A, H, E)
    parts = []
    if H is not None and np.isfinite(gain):
        parts.append(
            f" The small-gain number ‖E(zI − A)⁻¹H‖∞ = {gain:.4g}"
            + (" ≥ 1: no single quadratic Lyapunov function makes A + H F E stable for every time-varying "
               "contraction F, so no filter exists in this formulation whatever γ."
               if gain >= 1 else " < 1: the plant is quadratically stable; the filter part of the LMI fails.")
        )
    if H is not None:
        parts.append(
            " If the uncertain parameter is constant (or slowly varying) in time, write the uncertainty as a "
            "polytope (hinfnav.PolytopicSystem.from_norm_bounded) and design with parameter-dependent Lyapunov "
            "matrices (hinfnav.synthesize_polytopic(..., lyapunov='parameter-dependent')), far less conservative; "
            "otherwise reduce the uncertainty (smaller H or E)."
        )
        if structure == "full" and min(np.shape(H)[1], np.shape(E)[0]) > 1:
            parts.append(" If F is diagonal, structure='diagonal' balances H and E channel by channel and is less "
                         "conservative.")
    if form == "observer":
        parts.append(" The observer-form constraints (C_F = −L, A_F = A + B_F C) were imposed; form='general' may "
                     "be feasible.")
    return "".join(parts)


def unstable_plant_message(rho, where):
    """Why a plant that is not (robustly) Schur stable has no general-form design, and what would help."""
    return (
        f"the plant is not robustly Schur stable: its state matrix has spectral radius {rho:.12g} >= 1 at {where}. "
        "Lemma 1 bounds the error system, and the error system of a general-form filter carries the plant state x "
        "(Ā = [[A + ΔA, 0], [B_F C, A_F]] is block triangular, so its eigenvalues include those of A + ΔA), "
        "and with uncertainty the estimation error contains ΔA x, driven by a growing x: no filter makes it "
        "stable and no finite γ exists. What helps: form='observer' when the plant is only detectable and the "
        "uncertainty does not multiply the plant state (no ΔA, no ΔC: nominal, or uncertain B, D only); "
        "designing on a stabilized plant (a closed loop u = Kx, A + G K) when the input is known; or a smaller "
        "uncertainty."
    )
