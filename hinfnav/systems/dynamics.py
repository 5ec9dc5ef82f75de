"""Dynamics models as objects: ``x(k+1) = f(x(k), u(k), t_k) + w(k)``, with their Jacobian.

A dynamics model is what a filter propagates its estimate with, as a
measurement model is what it compares the estimate with. Every model gives
(the protocol shared with :class:`~hinfnav.systems.LinearSystem`):

* ``n``, ``n_input``, ``dt`` (s), ``state`` (a :class:`~hinfnav.systems.StateSpec`);
* ``Q``, the per-step process-noise covariance (n, n) (additive w(k));
* ``linear`` — True only for a linear system (then ``jacobian`` is Φ);
* ``f(x, u=None, t=0.0)`` — the state one step later, for a batch ``x``
  (runs, n) at time t (s, t = k Δt) with inputs ``u`` (runs, n_input) or None;
* ``jacobian(x, u=None, t=0.0)`` — ``∂f/∂x``, shape (runs, n, n).

Three ways to bring a model:

* :class:`DiscreteDynamics` — a discrete map f, with its Jacobian or the
  central finite-difference default (:meth:`DynamicsModel.jacobian`);
* :class:`ContinuousDynamics` — ``ẋ = a(x, u, t)`` stepped over Δt by the
  classical fourth-order Runge–Kutta rule (RK4; ``substeps`` equal sub-steps,
  input held). Its Jacobian is **the Jacobian of the integrator step**
  (the derivative of the RK4 map itself, by the chain rule through the four
  stages (D2), from the continuous Jacobian ``∂a/∂x`` — analytic if given,
  else central differences of a). It is exact for the discrete map the filter
  propagates, so the EKF's ``F P Fᵀ`` is the linearisation of the mean
  prediction it actually uses (rather than ``expm(A Δt)``, which differs at
  O(Δt⁵) per sub-step);
* a subclass of :class:`DynamicsModel` overriding ``f`` (and ``jacobian``),
  as :class:`ConstantTurn`.
"""

from __future__ import annotations

import functools
from collections.abc import Callable

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..core.exceptions import InputError
from ..core.linalg import as_covariance
from ..core.validation import as_int_at_least, as_nonnegative, as_positive
from .checks import JACOBIAN_TOL, CheckedModel, call_model, check_jacobian_against_differences
from .compiled import CompiledDynamics, package_functions
from .state import StateSpec

__all__ = [
    "DynamicsModel",
    "DiscreteDynamics",
    "ContinuousDynamics",
    "ConstantTurn",
    "constant_turn_state_spec",
    "finite_difference_jacobian",
    "MAX_SUBSTEPS",
]

#: Largest ``substeps`` a :class:`ContinuousDynamics` accepts: RK4's error falls as substeps⁻⁴, so beyond this a
#: smooth model is integrated to rounding already, and a stiff one needs an implicit integrator, not hours of RK4.
MAX_SUBSTEPS = 10_000


def finite_difference_jacobian(fun, x, u=None, t=0.0):
    """Central finite-difference Jacobian ``∂fun/∂x`` of a batched map, shape (runs, m, n).

    The step of component i is ``ε^{1/3} max(1, |x_i|)`` (ε the machine
    epsilon), which balances truncation O(h²) and rounding O(ε/h): about 1e-10
    relative accuracy for a smooth map of unit scale.

    Parameters
    ----------
    fun : callable
        ``fun(x, u, t)`` for a batch ``x`` (N, n), returning (N, m).
    x : ndarray, shape (runs, n)
    u : ndarray, shape (runs, n_input), optional
    t : float
    """
    runs, n = x.shape
    h = np.cbrt(np.finfo(float).eps) * np.maximum(1.0, np.abs(x))  # (runs, n)
    steps = np.eye(n)[None] * h[:, None, :]  # (runs, n, n): row j perturbs component j
    xp = (x[:, None, :] + steps).reshape(runs * n, n)
    xm = (x[:, None, :] - steps).reshape(runs * n, n)
    uu = None if u is None else np.repeat(u, n, axis=0)
    diff = (np.asarray(fun(xp, uu, t)) - np.asarray(fun(xm, uu, t))).reshape(runs, n, -1)
    return np.swapaxes(diff / (2.0 * h[:, :, None]), -1, -2)  # (runs, m, n)


