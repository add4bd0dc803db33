"""The photometry layer's error types: each says what was expected, what arrived and what to do."""

from spinorbit.core.errors import SpinorbitError


class PhotometryError(SpinorbitError, ValueError):
    """Base class of the photometry layer's errors."""


class InvalidDirectionsError(PhotometryError):
    """Sun or observer directions that are not finite (n, 3) unit vectors, or not as many of one as of the other."""
