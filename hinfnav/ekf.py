"""The EKF baseline of the paper (Table 1, Figs 2 and 4), built on filterpy.

The paper compares its robust H∞ filter with an EKF but prints nothing about
that EKF: not its measurement model, its Q, R, P₀, nor whether it knows the
chaser's control law. This module makes every one of those choices explicit
and selectable; :func:`build_ekf` gives the two variants of the filter
registry (:mod:`hinfnav.filters`):

``ekf`` (``known_input=False``)
    propagates the *unforced* Hill model. It does not know the thrust, so
    with the orbit maneuver u = Kx of (3) its model misses accelerations of
    up to ~3 m/s² (|u| ≈ 3000 N on 1000 kg at t = 0) while Q only allows
    0.001 m/s of velocity noise per step: it lags the maneuver until the
    thrust has died away (~500 s), which is the failure the paper describes
    for Fig 4 (measured, 100 runs: per-axis RMS over 100–500 s of
    0.43–0.67 m and 2.7–4.3 m/s; over 500–1000 s 0.064 m and 0.07–0.08 m/s).
    Nothing is tuned to make it fail: Q and R are the true noise levels.
``ekf_known_input`` (``known_input=True``)
    propagates the Hill model driven by the applied thrust u(k) (the ``u``
    argument of :meth:`EKF.estimate`). Its error obeys the unforced model
    whatever u is, so with or without maneuver it sits at the open-loop
    Riccati limit (0.0626 m, 0.0224 m/s per axis).

A third dynamics model, ``dynamics="control_law"``, assumes the law
u = K x̂ (the model the H∞ filter is designed on) without being told u.

Measurement models
------------------
``"position"`` (default)
    the indirect position measurement (8), y = C x + D v with C = [I 0]: the
    same as the H∞ filter's and what :func:`hinfnav.simulate_truth`
    produces. It is linear, so this "EKF" is the Kalman filter and its gain
    sequence does not depend on the data (see *Speed* below).
``"range_angles"``
    the direct measurement of range ρ, azimuth α and elevation β behind (7),
    nonlinear (C_bl = I unless given). Produce such measurements with
    :func:`range_angle_measurements`.

Speed
-----
With the position measurement the covariance and gain sequence is the same
for every run; the EKF computes it once with filterpy's own
``predict``/``update`` and applies the gains to all runs at once
(``vectorized=True``). ``tests/test_ekf.py`` checks that this equals running
filterpy's ``ExtendedKalmanFilter`` run by run. The range/angle model runs
filterpy run by run (``vectorized=False``).
"""

import numpy as np
from filterpy.kalman import ExtendedKalmanFilter

from .estimators import EstimateHistory, Estimator, check_estimator_inputs
from .exceptions import HinfnavError, InputError
from .kalman import _as_cov
from .models import measurement_matrix
from .scenario import Scenario
from .validation import as_choice, as_matrix, as_nonnegative, as_positive

__all__ = [
    "MEASUREMENT_MODELS",
    "DYNAMICS_MODELS",
    "OUTPUTS",
    "DEFAULT_P0_STD",
    "DEFAULT_SIGMA_RANGE",
    "DEFAULT_SIGMA_ANGLE",
    "EKF",
    "build_ekf",
    "range_angles",
    "range_angles_jacobian",
    "position_from_range_angles",
    "range_angle_measurements",
]

#: Measurement models of :class:`EKF`.
MEASUREMENT_MODELS = ("position", "range_angles")
#: Dynamics models of :class:`EKF`: what the filter assumes about the thrust.
DYNAMICS_MODELS = ("unforced", "applied_thrust", "control_law")
#: What :meth:`EKF.estimate` returns at t_k: x̂(k|k) or x̂(k|k−1).
OUTPUTS = ("filtered", "predicted")

#: Default initial standard deviations of the EKF, (m, m, m, m/s, m/s, m/s).
#: The paper's initial estimate (630, 520, 1000, 0, 0, 0) is off the truth
#: (600, 550, 1040, 0.02, −0.08, 0.03) by (30, 30, 40) m and
#: (0.02, 0.08, 0.03) m/s; 50 m and 0.1 m/s put each of those inside one σ.
DEFAULT_P0_STD = np.array([50.0, 50.0, 50.0, 0.1, 0.1, 0.1])
#: Default range noise of the range/angle model, m (the paper's 0.1 m accuracy).
DEFAULT_SIGMA_RANGE = 0.1
#: Default angle noise of the range/angle model, rad: 0.1 m across the line of
#: sight at the initial range of ~1.3 km is ~1e-4 rad.
DEFAULT_SIGMA_ANGLE = 1e-4


