"""spinorbit.frames against astropy/ERFA, and body-frame conversions."""

import astropy.units as u
import erfa
import numpy as np
import pytest
from _offline import no_network  # noqa: F401  (autouse socket guard)
from astropy.coordinates import BarycentricMeanEcliptic, CartesianRepresentation, SkyCoord
from astropy.time import Time

from spinorbit.core.math.rotations import quat_to_attitude
from spinorbit.ephemeris import moon_orientation
from spinorbit.frames import (
    OBLIQUITY_J2000,
    body_axes_icrs,
    body_to_icrf,
    ecliptic_to_icrf,
    icrf_to_ecliptic,
    icrf_to_ecliptic_matrix,
    icrs_skycoord,
)

#: Same matrix as astropy (both R1(ε₀)·B from ERFA at J2000 TT): only rounding separates them.
ASTROPY_AGREEMENT = 1e-14  # dimensionless (unit vectors)
#: The IAU 2006 frame bias is ≈ 23 mas in total; without it we must differ from astropy by about
#: that much and no more.
FRAME_BIAS_MAS = (15.0, 25.0)
MAS = 1e-3 * u.arcsec
#: Half-width (deg) around 1.543° for the lunar pole–ecliptic angle: ±0.06° libration + margin.
CASSINI_BAND_DEG = 0.08


def _unit_vectors(n=500, seed=20260101):
    v = np.random.default_rng(seed).normal(size=(n, 3))
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def test_obliquity_is_iau2006_at_j2000():
    assert OBLIQUITY_J2000.to_value(u.rad) == pytest.approx(erfa.obl06(2451545.0, 0.0), abs=1e-16)


def test_matrix_is_erfa_ecm06():
    np.testing.assert_allclose(icrf_to_ecliptic_matrix(), erfa.ecm06(2451545.0, 0.0), atol=1e-15)


def test_matches_astropy_barycentric_mean_ecliptic():
    v = _unit_vectors()
    astro = SkyCoord(CartesianRepresentation(v.T * u.AU), frame="icrs").transform_to(
        BarycentricMeanEcliptic()
    )
    ours = icrf_to_ecliptic(v * u.AU)
    assert ours.unit == u.AU
    assert np.abs(ours.to_value(u.AU) - astro.cartesian.xyz.to_value(u.AU).T).max() < ASTROPY_AGREEMENT


def test_without_frame_bias_differs_by_the_frame_bias():
    v = _unit_vectors()
    difference = np.abs(
        icrf_to_ecliptic(v, include_frame_bias=False) - icrf_to_ecliptic(v)
    ).max() * u.rad
    low, high = FRAME_BIAS_MAS
    assert low * MAS < difference < high * MAS


def test_ecliptic_round_trip_and_pole():
    v = _unit_vectors()
    np.testing.assert_allclose(ecliptic_to_icrf(icrf_to_ecliptic(v)), v, atol=1e-15)
    eps = OBLIQUITY_J2000.to_value(u.rad)
    pole = ecliptic_to_icrf(np.array([0.0, 0.0, 1.0]), include_frame_bias=False)
    np.testing.assert_allclose(pole, [0.0, -np.sin(eps), np.cos(eps)], atol=1e-15)


def test_body_to_icrf_uses_body_to_inertial_quaternion():
    angle = 0.3
    q = np.array([np.cos(angle / 2), 0.0, 0.0, np.sin(angle / 2)])  # body = inertial turned +0.3 about z
    rep = body_to_icrf(np.array([1.0, 0.0, 0.0]) * u.km, q)
    np.testing.assert_allclose(rep.xyz.to_value(u.km), [np.cos(angle), np.sin(angle), 0.0], atol=1e-15)


def test_moon_pole_obeys_cassini_inclination_to_ecliptic():
    # Cassini's laws: the lunar equator is inclined ≈ 1.543° to the ecliptic. DE421's physical
    # libration in the node/inclination components is ≈ 410–440″ peak to peak (DE421 over 2000–2010), i.e.
    # ±0.06°; measured 1.496°–1.602° over 2000–2010. A check of attitude sense and frames together.
    times = Time(np.linspace(2451545.0, 2451545.0 + 3650.0, 40), format="jd", scale="tdb")
    quaternion, _ = moon_orientation(times)
    pole = body_axes_icrs(quaternion)["z"]
    ecliptic_pole = ecliptic_to_icrf(np.array([0.0, 0.0, 1.0]))
    pole_xyz = pole.cartesian.xyz.value.T
    inclination = np.degrees(np.arccos(pole_xyz @ ecliptic_pole))
    assert np.all(np.abs(inclination - 1.543) < CASSINI_BAND_DEG)
    # The same pole straight from the attitude matrix rows (R maps inertial → body: row 3 is z).
    rows = np.array([quat_to_attitude(q)[2] for q in quaternion])
    np.testing.assert_allclose(pole_xyz, rows, atol=1e-14)


def test_icrs_skycoord_needs_a_length():
    with pytest.raises(u.UnitTypeError, match="length Quantity"):
        icrs_skycoord(np.ones(3))
    c = icrs_skycoord(np.array([[1.0, 0.0, 0.0], [0.0, 2.0, 0.0]]) * u.AU)
    np.testing.assert_allclose(c.distance.to_value(u.AU), [1.0, 2.0])


@pytest.mark.parametrize(
    "bad, match",
    [(np.ones(4), r"shape \(\.\.\., 3\)"), (np.ones((2, 2)), r"shape \(\.\.\., 3\)")],
)
def test_bad_vector_shapes(bad, match):
    with pytest.raises(ValueError, match=match):
        icrf_to_ecliptic(bad)


def test_non_unit_quaternion_is_refused():
    with pytest.raises(ValueError, match="unit norm"):
        body_to_icrf(np.ones(3), np.array([2.0, 0.0, 0.0, 0.0]))
