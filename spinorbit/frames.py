"""Frame bridge: ICRF ↔ ecliptic J2000, and body-frame vectors/attitudes ↔ astropy objects.

Obliquity
---------
The ecliptic of J2000 is tilted from the ICRF equator by the IAU 2006 obliquity at J2000,
ε₀ = 84381.406″ (Hilton et al. 2006, Celest. Mech. Dyn. Astron. 94, 351; ERFA ``obl06`` at
J2000). It is the value astropy's ``BarycentricMeanEcliptic`` / ``GeocentricMeanEcliptic`` use
(through ERFA ``ecm06``), so a spinorbit ecliptic vector and an astropy one are the same thing.

Frame bias
----------
The ICRF axes are not exactly the mean equator and equinox of J2000: they differ by the *frame
bias* (IAU 2006: dα₀ = −14.6 mas, ξ₀ = −16.617 mas, η₀ = −6.8192 mas; ≈ 23 mas in all). astropy's
ecliptic includes it: M = R1(ε₀) · B. With ``include_frame_bias=True`` (the default) the matrix
here is that one and agrees with astropy to rounding (measured 7e-16 on unit vectors; astropy's
equinox J2000 is taken on TT, as here). With ``include_frame_bias=False`` the matrix is the plain
R1(ε₀) applied to ICRF axes (the "ecliptic" many orbit codes use); it differs from astropy's by
the ≈ 23 mas frame bias, which is far below anything that matters for an Andoyer reference frame,
but not below what an ephemeris comparison sees (23 mas × 1 au ≈ 17 km).

Matrices here are passive, as everywhere in spinorbit: v_ecliptic = M · v_icrf.
"""

from __future__ import annotations

import astropy.units as u
import erfa
import numpy as np
from astropy.coordinates import (
    CartesianRepresentation,
    SkyCoord,
    UnitSphericalRepresentation,
)

from spinorbit.core.math.rotations import quat_to_matrix, rot1

__all__ = [
    "OBLIQUITY_J2000",
    "icrf_to_ecliptic_matrix",
    "icrf_to_ecliptic",
    "ecliptic_to_icrf",
    "body_to_icrf",
    "body_axes_icrs",
    "icrs_skycoord",
]

#: IAU 2006 mean obliquity of the ecliptic at J2000.0 (Hilton et al. 2006; ERFA obl06).
OBLIQUITY_J2000 = 84381.406 * u.arcsec

_J2000_JD_TT = 2451545.0


def icrf_to_ecliptic_matrix(include_frame_bias: bool = True) -> np.ndarray:
    """Passive rotation matrix ICRF → ecliptic and equinox of J2000.

    Parameters
    ----------
    include_frame_bias : bool, optional
        True (default): M = R1(ε₀) · B, with the IAU 2006 frame-bias matrix B (ERFA ``bp06`` at
        J2000 TT); equal to astropy's ``BarycentricMeanEcliptic(equinox='J2000')``.
        False: M = R1(ε₀) on the ICRF axes directly; differs from the former by ≈ 23 mas.

    Returns
    -------
    ndarray, shape (3, 3)
        v_ecliptic = M @ v_icrf.
    """
    matrix = rot1(OBLIQUITY_J2000.to_value(u.rad))
    if include_frame_bias:
        frame_bias, _precession, _product = erfa.bp06(_J2000_JD_TT, 0.0)
        matrix = matrix @ frame_bias
    return matrix


def _as_vectors(vectors, name):
    """Split a (..., 3) array or Quantity into (values, unit or None), checking the shape."""
    unit = getattr(vectors, "unit", None)
    values = np.asarray(vectors.value if unit is not None else vectors, dtype=float)
    if values.shape[-1:] != (3,):
        raise ValueError(
            f"{name} must have xyz as its last axis, shape (..., 3); got shape {values.shape}."
        )
    return values, unit


def icrf_to_ecliptic(vectors, include_frame_bias: bool = True):
    """Rotate ICRF vectors (..., 3), plain or Quantity, to ecliptic J2000 components (same unit)."""
    values, unit = _as_vectors(vectors, "vectors")
    rotated = values @ icrf_to_ecliptic_matrix(include_frame_bias).T
    return rotated if unit is None else rotated << unit


