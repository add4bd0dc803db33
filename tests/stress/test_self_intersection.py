"""A surface that crosses itself is refused, naming the faces (issue 36, class 3).

The pair tests of ``spinorbit.core.model.self_intersection`` on configurations whose answer is known by
construction, then whole meshes: valid ones of every generator pass, overlapping and pierced ones are
refused, and a mesh of 2·10⁴ faces is checked in well under a second.
"""

import time

import numpy as np
import pytest
from astropy import units as u

from spinorbit.core.model.polyhedron import InvalidMeshError, check_closed_mesh, mass_properties
from spinorbit.core.model.self_intersection import faces_intersect, intersecting_faces
from spinorbit.shape import Shape, ellipsoid_shape, gaussian_random_sphere, voxel_shape
from spinorbit.shape.mesh import icosphere


def pair(first, second, faces=((0, 1, 2), (3, 4, 5))):
    vertices = np.array([*first, *second], dtype=float)
    return faces_intersect(vertices, np.array(faces, dtype=np.int64), 0, 1)


FLOOR = [(0, 0, 0), (1, 0, 0), (0, 1, 0)]


@pytest.mark.parametrize("second, meets", [
    ([(0.2, 0.2, -1), (0.2, 0.2, 1), (0.9, 0.9, 0.5)], True),      # pierces the floor through its interior
    ([(2.0, 2.0, -1), (2.0, 2.0, 1), (3.0, 3.0, 0.5)], False),      # beside it
    ([(0.2, 0.2, 0.1), (0.9, 0.0, 0.3), (0.0, 0.9, 0.2)], False),   # just above it
    ([(0.5, -0.5, -1), (0.5, -0.5, 1), (0.5, 1.0, 0.0)], True),      # crosses both its legs, no vertex inside
    ([(0.1, 0.1, 0), (0.6, 0.1, 0), (0.1, 0.6, 0)], True),          # coplanar, inside it
    ([(0.5, -0.2, 0), (0.5, 0.8, 0), (-0.3, 0.3, 0)], True),        # coplanar, edges crossing
    ([(1.1, 0.1, 0), (2.0, 0.1, 0), (1.1, 1.0, 0)], False),         # coplanar, apart
])
def test_two_faces_without_a_common_vertex(second, meets):
    assert pair(FLOOR, second) is meets
    assert pair(second, FLOOR) is meets  # the order of the two faces does not matter


def test_two_faces_with_a_common_vertex():
    faces = ((0, 1, 2), (0, 3, 4))  # vertex 0 shared; the second face's own vertices are 3 and 4
    # A fan neighbour bent up out of the plane only touches at the vertex.
    assert not pair(FLOOR, [(1, 1, 0.5), (-1, 1, 0.5)], faces)
    # Bent down through the floor: its opposite edge passes under the floor, the floor's through it.
    assert pair(FLOOR, [(0.5, 0.5, -0.5), (0.2, 0.6, 0.4)], faces)
    # Coplanar, in another corner of the plane; coplanar and lying over the floor.
    assert not pair(FLOOR, [(-1, 0, 0), (0, -1, 0)], faces)
    assert pair(FLOOR, [(0.3, 0.3, 0), (0.1, 0.5, 0)], faces)


def test_two_faces_with_a_common_edge():
    faces = ((0, 1, 2), (2, 1, 3))  # the edge 1-2 shared; the second face's third vertex is 3
    assert not pair(FLOOR, [(1, 1, 0.3)], faces)  # a ridge: the faces meet only along the edge
    assert not pair(FLOOR, [(1, 1, 0)], faces)    # flat: the square's two halves
    assert pair(FLOOR, [(0.2, 0.2, 0)], faces)    # folded back onto the floor


@pytest.mark.parametrize("make", [
    lambda: ellipsoid_shape([1.0, 0.8, 0.6] * u.km, subdivisions=3),
    lambda: gaussian_random_sphere(1.0 * u.km, 0.3, seed=3, subdivisions=3),
    # Non-convex, with large flat regions of coplanar faces that share only a vertex or nothing.
    lambda: voxel_shape(np.array([[[1, 1], [1, 0]], [[1, 0], [0, 0]]], dtype=bool), 1.0 * u.km),
])
def test_valid_shapes_pass(make):
    shape = make()
    assert intersecting_faces(shape.vertices_km, shape.faces, 5)[0] == 0


def test_a_hollow_shell_passes():
    # Two nested spheres, the inner one turned inwards: a closed surface bounding a shell, crossing nowhere.
    vertices, faces = icosphere(3)
    shell = check_closed_mesh(np.vstack([vertices, 0.5 * vertices]), np.vstack([faces, faces[:, ::-1] + len(vertices)]))
    assert mass_properties(*shell)[0] == pytest.approx(7 / 8 * mass_properties(vertices, faces)[0], rel=1e-12)


def two_overlapping_spheres(subdivisions=3, offset=1.0):
    vertices, faces = icosphere(subdivisions)
    return (np.vstack([vertices, vertices + [offset, 0.0, 0.0]]), np.vstack([faces, faces + len(vertices)]),
            len(faces))


def test_two_overlapping_spheres_are_refused_naming_faces_of_each():
    vertices, faces, first = two_overlapping_spheres()
    count, pairs = intersecting_faces(vertices, faces, 1000)
    # The spheres' surfaces cross along a circle; each crossing pairs a face of one with a face of the other.
    assert count > 50 and len(pairs) == min(count, 1000)
    assert np.all(pairs[:, 0] < first) and np.all(pairs[:, 1] >= first)
    # Every face of the first sphere that reaches past the circle's plane x = 1/2 and straddles the second
    # sphere's surface takes part: the faces named are all close to that circle (|r - (1/2, ·, ·)| small).
    centroids = vertices[faces[pairs[:, 0]]].mean(axis=1)
    assert np.all(np.abs(centroids[:, 0] - 0.5) < 0.15)
    with pytest.raises(InvalidMeshError, match=rf"crosses itself: {count} pairs of faces intersect \(faces \d+ and "
                                               r"\d+, .*, …; numbered from 0\)") as refusal:
        Shape(vertices * u.km, faces)
    assert "np." not in str(refusal.value)
    # Apart, the same two spheres pass (two bodies in one file are not crossing).
    apart, faces, _ = two_overlapping_spheres(offset=2.5)
    assert intersecting_faces(apart, faces, 5)[0] == 0


def test_a_vertex_pushed_through_the_far_side_is_refused():
    vertices, faces = icosphere(2)
    pierced = vertices.copy()
    pierced[0] *= -1.3  # its fan of faces now spans the whole body and leaves through the other side
    count, pairs = intersecting_faces(pierced, faces, 5)
    assert count > 0
    assert all(0 in faces[i] or 0 in faces[j] for i, j in pairs)  # each pair has a face of that fan
    with pytest.raises(InvalidMeshError, match="crosses itself"):
        Shape(pierced * u.km, faces)


def test_twenty_thousand_faces_are_checked_in_well_under_a_second():
    vertices, faces = icosphere(5)  # 20 480 faces
    intersecting_faces(vertices, faces, 5)  # compiled (cached) before the clock starts
    times = []
    for _ in range(3):
        start = time.perf_counter()
        count, _ = intersecting_faces(vertices, faces, 5)
        times.append(time.perf_counter() - start)
    assert count == 0
    assert min(times) < 0.5, times  # measured 0.14 s on a loaded two-core machine
