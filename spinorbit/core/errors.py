"""Exceptions of the core (plain Python, no dependencies)."""

import math


class SpinorbitError(Exception):
    """Base class of spinorbit's own exceptions."""


class SingularElementsError(SpinorbitError, ValueError):
    """The canonical elements do not exist (are infinite) or cannot carry the state's branch."""


class NonFiniteError(SpinorbitError, ValueError):
    """NaN or ±inf where a finite number is needed: times, spans, steps, moments, masses, radii, G·M, states.

    Every layer raises this one type for a non-finite input (the units layer through subclasses that
    are also its own error types, e.g. ``InvalidStateError``), so ``except NonFiniteError`` catches
    all of them and a NaN never travels into a result (``docs/stability.md``, "What bad input gets").
    """


class WorkLimitError(SpinorbitError, ValueError):
    """A run whose estimated work (steps, output rows) exceeds its documented cap, refused before it starts."""


def require_finite(name, values, expected="finite numbers"):
    """Raise :class:`NonFiniteError` naming ``name`` if any of ``values`` (a number or a sequence) is NaN/inf."""
    if getattr(getattr(values, "dtype", None), "kind", "") == "f" and math.isfinite(values.sum()):
        return  # a finite sum has no NaN or inf in it: the common case at array speed (sampled orbits)
    flat = values.ravel().tolist() if hasattr(values, "ravel") else values
    items = flat if isinstance(flat, (list, tuple)) else [flat]
    try:
        bad = [v for v in items if not math.isfinite(v)]
    except TypeError:
        return  # not numbers: the caller's own type check reports it
    if bad:
        shown = flat if len(items) <= 8 else f"{len(items)} values including {bad[0]!r}"
        raise NonFiniteError(f"{name}: expected {expected}, got {shown!r}; NaN and inf are refused, check how "
                             "the value was computed.")
