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


class InputError(SpinorbitError, ValueError):
    """A value given on the command line or in a scene file of the wrong type, unit or range.

    Raised before any work is done. The message names the option or key (``where``: ``"--rtol"``,
    ``"[spin] period"``), says what was expected and what arrived, and what to do; the parts are kept
    as attributes for programs that read them.

    Parameters
    ----------
    where : str
        The option or scene-file key, as the user wrote it.
    expected : str
        What it takes ("a positive number such as 1e-12").
    got : str
        What arrived, described in words ("the string 'sun'"), never another exception's text.
    advice : str, optional
        What to do instead.
    """

    def __init__(self, where, expected, got, advice=""):
        self.where, self.expected, self.got, self.advice = where, expected, got, advice
        super().__init__(f"{where} expects {expected}; got {got}." + (f" {advice}" if advice else ""))

    def __reduce__(self):  # the four parts, not the message, rebuild it (process pools pickle errors)
        return type(self), (self.where, self.expected, self.got, self.advice)


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
