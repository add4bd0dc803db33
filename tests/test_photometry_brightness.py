"""The kernel's door, spinorbit.photometry.brightness, against independent references.

- the closed forms (Lommel–Seeliger ellipsoid at any geometry, Muinonen & Lumme 2015; Lambertian
  ellipsoid at opposition) against mpmath quadratures of the surface integral
  (tests/data/photometry_ellipsoid_reference.json, written by tests/_photometry_reference.py);
- the facet model of an ellipsoid converging to them as 4^−k with the icosphere level k;
- the compiled facet sum against a numpy evaluation of the same sum;
- convex shapes: shadowing skipped, bit for bit; non-convex shapes: the ray-traced sum against brute
  force (every sample point's two rays against every triangle, in numpy) and against the closed form
  of an L-shaped block's shadow;
- bad input gets its specific error.
"""

import json
import math
from pathlib import Path

import numpy as np
import pytest
from astropy import units as u

from spinorbit.core.photometry.ellipsoid import (
    lambert_ellipsoid_at_opposition,
    lambert_sphere,
    lommel_seeliger_ellipsoid,
    lommel_seeliger_sphere,
)
from spinorbit.core.photometry.scattering import facet_sum
from spinorbit.photometry import Ellipsoid, InvalidDirectionsError, PhotometryError, brightness, shadowing_decision
from spinorbit.shape import ellipsoid_shape, gaussian_random_sphere

from _photometry_reference import brute_force_brightness, l_shape

REFERENCE = json.loads((Path(__file__).parent / "data" / "photometry_ellipsoid_reference.json").read_text())
#: The closed forms against 25-digit quadratures: a few roundings of a dozen operations (the log term
#: loses nothing: its arguments are computed from atan2, not arccos).
CLOSED_FORM_TOLERANCE = 1e-14
#: Facet sums of ≤ 10⁴ terms against numpy's pairwise sums: rounding of the summation orders.
SUM_TOLERANCE = 1e-13
AXES = (1.3, 0.9, 0.6)


def unit(vectors):
    vectors = np.atleast_2d(np.asarray(vectors, dtype=float))
    return vectors / np.linalg.norm(vectors, axis=1)[:, None]


@pytest.mark.parametrize("case", REFERENCE["cases"], ids=lambda c: f"{c['law']}-{c['semi_axes']}")
def test_closed_forms_match_the_quadratures(case):
    reference = float(case["brightness"])
    sun, observer = np.array([case["sun"]]), np.array([case["observer"]])
    if case["law"] == "lommel-seeliger":
        value = lommel_seeliger_ellipsoid(case["semi_axes"], sun, observer)[0]
    else:
        value = lambert_ellipsoid_at_opposition(case["semi_axes"], observer)[0]
    assert abs(value / reference - 1) < CLOSED_FORM_TOLERANCE


def test_sphere_phase_integrals():
    # Up to 135°: towards 180° both formulas lose digits to cancellation (5e-14 at 170°), where L → 0.
    alpha = np.radians([0.0, 10.0, 45.0, 90.0, 120.0, 135.0])
    sun = np.stack([np.cos(alpha), np.sin(alpha), 0 * alpha], axis=1)
    observer = np.tile([1.0, 0.0, 0.0], (alpha.size, 1))
    # The LS sphere's phase integral is the ellipsoid's closed form at a = b = c (a different formula).
    assert np.allclose(lommel_seeliger_sphere(alpha), lommel_seeliger_ellipsoid((1, 1, 1), sun, observer),
                       rtol=CLOSED_FORM_TOLERANCE, atol=0)
    assert lommel_seeliger_sphere(0.0) == pytest.approx(math.pi / 2, rel=1e-15)
    # Lambert: (2/3)[sin α + (π − α) cos α] against the facet model, which converges to it as 4^-k
    # (near the terminator, at large α, less regularly: the facets' edges alias with it).
    exact = lambert_sphere(alpha)
    errors = [np.abs(brightness(ellipsoid_shape([1, 1, 1] * u.km, level), sun, observer, law="lambert").value
                     / exact - 1) for level in (3, 4, 5)]
    assert np.all(errors[1] < errors[0] / 3) and np.all(errors[2] < errors[1] / 3)
    assert np.all(errors[2] < 1e-3)  # measured 3.0e-4 at α = 0 to 8.5e-4 at 135°
    assert lambert_sphere(0.0) == pytest.approx(2 * math.pi / 3, rel=1e-15)


