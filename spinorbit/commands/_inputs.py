"""The one validation layer of the command line and the scene file: types, units and ranges, before any work.

Every value a user gives — an option's words from argparse, a key of a TOML scene file — passes
through one of these checkers before the command does anything. Each takes ``where`` (the option or
key as the user wrote it: ``"--rtol"``, ``"[run] n_times"``) and the raw value, and returns the value
as the command needs it (a float, an int, an astropy Quantity or Time) or raises
:class:`spinorbit.InputError`, whose message says what was expected, what arrived (described by
:func:`shown`, in the user's terms: "the string 'sun'", "the float 4.5") and what to do.

The messages are written here from the values themselves; no message is built from another
exception's text (issue 36: a message split out of an ERFA error ended in an IndexError).
"""

from __future__ import annotations

import datetime
import math
import re

from spinorbit.core.errors import InputError

#: Dates the commands accept and write: the years astropy reads and writes as ISO text (1 to 9999),
#: as Julian dates (TDB). ERFA refuses calendar dates much outside it (issue 36: an ErfaError).
FIRST_JD, LAST_JD = 1721425.5, 5373484.5
#: Dask's address schemes (distributed.comm), and the form of a scheduler address.
SCHEDULER_SCHEMES = ("tcp", "tls", "inproc", "ucx", "ws", "wss")
_ADDRESS = re.compile(r"^(?:(?P<scheme>[a-z]+)://)?(?P<host>\[[0-9a-fA-F:]+\]|[A-Za-z0-9.\-_]+):(?P<port>\d+)$")


def shown(value) -> str:
    """What arrived, in words and without numpy reprs: "the string 'sun'", "the list [1, 2]", "the float 4.5"."""
    value = getattr(value, "tolist", lambda: value)()  # numpy scalars and arrays as plain Python
    if isinstance(value, bool):
        return f"the boolean {str(value).lower()}"
    if isinstance(value, str):
        text = value if len(value) <= 60 else value[:57] + "..."
        return f"the string {text!r}" if value.strip() else "an empty string"
    if isinstance(value, (int, float)):
        return f"the {'integer' if isinstance(value, int) else 'float'} {value!r}"
    if isinstance(value, (list, tuple)):
        text = "[" + ", ".join(_plain(item) for item in value) + "]"
        return f"the list {text if len(text) <= 70 else text[:67] + '...'}"
    if isinstance(value, dict):
        return f"a table with keys {sorted(map(str, value))}"
    if isinstance(value, (datetime.date, datetime.time)):
        return f"the date {value.isoformat()}"
    return f"a {type(value).__name__}"


def arrived(where: str, value) -> str:
    """:func:`shown`, with an option's words as the user typed them ("the text '-8 h'", not a list)."""
    if where.startswith("--") and isinstance(value, str):
        return f"'{value}'"
    if where.startswith("--") and isinstance(value, (int, float)) and not isinstance(value, bool):
        return f"{value:g}"  # argparse already made a number of the word
    if where.startswith("--") and isinstance(value, (list, tuple)) and all(isinstance(v, str) for v in value):
        return f"'{words_of(value)}'"
    return shown(value)


def _plain(item) -> str:
    item = getattr(item, "tolist", lambda: item)()
    return repr(item) if isinstance(item, (str, int, float, bool)) else shown(item)


def words_of(value) -> str:
    """An option's words or a file's text as one string (argparse gives ``--span 1 yr`` as two words)."""
    return " ".join(map(str, value)) if isinstance(value, (list, tuple)) else str(value)


# -- plain values -----------------------------------------------------------------------------------


def text(where: str, value, example: str) -> str:
    """A non-empty string (a name, a file path): anything else is refused, so ``output = 5`` is not a path."""
    if not isinstance(value, str) or not value.strip():
        raise InputError(where, f"text such as {example!r}", arrived(where, value), "Quote it in the scene file.")
    return value


