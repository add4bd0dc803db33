"""A Scene that feels sunlight: ThermalModel, Orbit.kepler, the planner's full or mean YORP route, and bad input.

References: the Scene's full route against the core's quaternion integrator on a model built here
from the shape's block (the same numbers); the mean route against ``propagate_mean_thermal`` called
directly; the mean route against the full route over spans both afford, within the mean route's own
error estimate; Orbit.kepler's Sun against the independent element conversion of
:func:`spinorbit.orbital_elements.elements_to_state`.
"""

import math

import numpy as np
import pytest
from astropy import units as u
from astropy.time import Time

from spinorbit.quantities import QuantityInputError
from spinorbit import RigidBody, RotationState
from spinorbit.core.averaging.thermal_mean import SeparatrixReachedError, propagate_mean_thermal
from spinorbit.core.dynamics.equations import MODEL_PERTURBERS, make_model
from spinorbit.core.integrators.elements import elements_of_state
from spinorbit.core.integrators.quaternion import integrate_quaternion
from spinorbit.core.model.perturbers import perturber_state
from spinorbit.ephemeris import de421_constants
from spinorbit.orbital_elements import check_elements, elements_to_state
from spinorbit.scene import (Orbit, PlanError, Scene, SeparatrixCrossingError, ThermalInputError, ThermalModel,
                             VanishingYorpWarning)
from spinorbit.scene.thermal_planning import mean_difference
from spinorbit.shape import (InertiaMismatchError, ellipsoid_shape, gaussian_random_sphere, rigid_body_from_shape,
                             shape_mass_properties)
from spinorbit.shape import thermal_block

DENSITY = 2000 * u.kg / u.m**3
EPOCH = Time("2020-01-01", scale="tdb")
ELEMENTS = (1 * u.au, 0.1, 5 * u.deg, 20 * u.deg, 30 * u.deg, 0 * u.deg)
SPIN = 2 * math.pi / 0.25  # rad/day: a 6-h rotation
#: Orbit.kepler's Sun against elements_to_state: two Kepler solvers and two rotation chains, relative.
KEPLER_RTOL = 1e-11
#: Mean against full changes of S, Z, H over 4 whole orbits for a 60 m body: docs/thermal.md's table
#: gives 1.3e-3 … 6e-2 of the changes at 10–40 yr (the first-order theory's error); 0.1 holds them all.
CHANGE_RTOL = 0.1


def _body_and_thermal(radius_km, mu_q=None):
    shape = gaussian_random_sphere(radius_km * u.km, 0.15, seed=5, subdivisions=2)
    return shape, rigid_body_from_shape(shape, density=DENSITY), ThermalModel.from_shape(shape, DENSITY, mu_q=mu_q)


def _tumbler(body, spin=(0.3, 0.1, 1.0)):
    q = np.array([0.9, 0.2, -0.3, 0.25])
    return RotationState(body, q / np.linalg.norm(q), np.array(spin) * SPIN * u.rad / u.day)


@pytest.fixture(scope="module")
def small():
    shape, body, thermal = _body_and_thermal(0.06)
    return shape, body, thermal, _tumbler(body), Orbit.kepler(*ELEMENTS, EPOCH)


def _elements(table):
    s, z, h = (table[c].value for c in ("S", "Z", "H"))
    return np.stack([s, z, h, 0 * s, 0 * s, np.radians(table["h"].to_value(u.deg))], axis=1)


def test_kepler_orbit_puts_the_sun_where_the_elements_say(small):
    orbit = small[4]
    model = make_model([1.0, 2.0, 3.0], [orbit.kepler_sun()])
    a_km, e, inc, raan, argp, mean_anomaly = check_elements(*ELEMENTS)
    constants = de421_constants()
    position, velocity = elements_to_state(a_km / constants.au_km, e, inc, raan, argp, mean_anomaly,
                                           constants.gm["sun"], "ecliptic")
    sun = perturber_state(orbit.kepler_elements[-1], model, MODEL_PERTURBERS + 1)
    assert np.allclose(sun[:3], -position, rtol=0, atol=KEPLER_RTOL * np.linalg.norm(position))
    assert np.allclose(sun[3:], -velocity, rtol=0, atol=KEPLER_RTOL * np.linalg.norm(velocity))
    normal = np.cross(position, velocity)
    assert np.allclose(orbit.kepler_frame()[2], normal / np.linalg.norm(normal), atol=1e-14)
    assert np.allclose(orbit.kepler_frame() @ orbit.kepler_frame().T, np.eye(3), atol=1e-15)


