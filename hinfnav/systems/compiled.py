"""Compiled model functions: how a dynamics or measurement model brings its f, h and Jacobians to the kernels.

A model that declares numba-compiled functions runs the extended Kalman
filter and the sigma-point filter on the compiled path (a kernel that takes
the functions as arguments, :mod:`hinfnav.estimators.compiled_models`);
without them it runs on the NumPy path, and
:func:`hinfnav.estimators.compiled.why_numpy` says so. The package's own
models declare theirs (:class:`~hinfnav.systems.ConstantTurn`,
:class:`~hinfnav.systems.RangeBearing`,
:class:`~hinfnav.systems.RangeAzimuthElevation`,
:class:`~hinfnav.systems.LinearMeasurement`, and every
:class:`~hinfnav.systems.LinearSystem`, e.g. Hill's relative motion).

**How to write a numba-compilable model.** Give your model class (a subclass of
:class:`~hinfnav.systems.DynamicsModel` or
:class:`~hinfnav.systems.MeasurementModel`, with its NumPy ``f``/``jacobian``
or ``function``/``jacobian``, the reference) a method
``compiled_functions()`` that returns a :class:`CompiledDynamics` or a
:class:`CompiledMeasurement`: ``numba.njit`` functions of ONE state (not a
batch) with these fixed signatures (every array float64 and C-contiguous;
return new arrays)::

    f(x, u, t, p) -> x_next        # (n,), (n_input,), float s, (n_p,) -> (n,)
    jacobian(x, u, t, p) -> F      # ∂f/∂x, (n, n)
    h(x, p) -> y                   # (n,), (n_p,) -> (m,)
    jacobian(x, p) -> H            # ∂h/∂x, (m, n)
    residual(y, yhat, p) -> r      # y − ŷ, angles wrapped as your NumPy ``residual`` does (m,)

``p`` is the model's parameters as one float64 vector (``params``): pass
numbers through it, not through closures, so that every instance of the
model shares one compiled function (numba compiles a function once per
signature, and with ``cache=True`` once per installation). ``u`` is empty
(length 0) when the filter does not use its input; ``t = k Δt`` is the time
of the estimate being propagated, as the NumPy path passes it.

Example (a pendulum, θ̈ = −(g/ℓ) sin θ, one explicit Euler step of Δt; ``p = (Δt, g/ℓ)``)::

    import numba, numpy as np
    import hinfnav as hn
    from hinfnav.systems.compiled import CompiledDynamics

    @numba.njit(cache=True)
    def pendulum_f(x, u, t, p):
        out = np.empty(2)
        out[0] = x[0] + p[0] * x[1]
        out[1] = x[1] - p[0] * p[1] * np.sin(x[0])
        return out

    @numba.njit(cache=True)
    def pendulum_jacobian(x, u, t, p):
        J = np.empty((2, 2))
        J[0, 0], J[0, 1] = 1.0, p[0]
        J[1, 0], J[1, 1] = -p[0] * p[1] * np.cos(x[0]), 1.0
        return J

    class Pendulum(hn.DynamicsModel):
        ...                                   # f and jacobian for a batch, in NumPy (the reference)
        def compiled_functions(self):
            return CompiledDynamics(pendulum_f, pendulum_jacobian, [self.dt, self.g / self.length])

``tests/test_compiled_models.py`` writes such a model in full. Rules the
filters apply before they trust the functions:

* the class that defines ``compiled_functions()`` must also be where the
  NumPy functions are defined (a subclass that overrides ``f`` or ``function``
  without declaring ``compiled_functions()`` again runs on the NumPy path);
* at the first estimate of a model the compiled functions are compared with
  the NumPy ones at the initial estimate (relative 1e-9): a model whose two
  versions disagree is refused with an InputError naming the function;
* a function that numba cannot compile for the signature above raises numba's
  own typing error at the first estimate (``backend="numpy"`` still runs).

numba is not imported by this module: the package's functions are in
:mod:`hinfnav.systems.compiled_functions`, imported on the first call of a
model's ``compiled_functions()``.
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from ..core.exceptions import InputError

__all__ = ["CompiledDynamics", "CompiledMeasurement", "package_functions"]

_FUNCTIONS = {}


def _params(value: ArrayLike) -> np.ndarray:
    p = np.array(value, dtype=float, order="C").ravel()
    if not np.all(np.isfinite(p)):
        raise InputError("params of compiled model functions must be finite numbers")
    if p.size == 0:
        p = np.zeros(1)  # numba's arrays of length 0 are fine, but one float keeps every call's p non-empty
    return p


def _njit(name, fn):
    if fn is None or not hasattr(fn, "py_func"):
        raise InputError(f"{name} must be a numba.njit function (a CPUDispatcher); got {type(fn).__name__}")
    return fn


@dataclass(frozen=True, eq=False)
class CompiledDynamics:
    """``f(x, u, t, p)`` and ``jacobian(x, u, t, p)`` of one state, numba-compiled, and their parameters ``p``."""

    f: Any
    jacobian: Any
    params: np.ndarray = field(default_factory=lambda: np.zeros(1))

    def __post_init__(self):
        object.__setattr__(self, "f", _njit("f", self.f))
        object.__setattr__(self, "jacobian", _njit("jacobian", self.jacobian))
        object.__setattr__(self, "params", _params(self.params))


@dataclass(frozen=True, eq=False)
class CompiledMeasurement:
    """``h(x, p)``, ``jacobian(x, p)`` and ``residual(y, yhat, p)`` of one state, numba-compiled, and ``p``.

    ``residual`` None: the plain difference ``y − ŷ``
    (:func:`hinfnav.systems.compiled_functions.plain_residual`).
    """

    h: Any
    jacobian: Any
    residual: Any = None
    params: np.ndarray = field(default_factory=lambda: np.zeros(1))

    def __post_init__(self):
        object.__setattr__(self, "h", _njit("h", self.h))
        object.__setattr__(self, "jacobian", _njit("jacobian", self.jacobian))
        res = package_functions().plain_residual if self.residual is None else self.residual
        object.__setattr__(self, "residual", _njit("residual", res))
        object.__setattr__(self, "params", _params(self.params))


def package_functions():
    """The module of the package's own compiled functions (:mod:`hinfnav.systems.compiled_functions`), imported
    (with numba) on the first call."""
    if "module" not in _FUNCTIONS:
        _FUNCTIONS["module"] = importlib.import_module(f"{__package__}.compiled_functions")
    return _FUNCTIONS["module"]
