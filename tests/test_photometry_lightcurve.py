"""Lightcurves: phase functions against sbpy, light time against a root finder, the two attitude sources
against each other, aspect angles against the body frame, and the errors of bad input.

The orbit is ``Orbit.circular`` (a circle about the barycentre with a closed-form position), so the
light-time reference can solve |R(t − τ) − R_earth(t)| = cτ with its own root finder on the formula.
"""

import math
import warnings

import numpy as np
import pytest
from astropy import units as u
from astropy.time import Time
from scipy.optimize import brentq

from spinorbit import RigidBody, RotationState
from spinorbit.core.photometry.phase_functions import hg1g2_basis
from spinorbit.ephemeris import EphemerisRangeError, barycentric_state_km, de421_constants
from spinorbit.photometry import (
    HG1G2,
    Ellipsoid,
    LinearExponential,
    NoLightError,
    ObserverInsideBodyError,
    PhotometryError,
    brightness,
    lightcurve,
    reduced_magnitudes,
    viewing_geometry,
)
from spinorbit.photometry.phase import sphere_brightness
from spinorbit.scene import Orbit, Scene
from spinorbit.shape import ellipsoid_shape
from spinorbit.time import tdb_days

with warnings.catch_warnings():  # sbpy's import warns about astropy's deprecated test runner
    warnings.simplefilter("ignore")
    from sbpy.photometry import HG1G2 as SbpyHG1G2

#: sbpy and our splines are the same cubic through the same nodes, evaluated in different orders.
SBPY_TOLERANCE_MAG = 1e-12
RADIUS_AU = 1.4
EPOCH = Time("2024-03-01T00:00:00", scale="tdb")
TIMES = EPOCH + np.linspace(0.0, 1.0, 40) * u.day


def circular_orbit():
    return Orbit.circular(RADIUS_AU * u.au, name="rock")


def circular_position_km(day):
    """The closed form of Orbit.circular (ICRF xy plane, +x at J2000, Kepler's rate of DE421's GM_Sun)."""
    constants = de421_constants()
    n = math.sqrt(constants.gm["sun"] / RADIUS_AU**3)
    return RADIUS_AU * constants.au_km * np.array([math.cos(n * day), math.sin(n * day), 0.0])


def spinning_state(pole_tilt_deg=30.0):
    """A principal-axis rotator about its body z axis (the largest moment), 6 h period, pole tilted from ICRF z."""
    body = RigidBody([1.0, 1.3, 1.6])
    tilt = math.radians(pole_tilt_deg)
    quaternion = [math.cos(tilt / 2), math.sin(tilt / 2), 0.0, 0.0]
    return RotationState(body, quaternion, [0.0, 0.0, 2 * math.pi / 0.25] * u.rad / u.day, epoch=EPOCH)


def test_hg1g2_basis_matches_sbpy():
    alpha = np.radians(np.linspace(0.0, 179.0, 721))
    for g1, g2, index in ((1.0, 0.0, 0), (0.0, 1.0, 1), (0.0, 0.0, 2)):
        with np.errstate(divide="ignore"):  # Φ3 = 0 beyond 30°: sbpy's magnitude is +inf there
            sbpy_phi = 10 ** (-0.4 * SbpyHG1G2.evaluate(alpha, 0.0, g1, g2))
        assert np.allclose(hg1g2_basis(alpha)[index], sbpy_phi, rtol=1e-13, atol=1e-15)


