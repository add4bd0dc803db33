"""Exceptions of the core (plain Python, no dependencies)."""


class SpinorbitError(Exception):
    """Base class of spinorbit's own exceptions."""


class SingularElementsError(SpinorbitError, ValueError):
    """The canonical elements do not exist (are infinite) or cannot carry the state's branch."""
