"""The mutual potential of two rigid bodies (spinorbit.core.binary): its limits, its derivatives and
its convergence with order, each against a reference that does not use the expansion."""

import sys
from pathlib import Path

import numpy as np
import pytest

from spinorbit.core.binary import equations as eq
from spinorbit.core.binary.errors import ContactError, UnsupportedOrderError
from spinorbit.core.binary.inertia_integrals import (
    INTEGRALS_SIZE,
    ellipsoid_integrals,
    inertia_tensor,
    rotate_integrals,
    sphere_integrals,
)
from spinorbit.core.binary.monomials import EXPONENTS, MAX_ORDER
from spinorbit.core.binary.propagate import check_order, propagate_binary
from spinorbit.core.errors import SpinorbitError
from spinorbit.core.math.rotations import matrix_to_quat
from spinorbit.core.model.gravity_field import figure_force_function_and_gradient, figure_torque, make_body

sys.path.insert(0, str(Path(__file__).parent))
import _binary_reference as reference  # noqa: E402
from _binary_differences import differenced_field, rotation  # noqa: E402

AXES_A = (1.2, 1.0, 0.8)
AXES_B = (0.5, 0.4, 0.3)
MASS_A, MASS_B = 2.0, 0.3
CONTACT = max(AXES_A) + max(AXES_B)


def state(separation, attitude_a=np.eye(3), attitude_b=np.eye(3)):
    y = np.zeros(eq.BINARY_STATE_SIZE)
    y[eq.POSITION:eq.POSITION + 3] = separation
    y[eq.QUAT_A:eq.QUAT_A + 4] = matrix_to_quat(attitude_a)
    y[eq.QUAT_B:eq.QUAT_B + 4] = matrix_to_quat(attitude_b)
    return y


def ellipsoids(order, axes_b=AXES_B):
    return eq.make_binary_model(1.0, ellipsoid_integrals(MASS_A, AXES_A), ellipsoid_integrals(MASS_B, axes_b),
                                order, CONTACT)


M_A = rotation([0.3, -0.2, 0.5])
M_B = rotation([-0.4, 0.7, 0.1])
SEPARATION = np.array([3.1, 1.2, -0.7])


# --- inertia integrals ---------------------------------------------------------------------------

def test_ellipsoid_integrals_match_quadrature_of_every_monomial():
    # Gauss quadrature with 8 radial, 10 polar, 20 azimuthal nodes integrates degree ≤ 13 exactly, so the
    # closed form and the sum agree to rounding: 1e-14 of the largest integral of the same degree.
    nodes, weights = reference.ellipsoid_quadrature(MASS_A, AXES_A, 8, 10, 20)
    closed = ellipsoid_integrals(MASS_A, AXES_A)
    for index in range(INTEGRALS_SIZE):
        direct = np.sum(weights * np.prod(nodes ** EXPONENTS[index], axis=1))
        scale = MASS_A * max(AXES_A) ** EXPONENTS[index].sum()
        assert abs(closed[index] - direct) <= 1e-14 * scale, EXPONENTS[index]


def test_rotated_integrals_match_quadrature_of_the_rotated_body():
    # Same exactness argument: the rotated monomials are polynomials of the same degree.
    nodes, weights = reference.ellipsoid_quadrature(MASS_B, AXES_B, 8, 10, 20)
    rotated = np.empty(INTEGRALS_SIZE)
    rotate_integrals(ellipsoid_integrals(MASS_B, AXES_B), M_B, MAX_ORDER, rotated)
    turned = nodes @ M_B.T
    for index in range(INTEGRALS_SIZE):
        direct = np.sum(weights * np.prod(turned ** EXPONENTS[index], axis=1))
        assert abs(rotated[index] - direct) <= 1e-14 * MASS_B * max(AXES_B) ** EXPONENTS[index].sum()


def test_inertia_tensor_of_an_ellipsoid_is_the_textbook_one():
    a, b, c = AXES_A
    expected = MASS_A / 5 * np.diag([b * b + c * c, a * a + c * c, a * a + b * b])
    assert np.allclose(inertia_tensor(ellipsoid_integrals(MASS_A, AXES_A)), expected, rtol=1e-15, atol=0)


# --- limits ---------------------------------------------------------------------------------------

