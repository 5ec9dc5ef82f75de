"""Continuous-time robust H∞ analysis on a parameter box with a Lyapunov matrix polynomial in the parameters.

For ``ẋ = A(θ) x + B(θ) w``, ``e = C(θ) x + D(θ) w`` with the matrices
multi-affine in θ ∈ ∏ [loᵢ, hiᵢ] (affine in each θᵢ separately, products
such as θ₁θ₃ allowed), write ``θᵢ = loᵢ αᵢ₁ + hiᵢ αᵢ₂`` with ``αᵢ`` in the
unit simplex Λ₂ (a *multi-simplex*, Oliveira & Peres). The data are then
homogeneous polynomials of degree one in each αᵢ whose coefficients are the
plants at the box corners: ``A(α) = Σ_c ∏ᵢ αᵢ,cᵢ A(θ_c)``. With the
Lyapunov matrix ``P(α)`` homogeneous of degree g in each αᵢ, the bounded
real lemma::

    T(α) = [[A(α)ᵀP(α) + P(α)A(α) + C(α)ᵀC(α), ⋆], [B(α)ᵀP(α) + D(α)ᵀC(α), D(α)ᵀD(α) − γ² I]] < 0

is a homogeneous polynomial of degree g + 1 in each αᵢ (the constant and
lower-degree terms multiplied by ``(αᵢ₁ + αᵢ₂)^k = 1``); ``T(α) < 0`` on the
multi-simplex holds when every coefficient matrix is negative definite
(α^k ≥ 0), and ``P(α) > 0`` when every coefficient of P is. Optionally
(Pólya) T is first multiplied by ``∏ᵢ (αᵢ₁ + αᵢ₂)^d``, which relaxes the
test. g = 0 is the common Lyapunov function (C1) on the corners; larger g
certify every θ constant in time with a less conservative bound. This is
the relaxation of the ROLMIP manual, §7.2 (Agulhari, Oliveira, Peres), and
is tested against its printed values.

Certificate: the coefficient matrices recomputed in float64 from the
returned coefficients of P, the smallest γ making each negative definite
(:func:`hinfnav.analysis.certificates.schur_gamma`).
"""

from __future__ import annotations

import itertools
from collections.abc import Callable, Sequence
from math import comb
from typing import Any

import cvxpy as cp
import numpy as np

from ..analysis.certificates import schur_gamma
from ..core.exceptions import InputError
from .solve import solve_once_gamma

__all__ = ["robust_hinf_box"]


def _corners(plant, ranges, rng):
    """Plants at the corners, keyed by k ∈ {0, 1}^p (kᵢ = 1: θᵢ = loᵢ, the α_i1 coefficient); multi-affinity checked."""
    p = len(ranges)
    out = {}
    for k in itertools.product((0, 1), repeat=p):
        th = np.array([lo if ki else hi for ki, (lo, hi) in zip(k, ranges)])
        out[k] = tuple(np.atleast_2d(np.asarray(M, dtype=float)) for M in plant(th))
    for _ in range(3):  # a multi-affine plant equals the multilinear interpolation of its corners
        t = rng.random(p)
        th = np.array([lo + ti * (hi - lo) for ti, (lo, hi) in zip(t, ranges)])
        got = [np.atleast_2d(np.asarray(M, dtype=float)) for M in plant(th)]
        for j, M in enumerate(got):
            interp = sum(np.prod([(1 - ti) if ki else ti for ki, ti in zip(k, t)]) * out[k][j] for k in out)
            if not np.allclose(M, interp, rtol=1e-9, atol=1e-12 * max(1.0, np.abs(interp).max())):
                raise InputError(f"plant: matrix {'ABCD'[j]} is not multi-affine in θ (at θ = {th.tolist()} it differs "
                                 "from the interpolation of the box corners); write it in parameters it is affine in")
    return out


def _mul(P, Q):
    """Product of two multi-simplex polynomials {exponent tuple: matrix} (exponents of αᵢ₁; degrees add)."""
    out = {}
    for a, Ma in P.items():
        for b, Mb in Q.items():
            k = tuple(x + y for x, y in zip(a, b))
            out[k] = out[k] + Ma @ Mb if k in out else Ma @ Mb
    return out


def _weights(p, g):
    """Coefficients of ∏ᵢ (αᵢ₁ + αᵢ₂)^g: binomials."""
    return {k: float(np.prod([comb(g, ki) for ki in k])) for k in itertools.product(range(g + 1), repeat=p)}


