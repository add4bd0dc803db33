"""The mean YORP torque from the exact orbit average of the facet sum, against brute-force time averages.

References (independent of the averaging under test):

- tests/_yorp_reference.py: the facet sum averaged literally over the rotation phase and the mean anomaly
  of a Kepler orbit (Kepler's equation solved at each point), its grids doubled until converged;
- a frozen body's recoil averaged over the mean anomaly alone (the closed form's own claim);
- the torus × orbit grid average of the same facet sum (``mean_thermal_rates`` on a block that evaluates
  the facets directly), on a fine grid, for the tumbler's rates.

Shapes: Gaussian random spheres σ = 0.1, 0.2, 0.3 (1280 facets) and a bilobed body read from an OBJ file.
"""

import math
import sys
from pathlib import Path

import numpy as np
import pytest
from astropy import units as u

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _yorp_reference import converged_mean_torque, sun_on_kepler_orbit, write_bilobed_obj  # noqa: E402

from spinorbit.core.averaging.recoil_orbit_mean import (  # noqa: E402
    check_exact_average,
    orbit_mean_facet_sum_xyz,
    orbit_mean_scale,
    spin_mean_torque,
)
from spinorbit.core.averaging.thermal_mean import (  # noqa: E402
    exact_mean_thermal_rates,
    mean_thermal_rates,
    orbital_period,
    propagate_mean_thermal,
    recoil_only_model,
)
from spinorbit.core.dynamics.equations import make_model  # noqa: E402
from spinorbit.core.elements.canonical import inertia_constants  # noqa: E402
from spinorbit.core.integrators.elements import elements_of_state  # noqa: E402
from spinorbit.core.model.perturbers import kepler_source  # noqa: E402
from spinorbit.core.model.shadowing import shadow_geometry  # noqa: E402
from spinorbit.core.model.thermal import facet_force_torque, pack_thermal, thermal_force_torque_xyz  # noqa: E402
from spinorbit.shape import (  # noqa: E402
    ellipsoid_shape,
    gaussian_random_sphere,
    principal_facets,
    principal_vertices,
    read_obj,
    rigid_body_from_shape,
    shape_mass_properties,
    thermal_block,
)
from spinorbit.shape.symmetry import mirror_planes  # noqa: E402

DENSITY = 2000 * u.kg / u.m**3
GM_SUN = 0.01720209895**2  # au³/day²
ORBIT_FRAME = np.diag([-1.0, -1.0, 1.0])  # inertial → (P, Q, W) of the Sun's row below
#: The reference's own error: its grids are doubled until a doubling changes each component by ≤ 5e-4
#: of itself, and the error of the finer grid is below that change (N⁻² convergence). The exact average
#: with 128 rotation phases agreed with converged references to ≤ 2e-4 (docs/thermal.md); 2e-3 is the
#: reference's tolerance plus a margin, five times inside the 1 % the mean torque must meet.
REFERENCE_RTOL = 5e-4
AGREEMENT_RTOL = 2e-3


def unit_facets(shape):
    """Principal-axis facets of a shape in km (areas km², centroids km)."""
    normals, areas, centroids = principal_facets(shape, shape_mass_properties(shape, density=DENSITY))
    return normals, areas / 1e6, centroids / 1e3


def shapes(tmp_path):
    out = [(f"Gaussian random sphere σ = {sigma}", gaussian_random_sphere(1.0 * u.km, sigma, seed=seed, subdivisions=3))
           for sigma, seed in ((0.1, 3), (0.2, 1), (0.3, 2))]
    path = tmp_path / "bilobed.obj"
    write_bilobed_obj(path)
    return out + [("bilobed OBJ", read_obj(path, unit=u.km))]


def test_direct_block_is_the_facet_sum():
    normals, areas, centroids = unit_facets(gaussian_random_sphere(1.0 * u.km, 0.2, seed=4, subdivisions=2))
    keep = slice(0, 317)  # not a multiple of the eight facets per register: the padding must add nothing
    block = pack_thermal(normals[keep], areas[keep], centroids[keep], 4, pressure=2.0, distance=1.0, direct=True)
    rng = np.random.default_rng(8)
    for s in rng.normal(size=(20, 3)):
        force, torque = facet_force_torque(normals[keep], areas[keep], centroids[keep], s)
        got = np.array(thermal_force_torque_xyz(*s, 2.0, block, 0))
        # −P (d₀/d)² with P = 2, d = 2: the factor −1/2; the sums differ only in their order (rounding).
        np.testing.assert_allclose(got[:3], -0.5 * force, rtol=1e-13, atol=1e-15 * np.abs(force).max())
        np.testing.assert_allclose(got[3:], -0.5 * torque, rtol=1e-13, atol=1e-15 * np.abs(torque).max())


