"""Quantity arguments checked and converted in one place, for the API and the command line alike.

Every Quantity argument of the units layer, and every option of the command line that takes a
quantity, goes through :func:`value_in`: a wrong physical type is refused with the argument's name,
the unit expected and what arrived; NaN and ±inf are refused where a finite value is needed.

**Units are never guessed** (``docs/conventions.md``, "Units"): a dimensional argument is a Quantity,
and a bare number for it is refused with a one-line hint (:func:`bare_number_message`): "omega
expects an angular velocity Quantity (e.g. 2.18e-4 * u.rad / u.s); got the bare float 0.000218". Only
dimensionless arguments (ratios, an eccentricity) take plain numbers. The
command line parses its text with :func:`parse_quantity` and :func:`parse_unit`, which end in the
same checks, so ``RotationState(..., 1 * u.Hz)`` and ``--omega-unit Hz`` give the same refusal.

Rotation rates given as frequencies (``docs/conventions.md``, "Units"): a unit of physical type
*frequency* (``u.Hz``, ``1 / u.day``) is refused, because astropy's ``dimensionless_angles``
equivalency would silently read 1 Hz as 1 rad/s while "1 Hz" of rotation usually means one turn
per second (2π rad/s). Turns per time are written with astropy's ``u.cycle`` (``u.cycle / u.s``,
``--omega-unit cycle/d``), which converts with the factor 2π; radians and degrees per time as usual.
"""

from __future__ import annotations

import dataclasses
import functools
import inspect
import math

import numpy as np
from astropy import units as u

from spinorbit.core.errors import NonFiniteError, all_finite, require_finite_result

__all__ = ["QuantityInputError", "bare_number_message", "finite_result", "finite_values", "parse_quantity", "parse_unit",
           "require_quantity", "value_in"]

# The physical types value_in compares with, looked up once: comparing with a string parses the name
# on every call (~4 µs each, several per member of an ensemble); comparing PhysicalTypes is the same test.
_ANGULAR_VELOCITY = u.get_physical_type("angular velocity")
_FREQUENCY = u.get_physical_type("frequency")
_DIMENSIONLESS = u.get_physical_type("dimensionless")


class QuantityInputError(u.UnitTypeError):
    """A Quantity argument of the wrong physical type, a frequency given for a rotation rate, or unreadable text.

    A subclass of astropy's ``UnitTypeError`` (itself a ``TypeError``), so code that catches astropy's
    error keeps working.
    """


_BASE_DIMENSIONS = {"m": "length", "s": "time", "kg": "mass", "rad": "angle", "K": "temperature", "A": "current",
                    "mol": "amount", "cd": "luminous intensity"}


def _kind(unit) -> str:
    """The short name of a unit's physical type ("angular velocity", not astropy's three aliases).

    A type astropy has no name for (G·M's length³/time²) is spelt from its dimensions, never "unknown".
    """
    unit = u.Unit(unit)
    kind = str(unit.physical_type).split("/")[-1]
    if kind != "unknown":
        return kind
    si = unit.decompose(bases=[u.m, u.s, u.kg, u.rad, u.K, u.A, u.mol, u.cd])
    up = [f"{_BASE_DIMENSIONS[b.name]}" + (f"^{p:g}" if p != 1 else "") for b, p in zip(si.bases, si.powers) if p > 0]
    down = [f"{_BASE_DIMENSIONS[b.name]}" + (f"^{-p:g}" if p != -1 else "") for b, p in zip(si.bases, si.powers)
            if p < 0]
    return " ".join(up or ["1"]) + (" / " + " ".join(down) if down else "")


def _expected(unit) -> str:
    rate = ", an angle per time" if _kind(unit) == "angular velocity" else ""
    return f"{_kind(unit)} units ({unit}{rate})"


def _arrived(value) -> str:
    if isinstance(value, u.Quantity):
        return f"{value!s} (physical type {_kind(value.unit)})"
    return f"{value!r} ({type(value).__name__})"


