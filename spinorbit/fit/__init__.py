"""Fitting rotation states and moment ratios to observations (issue 21; ``docs/fitting.md``).

- :mod:`.observations` — attitudes, axis directions, spin rates and periods at astropy epochs, each
  with its whitened residuals and their derivatives;
- :mod:`.propagation` — states at the epochs with their STM, from the exact free flow or the DOP853
  variational equations;
- :mod:`.fitter` — :func:`fit_rotation`: least squares with the analytic Jacobian, multi-start over the
  phase, identifiability checks;
- :mod:`.result` — :class:`FitResult`: state, moment ratios, covariance, residuals, report and plot;
- :mod:`.errors` — the fitter's error types.
"""

from spinorbit.fit.errors import (
    FitError,
    FitNotConvergedError,
    InvalidObservationError,
    ObservationOutsideSpanError,
    SingularGeometryError,
    TooFewObservationsError,
    UnseparatedParametersWarning,
)
from spinorbit.fit.fitter import fit_rotation
from spinorbit.fit.observations import (
    AttitudeObservation,
    AxisObservation,
    PeriodObservation,
    SpinRateObservation,
)
from spinorbit.fit.result import FitResult

__all__ = [
    "AttitudeObservation", "AxisObservation", "FitError", "FitNotConvergedError", "FitResult",
    "InvalidObservationError", "ObservationOutsideSpanError", "PeriodObservation", "SingularGeometryError",
    "SpinRateObservation", "TooFewObservationsError", "UnseparatedParametersWarning", "fit_rotation",
]
