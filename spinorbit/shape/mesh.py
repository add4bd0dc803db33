"""A shape model: a closed triangulated surface with a length unit, and the generated shapes.

A :class:`Shape` is checked once on construction (closed, two-manifold, outward oriented, no
degenerate face, not crossing itself: :func:`spinorbit.core.model.polyhedron.check_closed_mesh`), so everything that takes
a Shape can rely on it. Generated shapes, for tests and examples:

- :func:`ellipsoid_shape`: a triaxial ellipsoid from a subdivided icosahedron. The icosahedron
  (0, ±1, ±φ) and its cyclic permutations is symmetric under each coordinate mirror, and so is every
  subdivision: the mesh keeps the ellipsoid's three mirror planes exactly.
- :func:`voxel_shape`: the surface of a union of cubes on a grid, for non-convex test bodies whose
  shadows have closed forms (an L-shaped block casts a rectangle on its floor). Each exposed square
  is split into four triangles about its centre, so every mirror symmetry of the voxel set is kept
  by the mesh.
- :func:`gaussian_random_sphere`: Muinonen's Gaussian random sphere (Muinonen 1998, Astron.
  Astrophys. 332, 1087; Muinonen & Lagerros 1998, A&A 333, 753): r = a exp(s − β²/2), s a Gaussian
  random field on the sphere with Legendre power c_l ∝ l^(−ν) for l = 2..l_max and variance β²,
  β² = ln(1 + σ²) for a relative radius standard deviation σ. Seeded: the same seed gives the same shape.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from astropy import units as u

from spinorbit.core.model.polyhedron import check_closed_mesh, regular_solid_harmonics
from spinorbit.quantities import value_in

__all__ = ["Shape", "box_shape", "ellipsoid_shape", "gaussian_random_sphere", "icosphere", "directions_to_shape",
           "voxel_shape"]

#: Highest icosphere subdivision: 20·4^7 = 327 680 faces, already far past what a torque needs.
MAX_SUBDIVISIONS = 7


@dataclass(frozen=True)
class Shape:
    """A closed, outward-oriented triangulated surface.

    Parameters
    ----------
    vertices : Quantity, shape (n, 3)
        Vertex positions, a length Quantity (``vertices_km * u.km``; a bare array is refused).
    faces : array_like of int, shape (m, 3)
        Vertex indices (from 0) of each triangle, counter-clockwise seen from outside.
    name : str, optional

    Raises
    ------
    InvalidMeshError
        The surface is open, non-manifold, inverted, has degenerate faces, or crosses itself (the
        message names the faces that intersect).
    """

    vertices: u.Quantity
    faces: np.ndarray
    name: str | None = None
    _vertices_km: np.ndarray = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        values = value_in("vertices", self.vertices, u.km, "np.array([[x, y, z], ...]) * u.km")
        vertices, faces = check_closed_mesh(values, self.faces)
        vertices.flags.writeable = False
        faces.flags.writeable = False
        object.__setattr__(self, "_vertices_km", vertices)
        object.__setattr__(self, "vertices", vertices * u.km)
        object.__setattr__(self, "faces", faces)

    @property
    def vertices_km(self) -> np.ndarray:
        """Vertex positions in km as plain floats (read-only)."""
        return self._vertices_km

    def __len__(self):
        return self.faces.shape[0]


def icosphere(subdivisions):
    """Unit-sphere vertices and outward faces of an icosahedron subdivided ``subdivisions`` times.

    Returns
    -------
    vertices : ndarray (10·4^k + 2, 3)
    faces : ndarray (20·4^k, 3)
    """
    if not (isinstance(subdivisions, (int, np.integer)) and 0 <= subdivisions <= MAX_SUBDIVISIONS):
        raise ValueError(f"subdivisions: expected an integer 0..{MAX_SUBDIVISIONS} (20·4^k faces); got {subdivisions!r}.")
    phi = (1.0 + math.sqrt(5.0)) / 2.0
    points = []
    for a, b in ((-1, phi), (1, phi), (-1, -phi), (1, -phi)):
        points += [(a, b, 0.0), (0.0, a, b), (b, 0.0, a)]
    vertices = [np.array(p) / math.hypot(1.0, phi) for p in points]
    faces = _icosahedron_faces(np.array(vertices))
    for _ in range(int(subdivisions)):
        midpoint = {}
        new_faces = []
        for a, b, c in faces:
            ab, bc, ca = (_midpoint(vertices, midpoint, i, j) for i, j in ((a, b), (b, c), (c, a)))
            new_faces += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        faces = new_faces
    return np.array(vertices), np.array(faces, dtype=np.int64)


def _icosahedron_faces(vertices):
    """The 20 faces: triples of mutually nearest vertices, ordered counter-clockwise from outside."""
    edge = min(np.linalg.norm(vertices[0] - v) for v in vertices[1:])
    near = np.linalg.norm(vertices[:, None] - vertices[None], axis=2) < edge * 1.01
    faces = []
    for i in range(12):
        for j in range(i + 1, 12):
            for k in range(j + 1, 12):
                if near[i, j] and near[j, k] and near[i, k]:
                    normal = np.cross(vertices[j] - vertices[i], vertices[k] - vertices[i])
                    faces.append((i, j, k) if normal @ vertices[i] > 0 else (i, k, j))
    return faces


def _midpoint(vertices, cache, i, j):
    key = (min(i, j), max(i, j))
    if key not in cache:
        point = vertices[i] + vertices[j]
        vertices.append(point / np.linalg.norm(point))
        cache[key] = len(vertices) - 1
    return cache[key]


def directions_to_shape(directions, faces, radii, name=None):
    """A star-shaped Shape: vertex k at radii[k] · directions[k] (unit ``directions``, ``radii`` a length Quantity)."""
    lengths = value_in("radii", radii, u.km, "np.ones(len(directions)) * u.km")
    return Shape(directions * np.asarray(lengths, dtype=float)[..., None] * u.km, faces, name=name)


def box_shape(half_sides, name=None):
    """A rectangular box |x| ≤ h_x, |y| ≤ h_y, |z| ≤ h_z as 12 outward triangles.

    Parameters
    ----------
    half_sides : Quantity, shape (3,)
        h_x, h_y, h_z (length).

    Returns
    -------
    Shape
        Vertex k at (±h_x, ±h_y, ±h_z) with the signs of the bits of k (4: x, 2: y, 1: z); faces 2j
        and 2j + 1 are the two triangles (c0, c1, c2), (c0, c2, c3) of the box's j-th side c0..c3.
    """
    half = value_in("half_sides", half_sides, u.km, "[1.5, 1.0, 0.7] * u.km", shape=(3,))
    if np.any(half <= 0):
        raise ValueError(f"half_sides: expected three positive lengths; got {half.tolist()} km.")
    signs = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], dtype=float)
    faces = []
    for axis in range(3):
        first, second = [k for k in range(3) if k != axis]
        for sign in (-1, 1):
            corners = []
            for a, b in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
                corner = np.zeros(3)
                corner[axis], corner[first], corner[second] = sign, a, b
                corners.append(int(4 * (corner[0] > 0) + 2 * (corner[1] > 0) + (corner[2] > 0)))
            if np.cross(np.eye(3)[first], np.eye(3)[second])[axis] * sign < 0:  # counter-clockwise from outside
                corners.reverse()
            faces += [corners[:3], [corners[0], corners[2], corners[3]]]
    return Shape(signs * half * u.km, np.array(faces, dtype=np.int64), name=name or "box")


def ellipsoid_shape(semi_axes, subdivisions=3, name=None):
    """A triaxial ellipsoid x²/a² + y²/b² + z²/c² = 1 as a subdivided icosahedron.

    Parameters
    ----------
    semi_axes : Quantity, shape (3,)
        a, b, c along x, y, z (length).
    subdivisions : int
        Icosphere level k (20·4^k faces). The volume and moments converge to the ellipsoid's as
        O(4^−k) (the edge length squared).

    Returns
    -------
    Shape
        Vertices on the ellipsoid; symmetric under x → −x, y → −y and z → −z.
    """
    axes = value_in("semi_axes", semi_axes, u.km, "[1.0, 0.8, 0.6] * u.km", shape=(3,))
    if np.any(axes <= 0):
        raise ValueError(f"semi_axes: expected three positive lengths; got {axes.tolist()} km.")
    directions, faces = icosphere(subdivisions)
    return Shape(directions * axes * u.km, faces, name=name or "ellipsoid")


def gaussian_random_sphere(radius, sigma, seed, nu=4.0, degree_max=10, subdivisions=4, name=None):
    """A Gaussian random sphere (Muinonen 1998) on an icosphere grid.

    Parameters
    ----------
    radius : Quantity
        Mean radius a (length).
    sigma : float
        Relative standard deviation of the radius (0 < σ; 0.1–0.3 look like asteroids).
    seed : int
        Seed of ``numpy.random.default_rng``: one seed, one shape.
    nu : float
        Power-law index of the Legendre coefficients c_l ∝ l^(−ν), l = 2..degree_max (Muinonen's
        power-law covariance; larger ν is smoother).
    degree_max : int
        Highest harmonic degree of the log-radius.
    subdivisions : int
        Icosphere level of the mesh.

    Returns
    -------
    Shape
    """
    mean_radius = value_in("radius", radius, u.km, "1.0 * u.km", shape=())
    if not (mean_radius > 0 and sigma > 0 and degree_max >= 2):
        raise ValueError(f"gaussian_random_sphere: expected radius > 0, sigma > 0 and degree_max ≥ 2; got radius "
                         f"{mean_radius!r} km, sigma {sigma!r}, degree_max {degree_max!r}.")
    rng = np.random.default_rng(seed)
    directions, faces = icosphere(subdivisions)
    beta2 = math.log1p(sigma * sigma)
    degrees = np.arange(2, degree_max + 1)
    power = degrees ** (-float(nu))
    power /= power.sum()
    cos_part, sin_part = regular_solid_harmonics(directions, degree_max)
    field_values = np.zeros(directions.shape[0])
    for n, c_l in zip(degrees, power):
        # Orthonormal real harmonics: Y = N_nm P_nm cos/sin mλ with ∫ Y² dΩ = 1; a_nm ~ N(0, 4π β² c_l / (2n + 1))
        # so that the field's variance at a point is β² c_l summed over n.
        spread = math.sqrt(4.0 * math.pi * beta2 * c_l / (2 * n + 1))
        for m in range(n + 1):
            norm = math.sqrt((2.0 - (m == 0)) * (2 * n + 1) / (4.0 * math.pi)
                             * math.factorial(n - m) / math.factorial(n + m))
            field_values += spread * norm * rng.standard_normal() * cos_part[n, m]
            if m > 0:
                field_values += spread * norm * rng.standard_normal() * sin_part[n, m]
    radii = mean_radius * np.exp(field_values - 0.5 * beta2)
    return directions_to_shape(directions, faces, radii * u.km, name=name or f"gaussian random sphere (seed {seed})")


def voxel_shape(occupied, pitch, name=None):
    """The surface of a union of cubes: voxel (i, j, k) fills [i, i + 1] × [j, j + 1] × [k, k + 1] · pitch.

    Parameters
    ----------
    occupied : array_like of bool, shape (nx, ny, nz)
        Which voxels are solid.
    pitch : Quantity
        Edge of a voxel (length).

    Returns
    -------
    Shape
        Every square between a solid and an empty voxel as four outward triangles about its centre.

    Raises
    ------
    ValueError
        ``occupied`` is not a 3-d boolean array with a solid voxel.
    InvalidMeshError
        The voxels touch only along an edge or at a corner somewhere (the surface is not a manifold there).
    """
    grid = np.asarray(occupied)
    if grid.ndim != 3 or grid.dtype != bool or not grid.any():
        raise ValueError(f"occupied: expected a 3-d boolean array with at least one True voxel; got shape "
                         f"{grid.shape}, dtype {grid.dtype}.")
    size = value_in("pitch", pitch, u.km, "0.1 * u.km", shape=())
    if not size > 0:
        raise ValueError(f"pitch: expected a positive length; got {size!r} km.")
    padded = np.pad(grid, 1)
    index, vertices, faces = {}, [], []

    def vertex(point):  # half-integer grid coordinates, doubled to stay exact integers as keys
        key = tuple(round(2.0 * float(c)) for c in point)
        if key not in index:
            index[key] = len(vertices)
            vertices.append(np.array(key, dtype=float) / 2.0)
        return index[key]

    for axis in range(3):
        first, second = [k for k in range(3) if k != axis]
        step = np.eye(3, dtype=int)[axis]
        for cell in zip(*np.nonzero(grid)):
            for sign in (1, -1):
                neighbour = tuple(np.array(cell) + 1 + sign * step)
                if padded[neighbour]:
                    continue
                base = np.array(cell, dtype=float)
                base[axis] += 1.0 if sign > 0 else 0.0
                corners = []
                for a, b in ((0, 0), (1, 0), (1, 1), (0, 1)):
                    corner = base.copy()
                    corner[first] += a
                    corner[second] += b
                    corners.append(corner)
                if np.cross(np.eye(3)[first], np.eye(3)[second])[axis] * sign < 0:  # counter-clockwise from outside
                    corners.reverse()
                centre = vertex(sum(corners) / 4.0)
                ids = [vertex(c) for c in corners]
                faces += [[ids[i], ids[(i + 1) % 4], centre] for i in range(4)]
    return Shape(np.array(vertices) * size * u.km, np.array(faces, dtype=np.int64), name=name or "voxels")
