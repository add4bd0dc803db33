"""The ensemble's error types."""

from spinorbit.core.errors import SpinorbitError

__all__ = ["EnsembleError", "EnsembleInterrupted"]


class EnsembleError(SpinorbitError, ValueError):
    """An ensemble's inputs are malformed (parameters, make_scene, chunk size, times, indices)."""


class EnsembleInterrupted(SpinorbitError, RuntimeError):
    """Some chunks did not come back (a worker died, the pool broke); the completed ones are kept."""
