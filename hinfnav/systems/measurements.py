"""Measurement models, outside the filters.

Each model gives its function h(x), its Jacobian, its noise (matrix D with
unit-variance white v, so R = D Dᵀ), labels and units, and how to form a
residual. Models act on batches: ``x`` of shape (..., n).

* :class:`LinearMeasurement` — y = C x + D v, e.g. the indirect position
  measurement (8) of Sun et al. (2011);
* :class:`RangeAzimuthElevation` — range ρ, azimuth α, elevation β of the
  relative position, the direct measurement behind (7), with its Jacobian and
  its inverse (the indirect position measurement);
* :class:`ConvertedPosition` — a range/angle reading converted to position,
  the indirect measurement as a filter uses it, with covariance J R Jᵀ at
  each reading;
* :class:`Saturated` — wraps a model and clips each channel to
  [lower, upper], reporting which channels saturated.
"""

from __future__ import annotations

import functools
from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..core.exceptions import InputError
from ..core.validation import as_int_at_least, as_matrix, as_positive
from .checks import CheckedModel, call_model, check_jacobian_against_differences
from .compiled import CompiledMeasurement, package_functions
from .dynamics import finite_difference_jacobian

__all__ = [
    "MeasurementModel",
    "LinearMeasurement",
    "RangeAzimuthElevation",
    "ConvertedPosition",
    "Saturated",
    "range_angles",
    "range_angles_jacobian",
    "position_from_range_angles",
    "wrap_angle",
    "as_measurement_model",
]


def _checked_function(raw):
    """A user subclass's ``h(x)``: called on a (N, n) batch (a copy), shape and finiteness checked."""

    @functools.wraps(raw)
    def function(self, x):
        xb, lead = _flat_states(self, x)
        out = call_model(self._label, "function h(x)", functools.partial(raw, self), xb, out_tail=(self.n_meas,),
                         state=self._first_calls)
        return out.reshape(lead + (self.n_meas,))

    return function


def _checked_measurement_jacobian(raw):
    """A user subclass's ``∂h/∂x``: checked, and compared with differences of h on its first call."""

    @functools.wraps(raw)
    def jacobian(self, x):
        xb, lead = _flat_states(self, x)
        shape = (self.n_meas, self.n_state)
        J = call_model(self._label, "jacobian(x)", functools.partial(raw, self), xb, out_tail=shape,
                       allow_shared=True, state=self._first_calls)
        if self.jacobian_tol is not None and not self._first_calls.get("differences"):
            fd = finite_difference_jacobian(lambda z, u, t: self.function(z), xb[:1])[0]
            check_jacobian_against_differences(self._label, "jacobian(x)", J if J.ndim == 2 else J[0],
                                               "function h", fd, self.jacobian_tol)
            self._first_calls["differences"] = True
        return np.broadcast_to(J, (xb.shape[0],) + shape).reshape(lead + shape)

    return jacobian


