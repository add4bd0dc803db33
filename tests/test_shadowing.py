"""Self-shadowing of the recoil: the ray tracer against closed forms, convex shapes untouched, symmetry.

References: an L-shaped block (a tower on a base), whose tower casts a rectangle of length
min(a, h cot e) on the floor for the Sun at elevation e in the tower's symmetry plane, so the shadowed
force and torque are the unshadowed facet sums (exact for flat faces) minus the rectangle's; the
bitwise identity of a convex shape's block with and without shadowing; the mirror symmetry of the
L-shape for the vanishing mean spin torque; the harmonics' orthonormality for the fit's quadrature.
"""

import math

import numpy as np
import pytest
from astropy import units as u

from spinorbit.core.model.polyhedron import (
    InvalidMeshError,
    face_geometry,
    mass_properties,
)
from spinorbit.core.model.shadowing import (
    shadow_candidates,
    shadow_geometry,
    shadowed_recoil_sums,
)
from spinorbit.core.model.thermal import (
    TH_PRESSURE,
    facet_force_torque,
    harmonic_count,
    pack_thermal,
    real_harmonics,
    sun_direction_grid,
    thermal_force_torque_xyz,
)
from spinorbit.shape import (
    box_shape,
    ellipsoid_shape,
    gaussian_random_sphere,
    shape_mass_properties,
    thermal_block,
    voxel_shape,
)

DENSITY = 2000 * u.kg / u.m**3
#: The L-shape in voxels of pitch 1: a base 2N × N × N/2 (x, y, z) and a tower N × N × N on its x < N half.
N = 4
FLOOR_HEIGHT, TOWER_HEIGHT = N // 2, N
#: Rounding of sums over a few hundred facets of size ~10 (arms ~10, areas ~1): far below any shadow step.
ROUNDING = 1e-12


def l_shape():
    occupied = np.zeros((2 * N, N, FLOOR_HEIGHT + TOWER_HEIGHT), dtype=bool)
    occupied[:, :, :FLOOR_HEIGHT] = True
    occupied[:N, :, FLOOR_HEIGHT:] = True
    return voxel_shape(occupied, 1.0 * u.km)


def sun_at_elevation(elevation):
    """The Sun beyond the tower (−x), at ``elevation`` above the floor, in the symmetry plane y = N/2."""
    return np.array([-math.cos(elevation), 0.0, math.sin(elevation)])


def spin_directions(latitude, count=64):
    phase = 2 * math.pi * np.arange(count) / count
    return np.stack([math.cos(latitude) * np.cos(phase), math.cos(latitude) * np.sin(phase),
                     math.sin(latitude) * np.ones(count)], axis=1)


@pytest.mark.parametrize("samples", [1, 2, 4])
@pytest.mark.parametrize("elevation_deg", [30.0, 50.0, 70.0])
def test_l_shape_shadow_against_its_closed_form(samples, elevation_deg):
    shape = l_shape()
    vertices, faces = shape.vertices_km, shape.faces
    normals, areas, centroids = face_geometry(vertices, faces)
    geometry = shadow_geometry(vertices, faces, samples)
    e = math.radians(elevation_deg)
    s = sun_at_elevation(e)
    force, torque = (x[0] for x in shadowed_recoil_sums(geometry, s))
    force0, torque0 = facet_force_torque(normals, areas, centroids, s)
    length = min(N, TOWER_HEIGHT / math.tan(e))  # the tower's shadow on the floor x ∈ [N, 2N]
    lost = length * N * math.sin(e)
    centre = np.array([N + length / 2, N / 2, FLOOR_HEIGHT])
    expected_force = force0 - lost * np.array([0.0, 0.0, 1.0])
    expected_torque = torque0 - lost * np.cross(centre, [0.0, 0.0, 1.0])
    if length == N:  # the whole floor in shadow: every sample point is dark, exactly
        bound_force = bound_torque = ROUNDING * np.abs(torque0).max()
    else:
        # Misclassified area: only sub-triangles that the shadow's edge x = N + length crosses, all inside
        # the strip |x − edge| < pitch / q (the floor's quarter-square triangles are a pitch wide), of
        # area 2 · N · pitch / q; times sin e for the force, times the largest arm for the torque.
        bound_force = 2 * N / samples * math.sin(e)
        bound_torque = bound_force * np.linalg.norm([2 * N, N, FLOOR_HEIGHT])
    assert np.abs(force - expected_force).max() <= bound_force
    assert np.abs(torque - expected_torque).max() <= bound_torque


