"""H∞ norms of discrete systems, the filtering error system (13)–(15), and
the independent checks that certify a synthesized filter.

Nothing here trusts an SDP solver. The numbers a filter is judged by are

* the H∞ norm of the error system (13)–(15) at sampled uncertainties,
  computed with SLICOT ``ab13dd`` (through :func:`control.linfnorm`) after an
  explicit Schur-stability check, and cross-checked in the tests by an
  independent implementation (:func:`hinf_norm_bisection`, the
  Boyd–Balakrishnan–Bruinsma–Steinbuch iteration on the discrete symplectic
  pencil) and by a dense frequency grid (:func:`hinf_norm_grid`);
* the level γ at which an LMI, evaluated in float64 at given variables, is
  negative definite (:func:`schur_gamma`, :func:`certify_negative_definite`):
  a rounding-aware eigenvalue test, no solver involved.

Frequencies are in rad/s when the sampling time ``dt`` is a number, in
rad/sample when ``dt`` is ``True`` (unspecified), as in python-control.
"""

import warnings
from dataclasses import dataclass

import control
import cvxpy as cp
import numpy as np
import scipy.linalg
import scipy.optimize

from .exceptions import InputError
from .validation import as_matrix, as_positive

__all__ = [
    "error_system_matrices",
    "error_system",
    "spectral_radius",
    "frequency_response_sigma",
    "frequency_grid",
    "hinf_norm",
    "hinf_norm_bisection",
    "hinf_norm_grid",
    "channel_norms",
    "WorstCase",
    "worst_case_norm",
    "schur_gamma",
    "certify_negative_definite",
    "LMICertificate",
    "brl_matrix",
    "robust_bounded_real_lmi",
]

#: Relative tolerance of the slycot norm (ab13dd).
NORM_TOL = 1e-10


def _dt_value(dt):
    """Sampling time as python-control wants it: True or a positive float."""
    if dt is True or dt is None:
        return True
    return as_positive("dt", dt)


def _dt_seconds(dt):
    return 1.0 if dt is True else float(dt)


def error_system_matrices(A, B, C, D, L, A_F, B_F, C_F):
    """State-space matrices of the filtering error system ε_d, (13)–(14).

    Parameters
    ----------
    A : array_like, shape (n, n)
        Plant matrix, possibly perturbed (``A + ΔA``, (14a)).
    B : array_like, shape (n, p)
        Process-noise matrix.
    C : array_like, shape (m, n)
        Measurement matrix.
    D : array_like, shape (m, q)
        Measurement-noise matrix.
    L : array_like, shape (l, n)
        Estimated signal ``z = L x``.
    A_F, B_F, C_F : array_like, shapes (nf, nf), (nf, m), (l, nf)
        The filter (12).

    Returns
    -------
    Abar : ndarray, shape (n + nf, n + nf)
        ``[[A, 0], [B_F C, A_F]]`` (14a).
    Bbar : ndarray, shape (n + nf, p + q)
        ``[[B, 0], [0, B_F D]]`` (14b); the input is ``τ = [w; v]``.
    Cbar : ndarray, shape (l, n + nf)
        ``[L, −C_F]`` (14c); the output is ``e = z − z_f``.
    """
    A = as_matrix("A", A)
    n = A.shape[0]
    if A.shape != (n, n):
        raise InputError(f"A must be square; got shape {A.shape}")
    B = as_matrix("B", B, (n, None))
    C = as_matrix("C", C, (None, n))
    m = C.shape[0]
    D = as_matrix("D", D, (m, None))
    L = as_matrix("L", L, (None, n))
    A_F = as_matrix("A_F", A_F)
    nf = A_F.shape[0]
    if A_F.shape != (nf, nf):
        raise InputError(f"A_F must be square; got shape {A_F.shape}")
    B_F = as_matrix("B_F", B_F, (nf, m))
    C_F = as_matrix("C_F", C_F, (L.shape[0], nf))
    p, q = B.shape[1], D.shape[1]
    Abar = np.block([[A, np.zeros((n, nf))], [B_F @ C, A_F]])
    Bbar = np.block([[B, np.zeros((n, q))], [np.zeros((nf, p)), B_F @ D]])
    Cbar = np.hstack([L, -C_F])
    return Abar, Bbar, Cbar


