"""Truncated normal moments: scipy at moderate bounds, asymptotics far in the tails, input errors."""

import numpy as np
import pytest
from scipy import integrate, stats

from hinfnav.analysis.truncated import truncated_normal_moments
from hinfnav.core.exceptions import InputError

INF = np.inf

# (loc, scale, lower, upper): one-sided both ways, two-sided on one side of the
# mean, and two-sided around it; every bound within 3 scales of the mean.
MODERATE = [
    (0.0, 1.0, 1.0, INF),
    (0.0, 1.0, -INF, 0.5),
    (1.3, 0.7, -INF, 0.2),
    (-2.0, 2.5, 1.0, INF),
    (0.0, 1.0, -1.0, 2.0),
    (1.3, 0.7, 0.5, 3.0),
    (0.0, 1.0, 0.5, 3.0),
    (0.0, 1.0, -3.0, -0.5),
    (5.0, 3.0, -1.0, 4.0),
    (0.0, 1.0, -0.3, 0.2),
]


@pytest.mark.parametrize("loc, scale, lower, upper", MODERATE)
def test_matches_scipy_truncnorm_at_moderate_bounds(loc, scale, lower, upper):
    # Source: scipy.stats.truncnorm, with standardised bounds a, b.
    a, b = (lower - loc) / scale, (upper - loc) / scale
    ref = stats.truncnorm(a, b, loc=loc, scale=scale)
    mean, var = truncated_normal_moments(loc, scale**2, lower, upper)
    assert isinstance(mean, float) and isinstance(var, float)
    assert mean == pytest.approx(ref.mean(), rel=1e-12, abs=1e-15)
    assert var == pytest.approx(ref.var(), rel=1e-12)


def test_vectorised_with_broadcasting_matches_scalar_calls():
    loc = np.array([0.0, 1.3, -2.0])[:, None]  # (3, 1)
    lower = np.array([-INF, -1.0, 0.5, 1.0])  # (4,)
    upper = np.array([0.5, 2.0, 3.0, INF])
    mean, var = truncated_normal_moments(loc, 0.49, lower, upper)
    assert mean.shape == (3, 4) and var.shape == (3, 4)
    for i in range(3):
        for j in range(4):
            a, b = (lower[j] - loc[i, 0]) / 0.7, (upper[j] - loc[i, 0]) / 0.7
            ref = stats.truncnorm(a, b, loc=loc[i, 0], scale=0.7)
            assert mean[i, j] == pytest.approx(ref.mean(), rel=1e-12)
            assert var[i, j] == pytest.approx(ref.var(), rel=1e-12)


def test_untruncated_limit():
    assert truncated_normal_moments(2.0, 3.0, -INF, INF) == (2.0, 3.0)


@pytest.mark.parametrize("a", [30.0, 100.0, 1e3, 1e5])
def test_one_sided_far_tail_against_asymptotic_series(a):
    # Source: closed form. For X ~ N(0, 1) given X > a, the inverse Mills
    # ratio expands as E[X] = a + 1/a - 2/a^3 + 10/a^5 - 74/a^7 + O(a^-9) and
    # Var[X] = 1 - E[X](E[X] - a) = 1/a^2 - 6/a^4 + 50/a^6 - 518/a^8 + O(a^-10).
    # The next coefficients are below 1e3 (mean) and 1e4 (variance) in size.
    x = 1.0 / a
    mean_series = a + x - 2 * x**3 + 10 * x**5 - 74 * x**7
    var_series = x**2 - 6 * x**4 + 50 * x**6 - 518 * x**8
    mu, sigma = 3.0, 2.0  # also exercises the location-scale transform
    mean, var = truncated_normal_moments(mu, sigma**2, mu + a * sigma, INF)
    assert np.isfinite(mean) and np.isfinite(var)
    assert mu + a * sigma < mean <= mu + (a + x) * sigma  # just beyond the bound
    assert 0 < var < (x * sigma) ** 2
    assert abs((mean - mu) / sigma - mean_series) <= 1e3 * x**9 + 4e-16 * a
    assert abs(var / sigma**2 - var_series) <= 1e4 * x**10 + 1e-14 * var_series
    # The lower tail is the mirror image.
    mean_lo, var_lo = truncated_normal_moments(-mu, sigma**2, -INF, -mu - a * sigma)
    assert mean_lo == pytest.approx(-mean, rel=1e-15) and var_lo == pytest.approx(var, rel=1e-13)


