"""Exception classes of hinfnav.

Every error the package raises on purpose derives from :class:`HinfnavError`,
so a caller can catch all of them at once. Input errors also derive from
:class:`ValueError`, so code written against NumPy conventions keeps working.
"""

__all__ = [
    "HinfnavError",
    "InputError",
    "UnstablePlantError",
    "SynthesisError",
    "InfeasibleLMIError",
    "CertificationError",
    "LooseBoundWarning",
    "SolverAccuracyWarning",
    "FilterDivergenceWarning",
]


class HinfnavError(Exception):
    """Base class of every error raised on purpose by hinfnav."""


class InputError(HinfnavError, ValueError):
    """A parameter has the wrong shape, type or value.

    The message names the parameter and says what is wrong with it.
    """


class UnstablePlantError(InputError):
    """The plant is not (robustly) Schur stable, so Lemma 1 cannot hold.

    The error system (13) contains the plant state; its H-infinity norm is
    finite only when the plant matrix ``A + ΔA`` is Schur stable for every
    admissible uncertainty.
    """


class SynthesisError(HinfnavError):
    """The LMI synthesis did not produce a usable filter."""


class InfeasibleLMIError(SynthesisError):
    """The solver found LMI (20) infeasible (the message carries its status)."""


class CertificationError(SynthesisError):
    """The filter rebuilt from the solver's solution fails independent verification."""


class LooseBoundWarning(UserWarning):
    """A certified level is far above the worst norm actually sampled.

    The certificate is valid (an upper bound), but more than twice the
    largest H-infinity norm of the error system at the uncertainty samples,
    after the synthesis tried harder (other solvers, bisection, another
    scaling). The message gives both numbers.
    """


class SolverAccuracyWarning(UserWarning):
    """A solver known to be slow and loose on these LMIs was chosen (SCS).

    The result is still certified; the message says how loose it was
    measured to be.
    """


class FilterDivergenceWarning(UserWarning):
    """A filter diverged or its covariance is far from honest (issue 17, never silent).

    Issued by the consistency statistics (:mod:`hinfnav.metrics.consistency`)
    when a filter's estimation error leaves the divergence bound (non-finite,
    or grown far beyond its initial scale) or its average NEES lies far above
    the 95 % χ² bound; the message names the filter, the criterion and the
    numbers.
    """