def _bare(value) -> str:
    """A bare number or array as the user wrote it, short: "float 0.000218", "list [0.1, 0, 0.3]"."""
    if isinstance(value, np.ndarray) and value.dtype.kind in "biuf":
        head = ", ".join(f"{x:.6g}" for x in value.ravel()[:3].tolist()) + (", ..." if value.size > 3 else "")
        shape = "" if value.ndim == 1 else f" of shape {value.shape}"
        return f"ndarray{shape} [{head}]"
    shown = " ".join(repr(value).split())  # one line, whatever arrived
    return f"{type(value).__name__} {shown if len(shown) <= 60 else shown[:57] + '...'}"


def bare_number_message(name: str, unit, example: str, value) -> str:
    """The one-line refusal of a bare number where a Quantity of ``unit``'s physical type is needed.

    ``name`` is the argument, ``example`` a correct value to copy (``"2.18e-4 * u.rad / u.s"``) and
    ``value`` what arrived. Used by :func:`value_in`; a check of its own (an ``isinstance`` test before
    a conversion) raises ``QuantityInputError`` with this message, so every refusal reads the same.
    """
    kind = _kind(unit)
    article = "an" if kind[0] in "aeiou" else "a"
    return (f"{name} expects {article} {kind} Quantity (e.g. {example}); got the bare {_bare(value)}: units are "
            "never guessed, multiply by the unit meant.")


def require_quantity(name: str, value, unit, example: str) -> None:
    """Raise ``QuantityInputError`` with :func:`bare_number_message` unless ``value`` is a Quantity.

    For checks of their own that read a Quantity's physical type before converting it (a G·M, an
    acceleration): the bare number is refused in the same words as by :func:`value_in`.
    """
    if not isinstance(value, u.Quantity):
        raise QuantityInputError(bare_number_message(name, unit, example, value))


def _frequency_advice(name: str, value, unit: u.UnitBase) -> str:
    time_unit = (u.rad / unit).to_string()  # the time unit of the expected rate: d for rad / d
    return (
        f"{name}: got {value!s}, a frequency, where an angular velocity (an angle per time, {unit}) is needed. A frequency "
        "is ambiguous for a rotation (1 Hz = 1 rad/s by astropy's dimensionless conversion, but one turn per second is "
        f"2π rad/s), so spinorbit refuses it. Write turns per time with u.cycle (e.g. cycle / {time_unit}, converted "
        f"with 2π) or an angle per time (rad / {time_unit}, deg / {time_unit})."
    )


