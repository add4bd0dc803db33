"""The ensemble's error types."""

from spinorbit.core.errors import SpinorbitError

__all__ = ["EnsembleError", "EnsembleInterrupted"]


class EnsembleError(SpinorbitError, ValueError):
    """An ensemble's inputs are malformed (parameters, make_scene, chunk size, times, indices)."""


class EnsembleInterrupted(SpinorbitError, RuntimeError):
    """Some chunks did not come back (a worker died, the pool broke); the completed ones are kept.

    Attributes ``members_lost`` (members of the chunks lost), ``cause`` (the first chunk's exception)
    and ``executor`` (where they ran), for a caller that words its own advice (the CLI).
    """

    def __init__(self, message, members_lost=None, cause=None, executor=None):
        super().__init__(message)
        self.members_lost, self.cause, self.executor = members_lost, cause, executor

    def __reduce__(self):
        return type(self), (str(self), self.members_lost, None, self.executor)