def rk4_step(a, x, u, t, h, A=None):
    """One classical Runge–Kutta step of ``ẋ = a(x, u, t)`` (D1), and its Jacobian (D2) when ``A`` is given.

    (D1) ``k₁ = a(x)``, ``k₂ = a(x + h k₁/2)``, ``k₃ = a(x + h k₂/2)``,
    ``k₄ = a(x + h k₃)``, ``x⁺ = x + h (k₁ + 2k₂ + 2k₃ + k₄)/6`` (t advanced
    by h/2 and h in the stages; u held).

    (D2) ``K₁ = A(x)``, ``K₂ = A(x + h k₁/2)(I + h K₁/2)``,
    ``K₃ = A(x + h k₂/2)(I + h K₂/2)``, ``K₄ = A(x + h k₃)(I + h K₃)``,
    ``∂x⁺/∂x = I + h (K₁ + 2K₂ + 2K₃ + K₄)/6``.

    Parameters
    ----------
    a : callable
        ``a(x, u, t)`` → ẋ, batched (runs, n).
    x : ndarray, shape (runs, n)
    u : ndarray or None
    t, h : float
        Time of x and step, s.
    A : callable, optional
        ``A(x, u, t)`` → ∂a/∂x, (runs, n, n).

    Returns
    -------
    x_next : ndarray, shape (runs, n)
    J : ndarray, shape (runs, n, n), or None without ``A``
    """
    k1 = a(x, u, t)
    x2 = x + 0.5 * h * k1
    k2 = a(x2, u, t + 0.5 * h)
    x3 = x + 0.5 * h * k2
    k3 = a(x3, u, t + 0.5 * h)
    x4 = x + h * k3
    k4 = a(x4, u, t + h)
    x_next = x + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
    if A is None:
        return x_next, None
    eye = np.eye(x.shape[-1])
    K1 = A(x, u, t)
    K2 = A(x2, u, t + 0.5 * h) @ (eye + 0.5 * h * K1)
    K3 = A(x3, u, t + 0.5 * h) @ (eye + 0.5 * h * K2)
    K4 = A(x4, u, t + h) @ (eye + h * K3)
    return x_next, eye + h / 6.0 * (K1 + 2.0 * K2 + 2.0 * K3 + K4)


def _checked_f(raw):
    """A user subclass's ``f`` called through :func:`~hinfnav.systems.checks.call_model`."""

    @functools.wraps(raw)
    def f(self, x, u=None, t=0.0):
        x, u, t = self.check(x, u, t)
        return call_model(self._label, "f(x, u, t)", functools.partial(raw, self), x, (u, t), out_tail=(self.n,),
                          t=t, state=self._first_calls)

    return f


def _checked_jacobian(raw):
    """A user subclass's ``jacobian``: checked, and compared with differences of f on its first call."""

    @functools.wraps(raw)
    def jacobian(self, x, u=None, t=0.0):
        x, u, t = self.check(x, u, t)
        J = call_model(self._label, "jacobian(x, u, t)", functools.partial(raw, self), x, (u, t),
                       out_tail=(self.n, self.n), t=t, allow_shared=True, state=self._first_calls)
        self._check_jacobian_once(J, x, u, t, "jacobian(x, u, t)", self.f, "f")
        return np.broadcast_to(J, (x.shape[0], self.n, self.n))

    return jacobian