def error_system(A, B, C, D, L, A_F, B_F, C_F, dt=True):
    """The error system ε_d of (13)–(15) as a discrete :class:`control.StateSpace`.

    Parameters are those of :func:`error_system_matrices`, plus

    dt : float or True, optional
        Sampling time, s (``True``: discrete with unspecified period).

    Returns
    -------
    control.StateSpace
        ``Ψ(z) = C̄ (zI − Ā)⁻¹ B̄`` (15), from ``τ = [w; v]`` (p + q inputs) to
        ``e = z − z_f`` (l outputs), no feedthrough.
    """
    Abar, Bbar, Cbar = error_system_matrices(A, B, C, D, L, A_F, B_F, C_F)
    return control.ss(Abar, Bbar, Cbar, np.zeros((Cbar.shape[0], Bbar.shape[1])), _dt_value(dt))


def spectral_radius(A):
    """Largest eigenvalue modulus of a square matrix (Schur stable iff < 1)."""
    A = np.asarray(A, dtype=float)
    if A.size == 0:
        return 0.0
    return float(np.max(np.abs(np.linalg.eigvals(A))))


def _ssdata(sys):
    if not isinstance(sys, control.StateSpace):
        raise InputError(f"sys must be a control.StateSpace; got {type(sys).__name__}")
    if not sys.isdtime():
        raise InputError("sys must be a discrete-time system (dt True or > 0)")
    return (np.asarray(sys.A, float), np.asarray(sys.B, float), np.asarray(sys.C, float), np.asarray(sys.D, float))


def frequency_response_sigma(sys, omega, all_values=False):
    """Singular values of ``G(e^{jωT})`` on a frequency grid.

    Parameters
    ----------
    sys : control.StateSpace
        Discrete system with sampling time T (``dt``; T = 1 if ``dt`` is True).
    omega : array_like, shape (k,)
        Frequencies, rad/s (rad/sample when ``dt`` is True).
    all_values : bool, optional
        Return every singular value instead of the largest.

    Returns
    -------
    ndarray, shape (k,) or (k, min(l, p + q))
        ``σ_max(G(e^{jωT}))`` (or all singular values, descending).
    """
    A, B, C, D = _ssdata(sys)
    theta = np.asarray(omega, dtype=float) * _dt_seconds(sys.dt)
    z = np.exp(1j * theta)
    n = A.shape[0]
    M = z[:, None, None] * np.eye(n)[None] - A[None]
    X = np.linalg.solve(M, np.broadcast_to(B, (len(z),) + B.shape))
    G = C[None] @ X + D[None]
    s = np.linalg.svd(G, compute_uv=False)
    return s if all_values else s[:, 0]


def frequency_grid(sys, points=2000, lowest=1e-7):
    """A frequency grid for a discrete system, dense near its pole angles.

    Parameters
    ----------
    sys : control.StateSpace
        Discrete system.
    points : int, optional
        Number of log-spaced points between ``lowest`` and π (rad/sample).
    lowest : float, optional
        Lowest normalized frequency, rad/sample.

    Returns
    -------
    ndarray
        Frequencies, rad/s (rad/sample when ``dt`` is True), sorted, starting at 0
        and ending at the Nyquist frequency π/T.
    """
    A, _, _, _ = _ssdata(sys)
    theta = [np.array([0.0, np.pi]), np.logspace(np.log10(lowest), np.log10(np.pi), points)]
    poles = np.linalg.eigvals(A) if A.size else np.array([])
    for p in poles:
        ang = abs(np.angle(p))
        width = max(1.0 - abs(p), 1e-9)
        theta.append(np.clip(ang + width * np.linspace(-4, 4, 41), 0.0, np.pi))
    theta = np.unique(np.concatenate(theta))
    return theta / _dt_seconds(sys.dt)