def test_facet_model_of_an_ellipsoid_converges_to_the_closed_forms():
    sun, observer = unit([[0.7, -0.2, 0.5], [0.3, 0.5, 0.8]]), unit([[0.3, 0.5, 0.8], [0.3, 0.5, 0.8]])
    exact_ls = lommel_seeliger_ellipsoid(AXES, sun, observer)
    exact_lambert = lambert_ellipsoid_at_opposition(AXES, observer[1:])
    errors_ls, errors_lambert = [], []
    for level in (3, 4, 5):
        shape = ellipsoid_shape(AXES * u.km, level)
        errors_ls.append(np.abs(brightness(shape, sun, observer).value / exact_ls - 1))
        lambert = brightness(shape, observer[1:], observer[1:], law="lambert").value
        errors_lambert.append(np.abs(lambert / exact_lambert - 1))
    for errors in (np.array(errors_ls), np.array(errors_lambert)):
        # The inscribed facets' area and normals err by O(edge²): each level quarters the error.
        ratios = errors[:-1] / errors[1:]
        assert np.all((ratios > 3.5) & (ratios < 4.6)), ratios
        assert np.all(errors[-1] < 5e-4), errors[-1]  # measured 2.9e-4 (LS), 1.5e-4 (Lambert) at level 5


def test_ellipsoid_shape_uses_the_closed_form_and_its_facets():
    ellipsoid = Ellipsoid(AXES * u.km, subdivisions=4)
    sun, observer = unit([[0.7, -0.2, 0.5]]), unit([[0.3, 0.5, 0.8]])
    assert brightness(ellipsoid, sun, observer)[0].value == lommel_seeliger_ellipsoid(AXES, sun, observer)[0]
    facets = brightness(ellipsoid_shape(AXES * u.km, 4), sun, observer, law="lambert")
    assert brightness(ellipsoid, sun, observer, law="lambert")[0] == facets[0]
    assert not shadowing_decision(ellipsoid)[0]


@pytest.mark.parametrize("law, c", [("lommel-seeliger", 0.0), ("lambert", 0.0), ("kaasalainen", 0.1),
                                    ("kaasalainen", 0.37)])
def test_compiled_sum_matches_numpy(law, c):
    rng = np.random.default_rng(7)
    normals, areas = unit(rng.normal(size=(517, 3))), rng.random(517)
    sun, observer = unit(rng.normal(size=(37, 3))), unit(rng.normal(size=(37, 3)))  # not a multiple of 16
    mu0, mu = sun @ normals.T, observer @ normals.T
    with np.errstate(divide="ignore", invalid="ignore"):
        law_value = {"lommel-seeliger": mu * mu0 / (mu + mu0), "lambert": mu * mu0,
                     "kaasalainen": mu * mu0 / (mu + mu0) + c * mu * mu0}[law]
    expected = np.where((mu > 0) & (mu0 > 0), law_value, 0.0) @ areas
    w = {"lommel-seeliger": (1.0, 0.0), "lambert": (0.0, 1.0), "kaasalainen": (1.0, c)}[law]
    assert np.allclose(facet_sum(normals, areas, sun, observer, *w), expected, rtol=SUM_TOLERANCE, atol=0)