class MeasurementModel(CheckedModel):
    """Base class: ``y = h(x) + D v`` with unit-variance white v.

    Attributes
    ----------
    n_state : int
    labels, units : tuple of str
        One per measurement channel.
    D : ndarray, shape (m, q)
        Noise matrix; ``R = D Dᵀ``.
    linear : bool
        True when ``h(x) = H x`` (then :attr:`H` is that matrix).
    """

    linear = False
    H = None
    #: a subclass written outside hinfnav has ``function`` and ``jacobian`` checked (:mod:`hinfnav.systems.checks`)
    _method_checks = {"function": _checked_function, "jacobian": _checked_measurement_jacobian}

    @property
    def _label(self):
        return f"measurement model {type(self).__name__}"

    def __init__(self, n_state: int, D: ArrayLike, labels: Sequence[str], units: Sequence[str]) -> None:
        self.n_state = int(n_state)
        self.D = as_matrix("D", D)
        self.D.setflags(write=False)
        self.labels = tuple(labels)
        self.units = tuple(units)
        if len(self.labels) != self.D.shape[0] or len(self.units) != self.D.shape[0]:
            raise InputError(f"labels and units must have {self.D.shape[0]} entries (rows of D)")

    @property
    def n_meas(self) -> int:
        """Number of measurement channels."""
        return self.D.shape[0]

    @property
    def n_noise(self) -> int:
        """Number of noise channels (columns of D)."""
        return self.D.shape[1]

    @property
    def R(self) -> NDArray[np.float64]:
        """Noise covariance ``D Dᵀ``."""
        return self.D @ self.D.T

    def function(self, x: ArrayLike) -> NDArray[np.float64]:
        """``h(x)`` for a batch ``x`` of shape (..., n), shape (..., m)."""
        raise NotImplementedError

    def jacobian(self, x: ArrayLike) -> NDArray[np.float64]:
        """``∂h/∂x`` at a batch of states, shape (..., m, n)."""
        raise NotImplementedError

    def residual(self, y: ArrayLike, yhat: ArrayLike) -> NDArray[np.float64]:
        """``y − ŷ`` (angles wrapped where a model has them)."""
        return np.asarray(y) - np.asarray(yhat)

    def compiled_functions(self) -> CompiledMeasurement | None:
        """numba-compiled ``h``, ``jacobian`` and ``residual`` of one state for the compiled filters (None here: the
        NumPy path). A subclass returns a :class:`~hinfnav.systems.compiled.CompiledMeasurement`; see
        :mod:`hinfnav.systems.compiled` for how to write one."""
        return None

    def measure(self, x: ArrayLike, v: ArrayLike) -> NDArray[np.float64]:
        """Noisy measurements ``h(x) + v Dᵀ`` of a batch; ``v`` of shape (..., q)."""
        return self.function(x) + np.asarray(v) @ self.D.T

    def check_state(self, x: ArrayLike, name: str = "x") -> NDArray[np.float64]:
        x = np.asarray(x, dtype=float)
        if x.ndim < 1 or x.shape[-1] != self.n_state:
            raise InputError(f"{name} must have shape (..., {self.n_state}); got {x.shape}")
        return x


class LinearMeasurement(MeasurementModel):
    """``y = C x + D v``.

    Parameters
    ----------
    C : array_like, shape (m, n)
    D : array_like, shape (m, q)
    labels, units : sequence of str, optional
    """

    linear = True

    def __init__(self, C: ArrayLike, D: ArrayLike, labels: Sequence[str] | None = None,
                 units: Sequence[str] | None = None) -> None:
        C = as_matrix("C", C)
        m = C.shape[0]
        D = as_matrix("D", D, (m, None))
        super().__init__(C.shape[1], D, labels or tuple(f"y{i}" for i in range(m)), units or ("",) * m)
        C.setflags(write=False)
        self.H = C

    @property
    def C(self) -> NDArray[np.float64]:
        """The measurement matrix."""
        return self.H

    def function(self, x: ArrayLike) -> NDArray[np.float64]:
        return np.asarray(x) @ self.H.T

    def jacobian(self, x: ArrayLike) -> NDArray[np.float64]:
        x = np.asarray(x)
        return np.broadcast_to(self.H, x.shape[:-1] + self.H.shape)

    def measure(self, x: ArrayLike, v: ArrayLike) -> NDArray[np.float64]:
        return np.asarray(x) @ self.H.T + np.asarray(v) @ self.D.T

    def compiled_functions(self) -> CompiledMeasurement:
        """``H x`` and H for one state, numba-compiled (:mod:`hinfnav.systems.compiled`)."""
        fns = package_functions()
        return CompiledMeasurement(fns.linear_h, fns.linear_h_jacobian, fns.plain_residual,
                                   np.concatenate([self.H.shape, self.H.ravel()]))


# ---------------------------------------------------------------------------
# range / azimuth / elevation, eq. (7) of Sun et al. (2011)
# ---------------------------------------------------------------------------


def _check_C_bl(C_bl):
    if C_bl is None:
        return np.eye(3)
    C = as_matrix("C_bl", C_bl, (3, 3))
    if not np.allclose(C @ C.T, np.eye(3), atol=1e-9):
        raise InputError("C_bl must be a rotation matrix (C_bl C_blᵀ = I); it is not orthogonal")
    return C