def test_order_two_with_a_sphere_is_the_point_mass_and_inertia_field_of_gravity_field():
    # B a homogeneous sphere: its field is that of a point mass, so U, the force and A's torque must be
    # the degree-2 figure field of core/model/gravity_field.py (MacCullagh, written independently). The
    # two sum the same terms in different orders: 1e-14 relative.
    model = eq.make_binary_model(1.0, ellipsoid_integrals(MASS_A, AXES_A), sphere_integrals(MASS_B, 0.4), 2, CONTACT)
    moments = np.diag(inertia_tensor(ellipsoid_integrals(MASS_A, AXES_A)))
    figure = make_body(moments, mass=MASS_A)
    y = state(SEPARATION, M_A, M_B)
    u, grad, torque_a, torque_b, r_a = eq.mutual_state(y, model)
    u_ref, grad_ref = figure_force_function_and_gradient(r_a, MASS_B, figure)
    assert u == pytest.approx(u_ref, rel=1e-14)
    assert np.allclose(M_A.T @ grad, grad_ref, rtol=0, atol=1e-14 * np.linalg.norm(grad_ref))
    torque_ref = figure_torque(r_a, MASS_B, figure)
    assert np.allclose(torque_a, torque_ref, rtol=0, atol=1e-14 * np.linalg.norm(torque_ref))
    # A sphere feels no torque: every term is a trace, zero up to the rounding of its rotated integrals.
    assert np.linalg.norm(torque_b) <= 1e-14 * np.linalg.norm(torque_ref)


def test_order_two_secondary_torque_is_the_gravity_field_torque_of_a_sphere_primary():
    # A a sphere and B the ellipsoid: B's torque on its own axes is gravity_field's torque from a point
    # mass m_A at −R on B's axes. Here B's integrals are rotated onto A's axes and the torque turned back,
    # two rotations the reference does not make: 1e-13 of the torque (measured 2e-14).
    model = eq.make_binary_model(1.0, sphere_integrals(MASS_A, 1.0), ellipsoid_integrals(MASS_B, AXES_B), 2, CONTACT)
    y = state(SEPARATION, M_A, M_B)
    _, _, torque_a, torque_b, _ = eq.mutual_state(y, model)
    figure = make_body(np.diag(inertia_tensor(ellipsoid_integrals(MASS_B, AXES_B))), mass=MASS_B)
    torque_ref = figure_torque(-(M_B.T @ SEPARATION), MASS_A, figure)
    assert np.allclose(torque_b, torque_ref, rtol=0, atol=1e-13 * np.linalg.norm(torque_ref))
    assert np.linalg.norm(torque_a) <= 1e-14 * np.linalg.norm(torque_ref)


@pytest.mark.parametrize("order", [2, 4])
def test_two_spheres_are_two_point_masses_at_every_order(order):
    # Every derivative tensor of 1/R is traceless, so a sphere's higher integrals contribute nothing.
    model = eq.make_binary_model(1.0, sphere_integrals(MASS_A, 1.0), sphere_integrals(MASS_B, 0.5), order, 1.5)
    u, grad, _, _, _ = eq.mutual_state(state(SEPARATION, M_A, M_B), model)
    r = np.linalg.norm(SEPARATION)
    assert u == pytest.approx(MASS_A * MASS_B / r, rel=1e-15)
    assert np.allclose(grad, -MASS_A * MASS_B * SEPARATION / r ** 3, rtol=0, atol=1e-15 * MASS_A * MASS_B / r ** 2)


# --- derivatives of the one potential ----------------------------------------------------------------

@pytest.mark.parametrize("order", [2, 3, 4])
def test_force_and_both_torques_are_derivatives_of_the_potential(order):
    # Five-point differences of U with h = 1e-3 (lengths and radians of order 1): truncation ~ h⁴ U⁽⁵⁾ ≈
    # 1e-12 U and rounding ~ ε U / h ≈ 1e-13 U, while the torques are ~1e-2 U: 1e-8 of the largest
    # component leaves a margin of 100 over both.
    model = ellipsoids(order)
    y = state(SEPARATION, M_A, M_B)
    _, grad, torque_a, torque_b, _ = eq.mutual_state(y, model)
    fd_grad, fd_a, fd_b = differenced_field(y, model, M_A, M_B, h=1e-3)
    assert np.allclose(grad, fd_grad, rtol=0, atol=1e-8 * np.abs(grad).max())
    # The finite differences rotate about inertial axes; the torques are on each body's axes.
    assert np.allclose(M_A @ torque_a, fd_a, rtol=0, atol=1e-8 * np.abs(fd_a).max())
    assert np.allclose(M_B @ torque_b, fd_b, rtol=0, atol=1e-8 * np.abs(fd_b).max())


@pytest.mark.parametrize("order", [2, 4])
def test_torques_and_the_orbit_torque_cancel(order):
    # Rotation invariance of each order's term: M_A N_A + M_B N_B + R × ∂U/∂R = 0 (inertial), the identity
    # behind the conservation of total angular momentum. Only rounding remains: 1e-14 of |R| |∂U/∂R|, the
    # size of the products each component of R × ∂U/∂R is a difference of.
    model = ellipsoids(order)
    _, grad, torque_a, torque_b, _ = eq.mutual_state(state(SEPARATION, M_A, M_B), model)
    total = M_A @ torque_a + M_B @ torque_b + np.cross(SEPARATION, grad)
    scale = np.linalg.norm(SEPARATION) * np.linalg.norm(grad)
    assert np.linalg.norm(total) <= 1e-14 * scale


