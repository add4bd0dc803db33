"""The spin pole (RA, Dec; ecliptic λ, β of J2000) and the obliquity, against astropy and DE421.

astropy's ``BarycentricMeanEcliptic(equinox="J2000")`` is the independent reference of the ecliptic
(it goes through ERFA ``ecm06``: the IAU 2006 obliquity 84381.406″ and the frame bias), ``ICRS`` that
of (RA, Dec). The orbit normal of the obliquity is checked against DE421's own states.
"""

import numpy as np
import pytest
from astropy import units as u
from astropy.coordinates import ICRS, BarycentricMeanEcliptic, SkyCoord
from astropy.time import Time

from spinorbit import RigidBody, RotationState
from spinorbit.pole import obliquity_deg, orbit_normals, pole_angles_deg

#: Angles from unit vectors by atan2/asin on both sides, through different rotation matrices
#: (spinorbit's R1(ε₀)·B against ERFA's ecm06): measured ≤ 7e-16 on the vectors (frames.py), so
#: 1e-12 deg (3.6 nas) leaves margin for the trigonometry and nothing else.
ANGLE_ATOL_DEG = 1e-12


def _wrapped(a, b):
    return (np.asarray(a) - np.asarray(b) + 180.0) % 360.0 - 180.0


def test_pole_angles_match_astropy_icrs_and_ecliptic_j2000():
    rng = np.random.default_rng(15)
    directions = rng.normal(size=(200, 3))
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    ra, dec, lon, lat = pole_angles_deg(directions)
    coords = SkyCoord(x=directions[:, 0], y=directions[:, 1], z=directions[:, 2], frame=ICRS(),
                      representation_type="cartesian")
    coords = coords.represent_as("unitspherical")
    assert np.abs(_wrapped(ra, coords.lon.deg)).max() < ANGLE_ATOL_DEG
    assert np.abs(dec - coords.lat.deg).max() < ANGLE_ATOL_DEG
    ecliptic = SkyCoord(ra=ra * u.deg, dec=dec * u.deg, frame="icrs").transform_to(BarycentricMeanEcliptic(equinox="J2000"))
    assert np.abs(_wrapped(lon, ecliptic.lon.deg)).max() < 1e-9  # via astropy's own (RA, Dec) round trip
    assert np.abs(lat - ecliptic.lat.deg).max() < 1e-9
    assert np.all((0 <= ra) & (ra < 360) & (0 <= lon) & (lon < 360))


def test_rotation_state_pole_and_obliquity():
    body = RigidBody([1.0, 2.0, 3.0])
    # spin about C, body axes = ICRF axes: the pole is the ICRF z axis, Dec 90°; in ecliptic J2000
    # λ = 90°, β = 90° − ε₀
    state = RotationState(body, [1, 0, 0, 0], [0, 0, 10.0] * u.rad / u.day)
    assert state.pole_icrf[1].to_value(u.deg) == pytest.approx(90.0, abs=1e-12)
    lon, lat = state.pole_ecliptic
    assert lat.to_value(u.deg) == pytest.approx(90.0 - 84381.406 / 3600, abs=2e-5)  # the frame bias: 23 mas
    assert lon.to_value(u.deg) == pytest.approx(90.0, abs=1e-4)
    # obliquity against a normal tilted by 30° (and the retrograde case)
    tilt = np.radians(30.0)
    assert state.obliquity([0, np.sin(tilt), np.cos(tilt)]).to_value(u.deg) == pytest.approx(30.0, abs=1e-12)
    assert state.obliquity([0, 0, -5.0]).to_value(u.deg) == pytest.approx(180.0, abs=1e-12)
    with pytest.raises(ValueError, match="non-zero"):
        state.obliquity([0, 0, 0])


def test_obliquity_is_accurate_near_0_and_180_deg():
    small = 1e-10
    assert obliquity_deg([[np.sin(small), 0, np.cos(small)]], [[0, 0, 1]])[0] == pytest.approx(np.degrees(small), rel=1e-9)
    assert obliquity_deg([[np.sin(small), 0, -np.cos(small)]], [[0, 0, 1]])[0] == pytest.approx(180 - np.degrees(small),
                                                                                              abs=1e-12)


def test_heliocentric_normals_from_samples_match_de421_states():
    from spinorbit.coupling.one_way import heliocentric_normals
    from spinorbit.coupling.sampling import de421_orbit, sample_from_ephemeris
    from spinorbit.ephemeris import barycentric_state_au
    from spinorbit.time import tdb_days

    start = Time("2010-01-01", scale="tdb")
    samples = sample_from_ephemeris(de421_orbit("moon"), start, start + 60 * u.day, perturbers=("sun", "earth"),
                                    tolerance=1e-10)
    times = start + np.linspace(0.0, 60.0, 97) * u.day
    days = np.sum(tdb_days(times), axis=0)
    normals = heliocentric_normals(samples, days)
    (moon_r, moon_v), (sun_r, sun_v) = barycentric_state_au("moon", days), barycentric_state_au("sun", days)
    direct = orbit_normals(moon_r - sun_r, moon_v - sun_v)
    # the Moon's heliocentric plane wobbles monthly: linear interpolation between the sampler's knots
    # follows it to 1e-5 deg (measured 4.4e-6 deg); at the knots it is exact to rounding
    angle = np.degrees(np.arccos(np.clip(np.sum(normals * direct, axis=1), -1, 1)))
    assert angle.max() < 1e-5
    assert angle[0] < 1e-9


def test_heliocentric_normals_refuse_times_outside_the_samples():
    from spinorbit.coupling.one_way import heliocentric_normals
    from spinorbit.coupling.sampling import de421_orbit, sample_from_ephemeris
    from spinorbit.time import tdb_days

    start = Time("2010-01-01", scale="tdb")
    samples = sample_from_ephemeris(de421_orbit("moon"), start, start + 10 * u.day, perturbers=("sun",), tolerance=1e-8)
    day = float(sum(tdb_days(start)))
    with pytest.raises(ValueError, match="sample the whole span"):
        heliocentric_normals(samples, [day - 1.0, day + 1.0])  # np.interp would have clamped silently
