"""Time bridge: ``astropy.time.Time`` ↔ core time (TDB days since J2000) in two-float form.

The core works on plain floats: **days since J2000.0 TDB** (JD 2451545.0 TDB), see
``docs/conventions.md``. This module is the only place where a ``Time`` becomes such a float, and
it does so without losing precision:

- :func:`tdb_day_and_fraction` splits the time into a whole number of days since J2000 and a
  fraction of a day in [−0.5, 0.5], both exact (astropy's own jd1/jd2 are re-split, not summed).
- :func:`tdb_days` gives the float the core wants plus the remainder that the float could not hold
  (``days + remainder`` is the exact time); the remainder is below half a unit in the last place of
  ``days`` (≤ 0.32 µs anywhere in 1900–2100, see :data:`FLOAT_DAYS_RESOLUTION_1900_2100`).
- :func:`time_from_tdb_days` goes back to a ``Time``.

Scale conversions TT ↔ TAI ↔ UTC ↔ TDB use only the leap-second table that astropy ships
(``astropy-iers-data``); nothing here downloads anything. UT1 needs Earth-orientation tables: it is
converted with automatic downloads switched off, and a clear :class:`TimeScaleError` explains what to
do if the bundled tables do not cover the date.
"""

from __future__ import annotations

import contextlib
import datetime as _dt
import warnings

import numpy as np
from astropy.time import Time, TimeDelta
from erfa import ErfaWarning

__all__ = [
    "J2000_JD_TDB",
    "FLOAT_DAYS_RESOLUTION_1900_2100",
    "TimeScaleError",
    "tdb_day_and_fraction",
    "tdb_days",
    "time_from_tdb_days",
]

#: Julian date of the core's time origin, J2000.0, on the TDB scale.
J2000_JD_TDB = 2451545.0

#: Worst rounding error (days) of a *single* float holding TDB days since J2000 in 1900–2100:
#: |t| < 2¹⁶ days there, so the spacing of doubles is 2^(15−52) d = 7.3e-12 d and rounding costs at
#: most half of it, 3.6e-12 d = 0.31 µs. The remainder returned by :func:`tdb_days` carries the rest.
FLOAT_DAYS_RESOLUTION_1900_2100 = 2.0 ** (15 - 52) / 2.0

# Scales astropy accepts that can be converted to TDB offline. 'local' has no relation to any
# astronomical scale and is refused.
_CONVERTIBLE_SCALES = ("tai", "tcb", "tcg", "tdb", "tt", "ut1", "utc")


class TimeScaleError(ValueError):
    """A time (or requested output scale) that cannot be brought to or from TDB offline."""


def _check_time(time) -> Time:
    """Return ``time`` if it is an astropy ``Time`` on a scale convertible to TDB, else raise."""
    if isinstance(time, (_dt.datetime, np.datetime64)) or (
        isinstance(time, np.ndarray) and time.dtype.kind == "M"
    ):
        aware = isinstance(time, _dt.datetime) and time.tzinfo is not None
        raise TypeError(
            "expected an astropy.time.Time; got a "
            + ("timezone-aware datetime" if aware else "datetime without a time scale")
            + f" ({time!r}). A datetime does not say which time scale it is on: wrap it as "
            "astropy.time.Time(value, scale='utc') (or 'tt', 'tdb', ...) to say so."
        )
    if not isinstance(time, Time):
        raise TypeError(
            f"expected an astropy.time.Time; got {type(time).__name__} ({time!r}). "
            "Build one with astropy.time.Time(value, format=..., scale=...); for core times "
            "already in TDB days since J2000 use spinorbit.time.time_from_tdb_days."
        )
    if time.scale not in _CONVERTIBLE_SCALES:
        raise TimeScaleError(
            f"time scale {time.scale!r} cannot be converted to TDB; expected one of "
            f"{_CONVERTIBLE_SCALES}. A 'local' time has no defined relation to atomic or dynamical "
            "time: create the Time on the scale it really is on."
        )
    return time


@contextlib.contextmanager
def _geocentric_tdb_tt_without_utc_warning():
    """Silence ERFA's "dubious year" warning raised *only* by astropy's TT ↔ TDB step.

    astropy computes TDB − TT with ``erfa.dtdb``, passing a UT fraction obtained through
    ``erfa.taiutc``; for a geocentric time (no ``location``) the UT argument multiplies zero, so the
    result does not depend on leap seconds at all, yet ERFA warns for dates outside its leap-second
    knowledge (before 1960, or a few years past its release). That warning says nothing about the
    TT ↔ TDB result and is silenced here, deliberately and only here. A UTC input in such a year
    still warns, from its own UTC → TAI step, which is run outside this context.
    """
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message=".*dubious year", category=ErfaWarning)
        yield


def _convert(time: Time, scale: str) -> Time:
    """``time`` on ``scale``, offline; UTC/UT1 legs warn as ERFA does, the TT ↔ TDB leg does not."""
    if time.scale == scale:
        return time
    # Imported here: astropy's IERS module loads astropy.table and its readers (0.13 s), which a run
    # that stays on one scale (TDB, as the Moon's) never needs.
    from astropy.utils import iers

    with iers.conf.set_temp("auto_download", False):
        try:
            if time.scale in ("utc", "ut1"):
                time = time.tt  # the step that really depends on leap seconds / UT1: warnings kept
            if scale in ("utc", "ut1"):
                with _geocentric_tdb_tt_without_utc_warning():
                    time = time.tt
                return getattr(time, scale)
            with _geocentric_tdb_tt_without_utc_warning():
                return getattr(time, scale)
        except (ValueError, iers.IERSRangeError) as error:  # stale or missing UT1−UTC tables
            raise TimeScaleError(
                f"converting a {time.scale.upper()} time to {scale.upper()} needs Earth-orientation "
                f"data the bundled IERS tables do not give offline ({error}). Use the UTC, TT or "
                "TDB scale instead, or provide up-to-date IERS tables yourself."
            ) from error


