"""User model functions checked at the door (issue 36).

A model of the user's own (a :class:`~hinfnav.systems.DiscreteDynamics`,
:class:`~hinfnav.systems.ContinuousDynamics`, or a subclass of
:class:`~hinfnav.systems.DynamicsModel` / :class:`~hinfnav.systems.MeasurementModel`
written outside hinfnav) is called through :func:`call_model`, which

* passes a **copy** of the batch, so a function that modifies its input in
  place cannot corrupt the filter's arrays;
* reports a function that raises as a :class:`~hinfnav.core.exceptions.ModelFunctionError`
  naming the model, the function, the time and the shapes it was given
  (the estimator adds the step);
* checks **on every call** that the result has exactly the declared shape —
  (runs, n) for f and a continuous derivative, (runs, m) for h, (runs, n, n)
  or (n, n) for ∂f/∂x, (runs, m, n) or (m, n) for ∂h/∂x — and is finite: no
  silent broadcasting of (runs, 1), of a scalar, of a vector, of (n, runs);
* on the **first call** of each function, checks the batch convention: the
  first row alone (or, with one run, the row twice) must give the same row
  of output, so f returning (n, runs) for a square batch or mixing the runs
  is caught even when the shapes happen to agree;
* on the first call of a user **Jacobian**, compares it with central
  differences (:func:`~hinfnav.systems.dynamics.finite_difference_jacobian`)
  at the first state of the batch: an entry with
  ``|J_ij − J^fd_ij| > tol · max(1, max|J^fd|)`` is named, with both values
  (and "it is the transpose" when it is). ``tol`` defaults to
  :data:`JACOBIAN_TOL` (central differences are accurate to about 1e-10
  relative on a smooth map of unit scale, so 1e-4 leaves room for curvature);
  ``None`` turns the comparison off.
"""

from __future__ import annotations

import numpy as np

from ..core.exceptions import ModelFunctionError

__all__ = [
    "JACOBIAN_TOL",
    "CheckedModel",
    "call_model",
    "check_jacobian_against_differences",
    "wrap_user_methods",
]

#: Default tolerance of the first-call Jacobian check (relative to ``max(1, max |J_fd|)``).
JACOBIAN_TOL = 1e-4


def is_user_class(cls):
    """True for a class written outside the hinfnav package (its functions are the user's, checked)."""
    return not str(getattr(cls, "__module__", "")).startswith("hinfnav.")


def wrap_user_methods(cls, **wrappers):
    """Wrap the methods a user class defines itself: ``name=wrapper`` replaces ``cls.name`` by ``wrapper(cls.name)``.

    Called from the ``__init_subclass__`` of the model base classes; a class inside hinfnav is left as it is,
    and so is a method the class inherits (it was checked, or trusted, where it was defined).
    """
    if not is_user_class(cls):
        return
    for name, wrapper in wrappers.items():
        if name in cls.__dict__:
            setattr(cls, name, wrapper(cls.__dict__[name]))


def first_call_memo(model):
    """Which first-call checks have run on ``model`` (check name → True); the ``state`` of :func:`call_model`."""
    memo = model.__dict__.get("_first_call_memo")
    if memo is None:
        memo = model.__dict__["_first_call_memo"] = {}
    return memo


class CheckedModel:
    """Base of the model classes whose subclasses written outside hinfnav are checked at the door.

    Such a subclass has the methods it defines itself and that :attr:`_method_checks` names wrapped
    (:func:`wrap_user_methods`); :attr:`_first_calls` records which first-call checks have run.
    """

    #: method name → wrapper of a user subclass's own method (each model base class names its own)
    _method_checks: dict = {}
    #: tolerance of the first-call check of a user Jacobian against central differences (None: no check)
    jacobian_tol = JACOBIAN_TOL

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        wrap_user_methods(cls, **cls._method_checks)

    #: which first-call checks have run on this model (check name → True)
    _first_calls = property(first_call_memo)


def _where(t):
    return "" if t is None else f" at t = {t:g} s"