def _quadrature_moments(a, b):
    """Moments of N(0,1) on [a, b], a > 0, by quadrature of exp(-a u - u^2/2) in u = x - a."""

    def w(u):  # phi(a + u) / phi(a)
        return np.exp(-u * (a + 0.5 * u))

    kw = {"epsabs": 0.0, "epsrel": 1e-13, "limit": 200}
    z = integrate.quad(w, 0.0, b - a, **kw)[0]
    m1 = integrate.quad(lambda u: u * w(u), 0.0, b - a, **kw)[0] / z
    m2 = integrate.quad(lambda u: (u - m1) ** 2 * w(u), 0.0, b - a, **kw)[0] / z
    return a + m1, m2


@pytest.mark.parametrize("a, b", [(30.0, 30.1), (30.0, 30.02), (8.0, 9.0), (40.0, 45.0), (5.0, 5.00001)])
def test_two_sided_far_tail_against_quadrature(a, b):
    # Source: independent computation (adaptive quadrature of the shifted density).
    ref_mean, ref_var = _quadrature_moments(a, b)
    mean, var = truncated_normal_moments(0.0, 1.0, a, b)
    assert a < mean < b
    assert mean == pytest.approx(ref_mean, rel=1e-14)
    assert var == pytest.approx(ref_var, rel=1e-11)


def test_narrow_interval_tends_to_uniform():
    # Width w around 0: mean -> centre, variance -> w^2 / 12 (relative O(w^2)).
    w = 1e-4
    mean, var = truncated_normal_moments(0.0, 1.0, 0.25 - w / 2, 0.25 + w / 2)
    assert mean == pytest.approx(0.25, abs=1e-9)
    assert var == pytest.approx(w**2 / 12, rel=1e-8)


@pytest.mark.parametrize(
    "args, name",
    [
        ((0.0, 0.0, -1.0, 1.0), "var"),
        ((0.0, -1.0, -1.0, 1.0), "var"),
        ((0.0, 1.0, 1.0, 1.0), "lower"),
        ((0.0, 1.0, 2.0, 1.0), "lower"),
        ((np.nan, 1.0, -1.0, 1.0), "mean"),
        ((INF, 1.0, -1.0, 1.0), "mean"),
        ((0.0, 1.0, np.nan, 1.0), "lower"),
        ((0.0, 1.0, -1.0, "x"), "upper"),
        ((np.zeros(2), 1.0, np.zeros(3), 1.0), "lower"),
    ],
)
def test_bad_inputs_raise_input_error_naming_the_parameter(args, name):
    with pytest.raises(InputError, match=rf"\b{name}\b"):
        truncated_normal_moments(*args)


def test_unchecked_call_gives_the_checked_numbers_bitwise():
    # Source: the checked call itself (check=False only skips the input checks, issue 21): every branch
    # (narrow, containing the mean, one- and two-sided tails, reflected) on 1-D float arrays of one shape.
    lo = np.array([-1.0, -INF, 0.25, 1.0, 30.0, -3.0, 2.0, -INF])
    up = np.array([2.0, 0.5, 0.2501, INF, INF, -0.5, 2.5, -40.0])
    mu = np.array([0.0, 1.3, 0.0, 0.0, 0.0, 0.0, 0.1, 0.0])
    var = np.array([1.0, 0.49, 1.0, 1.0, 1.0, 4.0, 0.25, 1.0])
    checked = truncated_normal_moments(mu, var, lo, up)
    unchecked = truncated_normal_moments(mu, var, lo, up, check=False)
    for a, b in zip(checked, unchecked):
        assert a.tobytes() == b.tobytes()
    with pytest.raises(InputError, match=r"\bvar\b"):
        truncated_normal_moments(mu, np.zeros(8), lo, up, check=False)