def hinf_norm(sys, tol=NORM_TOL, return_peak=False):
    """H∞ norm of a discrete system by SLICOT ``ab13dd`` (python-control).

    Parameters
    ----------
    sys : control.StateSpace
        Discrete system.
    tol : float, optional
        Relative accuracy asked of ab13dd.
    return_peak : bool, optional
        Also return the peak frequency.

    Returns
    -------
    norm : float
        ``sup_ω σ_max(G(e^{jωT}))``; ``inf`` when the system is not Schur
        stable (spectral radius ≥ 1), since then the H∞ norm is infinite.
    peak : float
        Frequency of the peak, rad/s (rad/sample when ``dt`` is True); only
        with ``return_peak``.

    Notes
    -----
    :func:`control.linfnorm` computes the L∞ norm, which equals the H∞ norm
    only for stable systems; stability is checked here first. (``control.norm``
    with ``p='inf'`` would also call ab13dd, but it reports ``inf`` for poles
    with ``|p|`` within 1e-5 of 1, which the lightly damped plant of this
    paper approaches.)
    """
    A, B, C, D = _ssdata(sys)
    if spectral_radius(A) >= 1.0:
        return (float("inf"), float("nan")) if return_peak else float("inf")
    if A.shape[0] == 0:
        g, f = float(np.linalg.norm(D, 2)), 0.0
    else:
        g, f = control.linfnorm(sys, tol)
    g, f = float(g), float(f)
    return (g, f) if return_peak else g


def _symplectic_pencil(A, B, C, D, gamma):
    """Pencil ``M − zN`` whose finite eigenvalues on |z| = 1 are the
    frequencies where γ is a singular value of ``G(z)``.

    Unknowns ``[x; q; u]``: ``z x = A x + B u``,
    ``q = z (Aᵀ q + Cᵀ(C x + D u))`` (the adjoint ``G(1/z)ᵀ``) and
    ``Bᵀ q + Dᵀ(C x + D u) = γ² u``.
    """
    n, m = B.shape
    M = np.block(
        [
            [A, np.zeros((n, n)), B],
            [np.zeros((n, n)), np.eye(n), np.zeros((n, m))],
            [D.T @ C, B.T, D.T @ D - gamma**2 * np.eye(m)],
        ]
    )
    N = np.block(
        [
            [np.eye(n), np.zeros((n, n)), np.zeros((n, m))],
            [C.T @ C, A.T, C.T @ D],
            [np.zeros((m, 2 * n + m))],
        ]
    )
    return M, N


def _sigma_at(A, B, C, D, theta):
    z = np.exp(1j * np.atleast_1d(theta))
    n = A.shape[0]
    X = np.linalg.solve(z[:, None, None] * np.eye(n)[None] - A[None], np.broadcast_to(B, (len(z),) + B.shape))
    return np.linalg.svd(C[None] @ X + D[None], compute_uv=False)[:, 0]


def hinf_norm_bisection(sys, tol=1e-10, max_iter=100, unit_tol=1e-7, return_peak=False):
    """H∞ norm by the Boyd–Balakrishnan / Bruinsma–Steinbuch iteration.

    An implementation independent of SLICOT, used to cross-check
    :func:`hinf_norm`. Starting from the largest singular value at a few
    test frequencies (0, π and the pole angles), each step finds the
    frequencies where the current level γ is a singular value of
    ``G(e^{jθ})`` (the unit-circle eigenvalues of a symplectic pencil) and
    moves γ to the largest singular value at the midpoints of those
    frequencies. It stops when the pencil has no unit-circle eigenvalue at
    ``(1 + 2 tol) γ``.

    Parameters
    ----------
    sys : control.StateSpace
        Discrete system.
    tol : float, optional
        Relative accuracy.
    max_iter : int, optional
    unit_tol : float, optional
        Distance from the unit circle below which an eigenvalue counts as on it.
    return_peak : bool, optional
        Also return the peak frequency (rad/s, rad/sample when ``dt`` is True).

    Returns
    -------
    norm : float
        ``inf`` if the system is not Schur stable.
    peak : float
        Only with ``return_peak``.
    """
    A, B, C, D = _ssdata(sys)
    T = _dt_seconds(sys.dt)
    if spectral_radius(A) >= 1.0:
        return (float("inf"), float("nan")) if return_peak else float("inf")
    if A.shape[0] == 0:
        g = float(np.linalg.norm(D, 2))
        return (g, 0.0) if return_peak else g
    test = np.concatenate([[0.0, np.pi], np.abs(np.angle(np.linalg.eigvals(A)))])
    sig = _sigma_at(A, B, C, D, test)
    k = int(np.argmax(sig))
    lower, peak = float(sig[k]), float(test[k])
    for _ in range(max_iter):
        if lower == 0.0:
            break
        gamma = (1.0 + 2.0 * tol) * lower
        M, N = _symplectic_pencil(A, B, C, D, gamma)
        z = scipy.linalg.eigvals(M, N)
        z = z[np.isfinite(z)]
        on = z[np.abs(np.abs(z) - 1.0) < unit_tol]
        theta = np.unique(np.round(np.abs(np.angle(on)), 14))
        if theta.size == 0:
            break
        # σ_max exceeds γ between some consecutive crossings; 0 and π close the outer intervals
        ends = np.unique(np.concatenate([[0.0], theta, [np.pi]]))
        mids = np.concatenate([0.5 * (ends[:-1] + ends[1:]), [0.0, np.pi]])
        sig = _sigma_at(A, B, C, D, mids)
        k = int(np.argmax(sig))
        if sig[k] <= lower * (1.0 + tol):
            break
        lower, peak = float(sig[k]), float(mids[k])
    return (lower, peak / T) if return_peak else lower