def test_l_shape_shadow_converges_with_the_samples():
    shape = l_shape()
    normals, areas, centroids = face_geometry(shape.vertices_km, shape.faces)
    e = math.radians(70.0)
    s = sun_at_elevation(e)
    length = TOWER_HEIGHT / math.tan(e)
    expected = facet_force_torque(normals, areas, centroids, s)[0][2] - length * N * math.sin(e)
    errors = [abs(shadowed_recoil_sums(shadow_geometry(shape.vertices_km, shape.faces, q), s)[0][0, 2] - expected)
              for q in (1, 4)]
    assert errors[1] < 0.5 * errors[0]


@pytest.mark.parametrize("shape", [ellipsoid_shape([1.0, 0.8, 0.6] * u.km, subdivisions=3),
                                   box_shape([1.5, 1.0, 0.7] * u.km)], ids=["ellipsoid", "box"])
def test_convex_shape_is_detected_and_its_block_is_unchanged_bit_for_bit(shape):
    assert not shadow_candidates(shape.vertices_km, shape.faces).any()
    geometry = shadow_geometry(shape.vertices_km, shape.faces, 2)
    assert geometry.convex and geometry.leaf.size == 0  # no hierarchy built: the work is skipped
    properties = shape_mass_properties(shape, density=DENSITY)
    plain = thermal_block(shape, properties, degree=8)
    shadowed = thermal_block(shape, properties, degree=8, self_shadowing=True)
    assert np.array_equal(plain, shadowed)
    normals, areas, centroids = face_geometry(shape.vertices_km, shape.faces)
    directions = spin_directions(0.4, 16)
    force, torque = shadowed_recoil_sums(geometry, directions)
    direct = np.array([np.concatenate(facet_force_torque(normals, areas, centroids, s)) for s in directions])
    assert np.abs(np.hstack([force, torque]) - direct).max() <= ROUNDING * np.abs(direct).max()


def test_non_convex_shapes_are_detected():
    assert shadow_candidates(l_shape().vertices_km, l_shape().faces).any()
    rough = gaussian_random_sphere(1.0 * u.km, 0.3, seed=3, subdivisions=2)
    assert not shadow_geometry(rough.vertices_km, rough.faces).convex


def mirror_centred_l_shape():
    """The L-shape about its centre of mass, whose y is N/2 by the mirror y → N − y (set exactly)."""
    shape = l_shape()
    _, centre, _ = mass_properties(shape.vertices_km, shape.faces)
    centre[1] = N / 2
    return shape.vertices_km - centre, shape.faces


def test_mirror_symmetric_non_convex_shape_has_zero_mean_spin_torque():
    vertices, faces = mirror_centred_l_shape()
    geometry = shadow_geometry(vertices, faces, 2)
    normals, areas, centroids = face_geometry(vertices, faces)
    block = pack_thermal(normals, areas, centroids, 8, 1.0, 1.0, shadowing=geometry)
    for latitude in (0.2, 0.7, 1.2):
        directions = spin_directions(latitude)
        _, torque = shadowed_recoil_sums(geometry, directions)
        fitted = np.array([thermal_force_torque_xyz(*s, 1.0, block, 0)[5] for s in directions])
        amplitude = np.abs(torque).max()
        shadow_effect = np.abs(torque - np.array([facet_force_torque(normals, areas, centroids, s)[1]
                                                  for s in directions])).max()
        assert shadow_effect > 0.05 * amplitude  # the spin does carry the floor in and out of the tower's shadow
        assert abs(torque[:, 2].mean()) <= ROUNDING * amplitude
        assert abs(fitted.mean()) <= ROUNDING * amplitude


