"""RigidBody and RotationState: validation, axes, elements, and the published Toutatis periods."""

import math

import numpy as np
import pytest
from astropy import units as u

from spinorbit.body import InvalidBodyError, RigidBody
from spinorbit import SingularElementsError
from spinorbit.state import InvalidStateError, RotationState

# Takahashi, Busch & Scheeres 2013 (AJ 146, 95), Table 2: torque-free from their state gives
# 5.369 d / 7.412 d (torque-free from Takahashi, Busch & Scheeres 2013, Table 2); quoted to 4 digits, so compare to half a unit of the last digit.
TOUTATIS_PERIODS_DAY = (5.369, 7.412)
QUOTED_DIGITS_TOLERANCE = 0.0005  # day


def toutatis():
    body = RigidBody([3.0836, 3.235, 1.0], name="Toutatis")  # z = long axis (smallest moment)
    return RotationState.from_euler313(
        body, 145.498 * u.deg, 65.865 * u.deg, 241.524 * u.deg, [14.51, 33.529, -98.709] * u.deg / u.day
    )


def test_toutatis_periods_match_takahashi_2013():
    state = toutatis()
    assert state.mode == "LAM"
    rotation, precession = state.periods
    assert rotation.to_value(u.day) == pytest.approx(TOUTATIS_PERIODS_DAY[0], abs=QUOTED_DIGITS_TOLERANCE)
    assert precession.to_value(u.day) == pytest.approx(TOUTATIS_PERIODS_DAY[1], abs=QUOTED_DIGITS_TOLERANCE)


def test_body_orders_axes_with_a_proper_rotation():
    body = RigidBody([3.0836, 3.235, 1.0])
    assert body.principal_moments == (1.0, 3.0836, 3.235)
    p = body.to_principal
    assert np.allclose(p @ p.T, np.eye(3)) and np.linalg.det(p) == pytest.approx(1.0)
    assert np.allclose(np.abs(p @ np.diag([3.0836, 3.235, 1.0]) @ p.T), np.diag(body.principal_moments))


@pytest.mark.parametrize("moments", [[1.0, 2.0, 3.0], [1.0, 3.0, 2.0], [2.0, 1.0, 3.0], [2.0, 3.0, 1.0],
                                     [3.0, 1.0, 2.0], [3.0, 2.0, 1.0], [2.0, 1.0, 1.0], [1.0, 1.0, 1.0]])
def test_every_axis_order_gives_a_proper_rotation_sorting_the_moments(moments):
    # the permutation's parity is counted (no determinant): each of the 6 orders, and ties, must give det +1
    p = RigidBody(moments).to_principal
    assert np.linalg.det(p) == 1.0 and np.all(np.abs(p).sum(axis=1) == 1.0)
    assert tuple(np.abs(p) @ np.array(moments)) == RigidBody(moments).principal_moments


def test_plain_angular_velocity_is_the_quantitys_values_and_a_copy():
    state = RotationState(RigidBody([1.0, 2.0, 3.0]), [1.0, 0.0, 0.0, 0.0], [0.1, -0.2, 0.3] * u.rad / u.s)
    plain = state.angular_velocity_rad_per_day
    assert plain.tobytes() == state.angular_velocity.to_value(u.rad / u.day).tobytes()
    plain[0] = 99.0
    assert state.angular_velocity_rad_per_day[0] != 99.0


@pytest.mark.parametrize("unit", [1.0, u.kg * u.m**2])
def test_body_owns_its_moments(unit):
    # The body keeps its own read-only copy: the caller's array stays writable, and changing it
    # afterwards does not change the body (or the states built on it).
    given = np.array([3.0836, 3.235, 1.0])
    body = RigidBody(given * unit if unit != 1.0 else given)
    state = RotationState.from_euler313(body, 0.1 * u.rad, 0.2 * u.rad, 0.3 * u.rad, [1.0, 2.0, 3.0] * u.rad / u.day)
    momentum = state.angular_momentum.value.copy()
    if unit == 1.0:
        given[0] = 10.0
    assert body.moment_values.tolist() == [3.0836, 3.235, 1.0]
    assert np.array_equal(state.angular_momentum.value, momentum)
    with pytest.raises(ValueError, match="read-only"):
        body.moment_values[0] = 1.0
    with pytest.raises(ValueError, match="read-only"):
        body.to_principal[0, 0] = 1.0