def hinf_norm_grid(sys, points=4000, refine=True):
    """Lower bound of the H∞ norm from a dense frequency grid.

    Parameters
    ----------
    sys : control.StateSpace
        Discrete system.
    points : int, optional
        Log-spaced points of :func:`frequency_grid`.
    refine : bool, optional
        Polish the grid maximum by a bounded scalar search between its
        neighbours.

    Returns
    -------
    float
        ``max σ_max(G(e^{jωT}))`` over the grid (a lower bound of the norm);
        ``inf`` if the system is not Schur stable.
    """
    A, B, C, D = _ssdata(sys)
    if spectral_radius(A) >= 1.0:
        return float("inf")
    omega = frequency_grid(sys, points)
    sig = frequency_response_sigma(sys, omega)
    k = int(np.argmax(sig))
    best = float(sig[k])
    if refine and 0 < k < len(omega) - 1:
        T = _dt_seconds(sys.dt)
        res = scipy.optimize.minimize_scalar(
            lambda th: -_sigma_at(A, B, C, D, th)[0],
            bounds=(omega[k - 1] * T, omega[k + 1] * T),
            method="bounded",
            options={"xatol": 1e-12},
        )
        best = max(best, float(-res.fun))
    return best


def channel_norms(sys, inputs, outputs, tol=NORM_TOL):
    """H∞ norms (and peak frequencies) of input/output blocks of a system.

    Parameters
    ----------
    sys : control.StateSpace
        Discrete system.
    inputs : dict of str to index
        Named input groups, e.g. ``{"w": slice(0, 6), "v": slice(6, 9)}``.
    outputs : dict of str to index
        Named output groups.

    Returns
    -------
    dict
        ``{(input_name, output_name): (norm, peak_frequency)}`` for every
        pair, frequencies in rad/s (rad/sample when ``dt`` is True).
    """
    A, B, C, D = _ssdata(sys)
    out = {}
    for iname, ii in inputs.items():
        for oname, oo in outputs.items():
            part = control.ss(A, B[:, ii], C[oo, :], D[oo, :][:, ii], sys.dt)
            out[(iname, oname)] = hinf_norm(part, tol, return_peak=True)
    return out


@dataclass(frozen=True, eq=False)
class WorstCase:
    """H∞ norms of the error system at sampled uncertainties.

    Attributes
    ----------
    norms : ndarray, shape (k,)
        ``‖Ψ‖∞`` at each sample (``inf`` where the error system is unstable).
    spectral_radii : ndarray, shape (k,)
        Spectral radius of ``Ā`` at each sample.
    peak_frequencies : ndarray, shape (k,)
        Peak frequency at each sample, rad/s (rad/sample when dt is True).
    index : int
        Index of the worst sample.
    """

    norms: np.ndarray
    spectral_radii: np.ndarray
    peak_frequencies: np.ndarray
    index: int

    @property
    def norm(self):
        """Largest sampled norm (``inf`` if any sample is unstable)."""
        return float(self.norms[self.index])

    @property
    def stable(self):
        """Whether the error system is Schur stable at every sample."""
        return bool(np.all(self.spectral_radii < 1.0))


