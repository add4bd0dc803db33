"""The Moon's physical librations τ, ρ, Iσ from its principal-axis attitude.

Definitions (Eckhardt 1981, Moon Planets 25, 3; the same as Newhall & Williams 1997, CeMDA 66, 21,
and Rambaux & Williams 2011, CeMDA 109, 85), written for this package's passive 3-1-3 angles
(``docs/conventions.md`` "Physical librations"): with (φ, θ, ψ) the Euler angles of the mantle's
principal axes with respect to the **mean ecliptic and equinox of date**, L the Moon's mean
longitude and Ω the mean longitude of the ascending node of its orbit (both of date),

    φ = Ω + π + σ,   θ = I + ρ,   φ + ψ = L + π + τ,

i.e. τ = φ + ψ − π − L (longitude), ρ = θ − I (latitude, inclination), Iσ = I·(φ − Ω − π) (node,
multiplied by I so that it measures the same pole displacement as ρ). The π in φ is Cassini's third
law in these angles: the lunar equator's ascending node on the ecliptic is the orbit's descending
node. I = 1°32′32.7″ = 1.54242° is the mean inclination of the lunar equator to the ecliptic
(the IAU value, Meeus 1998, *Astronomical Algorithms*, ch. 53).

Sources of the frames and elements: the mean ecliptic and equinox of date are IAU 2006
(Capitaine et al. 2003), through ERFA's ``ecm06`` (ICRS → ecliptic of date, frame bias included);
L = F + Ω with F and Ω the Delaunay arguments of the IERS Conventions 2003 (eq. 5.43, from Simon et
al. 1994, A&A 282, 663), through ERFA's ``faf03`` and ``faom03``, evaluated at TDB (the IERS series
take TDB ≈ TT; the 1.7 ms difference moves L by 1e-6″).

Angles are in radians here; the tables in :mod:`spinorbit.coupling.moon` give τ, ρ, Iσ in arcsec.
"""

from __future__ import annotations

import erfa
import numpy as np

from spinorbit.time import J2000_JD_TDB

__all__ = [
    "MEAN_EQUATOR_INCLINATION_RAD",
    "ecliptic_of_date_matrices",
    "euler313_from_attitudes",
    "mean_lunar_longitude_and_node",
    "physical_librations",
]

#: Mean inclination I of the lunar equator to the ecliptic, 1°32′32.7″ (IAU; Meeus 1998, ch. 53).
MEAN_EQUATOR_INCLINATION_RAD = np.deg2rad(1.0 + 32.0 / 60.0 + 32.7 / 3600.0)
#: Days per Julian century (the unit of the IERS fundamental-argument series).
DAYS_PER_JULIAN_CENTURY = 36525.0


def ecliptic_of_date_matrices(days) -> np.ndarray:
    """ICRF → mean ecliptic and equinox of date (IAU 2006), shape (n, 3, 3).

    Parameters
    ----------
    days : array_like
        TDB days since J2000.
    """
    days = np.atleast_1d(np.asarray(days, dtype=float))
    return erfa.ecm06(J2000_JD_TDB, days)


def mean_lunar_longitude_and_node(days):
    """The Moon's mean longitude L and mean node Ω of date (rad), IERS 2003 / Simon et al. 1994.

    Parameters
    ----------
    days : array_like
        TDB days since J2000.

    Returns
    -------
    longitude, node : ndarray
        L = F + Ω and Ω (rad; each reduced to [0, 2π) by ERFA).
    """
    centuries = np.asarray(days, dtype=float) / DAYS_PER_JULIAN_CENTURY
    node = erfa.faom03(centuries)
    return erfa.faf03(centuries) + node, node


def euler313_from_attitudes(attitudes) -> np.ndarray:
    """Passive 3-1-3 angles (φ, θ, ψ) of attitude matrices R = R3(ψ) R1(θ) R3(φ), shape (n, 3).

    φ, ψ in (−π, π], θ in [0, π]; vectorised form of
    :func:`spinorbit.core.math.rotations.attitude_to_euler313` (rows of R: body axes in the frame).
    """
    r = np.asarray(attitudes, dtype=float)
    phi = np.arctan2(r[:, 2, 0], -r[:, 2, 1])
    theta = np.arctan2(np.hypot(r[:, 2, 0], r[:, 2, 1]), r[:, 2, 2])
    psi = np.arctan2(r[:, 0, 2], r[:, 1, 2])
    return np.stack([phi, theta, psi], axis=1)


def _wrap(angle):
    """Reduce to (−π, π]."""
    return -np.remainder(-angle + np.pi, 2.0 * np.pi) + np.pi


def physical_librations(days, attitudes) -> np.ndarray:
    """τ, ρ, Iσ (rad) of the mantle attitudes ``attitudes`` (ICRF → mantle) at ``days``.

    Parameters
    ----------
    days : array_like, shape (n,)
        TDB days since J2000.
    attitudes : array_like, shape (n, 3, 3)
        Attitude matrices ICRF → mantle principal axes (``docs/conventions.md``).

    Returns
    -------
    ndarray, shape (n, 3)
        (τ, ρ, Iσ) in rad, as defined in the module docstring; τ and σ reduced to (−π, π].
    """
    days = np.atleast_1d(np.asarray(days, dtype=float))
    to_ecliptic = ecliptic_of_date_matrices(days)
    # R_ecliptic = R_ICRF · E^T: mantle components from ecliptic-of-date components.
    ecliptic = np.einsum("nij,nkj->nik", np.asarray(attitudes, dtype=float), to_ecliptic)
    phi, theta, psi = euler313_from_attitudes(ecliptic).T
    longitude, node = mean_lunar_longitude_and_node(days)
    inclination = MEAN_EQUATOR_INCLINATION_RAD
    tau = _wrap(phi + psi - np.pi - longitude)
    rho = theta - inclination
    sigma = _wrap(phi - node - np.pi)
    return np.stack([tau, rho, inclination * sigma], axis=1)
