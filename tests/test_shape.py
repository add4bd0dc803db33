"""Shape models: exact polyhedral mass properties against closed forms, file round trips, bad meshes refused.

References are independent of the kernels: the box's moments and Stokes coefficients from the
monomial integrals of a rectangular box (products of ∫ xᵖ dx), the ellipsoid's from the closed forms
(volume 4πabc/3, I = m(b² + c²)/5 …; Stokes coefficients of a homogeneous ellipsoid, Balmino 1994,
Manuscripta Geodaetica 19, 283: C20 = (2c² − a² − b²)/(10R²), C22 = (a² − b²)/(20R²),
C40 = 15/7 (C20² + 2 C22²), C42 = 5/7 C20 C22, C44 = 5/28 C22²), and the tetrahedron rule against
the Dirichlet integral ∫ u^a v^b w^c = a! b! c!/(a + b + c + 3)!.
"""

import math

import numpy as np
import pytest
from astropy import units as u

from spinorbit.core.model.polyhedron import (
    InvalidMeshError,
    check_closed_mesh,
    mass_properties,
    principal_frame,
    simplex_rule,
    stokes_coefficients,
)
from spinorbit.quantities import QuantityInputError
from spinorbit.shape import (
    InertiaMismatchError,
    box_shape,
    Shape,
    ShapeFileError,
    check_moments,
    ellipsoid_shape,
    gaussian_random_sphere,
    icq_grid,
    icq_mesh,
    principal_shape,
    read_icq,
    read_obj,
    rigid_body_from_shape,
    shape_mass_properties,
    write_icq,
    write_obj,
)

#: Box: every integral is a finite sum of exact products; 64 ulp allow for the sums over 12 faces.
BOX_RTOL = 64 * np.finfo(float).eps
#: Ellipsoid meshes: the error of an inscribed icosphere falls as the edge length squared, 4^−k.
REFINEMENT_RATIO = (3.9, 4.1)
SEMI_AXES = (1.0, 0.8, 0.6)


def box_mesh(hx, hy, hz, offset=(0.0, 0.0, 0.0)):
    """A box |x| ≤ hx, |y| ≤ hy, |z| ≤ hz as 12 outward triangles (plain km arrays)."""
    shape = box_shape([hx, hy, hz] * u.km)
    return shape.vertices_km + np.array(offset), shape.faces


def box_moment(p, q, r, h):
    """(1/V) ∫ xᵖ yq zʳ dV over the centred box with half sides h."""
    one = [0.0 if k % 2 else 2.0 * side ** (k + 1) / (k + 1) for k, side in zip((p, q, r), h)]
    return one[0] * one[1] * one[2] / (8.0 * h[0] * h[1] * h[2])


def test_tetrahedron_rule_is_exact_to_degree_five():
    points, weights = simplex_rule()
    for a, b, c in [(0, 0, 0), (1, 2, 2), (0, 0, 5), (3, 1, 1), (2, 0, 3), (1, 1, 1), (4, 0, 1)]:
        exact = math.factorial(a) * math.factorial(b) * math.factorial(c) / math.factorial(a + b + c + 3)
        got = float(np.sum(weights * points[:, 0] ** a * points[:, 1] ** b * points[:, 2] ** c))
        assert got == pytest.approx(exact, rel=16 * np.finfo(float).eps)
    # Degree 6 is beyond the rule: it must not be exact, or the test of exactness above proves nothing.
    assert abs(np.sum(weights * points[:, 0] ** 6) / (math.factorial(6) / math.factorial(9)) - 1) > 1e-6


