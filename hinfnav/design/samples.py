"""Uncertainty samples at which a robust design is checked, and the plant's robust stability.

A :class:`SampleSet` carries the contractions F with a label per sample and,
for a family parametrized by one scalar (the orbital-rate error δ of Sun et
al. 2011), the parameter value of each sample and its bound.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..core.exceptions import InputError, UnstablePlantError
from ..core.linalg import spectral_radius
from ..core.validation import as_matrix
from .explain import unstable_plant_message

if TYPE_CHECKING:
    from ..systems.uncertain import UncertainSystem

__all__ = ["SampleSet", "default_uncertainty_samples", "check_samples", "check_plant"]


@dataclass(frozen=True, eq=False)
class SampleSet:
    """Uncertainty matrices F with labels and, optionally, the parameter each comes from.

    Attributes
    ----------
    matrices : tuple of ndarray
        Contractions F (``FᵀF ≤ I``).
    labels : tuple of str
        One label per matrix (used in error messages and reports).
    values : ndarray or None
        The scalar parameter of each sample (δ), or None.
    bound : float or None
        The parameter's bound (δ̄), or None.
    """

    matrices: tuple
    labels: tuple = ()
    values: np.ndarray = None
    bound: float = None

    def __post_init__(self):
        mats = tuple(self.matrices)
        labels = tuple(str(s) for s in self.labels) or tuple(f"sample {i}" for i in range(len(mats)))
        if len(labels) != len(mats):
            raise InputError(f"labels must have one entry per sample ({len(mats)}); got {len(labels)}")
        values = None if self.values is None else np.asarray(self.values, dtype=float)
        if values is not None and values.shape != (len(mats),):
            raise InputError(f"values must have one entry per sample ({len(mats)}); got shape {values.shape}")
        object.__setattr__(self, "matrices", mats)
        object.__setattr__(self, "labels", labels)
        object.__setattr__(self, "values", values)
        object.__setattr__(self, "bound", None if self.bound is None else float(self.bound))

    def __len__(self):
        return len(self.matrices)




def default_uncertainty_samples(system: UncertainSystem, structure: str = "full", n_random: int = 4,
                                seed: int | np.random.Generator = 0, max_vertices: int = 64) -> list[NDArray[np.float64] | None]:
    """Uncertainty matrices F at which a design is checked.

    F = 0, ±I, the sign vertices ``diag(±1)`` of a diagonal F (all of them
    for up to ``log2(max_vertices)`` uncertain channels, a seeded random
    subset otherwise), and ``n_random`` seeded random contractions (diagonal
    with entries uniform in [−1, 1] for ``structure="diagonal"``, Gaussian
    matrices scaled to spectral norm 1 for ``"full"``).

    Parameters
    ----------
    system : UncertainSystem
    structure : {"diagonal", "full"}
    n_random : int
    seed : int or numpy.random.Generator
    max_vertices : int

    Returns
    -------
    list of ndarray, shape (r, r) each (``[None]`` for a nominal system)
    """
    if system.H is None:
        return [None]
    r1, r2 = system.H.shape[1], system.E.shape[0]
    rng = seed if isinstance(seed, np.random.Generator) else np.random.default_rng(seed)
    k = min(r1, r2)
    eye = np.eye(r1, r2)
    out = [np.zeros((r1, r2)), eye, -eye]
    if 2**k <= max_vertices:
        signs = [np.array([1 if (i >> j) & 1 else -1 for j in range(k)]) for i in range(2**k)]
    else:
        signs = [rng.choice([-1, 1], size=k) for _ in range(max_vertices)]
    for sg in signs:
        F = np.zeros((r1, r2))
        F[np.arange(k), np.arange(k)] = sg
        out.append(F)
    for _ in range(n_random):
        if structure == "diagonal":
            F = np.zeros((r1, r2))
            F[np.arange(k), np.arange(k)] = rng.uniform(-1, 1, k)
        else:
            F = rng.standard_normal((r1, r2))
            F /= np.linalg.norm(F, 2)
        out.append(F)
    return out


def check_samples(samples: Iterable[ArrayLike | None], system: UncertainSystem,
                  structure: str) -> list[NDArray[np.float64] | None]:
    if system.H is None:
        return [None]
    shape = (system.H.shape[1], system.E.shape[0])
    checked = []
    for i, F in enumerate(samples):
        if F is None:
            checked.append(np.zeros(shape))
            continue
        F = as_matrix(f"uncertainty_samples[{i}]", F, shape)
        if np.linalg.norm(F, 2) > 1.0 + 1e-9:
            raise InputError(
                f"uncertainty_samples[{i}] must be a contraction (FᵀF ≤ I, (11)); its spectral norm is {np.linalg.norm(F, 2):.6g}"
            )
        if structure == "diagonal" and np.any(F - np.diag(np.diag(F)) != 0):
            raise InputError(f"uncertainty_samples[{i}] must be diagonal with structure='diagonal'")
        checked.append(F)
    if not checked:
        raise InputError("uncertainty_samples must contain at least one matrix F")
    return checked


def check_plant(system: UncertainSystem, samples: Sequence[NDArray[np.float64] | None],
                labels: Sequence[str] | None = None) -> None:
    """Raise UnstablePlantError unless A and every A + H F E sampled are Schur stable (internal)."""
    rho = spectral_radius(system.A)
    if not rho < 1.0:
        raise UnstablePlantError(unstable_plant_message(rho, "the nominal plant (F = 0)"))
    for i, F in enumerate(samples):
        if F is None:
            continue
        rho = spectral_radius(system.perturbed_A(F))
        if not rho < 1.0:
            what = "" if labels is None else f" ({labels[i]})"
            raise UnstablePlantError(unstable_plant_message(rho, f"uncertainty sample {i}{what}"))


