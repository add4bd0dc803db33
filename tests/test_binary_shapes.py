"""Polyhedral figures in the binary: their inertia integrals, the field they make, and runs with them."""

import math

import astropy.units as u
import numpy as np
import pytest

from _binary_differences import differenced_field, rotation

from spinorbit.binary import BinaryState, BinarySystem, Figure, propagate
from spinorbit.core.binary import equations as eq
from spinorbit.core.binary.errors import UnsupportedOrderError
from spinorbit.core.binary.inertia_integrals import (
    ellipsoid_integrals,
    polyhedron_integrals,
)
from spinorbit.core.binary.monomials import DEGREE_START, EXPONENTS, MAX_ORDER
from spinorbit.core.math.rotations import matrix_to_quat
from spinorbit.core.model.polyhedron import monomial_moments
from spinorbit.shape import box_shape, ellipsoid_shape, gaussian_random_sphere

AXES = (3.0, 2.0, 1.0)
SIZE = int(DEGREE_START[MAX_ORDER + 1])


def test_ellipsoid_mesh_integrals_converge_to_the_closed_form_at_the_mesh_s_rate():
    # An inscribed icosphere mesh misses the ellipsoid by a layer of thickness ~h², h ~ 2^−k: each
    # subdivision divides every integral's error by ≈ 4 (measured 3.49, 3.86, 3.96, 3.99 for k = 1..5).
    # The mesh keeps the three mirror planes, so the odd and mixed integrals vanish to rounding.
    exact = ellipsoid_integrals(4.0 / 3.0 * math.pi * np.prod(AXES), AXES)
    even = exact != 0.0
    errors = []
    for subdivisions in (2, 3, 4):
        shape = ellipsoid_shape(AXES * u.km, subdivisions=subdivisions)
        integrals, center, _, _ = polyhedron_integrals(shape.vertices_km, shape.faces, 1.0)
        errors.append(np.max(np.abs(integrals[even] / exact[even] - 1.0)))
        assert np.max(np.abs(integrals[~even])) <= 1e-13 * exact[0] * max(AXES) ** 4
        assert np.linalg.norm(center) <= 1e-14 * max(AXES)
    ratios = np.array(errors[:-1]) / np.array(errors[1:])
    assert np.all((ratios > 3.7) & (ratios < 4.3)), ratios
    assert errors[-1] < 6e-3


def box_integrals(half_sides, density):
    """ρ Π_i ∫_{−h_i}^{h_i} x^{α_i} dx = ρ Π_i 2 h_i^{α_i+1}/(α_i + 1) for even α_i, else 0."""
    out = np.zeros(SIZE)
    for index in range(SIZE):
        alpha = EXPONENTS[index]
        if np.any(alpha % 2):
            continue
        out[index] = density * np.prod([2.0 * h ** (a + 1) / (a + 1) for h, a in zip(half_sides, alpha)])
    return out


def test_box_integrals_are_the_closed_form_to_rounding_wherever_and_however_it_is_placed():
    # A box turned and moved off the origin: centring and the principal frame must undo both. Rounding:
    # the 12 faces sum ~100 terms of size m L^n (L the largest half-side, n the degree; the odd ones are
    # zero and so measured on that scale), the rotation costs a few ε: 1e-13 m L^n leaves a factor ~10.
    half_sides = (3.0, 2.0, 1.0)
    density = 2.5
    turn = rotation([0.3, -1.1, 0.7])
    box = box_shape(half_sides * u.km)
    vertices = box.vertices_km @ turn.T + np.array([10.0, -4.0, 7.0])
    integrals, center, to_principal, _ = polyhedron_integrals(vertices, box.faces, density)
    exact = box_integrals(half_sides, density)
    for degree in range(MAX_ORDER + 1):
        block = slice(DEGREE_START[degree], DEGREE_START[degree + 1])
        scale = exact[0] * max(half_sides) ** degree
        assert np.allclose(integrals[block], exact[block], rtol=0, atol=1e-13 * scale), degree
    assert np.allclose(center, [10.0, -4.0, 7.0], rtol=0, atol=1e-13 * 10)
    assert np.allclose(np.abs(to_principal @ turn), np.eye(3), rtol=0, atol=1e-12)


def triangle_rule(order):
    """Collapsed Gauss–Legendre on the unit triangle (Duffy): exact to degree 2·order − 2 in (s, t)."""
    x, w = np.polynomial.legendre.leggauss(order)
    x, w = 0.5 * (x + 1.0), 0.5 * w
    s = x[:, None] * np.ones(order)[None, :]
    t = (1.0 - x[:, None]) * x[None, :]
    weights = w[:, None] * w[None, :] * (1.0 - x[:, None])
    return s.ravel(), t.ravel(), weights.ravel()


