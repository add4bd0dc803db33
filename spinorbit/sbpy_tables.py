"""Rows of sbpy's data containers read as spinorbit's inputs: orbital elements and published spins.

sbpy (an astropy-affiliated package) fills ``sbpy.data.Orbit`` from JPL Horizons and the Small-Body
Database, and ``sbpy.data.Phys`` with physical properties. A field is looked up by any of sbpy's
alternative names (``i``, ``inc``, ``incl``), as sbpy's own ``DataClass[name]`` does. Nothing here
imports sbpy: a container is recognised by its class, so spinorbit runs without the optional extra.

Units are never guessed (``docs/conventions.md``, "Units"): every dimensional field must carry its unit
(sbpy's tables from Horizons and SBDB do), and the epoch must be an astropy Time (a bare Julian date
says nothing of its time scale).

Spin fields (sbpy 0.6 defines none): the rotation period is read from ``rot_per`` (the SBDB's name),
``rotation_period`` or ``P_rot`` (never ``P``, which sbpy defines as the orbital period); the pole from
``pole_lon`` and ``pole_lat`` (ecliptic J2000, DAMIT's λ, β) or ``pole_ra`` and ``pole_dec`` (ICRF),
angle Quantities.
"""

from __future__ import annotations

import math

import numpy as np
from astropy import units as u
from astropy.time import Time

from spinorbit.core.errors import SpinorbitError
from spinorbit.quantities import require_quantity

__all__ = ["SbpyInputError", "orbit_arguments", "pole_arguments", "ROTATION_PERIOD_FIELDS"]

#: Names of a rotation period in a ``Phys`` row, first found first (``P``/``period`` is sbpy's orbital period).
ROTATION_PERIOD_FIELDS = ("rot_per", "rotation_period", "P_rot")


class SbpyInputError(SpinorbitError, ValueError):
    """An sbpy container that does not hold what is needed: not an Orbit or Phys, no such row, a missing field."""


def _one_row(data, row, kind):
    """The container's ``row`` as a one-row container of the same class, or SbpyInputError."""
    cls = type(data)
    if not (cls.__module__.startswith("sbpy.data") and cls.__name__ == kind):
        raise SbpyInputError(f"expects an sbpy.data.{kind} (e.g. sbpy.data.{kind}.from_dict(...), or from Horizons "
                             f"or the SBDB); got {cls.__module__}.{cls.__name__}.")
    rows = len(data)
    if not (isinstance(row, (int, np.integer)) and -rows <= row < rows):
        raise SbpyInputError(f"row expects an integer index into the {rows} row(s) of this sbpy.data.{kind}; "
                             f"got {row!r}.")
    return data[int(row)]


def _field(data, names):
    """The first of ``names`` in the one-row container, as a scalar (Quantity, Time or str), or None."""
    for name in names:
        try:
            value = data[name]  # sbpy resolves its alternative names
        except KeyError:
            continue
        return value[0] if getattr(value, "shape", ()) else value
    return None


def _required(data, names, kind, unit, example):
    value = _field(data, names)
    if value is None:
        raise SbpyInputError(f"the sbpy.data.{kind} row has no {names[0]!r} field (nor {', '.join(map(repr, names[1:]))}); "
                             f"its fields are {list(data.field_names)}.")
    require_quantity(f"sbpy field {names[0]!r}", value, unit, example)
    return value


