"""The estimator interface, and the fixed LTI filter (12).

Every estimator turns a batch of measurement histories into state-estimate
histories through one method::

    history = estimator.estimate(y, u, xhat0)

with ``y`` of shape (runs, n_steps + 1, 3) (the measurements y(k) of (8) at
t_k = kT), ``u`` of shape (runs, n_steps + 1, 3) (the thrust applied over
[t_k, t_k+1), N), and the initial estimate ``xhat0`` (6,). It returns an
:class:`EstimateHistory`: the estimate of x(k) available at t_k, and, for
filters that carry one, its covariance.

Two flags describe an estimator:

``uses_input``
    whether it uses the known thrust u (a filter designed on the closed loop
    u = Kx without it assumes that law);
``vectorized``
    whether one call processes all runs at once (LTI filters), or the
    simulation should call it run by run (nonlinear filters); both give the
    same numbers.
"""

from dataclasses import dataclass

import numpy as np

from .exceptions import InputError
from .validation import as_matrix, as_positive, as_vector

__all__ = ["EstimateHistory", "Estimator", "LTIFilter", "check_estimator_inputs"]


@dataclass(frozen=True, eq=False)
class EstimateHistory:
    """What an estimator returns.

    Attributes
    ----------
    xhat : ndarray, shape (runs, n_steps + 1, 6)
        Estimate of x(k) available at t_k.
    P : ndarray, shape (runs, n_steps + 1, 6, 6), or None
        Error covariance the filter believes in (None for filters without one).
    """

    xhat: np.ndarray
    P: np.ndarray = None


def check_estimator_inputs(y, u, xhat0, n_state=6):
    """Validate the arguments of :meth:`Estimator.estimate`; return float arrays."""
    y = np.asarray(y, dtype=float)
    if y.ndim != 3:
        raise InputError(f"y must have shape (runs, n_steps + 1, n_meas); got {y.shape}")
    if not np.all(np.isfinite(y)):
        raise InputError("y must contain only finite numbers; it has NaN or inf entries")
    u = np.asarray(u, dtype=float)
    if u.ndim != 3 or u.shape[:2] != y.shape[:2]:
        raise InputError(f"u must have shape (runs, n_steps + 1, n_input) matching y {y.shape[:2]}; got {u.shape}")
    if not np.all(np.isfinite(u)):
        raise InputError("u must contain only finite numbers; it has NaN or inf entries")
    xhat0 = as_vector("xhat0", xhat0, n_state)
    return y, u, xhat0


class Estimator:
    """Base class of the estimators (see the module docstring).

    Attributes
    ----------
    name : str
    uses_input : bool
    vectorized : bool
    """

    name = "estimator"
    uses_input = False
    vectorized = False

    def estimate(self, y, u, xhat0):
        """Estimate the state histories of a batch of runs.

        Parameters
        ----------
        y : array_like, shape (runs, n_steps + 1, 3)
            Measurements y(k), m.
        u : array_like, shape (runs, n_steps + 1, 3)
            Applied thrust u(k), N.
        xhat0 : array_like, shape (6,)
            Initial estimate, m and m/s.

        Returns
        -------
        EstimateHistory
        """
        raise NotImplementedError

    def __repr__(self):
        return f"<{type(self).__name__} {self.name!r} uses_input={self.uses_input}>"


class LTIFilter(Estimator):
    """The full-order filter F_d of (12), optionally told the applied thrust.

    ``x_f(k+1) = A_F x_f(k) + B_F y(k)``, ``ẑ(k) = C_F x_f(k)``.

    The filter is designed on the closed loop ``A = I + T(A₁ + G₀K)``: it
    assumes the thrust is ``K x``. With ``input_matrix=Γ`` and ``K`` given it
    replaces that assumed thrust by the applied one::

        x_f(k+1) = A_F x_f(k) + B_F y(k) + C_F⁻¹ Γ (u(k) − K ẑ(k))

    which is exact for a filter in observer form and needed when the truth
    does not follow u = Kx (no maneuver). It requires ``C_F`` square and
    invertible (L = I, the whole state estimated).

    Parameters
    ----------
    A_F : array_like, shape (n, n)
    B_F : array_like, shape (n, 3)
    C_F : array_like, shape (n, n)
    dt : float
        Sampling time, s.
    name : str
    input_matrix : array_like, shape (n, 3), optional
        Γ = T G₀ of the design model. Together with ``K`` switches on the
        known-input correction.
    K : array_like, shape (3, n), optional
        The feedback gain the design assumed.

    Notes
    -----
    The estimate at t_k uses y(0) … y(k−1), as (12) prescribes; the initial
    filter state is ``x_f(0) = C_F⁻¹ x̂(0)`` so that the first estimate is
    the scenario's initial estimate.
    """

    vectorized = True

    def __init__(self, A_F, B_F, C_F, *, dt, name="lti", input_matrix=None, K=None):
        self.A_F = as_matrix("A_F", A_F)
        n = self.A_F.shape[0]
        if self.A_F.shape != (n, n):
            raise InputError(f"A_F must be square; got shape {self.A_F.shape}")
        self.B_F = as_matrix("B_F", B_F, (n, None))
        self.C_F = as_matrix("C_F", C_F, (n, n))
        self.dt = as_positive("dt", dt)
        self.name = str(name)
        cond = np.linalg.cond(self.C_F)
        if not np.isfinite(cond) or cond > 1e12:
            raise InputError(f"C_F must be invertible (the filter estimates the whole state); its condition number is {cond:.3g}")
        self._CF_inv = np.linalg.inv(self.C_F)
        if (input_matrix is None) != (K is None):
            raise InputError("input_matrix and K must be given together to use the known thrust")
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

    def estimate(self, y, u, xhat0):
        y, u, xhat0 = check_estimator_inputs(y, u, xhat0, self.A_F.shape[0])
        if y.shape[2] != self.B_F.shape[1]:
            raise InputError(f"y has {y.shape[2]} measurement channels but B_F has {self.B_F.shape[1]} columns")
        runs, n1, _ = y.shape
        n = self.A_F.shape[0]
        drive = y @ self.B_F.T
        if self.uses_input:
            if u.shape[2] != self._M.shape[1]:
                raise InputError(f"u has {u.shape[2]} channels but input_matrix has {self._M.shape[1]} columns")
            drive = drive + u @ self._M.T
        xf = np.empty((runs, n1, n))
        xf[:, 0] = self._CF_inv @ xhat0
        At = self._A_eff.T
        for k in range(n1 - 1):
            xf[:, k + 1] = xf[:, k] @ At + drive[:, k]
        return EstimateHistory(xhat=xf @ self.C_F.T)
