"""ALCDEF, the Asteroid Lightcurve Data Exchange Format: read and write.

An ALCDEF file (Warner, Stephens et al., the ALCDEF Standard of the Minor Planet Center's
lightcurve archive, alcdef.org) is plain text, one ``KEYWORD=value`` per line. Each lightcurve
(session) is a block::

    STARTMETADATA
    OBJECTNUMBER=99942
    OBJECTNAME=Apophis
    SESSIONDATE=2013-01-10
    SESSIONTIME=03:14:00
    FILTER=V
    MAGBAND=V
    LTCAPP=NONE
    REDUCEDMAGS=NONE
    DELIMITER=PIPE
    COMMENT=...                     (any number)
    ENDMETADATA
    DATA=2456302.63924|15.432|0.021  (JD|MAG|MAGERR, optionally |AIRMASS)
    ...
    ENDDATA

The JD is the mid-exposure Julian date in UTC. ``LTCAPP`` says whether the JDs were corrected
for light time (NONE: not), ``REDUCEDMAGS`` whether the magnitudes were reduced to unit distances
(NONE, AVERAGE with the correction ``UCORMAG``, or POINT), and ``DELIMITER`` separates the fields (PIPE
or TAB). :func:`read_alcdef` returns the observation table of :mod:`spinorbit.photometry.observations` with each block's
keywords in ``meta["sessions"]``; the row's ``observer`` is the block's ``MPCCODE`` (the geometry
uses the geocentre). It reads files whose JDs are not corrected for light time and whose magnitudes
are not reduced, or reduced by one UCORMAG per block (which it undoes); other files are refused
with the reason, since their times or magnitudes would otherwise be misread.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from astropy import units as u
from astropy.time import Time
from astropy.timeseries import TimeSeries

from spinorbit.photometry.errors import PhotometryError
from spinorbit.photometry.observations import KNOWN_FILTERS, MissingUncertaintyError, check_observations
from spinorbit.runs.atomic import write_bytes_atomically

__all__ = ["ALCDEFError", "read_alcdef", "write_alcdef", "DELIMITERS"]

#: ALCDEF's delimiters by keyword value.
DELIMITERS = {"PIPE": "|", "TAB": "\t"}


class ALCDEFError(PhotometryError):
    """A file that does not follow the ALCDEF standard, or one this reader would misread."""


def _text_of(source):
    if isinstance(source, Path) or (isinstance(source, str) and "\n" not in source and "STARTMETADATA" not in source):
        path = Path(source)
        if not path.exists():
            raise ALCDEFError(f"source: no ALCDEF file at {str(path)!r}; pass a path or the file's text.")
        return path.read_text(encoding="utf-8", errors="replace"), str(path)
    return str(source), "the text given"


def _blocks(text, where):
    """[(metadata dict with COMMENT as a list, [(line number, data fields)])] of every STARTMETADATA … ENDDATA."""
    blocks, state, meta, rows = [], "outside", {}, []
    for number, raw in enumerate(text.splitlines(), start=1):
        line = raw.strip()
        if not line or line.startswith("#"):
            continue
        key, _, value = line.partition("=")
        key = key.strip().upper()
        if key == "STARTMETADATA":
            if state != "outside":
                raise ALCDEFError(f"{where}, line {number}: STARTMETADATA inside a block (a missing ENDDATA before it).")
            state, meta, rows = "metadata", {"COMMENT": []}, []
        elif key == "ENDMETADATA":
            if state != "metadata":
                raise ALCDEFError(f"{where}, line {number}: ENDMETADATA without STARTMETADATA.")
            state = "data"
        elif key == "ENDDATA":
            if state != "data":
                raise ALCDEFError(f"{where}, line {number}: ENDDATA outside a data section.")
            blocks.append((meta, rows))
            state = "outside"
        elif state == "metadata":
            if not _:
                raise ALCDEFError(f"{where}, line {number}: expected KEYWORD=value in the metadata; got {line!r}.")
            if key == "COMMENT":
                meta["COMMENT"].append(value.strip())
            else:
                meta[key] = value.strip()
        elif state == "data":
            if key != "DATA":
                raise ALCDEFError(f"{where}, line {number}: expected DATA=JD|MAG|MAGERR lines before ENDDATA; got {line!r}.")
            delimiter = DELIMITERS.get(meta.get("DELIMITER", "PIPE").upper())
            if delimiter is None:
                raise ALCDEFError(f"{where}: DELIMITER={meta['DELIMITER']!r}; ALCDEF's are PIPE and TAB.")
            rows.append((number, value.split(delimiter)))
        else:
            raise ALCDEFError(f"{where}, line {number}: {line!r} outside STARTMETADATA … ENDDATA.")
    if state != "outside":
        raise ALCDEFError(f"{where}: the file ends inside a block (no ENDDATA).")
    if not blocks:
        raise ALCDEFError(f"{where}: no STARTMETADATA … ENDDATA block; is this an ALCDEF file?")
    return blocks


def _number(text, where, number, what):
    try:
        value = float(text)
    except ValueError:
        raise ALCDEFError(f"{where}, line {number}: {what} {text.strip()!r} is not a number.") from None
    return value


def read_alcdef(source, filters=KNOWN_FILTERS, require_uncertainties=True):
    """Read every lightcurve of an ALCDEF file (module docstring) into one observation table.

    Parameters
    ----------
    source : str or Path
        A path, or the file's text.
    filters : sequence of str
        The filter codes accepted (:data:`~spinorbit.photometry.observations.KNOWN_FILTERS`).
    require_uncertainties : bool
        True (default): a block without MAGERR is refused (:class:`MissingUncertaintyError`); False:
        its ``magnitude_error`` is NaN and the table is not checked.

    Returns
    -------
    astropy.timeseries.TimeSeries
        ``time`` (UTC), ``magnitude``, ``magnitude_error``, ``filter``, ``observer``, ``session``, and
        ``airmass`` where the file gives it (else NaN); ``meta["sessions"]``: each block's keywords.

    Raises
    ------
    ALCDEFError
        A malformed file, light-time corrected JDs, or magnitudes reduced point by point.
    MissingUncertaintyError, UnknownFilterError, ObservationSpanError
        As :func:`~spinorbit.photometry.observations.check_observations`.
    """
    text, where = _text_of(source)
    times, magnitudes, errors, airmasses, filters_of, observers, sessions, metadata = [], [], [], [], [], [], [], []
    for index, (meta, rows) in enumerate(_blocks(text, where)):
        light_time = meta.get("LTCAPP", "NONE").upper()
        if light_time != "NONE":
            raise ALCDEFError(f"{where}, session {index}: LTCAPP={meta['LTCAPP']}: its JDs are corrected for light time, "
                              "and the geometry here corrects them itself; give the uncorrected JDs (LTCAPP=NONE).")
        reduced = meta.get("REDUCEDMAGS", "NONE").upper()
        if reduced not in ("NONE", "AVERAGE"):
            raise ALCDEFError(f"{where}, session {index}: REDUCEDMAGS={meta['REDUCEDMAGS']}: magnitudes reduced point by "
                              "point cannot be turned back into apparent ones without each point's distances.")
        correction = 0.0
        if reduced == "AVERAGE":
            if "UCORMAG" not in meta:
                raise ALCDEFError(f"{where}, session {index}: REDUCEDMAGS=AVERAGE needs UCORMAG, the correction applied.")
            correction = float(meta["UCORMAG"])
        for number, fields in rows:
            if len(fields) < 2:
                raise ALCDEFError(f"{where}, line {number}: expected JD{DELIMITERS['PIPE']}MAG[|MAGERR[|AIRMASS]]; got "
                                  f"{len(fields)} field(s).")
            times.append(_number(fields[0], where, number, "JD"))
            # UCORMAG = −5 log10(r Δ) was added to the apparent magnitudes: take it off again.
            magnitudes.append(_number(fields[1], where, number, "MAG") - correction)
            if len(fields) > 2 and fields[2].strip():
                errors.append(_number(fields[2], where, number, "MAGERR"))
            elif require_uncertainties:
                raise MissingUncertaintyError(f"{where}, line {number}: no MAGERR; every observation needs its "
                                              "uncertainty (read with require_uncertainties=False to look at the data).")
            else:
                errors.append(math.nan)
            airmasses.append(_number(fields[3], where, number, "AIRMASS") if len(fields) > 3 and fields[3].strip()
                             else math.nan)
        filters_of += [meta.get("FILTER", "")] * len(rows)
        observers += [meta.get("MPCCODE", "earth") or "earth"] * len(rows)
        sessions += [index] * len(rows)
        metadata.append(meta)
    table = TimeSeries(time=Time(np.array(times), format="jd", scale="utc"))
    table["magnitude"] = np.array(magnitudes) * u.mag
    table["magnitude_error"] = np.array(errors) * u.mag
    table["filter"] = np.array(filters_of, dtype=str)
    table["observer"] = np.array(observers, dtype=str)
    table["session"] = np.array(sessions, dtype=int)
    table["airmass"] = np.array(airmasses)
    table.meta["sessions"] = metadata
    table.meta["source"] = where
    return check_observations(table, filters) if require_uncertainties else table


def write_alcdef(table, path, metadata=None, digits=5):
    """Write an observation table as ALCDEF, one block per session (atomically).

    Parameters
    ----------
    table : astropy.timeseries.TimeSeries
        An observation table (:func:`~spinorbit.photometry.observations.photometric_observations`,
        :func:`read_alcdef`), checked first.
    path : str or Path
    metadata : dict, optional
        Keywords for every block (``OBJECTNAME``, ``OBJECTNUMBER``, ``CONTACTNAME``, …), over those the
        table carries in ``meta["sessions"]``. SESSIONDATE and SESSIONTIME (the block's middle, UTC),
        FILTER and MAGBAND (the rows' filter), LTCAPP=NONE, REDUCEDMAGS=NONE, DIFFERMAGS=FALSE and
        DELIMITER=PIPE are written from the data.
    digits : int
        Decimals of MAG and MAGERR (5: 10 µmag, below any photometry); JDs get 8 (1 ms).
    """
    check_observations(table, filters=tuple(set(np.asarray(table["filter"], dtype=str))))
    sessions = np.asarray(table["session"], dtype=int)
    lines = []
    for session in np.unique(sessions):
        rows = np.nonzero(sessions == session)[0]
        known = dict(table.meta.get("sessions", [])[session]) if session < len(table.meta.get("sessions", [])) else {}
        meta = {key: value for key, value in known.items() if key != "COMMENT"}
        meta.update(metadata or {})
        times = table["time"][rows].utc
        middle = Time((times.jd.min() + times.jd.max()) / 2, format="jd", scale="utc")
        date, clock = middle.isot.split("T")
        band = str(table["filter"][rows[0]])
        observer = str(table["observer"][rows[0]])
        meta.update(SESSIONDATE=date, SESSIONTIME=clock[:8], FILTER=band, MAGBAND=meta.get("MAGBAND", band),
                    LTCAPP="NONE", REDUCEDMAGS="NONE", DIFFERMAGS=meta.get("DIFFERMAGS", "FALSE"), DELIMITER="PIPE")
        if observer != "earth":
            meta["MPCCODE"] = observer
        meta.pop("UCORMAG", None)
        lines.append("STARTMETADATA")
        lines += [f"{key}={value}" for key, value in meta.items()]
        lines += [f"COMMENT={comment}" for comment in known.get("COMMENT", [])]
        lines.append("ENDMETADATA")
        magnitudes = table["magnitude"][rows].to_value(u.mag)
        errors = table["magnitude_error"][rows].to_value(u.mag)
        for jd, magnitude, error in zip(times.jd, magnitudes, errors):
            lines.append(f"DATA={jd:.8f}|{magnitude:.{digits}f}|{error:.{digits}f}")
        lines.append("ENDDATA")
    write_bytes_atomically(Path(path), ("\n".join(lines) + "\n").encode("utf-8"))
    return Path(path)
