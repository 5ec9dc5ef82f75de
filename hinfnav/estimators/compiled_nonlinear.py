"""The compiled path of the EKF and the sigma-point filter on a model's own compiled functions (NumPy side).

A filter class that declares the ``"kalman"`` or ``"sigma_point"`` kernel
runs on :mod:`hinfnav.estimators.compiled_models` (numba, imported on the
first request) when its model is not the linear kernels' (a dynamics model,
a measurement that is not ``y = H x + D v``, or ``missing="skip"``) and both
its models declare compiled functions (``compiled_functions()``, see
:mod:`hinfnav.systems.compiled`). :func:`model_status` says why not
otherwise (``hinfnav.estimators.compiled.why_numpy`` reports it).

Before a model's compiled functions are trusted they are compared, at the
initial estimate, with the model's NumPy functions (f, its Jacobian, h, its
Jacobian, the residual at a reading 4 rad away on every channel, which wraps
an angle): a relative difference above :data:`AGREEMENT` is an
:class:`~hinfnav.core.exceptions.InputError` naming the function (checked once
per model and parameter vector).
"""

from __future__ import annotations

import importlib
import importlib.util
import weakref
from typing import Any

import numpy as np

from ..core.exceptions import HinfnavError, InputError
from ..systems.dynamics import DynamicsModel
from ..systems.linear import LinearSystem
from ..systems.measurements import MeasurementModel
from .compiled_diagnostics import NIS_DIAGNOSTICS

__all__ = ["AGREEMENT", "MODEL_KERNELS", "model_status", "run_model_kernel", "uses_model_route"]

#: The declared kernels that have a route on a model's compiled functions.
MODEL_KERNELS = ("kalman", "sigma_point")

#: Largest relative difference between a model's compiled and NumPy functions at the initial estimate.
AGREEMENT = 1e-9

_DYNAMICS_METHODS = ("f", "jacobian", "propagate")
_MEASUREMENT_METHODS = ("function", "jacobian", "residual")
_VERIFIED: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()
_MODULE = {}
_ADDRESSES: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def _module():
    """The kernels' module (numba) and its entry points, imported on the first request.

    The kernels are called through their one compiled overload's entry point
    (their arguments are made C-contiguous float64 arrays here, the functions
    wrapped by :func:`_address`): numba's dispatcher would otherwise resolve the
    type of every function argument at each call (about 0.1 ms a call).
    """
    if "module" not in _MODULE:
        kern = importlib.import_module(f"{__package__}.compiled_models")
        fns = importlib.import_module("hinfnav.systems.compiled_functions")
        wap = importlib.import_module("numba.core.types.function_type").CompileResultWAP
        _MODULE.update(module=kern, functions=fns, wap=wap, entry={
            name: getattr(kern, name).overloads[getattr(kern, name).signatures[0]].entry_point
            for name in ("ekf_model_batch", "sigma_point_model_batch")})
    return _MODULE


def _address(fn, name):
    """``fn`` (a numba dispatcher) compiled for the signature ``name`` of :mod:`hinfnav.systems.compiled_functions`
    as a first-class function object (numba's ``CompileResultWAP``: the address of its compiled wrapper), once per
    function and signature (keyed by name: hashing numba's signature objects costs more than the call)."""
    per_fn = _ADDRESSES.setdefault(fn, {})
    if name not in per_fn:
        sig = getattr(_module()["functions"], name)
        if sig.args not in fn.overloads:
            fn.compile(sig)  # a user's lazily compiled function (numba's own typing error if it does not fit)
        per_fn[name] = _module()["wap"](fn.overloads[sig.args])
    return per_fn[name]


def uses_model_route(est: Any, kind: str | None) -> bool:
    """True when ``est`` (declaring ``kind``) runs on the model-function kernels rather than the linear ones."""
    if kind not in MODEL_KERNELS:
        return False
    system, meas = est.system, est.measurement
    linear_system = isinstance(system, LinearSystem) and type(system).propagate is LinearSystem.propagate
    linear_meas = (getattr(meas, "linear", False) and getattr(meas, "H", None) is not None
                   and type(meas).residual is MeasurementModel.residual and not hasattr(meas, "convert"))
    return not (linear_system and linear_meas and est.missing == "refuse"
                and not (kind == "kalman" and getattr(est, "nonlinear_dynamics", False)))


