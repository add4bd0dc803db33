"""DAMIT's lightcurve format (the ``lc`` files of the Database of Asteroid Models from Inversion Techniques).

The format of Kaasalainen's ``convexinv`` and of DAMIT's lightcurve downloads (Ďurech, Sidorin &
Kaasalainen 2010, A&A 513, A46; the ``convexinv`` documentation) is plain numbers::

    2                                   number of lightcurves
    3 0                                 points in the first, 0: relative (1: calibrated)
    2452254.21401  1.0213   x☉ y☉ z☉   x⊕ y⊕ z⊕
    ...

Each point is the JD **corrected for light time** (the time at the body), the brightness as an
intensity (not a magnitude; for a relative lightcurve its scale is arbitrary), and the
asteroid-centric ecliptic J2000 vectors to the Sun and to the Earth (the observer) in au.

:func:`read_damit` returns a ``TimeSeries`` with ``time`` (TDB, the body's time), ``brightness``
(dimensionless), ``sun_vector`` and ``observer_vector`` (ICRF, au), ``calibrated`` and ``session``.
The vectors turn into the body frame with the attitudes at those times and feed
:func:`spinorbit.photometry.brightness` directly. :func:`write_damit` writes the columns of a
:func:`spinorbit.photometry.lightcurve` table.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from astropy import units as u
from astropy.time import Time
from astropy.timeseries import TimeSeries

from spinorbit.frames import ecliptic_to_icrf, icrf_to_ecliptic
from spinorbit.photometry.errors import PhotometryError
from spinorbit.runs.atomic import write_bytes_atomically

__all__ = ["DAMITFormatError", "read_damit", "write_damit"]


class DAMITFormatError(PhotometryError):
    """A file that is not in DAMIT's lightcurve format (counts that do not match, fields that are not numbers)."""


def _numbers(line, number, where, count):
    fields = line.split()
    if len(fields) != count:
        raise DAMITFormatError(f"{where}, line {number}: expected {count} numbers; got {len(fields)} ({line.strip()!r}).")
    try:
        return [float(x) for x in fields]
    except ValueError:
        raise DAMITFormatError(f"{where}, line {number}: {line.strip()!r} is not all numbers.") from None


def read_damit(source):
    """Read a DAMIT lightcurve file (module docstring).

    Parameters
    ----------
    source : str or Path
        A path, or the file's text.

    Returns
    -------
    astropy.timeseries.TimeSeries

    Raises
    ------
    DAMITFormatError
        Counts that do not match the points, a flag other than 0 or 1, or a non-number.
    """
    if isinstance(source, Path) or (isinstance(source, str) and "\n" not in source.strip()):
        where, text = str(source), Path(source).read_text()
    else:
        where, text = "the text given", str(source)
    lines = [(i, line) for i, line in enumerate(text.splitlines(), start=1) if line.strip()]
    if not lines:
        raise DAMITFormatError(f"{where}: empty; expected the number of lightcurves on the first line.")
    count = _numbers(lines[0][1], lines[0][0], where, 1)[0]
    if count != int(count) or count < 1:
        raise DAMITFormatError(f"{where}, line {lines[0][0]}: expected a positive number of lightcurves; got {count!r}.")
    position, rows, sessions, calibrated = 1, [], [], []
    for session in range(int(count)):
        if position >= len(lines):
            raise DAMITFormatError(f"{where}: {int(count)} lightcurves announced, the file ends after {session}.")
        number, header = lines[position]
        points, flag = _numbers(header, number, where, 2)
        if points != int(points) or points < 1 or flag not in (0.0, 1.0):
            raise DAMITFormatError(f"{where}, line {number}: expected 'points flag' with points ≥ 1 and flag 0 (relative) "
                                   f"or 1 (calibrated); got {header.strip()!r}.")
        block = lines[position + 1: position + 1 + int(points)]
        if len(block) < points:
            raise DAMITFormatError(f"{where}, line {number}: {int(points)} points announced, {len(block)} follow.")
        rows += [_numbers(line, i, where, 8) for i, line in block]
        sessions += [session] * int(points)
        calibrated += [bool(flag)] * int(points)
        position += 1 + int(points)
    if position != len(lines):
        raise DAMITFormatError(f"{where}, line {lines[position][0]}: more lines than the {int(count)} lightcurves announced.")
    data = np.array(rows)
    table = TimeSeries(time=Time(data[:, 0], format="jd", scale="tdb"))
    table["brightness"] = data[:, 1]
    table["sun_vector"] = ecliptic_to_icrf(data[:, 2:5]) * u.au
    table["observer_vector"] = ecliptic_to_icrf(data[:, 5:8]) * u.au
    table["calibrated"] = np.array(calibrated)
    table["session"] = np.array(sessions)
    table.meta["source"] = where
    return table


def write_damit(table, path, calibrated=False):
    """Write a lightcurve table as a DAMIT file, one lightcurve per ``session`` (atomically).

    Parameters
    ----------
    table : astropy.timeseries.TimeSeries
        With ``body_time`` (or ``time``, taken as the body's time), ``sun_vector`` and
        ``observer_vector`` (body-centric ICRF, length) and ``brightness`` (any scale) or ``magnitude``
        (turned into the intensity 10^(−0.4 m)); ``session`` if several lightcurves.
    path : str or Path
    calibrated : bool
        The flag of every lightcurve: False (0, relative) or True (1, calibrated).
    """
    for name in ("sun_vector", "observer_vector"):
        if name not in table.colnames:
            raise DAMITFormatError(f"table: expected a {name} column (body-centric ICRF, au) as in a "
                                   "spinorbit.photometry.lightcurve table; it has {table.colnames}.")
    times = table["body_time"] if "body_time" in table.colnames else table["time"]
    if "magnitude" in table.colnames:
        intensity = 10.0 ** (-0.4 * table["magnitude"].to_value(u.mag))
    elif "brightness" in table.colnames:
        intensity = np.asarray(u.Quantity(table["brightness"]).value, dtype=float)
    else:
        raise DAMITFormatError("table: expected a magnitude or a brightness column to write as the intensity.")
    sun = icrf_to_ecliptic(u.Quantity(table["sun_vector"]).to_value(u.au))
    observer = icrf_to_ecliptic(u.Quantity(table["observer_vector"]).to_value(u.au))
    sessions = np.asarray(table["session"], dtype=int) if "session" in table.colnames else np.zeros(len(table), int)
    lines = [str(len(np.unique(sessions)))]
    for session in np.unique(sessions):
        rows = np.nonzero(sessions == session)[0]
        lines.append(f"{rows.size} {int(bool(calibrated))}")
        for i in rows:
            lines.append(f"{times[i].tdb.jd:.8f} {intensity[i]:.10e} " + " ".join(f"{x:.12f}" for x in (*sun[i], *observer[i])))
    write_bytes_atomically(Path(path), ("\n".join(lines) + "\n").encode("ascii"))
    return Path(path)