def value_in(name: str, value, unit, example: str, *, finite: bool = True,
             shape: tuple | None = None) -> np.ndarray | float:
    """``value`` as plain floats in ``unit``, after checking its physical type.

    Parameters
    ----------
    name : str
        The argument or option, as the user wrote it (``"angular_velocity"``, ``"--span"``).
    value : Quantity or array_like
        A Quantity of ``unit``'s physical type. Plain numbers only where ``unit`` is dimensionless; for
        a dimensional ``unit`` they are refused with :func:`bare_number_message` (units are never guessed).
    unit : str or astropy unit
        The unit the caller works in (``rad / day``, ``day``, ``kg m2``).
    example : str
        A correct value to show in the message (``"0.1 * u.rad / u.s"``).
    finite : bool
        Refuse NaN and ±inf (default).
    shape : tuple, optional
        The shape the value must have (``()`` for a scalar).

    Returns
    -------
    float or ndarray
        A float for a scalar, else an ndarray.

    Raises
    ------
    QuantityInputError
        Wrong physical type (a frequency where a rotation rate is needed gets its own advice), a
        plain number where a Quantity is needed, or text that is not a number.
    ValueError
        NaN/inf with ``finite``, or the wrong shape.
    """
    unit = u.Unit(unit)
    if isinstance(value, u.Quantity):
        expected_type, value_type = unit.physical_type, value.unit.physical_type  # each read costs ~1 µs: once
        if expected_type == _ANGULAR_VELOCITY and value_type == _FREQUENCY:
            raise QuantityInputError(_frequency_advice(name, value, unit))
        try:
            values = value.to_value(unit, equivalencies=u.dimensionless_angles())
        except u.UnitConversionError:
            raise QuantityInputError(
                f"{name}: expected a Quantity in {_expected(unit)} such as {example}; got "
                f"{_arrived(value)}."
            ) from None
        if expected_type != _DIMENSIONLESS and value_type != expected_type:
            # dimensionless_angles lets rad/day pass as 1/day; only the right physical type may pass
            raise QuantityInputError(
                f"{name}: expected a Quantity in {_expected(unit)} such as {example}; got "
                f"{_arrived(value)}."
            )
    elif unit.physical_type != _DIMENSIONLESS:
        require_quantity(name, value, unit, example)
    else:
        try:
            values = np.asarray(value, dtype=float) * u.dimensionless_unscaled.to(unit)
        except (TypeError, ValueError):
            raise QuantityInputError(f"{name}: expected a number or a dimensionless Quantity such as {example}; "
                                     f"got {_arrived(value)}.") from None
    values = np.asarray(values, dtype=float)
    if shape is not None and values.shape != tuple(shape):
        what = "a scalar" if shape == () else f"shape {tuple(shape)}"
        raise ValueError(f"{name}: expected {what} such as {example}; got shape {values.shape}.")
    if finite:
        finite_values(name, values, example)
    return float(values) if values.ndim == 0 else values


def finite_values(name: str, values, example: str = "") -> None:
    """Raise :class:`~spinorbit.core.errors.NonFiniteError` (a ``ValueError``) naming ``name`` and the first
    non-finite entry if any entry is NaN or ±inf."""
    values = np.asarray(values, dtype=float)
    bad = ~np.isfinite(values)
    if np.any(bad):
        first = float(values[bad].flat[0])
        raise NonFiniteError(f"{name}: expected finite numbers{f' such as {example}' if example else ''}; got "
                         f"{first!r}{f' among {values.size} values' if values.size > 1 else ''}.")


def parse_unit(option: str, text: str, unit, example: str) -> u.UnitBase:
    """An astropy unit of ``unit``'s physical type from command-line text (the checks of :func:`value_in`)."""
    try:
        result = u.Unit(text)
    except (TypeError, ValueError):
        raise QuantityInputError(f"{option} expects a unit of {_kind(unit)} such as {example}; got "
                                 f"'{text}', which astropy cannot read.") from None
    try:
        value_in(option, 1.0 * result, unit, example)
    except QuantityInputError:
        if _kind(unit) == "angular velocity" and _kind(result) == "frequency":
            raise QuantityInputError(_frequency_advice(option, f"'{text}'", u.Unit(unit))) from None
        raise QuantityInputError(f"{option} expects a unit of {_kind(unit)} such as {example}; got '{text}' "
                                 f"(physical type {_kind(result)}).") from None
    return result