def _functions(model, what, names):
    """``(compiled functions, None)`` of a model, or ``(None, why not)``."""
    cls = type(model)
    owner = next((c for c in cls.__mro__ if "compiled_functions" in vars(c)), None)
    if owner is None or owner in (DynamicsModel, MeasurementModel):
        return None, (f"its {what} {cls.__name__} declares no compiled functions (compiled_functions(); see "
                      "hinfnav.systems.compiled for how to write a numba-compilable model)")
    over = [name for name in names if getattr(cls, name, None) is not getattr(owner, name, None)]
    if over:
        return None, (f"its {what} {cls.__name__} overrides {', '.join(over)} of {owner.__name__}, whose "
                      f"compiled_functions() it inherits (declare compiled_functions() in {cls.__name__})")
    fns = model.compiled_functions()
    if fns is None:
        return None, f"its {what} {cls.__name__} has no compiled functions (compiled_functions() returns None)"
    return fns, None


def model_status(est: Any, kind: str) -> str | None:
    """Why ``est`` cannot run on the model-function kernels, or None when it can."""
    if kind == "kalman" and (getattr(est, "strong_tracking", False) or getattr(est, "huber_correction", False)
                             or getattr(est, "defers_prior", False)):
        return ("strong tracking and Huber's correction run compiled on a linear model only (a LinearSystem, "
                "y = H x + D v) and without missing='skip'")
    if kind == "sigma_point" and est.error_coordinates:
        return "its state has its own error coordinates (a quaternion)"
    if getattr(est, "R_of_reading", None) is not None or getattr(est, "R", None) is None or np.ndim(est.R) != 2:
        return "its R depends on the reading"
    if hasattr(est.measurement, "convert"):
        return "its measurement converts its readings"
    if np.ndim(est.Q) != 2:
        return "its process noise is given per run"
    if importlib.util.find_spec("numba") is None:
        return "numba is not installed (pip install numba==0.68.1)"
    for model, what, names in ((est.system, "dynamics model", _DYNAMICS_METHODS),
                               (est.measurement, "measurement model", _MEASUREMENT_METHODS)):
        reason = _functions(model, what, names)[1]
        if reason:
            return reason
    return None


def _agree(name, model, got, ref):
    got, ref = np.asarray(got, dtype=float), np.asarray(ref, dtype=float)
    if got.shape != ref.shape:
        raise InputError(f"the compiled {name} of {type(model).__name__} returns shape {got.shape}; its NumPy "
                         f"function gives {ref.shape} (hinfnav.systems.compiled)")
    scale = max(float(np.abs(ref).max(initial=0.0)), 1e-300)
    err = float(np.abs(got - ref).max(initial=0.0)) / scale
    if not err <= AGREEMENT:
        raise InputError(f"the compiled {name} of {type(model).__name__} differs from its NumPy function at the "
                         f"initial estimate by {err:.1e} relative (more than {AGREEMENT:g}): the two versions of the "
                         "model must agree (hinfnav.systems.compiled)")


def _numpy_reference(system, sensor, x0, u0):
    """The NumPy model's f, ∂f/∂x, h, ∂h/∂x and residual at x̂₀ (the residual of ``h + 4`` from h), or None when
    the model refuses x̂₀ (a singular point: the NumPy path raises its own error at its step)."""
    n = x0.size
    ub = u0[None] if u0.size else None
    try:
        f = np.asarray(system.f(x0[None], ub, 0.0), dtype=float)[0]
        J = np.broadcast_to(np.asarray(system.jacobian(x0[None], ub, 0.0), dtype=float), (1, n, n))[0]
        h0 = np.asarray(sensor.function(x0[None]), dtype=float)[0]
        H = np.asarray(sensor.jacobian(x0[None]), dtype=float)[0]
        r = np.asarray(sensor.residual((h0 + 4.0)[None], h0[None]), dtype=float)[0]
    except (HinfnavError, ArithmeticError):
        return None
    return f, J, h0, H, r


