"""Photometric observations: one table with each observation's epoch, magnitude, uncertainty, filter and observer.

The files (:mod:`spinorbit.photometry.alcdef`, :mod:`spinorbit.photometry.damit`) read into it, an astropy ``TimeSeries`` of one's own turns
into it (:func:`photometric_observations`), and the fit to brightness reads it. Columns:

- ``time``: the observation's epoch (mid-exposure; UTC for ALCDEF), an astropy Time;
- ``magnitude``, ``magnitude_error`` (mag): the measurement and its 1σ uncertainty;
- ``filter``: the ALCDEF filter code (:data:`KNOWN_FILTERS`);
- ``observer``: who observed from where: an MPC observatory code or a DE421 body (``"earth"`` for
  the geocentre, which is what the geometry uses; the topocentric parallax is not applied);
- ``session``: the lightcurve the row belongs to (an ALCDEF block, a DAMIT lightcurve), from 0.

``table.meta["sessions"]`` holds each session's metadata (its ALCDEF keywords) in session order.
"""

from __future__ import annotations

import numpy as np
from astropy import units as u
from astropy.table import Table
from astropy.time import Time
from astropy.timeseries import TimeSeries

from spinorbit.ephemeris import DE421_SPAN_JD_TDB
from spinorbit.photometry.errors import PhotometryError

__all__ = ["KNOWN_FILTERS", "COLUMNS", "UnknownFilterError", "MissingUncertaintyError", "ObservationSpanError",
           "photometric_observations", "check_observations"]

#: ALCDEF's filter codes: clear, Johnson–Cousins U B V R I, Sloan u′ g′ r′ i′ z′ (SU … SZ), and the
#: near-infrared J H K.
KNOWN_FILTERS = ("C", "U", "B", "V", "R", "I", "SU", "SG", "SR", "SI", "SZ", "J", "H", "K")
#: The columns every observation table has, in order.
COLUMNS = ("time", "magnitude", "magnitude_error", "filter", "observer", "session")


class UnknownFilterError(PhotometryError):
    """A filter code that is not one of :data:`KNOWN_FILTERS` (or of the ``filters`` given)."""


class MissingUncertaintyError(PhotometryError):
    """An observation without a finite, positive magnitude uncertainty: it cannot be weighted in a fit."""


class ObservationSpanError(PhotometryError):
    """An observation outside DE421's span, where the Earth's and the Sun's positions are not known here."""


def check_observations(table, filters=KNOWN_FILTERS):
    """Raise the specific error of the first problem of an observation table (module docstring), else return it.

    Raises
    ------
    PhotometryError
        A missing column, or a magnitude that is not finite.
    MissingUncertaintyError
        An uncertainty that is missing, not finite or not positive.
    UnknownFilterError
        A filter outside ``filters``.
    ObservationSpanError
        An epoch outside DE421's span (1899-12-04 to 2200-02-01 TDB).
    """
    missing = [name for name in COLUMNS if name not in table.colnames]
    if missing:
        raise PhotometryError(f"observations: expected the columns {', '.join(COLUMNS)}; {', '.join(missing)} missing. "
                              "Build the table with photometric_observations(...).")
    magnitudes = table["magnitude"].to_value(u.mag)
    if not np.all(np.isfinite(magnitudes)):
        raise PhotometryError(f"magnitude: expected finite magnitudes; row {int(np.argmax(~np.isfinite(magnitudes)))} is "
                              f"{magnitudes[~np.isfinite(magnitudes)][0]!r}.")
    errors = table["magnitude_error"].to_value(u.mag)
    bad = ~(np.isfinite(errors) & (errors > 0))
    if np.any(bad):
        row = int(np.argmax(bad))
        raise MissingUncertaintyError(
            f"magnitude_error: expected a finite uncertainty > 0 for every observation; row {row} (time "
            f"{table['time'][row].iso}) has {errors[row]!r}. A fit weights each point by 1/σ²; give the session's "
            "scatter if the file has none.")
    unknown = sorted(set(np.asarray(table["filter"], dtype=str)) - set(filters))
    if unknown:
        raise UnknownFilterError(f"filter: expected one of {', '.join(filters)} (ALCDEF's codes); got {unknown}. Map "
                                 "the filter to its ALCDEF code, or pass filters=(..., your code) if it is one.")
    # In the times' own scale: UTC, TT and TDB differ by ≤ 2 min here, and a UTC time beyond the leap-second
    # table must not be converted just to be refused.
    jd = table["time"].jd
    outside = (jd < DE421_SPAN_JD_TDB[0]) | (jd > DE421_SPAN_JD_TDB[1])
    if np.any(outside):
        raise ObservationSpanError(
            f"time: {int(outside.sum())} observation(s) outside DE421's span (JD {DE421_SPAN_JD_TDB[0]}–"
            f"{DE421_SPAN_JD_TDB[1]} TDB), first at JD {jd[outside][0]:.5f}: the Earth's and the Sun's positions are "
            "not known there. Drop them.")
    return table