class DynamicsModel(CheckedModel):
    """Base class of the nonlinear dynamics models (see the module docstring).

    Parameters
    ----------
    state : StateSpec
        Labels, units and groups of the state; gives ``n``.
    dt : float
        Step, s.
    Q : array_like, shape (n, n)
        Process-noise covariance per step (positive semidefinite).
    n_input : int
        Number of input channels (0: the model takes no input).
    name : str
    """

    linear = False
    #: a subclass written outside hinfnav has its ``f`` and ``jacobian`` checked (:mod:`hinfnav.systems.checks`)
    _method_checks = {"f": _checked_f, "jacobian": _checked_jacobian}

    @property
    def _label(self):
        return f"dynamics {getattr(self, 'name', type(self).__name__)!r}"

    def _check_jacobian_once(self, J, x, u, t, jname, fun, fname):
        """On the first call, ``J`` (runs, n, n) or (n, n) against central differences of ``fun`` at x[0]."""
        key = "differences:" + jname
        if self.jacobian_tol is None or self._first_calls.get(key):
            return
        u0 = None if u is None else u[:1]
        fd = finite_difference_jacobian(fun, x[:1], u0, t)[0]
        check_jacobian_against_differences(self._label, jname, J if J.ndim == 2 else J[0], fname, fd,
                                           self.jacobian_tol, t)
        self._first_calls[key] = True

    def __init__(self, state: StateSpec, dt: float, Q: ArrayLike, *, n_input: int = 0, name: str = "dynamics") -> None:
        if not isinstance(state, StateSpec):
            raise InputError(f"state must be a StateSpec; got {type(state).__name__}")
        self.state = state
        self.dt = as_positive("dt", dt)
        self.Q = as_covariance("Q", Q, state.n, definite=False)
        self.n_input = as_int_at_least("n_input", n_input, 0)
        self.name = str(name)

    @property
    def n(self) -> int:
        """State dimension."""
        return self.state.n

    def check(self, x: ArrayLike, u: ArrayLike | None = None, t: float = 0.0) -> tuple[NDArray[np.float64], NDArray[np.float64] | None, float]:
        """Validated ``(x, u, t)``: x (runs, n) finite, u (runs, n_input) or None, t finite."""
        x = np.asarray(x, dtype=float)
        if x.ndim != 2 or x.shape[1] != self.n:
            raise InputError(f"x must have shape (runs, {self.n}); got {x.shape}")
        if not np.all(np.isfinite(x)):
            raise InputError("x must contain only finite numbers; it has NaN or inf entries")
        if u is not None:
            u = np.asarray(u, dtype=float)
            if u.shape != (x.shape[0], self.n_input):
                raise InputError(f"u must have shape ({x.shape[0]}, {self.n_input}) (runs, n_input); got {u.shape}")
            if not np.all(np.isfinite(u)):
                raise InputError("u must contain only finite numbers; it has NaN or inf entries")
        t = float(t)
        if not np.isfinite(t):
            raise InputError(f"t must be a finite time in s; got {t}")
        return x, u, t

    def f(self, x: ArrayLike, u: ArrayLike | None = None, t: float = 0.0) -> NDArray[np.float64]:
        """The state one step later, shape (runs, n)."""
        raise NotImplementedError

    def jacobian(self, x: ArrayLike, u: ArrayLike | None = None, t: float = 0.0) -> NDArray[np.float64]:
        """``∂f/∂x`` at a batch of states, shape (runs, n, n): central differences by default."""
        x, u, t = self.check(x, u, t)
        return finite_difference_jacobian(self.f, x, u, t)

    def compiled_functions(self) -> CompiledDynamics | None:
        """numba-compiled ``f`` and ``jacobian`` of one state for the compiled filters (None here: the NumPy path).

        A subclass returns a :class:`~hinfnav.systems.compiled.CompiledDynamics`;
        see :mod:`hinfnav.systems.compiled` for how to write one.
        """
        return None

    def propagate(self, x: ArrayLike, u: ArrayLike | None = None, w: ArrayLike | None = None, t: float = 0.0) -> NDArray[np.float64]:
        """One step of the truth: ``f(x, u, t) + w`` (w (runs, n) a draw of the process noise, or None)."""
        out = self.f(x, u, t)
        return out if w is None else out + np.asarray(w, dtype=float)

    @property
    def n_noise(self) -> int:
        """Number of unit process-noise channels a simulated truth draws (:meth:`step`): n."""
        return self.n

    @property
    def noise_gain(self) -> NDArray[np.float64]:
        """G (n, n) with G Gᵀ = Q: the symmetric square root of Q (its eigenvalues clipped at 0, Q being semidefinite)."""
        lam, V = np.linalg.eigh(self.Q)
        return (V * np.sqrt(np.clip(lam, 0.0, None))) @ V.T

    def step(self, x: ArrayLike, u: ArrayLike | None = None, w: ArrayLike | None = None, t: float = 0.0) -> NDArray[np.float64]:
        """One step of a simulated truth from a unit-variance draw w (runs, n): ``f(x, u, t) + G w``, G Gᵀ = Q.

        This is what :func:`hinfnav.sim.simulate_truth` and the Monte Carlo engine call for a
        system that is not linear, so a dynamics model of your own is simulated with the noise
        model chosen there (Gaussian, mixture, …) at the covariance Q the filters assume.
        """
        return self.propagate(x, u, None if w is None else np.asarray(w, dtype=float) @ self.noise_gain.T, t)

    def __repr__(self):
        return f"<{type(self).__name__} {self.name!r} n={self.n} dt={self.dt}>"


