"""The Sun's tide on a binary whose barycentre follows a Keplerian heliocentric orbit."""

import math

import astropy.units as u
import numpy as np
import pytest

from _binary_differences import rotation

from spinorbit.binary import HeliocentricOrbit, propagate
from spinorbit.core.binary import equations as eq
from spinorbit.core.binary.inertia_integrals import ellipsoid_integrals
from spinorbit.core.binary.propagate import propagate_binary
from spinorbit.core.math.rotations import matrix_to_quat, quat_to_matrix
from spinorbit.core.model.gravity_field import figure_torque, make_body
from spinorbit.core.model.perturbers import fixed_source, kepler_source
from spinorbit.data.didymos import didymos_state

# A pair in units G = 1 with the Sun close enough (|s| ~ 60 |R|) that the tide's degree-3 remainder,
# ~|R|/|s| of it, is well above rounding: the degree-2 term is then visibly the leading one.
AXES_A, AXES_B = (1.2, 1.0, 0.8), (0.5, 0.4, 0.3)
MASS_A, MASS_B = 2.0, 0.3
MU_SUN = 5.0e4
SUN_ELEMENTS = dict(a=200.0, e=0.3, inc=0.4, node=1.1, argp=-0.6, mean_anomaly=2.0)


def pair_with_sun(separation=(3.1, 1.2, -0.7)):
    model = eq.make_binary_model(1.0, ellipsoid_integrals(MASS_A, AXES_A), ellipsoid_integrals(MASS_B, AXES_B), 4,
                                 max(AXES_A) + max(AXES_B))
    sun = kepler_source(MU_SUN, SUN_ELEMENTS["a"], SUN_ELEMENTS["e"], SUN_ELEMENTS["inc"], SUN_ELEMENTS["node"],
                        SUN_ELEMENTS["argp"], SUN_ELEMENTS["mean_anomaly"], mu_orbit=MU_SUN + MASS_A + MASS_B,
                        sign=-1.0)
    y = np.zeros(eq.BINARY_STATE_SIZE)
    y[eq.POSITION:eq.POSITION + 3] = separation
    along = np.cross([0.0, 0.0, 1.0], separation)  # a near-circular mutual orbit
    y[eq.VELOCITY:eq.VELOCITY + 3] = along / np.linalg.norm(along) * math.sqrt((MASS_A + MASS_B)
                                                                                / np.linalg.norm(separation))
    y[eq.QUAT_A:eq.QUAT_A + 4] = matrix_to_quat(rotation([0.3, -0.2, 0.5]))
    y[eq.QUAT_B:eq.QUAT_B + 4] = matrix_to_quat(rotation([-0.4, 0.7, 0.1]))
    return eq.with_sun(model, sun), y


def sun_from_elements(t):
    """The Sun relative to the barycentre from the elements, solved here (Newton on E − e sin E = M)."""
    a, e, inc, node, argp, m0 = (SUN_ELEMENTS[k] for k in ("a", "e", "inc", "node", "argp", "mean_anomaly"))
    mean = m0 + math.sqrt((MU_SUN + MASS_A + MASS_B) / a ** 3) * t
    anomaly = mean
    for _ in range(50):
        anomaly -= (anomaly - e * math.sin(anomaly) - mean) / (1 - e * math.cos(anomaly))
    perifocal = np.array([a * (math.cos(anomaly) - e), a * math.sqrt(1 - e * e) * math.sin(anomaly), 0.0])

    def turn(axis, angle):
        c, s = math.cos(angle), math.sin(angle)
        if axis == 3:
            return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])
        return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])

    barycentre = turn(3, node) @ turn(1, inc) @ turn(3, argp) @ perifocal
    return -barycentre


@pytest.mark.parametrize("t", [0.0, 37.0])
def test_tidal_acceleration_is_the_difference_of_the_sun_s_pulls_to_its_degree_three_remainder(t):
    # Exact point-mass pulls on A and B minus each other: the degree-2 tide differs from it by the degree-3
    # term, of relative size ~|R|/|s| times an angular factor below 4 (measured 0.93 and 0.99 |R|/|s| at
    # the two times); halving R halves the relative difference (it is that term, not an error of the tide).
    differences = []
    for scale in (1.0, 0.5):
        model, y = pair_with_sun(np.array([3.1, 1.2, -0.7]) * scale)
        r = y[eq.POSITION:eq.POSITION + 3]
        s = sun_from_elements(t)
        r_a, r_b = -MASS_B / (MASS_A + MASS_B) * r, MASS_A / (MASS_A + MASS_B) * r
        pull = lambda d: MU_SUN * d / np.linalg.norm(d) ** 3  # noqa: E731
        exact = pull(s - r_b) - pull(s - r_a)
        tide, _, _ = eq.solar_terms(t, y, model)
        relative = np.linalg.norm(tide - exact) / np.linalg.norm(exact)
        assert relative <= 4.0 * np.linalg.norm(r) / np.linalg.norm(s)
        differences.append(relative)
    assert differences[1] == pytest.approx(0.5 * differences[0], rel=0.05)