# ---------------------------------------------------------------------------
# range / azimuth / elevation, eq. (7)
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
    if x.ndim < 1 or x.shape[-1] not in (3, 6):
        raise InputError(f"x must have shape (..., 6) (states) or (..., 3) (positions); got {x.shape}")
    if not np.all(np.isfinite(x)):
        raise InputError("x must contain only finite numbers; it has NaN or inf entries")
    return x[..., :3]


def range_angles(x, C_bl=None):
    """Range, azimuth and elevation of a relative position, inverse of (7).

    (7) reads ``(x, y, z)ᵀ = C_bl⁻¹ (ρ cos β cos α, ρ cos β sin α, −ρ sin β)ᵀ``,
    so with ``p_b = C_bl (x, y, z)ᵀ``: ``ρ = |p_b|``,
    ``α = atan2(p_b2, p_b1)``, ``β = atan2(−p_b3, √(p_b1² + p_b2²))``.

    Parameters
    ----------
    x : array_like, shape (..., 6) or (..., 3)
        States (only the position is used) or positions, m.
    C_bl : array_like, shape (3, 3), optional
        Rotation from the relative (orbital) frame to the chaser body frame;
        the identity by default.

    Returns
    -------
    ndarray, shape (..., 3)
        ρ (m), α (rad, in (−π, π]), β (rad, in [−π/2, π/2]).

    Raises
    ------
    InputError
        For a bad shape or a zero range (the angles are undefined there).
    """
    p = _positions(x) @ _check_C_bl(C_bl).T
    rho = np.linalg.norm(p, axis=-1)
    if np.any(rho == 0):
        raise InputError("x has a zero relative position; range and angles are undefined there")
    h = np.hypot(p[..., 0], p[..., 1])
    return np.stack([rho, np.arctan2(p[..., 1], p[..., 0]), np.arctan2(-p[..., 2], h)], axis=-1)


def range_angles_jacobian(x, C_bl=None):
    """Jacobian of :func:`range_angles` with respect to the state, shape (3, 6).

    Parameters
    ----------
    x : array_like, shape (6,)
        State, m and m/s.
    C_bl : array_like, shape (3, 3), optional

    Returns
    -------
    ndarray, shape (3, 6)
        ∂(ρ, α, β)/∂x; the velocity columns are zero.

    Raises
    ------
    InputError
        On the line of sight's singularities (zero range, or the position
        along the body z axis where the azimuth is undefined).
    """
    C = _check_C_bl(C_bl)
    x = np.asarray(x, dtype=float)
    if x.shape != (6,):
        raise InputError(f"x must have shape (6,); got {x.shape}")
    p = C @ x[:3]
    rho2 = float(p @ p)
    h2 = p[0] ** 2 + p[1] ** 2
    if h2 == 0:
        raise InputError("the position lies on the body z axis (or at zero range): the azimuth has no derivative there")
    rho, h = np.sqrt(rho2), np.sqrt(h2)
    Jb = np.array(
        [
            p / rho,
            [-p[1] / h2, p[0] / h2, 0.0],
            [p[2] * p[0] / (h * rho2), p[2] * p[1] / (h * rho2), -h / rho2],
        ]
    )
    J = np.zeros((3, 6))
    J[:, :3] = Jb @ C
    return J


def position_from_range_angles(m, C_bl=None):
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
    m = np.asarray(m, dtype=float)
    if m.ndim < 1 or m.shape[-1] != 3:
        raise InputError(f"m must have shape (..., 3) (range, azimuth, elevation); got {m.shape}")
    rho, a, b = m[..., 0], m[..., 1], m[..., 2]
    pb = np.stack([rho * np.cos(b) * np.cos(a), rho * np.cos(b) * np.sin(a), -rho * np.sin(b)], axis=-1)
    return pb @ _check_C_bl(C_bl)  # C_bl⁻¹ = C_blᵀ, applied to row vectors


def _wrap(angle):
    """Wrap angles to (−π, π] (angles already inside are returned unchanged)."""
    angle = np.asarray(angle, dtype=float)
    inside = (angle > -np.pi) & (angle <= np.pi)
    return np.where(inside, angle, np.pi - np.mod(np.pi - angle, 2 * np.pi))


