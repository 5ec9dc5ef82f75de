"""Rigid-body attitude: quaternions, kinematics, dynamics with an augmented torque, star-sensor vectors.

Conventions (stated once, used everywhere in the package):

* **Quaternion, scalar last** (as paper 002 and Lefferts, Markley & Shuster
  1982): ``q = [q1, q2, q3, q4] = [e sin(φ/2), cos(φ/2)]``.
* **Attitude matrix** ``A(q)`` maps a vector's components in the reference
  (orbital) frame to the body frame (star-sensor axes = body axes):
  ``A(q) = (q4² − |e|²) I + 2 e eᵀ − 2 q4 [e×]``   (A1)
* **Product** ``p ⊗ q = [p4 q_v + q4 p_v − p_v × q_v, p4 q4 − p_v·q_v]`` (A2),
  so that ``A(p ⊗ q) = A(p) A(q)`` (Shuster's order).
* **Kinematics** ``q̇ = ½ Ω(ω) q = ½ [ω; 0] ⊗ q`` (A3), ω the body rate
  in body axes, ``Ω(ω) = [[−[ω×], ω], [−ωᵀ, 0]]``.
* **Dynamics** ``J ω̇ = −ω × (J ω + h) + T_c + T_d`` (A4), h the wheel
  momentum, T_c the (known) control torque, T_d the disturbance torque; as in
  paper 002 the orbital frame is treated as the reference frame and its own
  rotation is not in (A4).
* **Augmented torque** ``Ṫ_d = n_β`` (A5): a random walk in the filter's
  model (density Q, (N·m)²/s); the truth replaces it with a known T_d(t).
* **Attitude error** ``δq = q ⊗ q̂⁻¹`` (A6), reported as the Euler angles of
  δq in the **3-2-1 sequence** (yaw ψ about z, pitch θ about y, roll φ about
  x; ``A = R₁(φ) R₂(θ) R₃(ψ)``); to first order these are the small angles
  δθ with ``A(δq) ≈ I − [δθ×]``. Rate and torque errors are additive.
* **Star sensor** ``C_S = A(q) C_I + υ`` (A7) for each reference vector C_I
  (orbital frame), υ white with covariance R per vector (paper: 1e-10 I₃).

The state vector stored by systems and estimators is
``x = [q1, q2, q3, q4, ωx, ωy, ωz, Tx, Ty, Tz]`` (10 components); errors,
covariances, metrics and plots live in the 9 error coordinates
``[φ, θ, ψ, δωx, δωy, δωz, δTx, δTy, δTz]`` described by
:class:`AttitudeStateSpec`.
"""

from dataclasses import dataclass, field

import numpy as np

from ..core.exceptions import InputError
from ..core.validation import as_int_at_least, as_matrix, as_positive, as_vector
from .measurements import MeasurementModel
from .state import StateSpec

__all__ = [
    "QUAT",
    "RATE",
    "TORQUE",
    "AttitudeStateSpec",
    "AttitudeSystem",
    "StarSensorVectors",
    "attitude_matrix",
    "attitude_state_spec",
    "cross",
    "cross_matrix",
    "euler321_from_quat",
    "omega_matrix",
    "quat_conjugate",
    "quat_from_euler321",
    "quat_from_rotvec",
    "quat_multiply",
    "quat_normalize",
    "rotvec_from_quat",
]

#: Slices of the stored state: quaternion, body rate (rad/s), torque (N·m).
QUAT, RATE, TORQUE = slice(0, 4), slice(4, 7), slice(7, 10)


# ---------------------------------------------------------------------------
# quaternion algebra, batched over leading axes
# ---------------------------------------------------------------------------


def _levi_civita():
    eps = np.zeros((3, 3, 3))
    for i, j, k in ((0, 1, 2), (1, 2, 0), (2, 0, 1)):
        eps[i, j, k], eps[i, k, j] = 1.0, -1.0
    return eps


#: ε_ijk; ``[v×]_ij = −ε_ijk v_k`` and ``(a × b)_i = ε_ijk a_j b_k``.
_EPS = _levi_civita()
_CROSS_MAT = -_EPS.transpose(2, 0, 1).reshape(3, 9)  # v (3) -> [v×] (9)
_CROSS = _EPS.reshape(3, 9).T.copy()  # (a ⊗ b) (9) -> a × b (3)


