"""The scene's input error, shared by the inputs' checks and the orbit constructors."""

from spinorbit.core.errors import SpinorbitError

__all__ = ["SceneError"]


class SceneError(SpinorbitError, ValueError):
    """A scene was described with inputs of the wrong kind or inconsistent with each other."""
