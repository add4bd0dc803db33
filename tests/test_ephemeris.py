"""spinorbit.ephemeris: DE421 from the de421 package, cross-checked against skyfield's de421.bsp."""

import os

import astropy.units as u
import numpy as np
import pytest
from _offline import no_network  # noqa: F401  (autouse socket guard)
from astropy.time import Time

from spinorbit.core.math.rotations import euler313_to_attitude, quat_to_attitude
from spinorbit.ephemeris import (
    DE421_SPAN_JD_TDB,
    KNOWN_BODIES,
    EphemerisRangeError,
    UnknownBodyError,
    _span,
    barycentric_state,
    barycentric_state_au,
    barycentric_state_km,
    de421_constants,
    moon_libration_angles,
    moon_orientation_raw,
)

#: The .bsp and the de421 package are separate conversions of JPL's DE421 coefficients; measured
#: max differences over 1901–2052 (2001 epochs): 0.11 m (Mars barycentre), 0.06 m Earth/Moon,
#: ≤ 0.04 m Sun/Mercury, ≤ 0.012 m outer planets; velocities ≤ 1e-8 m/s. 0.2 m bounds them all.
SOURCE_AGREEMENT_M = 0.2
SOURCE_AGREEMENT_M_PER_S = 2e-8

SKYFIELD_NAMES = {
    "sun": "sun",
    "mercury": "mercury barycenter",
    "venus": "venus barycenter",
    "earth": "earth",
    "moon": "moon",
    "earth-moon barycenter": "earth barycenter",
    "mars": "mars barycenter",
    "jupiter": "jupiter barycenter",
    "saturn": "saturn barycenter",
    "uranus": "uranus barycenter",
    "neptune": "neptune barycenter",
    "pluto": "pluto barycenter",
}


@pytest.fixture(scope="module")
def bsp():
    import skyfield_data
    from skyfield.api import load_file

    # load_file on the shipped path: no Loader, no expiry check, no download.
    kernel = load_file(os.path.join(os.path.dirname(skyfield_data.__file__), "data", "de421.bsp"))
    yield kernel
    kernel.close()


@pytest.mark.validation
@pytest.mark.parametrize("body", KNOWN_BODIES)
def test_package_agrees_with_skyfield_bsp(body, bsp):
    from skyfield.api import load

    days = np.linspace(-36000.0, 19000.0, 401)  # 1901–2052, inside both files
    ts = load.timescale(builtin=True)
    t = ts.tdb_jd(2451545.0, days)
    position, velocity = barycentric_state_km(body, days, 0.0)
    reference = bsp[SKYFIELD_NAMES[body]].at(t)
    position_error_m = np.abs(position - reference.position.km.T).max() * 1e3
    velocity_error_m_s = np.abs(velocity - reference.velocity.km_per_s.T * 86400.0).max() / 86.4
    assert position_error_m < SOURCE_AGREEMENT_M
    assert velocity_error_m_s < SOURCE_AGREEMENT_M_PER_S


def test_span_constant_is_the_package_span():
    assert DE421_SPAN_JD_TDB == _span()


def test_quantity_api_shapes_units_and_au():
    times = Time(["2000-01-01T12:00:00", "2010-06-01T00:00:00"], scale="tdb")
    position, velocity = barycentric_state("Earth", times)
    assert position.shape == velocity.shape == (2, 3)
    assert position.unit == u.AU and velocity.unit == u.AU / u.day
    # ~1 au from the barycentre, ~30 km/s
    assert np.all(np.abs(np.linalg.norm(position, axis=-1) - 1 * u.AU) < 0.02 * u.AU)
    assert np.all(np.abs(np.linalg.norm(velocity, axis=-1) - 30 * u.km / u.s) < 1.5 * u.km / u.s)
    # DE421 au vs IAU 2012 au: the _au function is in DE421's unit.
    raw, _ = barycentric_state_au("earth", 0.0)
    assert raw == pytest.approx(position[0].to_value(u.AU), rel=1e-11)


def test_earth_and_moon_split_the_barycentre_by_emrat():
    c = de421_constants()
    days = np.array([0.0, 1234.5])
    emb, _ = barycentric_state_km("EMB", days)
    earth, _ = barycentric_state_km("earth", days)
    moon, _ = barycentric_state_km("moon", days)
    np.testing.assert_allclose((c.emrat * earth + moon) / (1 + c.emrat), emb, atol=1e-6)
    assert np.all(np.abs(np.linalg.norm(moon - earth, axis=-1) - 384400.0) < 30000.0)


def test_two_float_time_is_honoured():
    # Splitting the same instant differently must give the same state (to rounding).
    a, _ = barycentric_state_km("moon", 9000.0, 0.25)
    b, _ = barycentric_state_km("moon", 9000.25, 0.0)
    np.testing.assert_allclose(a, b, atol=1e-7)