def boolean(where: str, value) -> bool:
    """``true`` or ``false`` (TOML's booleans; not 0/1, not "yes")."""
    if not isinstance(value, bool):
        raise InputError(where, "true or false", arrived(where, value))
    return value


def choice(where: str, value, choices) -> str:
    """One of ``choices`` (strings)."""
    if not isinstance(value, str) or value not in choices:
        raise InputError(where, f"one of {', '.join(map(repr, choices))}", arrived(where, value))
    return value


def _bounds(low, high, low_open, high_open) -> str:
    low, high = (f"{end:g}" if isinstance(end, float) else end for end in (low, high))  # ints in full: 100000
    if low is not None and high is not None:
        return f" in {'(' if low_open else '['}{low}, {high}{')' if high_open else ']'}"
    if low is not None:
        return f" {'>' if low_open else '≥'} {low}"
    if high is not None:
        return f" {'<' if high_open else '≤'} {high}"
    return ""


def _in_bounds(value, low, high, low_open, high_open) -> bool:
    above = low is None or (value > low if low_open else value >= low)
    below = high is None or (value < high if high_open else value <= high)
    return above and below


def number(where: str, value, example: str, *, low=None, high=None, low_open=False, high_open=False,
           advice: str = "") -> float:
    """A finite float within the bounds, from a number (TOML) or its text (an option's word).

    Refused: booleans, text that is not one number, NaN and ±inf, a number float64 cannot hold as
    written (``1e400``, ``1e-400``), and values outside ``[low, high]`` (``low_open``/``high_open``
    exclude the ends).
    """
    expected = f"a finite number{_bounds(low, high, low_open, high_open)} such as {example}"
    raw = value
    if isinstance(value, (list, tuple)) and len(value) == 1:
        value = value[0]
    if isinstance(value, bool) or not isinstance(value, (int, float, str)):
        raise InputError(where, expected, arrived(where, raw), advice)
    if isinstance(value, str):
        try:
            result = float(value)
        except ValueError:
            raise InputError(where, expected, arrived(where, raw), advice) from None
        mantissa = value.strip().lower().split("e")[0]
        if result == 0.0 and any(digit in mantissa for digit in "123456789"):
            raise InputError(where, expected, f"{arrived(where, raw)}, which underflows to 0 in double precision", advice)
    else:
        try:
            result = float(value)
        except OverflowError:  # an int beyond float64
            raise InputError(where, expected, f"the integer {value:.3g}", advice) from None
    if not math.isfinite(result) or not _in_bounds(result, low, high, low_open, high_open):
        raise InputError(where, expected, arrived(where, raw), advice)
    return result


def integer(where: str, value, example: str, *, low=None, high=None, advice: str = "") -> int:
    """A whole number within ``[low, high]``, from an int (TOML) or its text; a float such as 4.5 or 4.0 is refused."""
    expected = f"a whole number{_bounds(low, high, False, False)} such as {example}"
    raw = value
    if isinstance(value, (list, tuple)) and len(value) == 1:
        value = value[0]
    if isinstance(value, str):
        try:
            value = int(value) if "_" not in value else None  # int() reads "1_000"; no option documents it
        except ValueError:
            value = None
        if value is None:
            raise InputError(where, expected, arrived(where, raw), advice)
    if isinstance(value, bool) or not isinstance(value, int) or not _in_bounds(value, low, high, False, False):
        raise InputError(where, expected, arrived(where, raw), advice)
    return value


def seed(where: str, value) -> int:
    """A random seed: a whole number ≥ 0 (numpy's SeedSequence refuses negative ones)."""
    return integer(where, value, "12345", low=0, advice="Give the seed printed by an earlier run to repeat it.")


def scheduler_address(where: str, value) -> str:
    """A Dask scheduler address, ``[scheme://]host:port`` with a port from 1 to 65535."""
    expected = f"a Dask scheduler address such as 'tcp://10.0.0.1:8786' (scheme {', '.join(SCHEDULER_SCHEMES)})"
    match = _ADDRESS.match(value) if isinstance(value, str) else None
    if match is None or (match["scheme"] or "tcp") not in SCHEDULER_SCHEMES or not 1 <= int(match["port"]) <= 65535:
        raise InputError(where, expected, arrived(where, value), "A running scheduler prints its address when it starts.")
    return value


