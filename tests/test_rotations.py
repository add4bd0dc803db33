"""Rotation algebra: conventions of docs/conventions.md checked against independent constructions."""

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from spinorbit.core.math import rotations as rot

# Double-precision rotations of unit vectors: every check below is a few ulp of 1.
ROUNDING = 1e-14

angles = st.floats(-math.pi, math.pi, allow_nan=False)
unit_quaternions = st.lists(st.floats(-1, 1), min_size=4, max_size=4).filter(
    lambda v: np.linalg.norm(v) > 0.1
).map(lambda v: np.array(v) / np.linalg.norm(v))


def axis_angle_quat(axis, angle):
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    return np.concatenate([[math.cos(angle / 2)], math.sin(angle / 2) * axis])


def test_quaternion_rotates_body_axes_into_inertial_frame():
    # A rotation by +90° about inertial z takes the body x axis to inertial y (active, body → inertial).
    q = axis_angle_quat([0, 0, 1], math.pi / 2)
    assert np.allclose(rot.quat_to_matrix(q) @ [1, 0, 0], [0, 1, 0], atol=ROUNDING)
    # The attitude matrix maps inertial components to body components: inertial y is body x.
    assert np.allclose(rot.quat_to_attitude(q) @ [0, 1, 0], [1, 0, 0], atol=ROUNDING)
    # And it equals the passive elementary rotation R3(90°).
    assert np.allclose(rot.quat_to_attitude(q), rot.rot3(math.pi / 2), atol=ROUNDING)


@given(unit_quaternions)
def test_matrix_quaternion_round_trip(q):
    back = rot.matrix_to_quat(rot.quat_to_matrix(q))
    assert min(np.abs(back - q).max(), np.abs(back + q).max()) < 4 * ROUNDING


@given(angles, st.floats(0, math.pi), angles)
def test_euler313_round_trip(phi, theta, psi):
    r = rot.euler313_to_attitude(phi, theta, psi)
    assert np.allclose(r @ r.T, np.eye(3), atol=ROUNDING)
    back = rot.euler313_to_attitude(*rot.attitude_to_euler313(r))
    assert np.abs(back - r).max() < 8 * ROUNDING


def test_euler313_gimbal_lock_keeps_the_attitude():
    for theta in (0.0, math.pi):
        r = rot.euler313_to_attitude(0.3, theta, 0.5)
        back = rot.euler313_to_attitude(*rot.attitude_to_euler313(r))
        assert np.abs(back - r).max() < 4 * ROUNDING


@given(angles, st.floats(0.05, math.pi - 0.05), angles, st.floats(-2, 2), st.floats(-2, 2), st.floats(-2, 2))
def test_euler313_rates_give_body_angular_velocity(phi, theta, psi, dphi, dtheta, dpsi):
    # Independent check: ω̂ (skew) = −Ṙ Rᵀ for the attitude matrix R (inertial → body), Ṙ by
    # central differences of the angles.
    h = 1e-6
    r_plus = rot.euler313_to_attitude(phi + h * dphi, theta + h * dtheta, psi + h * dpsi)
    r_minus = rot.euler313_to_attitude(phi - h * dphi, theta - h * dtheta, psi - h * dpsi)
    r = rot.euler313_to_attitude(phi, theta, psi)
    skew = -((r_plus - r_minus) / (2 * h)) @ r.T
    omega_fd = np.array([skew[2, 1], skew[0, 2], skew[1, 0]])
    omega = rot.euler313_rates_to_omega(phi, theta, psi, dphi, dtheta, dpsi)
    assert np.abs(omega - omega_fd).max() < 1e-8  # central difference, h = 1e-6: truncation ~h²


def test_quaternion_kinematics_match_attitude_kinematics():
    # q̇ = ½ q ⊗ (0, ω) with body ω must agree with Ṙ = −ω̂ R for R = M(q)ᵀ.
    q = axis_angle_quat([1, 2, 3], 0.7)
    omega = np.array([0.3, -1.2, 0.5])
    q_dot = 0.5 * rot.quat_multiply(q, np.concatenate([[0.0], omega]))
    h = 1e-6
    r_dot_fd = (rot.quat_to_attitude(q + h * q_dot) - rot.quat_to_attitude(q - h * q_dot)) / (2 * h)
    skew = np.array([[0, -omega[2], omega[1]], [omega[2], 0, -omega[0]], [-omega[1], omega[0], 0]])
    assert np.abs(r_dot_fd - (-skew @ rot.quat_to_attitude(q))).max() < 1e-9


def test_rotation_angle_between_is_accurate_for_tiny_angles():
    q1 = axis_angle_quat([0.2, -0.5, 1.0], 1.0)
    for angle in (1e-15, 1e-9, 1e-3, 3.0):
        q2 = rot.quat_multiply(q1, axis_angle_quat([1, 1, 0], angle))
        assert rot.rotation_angle_between(q1, q2) == pytest.approx(angle, rel=1e-12, abs=1e-16)
        assert rot.rotation_angle_between(q1, -q2) == pytest.approx(angle, rel=1e-12, abs=1e-16)


def test_many_variants_match_scalar_kernels():
    rng = np.random.default_rng(1)
    q = rng.normal(size=(5, 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    mats = rot.quat_to_attitude_many(q)
    back = rot.attitude_to_quat_many(mats)
    assert np.all(rot.rotation_angle_between_many(q, back) < 4 * ROUNDING)
    assert np.abs(mats[2] - rot.quat_to_attitude(q[2])).max() == 0.0
