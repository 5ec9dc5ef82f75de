"""A planar range/bearing sensor and its converted-position form.

* :class:`RangeBearing` — range r and bearing b of a target seen from a
  sensor at ``origin`` in the plane (P1), with its Jacobian (P2), wrapped
  bearing residuals and its inverse (P3);
* :class:`ConvertedRangeBearing` — the same readings converted to position,
  a linear measurement of the position with covariance ``R_k = J R Jᵀ`` at
  each reading (P4); it is :class:`~hinfnav.systems.measurements.ConvertedPosition`
  (the 3-D indirect measurement) on the planar sensor.

The planar counterpart of :class:`~hinfnav.systems.measurements.RangeAzimuthElevation`
for a tracking problem brought by a user (notebook 80).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..core.exceptions import InputError
from ..core.validation import as_int_at_least, as_positive, as_vector
from .compiled import CompiledMeasurement, package_functions
from .measurements import ConvertedPosition, MeasurementModel, RangeAzimuthElevation

__all__ = ["RangeBearing", "ConvertedRangeBearing"]


class RangeBearing(MeasurementModel):
    """Range and bearing of a planar position, plus white noise.

    (P1) ``r = |p − o|``, ``b = atan2(p_y − o_y, p_x − o_x)`` with ``p`` the
    state's ``position`` components and ``o`` the sensor's position.

    (P2) ``∂r/∂p = (d_x, d_y)/r``, ``∂b/∂p = (−d_y, d_x)/r²`` (d = p − o);
    zero for the other state components.

    Parameters
    ----------
    n_state : int
        Dimension of the state (≥ 2).
    sigma_range : float
        Range noise standard deviation, m.
    sigma_bearing : float
        Bearing noise standard deviation, rad.
    origin : array_like, shape (2,)
        Sensor position, m (default the origin).
    position : tuple of two int
        Indices of the planar position in the state (default (0, 1)).
    """

    def __init__(self, n_state: int, sigma_range: float, sigma_bearing: float,
                 origin: tuple[float, float] = (0.0, 0.0), position: tuple[int, int] = (0, 1)) -> None:
        n_state = as_int_at_least("n_state", n_state, 2)
        self.sigma_range = as_positive("sigma_range", sigma_range)
        self.sigma_bearing = as_positive("sigma_bearing", sigma_bearing)
        self.origin = as_vector("origin", origin, 2)
        try:
            idx = tuple(int(i) for i in position)
        except (TypeError, ValueError):
            raise InputError(f"position must be two state indices; got {position!r}") from None
        if len(idx) != 2 or len(set(idx)) != 2 or min(idx) < 0 or max(idx) >= n_state:
            raise InputError(f"position must be two different state indices in 0..{n_state - 1}; got {position!r}")
        self.position = idx
        super().__init__(n_state, np.diag([self.sigma_range, self.sigma_bearing]), ("range", "bearing"), ("m", "rad"))

    def _offset(self, x):
        x = self.check_state(x)
        if not np.all(np.isfinite(x)):
            raise InputError("x must contain only finite numbers; it has NaN or inf entries")
        return x[..., list(self.position)] - self.origin

    def function(self, x: ArrayLike) -> NDArray[np.float64]:
        """(P1) for a batch (..., n): shape (..., 2), (m, rad)."""
        d = self._offset(x)
        return np.stack([np.hypot(d[..., 0], d[..., 1]), np.arctan2(d[..., 1], d[..., 0])], axis=-1)

    def jacobian(self, x: ArrayLike) -> NDArray[np.float64]:
        """(P2), shape (..., 2, n); an :class:`InputError` at zero range (bearing undefined)."""
        d = self._offset(x)
        r2 = d[..., 0] ** 2 + d[..., 1] ** 2
        if np.any(r2 == 0):
            raise InputError("the position coincides with the sensor: range and bearing have no derivative there")
        r = np.sqrt(r2)
        J = np.zeros(d.shape[:-1] + (2, self.n_state))
        i, j = self.position
        J[..., 0, i], J[..., 0, j] = d[..., 0] / r, d[..., 1] / r
        J[..., 1, i], J[..., 1, j] = -d[..., 1] / r2, d[..., 0] / r2
        return J

    # ``y − ŷ`` with the angle channels (here the bearing) wrapped to (−π, π], and noisy readings with the
    # bearing wrapped: the 3-D sensor's, whose angles are its channels 1: as the bearing is here
    residual = RangeAzimuthElevation.residual
    measure = RangeAzimuthElevation.measure

    def compiled_functions(self) -> CompiledMeasurement:
        """(P1)-(P2) and the wrapped residual for one state, numba-compiled (:mod:`hinfnav.systems.compiled`)."""
        fns = package_functions()
        return CompiledMeasurement(fns.range_bearing_h, fns.range_bearing_jacobian, fns.angles_residual,
                                   np.concatenate([[self.n_state], self.position, self.origin]))

    def inverse(self, m: ArrayLike) -> NDArray[np.float64]:
        """(P3) The position ``o + r (cos b, sin b)`` of readings (r, b), shape (..., 2), m."""
        m = np.asarray(m, dtype=float)
        if m.ndim < 1 or m.shape[-1] != 2:
            raise InputError(f"m must have shape (..., 2) (range, bearing); got {m.shape}")
        if not np.all(np.isfinite(m)):
            raise InputError("m must contain only finite numbers; it has NaN or inf entries")
        return self.origin + m[..., :1] * np.stack([np.cos(m[..., 1]), np.sin(m[..., 1])], axis=-1)

    def position_covariance(self, m: ArrayLike) -> NDArray[np.float64]:
        """(P4) ``J R Jᵀ``, ``J = [[cos b, −r sin b], [sin b, r cos b]]`` at readings (r, b), shape (..., 2, 2), m²."""
        m = np.asarray(m, dtype=float)
        r, b = m[..., 0], m[..., 1]
        cb, sb = np.cos(b), np.sin(b)
        J = np.stack([np.stack([cb, -r * sb], axis=-1), np.stack([sb, r * cb], axis=-1)], axis=-2)
        return J @ self.R @ np.swapaxes(J, -1, -2)


class ConvertedRangeBearing(ConvertedPosition):
    """Planar range/bearing readings converted to position: ``z = g(y) = H x + e``, cov(e) ≈ J R Jᵀ (P4).

    :class:`~hinfnav.systems.measurements.ConvertedPosition` on a
    :class:`RangeBearing` sensor: readings are the sensor's (r, b); the model
    is linear in the state (``H`` selects the position), ``residual(y, ŷ) =
    g(y) − ŷ`` and ``noise_covariance(y)`` gives ``R_k`` per reading, which the
    Kalman filters use when the model has it.

    Parameters
    ----------
    sensor : RangeBearing
    """

    def __init__(self, sensor: RangeBearing) -> None:
        if not isinstance(sensor, RangeBearing):
            raise InputError(f"sensor must be a RangeBearing model; got {type(sensor).__name__}")
        MeasurementModel.__init__(self, sensor.n_state, sensor.D, sensor.labels, sensor.units)
        self.sensor = sensor
        H = np.zeros((2, sensor.n_state))
        H[0, sensor.position[0]] = H[1, sensor.position[1]] = 1.0
        H.setflags(write=False)
        self.H = H