class DiscreteDynamics(DynamicsModel):
    """A discrete map given as a function: ``x(k+1) = fun(x, u, t) + w``.

    Parameters
    ----------
    fun : callable
        ``fun(x, u, t)`` for a batch x (runs, n) → (runs, n).
    state, dt, Q, n_input, name
        As for :class:`DynamicsModel`.
    jacobian : callable, optional
        ``jacobian(x, u, t)`` → (runs, n, n) (or (n, n), shared); default central differences.
    jacobian_tol : float or None
        Tolerance of the first-call comparison of ``jacobian`` with central
        differences of ``fun`` (:mod:`hinfnav.systems.checks`); None: no check.

    Notes
    -----
    ``fun`` and ``jacobian`` are checked at every call (shape, finiteness,
    given a copy of x) and on the first call (batch convention, Jacobian
    against differences): see :mod:`hinfnav.systems.checks`.
    """

    def __init__(self, fun: Callable[..., ArrayLike], state: StateSpec, dt: float, Q: ArrayLike, *,
                 jacobian: Callable[..., ArrayLike] | None = None, n_input: int = 0,
                 name: str = "discrete dynamics", jacobian_tol: float | None = JACOBIAN_TOL) -> None:
        super().__init__(state, dt, Q, n_input=n_input, name=name)
        self.jacobian_tol = None if jacobian_tol is None else as_positive("jacobian_tol", jacobian_tol)
        if not callable(fun):
            raise InputError(f"fun must be callable as fun(x, u, t); got {type(fun).__name__}")
        if jacobian is not None and not callable(jacobian):
            raise InputError(f"jacobian must be callable as jacobian(x, u, t); got {type(jacobian).__name__}")
        self._fun, self._jac = fun, jacobian

    def f(self, x: ArrayLike, u: ArrayLike | None = None, t: float = 0.0) -> NDArray[np.float64]:
        x, u, t = self.check(x, u, t)
        return call_model(self._label, "f(x, u, t)", self._fun, x, (u, t), out_tail=(self.n,), t=t,
                          state=self._first_calls)

    def jacobian(self, x: ArrayLike, u: ArrayLike | None = None, t: float = 0.0) -> NDArray[np.float64]:
        if self._jac is None:
            return super().jacobian(x, u, t)
        x, u, t = self.check(x, u, t)
        J = call_model(self._label, "jacobian(x, u, t)", self._jac, x, (u, t), out_tail=(self.n, self.n), t=t,
                       allow_shared=True, state=self._first_calls)
        self._check_jacobian_once(J, x, u, t, "jacobian(x, u, t)", self.f, "f")
        return np.broadcast_to(J, (x.shape[0], self.n, self.n))