def range_angle_measurements(x, rng, sigma_range=DEFAULT_SIGMA_RANGE, sigma_angle=DEFAULT_SIGMA_ANGLE, C_bl=None):
    """Noisy range/azimuth/elevation measurements of the states ``x``, eq. (7).

    Parameters
    ----------
    x : array_like, shape (..., 6) or (..., 3)
        True states (e.g. ``Truth.x``, shape (runs, n_steps + 1, 6)), m, m/s.
    rng : numpy.random.Generator
        Source of the noise; one ``standard_normal(x.shape[:-1] + (3,))``
        draw.
    sigma_range : float
        Standard deviation of the range noise, m (≥ 0).
    sigma_angle : float
        Standard deviation of the azimuth and elevation noise, rad (≥ 0).
    C_bl : array_like, shape (3, 3), optional
        Rotation from the relative frame to the body frame (identity).

    Returns
    -------
    ndarray, shape (..., 3)
        ρ + σ_ρ n₁ (m), α + σ_α n₂ and β + σ_α n₃ (rad), with the azimuth
        wrapped to (−π, π]. Feed it to an :class:`EKF` built with
        ``measurement="range_angles"`` and the same sigmas.

    Notes
    -----
    The paper measures ρ, α, β with radar or cameras and turns them into the
    indirect measurement (8) through (7); (7) is taken literally here: the
    measured angles are those that (7) maps to the relative position x.
    """
    if not isinstance(rng, np.random.Generator):
        raise InputError(f"rng must be a numpy.random.Generator (e.g. numpy.random.default_rng(seed)); got {type(rng).__name__}")
    sr = as_nonnegative("sigma_range", sigma_range)
    sa = as_nonnegative("sigma_angle", sigma_angle)
    clean = range_angles(x, C_bl)
    noisy = clean + rng.standard_normal(clean.shape) * np.array([sr, sa, sa])
    noisy[..., 1] = _wrap(noisy[..., 1])
    return noisy


def _residual_range_angles(a, b):
    d = np.asarray(a, dtype=float) - np.asarray(b, dtype=float)
    d[1:] = _wrap(d[1:])
    return d


# ---------------------------------------------------------------------------
# the filter
# ---------------------------------------------------------------------------


