"""The spin pole and the obliquity: where a body's angular momentum points, in ICRF and ecliptic J2000.

The *pole* is the direction of the rotational angular momentum (fixed in inertial space in free
rotation; for a principal-axis rotator it is the spin axis). It is given as (RA, Dec) in ICRF and as
ecliptic (λ, β) of J2000, the frame of :func:`spinorbit.frames.icrf_to_ecliptic_matrix` with its
default frame bias: the IAU 2006 obliquity ε₀ = 84381.406″ (not IAU 1976's 84381.448″), the frame
astropy calls ``BarycentricMeanEcliptic(equinox="J2000")`` (``tests/test_pole.py`` checks against it).
The *obliquity* is the angle between the pole and the normal of the body's current (osculating,
heliocentric) orbit plane, r × v: 0° for a prograde spin perpendicular to the orbit, 180° for a
retrograde one. Definitions: ``docs/conventions.md`` ("Spin pole and obliquity").
"""

from __future__ import annotations

import numpy as np

from spinorbit.frames import icrf_to_ecliptic_matrix

__all__ = ["angle_between_deg", "directions_from_ra_dec_deg", "obliquity_deg", "orbit_normals", "pole_angles_deg"]


def _unit_rows(vectors, what):
    vectors = np.atleast_2d(np.asarray(vectors, dtype=float))
    if vectors.shape[-1] != 3 or vectors.ndim != 2:
        raise ValueError(f"{what} expects ICRF vectors of shape (3,) or (N, 3); got shape {vectors.shape}.")
    norms = np.linalg.norm(vectors, axis=1)
    if not np.all(np.isfinite(norms)) or not np.all(norms > 0.0):
        raise ValueError(f"{what} expects finite, non-zero vectors; got {vectors[~(norms > 0.0)][:1].tolist()} "
                         "(a zero or NaN vector has no direction).")
    return vectors / norms[:, None]


def _lon_lat_deg(unit):
    lon = np.degrees(np.arctan2(unit[:, 1], unit[:, 0])) % 360.0
    lat = np.degrees(np.arcsin(np.clip(unit[:, 2], -1.0, 1.0)))
    return lon, lat


def pole_angles_deg(directions):
    """(RA, Dec, λ, β) in degrees of ICRF directions (N, 3): ICRF and ecliptic J2000 (IAU 2006 ε₀, frame bias).

    RA and λ are in [0, 360), Dec and β in [−90, 90].
    """
    unit = _unit_rows(directions, "the pole")
    ra, dec = _lon_lat_deg(unit)
    # the rotation written out (no BLAS product): a row's angles do not depend on the rows beside it
    m = icrf_to_ecliptic_matrix()
    x, y, z = unit[:, 0], unit[:, 1], unit[:, 2]
    ecliptic = np.stack([m[j, 0] * x + m[j, 1] * y + m[j, 2] * z for j in range(3)], axis=1)
    lon, lat = _lon_lat_deg(ecliptic)
    return ra, dec, lon, lat


def orbit_normals(positions, velocities):
    """Unit normals r × v (N, 3) of the orbit planes of heliocentric ICRF states (any consistent units)."""
    return _unit_rows(np.cross(np.atleast_2d(positions), np.atleast_2d(velocities)), "the orbit normal (r × v)")


def directions_from_ra_dec_deg(ra_deg, dec_deg):
    """Unit ICRF vectors (N, 3) of right ascensions and declinations in degrees (the inverse of the
    (RA, Dec) that :func:`pole_angles_deg` gives)."""
    ra, dec = np.radians(np.atleast_1d(ra_deg)), np.radians(np.atleast_1d(dec_deg))
    return np.stack([np.cos(dec) * np.cos(ra), np.cos(dec) * np.sin(ra), np.sin(dec)], axis=1)


def angle_between_deg(first, second, first_name="the first direction", second_name="the second direction"):
    """Angle (deg, in [0, 180]) between two sets of directions, row by row ((3,) or (N, 3) each; one row
    of ``second`` serves every row of ``first``).

    Computed as atan2(|a × b|, a · b), accurate near 0° and 180° where acos of the dot product is not.
    """
    a, b = _unit_rows(first, first_name), _unit_rows(second, second_name)
    if b.shape[0] == 1 and a.shape[0] > 1:
        b = np.broadcast_to(b, a.shape)
    if b.shape != a.shape:
        raise ValueError(f"the angle between {first_name} and {second_name} expects one row of each per row; got "
                         f"{a.shape[0]} and {b.shape[0]}.")
    return np.degrees(np.arctan2(np.linalg.norm(np.cross(a, b), axis=1), np.sum(a * b, axis=1)))


def obliquity_deg(directions, normals):
    """Angle (deg, in [0, 180]) between pole directions and orbit normals, row by row (ICRF, (N, 3) each)."""
    return angle_between_deg(directions, normals, "the pole", "the orbit normal")