def test_odd_integrals_of_an_irregular_shape_match_the_divergence_theorem():
    # Independent of the tetrahedra: ∫_V x^α dV = ∮ x^{α+e_x}/(α_x + 1) n_x dS, each face integrated by a
    # degree-8 product rule (the integrand has degree ≤ 5 in the face's parameters). Both are exact;
    # they differ by rounding, ~1e-15 of the largest integral of the degree over ~10⁴ faces.
    shape = gaussian_random_sphere(1.0 * u.km, 0.2, seed=7, subdivisions=3)
    vertices, faces = shape.vertices_km, shape.faces
    tetrahedra = monomial_moments(vertices, faces, EXPONENTS[:SIZE])
    a, b, c = (vertices[faces[:, k]] for k in range(3))
    s, t, w = triangle_rule(5)
    doubled_normal = np.cross(b - a, c - a)  # n dS = (b − a) × (c − a) ds dt
    points = a[None] + s[:, None, None] * (b - a)[None] + t[:, None, None] * (c - a)[None]
    surface = np.empty(SIZE)
    for index, (ax, ay, az) in enumerate(EXPONENTS[:SIZE]):
        values = points[..., 0] ** (ax + 1) * points[..., 1] ** ay * points[..., 2] ** az / (ax + 1)
        surface[index] = np.einsum("k,kf,f->", w, values, doubled_normal[:, 0])
    for degree in range(MAX_ORDER + 1):
        block = slice(DEGREE_START[degree], DEGREE_START[degree + 1])
        assert np.allclose(tetrahedra[block], surface[block], rtol=0, atol=1e-13 * np.abs(surface[block]).max())
    third = slice(DEGREE_START[3], DEGREE_START[4])
    assert np.abs(tetrahedra[third]).max() > 1e-3 * tetrahedra[0]  # the shape really is lopsided


@pytest.mark.parametrize("order", [3, 4])
def test_lopsided_polyhedra_give_a_force_and_torques_that_are_derivatives_of_the_potential(order):
    # Ellipsoids have no odd integrals; two irregular shapes exercise the degree-3 terms of the expansion.
    # Five-point differences with h = 1e-3 (lengths ~1, radians): truncation ~1e-12 U, rounding ~1e-13 U,
    # so 1e-8 of the largest component has a margin of ~100 (as for the ellipsoids).
    primary = gaussian_random_sphere(1.0 * u.km, 0.2, seed=3, subdivisions=2)
    secondary = gaussian_random_sphere(0.4 * u.km, 0.25, seed=5, subdivisions=2)
    integrals_a, *_ = polyhedron_integrals(primary.vertices_km, primary.faces, 1.0)
    integrals_b, *_ = polyhedron_integrals(secondary.vertices_km, secondary.faces, 1.0)
    assert np.abs(integrals_b[DEGREE_START[3]:DEGREE_START[4]]).max() > 1e-3 * integrals_b[0] * 0.4 ** 3
    model = eq.make_binary_model(1.0, integrals_a, integrals_b, order, 2.5)
    attitude_a, attitude_b = rotation([0.3, -0.2, 0.5]), rotation([-0.4, 0.7, 0.1])
    y = np.zeros(eq.BINARY_STATE_SIZE)
    y[eq.POSITION:eq.POSITION + 3] = [3.1, 1.2, -0.7]
    y[eq.QUAT_A:eq.QUAT_A + 4] = matrix_to_quat(attitude_a)
    y[eq.QUAT_B:eq.QUAT_B + 4] = matrix_to_quat(attitude_b)
    _, grad, torque_a, torque_b, _ = eq.mutual_state(y, model)

    fd_grad, fd_a, fd_b = differenced_field(y, model, attitude_a, attitude_b, h=1e-3)
    assert np.allclose(grad, fd_grad, rtol=0, atol=1e-8 * np.abs(grad).max())
    assert np.allclose(attitude_a @ torque_a, fd_a, rtol=0, atol=1e-8 * np.abs(fd_a).max())
    assert np.allclose(attitude_b @ torque_b, fd_b, rtol=0, atol=1e-8 * np.abs(fd_b).max())
    # And the three torques still cancel (rotation invariance), to rounding.
    total = attitude_a @ torque_a + attitude_b @ torque_b + np.cross(y[:3], grad)
    assert np.linalg.norm(total) <= 1e-14 * np.linalg.norm(y[:3]) * np.linalg.norm(grad)


DENSITY = 2203.1 * u.kg / u.m ** 3
SECONDARY_AXES = (103.16, 79.35, 66.13)


def didymos_like(secondary):
    system = BinarySystem(Figure.sphere("Didymos", 390.6 * u.m, DENSITY), secondary, order=4)
    return BinaryState.synchronous(system, 1200 * u.m, 7.7227e-4 * u.rad / u.s, speed=0.1757 * u.m / u.s,
                                   libration=0.05 * u.rad)