def test_box_mass_properties_to_rounding_far_from_the_origin():
    h = (1.5, 1.0, 0.7)
    offset = (0.3, -0.2, 5.0)
    vertices, faces = box_mesh(*h, offset=offset)
    volume, center, inertia = mass_properties(vertices, faces)
    assert volume == pytest.approx(8 * h[0] * h[1] * h[2], rel=BOX_RTOL)
    np.testing.assert_allclose(center, offset, rtol=BOX_RTOL, atol=BOX_RTOL * 5)
    expected = volume / 3.0 * np.array([h[1] ** 2 + h[2] ** 2, h[0] ** 2 + h[2] ** 2, h[0] ** 2 + h[1] ** 2])
    np.testing.assert_allclose(np.diag(inertia), expected, rtol=BOX_RTOL)
    assert np.max(np.abs(inertia - np.diag(np.diag(inertia)))) < BOX_RTOL * expected.max()


def test_box_stokes_coefficients_against_the_monomial_integrals():
    h = (1.5, 1.0, 0.7)
    vertices, faces = box_mesh(*h)
    c, s = stokes_coefficients(vertices, faces, reference_radius=1.3)
    m = lambda p, q, r: box_moment(p, q, r, h)  # noqa: E731
    radius = 1.3
    c20 = (m(0, 0, 2) - 0.5 * (m(2, 0, 0) + m(0, 2, 0))) / radius**2
    c22 = (m(2, 0, 0) - m(0, 2, 0)) / 4.0 / radius**2
    r4 = m(4, 0, 0) + m(0, 4, 0) + m(0, 0, 4) + 2 * (m(2, 2, 0) + m(2, 0, 2) + m(0, 2, 2))
    z2r2 = m(2, 0, 2) + m(0, 2, 2) + m(0, 0, 4)
    c40 = (35 * m(0, 0, 4) - 30 * z2r2 + 3 * r4) / 8.0 / radius**4
    # C44 = 2 · 0!/8! · (1/V)∫ r⁴ P44(sin φ) cos 4λ dV, with r⁴ P44 cos 4λ = 105 Re (x + iy)⁴ = 105 (x⁴ − 6x²y² + y⁴)
    c44 = 2.0 / math.factorial(8) * 105.0 * (m(4, 0, 0) - 6 * m(2, 2, 0) + m(0, 4, 0)) / radius**4
    for got, want in ((c[2, 0], c20), (c[2, 2], c22), (c[4, 0], c40), (c[4, 4], c44)):
        assert got == pytest.approx(want, rel=BOX_RTOL * 4)
    assert c[0, 0] == pytest.approx(1.0, rel=BOX_RTOL)
    # The box is symmetric under each mirror: odd degrees, odd orders and every S vanish.
    scale = abs(c20)
    for n, mm in ((1, 0), (1, 1), (2, 1), (3, 0), (3, 1), (3, 2), (3, 3), (4, 1), (4, 3)):
        assert abs(c[n, mm]) < 1e-14 * scale
    assert np.max(np.abs(s)) < 1e-14 * scale


def test_ellipsoid_mesh_converges_to_the_closed_forms():
    a, b, c = SEMI_AXES
    c20 = (2 * c * c - a * a - b * b) / 10.0
    c22 = (a * a - b * b) / 20.0
    exact_stokes = {(2, 0): c20, (2, 2): c22, (4, 0): 15 / 7 * (c20**2 + 2 * c22**2), (4, 2): 5 / 7 * c20 * c22,
                    (4, 4): 5 / 28 * c22**2}
    errors = []
    for level in (3, 4, 5):
        shape = ellipsoid_shape(SEMI_AXES * u.km, subdivisions=level)
        volume, _, inertia = mass_properties(shape.vertices_km, shape.faces)
        stokes, _ = stokes_coefficients(shape.vertices_km, shape.faces, reference_radius=1.0)
        exact_inertia = volume / 5.0 * np.array([b * b + c * c, a * a + c * c, a * a + b * b])
        errors.append([volume / (4 / 3 * math.pi * a * b * c) - 1.0]
                      + list(np.diag(inertia) / exact_inertia - 1.0)
                      + [stokes[key] / value - 1.0 for key, value in exact_stokes.items()])
    errors = np.abs(np.array(errors))
    ratios = errors[:-1] / errors[1:]
    assert np.all((ratios > REFINEMENT_RATIO[0]) & (ratios < REFINEMENT_RATIO[1])), ratios
    assert errors[-1].max() < 1e-3


