"""The compiled backend of :meth:`Estimator.estimate <hinfnav.estimators.base.Estimator.estimate>`: one interface.

``est.estimate(y, u, xhat0, P0, backend=...)`` chooses how the batch runs:

* ``"numpy"`` (the default): the NumPy step loop, the reference of every
  number the workbook reports;
* ``"numba"``: a compiled kernel (:mod:`hinfnav.estimators.compiled_kernels`)
  that runs every run over every step in one call. It exists for the filters
  listed by :func:`kernel_status` on a linear system with a constant
  measurement matrix (``y = H x + D v``), a constant R, ``missing="refuse"``
  and no diagnostics requested; for any other estimator or option the request
  raises an :class:`~hinfnav.core.exceptions.InputError` that says why;
* ``"auto"``: the kernel where one exists, the NumPy path otherwise.

The kernels give the NumPy path's estimates and covariances to 1e-10 relative
(``tests/test_compiled.py`` checks every registered estimator); the
equations are the same, only the order of the floating-point sums and, in the
Huber M-estimation, the route to the same minimiser differ. What does not
depend on the data is computed once for the batch: the gains of the Kalman,
sigma-point (on a linear model its covariances do not depend on the state)
and recursive H∞ filters; the runs with a covariance each (strong tracking,
Huber) advance in blocks of eight, every product's innermost loop over the
block (:mod:`hinfnav.estimators.compiled_lanes`). A kernel that
meets a failed factorisation or a non-finite number hands the batch back to
the NumPy path, which raises its own error (or flags, as it is told).

numba is imported only when a kernel is first asked for (importing it costs
about 1 s); the kernels are compiled with ``cache=True`` (numba's on-disk
cache, in ``__pycache__`` beside the kernels' module, or ``NUMBA_CACHE_DIR``),
so the compilation is paid once per installation: the first call of the five
filters of the README's speed table in a new process costs about 32 s of CPU
from an empty cache and 0.4 s from a filled one (``python
benchmarks/speed_table.py --compile-cost``, on the README's machine under
load).
"""

from __future__ import annotations

import importlib
import importlib.util
from typing import Any

import numpy as np

from ..core.exceptions import InputError
from ..core.validation import as_choice
from ..systems.linear import LinearSystem
from ..systems.measurements import MeasurementModel

__all__ = ["BACKENDS", "KERNEL_CLASSES", "kernel_status", "numba_available", "run_compiled", "select_backend"]

#: What ``Estimator.estimate(backend=...)`` accepts.
BACKENDS = ("numpy", "numba", "auto")

#: The estimator classes (of :mod:`hinfnav.estimators`, exactly: a subclass may change a hook) that have a kernel.
KERNEL_CLASSES = {
    "ExtendedKalmanFilter": "kalman",
    "StrongTrackingEKF": "kalman",
    "HuberFilter": "kalman",
    "AugmentedInputKF": "augmented",
    "AugmentedInputSTKF": "augmented",
    "AugmentedInputHuberSTKF": "augmented",
    "SigmaPointFilter": "sigma_point",
    "RecursiveHInfinityFilter": "recursive_hinf",
}

_KERNELS = {}


def _kernel_steady_tol(est):
    """The recursive H∞ filter's freeze tolerance for the kernel: ``steady_tol`` (rule F2 of
    :func:`~hinfnav.estimators.steady.freeze_gain`), or −1 (never: a norm is never below a negative bound)."""
    return -1.0 if est.steady_tol is None else float(est.steady_tol)


def numba_available() -> bool:
    """True when numba can be imported (without importing it)."""
    return importlib.util.find_spec("numba") is not None


def _kernels():
    """The kernels' module, imported (with numba) on the first request."""
    if "module" not in _KERNELS:
        _KERNELS["module"] = importlib.import_module(f"{__package__}.compiled_kernels")
    return _KERNELS["module"]


def _kind(est):
    cls = type(est)
    if not cls.__module__.startswith(f"{__package__}.") or cls.__name__ not in KERNEL_CLASSES:
        return None
    return KERNEL_CLASSES[cls.__name__]


def _mro_names(est):
    return {c.__name__ for c in type(est).__mro__}


def _linear_measurement(est):
    meas = est.measurement
    if not getattr(meas, "linear", False) or getattr(meas, "H", None) is None:
        return "its measurement is not linear (a kernel needs y = H x + D v)"
    if type(meas).residual is not MeasurementModel.residual or hasattr(meas, "convert"):
        return "its measurement residual is not y - H x"
    if getattr(est, "R_of_reading", None) is not None or getattr(est, "R", None) is None:
        return "its R depends on the reading"
    return None


def kernel_status(est: Any) -> str | None:
    """Why ``est`` has no compiled kernel, or None when it has one (diagnostics aside)."""
    kind = _kind(est)
    if kind is None:
        return (f"no kernel for {type(est).__name__} (kernels: {', '.join(sorted(KERNEL_CLASSES))}, exactly these "
                "classes of hinfnav.estimators)")
    if est.missing != "refuse":
        return "missing='skip' runs on the NumPy path only"
    system = est.system
    if not isinstance(system, LinearSystem) or type(system).propagate is not LinearSystem.propagate:
        return "its system is not a hinfnav LinearSystem"
    reason = _linear_measurement(est)
    if reason:
        return reason
    if kind == "kalman" and est.nonlinear_dynamics:
        return "its dynamics are not linear"
    if kind == "augmented" and (not est.linear_model or np.ndim(est.Q) != 2):
        return "its model is not linear or its input noise is given per run"
    if kind == "sigma_point" and est.error_coordinates:
        return "its state has its own error coordinates (a quaternion)"
    return None


