"""The one result type of every certified filter design (:class:`DesignResult`)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import control
import numpy as np
from numpy.typing import ArrayLike

from ..analysis.error_system import error_system
from ..core.exceptions import InputError

if TYPE_CHECKING:
    from ..systems.uncertain import UncertainSystem

__all__ = ["DesignResult", "COVERS_NORM_BOUNDED", "COVERS_NOMINAL"]


#: What the certificate of a norm-bounded design (LMI (20), one quadratic Lyapunov function) covers.
COVERS_NORM_BOUNDED = "every time-varying F(k) with FᵀF ≤ I (one quadratic Lyapunov function)"
#: What the certificate of a design without uncertainty covers.
COVERS_NOMINAL = "the nominal system"


@dataclass(frozen=True, eq=False)
class DesignResult:
    """A certified filter design: the one result type of every design of hinfnav.

    Returned by :func:`~hinfnav.design.synthesize` (norm-bounded uncertainty,
    Theorem 1 / Corollary 1), :func:`~hinfnav.design.synthesize_polytopic`
    (a polytope, also with cells or the augmented observer form),
    :func:`~hinfnav.design.synthesize_mixed` (mixed H2/H∞) and
    :func:`~hinfnav.design.design_continuous_system` (continuous time). What
    the certificate says is in its fields, not in the type: ``uncertainty``
    (``"norm-bounded"`` or ``"polytope"``), ``domain`` (``"discrete"`` or
    ``"continuous"``), ``lyapunov`` and ``covers`` (which uncertainty and
    time variation the bound holds for), ``objective`` (``"hinf"``, ``"h2"``
    or ``"mixed"``) and ``witness`` (the LMI variables an independent check
    re-evaluates, :func:`~hinfnav.design.recertify`).

    Attributes
    ----------
    A_F : ndarray, shape (n_f, n_f)
    B_F : ndarray, shape (n_f, m)
    C_F : ndarray, shape (l, n_f)
        The filter ``x_f(k+1) = A_F x_f(k) + B_F y(k)``, ``z_f = C_F x_f``
        (``ẋ_f = A_F x_f + B_F y`` in continuous time), in the plant's
        (unscaled) state coordinates.
    gamma : float
        Certified level: the design's LMI holds in float64 (eigenvalue test)
        at the returned filter and witness with this γ, so the error system's
        norm is below ``gamma`` for everything ``covers`` names; every
        sampled norm is ≤ ``gamma``. With ``objective="h2"`` an H2 bound;
        with ``"mixed"`` the H∞ bound (the H2 bound is ``h2_bound``).
    lmi_gamma : float
        The level the solver reached (minimum, or the last feasible level of
        a bisection; for a mixed design the γ imposed, ``inf`` without one).
    verified_norm : float
        Largest sampled norm of the error system (a lower bound of the worst case).
    sample_norms : ndarray, shape (k,)
        The norm at each sample.
    worst_sample : int
        Index of the worst sample.
    spectral_radius : float
        Largest spectral radius of the error system over the samples (< 1;
        NaN in continuous time).
    solver : str
        Solver of the accepted solution.
    solve_time_s, total_time_s : float
        Wall time in the solvers (all attempts), and of the whole design with
        its certification, s.
    method : str
        ``"minimize"``, ``"bisection"`` or ``"h2-minimize"`` (mixed).
    dt : float or True
        Sampling time of :meth:`statespace` (0: continuous time).
    witness : dict
        The LMI variables of the certificate. Norm-bounded: ``R``, ``S``,
        ``Abar_F``, ``Bbar_F``, ``Cbar_F``, ``lam`` in the original
        coordinates and the balanced factors ``H``, ``E`` they go with (an
        observer-form nominal design: ``P``, ``G``). Polytope: ``P`` (one per
        vertex) and ``G`` (and ``W`` for H2, ``T`` and ``C0`` for the
        augmented observer form, ``cells``). Mixed: ``X, Y, Z, P2, Pinf``, ….
        Continuous: ``P``, ``F``, ``G`` and the line-search value ``eps``.
    attempts : tuple of str
        Log of the solves tried and why each was accepted or refused.
    structure : str
        Norm-bounded: the uncertainty structure assumed (``"diagonal"`` or ``"full"``).
    samples : tuple
        Norm-bounded: the uncertainty matrices F that were checked.
    uncertainty_bound : float or None
        Bound of the scalar parameter the uncertainty stands for, when the
        samples came from a :class:`~hinfnav.design.samples.SampleSet` that
        has one; None otherwise.
    sample_values : ndarray or None
        The parameter value of each sample (same order as ``sample_norms``).
    sample_labels : tuple of str
        A label per sample (e.g. ``"δ = 0.05"``).
    form : str
        ``"general"`` (any full-order filter) or ``"observer"`` (``C_F = −L``,
        ``A_F = A + B_F C``).
    system : UncertainSystem, PolytopicSystem, ContinuousPolytope or None
        The system the filter was designed for (with its sampling time).
    solver_calls : int
        Solver invocations of the design (a retry at looser tolerances
        counts), see :mod:`hinfnav.design.certify_loop`.
    uncertainty : {"norm-bounded", "polytope"}
        The uncertainty model of ``system``.
    domain : {"discrete", "continuous"}
    lyapunov : str
        ``"common"`` (one quadratic Lyapunov function: LMI (20), or one
        matrix on every vertex), ``"parameter-dependent"`` (one per vertex),
        ``"extended"`` (mixed design: separate H2 and H∞ matrices, one slack).
    covers : str
        What the certificate covers, in words.
    alphas : ndarray, shape (K, N) or None
        Polytope: the convex weights sampled.
    objective : {"hinf", "h2", "mixed"}
    h2_bound, h2_lmi, h2_synthesis_bound, h2_analysis_bound, h2_verified : float
        Mixed design: certified ν (the smaller of the synthesis and analysis
        certificates), the solver's ν, the two certificates, the largest
        sampled H2 norm (NaN for other designs).
    h2_sample_norms : ndarray or None
        Mixed design: the H2 norm at each sample.
    gamma_bound : float or None
        Mixed design: the γ it was asked to respect (None: unconstrained).
    """

    A_F: np.ndarray
    B_F: np.ndarray
    C_F: np.ndarray
    gamma: float
    lmi_gamma: float
    verified_norm: float
    sample_norms: np.ndarray
    worst_sample: int = 0
    spectral_radius: float = float("nan")
    solver: str = ""
    solve_time_s: float = 0.0
    total_time_s: float = 0.0
    method: str = "minimize"
    dt: object = True
    witness: dict = field(default_factory=dict)
    attempts: tuple = ()
    structure: str = "full"
    samples: tuple = ()
    uncertainty_bound: float = None
    sample_values: np.ndarray = None
    form: str = "general"
    sample_labels: tuple = ()
    system: object = None
    solver_calls: int = 0
    uncertainty: str = "norm-bounded"
    domain: str = "discrete"
    lyapunov: str = "common"
    covers: str = COVERS_NORM_BOUNDED
    alphas: np.ndarray = None
    objective: str = "hinf"
    h2_bound: float = float("nan")
    h2_lmi: float = float("nan")
    h2_synthesis_bound: float = float("nan")
    h2_analysis_bound: float = float("nan")
    h2_verified: float = float("nan")
    h2_sample_norms: np.ndarray = None
    gamma_bound: float = None

    def statespace(self) -> control.StateSpace:
        """The filter as a :class:`control.StateSpace` (y → z_f), with the design's ``dt`` (0: continuous)."""
        return control.ss(self.A_F, self.B_F, self.C_F, np.zeros((self.C_F.shape[0], self.B_F.shape[1])), self.dt)

    @property
    def worst_value(self) -> float | None:
        """Parameter value of the worst sample (None when the samples carry no values)."""
        return None if self.sample_values is None else float(self.sample_values[self.worst_sample])

    def error_system(self, system: UncertainSystem | None = None, F: ArrayLike | None = None) -> control.StateSpace:
        """Error system (13)–(15) of this filter on a norm-bounded ``system`` (default its own) at uncertainty F."""
        system = self.system if system is None else system
        if self.uncertainty != "norm-bounded" or system is None or not hasattr(system, "perturbed_A"):
            raise InputError("error_system needs the norm-bounded UncertainSystem of the design (this design is on a "
                             f"{self.uncertainty}); for a polytope use hinfnav.design.sampled_norms")
        Ap = system.A if F is None else system.perturbed_A(F)
        return error_system(Ap, system.B, system.C, system.D, system.L, self.A_F, self.B_F, self.C_F, self.dt)