def test_a_polyhedral_secondary_agrees_with_the_ellipsoid_as_its_mesh_refines():
    # Five orbits at order 4 from a libration of 0.05 rad. The mesh's integrals differ from the
    # ellipsoid's by O(h²), and so does the run (a smooth function of them over a few orbits): each
    # subdivision divides the libration's and the orbit's difference by ≈ 4 (measured 3.95, 3.99 for the
    # libration, 3.93, 3.98 for the separation); at subdivision 4 the libration differs by 3.3e-4 rad.
    times = np.linspace(0.0, 5 * 11.92, 101)[1:] * u.h
    reference = propagate(didymos_like(Figure.ellipsoid("Dimorphos", SECONDARY_AXES * u.m, DENSITY)), times,
                          rtol=1e-11)
    libration_errors, position_errors = [], []
    for subdivisions in (2, 3, 4):
        shape = ellipsoid_shape(SECONDARY_AXES * u.m, subdivisions=subdivisions)
        figure = Figure.from_shape("Dimorphos mesh", shape, density=DENSITY)
        assert np.allclose(np.abs(figure.to_principal), np.eye(3), rtol=0, atol=1e-12)
        run = propagate(didymos_like(figure), times, rtol=1e-11)
        difference = np.angle(np.exp(1j * (run.libration() - reference.libration()).to_value(u.rad)))
        libration_errors.append(np.max(np.abs(difference)))
        separation = np.linalg.norm(run.states[:, eq.POSITION:eq.POSITION + 3] - reference.states[:, eq.POSITION:eq.POSITION + 3],
                                    axis=1)
        position_errors.append(np.max(separation))
    for errors in (libration_errors, position_errors):
        ratios = np.array(errors[:-1]) / np.array(errors[1:])
        assert np.all((ratios > 3.7) & (ratios < 4.3)), (errors, ratios)
    assert libration_errors[-1] < 1e-3


def test_a_figure_known_by_its_inertia_tensor_alone_supports_order_two_only():
    ellipsoid = Figure.ellipsoid("Dimorphos", SECONDARY_AXES * u.m, DENSITY)
    tensor_only = Figure.from_inertia("Dimorphos (moments)", ellipsoid.mass, ellipsoid.moments, 103.16 * u.m)
    block = slice(0, DEGREE_START[3])
    assert np.allclose(tensor_only.integrals[block], ellipsoid.integrals[block], rtol=1e-14,
                       atol=1e-14 * ellipsoid.integrals[DEGREE_START[2]])
    primary = Figure.sphere("Didymos", 390.6 * u.m, DENSITY)
    BinarySystem(primary, tensor_only, order=2)
    BinarySystem(primary, ellipsoid, order=4)  # a sphere and an ellipsoid support order 4
    with pytest.raises(UnsupportedOrderError, match=r"order 4: the secondary 'Dimorphos \(moments\)' has inertia "
                                                    r"integrals to order 2 only.*Figure.from_shape"):
        BinarySystem(primary, tensor_only, order=4)
    with pytest.raises(UnsupportedOrderError, match="the primary"):
        BinarySystem(tensor_only, ellipsoid, order=3)


def test_bad_figure_input_is_refused_with_what_was_expected():
    shape = ellipsoid_shape(SECONDARY_AXES * u.m, subdivisions=1)
    with pytest.raises(ValueError, match="exactly one of density"):
        Figure.from_shape("x", shape)
    with pytest.raises(ValueError, match="exactly one of density"):
        Figure.from_shape("x", shape, density=DENSITY, mass=1e9 * u.kg)
    with pytest.raises(ValueError, match="positive density or mass"):
        Figure.from_shape("x", shape, mass=-1e9 * u.kg)
    with pytest.raises(ValueError, match="A \\+ B ≥ C"):
        Figure.from_inertia("x", 1e9 * u.kg, [1.0, 1.0, 3.0] * u.kg * u.m ** 2, 100 * u.m)
    with pytest.raises(ValueError, match="symmetric"):
        Figure.from_inertia("x", 1e9 * u.kg, [[1.0, 0.1, 0], [0, 1.0, 0], [0, 0, 1.5]] * u.kg * u.m ** 2, 100 * u.m)
    figure = Figure.from_shape("x", shape, mass=4.0e9 * u.kg)
    assert figure.mass.to_value(u.kg) == pytest.approx(4.0e9, rel=1e-14)


def test_monomial_moments_refuses_bad_exponents():
    shape = box_shape((1.0, 1.0, 1.0) * u.km)
    with pytest.raises(ValueError, match="non-negative integers"):
        monomial_moments(shape.vertices_km, shape.faces, [[1, -1, 0]])
    with pytest.raises(ValueError, match=r"\(p, 3\)"):
        monomial_moments(shape.vertices_km, shape.faces, [1, 2, 3])