@pytest.mark.parametrize("law", ["lommel-seeliger", "lambert", "kaasalainen"])
def test_a_sphere_follows_sbpys_hg1g2_phase_curve(law):
    # The equal-volume sphere's reduced magnitude is H − 2.5 log10 Φ(α) by construction (docs/photometry.md).
    alpha = np.radians([0.0, 0.5, 3.0, 7.5, 20.0, 45.0, 90.0, 120.0])
    sun = np.stack([np.cos(alpha), np.sin(alpha), 0 * alpha], axis=1)
    observer = np.tile([1.0, 0.0, 0.0], (alpha.size, 1))
    sphere = Ellipsoid([0.3, 0.3, 0.3] * u.km)
    if law == "lommel-seeliger":  # the brightness door's closed form
        values = brightness(sphere, sun, observer, law=law).to_value(u.km**2)
    else:  # the sphere's phase integral (the facet model of the door converges to it: test_photometry_brightness)
        values = 0.3**2 * sphere_brightness(alpha, law)
    phase = HG1G2(15.2 * u.mag, 0.58, 0.21)
    magnitudes = reduced_magnitudes(values, alpha, sphere, phase, law)
    expected = SbpyHG1G2.evaluate(alpha, 15.2, 0.58, 0.21)
    tolerance = SBPY_TOLERANCE_MAG
    assert np.max(np.abs(magnitudes - expected)) < tolerance


def test_linear_exponential_multiplies_the_law():
    alpha = np.radians([0.0, 5.0, 30.0, 80.0])
    sun = np.stack([np.cos(alpha), np.sin(alpha), 0 * alpha], axis=1)
    observer = np.tile([1.0, 0.0, 0.0], (alpha.size, 1))
    sphere = Ellipsoid([1.0, 1.0, 1.0] * u.km)
    phase = LinearExponential(12.0 * u.mag, amplitude=0.4, width=0.08 * u.rad, slope=-0.6 / u.rad)
    magnitudes = reduced_magnitudes(brightness(sphere, sun, observer).value, alpha, sphere, phase)
    f = 0.4 * np.exp(-alpha / 0.08) - 0.6 * alpha + 1.0
    expected = 12.0 - 2.5 * np.log10(f / 1.4 * sphere_brightness(alpha) / sphere_brightness(0.0))
    assert np.allclose(magnitudes, expected, rtol=0, atol=1e-13)


def test_light_time_solves_the_light_cone():
    geometry = viewing_geometry(TIMES[:5], circular_orbit())
    c = 299_792.458
    for t, tau in zip(TIMES[:5], geometry.light_time_s):
        day, rest = tdb_days(t)
        earth = barycentric_state_km("earth", day, rest)[0]

        def cone(tau_s):
            return np.linalg.norm(circular_position_km(day + rest - tau_s / 86400.0) - earth) - c * tau_s

        reference = brentq(cone, 0.0, 5000.0, xtol=1e-12, rtol=1e-15)
        assert abs(tau - reference) < 1e-7  # s: the root's bracket and DE421's float days (0.3 µs)
    assert np.all(geometry.light_time_s > 60)


def test_scene_result_and_state_give_the_same_lightcurve():
    orbit, state, shape = circular_orbit(), spinning_state(), Ellipsoid([0.5, 0.35, 0.25] * u.km)
    from_state = lightcurve(state, shape, orbit, times=TIMES)
    result = Scene(state, times=from_state["body_time"]).run()
    from_scene = lightcurve(result, shape, orbit)
    # The scene's observation times are t_e + τ: the state's within the light-time iteration's 1e-9 s.
    assert np.max(np.abs((from_scene["time"] - from_state["time"]).to_value(u.s))) < 1e-6
    assert np.max(np.abs(from_scene["magnitude"] - from_state["magnitude"])).to_value(u.mag) < 1e-9
    assert np.ptp(from_state["magnitude"].value) > 0.2  # the elongated body has a lightcurve


def test_aspect_angles_and_body_frame_directions():
    table = lightcurve(spinning_state(), Ellipsoid([0.5, 0.35, 0.25] * u.km), circular_orbit(), times=TIMES)
    # Spin about body z, so L ∥ z: the sub-observer latitude is 90° minus the aspect angle (the same for the Sun).
    assert np.allclose(table["observer_lat"].value, 90.0 - table["aspect_angle"].value, atol=1e-9)
    assert np.allclose(table["sun_lat"].value, 90.0 - table["solar_aspect_angle"].value, atol=1e-9)
    # The sub-observer longitude turns once per 6 h period: 4 turns a day (against the rotation).
    turns = np.unwrap(np.radians(table["observer_lon"].value))
    assert abs(abs(turns[-1] - turns[0]) / (2 * math.pi) - 4.0) < 0.01
    assert "convex" in table.meta["shadowing"]
    reduced = table["magnitude"] - 5 * np.log10(table["r"].value * table["delta"].value) * u.mag
    assert np.allclose(reduced.value, table["reduced_magnitude"].value, atol=1e-12)