def test_full_route_is_the_core_integration(small):
    shape, body, _, state, orbit = small
    times = EPOCH + np.linspace(5, 60, 12) * u.day
    result = Scene(state, EPOCH, times, orbit=orbit, thermal=small[2], thermal_route="full").run()
    assert result.plan.route == "thermal-full" and result.tolerance_met
    # Built here from the shape, not through the Scene: the block, the Sun, the model, the integration.
    block = thermal_block(shape, shape_mass_properties(shape, density=DENSITY))
    model = make_model(body.principal_moments, [orbit.kepler_sun()], thermal=block, thermal_sun=0)
    t0 = orbit.kepler_elements[-1]
    ys = integrate_quaternion(state.core_state(), t0, t0 + np.linspace(5, 60, 12), model,
                              rtol=result.table.meta["rtol"])
    q = np.stack([result.table[c] for c in ("q_w", "q_x", "q_y", "q_z")], axis=1)
    ys[:, :4] /= np.linalg.norm(ys[:, :4], axis=1, keepdims=True)
    sign = np.sign(np.sum(q * ys[:, :4], axis=1))[:, None]
    assert np.max(np.abs(q - sign * ys[:, :4])) <= 4e-16
    assert np.max(np.abs(result.table["omega_z"].to_value(u.rad / u.day) / ys[:, 6] - 1.0)) <= 4e-16
    assert {"S", "Z", "H", "h", "obliquity", "pole_ra"} <= set(result.table.colnames)


def test_mean_route_is_propagate_mean_thermal(small):
    _, body, thermal, state, orbit = small
    days = np.arange(1, 6) * 400.0
    scene = Scene(state, EPOCH, EPOCH + days * u.day, orbit=orbit, thermal=thermal, thermal_route="mean",
                  tolerance=0.05 * u.rad)
    result = scene.run()
    assert result.plan.route == "thermal-mean"
    model = make_model(body.principal_moments, [orbit.kepler_sun()],
                       thermal=thermal_block(thermal.shape, thermal.properties), thermal_sun=0)
    frame = orbit.kepler_frame()
    t0 = orbit.kepler_elements[-1]
    el0 = elements_of_state(state.core_state(), model, frame)
    direct, _ = propagate_mean_thermal(el0, t0, t0 + days, model, frame, result.table.meta["mean_step_days"])
    got = _elements(result.table)
    assert np.array_equal(got[:, :3], direct[:, :3])
    assert np.allclose(got[:, 5], np.mod(direct[:, 5], 2 * math.pi), rtol=0, atol=1e-13)
    assert "q_w" not in result.table.colnames and "omega_x" not in result.table.colnames
    cos_obliquity = direct[:, 2] / direct[:, 1]
    assert np.allclose(np.cos(result.table["obliquity"].to_value(u.rad)), cos_obliquity, atol=1e-12)
    assert set(result.error_parts) >= {"short_period", "averaging", "integration"}
    assert "rotation phase is not followed" in result.table.meta["estimated"]


def test_planner_chooses_mean_for_a_long_span_and_full_for_a_short_one(small):
    _, _, thermal, state, orbit = small
    short = Scene(state, EPOCH, EPOCH + np.linspace(0.1, 2, 5) * u.yr, orbit=orbit, thermal=thermal,
                  tolerance=1 * u.arcsec).plan()
    assert short.route == "thermal-full"
    text = str(short)
    assert "the mean route is not taken" in text and "> tolerance 1 arcsec" in text and "orbits" in text
    long = Scene(state, EPOCH, EPOCH + np.linspace(1e3, 2e4, 5) * u.yr, orbit=orbit, thermal=thermal,
                 tolerance=1 * u.deg).plan()
    assert long.route == "thermal-mean"
    text = str(long)
    assert "within the tolerance and cheaper" in text and "rotations" in text and "1 − m" in text
    assert "not approaching the separatrix" in text or "separatrix in" in text


def test_forced_routes(small):
    _, _, thermal, state, orbit = small
    mean = Scene(state, EPOCH, EPOCH + np.linspace(0.1, 2, 5) * u.yr, orbit=orbit, thermal=thermal,
                 tolerance=1 * u.arcsec, thermal_route="mean").plan()
    assert mean.route == "thermal-mean" and "forced" in str(mean) and "NOTE its estimate exceeds" in str(mean)
    full = Scene(state, EPOCH, EPOCH + np.linspace(1e3, 2e4, 5) * u.yr, orbit=orbit, thermal=thermal,
                 tolerance=1 * u.deg, thermal_route="full").plan()
    assert full.route == "thermal-full" and "forced" in str(full)