def parse_quantity(option: str, words, unit, example: str, default_unit=None) -> u.Quantity:
    """One number and a unit from command-line words (``["100", "d"]`` or ``"100 d"``), checked.

    A number alone is in ``default_unit`` (``unit`` if None). Refused: text that is not one number
    followed by a unit (``"1 2 d"``, ``"[1, 2] d"``), NaN/inf, and the wrong physical type.
    """
    text = " ".join(words) if isinstance(words, (list, tuple)) else str(words)
    default_unit = u.Unit(unit if default_unit is None else default_unit)
    article = "an" if _kind(unit)[0] in "aeiou" else "a"
    hint = f"{article} {_kind(unit)} such as '{example}' (a number alone means {default_unit})"
    number, _, rest = text.strip().partition(" ")
    try:
        magnitude = float(number)
        quantity_unit = u.Unit(rest) if rest.strip() else default_unit
    except (TypeError, ValueError):
        raise QuantityInputError(f"{option} expects {hint}; got '{text}'.") from None
    if not math.isfinite(magnitude):
        raise QuantityInputError(f"{option} expects {hint}, finite; got '{text}'.")
    if getattr(quantity_unit, "scale", 1.0) != 1.0:  # "1 2 d" reads as 1 × (2 d): not what was meant
        raise QuantityInputError(f"{option} expects {hint}: one number, then the unit; got '{text}'.")
    try:
        value_in(option, magnitude * quantity_unit, unit, f"'{example}'")
    except QuantityInputError as error:
        if _kind(unit) == "angular velocity" and _kind(quantity_unit) == "frequency":
            raise QuantityInputError(_frequency_advice(option, f"'{text}'", u.Unit(unit))) from error
        raise QuantityInputError(f"{option} expects {hint}; got '{text}' (physical type {_kind(quantity_unit)})."
                                 ) from error
    return magnitude * quantity_unit


def _numbers_in(result, depth=0):
    """(label, plain numbers) of every number a result carries: Quantities, arrays, floats, and the
    fields of tuples and dataclasses (two levels down, enough for the package's result records)."""
    if isinstance(result, u.Quantity):
        yield "", result.value
    elif isinstance(result, (np.ndarray, float, np.floating, complex)):
        yield "", result
    elif depth < 2 and isinstance(result, (tuple, list)):
        for k, item in enumerate(result):
            for label, values in _numbers_in(item, depth + 1):
                yield f"[{k}]{label}", values
    elif depth < 2 and dataclasses.is_dataclass(result) and not isinstance(result, type):
        for item in dataclasses.fields(result):
            for label, values in _numbers_in(getattr(result, item.name), depth + 1):
                yield f".{item.name}{label}", values


def _shown_arguments(function, args, kwargs):
    try:
        bound = inspect.signature(function).bind(*args, **kwargs)
    except TypeError:
        return ""
    parts = []
    for name, value in bound.arguments.items():
        if name in ("self", "cls"):
            continue
        text = f"{value:.4g}" if isinstance(value, u.Quantity) and value.isscalar else repr(value)
        parts.append(f"{name}={text if len(text) <= 40 else text[:37] + '...'}")
    return ", ".join(parts)


def finite_result(what, advice=""):
    """Decorate a public function of the units layer: its result is checked finite on the way out.

    Its inputs are checked on the way in (:func:`value_in`), so NaN or inf in the result, or an
    ``OverflowError`` or ``ZeroDivisionError`` on the way, means finite inputs beyond what double
    precision carries: :class:`~spinorbit.core.errors.NonFiniteError` names the function, the
    arguments and the part of the result, instead of a NaN handed on or a bare arithmetic error.
    Floating-point warnings inside are silenced, since the result is checked.
    """
    def decorate(function):
        @functools.wraps(function)
        def checked(*args, **kwargs):
            try:
                with np.errstate(over="ignore", invalid="ignore", divide="ignore", under="ignore"):
                    result = function(*args, **kwargs)
            except (OverflowError, ZeroDivisionError) as error:
                failure = "overflowed" if isinstance(error, OverflowError) else "divided by zero (a term underflowed to 0)"
                raise NonFiniteError(
                    f"{what}: the arithmetic {failure} for {_shown_arguments(function, args, kwargs)}: "
                    f"{advice or 'the inputs lie beyond what double precision carries through this computation'}. "
                    "Give values in the physical range (check their units and magnitudes).") from None
            for label, values in _numbers_in(result):
                if all_finite(values) is False:  # the message (and its argument list) only when needed
                    require_finite_result(
                        f"{what}{label} for {_shown_arguments(function, args, kwargs)}", values, advice)
            return result
        return checked
    return decorate
