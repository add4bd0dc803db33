"""Osculating Keplerian elements with units ↔ a Cartesian state in ICRF, checked on the way in.

A published small-body orbit is usually six osculating elements (a, e, i, Ω, ω, M) at an epoch,
heliocentric, referred to the ecliptic and equinox of J2000. :func:`elements_to_state` turns them
into a heliocentric ICRF position and velocity (plain floats in DE421's au and au/day, what a
REBOUND simulation of :mod:`spinorbit.coupling.rebound` takes); :func:`check_elements` is the one
check of the inputs, raising :class:`OrbitElementsError` with what was expected, what arrived and
what to do.

The conversion
--------------
Kepler's equation E − e sin E = M is solved by Newton's method from E₀ = M + e sin M (M reduced
to (−π, π]), to |ΔE| ≤ 4 ulp; the perifocal state r = a(cos E − e, √(1−e²) sin E, 0),
v = √(GM a)/r (−sin E, √(1−e²) cos E, 0) is turned by R3(−Ω) R1(−i) R3(−ω) (passive
rotations, so these are the active turns by ω, i, Ω) into the elements' frame and then into ICRF.
``tests/test_orbits.py`` checks it against a 40-digit mpmath Kepler solve and against REBOUND's
own converter.

Frames
------
``"ecliptic"`` (the default) is the ecliptic and equinox of J2000 that published element catalogues
use: JPL's Small-Body Database and Horizons (and the MPC) refer their elements to an ecliptic with the
IAU 1976 obliquity 84381.448″ and no frame bias. JPL#218's Apophis elements give Horizons' ICRF state
to 0.7 m through it (``tests/test_orbits.py``). ``"ecliptic-iau2006"`` is the ecliptic of
:mod:`spinorbit.frames` and astropy's ``BarycentricMeanEcliptic``: IAU 2006 obliquity 84381.406″
with the frame bias; the same elements land 31 km off through it. The two differ by ≈ 0.05″, far
below what few-digit elements carry but not below what a close approach resolves, so the default is
the catalogues' frame. ``"icrf"`` takes the elements as referred to the ICRF equator.
"""

from __future__ import annotations

import math

import numpy as np
from astropy import units as u

from spinorbit.core.errors import SpinorbitError
from spinorbit.core.math.rotations import rot1, rot3
from spinorbit.frames import icrf_to_ecliptic_matrix
from spinorbit.quantities import require_quantity

__all__ = ["ELEMENT_FRAMES", "JPL_OBLIQUITY_J2000", "OrbitElementsError", "check_elements", "elements_to_state",
           "frame_to_icrf_matrix", "solve_kepler"]

#: Frames the elements (or a state vector) may be referred to (module docstring).
ELEMENT_FRAMES = ("ecliptic", "ecliptic-iau2006", "icrf")
#: IAU 1976 obliquity of J2000, the one of JPL's ecliptic elements (Lieske et al. 1977).
JPL_OBLIQUITY_J2000 = 84381.448 * u.arcsec


class OrbitElementsError(SpinorbitError, ValueError):
    """Orbital elements, a state vector or their frame that spinorbit cannot turn into an orbit."""


def frame_to_icrf_matrix(frame):
    """Passive matrix taking a vector in ``frame`` (one of :data:`ELEMENT_FRAMES`) to ICRF."""
    if frame == "icrf":
        return np.eye(3)
    if frame == "ecliptic":
        return rot1(JPL_OBLIQUITY_J2000.to_value(u.rad)).T
    if frame == "ecliptic-iau2006":
        return icrf_to_ecliptic_matrix().T
    raise OrbitElementsError(
        f"frame expects one of {ELEMENT_FRAMES} ('ecliptic': ecliptic and equinox J2000 of JPL's SBDB, Horizons "
        f"and the MPC, IAU 1976 obliquity; 'ecliptic-iau2006': astropy's BarycentricMeanEcliptic); got {frame!r}."
    )


def _angle(name, value, low_deg, high_deg, what):
    require_quantity(name, value, u.deg, "10 * u.deg")
    if not isinstance(value, u.Quantity) or value.unit.physical_type != "angle" or not value.isscalar:
        raise OrbitElementsError(f"{name} expects a scalar angle Quantity such as 10 * u.deg; got {value!r}.")
    degrees = float(value.to_value(u.deg))
    if not (math.isfinite(degrees) and low_deg <= degrees <= high_deg):
        raise OrbitElementsError(f"{name} expects {what}, in [{low_deg:g}°, {high_deg:g}°]; got {value!r}. "
                                 f"{'Reduce it modulo 360° first.' if high_deg == 360 else ''}".rstrip())
    return math.radians(degrees)