def orbit_arguments(orbit, row=0):
    """The arguments of :meth:`spinorbit.scene.Orbit.from_elements` from one row of an ``sbpy.data.Orbit``.

    Reads ``a`` (or the perihelion distance ``q`` with ``e``: a = q / (1 − e)), ``e``, ``i``, ``Omega``,
    ``w``, ``M`` (or the time of perihelion ``Tp``: M = n (epoch − Tp), n from DE421's GM of the Sun) and
    ``epoch`` (a Time), with sbpy's alternative names; ``targetname`` names the orbit when present.

    Returns
    -------
    dict
        ``a, e, inc, raan, argp, mean_anomaly, epoch`` and ``name`` (None without a target name).
    """
    data = _one_row(orbit, row, "Orbit")
    e = _field(data, ("e", "ecc"))
    if e is None:
        raise SbpyInputError(f"the sbpy.data.Orbit row has no eccentricity 'e'; its fields are {list(data.field_names)}.")
    try:
        e = float(u.Quantity(e).to_value(u.dimensionless_unscaled))
    except u.UnitConversionError:
        raise SbpyInputError(f"the sbpy.data.Orbit row's eccentricity 'e' expects a pure number; got {e!r}.") from None
    epoch = _field(data, ("epoch",))
    if not isinstance(epoch, Time):
        raise SbpyInputError(f"the sbpy.data.Orbit row's 'epoch' expects an astropy Time (its scale matters: TDB for "
                             f"Horizons and SBDB elements); got {epoch!r}.")
    if _field(data, ("a", "sma")) is not None:
        a = _required(data, ("a", "sma"), "Orbit", u.au, "2.53 * u.au")
    else:
        q = _required(data, ("q", "periheldist"), "Orbit", u.au, "0.92 * u.au")
        if not e < 1.0:
            raise SbpyInputError(f"a = q / (1 - e) needs an elliptic orbit; got e = {e!r} (an open orbit goes through "
                                 "Orbit.from_state).")
        a = q / (1.0 - e)
    angles = [_required(data, names, "Orbit", u.deg, "10 * u.deg")
              for names in (("i", "inc", "incl"), ("Omega", "longnode", "node"), ("w", "argper"))]
    if _field(data, ("M", "mean_anom")) is not None:
        mean_anomaly = _required(data, ("M", "mean_anom"), "Orbit", u.deg, "5.12 * u.deg")
    else:
        perihelion = _field(data, ("Tp",))
        if not isinstance(perihelion, Time):
            raise SbpyInputError("the sbpy.data.Orbit row has no mean anomaly 'M' and no time of perihelion 'Tp' "
                                 f"(an astropy Time); its fields are {list(data.field_names)}.")
        from spinorbit.ephemeris import de421_constants

        motion = math.sqrt(de421_constants().gm["sun"] / float(a.to_value(u.au)) ** 3)  # rad/day
        elapsed = float((epoch.tdb - perihelion.tdb).to_value(u.day))
        mean_anomaly = (math.remainder(motion * elapsed, 2 * math.pi) * u.rad).to(u.deg)
    name = _field(data, ("targetname",))
    return dict(a=a, e=e, inc=angles[0], raan=angles[1], argp=angles[2], mean_anomaly=mean_anomaly, epoch=epoch,
                name=None if name is None else str(name))


def pole_arguments(phys, row=0):
    """(pole longitude, pole latitude, sidereal period, frame) from one row of an ``sbpy.data.Phys``.

    The period from :data:`ROTATION_PERIOD_FIELDS`; the pole from ``pole_lon``/``pole_lat`` (frame
    "ecliptic") or ``pole_ra``/``pole_dec`` (frame "icrf"). Raises SbpyInputError naming what is missing.
    """
    data = _one_row(phys, row, "Phys")
    period = _field(data, ROTATION_PERIOD_FIELDS)
    if period is None:
        raise SbpyInputError(f"the sbpy.data.Phys row has no rotation period (a field {' or '.join(ROTATION_PERIOD_FIELDS)}; "
                             f"'P' is sbpy's orbital period); its fields are {list(data.field_names)}.")
    require_quantity(f"sbpy field {ROTATION_PERIOD_FIELDS[0]!r}", period, u.hour, "2.26 * u.hour")
    for lon_name, lat_name, frame in (("pole_lon", "pole_lat", "ecliptic"), ("pole_ra", "pole_dec", "icrf")):
        lon, lat = _field(data, (lon_name,)), _field(data, (lat_name,))
        if lon is not None and lat is not None:
            require_quantity(f"sbpy field {lon_name!r}", lon, u.deg, "80 * u.deg")
            require_quantity(f"sbpy field {lat_name!r}", lat, u.deg, "30 * u.deg")
            return lon, lat, period, frame
    raise SbpyInputError("the sbpy.data.Phys row has no spin pole: give pole_lon and pole_lat (ecliptic J2000) or "
                         f"pole_ra and pole_dec (ICRF) as angle Quantities; its fields are {list(data.field_names)}.")
