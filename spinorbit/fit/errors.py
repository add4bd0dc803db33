"""The fitter's error types: each says what was expected, what arrived and what to do."""

from spinorbit.core.errors import SpinorbitError


class FitError(SpinorbitError, ValueError):
    """Base class of the fitter's errors."""


class InvalidObservationError(FitError):
    """An observation that is not well formed (shape, units, a non-positive uncertainty)."""


class ObservationOutsideSpanError(FitError):
    """An observation epoch outside the span over which the model (its torques) is defined."""


class TooFewObservationsError(FitError):
    """Fewer residual components than fitted parameters: the least-squares problem is underdetermined."""


class SingularGeometryError(FitError):
    """The observations cannot determine the parameters (rank-deficient Jacobian): no covariance exists."""


class FitNotConvergedError(FitError):
    """least_squares stopped without meeting a convergence test; ``result`` holds the last iterate."""

    def __init__(self, message, result=None):
        super().__init__(message)
        self.result = result


class UnseparatedParametersWarning(UserWarning):
    """Two fitted parameters are correlated beyond the threshold: the data hardly separate them."""
