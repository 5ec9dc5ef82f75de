"""Exception classes of hinfnav.

Every error the package raises on purpose derives from :class:`HinfnavError`,
so a caller can catch all of them at once. Input errors also derive from
:class:`ValueError`, so code written against NumPy conventions keeps working.
"""

__all__ = [
    "HinfnavError",
    "InputError",
    "ModelFunctionError",
    "FilterDivergedError",
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


class ModelFunctionError(InputError):
    """A user's model function (f, h, a Jacobian, a derivative) raised or returned something unusable.

    The message names the model, the function and, when an estimator ran it,
    the step (issue 36: a user model is checked at the door, never silently
    broadcast). ``model``, ``function`` and ``step`` are kept as attributes.
    """

    def __init__(self, message, *, model=None, function=None, step=None):
        super().__init__(message)
        self.model, self.function, self.step, self.detail = model, function, step, message

    def at_step(self, step):
        """The same error, its message prefixed with the estimator step (once)."""
        if self.step is not None:
            return self
        err = ModelFunctionError(f"at step {step}: {self.detail}", model=self.model, function=self.function, step=step)
        err.__cause__ = self.__cause__
        return err


class FilterDivergedError(HinfnavError):
    """A filter's estimate or covariance became non-finite (NaN or inf) (issue 36, never silent).

    Raised at the step where it happened, identically by the NumPy and the
    compiled paths; the message names the filter and the step.
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