def worst_case_norm(system, A_F, B_F, C_F, samples=None, dt=None, tol=NORM_TOL):
    """Worst sampled H∞ norm of the error system (13)–(15) of a filter.

    Parameters
    ----------
    system : hinfnav.models.UncertainSystem
        The uncertain plant ψ_d (9)–(11), with ``A + H F E``.
    A_F, B_F, C_F : array_like
        The filter (12).
    samples : sequence of array_like, optional
        Uncertainty matrices F (shape (r, r) of ``system.H``/``system.E``); a
        ``None`` entry means F = 0. Default: F = 0 only.
    dt : float or True, optional
        Sampling time of the returned frequencies; default ``system.dt``.
    tol : float, optional
        Relative accuracy of each norm.

    Returns
    -------
    WorstCase
    """
    if samples is None:
        samples = [None]
    dt = system.dt if dt is None else _dt_value(dt)
    norms, radii, peaks = [], [], []
    for F in samples:
        Ap = system.A if F is None else system.perturbed_A(F)
        sys = error_system(Ap, system.B, system.C, system.D, system.L, A_F, B_F, C_F, dt)
        radii.append(spectral_radius(sys.A))
        g, f = hinf_norm(sys, tol, return_peak=True)
        norms.append(g)
        peaks.append(f)
    norms = np.array(norms)
    if len(norms) == 0:
        raise InputError("samples must contain at least one uncertainty matrix F")
    return WorstCase(norms, np.array(radii), np.array(peaks), int(np.argmax(norms)))


def _sym(M):
    return 0.5 * (M + M.T)


def certify_negative_definite(M, rel_tol=1e-13):
    """Rounding-aware test that a symmetric float64 matrix is negative definite.

    Parameters
    ----------
    M : array_like, shape (N, N)
        Matrix as evaluated in float64 (its symmetric part is tested).
    rel_tol : float, optional
        Required margin relative to ``‖M‖₂``. The computed eigenvalues of a
        symmetric matrix are within about ``N · 1.1e-16 · ‖M‖₂`` of the exact
        ones (LAPACK ``syevd`` backward stability), and forming M in float64
        adds an error of the same order; for N up to ~100 the default keeps a
        safety factor of about 10 over both, so a largest eigenvalue below
        ``−rel_tol ‖M‖₂`` is negative for the exact matrix too.

    Returns
    -------
    ok : bool
    max_eig : float
        Largest eigenvalue.
    """
    M = _sym(np.asarray(M, dtype=float))
    eig = np.linalg.eigvalsh(M)
    scale = max(np.max(np.abs(eig)), np.finfo(float).tiny)
    return bool(eig[-1] < -rel_tol * scale), float(eig[-1])


def schur_gamma(M0, gamma_index, rel_tol=1e-13):
    """Smallest γ for which ``M0 − γ² P_G`` is negative definite.

    ``P_G`` is the coordinate projection onto the rows/columns
    ``gamma_index`` (the ``−γ² I`` blocks of an LMI such as (17) or (20)).
    By the Schur complement (Lemma 3), ``M(γ) < 0`` iff ``M_OO < 0`` and
    ``γ² > λ_max(M0_GG + M_GO (−M_OO)⁻¹ M_OG)``, O being the other indices.
    The value is then confirmed by a direct eigenvalue test of ``M(γ)`` at a
    level raised by the smallest relative step (1e-10, 1e-9, ..., 1e-3) that
    passes :func:`certify_negative_definite`.

    Parameters
    ----------
    M0 : array_like, shape (N, N)
        The LMI matrix evaluated with γ² = 0.
    gamma_index : array_like of int
        Indices carrying ``−γ²``.
    rel_tol : float, optional
        Margin of the eigenvalue tests (see :func:`certify_negative_definite`).

    Returns
    -------
    gamma : float
        Certified level (``inf`` if no level makes the matrix negative
        definite in float64, i.e. ``M_OO`` is not negative definite).
    info : dict
        ``max_eig_OO`` (largest eigenvalue of ``M_OO``), ``gamma_schur``
        (the Schur-complement value before the confirming step), ``step``.
    """
    M0 = _sym(np.asarray(M0, dtype=float))
    N = M0.shape[0]
    G = np.asarray(gamma_index, dtype=int)
    O = np.setdiff1d(np.arange(N), G)
    MOO = M0[np.ix_(O, O)]
    ok, max_oo = certify_negative_definite(MOO, rel_tol)
    info = {"max_eig_OO": max_oo, "gamma_schur": float("inf"), "step": float("nan")}
    if not ok:
        return float("inf"), info
    try:
        Lc = np.linalg.cholesky(-MOO)
    except np.linalg.LinAlgError:
        return float("inf"), info
    X = scipy.linalg.solve_triangular(Lc, M0[np.ix_(O, G)], lower=True)
    Q = _sym(M0[np.ix_(G, G)] + X.T @ X)
    g2 = max(float(np.linalg.eigvalsh(Q)[-1]), 0.0)
    info["gamma_schur"] = float(np.sqrt(g2))
    diag = np.zeros(N)
    diag[G] = 1.0
    for step in 10.0 ** np.arange(-12.0, -2.0, 0.5):
        level = g2 * (1.0 + step) + step * np.finfo(float).eps ** 0.5
        if certify_negative_definite(M0 - level * np.diag(diag), rel_tol)[0]:
            info["step"] = float(step)
            return float(np.sqrt(level)), info
    return float("inf"), info


