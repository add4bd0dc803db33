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


def all_finite(values):
    """True when ``values`` (a number, a sequence or an array) holds no NaN or inf; None if not numbers."""
    if getattr(getattr(values, "dtype", None), "kind", "") in "fc" and hasattr(values, "sum"):
        with _quiet():
            total = values.sum()
        if math.isfinite(abs(total)):
            return True  # a finite sum has no NaN or inf in it: the common case at array speed
    flat = values.ravel().tolist() if hasattr(values, "ravel") else values
    items = flat if isinstance(flat, (list, tuple)) else [flat]
    try:
        return all(math.isfinite(abs(v)) for v in items)
    except TypeError:
        return None


def _quiet():
    import numpy as np  # the core's own dependency; imported here so that this module stays importable alone

    return np.errstate(over="ignore", invalid="ignore")


def require_finite_result(name, values, advice=""):
    """Raise :class:`NonFiniteError` if a result computed from finite inputs holds NaN or inf.

    The one check on the way out (``docs/stability.md``, "What bad input gets"): inputs are checked
    finite on the way in, so a non-finite result means they were finite but beyond what double
    precision carries through the computation (an overflow, an underflow divided by). ``advice`` says
    what to change; without it the message asks for values in the physical range.
    """
    if all_finite(values) is not False:
        return
    flat = values.ravel().tolist() if hasattr(values, "ravel") else values
    items = flat if isinstance(flat, (list, tuple)) else [flat]
    shown = items if len(items) <= 6 else f"{len(items)} values including {next(v for v in items if not math.isfinite(abs(v)))!r}"
    raise NonFiniteError(f"{name}: the result is not finite ({shown}) although every input was: "
                         f"{advice or 'the inputs lie beyond what double precision carries through this computation'}. "
                         "Give values in the physical range (check their units and magnitudes).")