def test_orbit_average_of_a_frozen_body_is_the_closed_form():
    """The time average over a Kepler orbit (e = 0.4) of (a/r)² × the facet sum equals the closed form."""
    normals, areas, centroids = unit_facets(gaussian_random_sphere(1.0 * u.km, 0.2, seed=6, subdivisions=2))
    block = pack_thermal(normals, areas, centroids, 2, pressure=1.0, distance=1.0)
    rng = np.random.default_rng(2)
    for _ in range(3):
        rotation, _ = np.linalg.qr(rng.normal(size=(3, 3)))  # the orbit's frame in the body: an arbitrary turn
        sun, weights = sun_on_kepler_orbit(0.0, 0.4, rng.uniform(0, 2 * math.pi), 20000)
        body_sun = sun @ rotation.T
        lit = np.maximum(body_sun @ normals.T, 0.0) * areas  # the facet sum of facet_force_torque, all times at once
        literal = np.mean(weights[:, None] * (lit @ np.cross(centroids, normals)), axis=0)
        w = rotation @ np.array([0.0, 0.0, 1.0])  # the orbit normal (0, 0, 1) of sun_on_kepler_orbit at ε = 0
        exact = -orbit_mean_scale(block, 0, 1.0, math.sqrt(1 - 0.4**2)) * np.array(orbit_mean_facet_sum_xyz(*w, block, 0))
        # 20000 mean anomalies of a kinked integrand: the trapezoid's error ~1e-7 of the torque's size.
        np.testing.assert_allclose(exact, literal, rtol=0, atol=1e-6 * np.abs(literal).max())


@pytest.mark.parametrize("obliquity, eccentricity", [(0.4, 0.3), (1.3, 0.0)])
def test_mean_torque_of_a_principal_axis_rotator_against_the_brute_force_average(tmp_path, obliquity, eccentricity):
    for name, shape in shapes(tmp_path):
        normals, areas, centroids = unit_facets(shape)
        reference, change, points = converged_mean_torque(normals, areas, centroids, [0.0, 0.0, 1.0], obliquity,
                                                          eccentricity, rtol=REFERENCE_RTOL)
        block = pack_thermal(normals, areas, centroids, 2, pressure=1.0, distance=1.0)
        exact = -spin_mean_torque(block, [0.0, 0.0, 1.0], obliquity, 1.0, eccentricity)  # the geometry: −T/P
        error = np.abs(exact / reference - 1)
        assert np.all(error < AGREEMENT_RTOL), (name, exact, reference, error, change, points)


def test_the_exact_average_refuses_what_it_cannot_average():
    shape = gaussian_random_sphere(1.0 * u.km, 0.3, seed=3, subdivisions=2)
    normals, areas, centroids = unit_facets(shape)
    vertices = principal_vertices(shape, shape_mass_properties(shape, density=DENSITY)) / 1e3
    shadowed = pack_thermal(normals, areas, centroids, 4, 1.0, 1.0, shadowing=shadow_geometry(vertices, shape.faces, 1))
    with pytest.raises(ValueError, match="shadowed fit"):
        check_exact_average(shadowed)
    with pytest.raises(ValueError, match="direct"):
        pack_thermal(normals, areas, centroids, 4, 1.0, 1.0, shadowing=shadow_geometry(vertices, shape.faces, 1),
                     direct=True)
    plain = pack_thermal(normals, areas, centroids, 4, 1.0, 1.0)
    with pytest.raises(ValueError, match="spin_axis"):
        spin_mean_torque(plain, [0.0, 0.0, 0.0], 0.3, 1.0)
    with pytest.raises(ValueError, match="orbit"):
        spin_mean_torque(plain, [0.0, 0.0, 1.0], 0.3, 1.0, eccentricity=1.2)


def tumbler_models(subdivisions=2):
    """A 200 m tumbler (σ = 0.15, seed 5) with a direct-sum block: its recoil model and the elements."""
    shape = gaussian_random_sphere(0.2 * u.km, 0.15, seed=5, subdivisions=subdivisions)
    properties = shape_mass_properties(shape, density=DENSITY)
    moments = np.array(rigid_body_from_shape(shape, density=DENSITY).principal_moments)
    sun = kepler_source(GM_SUN, 1.0, 0.1, 0.3, 0.2, 0.5, 0.0, sign=-1.0)
    model = make_model(moments, [sun], thermal=thermal_block(shape, properties, torque="facets"), thermal_sun=0)
    omega = 2 * math.pi / 0.25
    q = np.array([0.9, 0.2, -0.3, 0.25])
    y0 = np.array([*(q / np.linalg.norm(q)), 0.3 * omega, 0.1 * omega, omega])
    return recoil_only_model(model), y0, inertia_constants(*moments)