def _verify(est, dyn, meas, x0, u0):
    """The compiled functions against the NumPy ones at x̂₀ (once per model and parameters); False when the NumPy
    model refuses x̂₀."""
    system, sensor = est.system, est.measurement
    key_d = (dyn.f, dyn.jacobian, dyn.params.tobytes())
    key_m = (meas.h, meas.jacobian, meas.residual, meas.params.tobytes())
    if _VERIFIED.get(system) == key_d and _VERIFIED.get(sensor) == key_m:
        return True
    ref = _numpy_reference(system, sensor, x0, u0)
    if ref is None:
        return False
    f, J, h0, H, r = ref
    _agree("f", system, dyn.f(x0, u0, 0.0, dyn.params), f)
    _agree("jacobian", system, dyn.jacobian(x0, u0, 0.0, dyn.params), J)
    _agree("h", sensor, meas.h(x0, meas.params), h0)
    _agree("jacobian", sensor, meas.jacobian(x0, meas.params), H)
    _agree("residual", sensor, meas.residual(h0 + 4.0, h0, meas.params), r)
    _VERIFIED[system], _VERIFIED[sensor] = key_d, key_m
    return True


def _float(v):
    return np.array(v, dtype=float, order="C")


def run_model_kernel(est: Any, kind: str, y: np.ndarray, u: np.ndarray, xhat0: np.ndarray, P0: np.ndarray | None,
                     keep_covariance: bool | str, diagnostics: set) -> tuple[np.ndarray | None, np.ndarray | None, dict]:
    """``(xhat, P history, diagnostics)`` of ``est`` on its models' compiled functions, or ``(None, None, {})`` to
    fall back to the NumPy path (arguments as :func:`hinfnav.estimators.compiled.run_compiled`'s)."""
    entry = _module()["entry"]
    dyn, _ = _functions(est.system, "dynamics model", _DYNAMICS_METHODS)
    meas, _ = _functions(est.measurement, "measurement model", _MEASUREMENT_METHODS)
    runs, steps, m = y.shape
    state = est.start(xhat0, P0, runs)  # the filter's own checks of P0
    x0 = _float(state.x[0])
    P_start = _float(state.P if state.P.ndim == 2 else state.P[0])
    n = x0.size
    uu = _float(u) if est.uses_input else np.zeros((runs, steps, 0))
    if not _verify(est, dyn, meas, x0, uu[0, 0]):
        return None, None, {}  # a model that refuses x̂₀ (a singular point): the NumPy path raises at its step
    keep = {False: 0, "diagonal": 1, True: 2}[keep_covariance]
    xhat = np.empty((runs, steps, n))
    Pdiag = np.empty((runs, steps, n)) if keep == 1 else np.empty((1, 1, 1))
    Pfull = np.empty((runs, steps, n, n)) if keep == 2 else np.empty((1, 1, 1, 1))
    keys = set(diagnostics or ()) & set(NIS_DIAGNOSTICS)
    diag = bool(keys)
    nu_hist = np.empty((runs, steps, m)) if diag else np.empty((1, 1, 1))
    S_hist = np.empty((runs, steps, m, m)) if diag else np.empty((1, 1, 1, 1))
    y = _float(y)
    common = (_float(est.Q), _float(est.R), P_start, x0, y, uu, float(est.dt), est.output == "filtered")
    f = _address(dyn.f, "DYNAMICS_SIGNATURE")
    h = _address(meas.h, "MEASUREMENT_SIGNATURE")
    res = _address(meas.residual, "RESIDUAL_SIGNATURE")
    skip = est.missing == "skip"
    if kind == "kalman":
        ok = entry["ekf_model_batch"](f, _address(dyn.jacobian, "DYNAMICS_JACOBIAN_SIGNATURE"), h,
                                      _address(meas.jacobian, "MEASUREMENT_JACOBIAN_SIGNATURE"), res, dyn.params,
                                      meas.params, *common, skip, keep, xhat, Pdiag, Pfull, diag, nu_hist, S_hist)
    else:
        ok = entry["sigma_point_model_batch"](f, h, res, dyn.params, meas.params, *common, _float(est.Wm),
                                              _float(est.Wc), float(est.scale), est.rule == "unscented", skip, keep,
                                              xhat, Pdiag, Pfull, diag, nu_hist, S_hist)
    if not ok:
        return None, None, {}
    out = {"innovation": nu_hist, "innovation_covariance": S_hist}
    P_hist = {0: None, 1: Pdiag, 2: Pfull}[keep]
    if P_hist is not None and runs > 1 and getattr(est, "shares_covariance", False) and (P_hist == P_hist[:1]).all():
        # a linear model whose runs lack the same channels: one covariance for every run, as the NumPy path keeps it
        P_hist = P_hist[0]
        P_hist.setflags(write=False)
        P_hist = np.broadcast_to(P_hist, (runs,) + P_hist.shape)
    return xhat, P_hist, {k: v for k, v in out.items() if k in keys}