def test_unknown_body_lists_the_known_ones():
    with pytest.raises(UnknownBodyError, match="unknown body 'Vulcan'.*sun, mercury"):
        barycentric_state("Vulcan", Time("2000-01-01", scale="tdb"))
    with pytest.raises(TypeError, match="body must be a name"):
        barycentric_state_km(399, 0.0)


def test_outside_span_gives_the_span():
    with pytest.raises(EphemerisRangeError, match="2414992.5–2524624.5"):
        barycentric_state("moon", Time("1850-01-01", scale="tdb"))
    with pytest.raises(EphemerisRangeError, match="1899-12-04 to 2200-02-01"):
        moon_orientation_raw(np.array([0.0, 80000.0]))


def test_librations_reproduce_header_epoch_values():
    # DE421's header holds the mantle angles and angular velocity at JDEPOC: the angles come from the
    # series, ω from the body angular velocity formula. Measured: exact to 1e-20 rad/day.
    c = de421_constants()
    day = c.moon_epoch_jd_tdb - 2451545.0
    angles, rates = moon_libration_angles(Time(c.moon_epoch_jd_tdb, format="jd", scale="tdb"))
    np.testing.assert_allclose(angles.to_value(u.rad), c.moon_angles_at_epoch, rtol=0, atol=1e-12)
    _, omega = moon_orientation_raw(day)
    np.testing.assert_allclose(omega, c.moon_omega_at_epoch, rtol=1e-12, atol=1e-16)


def test_orientation_quaternion_matches_euler_angles():
    days = np.linspace(-30000.0, 70000.0, 7)
    quaternion, omega = moon_orientation_raw(days)
    assert quaternion.shape == (7, 4) and omega.shape == (7, 3)
    angles, _ = moon_libration_angles(Time(2451545.0 + days, format="jd", scale="tdb"))
    for q, (phi, theta, psi) in zip(quaternion, angles.to_value(u.rad)):
        np.testing.assert_allclose(quat_to_attitude(q), euler313_to_attitude(phi, theta, psi), atol=1e-12)
    # Spin ≈ one turn per sidereal month (27.3217 d), about the C axis.
    assert np.all(np.abs(omega[:, 2] - 2 * np.pi / 27.321661) < 2e-3)


def test_constants_are_read_and_moments_derived():
    c = de421_constants()
    assert c.moon_beta == pytest.approx(6.310022e-4, rel=1e-6)
    assert c.moon_gamma == pytest.approx(2.277305e-4, rel=1e-6)
    assert c.gm["sun"] == pytest.approx(0.01720209895**2, rel=1e-15)  # Gauss's k², REBOUND's G
    assert c.gm["earth"] + c.gm["moon"] == pytest.approx(c.gm["earth-moon barycenter"], rel=1e-15)
    assert set(c.moon_degree3) == {"C31M", "S31M", "C32M", "S32M", "C33M", "S33M"}
    assert len(c.moon_degree4) == 8
    # C/MR² two ways: from C22 and γ, and from J2 with β and γ. They must be DE421's single value.
    beta, gamma = c.moon_beta, c.moon_gamma
    from_j2 = c.moon_j2 / ((beta - gamma) / (1 + beta) + gamma / 2)
    assert c.moon_c_over_mr2 == pytest.approx(from_j2, rel=1e-13)
    a, b, cc = c.moon_moments_over_mr2
    assert a < b < cc
    assert (cc - a) / b == pytest.approx(beta, rel=1e-12)
    assert (b - a) / cc == pytest.approx(gamma, rel=1e-12)
    assert cc - (a + b) / 2 == pytest.approx(c.moon_j2, rel=1e-12)
    assert (b - a) / 4 == pytest.approx(c.moon_c22, rel=1e-12)
    with pytest.raises(TypeError):
        c.header["AU"] = 1.0  # read-only


def test_earth_from_moon_is_the_difference_of_the_barycentric_states():
    from spinorbit.ephemeris import barycentric_state_au, earth_from_moon_au

    days = np.linspace(-3000.0, 7000.0, 11)
    relative, rate = earth_from_moon_au(days)
    (earth, earth_v), (moon, moon_v) = barycentric_state_au("earth", days), barycentric_state_au("moon", days)
    # The barycentric difference cancels ~1 au to 0.0026 au: rounding ~ ε·400 ≈ 1e-13 relative.
    np.testing.assert_allclose(relative, earth - moon, rtol=0, atol=1e-12 * np.abs(relative).max())
    np.testing.assert_allclose(rate, earth_v - moon_v, rtol=0, atol=1e-12 * np.abs(rate).max())