class ContinuousDynamics(DynamicsModel):
    """``ẋ = a(x, u, t)`` stepped over Δt with RK4 (D1) in ``substeps`` sub-steps.

    Parameters
    ----------
    derivative : callable
        ``a(x, u, t)`` for a batch x (runs, n) → ẋ (runs, n).
    state, dt, Q, n_input, name
        As for :class:`DynamicsModel`; Q is the per-step covariance of the
        discretised model (e.g. ``∫ e^{Aτ} G Q_c Gᵀ e^{Aᵀτ} dτ`` over Δt).
    derivative_jacobian : callable, optional
        ``∂a/∂x`` (runs, n, n); default central differences of a.
    substeps : int
        RK4 sub-steps per Δt (1 to :data:`MAX_SUBSTEPS`).
    jacobian_tol : float or None
        Tolerance of the first-call comparison of ``derivative_jacobian`` with
        central differences of ``derivative`` (None: no check).

    Notes
    -----
    :meth:`jacobian` is the exact Jacobian of the RK4 step (D2), product over
    the sub-steps: the covariance of an EKF follows the linearisation of the
    discrete map that propagates its mean. ``derivative`` and
    ``derivative_jacobian`` are checked as :class:`DiscreteDynamics`' functions
    (a (runs, 1) derivative is refused, not broadcast).
    """

    def __init__(self, derivative: Callable[..., ArrayLike], state: StateSpec, dt: float, Q: ArrayLike, *,
                 derivative_jacobian: Callable[..., ArrayLike] | None = None, substeps: int = 1, n_input: int = 0,
                 name: str = "continuous dynamics", jacobian_tol: float | None = JACOBIAN_TOL) -> None:
        super().__init__(state, dt, Q, n_input=n_input, name=name)
        if not callable(derivative):
            raise InputError(f"derivative must be callable as a(x, u, t); got {type(derivative).__name__}")
        if derivative_jacobian is not None and not callable(derivative_jacobian):
            raise InputError("derivative_jacobian must be callable as A(x, u, t); "
                             f"got {type(derivative_jacobian).__name__}")
        self._a, self._A = derivative, derivative_jacobian
        self.substeps = as_int_at_least("substeps", substeps, 1)
        if self.substeps > MAX_SUBSTEPS:
            raise InputError(f"substeps must be <= {MAX_SUBSTEPS}; got {self.substeps} (RK4's error falls as "
                             "substeps⁻⁴: a smooth model is integrated to rounding well below this, and a stiff one "
                             "needs an implicit integrator; the limit keeps a run from taking hours without a word)")
        self.jacobian_tol = None if jacobian_tol is None else as_positive("jacobian_tol", jacobian_tol)

    def derivative(self, x: ArrayLike, u: ArrayLike | None = None, t: float = 0.0) -> NDArray[np.float64]:
        """ẋ = a(x, u, t), shape (runs, n) (checked: :mod:`hinfnav.systems.checks`)."""
        x = np.asarray(x, dtype=float)
        return call_model(self._label, "derivative a(x, u, t)", self._a, x, (u, t), out_tail=(self.n,), t=t,
                          state=self._first_calls)

    def derivative_jacobian(self, x: ArrayLike, u: ArrayLike | None = None, t: float = 0.0) -> NDArray[np.float64]:
        """∂a/∂x, shape (runs, n, n) (analytic if given, else central differences)."""
        if self._A is None:
            return finite_difference_jacobian(self.derivative, x, u, t)
        x = np.asarray(x, dtype=float)
        J = call_model(self._label, "derivative_jacobian A(x, u, t)", self._A, x, (u, t), out_tail=(self.n, self.n),
                       t=t, allow_shared=True, state=self._first_calls)
        self._check_jacobian_once(J, x, u, t, "derivative_jacobian A(x, u, t)", self.derivative, "the derivative a")
        return np.broadcast_to(J, (x.shape[0], self.n, self.n))

    def _integrate(self, x, u, t, with_jacobian):
        h = self.dt / self.substeps
        J = np.broadcast_to(np.eye(self.n), (x.shape[0], self.n, self.n)) if with_jacobian else None
        for i in range(self.substeps):
            x, Ji = rk4_step(self.derivative, x, u, t + i * h, h, self.derivative_jacobian if with_jacobian else None)
            if with_jacobian:
                J = Ji @ J
        return x, J

    def f(self, x: ArrayLike, u: ArrayLike | None = None, t: float = 0.0) -> NDArray[np.float64]:
        x, u, t = self.check(x, u, t)
        return self._integrate(x, u, t, False)[0]

    def jacobian(self, x: ArrayLike, u: ArrayLike | None = None, t: float = 0.0) -> NDArray[np.float64]:
        x, u, t = self.check(x, u, t)
        return self._integrate(x, u, t, True)[1]


