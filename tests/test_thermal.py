"""Sunlight's recoil (Rubincam's zero-conductivity Lambertian model) and its compact representation.

References: the Funk–Hecke eigenvalues of the clamped cosine in closed form (π, 2π/3, π/4, 0, −π/24,
0, π/64; Ramamoorthi & Hanrahan 2001, J. Opt. Soc. Am. A 18, 2448, eq. 8); the direct facet sum
(:func:`facet_force_torque`, no harmonics) for the representation; the mirror symmetry of the
ellipsoid mesh for the vanishing mean spin torque.
"""

import math
import warnings

import numpy as np
import pytest
from astropy import units as u

from spinorbit.core.dynamics.equations import MODEL_PERTURBERS, force_function_and_torque_xyz, make_model
from spinorbit.core.dynamics.python_reference import make_rhs
from spinorbit.core.integrators.elements import integrate_elements
from spinorbit.core.integrators.quaternion import integrate_quaternion
from spinorbit.core.integrators.taylor import TaylorFallbackWarning, integrate_taylor
from spinorbit.core.model.perturbers import kepler_source, perturber_position_xyz
from spinorbit.core.model.thermal import (
    clamped_cosine_coefficient,
    facet_force_torque,
    harmonic_count,
    pack_thermal,
    real_harmonics,
    recoil_pressure,
    thermal_force_torque_xyz,
)
from spinorbit.shape import (
    ellipsoid_shape,
    gaussian_random_sphere,
    principal_facets,
    rigid_body_from_shape,
    shape_mass_properties,
    thermal_block,
)

#: G M_sun in au³/day² (Gaussian gravitational constant k² = 0.01720209895²).
GM_SUN = 0.01720209895**2
DENSITY = 2000 * u.kg / u.m**3


def facets_of(shape):
    return principal_facets(shape, shape_mass_properties(shape, density=DENSITY))


def unit_vectors(count, seed):
    rng = np.random.default_rng(seed)
    v = rng.standard_normal((count, 3))
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def spin_directions(latitude, count=256):
    """The Sun seen from a body spinning about its z axis: uniform phases at one latitude."""
    phase = 2 * math.pi * np.arange(count) / count
    return np.stack([math.cos(latitude) * np.cos(phase), math.cos(latitude) * np.sin(phase),
                     math.sin(latitude) * np.ones(count)], axis=1)


def test_clamped_cosine_eigenvalues_match_the_closed_form():
    closed = [math.pi, 2 * math.pi / 3, math.pi / 4, 0.0, -math.pi / 24, 0.0, math.pi / 64]
    for degree, value in enumerate(closed):
        assert clamped_cosine_coefficient(degree) == pytest.approx(value, rel=1e-14, abs=1e-16)
    assert clamped_cosine_coefficient(7) == 0.0  # odd degrees ≥ 3: exactly zero, not rounding


def test_real_harmonics_are_orthonormal():
    degree = 6
    nodes, weights = np.polynomial.legendre.leggauss(12)  # exact in sin(latitude) to degree 23
    longitudes = 2 * math.pi * np.arange(16) / 16  # exact in longitude for orders < 16
    z = np.repeat(nodes, longitudes.size)
    lam = np.tile(longitudes, nodes.size)
    rho = np.sqrt(1 - z * z)
    directions = np.stack([rho * np.cos(lam), rho * np.sin(lam), z], axis=1)
    w = np.repeat(weights, longitudes.size) * (2 * math.pi / longitudes.size)
    y = real_harmonics(directions, degree)
    gram = (y * w[:, None]).T @ y
    np.testing.assert_allclose(gram, np.eye(harmonic_count(degree)), atol=1e-13)


def test_kernel_sums_the_packed_harmonics_exactly():
    """The allocation-free recursion equals the coefficients times the harmonics, to rounding."""
    normals, areas, centroids = facets_of(gaussian_random_sphere(1.0 * u.km, 0.1, seed=2, subdivisions=2))
    degree = 10
    block = pack_thermal(normals, areas, centroids, degree, pressure=1.0, distance=1.0)
    lam = np.array([clamped_cosine_coefficient(n) for n in range(degree + 1) for _ in range(2 * n + 1)])
    weights = real_harmonics(normals, degree) * areas[:, None] * lam
    for s in unit_vectors(20, seed=4):
        y = real_harmonics(s[None], degree)[0]
        torque = -(y @ (weights.T @ np.cross(centroids, normals)))
        force = -(y @ (weights.T @ normals))
        got = np.array(thermal_force_torque_xyz(*(3.0 * s), 1.0, block, 0))
        scale = np.abs(torque).max()
        np.testing.assert_allclose(got[3:], torque, atol=1e-12 * scale)
        np.testing.assert_allclose(got[:3], force, atol=1e-12 * np.abs(force).max())