def _raw_call(model, fname, fun, args, t):
    args = tuple(a.copy() if isinstance(a, np.ndarray) else a for a in args)
    try:
        out = fun(*args)
    except ModelFunctionError:
        raise
    except Exception as exc:
        shapes = ", ".join(str(a.shape) for a in args if isinstance(a, np.ndarray))
        raise ModelFunctionError(f"{model}: {fname} raised {type(exc).__name__}: {exc}{_where(t)} (called with "
                                 f"arrays of shape {shapes}: a batch, one state per row)", model=model,
                                 function=fname) from exc
    try:
        return np.asarray(out, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ModelFunctionError(f"{model}: {fname} returned {type(out).__name__}, not an array of real numbers "
                                 f"({exc}){_where(t)}", model=model, function=fname) from None


def _check_shape(model, fname, out, shapes, t):
    if out.shape not in shapes:
        want = " or ".join(str(s) for s in shapes)
        hint = ""
        if len(shapes[0]) == 2 and out.shape == shapes[0][::-1]:
            hint = " (transposed: return one row per run)"
        elif out.ndim < len(shapes[0]):
            hint = " (a scalar or vector is not broadcast: return the full array)"
        raise ModelFunctionError(f"{model}: {fname} returned shape {out.shape}{_where(t)}; expected {want}{hint}",
                                 model=model, function=fname)
    if not np.all(np.isfinite(out)):
        raise ModelFunctionError(f"{model}: {fname} returned NaN or inf{_where(t)} from finite arguments",
                                 model=model, function=fname)


def call_model(model, fname, fun, x, rest=(), *, out_tail, t=None, allow_shared=False, state=None):
    """``fun(x, *rest)`` checked as the module docstring says; returns the ``(runs, *out_tail)`` result.

    Parameters
    ----------
    model : str
        The model as named in messages (e.g. ``"dynamics 'orbit'"``).
    fname : str
        The function as named in messages (``"f(x, u, t)"`` …).
    fun : callable
    x : ndarray, shape (runs, n)
        The checked batch (passed as a copy).
    rest : tuple
        Further arguments (u, t …); arrays among them are copied too, and a
        (runs, ·) array is sliced with x in the first-call batch check.
    out_tail : tuple of int
        The result's shape after the batch dimension.
    allow_shared : bool
        Accept ``out_tail`` alone (one array shared by every run, a Jacobian).
    state : dict, optional
        Per-model memory (the first-call checks run once per function name).
    """
    out = _raw_call(model, fname, fun, (x,) + tuple(rest), t)
    runs = x.shape[0]
    shapes = ((runs,) + tuple(out_tail),) + ((tuple(out_tail),) if allow_shared else ())
    _check_shape(model, fname, out, shapes, t)
    if state is not None and not state.get(fname):
        probe = x[:1] if runs > 1 else np.repeat(x, 2, axis=0)
        prest = tuple((a[:1] if runs > 1 else np.repeat(a, 2, axis=0))
                      if isinstance(a, np.ndarray) and a.ndim >= 1 and a.shape[0] == runs else a for a in rest)
        try:
            p = _raw_call(model, fname, fun, (probe,) + prest, t)
        except ModelFunctionError as exc:
            raise ModelFunctionError(f"{model}: {fname} works on the batch of {runs} but not on {probe.shape[0]} "
                                     f"state(s): it must act row by row on a (runs, n) batch (one state per row) "
                                     f"({exc.detail})", model=model, function=fname) from exc.__cause__
        pshapes = ((probe.shape[0],) + tuple(out_tail),) + ((tuple(out_tail),) if allow_shared else ())
        if p.shape not in pshapes:
            raise ModelFunctionError(f"{model}: {fname} returned shape {p.shape} for a batch of {probe.shape[0]} "
                                     f"state(s) but {out.shape} for {runs}: it must act row by row on a (runs, n) "
                                     f"batch and return {pshapes[0]}{_where(t)}", model=model, function=fname)
        first = out if out.shape == tuple(out_tail) else out[0]
        pfirst = p if p.shape == tuple(out_tail) else p[0]
        scale = max(1.0, float(np.abs(first).max(initial=0.0)))
        if not np.allclose(first, pfirst, rtol=1e-9, atol=1e-9 * scale):
            raise ModelFunctionError(f"{model}: {fname} gives a different result for the first state alone than "
                                     f"within the batch of {runs}{_where(t)}: it must act row by row on a (runs, n) "
                                     f"batch (one state per row), not on columns or across runs",
                                     model=model, function=fname)
        state[fname] = True
    return out


def check_jacobian_against_differences(model, jname, J, fname, fd, tol, t=None):
    """Raise naming the first entry where the Jacobian ``J`` (m, n) disagrees with differences ``fd`` (m, n)."""
    if tol is None:
        return
    J, fd = np.asarray(J, dtype=float), np.asarray(fd, dtype=float)
    scale = max(1.0, float(np.abs(fd).max(initial=0.0)))
    bad = np.abs(J - fd) > tol * scale
    if not bad.any():
        return
    i, j = np.argwhere(bad)[0]
    hint = ""
    if J.shape[0] == J.shape[1] and np.allclose(J.T, fd, rtol=0, atol=tol * scale):
        hint = "; it is the transpose of ∂f/∂x (row i must hold the derivatives of output i)"
    raise ModelFunctionError(
        f"{model}: {jname} disagrees with central differences of {fname}{_where(t)}: entry [{i}, {j}] "
        f"(∂out_{i}/∂x_{j}) is {J[i, j]:.6g} but differences give {fd[i, j]:.6g} (tolerance {tol:g} × {scale:.3g})"
        f"{hint} (jacobian_tol=None skips this first-call check)", model=model, function=jname)