def _raise(P, p, d):
    """Multiply a polynomial by ∏ᵢ (αᵢ₁ + αᵢ₂)^d."""
    if d == 0:
        return P
    W = _weights(p, d)
    out = {}
    for a, Ma in P.items():
        for b, w in W.items():
            k = tuple(x + y for x, y in zip(a, b))
            out[k] = out[k] + w * Ma if k in out else w * Ma
    return out


def _blocks(corners, Pc, p, g, d):
    """Coefficients (γ² = 0 part, weight of −γ²) of T(α)·∏(Σα)^d, degree g + 1 + d per simplex."""
    A = {k: v[0] for k, v in corners.items()}
    Bt = {k: v[1].T for k, v in corners.items()}
    C = next(iter(corners.values()))[2]
    D = next(iter(corners.values()))[3]
    if any(not np.array_equal(v[2], C) or not np.array_equal(v[3], D) for v in corners.values()):
        raise InputError("plant: C and D must not depend on θ in this relaxation (write the output through the state)")
    At = {k: M.T for k, M in A.items()}
    AP, PA, BP = _mul(At, Pc), _mul(Pc, A), _mul(Bt, Pc)
    top = {k: AP[k] + PA[k] for k in AP}
    W = _weights(p, g + 1)
    T11, T21 = _raise(top, p, d), _raise(BP, p, d)
    Wd = _raise(W, p, d) if d else W
    return T11, T21, Wd, C, D


def robust_hinf_box(plant: Callable[[np.ndarray], Sequence[Any]], ranges: Sequence[tuple[float, float]], degree: int = 1,
                    polya: int = 0, solver: str = "CLARABEL", margin: float = 1e-9, seed: int = 0) -> dict[str, Any]:
    """Minimize γ² subject to the multi-simplex BRL with P(α) of ``degree`` in each parameter (see the module docstring).

    Parameters
    ----------
    plant : callable
        ``plant(theta)`` returns ``(A, B, C, D)`` at the parameter vector θ; A, B
        multi-affine in θ; C, D constant.
    ranges : sequence of (low, high)
    degree : int
        Degree g of P(α) in each simplex (0: one common P).
    polya : int
        Pólya exponent d.

    Returns
    -------
    dict
        ``status``, ``gamma`` (solver's), ``certified`` (float64), ``P`` (coefficients), ``seconds``.
    """
    ranges = [(float(lo), float(hi)) for lo, hi in ranges]
    if not ranges or any(not lo < hi for lo, hi in ranges):
        raise InputError("ranges must be a non-empty sequence of (low, high) with low < high")
    if int(degree) != degree or degree < 0 or int(polya) != polya or polya < 0:
        raise InputError(f"degree and polya must be integers >= 0; got {degree!r}, {polya!r}")
    p = len(ranges)
    corners = _corners(plant, ranges, np.random.default_rng(seed))
    n, m = corners[(0,) * p][0].shape[0], corners[(0,) * p][1].shape[1]
    keys = list(itertools.product(range(degree + 1), repeat=p))
    Pv = {k: cp.Variable((n, n), symmetric=True) for k in keys}
    mu = cp.Variable()
    T11, T21, W, C, D = _blocks(corners, Pv, p, degree, polya)
    cons = [P >> margin * np.eye(n) for P in Pv.values()]
    for k, w in W.items():
        M = cp.bmat([[T11[k] + w * C.T @ C, T21[k].T + w * C.T @ D], [T21[k] + w * D.T @ C, w * (D.T @ D) - w * mu * np.eye(m)]])
        cons.append(0.5 * (M + M.T) << -margin * np.eye(n + m))
    out = solve_once_gamma(cons, mu, solver, 1e-9)
    if any(P.value is None for P in Pv.values()):
        out["certified"] = float("inf")
        return out
    Pn = {k: 0.5 * (P.value + P.value.T) for k, P in Pv.items()}
    out["P"] = Pn
    out["certified"] = _certify(corners, Pn, p, degree, polya)
    return out


def _certify(corners, Pn, p, g, d):
    if any(not np.all(np.linalg.eigvalsh(P) > 0) for P in Pn.values()):
        return float("inf")
    T11, T21, W, C, D = _blocks(corners, Pn, p, g, d)
    n, m = C.shape[1], D.shape[1]
    worst = 0.0
    for k, w in W.items():  # divide by the weight w > 0: the −γ² block becomes −γ² I
        M0 = np.block([[T11[k] + w * C.T @ C, T21[k].T + w * C.T @ D], [T21[k] + w * D.T @ C, w * (D.T @ D)]]) / w
        worst = max(worst, schur_gamma(0.5 * (M0 + M0.T), np.arange(n, n + m))[0])
    return worst