def _rows(a, B):
    """``a @ B`` for a batch of row vectors ``a`` (..., k) and one matrix ``B`` (k, m), row by row.

    ``a @ B`` on a 2-D ``a`` is one BLAS call whose kernel (matrix-vector for
    one row, matrix-matrix for several) and hence rounding depend on the number
    of rows: a run's numbers would depend on which runs share its batch.
    Each row here is the same sum of products whatever the batch.
    """
    return np.einsum("...k,km->...m", a, B)


def cross_matrix(v):
    """``[v×]`` such that ``[v×] w = v × w``; shape (..., 3, 3)."""
    v = np.asarray(v, dtype=float)
    return _rows(v, _CROSS_MAT).reshape(v.shape[:-1] + (3, 3))


def cross(a, b):
    """``a × b`` for batches (faster than :func:`numpy.cross` on small vectors)."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    outer = a[..., :, None] * b[..., None, :]
    return _rows(outer.reshape(outer.shape[:-2] + (9,)), _CROSS)


def _quat_multiply_reference(p, q):
    """(A2) written out, used once to build the product tensor."""
    pv, p4, qv, q4 = p[:3], p[3], q[:3], q[3]
    return np.concatenate([p4 * qv + q4 * pv - np.cross(pv, qv), [p4 * q4 - pv @ qv]])


def _product_tensor():
    basis = np.eye(4)
    C = np.empty((4, 4, 4))  # (p ⊗ q)_i = Σ_jk C_ijk p_j q_k
    for j in range(4):
        for k in range(4):
            C[:, j, k] = _quat_multiply_reference(basis[j], basis[k])
    return C.reshape(4, 16).T.copy()


def _attitude_reference(q):
    """(A1) written out, used once to build the attitude tensor."""
    e, q4 = q[:3], q[3]
    ex = np.array([[0, -e[2], e[1]], [e[2], 0, -e[0]], [-e[1], e[0], 0]])
    return (q4**2 - e @ e) * np.eye(3) + 2 * np.outer(e, e) - 2 * q4 * ex


def _attitude_tensor():
    # A is quadratic in q: A_ab = Σ_kl C_abkl q_k q_l with C symmetric in (k, l)
    basis = np.eye(4)
    C = np.empty((3, 3, 4, 4))
    for k in range(4):
        C[:, :, k, k] = _attitude_reference(basis[k])
        for l in range(k + 1, 4):
            both = _attitude_reference(basis[k] + basis[l]) - _attitude_reference(basis[k]) - _attitude_reference(basis[l])
            C[:, :, k, l] = C[:, :, l, k] = 0.5 * both
    return C


_QPROD = _product_tensor()  # (16, 4): (p ⊗ q) = vec(p qᵀ) @ _QPROD
_ATT = _attitude_tensor()  # (3, 3, 4, 4)
_ATT_FLAT = _ATT.reshape(9, 16).T.copy()  # vec(q qᵀ) @ _ATT_FLAT = vec(A(q))


def _outer16(p, q):
    outer = p[..., :, None] * q[..., None, :]
    return outer.reshape(outer.shape[:-2] + (16,))


def _outer12(w, q):
    outer = w[..., :, None] * q[..., None, :]
    return outer.reshape(outer.shape[:-2] + (12,))


def quat_multiply(p, q):
    """``p ⊗ q`` of (A2), scalar last, so that ``A(p ⊗ q) = A(p) A(q)``."""
    return _rows(_outer16(np.asarray(p, dtype=float), np.asarray(q, dtype=float)), _QPROD)


def quat_conjugate(q):
    """``q⁻¹`` of a unit quaternion: ``[−q_v, q4]``."""
    q = np.asarray(q, dtype=float)
    return np.concatenate([-q[..., :3], q[..., 3:]], axis=-1)


def quat_normalize(q):
    """``q / |q|`` (raises :class:`InputError` on a zero quaternion)."""
    q = np.asarray(q, dtype=float)
    n = np.sqrt(np.sum(q * q, axis=-1, keepdims=True))
    if not np.all(n > 0):
        raise InputError("q must be non-zero; a zero quaternion has no attitude")
    return q / n


def quat_from_rotvec(v):
    """Unit quaternion of the rotation vector v (rad): ``[sin(|v|/2) v/|v|, cos(|v|/2)]``."""
    v = np.asarray(v, dtype=float)
    ang = np.sqrt(np.sum(v * v, axis=-1, keepdims=True))
    # sin(|v|/2)/|v| = sinc(|v|/2π)/2, exact at 0
    return np.concatenate([0.5 * np.sinc(ang / (2 * np.pi)) * v, np.cos(0.5 * ang)], axis=-1)


def rotvec_from_quat(q):
    """Rotation vector (rad) of a unit quaternion, the inverse of :func:`quat_from_rotvec` (``|angle| ≤ π``)."""
    q = np.asarray(q, dtype=float)
    q = np.where(q[..., 3:] < 0, -q, q)
    s = np.linalg.norm(q[..., :3], axis=-1, keepdims=True)
    ang = 2.0 * np.arctan2(s, q[..., 3:])
    k = np.where(s > 1e-12, ang / np.where(s > 0, s, 1.0), 2.0 / np.maximum(q[..., 3:], 1e-300))
    return k * q[..., :3]


def attitude_matrix(q):
    """``A(q)`` of (A1), reference (orbital) frame → body frame; shape (..., 3, 3)."""
    q = np.asarray(q, dtype=float)
    return _rows(_outer16(q, q), _ATT_FLAT).reshape(q.shape[:-1] + (3, 3))


def omega_matrix(w):
    """``Ω(ω)`` of (A3), shape (..., 4, 4)."""
    w = np.asarray(w, dtype=float)
    out = np.zeros(w.shape[:-1] + (4, 4))
    out[..., :3, :3] = -cross_matrix(w)
    out[..., :3, 3] = w
    out[..., 3, :3] = -w
    return out


def euler321_from_matrix(A):
    """Euler angles (φ, θ, ψ) of the 3-2-1 sequence, ``A = R₁(φ) R₂(θ) R₃(ψ)``, rad; shape (..., 3)."""
    A = np.asarray(A, dtype=float)
    phi = np.arctan2(A[..., 1, 2], A[..., 2, 2])
    theta = -np.arcsin(np.clip(A[..., 0, 2], -1.0, 1.0))
    psi = np.arctan2(A[..., 0, 1], A[..., 0, 0])
    return np.stack([phi, theta, psi], axis=-1)


def euler321_from_quat(q):
    """3-2-1 Euler angles (φ, θ, ψ) of ``A(q)``, rad."""
    return euler321_from_matrix(attitude_matrix(q))


def quat_from_euler321(angles):
    """Unit quaternion with ``A(q) = R₁(φ) R₂(θ) R₃(ψ)`` for angles (φ, θ, ψ) in rad."""
    a = np.asarray(angles, dtype=float)
    z = np.zeros(a.shape[:-1] + (1,))

    def axis_quat(i, ang):
        v = [z, z, z]
        v[i] = np.sin(ang[..., None] / 2)
        return np.concatenate(v + [np.cos(ang[..., None] / 2)], axis=-1)

    # A(p ⊗ q) = A(p) A(q): R₁(φ) R₂(θ) R₃(ψ) is q(φ about x) ⊗ q(θ about y) ⊗ q(ψ about z)
    return quat_multiply(quat_multiply(axis_quat(0, a[..., 0]), axis_quat(1, a[..., 1])), axis_quat(2, a[..., 2]))


# ---------------------------------------------------------------------------
# the state and its error
# ---------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class AttitudeStateSpec(StateSpec):
    """State spec of ``x = [q (scalar last), ω, T_d]`` with a multiplicative attitude error.

    ``labels``, ``units`` and ``groups`` describe the **error coordinates**
    (what :meth:`error` returns and what metrics and plots read): the 3-2-1
    Euler angles (φ, θ, ψ) of ``δq = q ⊗ q̂⁻¹`` (rad), the rate error (rad/s)
    and the torque error (N·m); 9 components, also the dimension of the
    filters' covariance. ``stored_labels`` and ``stored_units`` name the 10
    components of the stored state.
    """

    stored_labels: tuple = ("q1", "q2", "q3", "q4", "wx", "wy", "wz", "Tx", "Ty", "Tz")
    stored_units: tuple = ("-", "-", "-", "-", "rad/s", "rad/s", "rad/s", "N m", "N m", "N m")
    sequence: str = "3-2-1"

    @property
    def n_stored(self):
        """Number of stored state components (10)."""
        return len(self.stored_labels)

    def error(self, x, xhat):
        """Estimation error in error coordinates, shape (..., 9).

        ``[euler321(q ⊗ q̂⁻¹), ω − ω̂, T − T̂]``; the Euler angles are those of
        the error quaternion (A6), small angles to first order.
        """
        x, xhat = np.asarray(x, dtype=float), np.asarray(xhat, dtype=float)
        if x.shape[-1] != self.n_stored or xhat.shape[-1] != self.n_stored:
            raise InputError(f"x and xhat must have {self.n_stored} components (q, ω, T); got {x.shape}, {xhat.shape}")
        dq = quat_multiply(x[..., QUAT], quat_conjugate(quat_normalize(xhat[..., QUAT])))
        return np.concatenate([euler321_from_quat(dq), x[..., 4:] - xhat[..., 4:]], axis=-1)


def attitude_state_spec():
    """The attitude state spec: groups ``attitude`` (rad), ``rate`` (rad/s), ``torque`` (N m)."""
    return AttitudeStateSpec(
        labels=("phi", "theta", "psi", "wx", "wy", "wz", "Tx", "Ty", "Tz"),
        units=("rad", "rad", "rad", "rad/s", "rad/s", "rad/s", "N m", "N m", "N m"),
        groups={"attitude": (0, 1, 2), "rate": (3, 4, 5), "torque": (6, 7, 8)},
        axis_names={"attitude": ("φ", "θ", "ψ"), "rate": ("x", "y", "z"), "torque": ("x", "y", "z")},
    )


# ---------------------------------------------------------------------------
# dynamics
# ---------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class AttitudeSystem:
    """Rigid-body attitude (A3)–(A5) with the torque as augmented state, sampled every ``dt``.

    Attributes
    ----------
    J : ndarray, shape (3, 3)
        Inertia, kg·m² (symmetric positive definite).
    dt : float
        Sampling time, s.
    h : ndarray, shape (3,)
        Wheel angular momentum in body axes, N·m·s (constant).
    disturbance : callable, optional
        ``T_d(t)`` → shape (3,) (N·m). Given: the truth, whose torque follows it
        (the state's torque slot holds T_d(t_k)). None: the filter's model,
        where the torque is the random walk (A5).
    substeps : int
        Runge–Kutta (4th order) steps per sampling interval.
    name : str
    """

    J: np.ndarray
    dt: float
    h: np.ndarray = field(default_factory=lambda: np.zeros(3))
    disturbance: object = None
    substeps: int = 1
    name: str = "rigid-body attitude with augmented torque"
    state: AttitudeStateSpec = field(default_factory=attitude_state_spec)

    def __post_init__(self):
        J = as_matrix("J", self.J, (3, 3))
        if not np.allclose(J, J.T, atol=1e-12 * np.abs(J).max()) or np.min(np.linalg.eigvalsh(J)) <= 0:
            raise InputError("J must be a symmetric positive definite inertia matrix (kg m^2)")
        J.setflags(write=False)
        object.__setattr__(self, "J", J)
        Ji = np.linalg.inv(J)
        Ji.setflags(write=False)
        object.__setattr__(self, "J_inv", Ji)
        h = as_vector("h", self.h, 3)
        h.setflags(write=False)
        object.__setattr__(self, "h", h)
        F0 = self._error_dynamics_reference(np.zeros(3))
        F1 = np.stack([self._error_dynamics_reference(e) - F0 for e in np.eye(3)]).reshape(3, 81)
        object.__setattr__(self, "_F_affine", (F0.reshape(81), F1))
        object.__setattr__(self, "dt", as_positive("dt", self.dt))
        object.__setattr__(self, "substeps", as_int_at_least("substeps", self.substeps, 1))
        if self.disturbance is not None and not callable(self.disturbance):
            raise InputError("disturbance must be a callable t -> torque (3,) in N m, or None")

    n = 10
    n_input = 3
    n_noise = 0
    n_error = 9
    input_labels = ("Tc_x", "Tc_y", "Tc_z")
    input_units = ("N m", "N m", "N m")

    def rate_derivative(self, w, torque):
        """``ω̇ = J⁻¹(−ω × (J ω + h) + torque)`` of (A4) for a batch, rad/s²."""
        Hm = _rows(w, self.J.T) + self.h
        return _rows(torque - cross(w, Hm), self.J_inv.T)

    def _derivative(self, q, w, torque):
        # q̇ = ½ [ω; 0] ⊗ q (A3): the product tensor's rows with p4 = 0
        qdot = 0.5 * _rows(_outer12(w, q), _QPROD[:12])
        return qdot, self.rate_derivative(w, torque)

    def step(self, x, u=None, w=None, t=0.0):
        """Propagate a batch of states over one ``dt`` (RK4, ``substeps`` steps).

        Parameters
        ----------
        x : ndarray, shape (runs, 10)
        u : ndarray, shape (runs, 3), optional
            Control torque T_c held over the interval, N·m.
        w : ignored (no process noise in the truth: the torque is given)
        t : float
            Time at the start of the interval, s (for the disturbance).

        Returns
        -------
        ndarray, shape (runs, 10), quaternion normalized.
        """
        x = np.asarray(x, dtype=float)
        q, om, T = x[..., QUAT], x[..., RATE], x[..., TORQUE]
        uc = np.zeros_like(om) if u is None else np.asarray(u, dtype=float)
        hstep = self.dt / self.substeps
        for i in range(self.substeps):
            t0 = t + i * hstep
            tq = (lambda s: uc + self.disturbance(s)) if self.disturbance is not None else (lambda s: uc + T)
            k1q, k1w = self._derivative(q, om, tq(t0))
            k2q, k2w = self._derivative(q + 0.5 * hstep * k1q, om + 0.5 * hstep * k1w, tq(t0 + 0.5 * hstep))
            k3q, k3w = self._derivative(q + 0.5 * hstep * k2q, om + 0.5 * hstep * k2w, tq(t0 + 0.5 * hstep))
            k4q, k4w = self._derivative(q + hstep * k3q, om + hstep * k3w, tq(t0 + hstep))
            q = q + hstep / 6.0 * (k1q + 2 * k2q + 2 * k3q + k4q)
            om = om + hstep / 6.0 * (k1w + 2 * k2w + 2 * k3w + k4w)
        q = quat_normalize(q)
        if self.disturbance is not None:
            T = np.broadcast_to(self.disturbance(t + self.dt), om.shape)
        return np.concatenate([q, om, T], axis=-1)

    def predict_mean(self, x, u=None):
        """The filters' one-step mean prediction (torque held constant), shape (runs, 10).

        ``ω⁺ = ω + Δt ω̇(ω, T_c + T̂)`` and ``q⁺ = exp(½ [ω̄; 0] Δt) ⊗ q`` with
        ω̄ = (ω + ω⁺)/2: second order in Δt, and cheaper than the truth's RK4.
        With ``|ω|`` ~ 1e-4 rad/s and Δt = 1 s it differs from the RK4 step by
        far less than a micro-radian per step.
        """
        x = np.asarray(x, dtype=float)
        q, om, T = x[..., QUAT], x[..., RATE], x[..., TORQUE]
        torque = T if u is None else T + u
        om1 = om + self.dt * self.rate_derivative(om, torque)
        q1 = quat_multiply(quat_from_rotvec(0.5 * (om + om1) * self.dt), q)
        return np.concatenate([quat_normalize(q1), om1, T], axis=-1)

    def _error_dynamics_reference(self, w):
        """F of :meth:`error_dynamics` at one rate, written out (builds the linear map once)."""
        F = np.zeros((9, 9))
        Wx = cross_matrix(w)
        F[:3, :3] = -Wx
        F[:3, 3:6] = np.eye(3)
        F[3:6, 3:6] = self.J_inv @ (cross_matrix(self.J @ w + self.h) - Wx @ self.J)
        F[3:6, 6:9] = self.J_inv
        return F

    def error_dynamics(self, x):
        """Jacobian F of the error dynamics at a batch of estimates, shape (runs, 9, 9).

        ``δθ̇ = −[ω̂×] δθ + δω``, ``δω̇ = J⁻¹([(Jω̂ + h)×] − [ω̂×] J) δω + J⁻¹ δT``,
        ``δṪ = n_β`` (Lefferts, Markley & Shuster 1982 for the attitude part).
        F is affine in ω̂, evaluated as ``F₀ + ω̂ F₁``.
        """
        w = np.asarray(x, dtype=float)[..., RATE]
        F0, F1 = self._F_affine
        return (F0 + _rows(w, F1)).reshape(w.shape[:-1] + (9, 9))

    def transition(self, x, order=3):
        """``Φ = e^{F Δt}`` by its Taylor series to ``order`` (‖FΔt‖ ≪ 1 here), shape (runs, 9, 9).

        Evaluated by Horner's rule, ``I + A(I + A/2 (I + A/3 (…)))`` with A = FΔt.
        """
        A = self.error_dynamics(x) * self.dt
        eye = np.eye(9)
        Phi = eye + A / order
        for k in range(order - 1, 0, -1):
            Phi = eye + (A @ Phi) / k
        return Phi

    @staticmethod
    def noise_input():
        """Γ of the error dynamics: the torque random walk enters the last three coordinates, (9, 3)."""
        G = np.zeros((9, 3))
        G[6:, :] = np.eye(3)
        return G

    @staticmethod
    def inject(x, dx):
        """Apply an error-coordinate correction: ``q ← δq(δθ) ⊗ q``, ``ω ← ω + δω``, ``T ← T + δT``."""
        q = quat_normalize(quat_multiply(quat_from_rotvec(dx[..., :3]), x[..., QUAT]))
        return np.concatenate([q, x[..., 4:] + dx[..., 3:]], axis=-1)


# ---------------------------------------------------------------------------
# star-sensor vector measurements (A7)
# ---------------------------------------------------------------------------


class StarSensorVectors(MeasurementModel):
    """Star-sensor vector measurements ``C_S,i = A(q) C_I,i + υ_i`` (A7) for i = 1..k.

    Parameters
    ----------
    references : array_like, shape (k, 3)
        Reference unit vectors in the orbital frame; at least two, not parallel.
    sigma : float
        Standard deviation of each component of υ (R = σ² I per vector;
        paper 002: R = 1e-10 I₃, σ = 1e-5).
    """

    def __init__(self, references, sigma):
        refs = as_matrix("references", references, (None, 3))
        norms = np.linalg.norm(refs, axis=1)
        if refs.shape[0] < 2 or np.any(norms == 0):
            raise InputError(f"references must hold at least two non-zero vectors; got shape {refs.shape}")
        refs = refs / norms[:, None]
        crosses = [np.linalg.norm(np.cross(refs[i], refs[j])) for i in range(len(refs)) for j in range(i + 1, len(refs))]
        if max(crosses) < 1e-6:
            raise InputError("references must contain two non-parallel vectors: the attitude is not observable otherwise")
        self.sigma = as_positive("sigma", sigma)
        refs.setflags(write=False)
        self.references = refs
        k = refs.shape[0]
        # A(q) r_i is quadratic in q: vec(q qᵀ) @ _body (16, 3k); [b×] is linear in b: b @ _hmap (3k, 9k)
        self._body = np.einsum("abkl,ib->klia", _ATT, refs).reshape(16, 3 * k)
        self._hmap = np.zeros((3 * k, 9 * k))
        for i in range(k):
            self._hmap[3 * i:3 * i + 3, 9 * i:9 * i + 9] = _CROSS_MAT
        labels = tuple(f"b{i + 1}_{c}" for i in range(k) for c in "xyz")
        super().__init__(10, self.sigma * np.eye(3 * k), labels, ("-",) * (3 * k))

    def body_vectors(self, x):
        """``A(q) C_I,i`` for a batch, shape (..., k, 3)."""
        b = self.function(x)
        return b.reshape(b.shape[:-1] + (-1, 3))

    def function(self, x):
        x = self.check_state(x)
        q = x[..., QUAT]
        return _rows(_outer16(q, q), self._body)

    def jacobian(self, x):
        """``∂h/∂x`` with respect to the 10 stored components, shape (..., 3k, 10) (zero for ω, T)."""
        x = self.check_state(x)
        e, q4 = x[..., :3], x[..., 3]
        k = self.references.shape[0]
        out = np.zeros(x.shape[:-1] + (3 * k, 10))
        eye = np.eye(3)
        for i, r in enumerate(self.references):
            er = e @ r
            de = (-2.0 * r[:, None] * e[..., None, :] + 2.0 * er[..., None, None] * eye
                  + 2.0 * e[..., :, None] * r[None, :] + 2.0 * q4[..., None, None] * cross_matrix(r))
            dq4 = 2.0 * q4[..., None] * r - 2.0 * np.cross(e, r)
            out[..., 3 * i:3 * i + 3, :3] = de
            out[..., 3 * i:3 * i + 3, 3] = dq4
        return out

    def error_jacobian(self, x):
        """``∂h/∂(δθ, δω, δT)`` at a batch of estimates: blocks ``[b̂_i×]``, shape (..., 3k, 9)."""
        return self.error_jacobian_at(self.function(x))

    def error_jacobian_at(self, b):
        """:meth:`error_jacobian` from the predicted reading ``b = h(x̂)`` (..., 3k) already computed."""
        m = b.shape[-1]
        out = np.zeros(b.shape[:-1] + (m, 9))
        out[..., :, :3] = _rows(b, self._hmap).reshape(b.shape[:-1] + (m, 3))
        return out