@pytest.mark.parametrize(
    "moments, error, message",
    [
        ([1.0, 2.0, -1.0], InvalidBodyError, "positive"),
        ([1.0, 1.0, 3.0], InvalidBodyError, "triangle"),
        ([1.0, 2.0], InvalidBodyError, "three"),
        ([1.0, math.nan, 2.0], InvalidBodyError, "finite"),
        ([1.0, 2.0, 2.5] * u.m, u.UnitTypeError, "kg m"),
    ],
)
def test_bad_bodies_are_named(moments, error, message):
    with pytest.raises(error, match=message):
        RigidBody(moments)


def test_state_elements_round_trip_in_user_axes():
    body = RigidBody([2.5, 1.0, 2.0] * u.kg * u.m**2)
    q = np.array([0.3, -0.5, 0.2, 0.7])
    state = RotationState(body, q / np.linalg.norm(q), [0.4, -1.1, 0.3] * u.rad / u.s)
    back = RotationState.from_canonical_elements(body, state.canonical_elements())
    assert np.abs(back.attitude_matrix - state.attitude_matrix).max() < 1e-13
    assert np.abs((back.angular_velocity - state.angular_velocity) / state.angular_velocity.max()).max() < 1e-13


def test_auto_reference_frame_keeps_away_from_i_zero():
    body = RigidBody([1.0, 2.0, 2.5])
    state = RotationState.from_angular_momentum(body, [1.0, 0.0, 0.0, 0.0], [0.02, 0.03, 1.0] * u.rad / u.day)  # momentum 2° from z
    elements = state.canonical_elements()
    assert abs(elements.H) < 0.2 * elements.Z  # the reference frame was turned: I is near 90°
    back = RotationState.from_canonical_elements(body, elements)
    assert np.abs(back.attitude_matrix - state.attitude_matrix).max() < 1e-13


def test_energy_ratio_and_modes_at_principal_axes():
    body = RigidBody([1.0, 2.0, 2.5])
    about_c = RotationState(body, [1, 0, 0, 0], [0.0, 0.0, 1.0] * u.rad / u.day)
    about_a = RotationState(body, [1, 0, 0, 0], [-1.0, 0.0, 0.0] * u.rad / u.day)
    about_b = RotationState(body, [1, 0, 0, 0], [0.0, 1.0, 0.0] * u.rad / u.day)
    # spin exactly about C or A is a permanent rotation (issue 15; its periods: tests/test_periods.py);
    # the sense is still the sign of the momentum on that axis
    assert about_c.energy_ratio == pytest.approx(1.0) and about_c.mode == "permanent rotation" and about_c.sense == "+C"
    assert about_a.energy_ratio == pytest.approx(2.5) and about_a.mode == "permanent rotation" and about_a.sense == "-A"
    assert about_b.mode == "permanent rotation"
    with pytest.raises(SingularElementsError):
        about_b.canonical_elements()


def test_torque_free_propagation_keeps_momentum_and_energy():
    state = toutatis()
    quaternions, omega = state.propagate_torque_free(np.linspace(0, 400, 9) * u.day)
    moments = np.array([3.0836, 3.235, 1.0])
    momentum_body = omega.value * moments
    inertial = np.array([RotationState(state.body, q, w * u.rad / u.day).angular_momentum_direction for q, w in zip(quaternions, omega.value)])
    assert np.abs(inertial - inertial[0]).max() < 1e-12
    energy = np.sum(momentum_body**2 / moments, axis=1)
    assert np.abs(energy / energy[0] - 1).max() < 1e-13
    assert np.abs(quaternions[0] - state.quaternion).max() < 1e-14 or np.abs(quaternions[0] + state.quaternion).max() < 1e-14


