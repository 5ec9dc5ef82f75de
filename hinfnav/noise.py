"""Noise generators, all of zero mean and unit variance.

The paper drives the system with "unit-intensity colored noise" w(k), v(k)
scaled by B and D (6), (8); Table 1 uses white noise, Fig 7 "non-Gaussian"
noise without saying which. Every generator here draws from an explicit
:class:`numpy.random.Generator` and returns samples of unit variance, so the
matrices B and D alone set the noise levels.

=============  ==========================================================
name           distribution of one sample
=============  ==========================================================
``gaussian``   N(0, 1), white
``colored``    first-order Gauss–Markov, stationary N(0, 1), correlation
               time ``tau_s``
``mixture``    (1−ε) N(0, σ₁²) + ε N(0, σ₂²), σ₂ = 2σ₁, ε = 0.6 (paper 001),
               σ₁ chosen for unit variance
``uniform``    U(−√3, √3)
``laplace``    Laplace with scale 1/√2
``student_t``  Student-t with ν = 5 degrees of freedom, scaled by √((ν−2)/ν)
=============  ==========================================================
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import scipy.signal
from numpy.typing import NDArray

from .core.exceptions import InputError
from .core.validation import as_choice, as_int_at_least, as_positive, as_real

__all__ = [
    "NoiseModel",
    "GaussianNoise",
    "ColoredNoise",
    "MixtureNoise",
    "UniformNoise",
    "LaplaceNoise",
    "StudentTNoise",
    "NOISE_NAMES",
    "make_noise",
]


def _check(rng, shape):
    if not isinstance(rng, np.random.Generator):
        raise InputError(f"rng must be a numpy.random.Generator (e.g. numpy.random.default_rng(seed)); got {type(rng).__name__}")
    try:
        items = tuple(shape)
    except TypeError:
        raise InputError(f"shape must be a tuple of non-negative integers; got {shape!r}") from None
    if any(isinstance(s, bool) or not isinstance(s, (int, np.integer)) for s in items):
        raise InputError(f"shape must be a tuple of non-negative integers; got {shape!r}")
    shape = tuple(int(s) for s in items)
    if any(s < 0 for s in shape):
        raise InputError(f"shape must be a tuple of non-negative integers; got {shape!r}")
    return shape


class NoiseModel:
    """Base class: ``sample(rng, shape)`` gives zero-mean, unit-variance noise.

    For shapes ``(..., n_steps, dim)`` the time axis is the second to last
    (only :class:`ColoredNoise` cares).
    """

    name = "noise"

    def sample(self, rng: np.random.Generator, shape: int | tuple[int, ...]) -> NDArray[np.float64]:
        """Draw samples.

        Parameters
        ----------
        rng : numpy.random.Generator
        shape : tuple of int
            For a sequence, ``(n_steps, dim)`` or ``(runs, n_steps, dim)``.

        Returns
        -------
        ndarray of the given shape
        """
        shape = _check(rng, shape)
        try:
            return self._sample(rng, shape)
        except MemoryError:
            need = 8.0 * float(np.prod([float(s) for s in shape]))
            raise InputError(f"shape {shape} asks for {need / 2**30:.3g} GiB of samples, more than this machine can "
                             "hold; draw fewer (e.g. in batches)") from None

    def _sample(self, rng, shape):  # pragma: no cover - abstract
        raise NotImplementedError

    #: Theoretical kurtosis E[x⁴] (3 for a Gaussian).
    kurtosis = 3.0


@dataclass(frozen=True)
class GaussianNoise(NoiseModel):
    """White N(0, 1)."""

    name = "gaussian"
    kurtosis = 3.0

    def _sample(self, rng, shape):
        return rng.standard_normal(shape)


@dataclass(frozen=True)
class ColoredNoise(NoiseModel):
    """First-order Gauss–Markov noise of unit stationary variance.

    ``n(k+1) = a n(k) + √(1−a²) ξ(k)``, ``a = exp(−dt/tau_s)``, ξ white N(0, 1),
    ``n(0) ~ N(0, 1)`` so the sequence is stationary from the start.
    Its autocorrelation is ``a^|j|`` at lag j.

    Parameters
    ----------
    tau_s : float
        Correlation time, s (default 1 s, ten samples at T = 0.1 s).
    dt : float
        Sampling time, s.
    """

    tau_s: float = 1.0
    dt: float = 0.1
    name = "colored"
    kurtosis = 3.0

    def __post_init__(self):
        as_positive("tau_s", self.tau_s)
        as_positive("dt", self.dt)

    @property
    def a(self) -> float:
        """One-step correlation ``exp(−dt/tau_s)``."""
        return float(np.exp(-self.dt / self.tau_s))

    def _sample(self, rng, shape):
        if len(shape) < 2:
            raise InputError(f"colored noise needs a shape (..., n_steps, dim) with a time axis; got {shape}")
        xi = rng.standard_normal(shape)
        out = np.empty(shape)
        if shape[-2] == 0:
            return out
        a, b = self.a, np.sqrt(1.0 - self.a**2)
        out[..., 0, :] = xi[..., 0, :]
        if shape[-2] > 1:
            # n(k) = b ξ(k) + a n(k−1) for k ≥ 1 as one IIR filter along the time axis, each
            # sequence contiguous (time last); the initial state a n(0) makes the first output
            # b ξ(1) + a n(0), the recursion's, and lfilter adds in the recursion's order.
            seq = np.moveaxis(xi, -2, -1).reshape(-1, shape[-2])
            filtered = scipy.signal.lfilter([b], [1.0, -a], seq[:, 1:], axis=-1, zi=a * seq[:, :1])[0]
            out[..., 1:, :] = np.moveaxis(filtered.reshape(shape[:-2] + (shape[-1], shape[-2] - 1)), -1, -2)
        return out


@dataclass(frozen=True)
class MixtureNoise(NoiseModel):
    """Gaussian mixture (1−ε) N(0, σ₁²) + ε N(0, σ₂²) of paper 001, unit variance.

    Parameters
    ----------
    eps : float
        Weight of the wide component (0.6 in paper 001).
    ratio : float
        σ₂/σ₁ (2 in paper 001).

    Notes
    -----
    ``σ₁² = 1/((1−ε) + ε r²)``; kurtosis ``3((1−ε) + ε r⁴)/((1−ε) + ε r²)²``
    (3.827 for ε = 0.6, r = 2).
    """

    eps: float = 0.6
    ratio: float = 2.0
    name = "mixture"

    def __post_init__(self):
        if not (0.0 <= as_real("eps", self.eps) <= 1.0):
            raise InputError(f"eps must be in [0, 1]; got {self.eps}")
        as_positive("ratio", self.ratio)

    @property
    def sigma1(self) -> float:
        """Standard deviation of the narrow component."""
        return 1.0 / np.sqrt((1 - self.eps) + self.eps * self.ratio**2)

    @property
    def kurtosis(self) -> float:
        """Theoretical kurtosis."""
        e, r = self.eps, self.ratio
        return 3 * ((1 - e) + e * r**4) / ((1 - e) + e * r**2) ** 2

    def _sample(self, rng, shape):
        wide = rng.random(shape) < self.eps
        scale = np.where(wide, self.sigma1 * self.ratio, self.sigma1)
        return scale * rng.standard_normal(shape)


@dataclass(frozen=True)
class UniformNoise(NoiseModel):
    """U(−√3, √3): unit variance, kurtosis 1.8."""

    name = "uniform"
    kurtosis = 1.8

    def _sample(self, rng, shape):
        return rng.uniform(-np.sqrt(3.0), np.sqrt(3.0), shape)


@dataclass(frozen=True)
class LaplaceNoise(NoiseModel):
    """Laplace with scale 1/√2: unit variance, kurtosis 6."""

    name = "laplace"
    kurtosis = 6.0

    def _sample(self, rng, shape):
        return rng.laplace(0.0, 1.0 / np.sqrt(2.0), shape)


@dataclass(frozen=True)
class StudentTNoise(NoiseModel):
    """Student-t with ``dof`` degrees of freedom scaled to unit variance.

    Requires ``dof > 4`` so that the kurtosis ``3 + 6/(dof−4)`` is finite
    (9 for the default ``dof = 5``).
    """

    dof: int = 5
    name = "student_t"

    def __post_init__(self):
        as_int_at_least("dof", self.dof, 5)

    @property
    def kurtosis(self) -> float:
        """Theoretical kurtosis."""
        return 3.0 + 6.0 / (self.dof - 4)

    def _sample(self, rng, shape):
        return rng.standard_t(self.dof, shape) * np.sqrt((self.dof - 2) / self.dof)


_FACTORIES = {
    "gaussian": GaussianNoise,
    "colored": ColoredNoise,
    "mixture": MixtureNoise,
    "uniform": UniformNoise,
    "laplace": LaplaceNoise,
    "student_t": StudentTNoise,
}

#: Names accepted by :func:`make_noise` and the command line.
NOISE_NAMES = tuple(_FACTORIES)


def make_noise(name: str | NoiseModel, **params: Any) -> NoiseModel:
    """Build a noise model by name (see the module table), or pass one through.

    Parameters
    ----------
    name : str or NoiseModel
    **params
        Passed to the model's constructor (e.g. ``tau_s``, ``dt`` for
        ``colored``; ``eps``, ``ratio`` for ``mixture``).
    """
    if isinstance(name, NoiseModel):
        if params:
            raise InputError("noise parameters can only be given with a noise name, not with a NoiseModel instance")
        return name
    as_choice("noise", name, NOISE_NAMES)
    try:
        return _FACTORIES[name](**params)
    except TypeError as exc:
        raise InputError(f"bad parameters for noise {name!r}: {exc}") from None
