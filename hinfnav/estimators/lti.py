"""The fixed full-order LTI filter (12) of Sun et al. (2011), on the step contract."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from ..core.exceptions import InputError
from ..core.linalg import spectral_radius
from ..core.validation import as_matrix
from .base import Estimator, FilterState, StepOutput

if TYPE_CHECKING:
    from ..systems.dynamics import DynamicsModel
    from ..systems.linear import LinearSystem
    from ..systems.measurements import MeasurementModel

__all__ = ["LTIFilter"]


class LTIFilter(Estimator):
    """The full-order filter F_d of (12), optionally told the applied input.

    ``x_f(k+1) = A_F x_f(k) + B_F y(k)``, ``ẑ(k) = C_F x_f(k)``.

    A filter designed on a closed loop ``A = Φ + Γ K`` assumes the input is
    ``K x``. With ``input_matrix=G`` and ``K`` given it replaces that assumed
    input by the applied one::

        x_f(k+1) = A_F x_f(k) + B_F y(k) + C_F⁻¹ G (u(k) − K ẑ(k))

    which is exact for a filter in observer form. It requires ``C_F`` square
    and invertible (the whole state estimated).

    Parameters
    ----------
    A_F : array_like, shape (n, n)
    B_F : array_like, shape (n, m)
    C_F : array_like, shape (n, n)
    system : LinearSystem
        The system the filter estimates (labels, units, dt; ``n`` must match).
    measurement : MeasurementModel
        Its measurement (``n_meas`` must equal the columns of B_F).
    name : str
    input_matrix : array_like, shape (n, m_u), optional
        G of the design model. Together with ``K`` switches on the
        known-input correction (then ``uses_input`` is True).
    K : array_like, shape (m_u, n), optional
        The feedback gain the design assumed.
    missing : {"refuse", "skip"}
        A NaN channel of a reading: an InputError, or (fixed gains) replaced
        by the reading the filter predicts from its estimate, ``h(x̂(k))``,
        so that it drives the filter with a zero innovation (documented
        choice: the gain B_F is not re-designed for the channels left).

    Notes
    -----
    A predictor: the estimate at t_k uses y(0) … y(k−1), as (12) prescribes
    (``update`` stores y_k and reports ``C_F x_f(k)``). The initial filter
    state is ``x_f(0) = C_F⁻¹ x̂(0)`` so that the first estimate is x̂(0).
    The gains are fixed: the batch ``estimate`` runs the compiled kernel
    (:func:`hinfnav.estimators.compiled_kernels.lti_batch`, the same
    recursion) by default, the base class's loop over these hooks with
    ``backend="numpy"``. It reports no covariance and no diagnostics.
    """

    #: The compiled kernel of this class (:mod:`hinfnav.estimators.compiled`; declared per class, not inherited).
    compiled_kernel = "lti"

    def __init__(self, A_F: ArrayLike, B_F: ArrayLike, C_F: ArrayLike, system: LinearSystem | DynamicsModel, measurement: MeasurementModel,
                 *, name: str = "lti", input_matrix: ArrayLike | None = None, K: ArrayLike | None = None, missing: str = "refuse") -> None:
        super().__init__(system, measurement, name=name, missing=missing)
        n = system.n
        self.A_F = as_matrix("A_F", A_F, (n, n))
        self.B_F = as_matrix("B_F", B_F, (n, measurement.n_meas))
        self.C_F = as_matrix("C_F", C_F, (n, n))
        cond = np.linalg.cond(self.C_F)
        if not np.isfinite(cond) or cond > 1e12:
            raise InputError(f"C_F must be invertible (the filter estimates the whole state); its condition number is {cond:.3g}")
        self._CF_inv = np.linalg.inv(self.C_F)
        if (input_matrix is None) != (K is None):
            raise InputError("input_matrix and K must be given together to use the known input")
        self.uses_input = input_matrix is not None
        if self.uses_input:
            G = as_matrix("input_matrix", input_matrix, (n, None))
            self.K = as_matrix("K", K, (G.shape[1], n))
            self._M = self._CF_inv @ G
            self._A_eff = self.A_F - self._M @ self.K @ self.C_F
        else:
            self.K = None
            self._M = None
            self._A_eff = self.A_F
        rho = spectral_radius(self._A_eff)
        if not rho < 1.0:
            what = "A_F with the input correction (A_F − C_F⁻¹ G K C_F)" if self.uses_input else "A_F"
            raise InputError(
                f"{what} must be Schur stable (spectral radius < 1); it is {rho:.6g}: the filter's estimates "
                "would diverge whatever the data (check A_F, or the T and K it was designed for)"
            )

    @property
    def A_effective(self) -> np.ndarray:
        """The matrix of the recursion: ``A_F``, or ``A_F − C_F⁻¹ G K C_F`` with the known input."""
        return self._A_eff

    @property
    def input_correction(self) -> np.ndarray | None:
        """``C_F⁻¹ G`` (n, m_u) of the known-input correction, None without it."""
        return self._M

    @property
    def n_input(self) -> int:
        return 0 if self._M is None else self._M.shape[1]

    def _start(self, xhat0, P0, runs):
        x0 = self._CF_inv @ np.asarray(xhat0, dtype=float)
        return FilterState(x=np.broadcast_to(x0, (runs, x0.size)).copy())

    def _update(self, state, y):
        xhat = state.x @ self.C_F.T
        if self.missing == "skip" and np.isnan(y).any():
            y = np.where(np.isnan(y), self.measurement.function(xhat), y)  # the reading the filter predicts
        state.extra["y"] = y
        return state, StepOutput(xhat=xhat)

    def _drive(self, y, u):
        drive = y @ self.B_F.T
        if self.uses_input:
            drive = drive + u @ self._M.T
        return drive

    def _predict(self, state, u):
        if self.uses_input and u is None:
            raise InputError(f"filter {self.name!r} uses the applied input: predict needs u")
        x = state.x @ self._A_eff.T + self._drive(state.extra["y"], u)
        return FilterState(x=x, k=state.k + 1)