def _positions(x):
    x = np.asarray(x, dtype=float)
    if x.ndim < 1 or x.shape[-1] < 3:
        raise InputError(f"x must have shape (..., n) with the position in its first 3 components; got {x.shape}")
    if not np.all(np.isfinite(x)):
        raise InputError("x must contain only finite numbers; it has NaN or inf entries")
    return x[..., :3]


def wrap_angle(angle: ArrayLike) -> NDArray[np.float64]:
    """Wrap angles to (−π, π] (angles already inside are returned unchanged)."""
    angle = np.asarray(angle, dtype=float)
    inside = (angle > -np.pi) & (angle <= np.pi)
    return np.where(inside, angle, np.pi - np.mod(np.pi - angle, 2 * np.pi))


def range_angles(x: ArrayLike, C_bl: ArrayLike | None = None) -> NDArray[np.float64]:
    """Range, azimuth and elevation of a relative position, inverse of (7).

    (7) reads ``(x, y, z)ᵀ = C_bl⁻¹ (ρ cos β cos α, ρ cos β sin α, −ρ sin β)ᵀ``,
    so with ``p_b = C_bl (x, y, z)ᵀ``: ``ρ = |p_b|``,
    ``α = atan2(p_b2, p_b1)``, ``β = atan2(−p_b3, √(p_b1² + p_b2²))``.

    Parameters
    ----------
    x : array_like, shape (..., n), n ≥ 3
        States whose first three components are the position, m.
    C_bl : array_like, shape (3, 3), optional
        Rotation from the relative (orbital) frame to the sensor frame.

    Returns
    -------
    ndarray, shape (..., 3)
        ρ (m), α (rad, in (−π, π]), β (rad, in [−π/2, π/2]).
    """
    return _range_angles(x, _check_C_bl(C_bl))


def _range_angles(x, C):
    """:func:`range_angles` with ``C`` already checked by :func:`_check_C_bl`."""
    p = _positions(x) @ C.T
    rho = np.linalg.norm(p, axis=-1)
    if np.any(rho == 0):
        raise InputError("x has a zero relative position; range and angles are undefined there")
    h = np.hypot(p[..., 0], p[..., 1])
    return np.stack([rho, np.arctan2(p[..., 1], p[..., 0]), np.arctan2(-p[..., 2], h)], axis=-1)


def range_angles_jacobian(x: ArrayLike, C_bl: ArrayLike | None = None, n_state: int | None = None) -> NDArray[np.float64]:
    """Jacobian of :func:`range_angles` with respect to the state, batched.

    Parameters
    ----------
    x : array_like, shape (..., n)
    C_bl : array_like, shape (3, 3), optional
    n_state : int, optional
        Number of state columns (default ``x.shape[-1]``); columns beyond the
        position are zero.

    Returns
    -------
    ndarray, shape (..., 3, n)

    Raises
    ------
    InputError
        On the line of sight's singularities (zero range, or the position on
        the sensor z axis where the azimuth is undefined).
    """
    return _range_angles_jacobian(x, _check_C_bl(C_bl), n_state)


def _range_angles_jacobian(x, C, n_state):
    """:func:`range_angles_jacobian` with ``C`` already checked by :func:`_check_C_bl`."""
    x = np.asarray(x, dtype=float)
    n = x.shape[-1] if n_state is None else int(n_state)
    p = _positions(x) @ C.T
    rho2 = np.sum(p * p, axis=-1)
    h2 = p[..., 0] ** 2 + p[..., 1] ** 2
    if np.any(h2 == 0):
        raise InputError("the position lies on the sensor z axis (or at zero range): the azimuth has no derivative there")
    rho, h = np.sqrt(rho2), np.sqrt(h2)
    Jb = np.empty(p.shape[:-1] + (3, 3))
    Jb[..., 0, :] = p / rho[..., None]
    Jb[..., 1, 0] = -p[..., 1] / h2
    Jb[..., 1, 1] = p[..., 0] / h2
    Jb[..., 1, 2] = 0.0
    Jb[..., 2, 0] = p[..., 2] * p[..., 0] / (h * rho2)
    Jb[..., 2, 1] = p[..., 2] * p[..., 1] / (h * rho2)
    Jb[..., 2, 2] = -h / rho2
    J = np.zeros(p.shape[:-1] + (3, n))
    J[..., :3] = Jb @ C
    return J