def test_convex_shapes_skip_shadowing_exactly():
    shape = ellipsoid_shape(AXES * u.km, 3)
    traced, reason = shadowing_decision(shape)
    sun, observer = unit([[1, 0.2, 0.1], [0.3, -1, 0.4]]), unit([[0.8, 0.5, 0.0], [0.0, -1, 1.0]])
    assert not traced and "convex" in reason
    assert np.array_equal(brightness(shape, sun, observer), brightness(shape, sun, observer, shadowing="none"))


@pytest.mark.parametrize("make", [l_shape, lambda: gaussian_random_sphere(1.0 * u.km, 0.35, seed=11, subdivisions=2)],
                         ids=["L-shape", "gaussian-sphere"])
def test_shadowing_matches_brute_force_ray_casting(make):
    shape = make()
    traced, reason = shadowing_decision(shape)
    assert traced and "non-convex" in reason
    rng = np.random.default_rng(5)
    sun, observer = unit(rng.normal(size=(4, 3))), unit(rng.normal(size=(4, 3)))
    sun[0], observer[0] = unit([-1, 0.3, 1.2])[0], unit([1, -0.2, 0.9])[0]
    traced_values = brightness(shape, sun, observer, law="kaasalainen", shadow_samples=2).value
    reference = brute_force_brightness(shape, sun, observer, 2, (1.0, 0.1))
    assert np.allclose(traced_values, reference, rtol=1e-12, atol=0)
    # Shadows matter on these shapes: without them the sum is larger.
    assert np.any(brightness(shape, sun, observer, law="kaasalainen", shadowing="none").value > traced_values * 1.01)


def test_l_shape_shadow_closed_form():
    # The Sun beyond the tower (−x) at elevation e with cot e = 1/2: the tower (height 4 above the floor)
    # casts a 2 × 4 shadow on the 4 × 4 floor; the observer at the zenith sees the tower's top and the floor
    # (the walls are edge-on). L = (16 + 16 − 8) S(sin e, 1), exactly, for any sample count.
    shape = l_shape(4)
    elevation = math.atan(2.0)
    sun = np.array([[-math.cos(elevation), 0.0, math.sin(elevation)]])
    observer = np.array([[0.0, 0.0, 1.0]])
    mu0 = math.sin(elevation)
    expected = 24.0 * mu0 / (1.0 + mu0)
    for samples in (1, 3):
        assert brightness(shape, sun, observer, shadow_samples=samples)[0].to_value(u.km**2) == pytest.approx(
            expected, rel=1e-13)


def test_bad_input_gets_specific_errors():
    shape = Ellipsoid(AXES * u.km)
    good = unit([[1, 0, 0]])
    with pytest.raises(InvalidDirectionsError, match="unit vectors"):
        brightness(shape, [[1.0, 1.0, 0.0]], good)
    with pytest.raises(InvalidDirectionsError, match=r"\(n, 3\)"):
        brightness(shape, [[1.0, 0.0]], good)
    with pytest.raises(InvalidDirectionsError, match="finite"):
        brightness(shape, [[np.nan, 0.0, 1.0]], good)
    with pytest.raises(InvalidDirectionsError, match="one observer direction per Sun"):
        brightness(shape, unit([[1, 0, 0], [0, 1, 0]]), good)
    with pytest.raises(InvalidDirectionsError, match="dimensionless"):
        brightness(shape, good * u.km, good)
    with pytest.raises(PhotometryError, match="law: expected one of"):
        brightness(shape, good, good, law="hapke")
    with pytest.raises(PhotometryError, match="lambert_weight"):
        brightness(shape, good, good, law="kaasalainen", lambert_weight=-1)
    with pytest.raises(PhotometryError, match="spinorbit.shape.Shape"):
        brightness(np.ones(3), good, good)
    with pytest.raises(PhotometryError, match="shadowing"):
        brightness(ellipsoid_shape(AXES * u.km, 1), good, good, shadowing="yes")
    with pytest.raises(PhotometryError, match="positive lengths"):
        Ellipsoid([1, -1, 1] * u.km)