def names(where: str, value, example: str, choices=None) -> list[str]:
    """A list of names (perturbers); one string alone is refused, not read letter by letter."""
    if isinstance(value, str):
        raise InputError(where, f"a list of names such as {example}", arrived(where, value),
                         f"Write a list, even of one name: [{value!r}].")
    if not isinstance(value, (list, tuple)) or not all(isinstance(item, str) and item.strip() for item in value):
        raise InputError(where, f"a list of names such as {example}", arrived(where, value))
    if choices is not None:
        unknown = [item for item in value if item.lower() not in choices]
        if unknown:
            raise InputError(where, f"names among {', '.join(choices)}", arrived(where, value), f"{unknown[0]!r} is not one.")
    return list(value)


# -- quantities -------------------------------------------------------------------------------------


def _unit_kind(unit) -> str:
    from astropy import units as u

    return str(u.Unit(unit).physical_type).split("/")[-1]


def quantity(where: str, value, unit: str, example: str, *, default_unit: str | None = None, low=None, high=None,
             low_open=False, high_open=False, advice: str = ""):
    """A Quantity of ``unit``'s physical type from text (``"8 h"``) or an option's words (``["8", "h"]``).

    A number without a unit is read in ``default_unit`` (the unit the option's ``--help`` names) or,
    without one (the scene file), refused: units are never guessed. ``low``/``high`` bound the value
    in ``unit``.
    """
    from astropy import units as u

    from spinorbit.quantities import QuantityInputError, parse_quantity

    kind = _unit_kind(unit)
    article = "an" if kind[0] in "aeiou" else "a"
    alone = f" (a number alone is {default_unit})" if default_unit else ""
    bounds = _bounds(low, high, low_open, high_open)
    expected = f"{article} {kind}{bounds}{f' {unit}' if bounds else ''} such as '{example}'{alone}"
    if isinstance(value, bool) or not isinstance(value, (str, list, tuple, int, float)):
        raise InputError(where, expected, arrived(where, value), advice)
    if isinstance(value, (int, float)) or len(words_of(value).split()) == 1:
        if default_unit is None:
            raise InputError(where, expected, arrived(where, value), f"Write the unit: e.g. '{example}'; units are never guessed.")
    try:
        result = parse_quantity(where, words_of(value), unit, example, default_unit=default_unit or unit)
    except QuantityInputError:
        advice = " ".join(part for part in (_unit_advice(value, kind), advice) if part)
        raise InputError(where, expected, arrived(where, value), advice) from None
    magnitude = result.to_value(unit, equivalencies=u.dimensionless_angles())
    if not _in_bounds(magnitude, low, high, low_open, high_open):
        converted = f" ({magnitude:.6g} {unit})" if result.unit != u.Unit(unit) else ""
        raise InputError(where, expected, f"{arrived(where, value)}{converted}", advice)
    return result


def _unit_advice(value, kind: str) -> str:
    """Why a unit was refused, where a word helps: a frequency given for a rotation rate."""
    from astropy import units as u

    try:
        given = u.Unit(words_of(value).strip().partition(" ")[2])
    except (TypeError, ValueError):
        return ""
    if kind == "angular velocity" and _unit_kind(given) == "frequency":
        return ("A frequency is ambiguous for a rotation (astropy reads 1 Hz as 1 rad/s; one turn per second is "
                "2π rad/s): write turns per time as cycle/d, or an angle per time such as deg/d.")
    return f"{given} is a unit of {_unit_kind(given)}." if _unit_kind(given) != kind else ""