def photometric_observations(data, magnitude="magnitude", magnitude_error="magnitude_error", filter=None,
                             observer="earth", session=None, filters=KNOWN_FILTERS):
    """An observation table (module docstring) from an astropy ``TimeSeries`` or any table with a ``time`` column.

    Parameters
    ----------
    data : astropy.timeseries.TimeSeries or astropy.table.Table
        With a ``time`` column (Time) and magnitude columns (mag Quantities or numbers in mag).
    magnitude, magnitude_error : str
        The names of the magnitude and uncertainty columns in ``data``.
    filter : str, optional
        The filter of every row, when ``data`` has no ``filter`` column.
    observer : str
        The observer of every row, when ``data`` has no ``observer`` column ("earth": the geocentre).
    session : int, optional
        The session of every row, when ``data`` has no ``session`` column (default 0).
    filters : sequence of str
        The filter codes accepted.

    Returns
    -------
    astropy.timeseries.TimeSeries
        Checked by :func:`check_observations`.
    """
    if not isinstance(data, Table) or "time" not in data.colnames or not isinstance(data["time"], Time):
        raise PhotometryError(f"data: expected an astropy TimeSeries (or a Table with a 'time' Time column); got "
                              f"{type(data).__name__}{' without a time column' if isinstance(data, Table) else ''}.")
    for name, label in ((magnitude, "magnitude"), (magnitude_error, "magnitude_error")):
        if name not in data.colnames:
            if label == "magnitude_error":
                raise MissingUncertaintyError(f"{label}: data has no column {name!r} (it has {data.colnames}); every "
                                              "observation needs its uncertainty. Name it with magnitude_error=...")
            raise PhotometryError(f"{label}: data has no column {name!r} (it has {data.colnames}).")

    def in_mag(name):
        column = data[name]
        if isinstance(column, u.Quantity):
            if column.unit.physical_type != u.mag.physical_type and column.unit != u.mag:
                raise PhotometryError(f"{name}: expected magnitudes (mag); got {column.unit}.")
            return column.to_value(u.mag)
        return np.asarray(column, dtype=float)

    n = len(data)
    table = TimeSeries(time=data["time"])
    table["magnitude"] = in_mag(magnitude) * u.mag
    table["magnitude_error"] = in_mag(magnitude_error) * u.mag
    for name, default in (("filter", filter), ("observer", observer), ("session", 0 if session is None else session)):
        if name in data.colnames:
            table[name] = np.asarray(data[name])
        elif default is None:
            raise UnknownFilterError("filter: data has no filter column and none was given; pass filter='V' (an ALCDEF "
                                     "code) for the whole table.")
        else:
            table[name] = np.full(n, default)
    table.meta.update(data.meta)
    table.meta.setdefault("sessions", [{} for _ in range(int(np.max(table["session"], initial=-1)) + 1)])
    return check_observations(table, filters)