@dataclass(frozen=True, eq=False)
class LMICertificate:
    """Result of :func:`robust_bounded_real_lmi`.

    Attributes
    ----------
    gamma : float
        Level certified by the eigenvalue test at the returned ``P``, ``lam``
        (``inf`` if none).
    lmi_gamma : float
        Level the solver reached.
    P : ndarray, shape (N, N)
        Lyapunov matrix of Lemma 1 (in the caller's coordinates).
    lam : float
        Multiplier λ = 1/ε of Lemma 2 (0 without uncertainty).
    status : str
        Solver status.
    """

    gamma: float
    lmi_gamma: float
    P: np.ndarray
    lam: float
    status: str


def brl_matrix(Abar, Bbar, Cbar, P, gamma2, Hbar=None, Ebar=None, lam=0.0):
    """The matrix of the bounded real lemma (17), or of its robust form (26).

    Without ``Hbar``: Lemma 1, (17)::

        [ −P   PĀ    PB̄     0  ]
        [  *  −P     0      C̄ᵀ ]
        [  *   *    −γ²I    0  ]
        [  *   *     *     −I  ]

    With ``Hbar``, ``Ebar`` and ``lam`` = λ = 1/ε: the same with
    ``−P + λĒᵀĒ`` in block (2, 2) and a last block row/column
    ``[PH̄; 0; 0; 0; −λI]`` — (26), the form Lemmas 2–3 turn (17) into for
    ``Ā + H̄FĒ`` with ``FᵀF ≤ I``.

    Parameters
    ----------
    Abar : ndarray, shape (N, N)
    Bbar : ndarray, shape (N, k)
    Cbar : ndarray, shape (l, N)
    P : ndarray, shape (N, N)
    gamma2 : float
        γ².
    Hbar : ndarray, shape (N, r1), optional
    Ebar : ndarray, shape (r2, N), optional
    lam : float, optional

    Returns
    -------
    ndarray, shape (2N + k + l [+ r1],) * 2
        Negative definite iff the bound holds with this P (and λ).
    """
    return _brl_blocks(
        np.asarray(Abar, float), np.asarray(Bbar, float), np.asarray(Cbar, float),
        None if Hbar is None else np.asarray(Hbar, float), None if Ebar is None else np.asarray(Ebar, float),
        np.asarray(P, float), float(lam), float(gamma2), np.block,
    )


def _brl_blocks(Abar, Bbar, Cbar, Hbar, Ebar, P, lam, g, lib):
    """LMI (17), with the uncertainty eliminated by Lemmas 2–3 when Hbar is given."""
    N = Abar.shape[0]
    nin = Bbar.shape[1]
    nout = Cbar.shape[0]
    Z = np.zeros
    rows = [
        [-P, P @ Abar, P @ Bbar, Z((N, nout))],
        [(P @ Abar).T, -P, Z((N, nin)), Cbar.T],
        [(P @ Bbar).T, Z((nin, N)), -g * np.eye(nin), Z((nin, nout))],
        [Z((nout, N)), Cbar, Z((nout, nin)), -np.eye(nout)],
    ]
    if Hbar is not None:
        r1, r2 = Hbar.shape[1], Ebar.shape[0]
        rows[1][1] = -P + lam * (Ebar.T @ Ebar)
        extra = [P @ Hbar, Z((N, r1)), Z((nin, r1)), Z((nout, r1))]
        for row, blk in zip(rows, extra):
            row.append(blk)
        rows.append([(P @ Hbar).T, Z((r1, N)), Z((r1, nin)), Z((r1, nout)), -lam * np.eye(r1)])
    return lib(rows)


