"""Noise generators: moments within statistical tolerance, determinism, errors."""

import numpy as np
import pytest

from hinfnav import InputError, make_noise
from hinfnav.noise import NOISE_NAMES, ColoredNoise, MixtureNoise

N = 400_000


@pytest.mark.parametrize("name", NOISE_NAMES)
def test_zero_mean_unit_variance(name):
    # every model is built for mean 0, variance 1 (closed form, module docstring);
    # tolerance: 5 standard errors of the sample mean / variance over N draws
    # (var of the sample variance = (kurtosis - 1)/N; student_t's 4th moment is 9)
    model = make_noise(name)
    shape = (40, N // 40, 1) if name == "colored" else (N, 1)
    x = model.sample(np.random.default_rng(123), shape).ravel()
    n_eff = N if name != "colored" else N / ((1 + model.a) / (1 - model.a))
    assert abs(x.mean()) < 5 / np.sqrt(n_eff)
    kurt = 9.0 if name == "student_t" else model.kurtosis
    assert abs(x.var() - 1.0) < 5 * np.sqrt((kurt - 1) / n_eff)


@pytest.mark.parametrize("name, expected", [("mixture", 3.8265), ("uniform", 1.8), ("laplace", 6.0), ("gaussian", 3.0)])
def test_kurtosis(name, expected):
    # closed forms: mixture 3((1-ε)+εr⁴)/((1-ε)+εr²)² = 3.8265 (ε = 0.6, r = 2);
    # uniform 9/5; Laplace 6; Gaussian 3. Tolerance 3 % (≥ 5 standard errors for N = 4e5)
    x = make_noise(name).sample(np.random.default_rng(7), (N,))
    assert make_noise(name).kurtosis == pytest.approx(expected, rel=1e-4)
    assert np.mean(x**4) / np.var(x) ** 2 == pytest.approx(expected, rel=0.03)


def test_mixture_components_of_paper_001():
    # paper 001: (1-ε)N(0,σ₁²)+εN(0,σ₂²), ε = 0.6, σ₂ = 2σ₁; unit variance gives σ₁² = 1/2.8
    m = MixtureNoise()
    assert m.sigma1**2 == pytest.approx(1 / 2.8, rel=1e-12)


def test_colored_noise_autocorrelation():
    # Gauss–Markov: correlation a^j at lag j, a = exp(-dt/tau) (closed form)
    m = ColoredNoise(tau_s=0.5, dt=0.1)
    x = m.sample(np.random.default_rng(3), (200, 2000, 1))[..., 0]
    for lag in (1, 3):
        rho = np.mean(x[:, lag:] * x[:, :-lag])
        assert rho == pytest.approx(m.a**lag, abs=0.01)


def _colored_by_recursion(m, xi):
    # the Gauss–Markov recursion n(k) = a n(k−1) + √(1−a²) ξ(k), n(0) = ξ(0), written out step by step
    # (the loop hinfnav.noise used before issue 21): the independent reference for the lfilter path
    out = np.empty_like(xi)
    a, b = m.a, np.sqrt(1.0 - m.a**2)
    out[..., 0, :] = xi[..., 0, :]
    for k in range(1, xi.shape[-2]):
        out[..., k, :] = a * out[..., k - 1, :] + b * xi[..., k, :]
    return out


@pytest.mark.parametrize("shape", [(300, 2), (4, 250, 3), (2, 3, 40, 1), (1, 1), (5, 1, 2)])
def test_colored_noise_equals_the_recursion(shape):
    # same ξ (same seed) through the old step loop and the IIR filter: equal to 1e-12 relative
    # (both compute b ξ(k) + a n(k−1) in the same order, so they agree to rounding)
    m = ColoredNoise(tau_s=0.7, dt=0.1)
    got = m.sample(np.random.default_rng(11), shape)
    xi = np.random.default_rng(11).standard_normal(shape)
    np.testing.assert_allclose(got, _colored_by_recursion(m, xi), rtol=1e-12, atol=0)
    assert m.sample(np.random.default_rng(0), (3, 0, 2)).shape == (3, 0, 2)


@pytest.mark.parametrize("name", NOISE_NAMES)
def test_same_seed_same_numbers(name):
    m = make_noise(name)
    a = m.sample(np.random.default_rng(5), (3, 50, 2))
    b = m.sample(np.random.default_rng(5), (3, 50, 2))
    np.testing.assert_array_equal(a, b)


def test_bad_input():
    with pytest.raises(InputError, match="unknown noise 'cauchy'; choose one of: gaussian"):
        make_noise("cauchy")
    with pytest.raises(InputError, match="rng must be a numpy.random.Generator"):
        make_noise("gaussian").sample(42, (3,))
    with pytest.raises(InputError, match="tau_s must be > 0"):
        ColoredNoise(tau_s=-1.0)
    with pytest.raises(InputError, match="eps must be in"):
        MixtureNoise(eps=1.5)
    with pytest.raises(InputError, match="dof must be >= 5"):
        make_noise("student_t", dof=3)
    with pytest.raises(InputError, match="bad parameters for noise 'uniform'"):
        make_noise("uniform", width=2)