# --- convergence against the direct mutual integral --------------------------------------------------

def direct_potential(separation_a, c):
    return reference.mutual_force_function(separation_a, c, MASS_A, AXES_A, MASS_B, AXES_B, n_radial=12,
                                           n_polar=16, n_azimuth=32)


def test_expansion_converges_to_the_direct_integral_with_the_predicted_rates():
    # The first term left out at order N (N = 0, 2, 4, the odd terms vanish for ellipsoids) is of degree
    # N + 2 and falls as R^−(N+3); relative to U ∝ 1/R it falls as R^−(N+2), so doubling R divides the
    # relative error by 2^(N+2) = 4, 16, 64 asymptotically.
    # At R = 8 and 16 (R / contact ≥ 4.7) the next terms still change the ratio by ~(1.7/8)² ≈ 5 %, hence
    # the 20 % band. The direct integral (A's exact exterior field over B by quadrature) converges to
    # ~1e-16 relative (12/16/32 against 16/20/40 nodes), far below the smallest error measured (~1e-9).
    c = M_A.T @ M_B
    direction = SEPARATION / np.linalg.norm(SEPARATION)
    errors = {}
    for distance in (8.0, 16.0):
        r_a = distance * direction
        exact = direct_potential(r_a, c)
        for order in (0, 2, 4):
            y = state(M_A @ r_a, M_A, M_B)
            errors[order, distance] = abs(eq.mutual_state(y, ellipsoids(order))[0] - exact) / exact
    for order, rate in ((0, 4.0), (2, 16.0), (4, 64.0)):
        assert errors[order, 8.0] / errors[order, 16.0] == pytest.approx(rate, rel=0.2), order
    for distance in (8.0, 16.0):
        assert errors[4, distance] < errors[2, distance] < errors[0, distance]


def test_order_four_near_contact_is_within_its_truncation_estimate():
    # At R = 2.5 (1.47 × contact) order 4 must still improve on order 2 by about (size/R)² ≈ 0.2 or better;
    # bound the ratio at 0.5 (no asymptotic regime this close).
    c = M_A.T @ M_B
    r_a = 2.5 * SEPARATION / np.linalg.norm(SEPARATION)
    exact = direct_potential(r_a, c)
    error = {order: abs(eq.mutual_state(state(M_A @ r_a, M_A, M_B), ellipsoids(order))[0] - exact)
             for order in (2, 4)}
    assert error[4] < 0.5 * error[2]


# --- bad input ------------------------------------------------------------------------------------

@pytest.mark.parametrize("order", [MAX_ORDER + 1, -1, 2.0, True])
def test_order_outside_the_tables_is_refused(order):
    with pytest.raises(UnsupportedOrderError, match=r"expected a whole number 0 ≤ order ≤ 4.*got") as info:
        check_order(order)
    assert isinstance(info.value, SpinorbitError) and isinstance(info.value, ValueError)


def test_overlapping_bodies_are_refused_before_the_first_step():
    y = state([1.0, 0.5, 0.0])  # 1.12 apart, contact distance 1.7: the bodies overlap
    with pytest.raises(ContactError, match=r"expected more than the contact distance 1\.7.*got 1\.118"):
        propagate_binary(y, 0.0, [1.0], ellipsoids(2))


def test_a_collision_orbit_stops_with_the_time_of_contact():
    # Released at rest 3 apart along A's long axis, the bodies fall straight in. Point masses with
    # G(m_A + m_B) = 2.3 reach 1.7 at t = √(r₀³/2μ) (√(x(1 − x)) + arccos √x) = 2.942, x = 1.7/3 (radial
    # Kepler); the figures pull a little harder and the run reports the last accepted step before
    # contact, so the time is earlier by a few percent at most: between 0.95 and 1 of the point-mass time.
    y = state([3.0, 0.0, 0.0])
    with pytest.raises(ContactError, match=r"reached at t = ") as info:
        propagate_binary(y, 0.0, [5.0], ellipsoids(2))
    x = CONTACT / 3.0
    free_fall = np.sqrt(27.0 / (2 * (MASS_A + MASS_B))) * (np.sqrt(x * (1 - x)) + np.arccos(np.sqrt(x)))
    reached = float(str(info.value).split("reached at t = ")[1].split(" ")[0])
    assert 0.95 * free_fall < reached <= free_fall
