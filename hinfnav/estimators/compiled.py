"""The compiled backend of :meth:`Estimator.estimate <hinfnav.estimators.base.Estimator.estimate>`: one interface.

``est.estimate(y, u, xhat0, P0, backend=...)`` chooses how the batch runs:

* ``"auto"`` (the default, or the environment variable ``HINFNAV_BACKEND``
  when it is set: :func:`default_backend`): the kernel where one exists, the
  NumPy path otherwise; :func:`why_numpy` says why a filter falls back (and
  the ``hinfnav.backend`` logger reports it at INFO level);
* ``"numpy"``: the NumPy step loop, the reference of every number the
  workbook reports;
* ``"numba"``: a compiled kernel (:mod:`hinfnav.estimators.compiled_kernels`)
  that runs every run over every step in one call. It exists for the filters
  that declare one (the class attribute ``compiled_kernel``, one of
  :data:`KERNELS`, set in the class's own body: a subclass that changes a hook
  does not inherit it) on a linear system with a constant measurement matrix
  (``y = H x + D v``), a constant R, ``missing="refuse"`` and no diagnostics
  requested; for any other estimator or option the request raises an
  :class:`~hinfnav.core.exceptions.InputError` that says why. The EKF and the
  sigma-point filter also run on a nonlinear model (or with ``missing="skip"``)
  whose dynamics and measurement declare compiled functions
  (``compiled_functions()``, :mod:`hinfnav.systems.compiled`): the kernels of
  :mod:`hinfnav.estimators.compiled_models`, routed by
  :mod:`hinfnav.estimators.compiled_nonlinear`.

A filter that declares a kernel gives it what it needs through public
attributes: the model (``F``/``Gamma``/``Q``/``R`` or the augmented ``Phi_a``,
``Qd``, ``H_augmented``), strong tracking's ``rho``/``beta``/``a`` (the
mixin's ``strong_tracking`` flag), Huber's ``gamma``/``tol``/``max_iter``
and ``whitening_matrix`` (the mixin's ``huber_correction`` flag), the
recursive H∞ filter's ``G_theta`` and ``HtRi``.

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

import contextlib
import importlib
import importlib.util
import logging
import os
from collections.abc import Iterator
from typing import Any

import numpy as np

from ..core.exceptions import InputError
from ..core.validation import as_choice
from ..systems.linear import LinearSystem
from ..systems.measurements import MeasurementModel
from .compiled_diagnostics import NIS_DIAGNOSTICS, nis_diagnostics
from .compiled_nonlinear import model_status, run_model_kernel, uses_model_route

__all__ = ["BACKEND_VARIABLE", "KERNELS", "default_backend", "kernel_status",
           "run_compiled", "select_backend", "use_backend", "why_numpy"]

#: What ``Estimator.estimate(backend=...)`` accepts.
BACKENDS = ("numpy", "numba", "auto")

#: The kernels a filter class may declare (its ``compiled_kernel`` attribute).
KERNELS = ("kalman", "augmented", "sigma_point", "recursive_hinf", "lti")

#: The environment variable that sets the backend of every ``estimate`` not given one (``python -m hinfnav
#: ... --backend`` sets it, so that worker processes inherit it).
BACKEND_VARIABLE = "HINFNAV_BACKEND"

_LOG = logging.getLogger("hinfnav.backend")

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


def default_backend() -> str:
    """The backend of an ``estimate`` called without one: ``$HINFNAV_BACKEND`` if set, else "auto"."""
    return as_choice(BACKEND_VARIABLE, os.environ.get(BACKEND_VARIABLE, "auto"), BACKENDS)


@contextlib.contextmanager
def use_backend(backend: str | None) -> Iterator[None]:
    """Within the block, every ``estimate`` called without a backend uses ``backend`` (None: leave it as it is).

    Sets :data:`BACKEND_VARIABLE` in the environment (so that worker processes
    started within the block inherit it) and restores it after.
    """
    if backend is None:
        yield
        return
    backend = as_choice("backend", backend, BACKENDS)
    old = os.environ.get(BACKEND_VARIABLE)
    os.environ[BACKEND_VARIABLE] = backend
    try:
        yield
    finally:
        if old is None:
            os.environ.pop(BACKEND_VARIABLE, None)
        else:
            os.environ[BACKEND_VARIABLE] = old


def _kind(est):
    """The kernel declared by the estimator's own class (``compiled_kernel`` in its body), or None."""
    kind = vars(type(est)).get("compiled_kernel")
    return kind if kind in KERNELS else None


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
    composed = getattr(est, "strategies", ())
    if composed:  # a filter composed with strategies (hinfnav.estimators.strategies): no kernel knows the combination
        return (f"its class {type(est).__name__} is composed with the {' and '.join(composed)} strategy "
                "(no compiled kernel for this combination)")
    kind = _kind(est)
    if kind is None:
        inherited = getattr(type(est), "compiled_kernel", None)
        return (f"no kernel for {type(est).__name__}" + (
            f" (its base class declares the {inherited!r} kernel; a subclass that changes a hook declares "
            "compiled_kernel itself to keep it)" if inherited else " (the class declares no compiled_kernel)"))
    if kind == "lti":
        if est.missing == "skip" and (not getattr(est.measurement, "linear", False)
                                      or getattr(est.measurement, "H", None) is None):
            return "missing='skip' replaces a missing reading by h(x̂): on the compiled path for a linear h only"
        return None
    if uses_model_route(est, kind):  # a nonlinear model or missing="skip": the kernels on the model's functions
        return model_status(est, kind)
    if est.missing != "refuse":
        return "missing='skip' runs on the NumPy path only (except for the LTI filter, the EKF and the sigma-point filter)"
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