def position_from_range_angles(m: ArrayLike, C_bl: ArrayLike | None = None) -> NDArray[np.float64]:
    """Relative position from range and line-of-sight angles, eq. (7).

    Parameters
    ----------
    m : array_like, shape (..., 3)
        ρ (m), α (rad), β (rad).
    C_bl : array_like, shape (3, 3), optional

    Returns
    -------
    ndarray, shape (..., 3)
        ``C_bl⁻¹ (ρ cos β cos α, ρ cos β sin α, −ρ sin β)``, m.
    """
    m = _check_range_angles(m)
    return _position_from_range_angles(m, _check_C_bl(C_bl))


def _check_range_angles(m):
    m = np.asarray(m, dtype=float)
    if m.ndim < 1 or m.shape[-1] != 3:
        raise InputError(f"m must have shape (..., 3) (range, azimuth, elevation); got {m.shape}")
    if not np.all(np.isfinite(m)):
        raise InputError("m must contain only finite numbers; it has NaN or inf entries")
    if np.any(m[..., 0] < 0):
        raise InputError(f"m: the range (first entry) must be >= 0 m; its smallest is {m[..., 0].min():g}")
    return m


def _position_from_range_angles(m, C):
    """:func:`position_from_range_angles` of checked readings ``m`` with ``C`` checked by :func:`_check_C_bl`."""
    rho, a, b = m[..., 0], m[..., 1], m[..., 2]
    pb = np.stack([rho * np.cos(b) * np.cos(a), rho * np.cos(b) * np.sin(a), -rho * np.sin(b)], axis=-1)
    return pb @ C  # C_bl⁻¹ = C_blᵀ, applied to row vectors


class RangeAzimuthElevation(MeasurementModel):
    """Range ρ, azimuth α, elevation β of the relative position, plus white noise.

    Parameters
    ----------
    n_state : int
        Dimension of the state; its first three components are the position (m).
    sigma_range : float
        Range noise standard deviation, m.
    sigma_angle : float
        Azimuth and elevation noise standard deviation, rad.
    C_bl : array_like, shape (3, 3), optional
        Rotation from the relative frame to the sensor frame (identity).
    """

    def __init__(self, n_state: int, sigma_range: float, sigma_angle: float, C_bl: ArrayLike | None = None) -> None:
        n_state = as_int_at_least("n_state", n_state, 3)  # the first three components are the position
        self.sigma_range = as_positive("sigma_range", sigma_range)
        self.sigma_angle = as_positive("sigma_angle", sigma_angle)
        self.C_bl = _check_C_bl(C_bl).copy()
        self.C_bl.setflags(write=False)  # checked once here (read-only), not at every call
        self._C_checked = self.C_bl
        super().__init__(
            n_state, np.diag([self.sigma_range, self.sigma_angle, self.sigma_angle]),
            ("range", "azimuth", "elevation"), ("m", "rad", "rad"),
        )

    def function(self, x: ArrayLike) -> NDArray[np.float64]:
        return _range_angles(self.check_state(x), self._rotation())

    def jacobian(self, x: ArrayLike) -> NDArray[np.float64]:
        return _range_angles_jacobian(self.check_state(x), self._rotation(), self.n_state)

    def _rotation(self):
        """C_bl, checked again only if it was replaced since the constructor checked it."""
        C = self.C_bl
        return C if C is self._C_checked else _check_C_bl(C)

    def residual(self, y: ArrayLike, yhat: ArrayLike) -> NDArray[np.float64]:
        d = np.asarray(y, dtype=float) - np.asarray(yhat, dtype=float)
        d = d.copy()
        d[..., 1:] = wrap_angle(d[..., 1:])
        return d

    def measure(self, x: ArrayLike, v: ArrayLike) -> NDArray[np.float64]:
        out = self.function(x) + np.asarray(v) @ self.D.T
        out[..., 1] = wrap_angle(out[..., 1])
        return out

    def compiled_functions(self) -> CompiledMeasurement:
        """Range, azimuth, elevation and their Jacobian for one state, numba-compiled (:mod:`hinfnav.systems.compiled`)."""
        fns = package_functions()
        return CompiledMeasurement(fns.range_angles_h, fns.range_angles_jacobian, fns.angles_residual,
                                   np.concatenate([[self.n_state], self._rotation().ravel()]))

    def inverse(self, m: ArrayLike) -> NDArray[np.float64]:
        """The indirect position measurement: position (m) from (ρ, α, β), eq. (7)."""
        return _position_from_range_angles(_check_range_angles(m), self._rotation())

    def position_covariance(self, m: ArrayLike) -> NDArray[np.float64]:
        """Covariance ``J R Jᵀ`` of the converted position at (ρ, α, β) (first order), shape (..., 3, 3)."""
        m = np.asarray(m, dtype=float)
        rho, a, b = m[..., 0], m[..., 1], m[..., 2]
        J = np.zeros(m.shape[:-1] + (3, 3))
        ca, sa, cb, sb = np.cos(a), np.sin(a), np.cos(b), np.sin(b)
        J[..., 0, 0], J[..., 0, 1], J[..., 0, 2] = cb * ca, -rho * cb * sa, -rho * sb * ca
        J[..., 1, 0], J[..., 1, 1], J[..., 1, 2] = cb * sa, rho * cb * ca, -rho * sb * sa
        J[..., 2, 0], J[..., 2, 2] = -sb, -rho * cb  # J[..., 2, 1] = 0
        Jl = self.C_bl.T @ J
        return Jl @ self.R @ np.swapaxes(Jl, -1, -2)