def constant_turn_state_spec() -> StateSpec:
    """Planar position, velocity and turn rate: ``(x, y, vx, vy, ω)`` in m, m/s, rad/s."""
    return StateSpec(
        labels=("x", "y", "vx", "vy", "omega"),
        units=("m", "m", "m/s", "m/s", "rad/s"),
        groups={"position": (0, 1), "velocity": (2, 3), "turn_rate": (4,)},
        axis_names={"position": ("x", "y"), "velocity": ("x", "y"), "turn_rate": ("ω",)},
    )


def _turn_coefficients(omega, T):
    """``s = sin(ωT)/ω``, ``c = (1 − cos ωT)/ω`` and their ω-derivatives, exact as ω → 0 (CT1).

    With a = ωT: ``s = T sinc_a``, ``c = T sin(a/2) sinc_{a/2}`` (sinc(z) =
    sin z / z, from 1 − cos a = 2 sin²(a/2)), so no division by ω. The
    derivatives ``ds/dω = T² (a cos a − sin a)/a²``, ``dc/dω = T² (a sin a −
    1 + cos a)/a²`` use their Taylor series for |a| < 1e-2 (truncation below
    1e-18 T²).
    """
    a = omega * T
    s = T * np.sinc(a / np.pi)
    c = T * np.sin(0.5 * a) * np.sinc(0.5 * a / np.pi)
    small = np.abs(a) < 1e-2
    a_safe = np.where(small, 1.0, a)
    a2 = a * a
    ds = np.where(small, -a / 3.0 + a * a2 / 30.0 - a * a2 * a2 / 840.0,
                  (a_safe * np.cos(a_safe) - np.sin(a_safe)) / a_safe**2) * T * T
    dc = np.where(small, 0.5 - a2 / 8.0 + a2 * a2 / 144.0,
                  (a_safe * np.sin(a_safe) - 1.0 + np.cos(a_safe)) / a_safe**2) * T * T
    return s, c, ds, dc