def why_numpy(est: Any, diagnostics: set | bool | None = frozenset()) -> str | None:
    """Why ``backend="auto"`` runs ``est`` on the NumPy path, or None when it runs its kernel.

    ``diagnostics`` as :meth:`~hinfnav.estimators.base.Estimator.estimate`
    takes it (True/False or names) or as
    :func:`~hinfnav.estimators.base.history_keys` returns it (a set; None: all).
    """
    if diagnostics is True:
        diagnostics = None
    elif diagnostics is False:
        diagnostics = frozenset()
    reason = kernel_status(est)
    extra = None if diagnostics is None else set(diagnostics) - set(NIS_DIAGNOSTICS)
    if extra and getattr(est, "gate", None) is None:  # an ungated filter reports no gate diagnostics (a campaign
        extra = {name for name in extra if not name.startswith("gate_")}  # asks every filter for them)
    if reason is None and (extra is None or extra):
        reason = (f"diagnostics other than {', '.join(NIS_DIAGNOSTICS)} are computed on the NumPy path only (asked: "
                  f"{'all' if extra is None else ', '.join(sorted(extra))})")
    if reason is None and not numba_available():
        reason = "numba is not installed (pip install numba==0.68.1)"
    return reason


def select_backend(est: Any, backend: str | None, diagnostics: set | None = frozenset()) -> str:
    """The backend that runs ``est.estimate``: "numpy" or "numba" (see the module docstring).

    ``backend`` None: :func:`default_backend`. ``diagnostics`` is what
    :func:`hinfnav.estimators.base.history_keys` returns (None: all). Raises
    InputError naming ``backend`` when "numba" is asked for and no kernel fits.
    """
    backend = default_backend() if backend is None else as_choice("backend", backend, BACKENDS)
    if backend == "numpy":
        return "numpy"
    reason = why_numpy(est, diagnostics)
    if reason is None:
        return "numba"
    if backend == "auto":
        if _LOG.isEnabledFor(logging.INFO):
            _LOG.info("filter %r runs on the NumPy path: %s", getattr(est, "name", "?"), reason)
        return "numpy"
    raise InputError(f"backend='numba' is not available for filter {est.name!r}: {reason}; use backend='numpy' "
                     "or 'auto'")


def _float(v):
    return np.array(v, dtype=float, order="C")  # a writable copy: one compiled specialization for every call


def _per_run(value, runs):
    return _float(np.broadcast_to(np.asarray(value, dtype=float), (runs,)))