def select_backend(est: Any, backend: str, diagnostics: set | None = frozenset()) -> str:
    """The backend that runs ``est.estimate``: "numpy" or "numba" (see the module docstring).

    ``diagnostics`` is what :func:`hinfnav.estimators.base.history_keys` returns
    (None: all). Raises InputError naming ``backend`` when "numba" is asked for
    and no kernel fits.
    """
    backend = as_choice("backend", backend, BACKENDS)
    if backend == "numpy":
        return "numpy"
    reason = kernel_status(est)
    if reason is None and (diagnostics is None or diagnostics):
        reason = "diagnostics are computed on the NumPy path only (pass diagnostics=False)"
    if reason is None and not numba_available():
        reason = "numba is not installed (pip install numba==0.68.1)"
    if reason is None:
        return "numba"
    if backend == "auto":
        return "numpy"
    raise InputError(f"backend='numba' is not available for filter {est.name!r}: {reason}; use backend='numpy' "
                     "or 'auto'")


def _float(v):
    return np.array(v, dtype=float, order="C")  # a writable copy: one compiled specialization for every call


def _per_run(value, runs):
    return _float(np.broadcast_to(np.asarray(value, dtype=float), (runs,)))


def run_compiled(est: Any, y: np.ndarray, u: np.ndarray, xhat0: np.ndarray, P0: np.ndarray | None,
                 keep_covariance: bool | str) -> tuple[np.ndarray | None, np.ndarray | None]:
    """``(xhat, P history)`` of ``est`` on checked inputs by its kernel, or ``(None, None)`` to fall back.

    ``y`` (runs, n_samples, m), ``u`` (runs, n_samples, n_input) and ``xhat0``
    as :func:`~hinfnav.estimators.base.check_estimator_inputs` returns them.
    The P history is (runs, n_samples, n, n) (its diagonal with
    ``keep_covariance="diagonal"``, None with False), a read-only broadcast
    when the covariance is shared by every run (as on the NumPy path of the Kalman filters; the sigma-point
    filter's NumPy path returns a copy per run).
    """
    kern = _kernels()
    kind = _kind(est)
    runs, steps, _ = y.shape
    state = est.start(xhat0, P0, runs)  # the filter's own checks of P0 and its per-run parameters
    x0 = _float(state.x[0])
    P_start = _float(state.P if state.P.ndim == 2 else state.P[0])
    y = _float(y)
    u = _float(u) if u.shape[2] else np.zeros((runs, steps, 1))
    keep = {False: 0, "diagonal": 1, True: 2}[keep_covariance]
    use_input = bool(est.uses_input)
    H = _float(est.measurement.H)
    shared = False
    if kind in ("kalman", "augmented"):
        names = _mro_names(est)
        strong, huber = "StrongTracking" in names, "HuberCorrection" in names
        shared = bool(est.shares_covariance)
        if kind == "kalman":
            F, Qd, n_rep = est.F, est.Q, est.n_state
            G = est.Gamma if use_input else np.zeros((est.n_state, u.shape[2]))
        else:
            F, Qd, n_rep, use_input = est.Phi_a, est.Qd, est.n_state, False
            H = _float(est._H)
            G = np.zeros((F.shape[0], u.shape[2]))
        n = F.shape[0]
    elif kind == "sigma_point":
        F, G, n_rep, n = est.system.Phi, est.system.Gamma if use_input else None, est.n_state, est.n_state
        shared = True  # on a linear model the covariance recursion does not depend on the data
    else:
        F, G, n_rep, n = est.F, est.Gamma, est.n_state, est.n_state
        shared = True
    if G is None or G.shape[1] != u.shape[2]:
        G = np.zeros((n, u.shape[2]))
    xhat = np.empty((runs, steps, n_rep))
    p_runs = 1 if shared else runs
    Pdiag = np.empty((p_runs, steps, n_rep)) if keep == 1 else np.empty((1, 1, 1))
    Pfull = np.empty((p_runs, steps, n_rep, n_rep)) if keep == 2 else np.empty((1, 1, 1, 1))
    F, G = _float(F), _float(G)
    if kind in ("kalman", "augmented"):
        LRi = _float(est._LRi) if huber else np.eye(H.shape[0])
        rho = _per_run(est.rho, runs) if strong else np.ones(runs)
        beta = _per_run(est.beta, runs) if strong else np.ones(runs)
        a = _float(est.a) if strong else np.ones(n)
        ok = kern.kalman_batch(F, G, H, _float(Qd), _float(est.R), P_start, x0, y, u, use_input,
                               est.output == "filtered", bool(est.symmetric_posterior), huber, LRi,
                               float(getattr(est, "gamma", 1.0)), float(getattr(est, "tol", 1.0)),
                               int(getattr(est, "max_iter", 1)), strong, rho, beta, a, shared, n_rep, keep, xhat,
                               Pdiag, Pfull)
    elif kind == "sigma_point":
        ok = kern.sigma_point_batch(F, G, H, _float(est.Q), _float(est.R), P_start, x0, y, u, use_input,
                                    est.output == "filtered", _float(est.Wm), _float(est.Wc), float(est.scale),
                                    est.rule == "unscented", keep, xhat, Pdiag, Pfull)
    else:
        ok = kern.recursive_hinf_batch(F, G, H, _float(est.Q), _float(est._G), _float(est._HtRi), P_start, x0, y, u,
                                       use_input, _kernel_steady_tol(est), keep, xhat, Pdiag, Pfull)
    if not ok:
        return None, None
    P_hist = {0: None, 1: Pdiag, 2: Pfull}[keep]
    if P_hist is not None and shared:
        P_hist = P_hist[0]
        P_hist.setflags(write=False)
        P_hist = np.broadcast_to(P_hist, (runs,) + P_hist.shape)
    return xhat, P_hist