def test_shape_body_and_principal_frame():
    shape = gaussian_random_sphere(1.0 * u.km, 0.15, seed=7, subdivisions=3)
    properties = shape_mass_properties(shape, density=2000 * u.kg / u.m**3)
    rotation = properties.to_principal
    np.testing.assert_allclose(rotation @ rotation.T, np.eye(3), atol=1e-14)
    assert np.linalg.det(rotation) == pytest.approx(1.0, abs=1e-14)
    turned = principal_shape(shape, properties)
    volume, center, inertia = mass_properties(turned.vertices_km, turned.faces)
    moments = properties.principal_moments.to_value(u.kg * u.m**2) / (2000 * 1e15)
    np.testing.assert_allclose(np.diag(inertia), moments, rtol=1e-12)
    assert np.max(np.abs(inertia - np.diag(np.diag(inertia)))) < 1e-12 * moments.max()
    assert np.max(np.abs(center)) < 1e-12
    # Principal axes, centre of mass: the degree-1 and off-diagonal degree-2 Stokes terms vanish.
    c, s = properties.stokes_c, properties.stokes_s
    for value in (c[1, 0], c[1, 1], s[1, 1], c[2, 1], s[2, 1], s[2, 2]):
        assert abs(value) < 1e-12
    # MacCullagh: C20 and C22 from the moments (A ≤ B ≤ C on x, y, z).
    big_a, big_b, big_c = moments * 2000 * 1e15
    mass_r2 = properties.mass.to_value(u.kg) * properties.reference_radius.to_value(u.m) ** 2
    assert c[2, 0] == pytest.approx((big_a + big_b - 2 * big_c) / (2 * mass_r2), rel=1e-10)
    assert c[2, 2] == pytest.approx((big_b - big_a) / (4 * mass_r2), rel=1e-10)
    body = rigid_body_from_shape(shape, density=2000 * u.kg / u.m**3)
    np.testing.assert_allclose(body.principal_moments, properties.principal_moments.value, rtol=0)
    assert body.mass.to_value(u.kg) == pytest.approx(2000 * volume * 1e9, rel=1e-12)
    same = rigid_body_from_shape(shape, mass=properties.mass)
    np.testing.assert_allclose(same.principal_moments, body.principal_moments, rtol=1e-14)
    check_moments(body, properties)
    with pytest.raises(InertiaMismatchError, match="differ from its shape"):
        check_moments(type(body)([1.0, 1.1, 1.3]), properties)


def test_gaussian_random_sphere_is_seeded():
    first = gaussian_random_sphere(1.0 * u.km, 0.1, seed=11, subdivisions=2)
    again = gaussian_random_sphere(1.0 * u.km, 0.1, seed=11, subdivisions=2)
    other = gaussian_random_sphere(1.0 * u.km, 0.1, seed=12, subdivisions=2)
    np.testing.assert_array_equal(first.vertices_km, again.vertices_km)
    assert np.max(np.abs(first.vertices_km - other.vertices_km)) > 1e-3
    radii = np.linalg.norm(first.vertices_km, axis=1)
    assert 0.03 < np.std(radii) / np.mean(radii) < 0.3  # σ = 0.1 of the radius, on one realisation


def test_obj_round_trip_is_exact(tmp_path):
    shape = gaussian_random_sphere(1.0 * u.km, 0.1, seed=5, subdivisions=2)
    path = tmp_path / "body.obj"
    write_obj(path, shape)
    back = read_obj(path, u.km)
    np.testing.assert_array_equal(back.vertices_km, shape.vertices_km)
    np.testing.assert_array_equal(back.faces, shape.faces)