def test_mean_route_agrees_with_the_full_route_within_its_estimate(small):
    shape, _, _, state, orbit = small
    # The full route on the facet sum itself: the mean route averages the facets exactly, and the degree-8
    # harmonics' mean torque differs from theirs by ~15 % here (docs/thermal.md), more than CHANGE_RTOL.
    thermal = ThermalModel.from_shape(shape, DENSITY, torque="facets")
    period = 2 * math.pi / math.sqrt(de421_constants().gm["sun"] / orbit.kepler_elements[0] ** 3)
    # Whole orbits (the orbit's short-period terms return) and half orbits (they do not).
    days = period * np.array([1.0, 1.5, 2.5, 4.0])
    results = {route: Scene(state, EPOCH, EPOCH + days * u.day, orbit=orbit, thermal=thermal,
                            tolerance=0.01 * u.rad, thermal_route=route).run() for route in ("full", "mean")}
    full, mean = (_elements(results[r].table) for r in ("full", "mean"))
    difference = mean_difference(full, mean)
    estimate = results["mean"].error_estimate.to_value(u.rad)
    assert difference <= estimate
    # The estimate is not vacuous: the half-orbit rows differ by a tenth of it or more (measured: 0.55).
    assert mean_difference(full[[1, 2]], mean[[1, 2]]) >= 0.1 * estimate
    el0 = elements_of_state(state.core_state(), results["full"].plan.thermal["setup"].model, orbit.kepler_frame())
    for k in (0, 1, 2):
        change_full, change_mean = full[-1, k] - el0[k], mean[-1, k] - el0[k]
        assert abs(change_full) > 1e-6 * abs(el0[1])
        assert change_mean == pytest.approx(change_full, rel=CHANGE_RTOL)


def test_a_mean_step_does_not_jump_the_separatrix():
    _, body, thermal = _body_and_thermal(0.03)
    state = _tumbler(body, (0.02, 1.0, 0.2))  # SAM, 1 − m ≈ 0.05, driven toward the separatrix
    orbit = Orbit.kepler(*ELEMENTS, EPOCH)
    scene = Scene(state, EPOCH, EPOCH + 1e4 * u.yr, orbit=orbit, thermal=thermal, tolerance=0.1 * u.rad,
                  thermal_route="mean")
    setup = scene.plan().thermal["setup"]
    with pytest.raises(SeparatrixReachedError):  # steps of 200 yr: one would carry it across unnoticed
        propagate_mean_thermal(setup.el0, setup.t0, setup.t0 + np.array([1e4]) * 365.25, setup.model,
                               setup.frame, 200 * 365.25)
    with pytest.raises(SeparatrixCrossingError, match="separatrix near") as caught:
        # 3e4 yr: the full route would need ~3e9 right-hand sides, above MAX_FULL_RHS
        Scene(state, EPOCH, EPOCH + 3e4 * u.yr, orbit=orbit, thermal=thermal, tolerance=0.1 * u.rad).plan()
    assert 100 < (caught.value.time - EPOCH).to_value(u.yr) < 1e4
    times = EPOCH + np.linspace(50, 1e4, 200) * u.yr
    with pytest.raises(SeparatrixCrossingError, match="reached the separatrix") as caught:
        Scene(state, EPOCH, times, orbit=orbit, thermal=thermal, tolerance=0.1 * u.rad, thermal_route="mean").run()
    reached = (caught.value.time - EPOCH).to_value(u.yr)
    assert 100 < reached < 1e4
    assert caught.value.table is not None and len(caught.value.table) >= 1
    assert (caught.value.table["time"][-1] - EPOCH).to_value(u.yr) <= reached


def test_thermal_model_quantities(small):
    shape, body, thermal, _, _ = small
    damped = ThermalModel.from_shape(shape, DENSITY, mu_q=1e9 * u.Pa)
    # Burns & Safronov: τ_D = μQ/(ρ K₃² R² ω³) in SI, against the model's k/ω³.
    omega = 1e-4 * u.rad / u.s
    expected = (1e9 / (2000 * 0.01 * damped.mean_radius.to_value(u.m) ** 2 * 1e-12) * u.s).to(u.yr)
    assert damped.damping_time(omega).to_value(u.yr) == pytest.approx(expected.value, rel=1e-12)
    assert thermal.damping_constant == 0.0
    force, torque = thermal.force_and_torque([1.0, 0.2, 0.1], 1 * u.au)
    assert force.unit == u.N and torque.unit == u.N * u.m
    assert 0 < np.linalg.norm(torque.value) <= thermal.torque_bound(1 * u.au).value
    far_force, _ = thermal.force_and_torque([1.0, 0.2, 0.1], 2 * u.au)
    assert np.allclose(far_force.value, force.value / 4, rtol=1e-14)