def test_permanent_rotation_about_b_propagates_uniformly():
    body = RigidBody([1.0, 2.0, 2.5])
    state = RotationState(body, [1, 0, 0, 0], [0.0, 2 * math.pi, 0.0] * u.rad / u.day)  # one turn a day about B
    quaternions, _ = state.propagate_torque_free([0.25, 1.0] * u.day)
    assert abs(abs(quaternions[1][0]) - 1.0) < 1e-14  # back where it started after a day
    assert abs(quaternions[0][0]) == pytest.approx(math.cos(math.pi / 4))


@pytest.mark.parametrize(
    "quaternion, omega, message",
    [
        ([1.0, 0.0, 0.0], [1.0, 0.0, 0.0], "4 components"),
        ([0.0, 0.0, 0.0, 0.0], [1.0, 0.0, 0.0], "unit norm"),
        ([2.0, 0.0, 0.0, 0.0], [1.0, 0.0, 0.0], "unit norm"),
        ([1.0, 0.0, 0.0, 0.0], [1.0, math.inf, 0.0], "finite"),
    ],
)
def test_bad_states_are_named(quaternion, omega, message):
    with pytest.raises(InvalidStateError, match=message):
        RotationState(RigidBody([1.0, 2.0, 2.5]), quaternion, omega * u.rad / u.day)


def test_rotation_matrix_must_be_a_rotation():
    with pytest.raises(InvalidStateError, match="not a rotation"):
        RotationState.from_matrix(RigidBody([1.0, 2.0, 2.5]), np.diag([1.0, 1.0, -1.0]), [1.0, 0, 0] * u.rad / u.day)
    with pytest.raises(u.UnitTypeError, match="angle per time"):
        RotationState(RigidBody([1.0, 2.0, 2.5]), [1, 0, 0, 0], [1.0, 0, 0] * u.m / u.s)


def test_hairer_lubich_wanner_body_needs_physical_false_and_is_lam():
    # I = (2, 1, 2/3): A + B = 5/3 < C = 2, a mathematical test problem (GNI §IV.1).
    with pytest.raises(InvalidBodyError, match="physical=False"):
        RigidBody([2.0, 1.0, 2 / 3])
    body = RigidBody([2.0, 1.0, 2 / 3], physical=False)
    state = RotationState.from_angular_momentum(body, [1, 0, 0, 0], [math.cos(1.1), 0.0, math.sin(1.1)] * u.rad / u.day)
    assert state.mode == "LAM"
    quaternions, omega = state.propagate_torque_free(np.linspace(0, 1e4, 5) * u.day)
    momentum = omega.value * np.array([2.0, 1.0, 2 / 3])
    assert np.abs(np.linalg.norm(momentum, axis=1) - 1.0).max() < 1e-14  # |M| is exact


def test_andoyer_variables_round_trip_and_meaning():
    body = RigidBody([2.5, 1.0, 2.0])
    q = np.array([0.2, 0.5, -0.4, 0.7])
    state = RotationState(body, q / np.linalg.norm(q), [0.3, 1.2, -0.4] * u.rad / u.day)
    big_l, big_g, big_h, l, g, h = state.andoyer_variables(reference="inertial")
    momentum = body.to_principal @ state.angular_momentum.value
    assert big_g.unit == u.rad / u.day and l.unit == u.rad  # moments as ratios: momenta in rad/day
    assert big_g.value == pytest.approx(np.linalg.norm(momentum), rel=1e-15)
    assert big_l.value == pytest.approx(momentum[2], rel=1e-14)  # L is the C-axis component
    back = RotationState.from_andoyer(body, big_l, big_g, big_h, l, g, h)
    assert np.abs(back.attitude_matrix - state.attitude_matrix).max() < 1e-14
    assert np.abs((back.angular_velocity - state.angular_velocity).value).max() < 1e-14
    with pytest.raises(InvalidStateError, match="G > 0"):
        RotationState.from_andoyer(body, *[2.0, 1.0, 0.0] * u.rad / u.day, *[0.0, 0.0, 0.0] * u.rad)