def test_shape_files_take_their_unit_explicitly(tmp_path):
    # OBJ and ICQ state no unit: the readers refuse to guess one, and read metres as metres.
    shape = box_shape([1.5, 1.0, 0.7] * u.km)
    path = tmp_path / "box.obj"
    write_obj(path, shape, unit=u.m)
    assert "1500.0" in path.read_text() and path.read_text().startswith("# box: 8 vertices, 12 faces, m")
    with pytest.raises(QuantityInputError, match=r"read_obj expects the length unit .*read_obj\(path, unit=u.km\)"):
        read_obj(path)
    with pytest.raises(QuantityInputError, match="unit: expected a Quantity in length units"):
        read_obj(path, u.s)
    # 700 m × 0.001 km/m is 0.7000000000000001 km: one rounding of the conversion
    np.testing.assert_allclose(read_obj(path, "m").vertices_km, shape.vertices_km, rtol=2 ** -52, atol=0)
    grid = icq_grid(lambda d: np.ones(d.shape[0]) * u.km, 2)
    write_icq(tmp_path / "sphere.icq", grid)
    with pytest.raises(QuantityInputError, match="read_icq expects the length unit"):
        read_icq(tmp_path / "sphere.icq")
    assert read_icq(tmp_path / "sphere.icq", u.m).vertices_km.max() == pytest.approx(1e-3, rel=1e-15)


def test_obj_reader_takes_quads_slashes_and_negative_indices(tmp_path):
    vertices, faces = box_mesh(1.0, 1.0, 1.0)
    text = "".join(f"v {x} {y} {z}\n" for x, y, z in vertices)
    # box_shape's faces 2j, 2j + 1 are (c0, c1, c2), (c0, c2, c3) of side j: the quads back
    quads = [[first[0], first[1], first[2], second[2]] for first, second in zip(faces[0::2], faces[1::2])]
    text += "vn 0 0 1\n# a comment\n"
    text += "".join(f"f {q[0] + 1}/1/1 {q[1] + 1}//1 {q[2] - 8} {q[3] + 1}\n" for q in quads)
    path = tmp_path / "cube.obj"
    path.write_text(text)
    shape = read_obj(path, u.km)
    assert len(shape) == 12
    assert mass_properties(shape.vertices_km, shape.faces)[0] == pytest.approx(8.0, rel=BOX_RTOL)


def test_icq_round_trip_and_ellipsoid(tmp_path):
    a, b, c = SEMI_AXES
    radius = lambda d: 1.0 / np.sqrt((d[:, 0] / a) ** 2 + (d[:, 1] / b) ** 2 + (d[:, 2] / c) ** 2) * u.km  # noqa: E731
    volumes = []
    for q in (8, 16, 32):
        grid = icq_grid(radius, q)
        path = tmp_path / f"ellipsoid_{q}.icq"
        write_icq(path, grid)
        shape = read_icq(path, u.km)
        vertices, faces = icq_mesh(grid)
        np.testing.assert_array_equal(shape.vertices_km, vertices.to_value(u.km))
        np.testing.assert_array_equal(shape.faces, faces)
        assert shape.vertices_km.shape[0] == 6 * q * q + 2 and len(shape) == 12 * q * q
        volumes.append(mass_properties(shape.vertices_km, shape.faces)[0])
    errors = np.abs(np.array(volumes) / (4 / 3 * math.pi * a * b * c) - 1.0)
    assert np.all(errors[:-1] / errors[1:] > 3.5) and errors[-1] < 2e-3


def test_icq_mirrored_file_is_reoriented(tmp_path):
    grid = icq_grid(lambda d: np.ones(d.shape[0]) * u.km, 4)
    mirrored = grid * np.array([1.0, 1.0, -1.0])
    vertices, faces = icq_mesh(mirrored)
    assert check_closed_mesh(vertices.to_value(u.km), faces)[1].shape == faces.shape


@pytest.mark.parametrize("text, message", [
    ("v 0 0 0\nv 1 0 0\n", "no faces"),
    ("v 0 0\nf 1 2 3\n", "line 1: expected 'v x y z'"),
    ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n", "vertex index 9"),
    ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 x 3\n", "integer vertex indices"),
    ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n", "at least three"),
])
def test_bad_obj_files(tmp_path, text, message):
    path = tmp_path / "bad.obj"
    path.write_text(text)
    with pytest.raises(ShapeFileError, match=message):
        read_obj(path, u.km)