def test_quadrature_of_the_fit_is_exact_for_harmonics_up_to_its_degree():
    latitudes = 6  # exact to degree 2·6 − 1 = 11: Y_lm Y_l'm' with l + l' ≤ 11
    directions, weights = sun_direction_grid(latitudes)
    harmonics = real_harmonics(directions, 5)
    gram = harmonics.T @ (harmonics * weights[:, None])
    assert np.abs(gram - np.eye(harmonic_count(5))).max() < 1e-13
    assert abs(weights.sum() - 4 * math.pi) < 1e-13


def test_shadowed_block_sums_odd_degrees_like_the_harmonics_do():
    """The kernel's recurrences against the harmonics of real_harmonics, odd degrees included."""
    vertices, faces = mirror_centred_l_shape()
    geometry = shadow_geometry(vertices, faces, 1)
    normals, areas, centroids = face_geometry(vertices, faces)
    degree = 6
    block = pack_thermal(normals, areas, centroids, degree, 1.0, 1.0, shadowing=geometry)
    directions, weights = sun_direction_grid(2 * (degree + 1))
    force, torque = shadowed_recoil_sums(geometry, directions)
    projection = real_harmonics(directions, degree) * weights[:, None]
    coefficients = projection.T @ np.hstack([torque, force])  # (count, 6): g_lm, all degrees
    assert np.abs(coefficients[9:16]).max() > 1e-3 * np.abs(coefficients).max()  # degree 3 is not zero
    probe = spin_directions(0.5, 8)
    expected = -(real_harmonics(probe, degree) @ coefficients)
    fast = np.array([thermal_force_torque_xyz(*s, 1.0, block, 0) for s in probe])
    assert np.abs(fast[:, 3:] - expected[:, :3]).max() <= ROUNDING * np.abs(expected).max()
    assert np.abs(fast[:, :3] - expected[:, 3:]).max() <= ROUNDING * np.abs(expected).max()


def test_shadowed_fit_converges_with_degree():
    rough = gaussian_random_sphere(1.0 * u.km, 0.3, seed=3, subdivisions=2)
    properties = shape_mass_properties(rough, density=DENSITY)
    directions = spin_directions(0.6, 32)
    geometry = shadow_geometry((rough.vertices_km - properties.center_of_mass.to_value(u.km))
                               @ properties.to_principal.T * 1000.0, rough.faces, 1)
    _, direct = shadowed_recoil_sums(geometry, directions)
    errors = []
    for degree in (4, 16):
        block = thermal_block(rough, properties, degree=degree, self_shadowing=True, shadow_samples=1)
        fast = np.array([thermal_force_torque_xyz(*s, 1.0, block, 0)[3:] for s in directions])
        errors.append(np.abs(fast / -block[TH_PRESSURE] - direct).max())  # the block's torque is −P × the sum
    assert errors[1] < 0.5 * errors[0]


def test_bad_input_is_refused_by_name():
    shape = l_shape()
    open_faces = shape.faces[1:]
    with pytest.raises(InvalidMeshError, match="self-shadowing needs a closed"):
        shadow_geometry(shape.vertices_km, open_faces)
    with pytest.raises(ValueError, match="shadow_samples"):
        shadow_geometry(shape.vertices_km, shape.faces, 0)
    with pytest.raises(ValueError, match="shadow_grid"):
        sun_direction_grid(1)
    geometry = shadow_geometry(shape.vertices_km, shape.faces)
    with pytest.raises(ValueError, match="zero vector"):
        shadowed_recoil_sums(geometry, [0.0, 0.0, 0.0])
    properties = shape_mass_properties(shape, density=DENSITY)
    with pytest.raises(TypeError, match="self_shadowing"):
        thermal_block(shape, properties, self_shadowing="yes")
    normals, areas, centroids = face_geometry(shape.vertices_km, shape.faces)
    with pytest.raises(ValueError, match="same 5"):
        pack_thermal(normals[:5], areas[:5], centroids[:5], 4, 1.0, 1.0, shadowing=geometry)
    with pytest.raises(ValueError, match="voxel"):
        voxel_shape(np.zeros((2, 2, 2), dtype=bool), 1.0 * u.km)
    touching = np.zeros((2, 2, 1), dtype=bool)
    touching[0, 0, 0] = touching[1, 1, 0] = True  # two cubes sharing only an edge
    with pytest.raises(InvalidMeshError):
        voxel_shape(touching, 1.0 * u.km)