class ConstantTurn(DynamicsModel):
    """Planar constant-turn motion with unknown turn rate: state ``(x, y, vx, vy, ω)``.

    The exact discretisation of ``ẍ = −ω ẏ``, ``ÿ = ω ẋ``, ω̇ = 0 over T = Δt
    (Bar-Shalom, Li & Kirubarajan, *Estimation with Applications to Tracking
    and Navigation*, 2001, §11.7.1):

    .. math::

        x^+ = x + s\\,v_x - c\\,v_y,\\quad y^+ = y + c\\,v_x + s\\,v_y,\\quad
        v_x^+ = \\cos(ωT) v_x - \\sin(ωT) v_y,\\quad v_y^+ = \\sin(ωT) v_x + \\cos(ωT) v_y,\\quad ω^+ = ω

    with ``s = sin(ωT)/ω``, ``c = (1 − cos ωT)/ω`` (CT1), which tend to T and 0
    as ω → 0 (straight line; evaluated without division, see
    :func:`_turn_coefficients`). The analytic Jacobian is :meth:`jacobian`.

    Process noise (CT2): a white acceleration held over each step, σ_a (m/s²)
    per axis, ``Q_axis = σ_a² [[T⁴/4, T³/2], [T³/2, T²]]`` on (position,
    velocity), and a random walk of ω with σ_ω (rad/s per step).

    Parameters
    ----------
    dt : float
        T, s.
    sigma_accel : float
        σ_a, m/s² (≥ 0).
    sigma_turn_rate : float
        σ_ω, rad/s per step (≥ 0).
    name : str
    """

    def __init__(self, dt: float, sigma_accel: float, sigma_turn_rate: float, *, name: str = "constant turn") -> None:
        dt = as_positive("dt", dt)
        self.sigma_accel = as_nonnegative("sigma_accel", sigma_accel)
        self.sigma_turn_rate = as_nonnegative("sigma_turn_rate", sigma_turn_rate)
        G = np.array([[dt * dt / 2, 0.0], [0.0, dt * dt / 2], [dt, 0.0], [0.0, dt]])
        Q = np.zeros((5, 5))
        Q[:4, :4] = self.sigma_accel**2 * G @ G.T
        Q[4, 4] = self.sigma_turn_rate**2
        super().__init__(constant_turn_state_spec(), dt, Q, n_input=0, name=name)

    def f(self, x: ArrayLike, u: ArrayLike | None = None, t: float = 0.0) -> NDArray[np.float64]:
        """(CT1) for a batch, shape (runs, 5); u is ignored (the model has no input)."""
        x, _, _ = self.check(x, None, t)
        px, py, vx, vy, w = x.T
        s, c, _, _ = _turn_coefficients(w, self.dt)
        cw, sw = np.cos(w * self.dt), np.sin(w * self.dt)
        return np.stack([px + s * vx - c * vy, py + c * vx + s * vy, cw * vx - sw * vy, sw * vx + cw * vy, w], axis=-1)

    def jacobian(self, x: ArrayLike, u: ArrayLike | None = None, t: float = 0.0) -> NDArray[np.float64]:
        """Analytic ``∂f/∂x`` of (CT1), shape (runs, 5, 5)."""
        x, _, _ = self.check(x, None, t)
        _, _, vx, vy, w = x.T
        T = self.dt
        s, c, ds, dc = _turn_coefficients(w, T)
        cw, sw = np.cos(w * T), np.sin(w * T)
        J = np.zeros((x.shape[0], 5, 5))
        J[:, 0, 0] = J[:, 1, 1] = J[:, 4, 4] = 1.0
        J[:, 0, 2], J[:, 0, 3], J[:, 0, 4] = s, -c, ds * vx - dc * vy
        J[:, 1, 2], J[:, 1, 3], J[:, 1, 4] = c, s, dc * vx + ds * vy
        J[:, 2, 2], J[:, 2, 3], J[:, 2, 4] = cw, -sw, -T * (sw * vx + cw * vy)
        J[:, 3, 2], J[:, 3, 3], J[:, 3, 4] = sw, cw, T * (cw * vx - sw * vy)
        return J

    def compiled_functions(self) -> CompiledDynamics:
        """(CT1) and its Jacobian for one state, numba-compiled (:mod:`hinfnav.systems.compiled_functions`)."""
        fns = package_functions()
        return CompiledDynamics(fns.constant_turn_f, fns.constant_turn_jacobian, [self.dt])
