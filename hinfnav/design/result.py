"""The result of a certified robust filter synthesis."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import control
import numpy as np
from numpy.typing import ArrayLike

from ..analysis.error_system import error_system

if TYPE_CHECKING:
    from ..systems.uncertain import UncertainSystem

__all__ = ["FilterDesign", "SynthesisResult"]

@dataclass(frozen=True, eq=False)
class FilterDesign:
    """What every certified filter design holds first: the filter (12) and its levels.

    The common head of :class:`SynthesisResult` (norm-bounded uncertainty) and
    :class:`~hinfnav.design.polytopic.PolytopicResult` (a polytope), whose
    attributes say what each level certifies.

    Attributes
    ----------
    A_F, B_F, C_F : ndarray
        The filter ``x_f(k+1) = A_F x_f(k) + B_F y(k)``, ``z_f = C_F x_f``.
    gamma : float
        Certified level.
    lmi_gamma : float
        The solver's level.
    verified_norm : float
        Largest sampled norm of the error system (a lower bound of the worst case).
    sample_norms : ndarray, shape (K,)
    """

    A_F: np.ndarray
    B_F: np.ndarray
    C_F: np.ndarray
    gamma: float
    lmi_gamma: float
    verified_norm: float
    sample_norms: np.ndarray

    def statespace(self) -> control.StateSpace:
        """The filter as a discrete :class:`control.StateSpace` (y → z_f), with the design's ``dt``."""
        return control.ss(self.A_F, self.B_F, self.C_F, np.zeros((self.C_F.shape[0], self.B_F.shape[1])), self.dt)


@dataclass(frozen=True, eq=False)
class SynthesisResult(FilterDesign):
    """A certified robust H∞ filter (12) from Theorem 1 / Corollary 1.

    Attributes
    ----------
    A_F : ndarray, shape (n, n)
    B_F : ndarray, shape (n, m)
    C_F : ndarray, shape (l, n)
        The filter ``x_f(k+1) = A_F x_f(k) + B_F y(k)``, ``z_f = C_F x_f``,
        rebuilt by (21), in the plant's (unscaled) state coordinates.
    gamma : float
        Certified level: LMI (20) holds (float64 eigenvalue test) at the
        returned filter with this γ, so ``‖Ψ‖∞ < gamma`` for every admissible
        F (Theorem 1); every sampled norm is ≤ ``gamma``.
    lmi_gamma : float
        The γ the solver reached (minimum of Corollary 1, or the last feasible
        level of the bisection).
    verified_norm : float
        Largest H∞ norm of the error system (13)–(15) over the samples
        (SLICOT ab13dd), a lower bound of the true worst case.
    sample_norms : ndarray, shape (k,)
        The norm at each uncertainty sample.
    worst_sample : int
        Index of the worst sample.
    spectral_radius : float
        Largest spectral radius of the error system over the samples (< 1).
    solver : str
        Solver of the accepted solution.
    solve_time_s : float
        Wall time spent in the solvers (all attempts), s.
    total_time_s : float
        Wall time of the whole synthesis with certification, s.
    method : str
        ``"minimize"`` (Corollary 1 directly) or ``"bisection"``.
    dt : float or True
        Sampling time of :meth:`statespace`.
    variables : dict
        LMI variables in the original coordinates: ``R``, ``S``, ``Abar_F``,
        ``Bbar_F``, ``Cbar_F`` (= ``S A_F``, ``S B_F``, ``C_F``), ``lam``; and
        the balanced uncertainty factors ``H``, ``E`` they go with (``None``
        for a nominal design).
    attempts : tuple of str
        Log of the solves tried and why each was accepted or refused.
    structure : str
        Uncertainty structure assumed (``"diagonal"`` or ``"full"``).
    samples : tuple
        The uncertainty matrices F that were checked.
    uncertainty_bound : float or None
        Bound of the scalar parameter the uncertainty stands for, when the
        samples came from a :class:`~hinfnav.design.samples.SampleSet` that
        has one (e.g. the bound of a relative parameter error); None otherwise.
    sample_values : ndarray or None
        The parameter value of each sample (same order as ``sample_norms``),
        from the sample set; None when the samples carry no values.
    sample_labels : tuple of str
        A label per sample (e.g. ``"δ = 0.05"``).
    form : str
        ``"general"`` (LMI (20) as in the paper) or ``"observer"`` (filter
        constrained to ``C_F = −L``, ``A_F = A + B_F C``; see :func:`synthesize`).
    system : UncertainSystem or None
        The system the filter was designed for (with its sampling time), so
        that a design can be saved with its own system.
    solver_calls : int
        Solver invocations of the design (LMI solves; a retry at looser
        tolerances counts), see :mod:`hinfnav.design.certify_loop`.
    """

    worst_sample: int
    spectral_radius: float
    solver: str
    solve_time_s: float
    total_time_s: float
    method: str
    dt: object = True
    variables: dict = field(default_factory=dict)
    attempts: tuple = ()
    structure: str = "full"
    samples: tuple = ()
    uncertainty_bound: float = None
    sample_values: np.ndarray = None
    form: str = "general"
    sample_labels: tuple = ()
    system: object = None
    solver_calls: int = 0

    @property
    def worst_value(self) -> float | None:
        """Parameter value of the worst sample (None when the samples carry no values)."""
        return None if self.sample_values is None else float(self.sample_values[self.worst_sample])

    def error_system(self, system: UncertainSystem, F: ArrayLike | None = None) -> control.StateSpace:
        """Error system (13)–(15) of this filter on ``system`` at uncertainty F."""
        Ap = system.A if F is None else system.perturbed_A(F)
        return error_system(Ap, system.B, system.C, system.D, system.L, self.A_F, self.B_F, self.C_F, self.dt)