def test_exact_torus_rates_against_the_grid_average_of_the_facet_sum():
    """The tumbler's d(S, Z, H)/dt: the exact orbit average on the default torus grid against the torus × orbit
    trapezoid of the same facet sum evaluated directly (kinked, so it converges as N⁻²: 64³ points)."""
    model, y0, ic = tumbler_models()
    el = elements_of_state(y0, model, ORBIT_FRAME)
    exact, brute = np.empty(4), np.empty(4)
    exact_mean_thermal_rates(el, model, ORBIT_FRAME, ic, 16, 64, exact)
    mean_thermal_rates(0.0, el, model, ORBIT_FRAME, ic, 64, 64, 64, orbital_period(model), brute)
    # Measured: 16 × 64 is within 4e-4 of 64 × 256 on this tumbler; the 64³ brute force within 1e-4 of it.
    np.testing.assert_allclose(exact[:3], brute[:3], rtol=1e-3)


def test_a_mirror_symmetric_shape_has_no_exact_mean_yorp():
    """An ellipsoid mesh keeps its three mirror planes (T(σŝ) = −σT(ŝ)): its mean rates of S, Z and H vanish.

    What is left is a torque across the plane of the spin and the orbit normal: it precesses L about the
    orbit normal (dh/dt), like the Sun's gravity, and changes neither the spin nor the obliquity.

    The trapezoids over the torus do not pair σ-images point by point, so the zero is the grid's: measured
    2.6e-7 of the instantaneous rates at 16 × 64, 9e-8 at 32 × 128, 6e-10 at 64 × 256. A rotation about a
    principal axis pairs them exactly (φ and −φ are both phases of the grid): zero to rounding.
    """
    shape = ellipsoid_shape([0.2, 0.15, 0.12] * u.km, subdivisions=2)
    properties = shape_mass_properties(shape, density=DENSITY)
    assert mirror_planes(shape, properties) == (0, 1, 2)
    assert mirror_planes(gaussian_random_sphere(0.2 * u.km, 0.1, seed=3, subdivisions=2),
                         shape_mass_properties(gaussian_random_sphere(0.2 * u.km, 0.1, seed=3, subdivisions=2),
                                               density=DENSITY)) == ()
    moments = np.array(rigid_body_from_shape(shape, density=DENSITY).principal_moments)
    sun = kepler_source(GM_SUN, 1.0, 0.1, 0.0, 0.0, 0.0, 0.0, sign=-1.0)  # ORBIT_FRAME is this orbit's (P, Q, W)
    model = recoil_only_model(make_model(moments, [sun], thermal=thermal_block(shape, properties), thermal_sun=0))
    ic = inertia_constants(*moments)
    omega = 2 * math.pi / 0.25
    y0 = np.array([0.9, 0.2, -0.3, 0.25]) / np.linalg.norm([0.9, 0.2, -0.3, 0.25])
    el = elements_of_state(np.array([*y0, 0.3 * omega, 0.1 * omega, omega]), model, ORBIT_FRAME)
    rates, instant = np.empty(4), np.empty(4)
    exact_mean_thermal_rates(el, model, ORBIT_FRAME, ic, 16, 64, rates)
    mean_thermal_rates(0.0, el, model, ORBIT_FRAME, ic, 16, 8, 1, 1.0, instant)  # one orbit time: not averaged
    scale = np.abs(instant[:3] / el[:3]).max()
    assert scale > 1e-8
    assert np.all(np.abs(rates[:3] / el[:3]) < 1e-6 * scale)
    finer = np.empty(4)
    exact_mean_thermal_rates(el, model, ORBIT_FRAME, ic, 64, 256, finer)
    assert np.all(np.abs(finer[:3] / el[:3]) < 1e-8 * scale)
    normals, areas, centroids = unit_facets(shape)
    block = pack_thermal(normals, areas, centroids, 2, 1.0, 1.0)
    torque = spin_mean_torque(block, [0.0, 0.0, 1.0], 0.7, 1.0, 0.2)
    size = np.abs(areas[:, None] * np.cross(centroids, normals)).sum()
    assert np.abs(torque[1:]).max() < 1e-15 * size  # obliquity and spin: zero to rounding
    assert abs(torque[0]) > 1e-3 * size  # the precession part is not (measured 2.7e-2)
    assert abs(rates[3]) > 0.0


def test_mean_run_takes_the_exact_average_by_default():
    model, y0, ic = tumbler_models()
    el = elements_of_state(y0, model, ORBIT_FRAME)
    period = orbital_period(model)
    rates = np.empty(4)
    exact_mean_thermal_rates(el, model, ORBIT_FRAME, ic, 16, 64, rates)
    out, _ = propagate_mean_thermal(el, 0.0, [period], model, ORBIT_FRAME, step=period, with_gravity=False)
    # One orbit of a ~1e-6 relative change: the change is the initial rate × the period to its square.
    np.testing.assert_allclose(out[0, :3] - el[:3], rates[:3] * period, rtol=1e-3)
    with pytest.raises(ValueError, match="average"):
        propagate_mean_thermal(el, 0.0, [period], model, ORBIT_FRAME, step=period, average="harmonic")