def robust_bounded_real_lmi(Abar, Bbar, Cbar, Hbar=None, Ebar=None, solver=None, margin=1e-9):
    """Certified upper bound of ``‖C̄(zI − Ā − H̄FĒ)⁻¹B̄‖∞`` over ``FᵀF ≤ I``.

    Minimizes γ² subject to the bounded real lemma (Lemma 1, (17)), with the
    uncertainty ``Ā + H̄ F Ē`` removed by Lemma 2 and the Schur complement
    (Lemma 3), exactly as in the proof of Theorem 1 but for a fixed filter::

        [ −P   PĀ             PB̄     0    PH̄  ]
        [  *  −P + λĒᵀĒ       0      C̄ᵀ   0   ]
        [  *   *             −γ²I    0    0   ]  < 0
        [  *   *              *     −I    0   ]
        [  *   *              *      *   −λI  ]

    Without ``Hbar`` it is Lemma 1 alone (the nominal norm, up to solver
    accuracy). The returned ``gamma`` is certified by :func:`schur_gamma` at
    the solver's ``P`` and ``λ``, not taken from the solver.

    Parameters
    ----------
    Abar : array_like, shape (N, N)
    Bbar : array_like, shape (N, k)
    Cbar : array_like, shape (l, N)
    Hbar : array_like, shape (N, r1), optional
    Ebar : array_like, shape (r2, N), optional
    solver : str, optional
        cvxpy solver name; default: Clarabel and CVXOPT, the smaller
        certified bound is kept.
    margin : float, optional
        Strictness margin: the LMI is imposed as ``≤ −margin·I``.

    Returns
    -------
    LMICertificate
    """
    Abar = as_matrix("Abar", Abar)
    N = Abar.shape[0]
    Bbar = as_matrix("Bbar", Bbar, (N, None))
    Cbar = as_matrix("Cbar", Cbar, (None, N))
    if (Hbar is None) != (Ebar is None):
        raise InputError("Hbar and Ebar must be given together")
    if Hbar is not None:
        Hbar = as_matrix("Hbar", Hbar, (N, None))
        Ebar = as_matrix("Ebar", Ebar, (None, N))
    solvers = ("CLARABEL", "CVXOPT") if solver is None else (solver,)
    best = None
    for slv in solvers:
        cert = _robust_brl_once(Abar, Bbar, Cbar, Hbar, Ebar, slv, margin)
        if best is None or cert.gamma < best.gamma:
            best = cert
    return best


def _robust_brl_once(Abar, Bbar, Cbar, Hbar, Ebar, solver, margin):
    N = Abar.shape[0]
    P = cp.Variable((N, N), symmetric=True)
    lam = cp.Variable() if Hbar is not None else 0.0
    g = cp.Variable()
    M = _brl_blocks(Abar, Bbar, Cbar, Hbar, Ebar, P, lam, g, cp.bmat)
    size = M.shape[0]
    prob = cp.Problem(cp.Minimize(g), [0.5 * (M + M.T) << -margin * np.eye(size)])
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            prob.solve(solver=solver)
    except (cp.error.SolverError, ArithmeticError, ValueError, np.linalg.LinAlgError) as exc:
        return LMICertificate(float("inf"), float("nan"), None, float("nan"), f"{solver}: solver error ({exc})")
    if P.value is None:
        return LMICertificate(float("inf"), float("nan"), None, float("nan"), f"{solver}: {prob.status}")
    Pv = _sym(P.value)
    lamv = float(lam.value) if Hbar is not None else 0.0
    M0 = _brl_blocks(Abar, Bbar, Cbar, Hbar, Ebar, Pv, lamv, 0.0, np.block)
    nin = Bbar.shape[1]
    gamma, _ = schur_gamma(M0, np.arange(2 * N, 2 * N + nin))
    return LMICertificate(gamma, float(np.sqrt(max(g.value, 0.0))), Pv, lamv, f"{solver}: {prob.status}")