def run_compiled(est: Any, y: np.ndarray, u: np.ndarray, xhat0: np.ndarray, P0: np.ndarray | None,
                 keep_covariance: bool | str, diagnostics: set = frozenset()
                 ) -> tuple[np.ndarray | None, np.ndarray | None, dict]:
    """``(xhat, P history, diagnostics)`` of ``est`` on checked inputs by its kernel, or ``(None, None, {})`` to
    fall back.

    ``diagnostics``: names among :data:`~.compiled_diagnostics.NIS_DIAGNOSTICS`
    (computed from the kernel's histories by
    :func:`~.compiled_diagnostics.nis_diagnostics`).

    ``y`` (runs, n_samples, m), ``u`` (runs, n_samples, n_input) and ``xhat0``
    as :func:`~hinfnav.estimators.base.check_estimator_inputs` returns them.
    The P history is (runs, n_samples, n, n) (its diagonal with
    ``keep_covariance="diagonal"``, None with False), a read-only broadcast
    when the covariance is shared by every run (as on the NumPy path of the Kalman filters; the sigma-point
    filter's NumPy path returns a copy per run).
    """
    kind = _kind(est)
    if uses_model_route(est, kind):
        return run_model_kernel(est, kind, y, u, xhat0, P0, keep_covariance, diagnostics)
    kern = _kernels()
    runs, steps, _ = y.shape
    if kind == "lti":
        xhat = np.empty((runs, steps, est.n_state))
        use_input = bool(est.uses_input)
        M = _float(est.input_correction) if use_input else np.zeros((est.n_state, 1))
        H = _float(est.measurement.H) if est.missing == "skip" else np.zeros((y.shape[2], est.n_state))
        ok = kern.lti_batch(_float(est.A_effective), _float(est.B_F), _float(est.C_F), M, H,
                            _float(est.start(xhat0, None, 1).x[0]), _float(y), _float(u) if use_input else
                            np.zeros((runs, steps, 1)), use_input, est.missing == "skip", xhat)
        return (xhat, None, {}) if ok else (None, None, {})
    state = est.start(xhat0, P0, runs)  # the filter's own checks of P0 and its per-run parameters
    x0 = _float(state.x[0])
    P_start = _float(state.P if state.P.ndim == 2 else state.P[0])
    y = _float(y)
    u = _float(u) if u.shape[2] else np.zeros((runs, steps, 1))
    keep = want_keep = {False: 0, "diagonal": 1, True: 2}[keep_covariance]
    if diagnostics and kind != "recursive_hinf":
        keep = 2  # the posterior covariances give S
    use_input = bool(est.uses_input)
    H = _float(est.measurement.H)
    shared = strong = False
    if kind in ("kalman", "augmented"):
        strong, huber = bool(getattr(est, "strong_tracking", False)), bool(getattr(est, "huber_correction", False))
        shared = bool(est.shares_covariance)
        if kind == "kalman":
            F, Qd, n_rep = est.F, est.Q, est.n_state
            G = est.Gamma if use_input else np.zeros((est.n_state, u.shape[2]))
        else:
            F, Qd, n_rep, use_input = est.Phi_a, est.Qd, est.n_state, False
            H = _float(est.H_augmented)
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
    n_out = n_rep
    if diagnostics:
        n_rep = n  # the whole (augmented) state: the priors follow from it
    xhat = np.empty((runs, steps, n_rep))
    p_runs = 1 if shared else runs
    Pdiag = np.empty((p_runs, steps, n_rep)) if keep == 1 else np.empty((1, 1, 1))
    Pfull = np.empty((p_runs, steps, n_rep, n_rep)) if keep == 2 else np.empty((1, 1, 1, 1))
    F, G = _float(F), _float(G)
    if kind in ("kalman", "augmented"):
        LRi = _float(est.whitening_matrix) if huber else np.eye(H.shape[0])
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
        ok = kern.recursive_hinf_batch(F, G, H, _float(est.Q), _float(est.G_theta), _float(est.HtRi), P_start, x0, y, u,
                                       use_input, _kernel_steady_tol(est), keep, xhat, Pdiag, Pfull)
    if not ok:
        return None, None, {}
    diag = {}
    if diagnostics:
        filtered = kind != "recursive_hinf" and est.output == "filtered"
        Qd_used = _float(est.Qd if kind == "augmented" else est.Q)
        diag = nis_diagnostics(est, diagnostics, F=F, G=G, H=H, Qd=Qd_used, R=_float(est.R), P_start=P_start, x0=x0,
                               y=y, u=u, use_input=use_input, filtered=filtered, xhat=xhat,
                               P=Pfull if keep == 2 else None, strong=kind != "recursive_hinf" and strong,
                               with_S=kind != "recursive_hinf")
        xhat = np.ascontiguousarray(xhat[:, :, :n_out])
        if want_keep == 0:
            Pfull = None
        elif want_keep == 1:
            Pdiag = np.ascontiguousarray(np.diagonal(Pfull, axis1=-2, axis2=-1)[:, :, :n_out])
        elif keep == 2 and n_out < n_rep:
            Pfull = np.ascontiguousarray(Pfull[:, :, :n_out, :n_out])
        keep = want_keep
    P_hist = {0: None, 1: Pdiag, 2: Pfull}[keep]
    if P_hist is not None and shared:
        P_hist = P_hist[0]
        P_hist.setflags(write=False)
        P_hist = np.broadcast_to(P_hist, (runs,) + P_hist.shape)
    return xhat, P_hist, diag