def test_bad_thermal_input(small):
    shape, body, thermal, state, orbit = small
    times = EPOCH + [10, 20] * u.day
    with pytest.raises(ThermalInputError, match="Shape"):
        ThermalModel.from_shape("asteroid.obj", DENSITY)
    with pytest.raises(QuantityInputError, match="density expects a mass density Quantity .*bare float 2000.0"):
        ThermalModel.from_shape(shape, 2000.0)
    with pytest.raises(ThermalInputError, match="positive"):
        ThermalModel.from_shape(shape, -2000 * u.kg / u.m**3)
    with pytest.raises(ThermalInputError, match="efficiency"):
        ThermalModel.from_shape(shape, DENSITY, efficiency=1.5)
    with pytest.raises(QuantityInputError, match="mu_q expects a stress Quantity .*bare float"):
        ThermalModel.from_shape(shape, DENSITY, mu_q=1e9)
    with pytest.raises(ThermalInputError, match="torque expects"):
        ThermalModel.from_shape(shape, DENSITY, torque="exact")
    with pytest.raises(ThermalInputError, match="harmonics' degree"):
        ThermalModel.from_shape(shape, DENSITY, degree=12, torque="facets")
    with pytest.raises(ThermalInputError, match="distance"):
        thermal.force_and_torque([1.0, 0.0, 0.0], 0 * u.au)
    with pytest.raises(ThermalInputError, match="distance"):
        thermal.torque_bound(-1 * u.au)
    with pytest.raises(ThermalInputError, match="orbit=Orbit.kepler"):
        Scene(state, EPOCH, times, thermal=thermal)
    with pytest.raises(ThermalInputError, match="kind 'ephemeris'"):
        Scene(state, EPOCH, times, orbit=Orbit.circular(1 * u.au), thermal=thermal)
    with pytest.raises(ThermalInputError, match="earth"):
        Scene(state, EPOCH, times, perturbers=("sun", "earth"), orbit=orbit, thermal=thermal)
    with pytest.raises(ThermalInputError, match="thermal_route"):
        Scene(state, EPOCH, times, orbit=orbit, thermal=thermal, thermal_route="fast")
    with pytest.raises(ThermalInputError, match="ThermalModel"):
        Scene(state, EPOCH, times, orbit=orbit, thermal=shape)
    with pytest.raises(ThermalInputError, match="thermal=ThermalModel"):
        Scene(state, EPOCH, times, orbit=orbit)
    with pytest.raises(Exception, match="after the epoch"):
        Scene(state, EPOCH, EPOCH - [10, 5] * u.day, orbit=orbit, thermal=thermal)
    denser = RotationState(rigid_body_from_shape(shape, density=3000 * u.kg / u.m**3), state.quaternion,
                           state.angular_velocity)
    with pytest.raises(InertiaMismatchError, match="differ from its shape"):
        Scene(denser, EPOCH, times, orbit=orbit, thermal=thermal)
    ratios = RotationState(RigidBody(np.array(body.principal_moments) / body.principal_moments[2]),
                           state.quaternion, state.angular_velocity)
    with pytest.raises(ThermalInputError, match="kg m²"):
        Scene(ratios, EPOCH, times, orbit=orbit, thermal=thermal)
    with pytest.raises(PlanError, match="cannot run"):
        about_b = _tumbler(body, (1e-6, 1.0, 1e-6))  # at the separatrix: no torus to average over
        Scene(about_b, EPOCH, EPOCH + 100 * u.yr, orbit=orbit, thermal=thermal, tolerance=0.1 * u.rad,
              thermal_route="mean").plan()


def test_a_shape_without_yorp_by_symmetry_warns(small):
    """A triaxial ellipsoid mirrors itself in its principal planes: its mean YORP is zero, and a run says so."""
    ellipsoid = ellipsoid_shape([0.06, 0.05, 0.04] * u.km, subdivisions=2)
    thermal = ThermalModel.from_shape(ellipsoid, DENSITY)
    assert thermal.mirror_planes == (0, 1, 2) and not small[2].yorp_vanishes
    state = _tumbler(rigid_body_from_shape(ellipsoid, density=DENSITY))
    scene = Scene(state, EPOCH, EPOCH + [5, 10] * u.day, orbit=small[4], thermal=thermal, thermal_route="full")
    with pytest.warns(VanishingYorpWarning, match="zero by symmetry"):
        scene.run()


def test_only_a_kepler_orbit_carries_elements():
    """The elements field must not share its name with the ``Orbit.kepler`` constructor: a dataclass
    then takes the bound classmethod as every other orbit's default (a truthy non-tuple)."""
    assert Orbit.circular(2.0 * u.au).kepler_elements is None
    assert Orbit.de421("moon").kepler_elements is None
    elements = Orbit.kepler(*ELEMENTS, EPOCH).kepler_elements
    assert isinstance(elements, tuple) and len(elements) == 7
    assert all(isinstance(value, float) for value in elements)