def vector(where: str, value, unit: str, example: str, *, count: int = 3, default_unit: str | None = None):
    """``count`` components and one unit, as a Quantity array.

    Taken as an option's words (``0 0 1080 deg/day``: the numbers, then the unit), one string of the
    same form, or (the scene file) a list of ``count`` quantities (``["0 deg/h", "0 deg/h", "45 deg/h"]``).
    Without a unit the numbers are in ``default_unit``, or refused when there is none.
    """
    from astropy import units as u

    expected = f"{count} numbers and a unit of {_unit_kind(unit)} such as '{example}'"
    if isinstance(value, (list, tuple)) and len(value) == count and not all(isinstance(v, str) for v in value[:count]):
        raise InputError(where, expected, arrived(where, value), "Write each component with its unit, or one string "
                         f"'{example}'.")
    if isinstance(value, (list, tuple)) and len(value) == count and all(len(v.split()) > 1 for v in value):
        component = " ".join(example.split()[count - 1:])  # "1080 deg/day" of "0 0 1080 deg/day"
        parts = [quantity(where, item, unit, component) for item in value]
        return u.Quantity([part.to(parts[0].unit, equivalencies=u.dimensionless_angles()) for part in parts])
    words = words_of(value).split() if isinstance(value, (str, list, tuple)) else None
    if not words or len(words) < count:
        raise InputError(where, expected, arrived(where, value))
    numbers = [number(where, word, example) if _is_number(word) else None for word in words[:count]]
    if None in numbers or (len(words) > count and _is_number(words[count])):
        raise InputError(where, expected, arrived(where, value), f"Give {count} numbers, then the unit.")
    unit_text = " ".join(words[count:]) or default_unit
    if unit_text is None:
        raise InputError(where, expected, arrived(where, value), "Write the unit after the numbers; units are never guessed.")
    try:
        one = quantity(where, f"1 {unit_text}", unit, example)
    except InputError as error:
        raise InputError(where, expected, arrived(where, value), error.advice) from None
    return numbers * one.unit


def _is_number(word: str) -> bool:
    try:
        float(word)
    except ValueError:
        return False
    return True


# -- times ------------------------------------------------------------------------------------------


def time(where: str, value, *, julian: bool = False):
    """A TDB astropy Time from ISO text (or a TOML date), inside :data:`FIRST_JD` .. :data:`LAST_JD`.

    ``julian``: a number (or its text) is also accepted, as a Julian date (TDB).
    """
    from astropy.time import Time

    expected = "a TDB date such as '2020-01-01T00:00:00'" + (" or a Julian date such as '2451545.0'" if julian else "")
    if isinstance(value, (datetime.date, datetime.datetime)) and not (isinstance(value, datetime.datetime)
                                                                     and value.tzinfo is not None):
        value = value.isoformat()
    if julian and not isinstance(value, bool) and isinstance(value, (int, float)):
        value = repr(value)
    if isinstance(value, datetime.datetime):  # with a time zone: UTC, which is not TDB
        raise InputError(where, expected, arrived(where, value), "Quote the date and give it in TDB, without a zone.")
    if not isinstance(value, str):
        raise InputError(where, expected, arrived(where, value))
    try:
        result = Time(float(value), format="jd", scale="tdb") if julian and _is_number(value) else \
            Time(value, scale="tdb")
    except (TypeError, ValueError):
        raise InputError(where, expected, arrived(where, value)) from None
    if result.ndim != 0:
        raise InputError(where, expected, arrived(where, value))
    check_date(where, result.jd1 + result.jd2, f"{arrived(where, value)}")
    return result


def check_date(where: str, jd: float, what: str, advice: str = "") -> None:
    """Refuse a date (TDB Julian date ``jd``) outside the years 1 to 9999, before ERFA is asked about it."""
    if not (math.isfinite(jd) and FIRST_JD <= jd <= LAST_JD):
        year = f" (near the year {2000 + (jd - 2451545.0) / 365.25:.3g})" if math.isfinite(jd) else ""
        raise InputError(where, "dates in the years 1 to 9999 (the dates astropy reads and writes as ISO text)",
                         f"{what}{year}", advice)