class Saturated(MeasurementModel):
    """A measurement model whose channels saturate at [lower, upper].

    ``measure`` returns the clipped reading; :meth:`clip` returns it with a
    boolean flag per channel (True where the reading sat at a bound).

    Parameters
    ----------
    model : MeasurementModel
    lower, upper : array_like, shape (m,)
        Channel bounds (``-inf``/``inf`` for a channel that does not saturate).
    """

    def __init__(self, model: MeasurementModel, lower: ArrayLike, upper: ArrayLike) -> None:
        if not isinstance(model, MeasurementModel):
            raise InputError(f"model must be a MeasurementModel; got {type(model).__name__}")
        m = model.n_meas
        lo, hi = (np.asarray(b, dtype=float) for b in (lower, upper))
        for name, b in (("lower", lo), ("upper", hi)):
            if b.ndim > 1 or b.size not in (1, m):
                raise InputError(f"{name} must be one bound or one per channel ({m}); got shape {b.shape}")
        lo = np.broadcast_to(lo, (m,)).copy()
        hi = np.broadcast_to(hi, (m,)).copy()
        if np.any(np.isnan(lo)) or np.any(np.isnan(hi)) or np.any(lo >= hi):
            raise InputError(f"lower must be < upper in every channel; got lower={lo}, upper={hi}")
        super().__init__(model.n_state, model.D, model.labels, model.units)
        self.model, self.lower, self.upper = model, lo, hi
        self.linear = model.linear
        self.H = model.H

    def function(self, x: ArrayLike) -> NDArray[np.float64]:
        return self.model.function(x)

    def jacobian(self, x: ArrayLike) -> NDArray[np.float64]:
        return self.model.jacobian(x)

    def residual(self, y: ArrayLike, yhat: ArrayLike) -> NDArray[np.float64]:
        return self.model.residual(y, yhat)

    def clip(self, y: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
        """``(clipped y, flags)``: flags True where a channel sat at a bound."""
        y = np.asarray(y, dtype=float)
        return np.clip(y, self.lower, self.upper), (y <= self.lower) | (y >= self.upper)

    def measure(self, x: ArrayLike, v: ArrayLike) -> NDArray[np.float64]:
        return self.clip(self.model.measure(x, v))[0]


def as_measurement_model(value: object, name: str = "measurement") -> MeasurementModel:
    """Check that ``value`` is a :class:`MeasurementModel`."""
    if not isinstance(value, MeasurementModel):
        raise InputError(f"{name} must be a hinfnav MeasurementModel; got {type(value).__name__}")
    return value



# ---------------------------------------------------------------------------
# the indirect (converted) position measurement, (7)-(8) of Sun et al. (2011),
# (20)-(22) of Shi & Wang (2018)
# ---------------------------------------------------------------------------


class ConvertedPosition(MeasurementModel):
    """A range/azimuth/elevation reading converted to position: the indirect measurement.

    The sensor reads ``m = (ρ, α, β) + v`` with ``cov(v) = R = diag(σ_ρ², σ_α², σ_β²)``.
    A filter on the indirect measurement uses the converted position
    ``z = g(m) = C_bl⁻¹ (ρ cos β cos α, ρ cos β sin α, −ρ sin β)`` ((7) of Sun
    et al. 2011) as a linear measurement of the state,

    .. math::

        z = [I_3 \\; 0]\\, x + e, \\qquad \\operatorname{cov}(e) \\approx J(m) R J(m)^T,

    with ``J = ∂g/∂m`` at the reading (first order; (21)–(22) of Shi & Wang
    2018, "Z = HX + DV, E[DV (DV)ᵀ] = D R Dᵀ"). Its noise covariance depends
    on the reading: :meth:`noise_covariance` gives ``R_k`` for each y_k, and
    :class:`hinfnav.estimators.ExtendedKalmanFilter` uses it when the model
    has it (then each run carries its own covariance).

    The readings ``y`` are the sensor's (ρ, α, β) — ``labels``, ``units``,
    ``D`` and :meth:`measure` are the sensor's, so one simulated truth serves
    filters on the direct and on the converted measurement — while
    :meth:`function` and :meth:`jacobian` are those of the position
    ``[I 0] x``, and :meth:`residual` converts the reading:
    ``residual(y, ŷ) = g(y) − ŷ``.

    Parameters
    ----------
    sensor : RangeAzimuthElevation
        The sensor whose readings are converted.
    """

    linear = True

    def __init__(self, sensor: MeasurementModel) -> None:
        if not isinstance(sensor, RangeAzimuthElevation):
            raise InputError(f"sensor must be a RangeAzimuthElevation model; got {type(sensor).__name__}")
        super().__init__(sensor.n_state, sensor.D, sensor.labels, sensor.units)
        self.sensor = sensor
        H = np.zeros((3, sensor.n_state))
        H[:, :3] = np.eye(3)
        H.setflags(write=False)
        self.H = H

    @property
    def R(self) -> NDArray[np.float64]:
        """Not defined: the converted position's covariance depends on the reading (see :meth:`noise_covariance`)."""
        raise InputError("a converted measurement has no constant R: its covariance J R Jᵀ depends on the reading "
                         "(use noise_covariance(y), or give the filter an explicit R)")

    def function(self, x: ArrayLike) -> NDArray[np.float64]:
        """The position ``[I 0] x``, shape (..., 3), m."""
        return self.check_state(x) @ self.H.T

    def jacobian(self, x: ArrayLike) -> NDArray[np.float64]:
        """``[I 0]`` broadcast over the batch, shape (..., 3, n)."""
        x = self.check_state(x)
        return np.broadcast_to(self.H, x.shape[:-1] + self.H.shape)

    def convert(self, y: ArrayLike) -> NDArray[np.float64]:
        """The indirect position measurement ``g(y)`` of readings (ρ, α, β), shape (..., 3), m."""
        return self.sensor.inverse(y)

    def residual(self, y: ArrayLike, yhat: ArrayLike) -> NDArray[np.float64]:
        """``g(y) − ŷ``: the converted reading minus a predicted position, m."""
        return self.convert(y) - np.asarray(yhat, dtype=float)

    def measure(self, x: ArrayLike, v: ArrayLike) -> NDArray[np.float64]:
        """The sensor's noisy readings (ρ, α, β) of a batch (see :meth:`RangeAzimuthElevation.measure`)."""
        return self.sensor.measure(x, v)

    def noise_covariance(self, y: ArrayLike) -> NDArray[np.float64]:
        """``R_k = J(y) R J(y)ᵀ`` of the converted position at readings ``y``, shape (..., 3, 3), m²."""
        return self.sensor.position_covariance(y)


def _flat_states(model, x):
    """A user model's argument as a finite (N, n) batch, and the leading shape to restore."""
    x = model.check_state(x)
    if not np.all(np.isfinite(x)):
        raise InputError(f"{model._label}: x must contain only finite numbers; it has NaN or inf entries")
    return x.reshape(-1, model.n_state), x.shape[:-1]