@pytest.mark.parametrize("text, message", [
    ("", "expected the ICQ resolution"),
    ("v 1 2 3\n", "expected the ICQ resolution"),
    ("2\n0 0 1\n", "54 vertex lines"),
    ("1\n" + "0 0 1\n" * 23 + "0 zero 1\n", "vertex line 24: expected three numbers"),
])
def test_bad_icq_files(tmp_path, text, message):
    path = tmp_path / "bad.icq"
    path.write_text(text)
    with pytest.raises(ShapeFileError, match=message):
        read_icq(path, u.km)


def test_icq_with_mismatched_edges_is_refused(tmp_path):
    grid = icq_grid(lambda d: np.ones(d.shape[0]) * u.km, 3)
    grid[1, 0, 1] += 1e-3 * u.km  # a shared edge vertex of cube face 1 no longer matches face 0
    path = tmp_path / "torn.icq"
    write_icq(path, grid)
    with pytest.raises(InvalidMeshError, match="distinct vertices"):
        read_icq(path, u.km)


def test_open_inverted_and_degenerate_meshes_are_refused():
    vertices, faces = box_mesh(1.0, 1.0, 1.0)
    with pytest.raises(InvalidMeshError, match="open"):
        Shape(vertices * u.km, faces[:-1])
    with pytest.raises(InvalidMeshError, match="inverted normals"):
        Shape(vertices * u.km, faces[:, ::-1])
    flipped = faces.copy()
    flipped[0] = flipped[0, ::-1]
    with pytest.raises(InvalidMeshError, match="same direction"):
        Shape(vertices * u.km, flipped)
    with pytest.raises(InvalidMeshError, match="repeat a vertex"):
        Shape(vertices * u.km, np.vstack([faces, [[0, 0, 1]]]))
    doubled = np.vstack([faces, faces[:2]])
    with pytest.raises(InvalidMeshError, match="same direction"):
        Shape(vertices * u.km, doubled)
    sliver = np.vstack([vertices, [[0.5, -1.0, -1.0]]])  # on the edge from vertex 0 to vertex 4
    with pytest.raises(InvalidMeshError, match="zero area"):
        check_closed_mesh(sliver, np.vstack([faces, [[0, 8, 4]]]))
    with pytest.raises(InvalidMeshError, match="out of range|must lie in"):
        Shape(vertices * u.km, faces + 1)
    with pytest.raises(InvalidMeshError, match="integer vertex indices"):
        Shape(vertices * u.km, faces.astype(float))
    nan_vertices = vertices.copy()
    nan_vertices[3, 1] = np.nan
    with pytest.raises(ValueError, match="finite"):
        Shape(nan_vertices * u.km, faces)


def test_mass_inputs_are_checked():
    shape = ellipsoid_shape(SEMI_AXES * u.km, subdivisions=1)
    with pytest.raises(ValueError, match="exactly one of density"):
        shape_mass_properties(shape)
    with pytest.raises(ValueError, match="exactly one of density"):
        shape_mass_properties(shape, density=1 * u.kg / u.m**3, mass=1 * u.kg)
    with pytest.raises(ValueError, match="positive"):
        shape_mass_properties(shape, density=-1 * u.kg / u.m**3)
    with pytest.raises(u.UnitTypeError, match="density"):
        shape_mass_properties(shape, density=1 * u.kg)


def test_principal_frame_is_proper_and_sorted():
    rng = np.random.default_rng(3)
    for _ in range(20):
        matrix = rng.standard_normal((3, 3))
        tensor = matrix @ matrix.T + 3 * np.eye(3)
        moments, rotation = principal_frame(tensor)
        assert np.all(np.diff(moments) >= 0)
        assert np.linalg.det(rotation) == pytest.approx(1.0, abs=1e-13)
        np.testing.assert_allclose(rotation @ tensor @ rotation.T, np.diag(moments), atol=1e-12 * moments.max())