def check_elements(a, e, inc, raan, argp, mean_anomaly):
    """The elements as plain floats (a in km, angles in rad), or :class:`OrbitElementsError`.

    Parameters
    ----------
    a : Quantity (length)
        Semi-major axis, positive (only elliptic orbits: 0 ≤ e < 1).
    e : float or dimensionless Quantity
        Eccentricity, 0 ≤ e < 1.
    inc : Quantity (angle)
        Inclination, 0° … 180°.
    raan, argp, mean_anomaly : Quantity (angle)
        Longitude of the ascending node Ω, argument of periapsis ω and mean anomaly M, each in
        [−360°, 360°] (a value further out is almost always a unit slip, so it is refused).

    Returns
    -------
    tuple of float
        (a_km, e, inc, raan, argp, mean_anomaly), angles in rad.
    """
    require_quantity("a", a, u.au, "2.53 * u.au")
    if not isinstance(a, u.Quantity) or a.unit.physical_type != "length" or not a.isscalar:
        raise OrbitElementsError(f"a expects a scalar length Quantity such as 2.53 * u.au; got {a!r}.")
    a_km = float(a.to_value(u.km))
    if not (math.isfinite(a_km) and a_km > 0.0):
        raise OrbitElementsError(f"a expects a positive semi-major axis (an elliptic orbit); got {a!r}. "
                                 "A hyperbolic orbit has a < 0: give it as a state vector (Orbit.from_state).")
    if isinstance(e, u.Quantity):
        if e.unit.physical_type != "dimensionless":
            raise OrbitElementsError(f"e expects a dimensionless eccentricity; got {e!r}.")
        e = e.to_value(u.dimensionless_unscaled)
    try:
        e = float(e)
    except (TypeError, ValueError):
        raise OrbitElementsError(f"e expects a number (the eccentricity); got {e!r}.") from None
    if not (math.isfinite(e) and 0.0 <= e < 1.0):
        kind = "parabolic" if e == 1.0 else "hyperbolic" if e > 1.0 else "not an eccentricity"
        raise OrbitElementsError(f"e expects an elliptic orbit, 0 <= e < 1; got e = {e!r} ({kind}). "
                                 "Give an open orbit as a state vector (Orbit.from_state).")
    inc_rad = _angle("inc", inc, 0.0, 180.0, "an inclination")
    angles = [_angle(name, value, -360.0, 360.0, "an angle")
              for name, value in (("raan", raan), ("argp", argp), ("mean_anomaly", mean_anomaly))]
    return (a_km, e, inc_rad, *angles)


def solve_kepler(mean_anomaly, e):
    """Eccentric anomaly E (rad) with E − e sin E = M, for 0 ≤ e < 1 (Newton, module docstring)."""
    m = math.remainder(mean_anomaly, 2.0 * math.pi)
    big_e = m + e * math.sin(m) if e < 0.8 else math.copysign(math.pi, m) if m else 0.0
    for _ in range(60):
        step = (big_e - e * math.sin(big_e) - m) / (1.0 - e * math.cos(big_e))
        big_e -= step
        if abs(step) <= 4.0 * math.ulp(max(abs(big_e), 1.0)):
            break
    return big_e


def elements_to_state(a, e, inc, raan, argp, mean_anomaly, gm, frame="ecliptic"):
    """Position and velocity of an elliptic Kepler orbit, in ICRF axes.

    Parameters
    ----------
    a : float
        Semi-major axis (any length unit; the position comes out in it).
    e, inc, raan, argp, mean_anomaly : float
        Eccentricity and angles in rad (:func:`check_elements`).
    gm : float
        G·M of the central body, in (length unit)³/(time unit)²; the velocity comes out in
        length unit / time unit.
    frame : {"ecliptic", "ecliptic-iau2006", "icrf"}
        The frame the elements are referred to (module docstring).

    Returns
    -------
    position, velocity : ndarray, shape (3,)
        Relative to the central body, ICRF axes.
    """
    to_icrf = frame_to_icrf_matrix(frame)
    big_e = solve_kepler(mean_anomaly, e)
    cos_e, sin_e = math.cos(big_e), math.sin(big_e)
    root = math.sqrt((1.0 - e) * (1.0 + e))
    radius = a * (1.0 - e * cos_e)
    perifocal_r = np.array([a * (cos_e - e), a * root * sin_e, 0.0])
    perifocal_v = math.sqrt(gm * a) / radius * np.array([-sin_e, root * cos_e, 0.0])
    turn = to_icrf @ rot3(-raan) @ rot1(-inc) @ rot3(-argp)
    return turn @ perifocal_r, turn @ perifocal_v