def test_gravity_gradient_torques_are_gravity_field_s_degree_two_torque_of_the_sun():
    # gravity_field.py's torque of a point mass on a figure with moments (A, B, C) only (degree 2), the Sun at
    # its position on each body's axes measured from that body's centre: equal to rounding (1e-13 relative).
    t = 11.0
    model, y = pair_with_sun()
    _, torque_a, torque_b = eq.solar_terms(t, y, model)
    r = y[eq.POSITION:eq.POSITION + 3]
    s = sun_from_elements(t)
    centres = {"A": -MASS_B / (MASS_A + MASS_B) * r, "B": MASS_A / (MASS_A + MASS_B) * r}
    for name, axes, mass, offset, torque in (("A", AXES_A, MASS_A, eq.QUAT_A, torque_a),
                                             ("B", AXES_B, MASS_B, eq.QUAT_B, torque_b)):
        a2, b2, c2 = (x * x for x in axes)
        moments = (mass * (b2 + c2) / 5, mass * (a2 + c2) / 5, mass * (a2 + b2) / 5)
        body_sun = quat_to_matrix(y[offset:offset + 4]).T @ (s - centres[name])
        expected = figure_torque(body_sun, MU_SUN, make_body(moments))
        assert np.allclose(torque, expected, rtol=0, atol=1e-13 * np.linalg.norm(expected)), name
        assert np.linalg.norm(expected) > 0


def test_a_run_with_the_sun_changes_the_energy_by_the_work_of_the_tide():
    # Didymos (order 2) at its heliocentric orbit, two mutual orbits. E(t) − E(0) must equal ∫ dE/dt, the
    # tide's power on the orbit and both spins, integrated over 800 outputs by the trapezoidal rule: its
    # error ~ (Δt²/12) max|P''| T, measured 8e-5 of the change; the change is 1.6e-8 of E, 10⁵ times the
    # integrator's own conservation error (1e-13): 1e-3 of the largest change is the bound.
    state = didymos_state(order=2)
    times = np.linspace(0.0, 2 * 11.92, 801) * u.h
    sun = HeliocentricOrbit(1.6444 * u.au, 0.3839, 3.408 * u.deg, 73.2 * u.deg, 319.3 * u.deg, 40 * u.deg)
    run = propagate(state, times, sun=sun)
    energy = run.energy().to_value(u.J)
    power = run.tide_power().to_value(u.W)
    t = times.to_value(u.s)
    work = np.concatenate([[0.0], np.cumsum(0.5 * (power[1:] + power[:-1]) * np.diff(t))])
    change = energy - energy[0]
    assert np.max(np.abs(change)) > 1e-9 * abs(energy[0])
    assert np.max(np.abs(change - work)) <= 1e-3 * np.max(np.abs(change))
    without = propagate(state, times)
    drift, _ = without.energy_drift()
    assert np.max(drift) <= 1e-12
    assert np.max(np.abs(without.tide_power().value)) == 0.0


def test_the_sun_switched_off_leaves_the_pair_exactly_as_it_was():
    # The Sun's block off is the isolated pair bit for bit (the conservation tests then hold as before).
    model, y = pair_with_sun()
    off = model.copy()
    off[eq.M_SUN] = 0.0
    bare = eq.make_binary_model(1.0, ellipsoid_integrals(MASS_A, AXES_A), ellipsoid_integrals(MASS_B, AXES_B), 4,
                                max(AXES_A) + max(AXES_B))
    t_out = np.linspace(0.0, 30.0, 7)[1:]
    assert np.array_equal(propagate_binary(y, 0.0, t_out, off), propagate_binary(y, 0.0, t_out, bare))
    with_sun = propagate_binary(y, 0.0, t_out, bare, sun=kepler_source(
        MU_SUN, SUN_ELEMENTS["a"], SUN_ELEMENTS["e"], SUN_ELEMENTS["inc"], SUN_ELEMENTS["node"], SUN_ELEMENTS["argp"],
        SUN_ELEMENTS["mean_anomaly"], mu_orbit=MU_SUN + MASS_A + MASS_B, sign=-1.0))
    assert np.array_equal(with_sun, propagate_binary(y, 0.0, t_out, model))
    assert not np.array_equal(with_sun, propagate_binary(y, 0.0, t_out, bare))


def test_bad_sun_input_is_refused_with_what_was_expected():
    model, _ = pair_with_sun()
    with pytest.raises(ValueError, match="expected a Keplerian source"):
        eq.with_sun(model, fixed_source(1.0, [100.0, 0.0, 0.0]))
    state = didymos_state(order=2)
    with pytest.raises(ValueError, match="0 ≤ e < 1"):
        propagate(state, [1.0] * u.h, sun=HeliocentricOrbit(1.6 * u.au, 1.2))
    with pytest.raises(TypeError, match="HeliocentricOrbit"):
        propagate(state, [1.0] * u.h, sun=kepler_source(1.0, 1.0, 0.1, 0.0, 0.0, 0.0, 0.0))