def test_bad_input_gets_specific_errors():
    orbit, state, shape = circular_orbit(), spinning_state(), Ellipsoid([0.5, 0.35, 0.25] * u.km)
    with pytest.raises(EphemerisRangeError, match="DE421"):
        lightcurve(state, shape, orbit, times=Time(["2250-01-01"], scale="tdb"))
    day, rest = tdb_days(TIMES[:2])
    body = np.array([circular_position_km(d + r) for d, r in zip(day, rest)])
    with pytest.raises(ObserverInsideBodyError, match="inside its outer radius"):
        lightcurve(state, shape, orbit, times=TIMES[:2], observer=(body + [0.1, 0.0, 0.0]) * u.km)
    # An observer straight behind the body, as seen from the Sun: the phase angle is 180° but for the body's
    # motion during the light time (1e-4 rad), and no facet of a coarse mesh faces both.
    sun = np.array([barycentric_state_km("sun", d, r)[0] for d, r in zip(day, rest)])
    behind = body + 1e6 * (body - sun) / np.linalg.norm(body - sun, axis=1)[:, None]
    with pytest.raises(NoLightError, match="no facet facing the Sun and the observer"):
        lightcurve(state, ellipsoid_shape([0.5, 0.35, 0.25] * u.km, 2), orbit, times=TIMES[:2],
                   observer=behind * u.km)
    with pytest.raises(PhotometryError, match="DE421 body name"):
        lightcurve(state, shape, orbit, times=TIMES[:2], observer="vulcan")
    with pytest.raises(PhotometryError, match="no epoch"):
        lightcurve(state.with_epoch(None), shape, orbit, times=TIMES[:2])
    with pytest.raises(PhotometryError, match="needs the observation times"):
        lightcurve(state, shape, orbit)
    with pytest.raises(PhotometryError, match="RotationState or a spinorbit.scene.SceneResult"):
        lightcurve("state", shape, orbit, times=TIMES[:2])
    with pytest.raises(PhotometryError, match="G1 ≥ 0"):
        HG1G2(15 * u.mag, 0.8, 0.5)


def test_body_frame_turns_by_the_attitude_matrix():
    from spinorbit.core.math.rotations import quat_to_attitude
    from spinorbit.photometry.lightcurve import body_frame

    rng = np.random.default_rng(2)
    quaternions = rng.normal(size=(6, 4))
    quaternions /= np.linalg.norm(quaternions, axis=1)[:, None]
    vectors = rng.normal(size=(6, 3))
    vectors /= np.linalg.norm(vectors, axis=1)[:, None]
    expected = np.array([quat_to_attitude(q) @ v for q, v in zip(quaternions, vectors)])
    assert np.allclose(body_frame(vectors, quaternions), expected, rtol=0, atol=1e-15)


def test_a_lightcurve_written_as_damit_keeps_its_geometry(tmp_path):
    from spinorbit.photometry import read_damit, write_damit

    table = lightcurve(spinning_state(), Ellipsoid([0.5, 0.35, 0.25] * u.km), circular_orbit(), times=TIMES[:6])
    again = read_damit(write_damit(table, tmp_path / "lc.txt"))
    assert np.max(np.abs((again["time"] - table["body_time"]).to_value(u.s))) < 1e-3  # JD to 8 decimals
    assert np.allclose(again["sun_vector"].value, table["sun_vector"].value, atol=2e-12)  # 12 decimals, rotated
    assert np.allclose(again["observer_vector"].value, table["observer_vector"].value, atol=2e-12)
    assert np.allclose(again["brightness"], 10 ** (-0.4 * table["magnitude"].value), rtol=1e-10)
    # The vectors are the geometry's: their lengths are r and Δ.
    assert np.allclose(np.linalg.norm(again["sun_vector"].value, axis=1), table["r"].value, rtol=1e-11)