def test_representation_converges_to_the_facet_sum():
    normals, areas, centroids = facets_of(gaussian_random_sphere(1.0 * u.km, 0.1, seed=3, subdivisions=3))
    directions = unit_vectors(100, seed=1)
    direct = np.array([facet_force_torque(normals, areas, centroids, s)[1] for s in directions])
    scale = np.abs(direct).max()
    errors = []
    for degree in (4, 8, 16, 32):
        block = pack_thermal(normals, areas, centroids, degree, pressure=1.0, distance=1.0)
        fast = -np.array([thermal_force_torque_xyz(*s, 1.0, block, 0)[3:] for s in directions])
        errors.append(np.abs(fast - direct).max() / scale)
    # The clamped cosine's kink: the worst-direction error falls roughly like 1/L (measured 0.04, 0.01,
    # 0.003, 0.0007 at L = 4, 8, 16, 32); each doubling must gain at least 2x.
    assert all(later < earlier / 2 for earlier, later in zip(errors, errors[1:])), errors
    assert errors[-1] < 2e-3


def test_spin_averaged_torque_agrees_with_the_facet_sum_at_low_degree():
    normals, areas, centroids = facets_of(gaussian_random_sphere(1.0 * u.km, 0.1, seed=3, subdivisions=3))
    block = pack_thermal(normals, areas, centroids, 8, pressure=1.0, distance=1.0)
    for latitude in (0.2, 0.7, 1.2):
        directions = spin_directions(latitude)
        direct = np.array([facet_force_torque(normals, areas, centroids, s)[1] for s in directions])
        fast = -np.array([thermal_force_torque_xyz(*s, 1.0, block, 0)[3:] for s in directions])
        amplitude = np.abs(direct).max()
        assert abs(direct[:, 2].mean()) > 0.02 * amplitude  # a real YORP spin torque, so the comparison bites
        assert abs(fast[:, 2].mean() - direct[:, 2].mean()) < 1e-3 * amplitude


def test_symmetric_shape_has_no_mean_spin_torque():
    normals, areas, centroids = facets_of(ellipsoid_shape([1.0, 0.8, 0.6] * u.km, subdivisions=3))
    amplitude = 0.0
    for latitude in (0.1, 0.5, 0.9, 1.3):
        directions = spin_directions(latitude)
        torque = np.array([facet_force_torque(normals, areas, centroids, s)[1] for s in directions])
        amplitude = max(amplitude, np.abs(torque).max())
        assert abs(torque[:, 2].mean()) < 1e-13 * amplitude
    assert amplitude > 0.01  # the instantaneous torque is not zero: only its mean is


def test_torque_is_invariant_under_mesh_refinement():
    """The same random surface (one seed) at three resolutions: the torque converges like the area error."""
    directions = unit_vectors(30, seed=8)
    torques = []
    for level in (3, 4, 5):
        normals, areas, centroids = facets_of(gaussian_random_sphere(1.0 * u.km, 0.1, seed=9, subdivisions=level))
        torques.append(np.array([facet_force_torque(normals, areas, centroids, s)[1] for s in directions]))
    scale = np.abs(torques[-1]).max()
    first, second = np.abs(torques[1] - torques[0]).max() / scale, np.abs(torques[2] - torques[1]).max() / scale
    assert second < first / 2.0 and second < 0.02, (first, second)