class EKF(Estimator):
    """Extended Kalman filter of the chaser's relative state (filterpy).

    Parameters
    ----------
    scenario : Scenario, optional
        Gives T, ω₀, mass, K, B and D; the paper's by default.
    measurement : {"position", "range_angles"}
        ``"position"``: y = C x + D v of (8), R = D Dᵀ by default.
        ``"range_angles"``: y = (ρ, α, β) of (7) plus white noise,
        R = diag(σ_ρ², σ_α², σ_α²) by default.
    dynamics : {"unforced", "applied_thrust", "control_law"}
        ``"unforced"``: x̂(k+1|k) = Φ x̂(k|k), the thrust unknown (the
        paper's EKF). ``"applied_thrust"``: Φ x̂(k|k) + Γ u(k) with the
        applied u. ``"control_law"``: (Φ + Γ K) x̂(k|k), the law u = Kx
        assumed (right with the maneuver: 0.0625 m, 0.0138 m/s; wrong
        without it: 7–12 m, 40–80 m/s over 100–1000 s).
    discretization : {"exact", "euler"}
        (Φ, Γ) from ``scenario.truth_matrices(0.0, discretization)``.
        ``"exact"`` (zero-order hold, default) is the truth simulation's
        default model, so the filter's model is the truth's at δ = 0 and its
        covariance is the true error covariance. ``"euler"`` is the paper's
        (6); the two differ by T²A₀²/2, which is tiny for A₁ but, for the
        thrust, leaves out the T²/2m position term of Γ (5 mm per step at
        1000 N).
    Q : array_like, shape (6, 6), optional
        Process-noise covariance per step; default B Bᵀ (positive
        semidefinite).
    R : array_like, shape (3, 3), optional
        Measurement-noise covariance (positive definite); default D Dᵀ or
        diag(σ_ρ², σ_α², σ_α²).
    P0 : array_like, shape (6, 6), optional
        Initial covariance (positive definite); default
        diag(:data:`DEFAULT_P0_STD`)².
    sigma_range, sigma_angle : float, optional
        Noise of the range/angle model (m, rad) for its default R; only
        with ``measurement="range_angles"``.
    C_bl : array_like, shape (3, 3), optional
        Relative-to-body rotation of the range/angle model (identity).
    output : {"filtered", "predicted"}
        What ``xhat[:, k]`` is: ``"filtered"`` (default) x̂(k|k), which uses
        y(0) … y(k); ``"predicted"`` x̂(k|k−1), which uses y(0) … y(k−1) like
        the fixed LTI filter (12) (and ``xhat[:, 0] = xhat0``).
    vectorized : bool, optional
        Position model only: True (default) computes the gain sequence once
        with filterpy and applies it to all runs at once; False runs
        filterpy's ``ExtendedKalmanFilter`` run by run (the reference). The
        range/angle model is always run by run.
    keep_covariance : bool
        Return the covariance history ``P`` (default). In vectorized mode it
        is one read-only (n_steps + 1, 6, 6) array broadcast over the runs
        (no memory per run, but concatenating batches materializes it:
        ~290 MB per 100 runs of 10 001 samples); False for Monte Carlo.
    name : str, optional

    Notes
    -----
    *Model.* The Hill dynamics (1)–(2) are linear, so the dynamics Jacobian
    is Φ (or Φ + ΓK) itself and the only nonlinearity is the range/angle
    measurement; with the indirect measurement (8) the EKF is exactly the
    Kalman filter. The filter uses the nominal rate ω₀ (δ = 0).

    *Noise.* The simulation drives the truth with unit-variance white w, v
    scaled by B and D ((6), (8)), so Q = B Bᵀ and R = D Dᵀ are the true
    covariances: no tuning. The unforced EKF's failure with maneuver follows
    from Q being far too small for the unmodelled thrust, which is exactly
    what an EKF built on the stated noise model and without the control law
    has to do.

    *Timing.* ``xhat[:, k]`` is by default the filtered estimate x̂(k|k): it
    has used y(k), as a textbook EKF does. The fixed LTI filter (12) is a
    predictor (y up to k−1); its limit is the predicted one (0.0802 m instead
    of 0.0626 m per axis, velocity nearly the same). ``output="predicted"``
    gives the EKF on the same footing.

    *Discretization.* Exact (zero-order hold) by default because the truth
    simulation uses it: the filter's model then is the truth's at δ = 0, so
    its covariance is the true error covariance and it reaches the Riccati
    limit. Euler ((6) of the paper) is available for comparison.

    *Initial covariance.* P₀ = diag(50², 50², 50², 0.1², 0.1², 0.1²) covers
    the initial estimate's errors (30, 30, 40) m, (0.02, 0.08, 0.03) m/s
    within one σ. The position part is irrelevant after the first update
    (R = 0.01 m²); the velocity part sets how fast the velocity converges.

    *Accuracy limit.* Its steady-state covariance is the discrete Riccati
    solution of :func:`hinfnav.kalman.kalman_limit` for the open-loop
    model: 0.0626 m and 0.0224 m/s per axis, filtered. Table 1's EKF
    numbers (0.04 m, 0.001 m/s) are below that limit.
    """

    def __init__(
        self,
        scenario=None,
        *,
        measurement="position",
        dynamics="unforced",
        discretization="exact",
        Q=None,
        R=None,
        P0=None,
        sigma_range=None,
        sigma_angle=None,
        C_bl=None,
        output="filtered",
        vectorized=None,
        keep_covariance=True,
        name=None,
    ):
        scenario = Scenario() if scenario is None else scenario
        if not isinstance(scenario, Scenario):
            raise InputError(f"scenario must be a hinfnav.Scenario; got {type(scenario).__name__}")
        self.measurement = as_choice("measurement model", measurement, MEASUREMENT_MODELS)
        self.dynamics = as_choice("dynamics model", dynamics, DYNAMICS_MODELS)
        self.discretization = as_choice("discretization", discretization, ("exact", "euler"))
        self.output = as_choice("output", output, OUTPUTS)
        if not isinstance(keep_covariance, (bool, np.bool_)):
            raise InputError(f"keep_covariance must be True or False; got {keep_covariance!r}")
        self.keep_covariance = bool(keep_covariance)
        self.dt = scenario.dt

        Phi, Gamma = scenario.truth_matrices(0.0, self.discretization)
        self.Gamma = Gamma
        self.F = Phi + Gamma @ scenario.K if self.dynamics == "control_law" else Phi
        self.uses_input = self.dynamics == "applied_thrust"
        self.Q = _as_cov("Q", scenario.B @ scenario.B.T if Q is None else Q, 6, definite=False)
        self.P0 = _as_cov("P0", np.diag(DEFAULT_P0_STD**2) if P0 is None else P0, 6, definite=True)

        if self.measurement == "position":
            for key, val in (("sigma_range", sigma_range), ("sigma_angle", sigma_angle), ("C_bl", C_bl)):
                if val is not None:
                    raise InputError(f"{key} applies only to measurement='range_angles'")
            self.H = measurement_matrix()
            self.C_bl = None
            default_R = scenario.D @ scenario.D.T
            if vectorized is None:
                vectorized = True
        else:
            self.H = None
            self.C_bl = _check_C_bl(C_bl)
            sr = DEFAULT_SIGMA_RANGE if sigma_range is None else as_positive("sigma_range", sigma_range)
            sa = DEFAULT_SIGMA_ANGLE if sigma_angle is None else as_positive("sigma_angle", sigma_angle)
            default_R = np.diag([sr**2, sa**2, sa**2])
            if vectorized:
                raise InputError("vectorized=True needs measurement='position' (the range/angle gains depend on the data)")
            vectorized = False
        if not isinstance(vectorized, (bool, np.bool_)):
            raise InputError(f"vectorized must be True, False or None; got {vectorized!r}")
        self.vectorized = bool(vectorized)
        self.R = _as_cov("R", default_R if R is None else R, 3, definite=True)

        if name is None:
            name = {"unforced": "ekf", "applied_thrust": "ekf_known_input", "control_law": "ekf_control_law"}[self.dynamics]
            if self.measurement == "range_angles":
                name += "_range_angles"
        self.name = str(name)
        self._gain_cache = {}

    # -- filterpy plumbing ------------------------------------------------

    def _hjacobian(self, x):
        return self.H if self.H is not None else range_angles_jacobian(x, self.C_bl)

    def _hx(self, x):
        return self.H @ x if self.H is not None else range_angles(x, self.C_bl)

    def _new_filterpy(self, x0):
        f = ExtendedKalmanFilter(dim_x=6, dim_z=3, dim_u=3)
        f.x = np.array(x0, dtype=float)
        f.P = self.P0.copy()
        f.F = self.F
        f.Q = self.Q
        f.R = self.R
        f.B = self.Gamma if self.uses_input else 0
        return f

    def _residual(self):
        return np.subtract if self.measurement == "position" else _residual_range_angles

    def _run_filterpy(self, y, u, xhat0):
        """One run through filterpy's ExtendedKalmanFilter, step by step.

        Returns prior and posterior states (n1, 6) and covariances (n1, 6, 6).
        """
        n1 = y.shape[0]
        f = self._new_filterpy(xhat0)
        residual = self._residual()
        xs = np.empty((2, n1, 6))
        Ps = np.empty((2, n1, 6, 6)) if self.keep_covariance else None
        for k in range(n1):
            if k:
                f.predict(u=u[k - 1] if self.uses_input else 0)
            xs[0, k] = f.x
            if Ps is not None:
                Ps[0, k] = f.P
            try:
                f.update(y[k], self._hjacobian, self._hx, residual=residual)
            except InputError as exc:
                raise HinfnavError(f"EKF {self.name!r} stopped at step {k}: the estimate reached a singular point ({exc})") from None
            xs[1, k] = f.x
            if Ps is not None:
                Ps[1, k] = f.P
        return xs, Ps

    def gain_sequence(self, n_samples):
        """Covariances and gains of the position model, computed by filterpy.

        Parameters
        ----------
        n_samples : int
            Number of samples n_steps + 1.

        Returns
        -------
        gains : ndarray, shape (n_samples, 6, 3)
            Kalman gain K_k of the update at t_k.
        P_prior, P_post : ndarray, shape (n_samples, 6, 6)
            P(k|k−1) (P₀ at k = 0) and P(k|k).
        """
        if self.measurement != "position":
            raise InputError("gain_sequence needs measurement='position' (the range/angle gains depend on the data)")
        n_samples = int(n_samples)
        if n_samples not in self._gain_cache:
            f = self._new_filterpy(np.zeros(6))
            f.B = 0
            zero = np.zeros(3)
            gains = np.empty((n_samples, 6, 3))
            Pp = np.empty((n_samples, 6, 6))
            Pf = np.empty((n_samples, 6, 6))
            for k in range(n_samples):
                if k:
                    f.predict()
                Pp[k] = f.P
                f.update(zero, self._hjacobian, self._hx)
                gains[k] = f.K
                Pf[k] = f.P
            for arr in (gains, Pp, Pf):
                arr.setflags(write=False)
            self._gain_cache = {n_samples: (gains, Pp, Pf)}  # keep the latest only
        return self._gain_cache[n_samples]

    # -- the estimator interface -------------------------------------------

    def estimate(self, y, u, xhat0):
        """Estimate the state histories of a batch of runs.

        Parameters
        ----------
        y : array_like, shape (runs, n_steps + 1, 3)
            Measurements at t_k: positions (m) for ``"position"``, or
            (ρ, α, β) (m, rad, rad) for ``"range_angles"``.
        u : array_like, shape (runs, n_steps + 1, 3)
            Thrust applied over [t_k, t_k+1), N; used only with
            ``dynamics="applied_thrust"``.
        xhat0 : array_like, shape (6,)
            Prior estimate of x(0), m and m/s.

        Returns
        -------
        EstimateHistory
            ``xhat`` (runs, n_steps + 1, 6): x̂(k|k) (``output="filtered"``)
            or x̂(k|k−1) (``"predicted"``); ``P`` (runs, n_steps + 1, 6, 6),
            the matching covariance, or None without ``keep_covariance``.
        """
        y, u, xhat0 = check_estimator_inputs(y, u, xhat0)
        if y.shape[2] != 3:
            raise InputError(f"y must have 3 measurement channels; got {y.shape[2]}")
        if u.shape[2] != 3:
            raise InputError(f"u must have 3 thrust channels; got {u.shape[2]}")
        which = 1 if self.output == "filtered" else 0
        runs, n1, _ = y.shape
        if not self.vectorized:
            xhat = np.empty((runs, n1, 6))
            P = np.empty((runs, n1, 6, 6)) if self.keep_covariance else None
            for r in range(runs):
                xs, Ps = self._run_filterpy(y[r], u[r], xhat0)
                xhat[r] = xs[which]
                if P is not None:
                    P[r] = Ps[which]
            return EstimateHistory(xhat=xhat, P=P)

        gains, Pp, Pf = self.gain_sequence(n1)
        FT = self.F.T
        HT = self.H.T
        drive = u @ self.Gamma.T if self.uses_input else None
        xhat = np.empty((runs, n1, 6))
        xp = np.broadcast_to(xhat0, (runs, 6)).copy()
        for k in range(n1):
            if k:
                xp = xf @ FT
                if drive is not None:
                    xp += drive[:, k - 1]
            xf = xp + (y[:, k] - xp @ HT) @ gains[k].T
            xhat[:, k] = xf if which else xp
        P = None
        if self.keep_covariance:
            P = np.broadcast_to((Pf if which else Pp)[None], (runs, n1, 6, 6))
        return EstimateHistory(xhat=xhat, P=P)