def ecliptic_to_icrf(vectors, include_frame_bias: bool = True):
    """Rotate ecliptic J2000 vectors (..., 3), plain or Quantity, to ICRF components."""
    values, unit = _as_vectors(vectors, "vectors")
    rotated = values @ icrf_to_ecliptic_matrix(include_frame_bias)
    return rotated if unit is None else rotated << unit


def _check_quaternions(quaternion):
    q = np.asarray(quaternion, dtype=float)
    if q.shape[-1:] != (4,):
        raise ValueError(
            f"quaternion must be scalar-first (w, x, y, z) with shape (..., 4); got shape {q.shape}."
        )
    norm = np.linalg.norm(q, axis=-1)
    if np.any(np.abs(norm - 1.0) > 1e-6):
        raise ValueError(
            "quaternion must have unit norm (|q| − 1 within 1e-6); got norms "
            f"{np.ravel(norm)[:3]}. Normalise it first (q / |q|)."
        )
    return q / norm[..., None]


def body_to_icrf(vectors_body, quaternion) -> CartesianRepresentation:
    """Body-frame vectors → astropy ``CartesianRepresentation`` in ICRF axes.

    Parameters
    ----------
    vectors_body : array_like or Quantity, shape (..., 3)
        Components on the body axes (any unit; plain arrays become dimensionless).
    quaternion : array_like, shape (..., 4)
        Attitude, scalar first, body → inertial (ICRF) as in ``docs/conventions.md``
        (v_icrf = M(q) v_body). Broadcasts against ``vectors_body``.

    Returns
    -------
    CartesianRepresentation
        Same unit as the input, ICRF axes; ``xyz`` has the vectors' axis first, as astropy keeps it.
    """
    values, unit = _as_vectors(vectors_body, "vectors_body")
    q = _check_quaternions(quaternion)
    shape = np.broadcast_shapes(values.shape[:-1], q.shape[:-1])
    values = np.broadcast_to(values, shape + (3,)).reshape(-1, 3)
    q = np.broadcast_to(q, shape + (4,)).reshape(-1, 4)
    rotated = np.array([quat_to_matrix(qi) @ vi for qi, vi in zip(q, values)]).reshape(shape + (3,))
    return CartesianRepresentation(np.moveaxis(rotated, -1, 0) << (unit or u.one), xyz_axis=0)


def body_axes_icrs(quaternion) -> dict:
    """Directions of the body's x, y, z (A, B, C) axes on the sky, as ICRS ``SkyCoord`` objects.

    Parameters
    ----------
    quaternion : array_like, shape (..., 4)
        Attitude, scalar first, body → ICRF.

    Returns
    -------
    dict
        ``{'x': SkyCoord, 'y': SkyCoord, 'z': SkyCoord}`` of unit directions (no distance). For the
        Moon's DE421 mantle frame 'z' is the pole of the principal axis of largest moment.
    """
    q = _check_quaternions(quaternion)
    axes = {}
    for name, unit_vector in zip("xyz", np.eye(3)):
        cartesian = body_to_icrf(unit_vector, q)
        axes[name] = SkyCoord(
            cartesian.represent_as(UnitSphericalRepresentation), frame="icrs"
        )
    return axes


def icrs_skycoord(position) -> SkyCoord:
    """Barycentric ICRF positions (Quantity (..., 3), length unit) → ICRS ``SkyCoord``.

    ICRS in astropy is barycentric, so a barycentric ephemeris position needs no origin shift.
    Use ``.transform_to(BarycentricMeanEcliptic())`` on the result for ecliptic coordinates.

    Raises
    ------
    u.UnitTypeError
        If ``position`` is not a length Quantity.
    """
    if not (hasattr(position, "unit") and position.unit.physical_type == "length"):
        raise u.UnitTypeError(
            f"position must be a length Quantity of shape (..., 3); got {type(position).__name__}"
            f"{' in ' + str(position.unit) if hasattr(position, 'unit') else ''}. "
            "Attach a unit, e.g. array << u.AU."
        )
    values, unit = _as_vectors(position, "position")
    return SkyCoord(
        CartesianRepresentation(np.moveaxis(values, -1, 0) << unit, xyz_axis=0), frame="icrs"
    )