def test_thermal_torque_joins_the_torque_sum_of_every_integrator():
    shape = gaussian_random_sphere(0.5 * u.km, 0.1, seed=5, subdivisions=3)
    properties = shape_mass_properties(shape, density=DENSITY)
    body = rigid_body_from_shape(shape, density=DENSITY)
    moments = np.array(body.principal_moments)
    sun = kepler_source(GM_SUN, 1.2, 0.1, 0.3, 0.2, 0.4, 0.5, sign=-1.0)
    block = thermal_block(shape, properties, degree=8)
    with_sunlight = make_model(moments, [sun], thermal=block, thermal_sun=0)
    gravity_only = make_model(moments, [sun])
    q = np.array([0.9, 0.1, -0.3, 0.2])
    q /= np.linalg.norm(q)
    t = 3.0
    _, *n_all = force_function_and_torque_xyz(t, *q, with_sunlight)
    _, *n_gravity = force_function_and_torque_xyz(t, *q, gravity_only)
    # The Sun's body-frame position, by hand (M(q)ᵀ r) from the Kepler orbit at t.
    r = np.array(perturber_position_xyz(t, gravity_only, MODEL_PERTURBERS + 1))
    w, x, y, z = q
    m = np.array([[w*w + x*x - y*y - z*z, 2*(x*y - w*z), 2*(x*z + w*y)],
                  [2*(x*y + w*z), w*w - x*x + y*y - z*z, 2*(y*z - w*x)],
                  [2*(x*z - w*y), 2*(y*z + w*x), w*w - x*x - y*y + z*z]])
    s = m.T @ r
    distance = np.linalg.norm(s)
    _, direct = facet_force_torque(*principal_facets(shape, properties), s)
    expected = -recoil_pressure() * 86400.0**2 / distance**2 * direct
    thermal = np.array(n_all) - np.array(n_gravity)
    np.testing.assert_allclose(thermal, expected, atol=0.02 * np.abs(expected).max())  # L = 8 truncation
    # Spin about C, 6 h period: the quaternion and element integrators both see the torque (their
    # runs agree, and differ from the gravity-only run by the YORP change of ω).
    omega = 2 * math.pi / 0.25
    y0 = np.array([*q, 0.01 * omega, 0.0, omega])
    t_out = np.array([20.0])
    full = integrate_quaternion(y0, 0.0, t_out, with_sunlight, rtol=1e-12)
    gravity = integrate_quaternion(y0, 0.0, t_out, gravity_only, rtol=1e-12)
    elements = integrate_elements(y0, 0.0, t_out, with_sunlight, rtol=1e-12)
    yorp = np.abs(full[0, 4:] - gravity[0, 4:]).max()
    assert yorp > 1e-9 * omega
    assert np.abs(elements[0, 4:] - full[0, 4:]).max() < 1e-3 * yorp
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(TaylorFallbackWarning, match="thermal"):
            integrate_taylor(y0, 0.0, t_out, with_sunlight)


def test_bad_thermal_input_is_refused():
    normals, areas, centroids = facets_of(ellipsoid_shape([1.0, 0.8, 0.6] * u.km, subdivisions=1))
    with pytest.raises(ValueError, match="degree_max"):
        pack_thermal(normals, areas, centroids, 41, 1.0, 1.0)
    with pytest.raises(ValueError, match="positive finite"):
        pack_thermal(normals, areas, centroids, 4, -1.0, 1.0)
    block = pack_thermal(normals, areas, centroids, 4, 1.0, 1.0)
    with pytest.raises(ValueError, match="thermal_sun"):
        make_model([1.0, 2.0, 3.0], [], thermal=block)
    sun = kepler_source(GM_SUN, 1.0, 0.1, 0.0, 0.0, 0.0, 0.0, sign=-1.0)
    with pytest.raises(ValueError, match="no transcription of the thermal"):
        make_rhs(make_model([1.0, 2.0, 3.0], [sun], thermal=block))


def test_sensitivities_refuse_a_thermal_model():
    """The STMs linearise gravity only: with the recoil in the model their Φ and Ψ would miss its part."""
    from spinorbit.core.averaging.mean_variational import mean_elements_stm
    from spinorbit.core.integrators.taylor_variational import integrate_taylor_variational
    from spinorbit.core.integrators.variational import integrate_variational

    normals, areas, centroids = facets_of(ellipsoid_shape([1.0, 0.8, 0.6] * u.km, subdivisions=1))
    block = pack_thermal(normals, areas, centroids, 4, 1.0, 1.0)
    sun = kepler_source(GM_SUN, 1.0, 0.1, 0.0, 0.0, 0.0, 0.0, sign=-1.0)
    model = make_model([0.6, 0.9, 1.0], [sun], thermal=block, thermal_sun=0)
    y0 = np.array([1.0, 0.0, 0.0, 0.0, 0.5, 0.0, 20.0])
    for integrate in (integrate_variational, integrate_taylor_variational):
        with pytest.raises(ValueError, match="thermal"):
            integrate(y0, 0.0, np.array([1.0]), model)
    with pytest.raises(ValueError, match="thermal"):
        mean_elements_stm(np.array([1.0, 0.5, 0.3, 0.0, 0.0, 0.0]), 0.0, np.array([1.0]), model, np.eye(3))