def build_ekf(scenario=None, known_input=False, **options):
    """Build the EKF of the filter registry (names ``ekf``, ``ekf_known_input``).

    Parameters
    ----------
    scenario : Scenario, optional
        The paper's by default.
    known_input : bool
        False: the paper's EKF, which does not know the thrust
        (``dynamics="unforced"``). True: told the applied thrust
        (``dynamics="applied_thrust"``).
    **options
        Passed to :class:`EKF` (``measurement``, ``discretization``, ``Q``,
        ``R``, ``P0``, ``output``, ...). ``dynamics="control_law"`` is
        accepted with ``known_input=False`` (it does not use u).

    Returns
    -------
    EKF
    """
    if not isinstance(known_input, (bool, np.bool_)):
        raise InputError(f"known_input must be True or False; got {known_input!r}")
    dynamics = options.pop("dynamics", None)
    if dynamics is None:
        dynamics = "applied_thrust" if known_input else "unforced"
    else:
        as_choice("dynamics model", dynamics, DYNAMICS_MODELS)
        if (dynamics == "applied_thrust") != bool(known_input):
            raise InputError(
                f"dynamics={dynamics!r} contradicts known_input={bool(known_input)}: "
                "only dynamics='applied_thrust' uses the applied thrust"
            )
    return EKF(scenario, dynamics=dynamics, **options)