def _stored_jd(tdb: Time):
    """(jd1, jd2) of a TDB time: the doubles astropy stores, or its public properties where those differ.

    astropy's ``jd1``/``jd2`` properties cost ~8 µs each (they rebuild the input's shape and unbox a
    scalar) for the same numbers, so the stored ones are read when they are plainly the same: not
    masked, and held by astropy's format object with the time's own shape. ``_time`` is not public
    API; if a later astropy moves it, the public properties are used (``tests/test_time.py`` checks
    both give the same bits). Read on every call, never cached: a Time is mutable.
    """
    stored = getattr(tdb, "_time", None)
    jd1, jd2 = getattr(stored, "jd1", None), getattr(stored, "jd2", None)
    if (tdb.masked or not isinstance(jd1, np.ndarray) or not isinstance(jd2, np.ndarray)
            or jd1.shape != tdb.shape or jd2.shape != tdb.shape):
        return tdb.jd1, tdb.jd2
    return jd1, jd2


def tdb_day_and_fraction(time: Time) -> tuple[np.ndarray | float, np.ndarray | float]:
    """Split a time into whole TDB days since J2000 and a fraction of a day, both exact.

    Parameters
    ----------
    time : astropy.time.Time
        Scalar or array, on any scale convertible to TDB (not 'local').

    Returns
    -------
    day : float or ndarray
        Whole number of days since J2000.0 TDB (an integer stored as float), unit: day.
    fraction : float or ndarray
        Remaining fraction, in [−0.5, 0.5], unit: day. ``day + fraction`` is the time to
        astropy's own precision (better than a picosecond).

    Raises
    ------
    TypeError
        If ``time`` is not a ``Time`` (for example a naive ``datetime``).
    TimeScaleError
        If the scale is 'local', or a UT1 time is outside the bundled IERS tables.
    """
    tdb = _convert(_check_time(time), "tdb")
    # astropy keeps jd1 integer-valued (or half-integer) and |jd2| ≤ 0.5 d; jd1 − J2000 is an exact
    # difference of integers. Re-splitting with round() moves only exactly representable values.
    jd1, jd2 = _stored_jd(tdb)
    offset = jd1 - J2000_JD_TDB
    day = np.round(offset + jd2)
    fraction = (offset - day) + jd2
    if np.ndim(day) == 0:
        return float(day), float(fraction)
    return day, fraction


def tdb_days(time: Time) -> tuple[np.ndarray | float, np.ndarray | float]:
    """Core time: TDB days since J2000 as one float, plus what the float could not hold.

    Parameters
    ----------
    time : astropy.time.Time
        Scalar or array, on any scale convertible to TDB.

    Returns
    -------
    days : float or ndarray
        TDB days since J2000.0, the nearest double to the exact value, unit: day.
    remainder : float or ndarray
        ``exact − days``, unit: day; |remainder| ≤ half the spacing of doubles at ``days``
        (≤ :data:`FLOAT_DAYS_RESOLUTION_1900_2100` = 3.6e-12 d = 0.31 µs in 1900–2100).

    Raises
    ------
    TypeError, TimeScaleError
        As :func:`tdb_day_and_fraction`.

    Notes
    -----
    The remainder is the error term of Knuth's two-sum of (day, fraction): exact by construction.
    """
    day, fraction = tdb_day_and_fraction(time)
    days = day + fraction
    remainder = fraction - (days - day)  # Fast two-sum; valid because |day| ≥ |fraction| or day = 0.
    return days, remainder


def time_from_tdb_days(days, remainder=0.0, scale: str = "tdb") -> Time:
    """Build an astropy ``Time`` from core time (TDB days since J2000).

    Parameters
    ----------
    days : float or array_like
        TDB days since J2000.0, unit: day.
    remainder : float or array_like, optional
        Small correction added to ``days`` without rounding (as returned by :func:`tdb_days`),
        unit: day.
    scale : str, optional
        Scale of the returned ``Time`` (default 'tdb'); any of
        'tai', 'tcb', 'tcg', 'tdb', 'tt', 'ut1', 'utc'.

    Returns
    -------
    astropy.time.Time
        In Julian-date format, on ``scale``.

    Raises
    ------
    TypeError
        If ``days`` is not numeric (e.g. a ``Time`` or ``Quantity`` was passed).
    TimeScaleError
        If ``scale`` is not a known convertible scale.
    """
    if isinstance(days, (Time, TimeDelta)) or hasattr(days, "unit"):
        raise TypeError(
            f"expected plain float days since J2000 TDB; got {type(days).__name__}. "
            "Pass a Time to tdb_days() instead, or strip units with quantity.to_value(u.day)."
        )
    days = np.asarray(days, dtype=float)
    remainder = np.asarray(remainder, dtype=float)
    if scale not in _CONVERTIBLE_SCALES:
        raise TimeScaleError(
            f"unknown output time scale {scale!r}; expected one of {_CONVERTIBLE_SCALES}."
        )
    whole = np.round(days)
    fraction = (days - whole) + remainder  # days − whole is exact (Sterbenz)
    if whole.ndim == 0 and fraction.ndim == 0:
        whole, fraction = float(whole), float(fraction)
    time = Time(J2000_JD_TDB + whole, fraction, format="jd", scale="tdb")
    return _convert(time, scale)
