"""Self-shadowing of a closed triangulated surface: which parts of which facets the Sun sees.

A facet k with n_k·ŝ > 0 faces the Sun, but on a non-convex body another part of the surface may
stand between it and the Sun. A point p of the facet is lit when the ray p + t ŝ, t > 0, meets no
other triangle (Möller & Trumbore 1997, J. Graphics Tools 2, 21, "Fast, minimum storage ray–triangle
intersection"). Each facet carries q² sample points, the centroids of the q² equal sub-triangles of
its barycentric subdivision, each standing for A_k/q²; q = 1 tests the centroid alone. The shadowed
recoil sums of :mod:`spinorbit.core.model.thermal` then read::

    F/P = Σ_k Σ_j (A_k/q²) max(0, n_k·ŝ) v_kj(ŝ) n_k,   T/P = Σ_k Σ_j (A_k/q²) max(0, n_k·ŝ) v_kj(ŝ) (p_kj × n_k)

with v_kj = 1 for a lit sample point and 0 for a shadowed one. The misclassified area is confined
to the sub-triangles that a shadow's edge crosses, so the error falls as the sample spacing (the
facet's edge over q).

**Culling.** A facet can be shadowed only if some vertex of the surface lies above its plane
(a ray leaving the facet upwards stays in the open half-space above it, and a triangle entirely on or
below the plane cannot meet it there). Facets with no vertex above their plane are never tested;
on a convex surface that is every facet, so convexity is detected by the same test and costs
O(faces × vertices) once. The remaining rays descend a bounding-volume hierarchy of axis-aligned
boxes (median split of the triangle centroids along the longest axis, leaves of at most
:data:`LEAF_SIZE` triangles), so a ray costs O(log m) box tests instead of m triangle tests; and a ray is followed only up to the
height of the highest vertex above its facet's plane, beyond which nothing can stop it.
"""

import math
from typing import NamedTuple

import numpy as np

from spinorbit.core.jit import jit
from spinorbit.core.model.polyhedron import (
    InvalidMeshError,
    check_closed_mesh,
    face_geometry,
)

__all__ = [
    "CONVEXITY_TOLERANCE",
    "LEAF_SIZE",
    "MAX_SHADOW_SAMPLES",
    "STACK_DEPTH",
    "ShadowGeometry",
    "ray_blocked",
    "shadow_candidates",
    "shadow_geometry",
    "shadowed_recoil_sums",
    "subdivision_points",
]

#: Triangles per leaf of the hierarchy: a few Möller–Trumbore tests cost about one box test each.
LEAF_SIZE = 4
#: Highest subdivision q of a facet's sample points (q² rays per facet and direction).
MAX_SHADOW_SAMPLES = 16
#: A vertex counts as above a facet's plane when its height exceeds this fraction of the body's
#: size: far above rounding (≈ 1e-16 of the size) so that the coplanar neighbours of a flat face
#: and the facets of a convex mesh are not taken for occluders, far below any real relief.
CONVEXITY_TOLERANCE = 1e-10
#: Depth of the traversal stack: a median-split tree of m triangles is ⌈log₂(m / LEAF_SIZE)⌉ + 1 deep.
STACK_DEPTH = 64


class ShadowGeometry(NamedTuple):
    """A surface prepared for shadow rays (:func:`shadow_geometry`); plain arrays, in the vertices' unit."""

    vertices: np.ndarray        #: (n, 3)
    faces: np.ndarray           #: (m, 3) int64
    normals: np.ndarray         #: (m, 3) unit outward normals
    areas: np.ndarray           #: (m,)
    candidates: np.ndarray      #: (m,) bool: some vertex lies above the facet's plane
    heights: np.ndarray         #: (m,) the highest vertex's height above it (0 for the others)
    points: np.ndarray          #: (q², 2) barycentric (u, v) of the sample points, p = a + u(b − a) + v(c − a)
    box_low: np.ndarray         #: (nodes, 3) lower corners of the hierarchy's boxes
    box_high: np.ndarray        #: (nodes, 3) upper corners
    children: np.ndarray        #: (nodes, 2) int64: child nodes, or (first, count) in ``order`` for a leaf
    leaf: np.ndarray            #: (nodes,) bool
    order: np.ndarray           #: (m,) int64: the faces in leaf order

    @property
    def convex(self):
        """True when no facet can be shadowed: shadowing changes nothing and is skipped."""
        return not bool(self.candidates.any())


def subdivision_points(samples):
    """Barycentric (u, v) of the centroids of the q² equal sub-triangles of a triangle, q = ``samples``."""
    if not (isinstance(samples, (int, np.integer)) and 1 <= samples <= MAX_SHADOW_SAMPLES):
        raise ValueError(f"shadow_samples: expected an integer 1..{MAX_SHADOW_SAMPLES} (q² sample points per facet, "
                         f"1 = the centroid); got {samples!r}.")
    q = int(samples)
    points = []
    for i in range(q):
        for j in range(q - i):
            points.append(((i + 1.0 / 3.0) / q, (j + 1.0 / 3.0) / q))      # the upward sub-triangle
            if i + j <= q - 2:
                points.append(((i + 2.0 / 3.0) / q, (j + 2.0 / 3.0) / q))  # the downward one beside it
    return np.array(points)


@jit
def _heights(vertices, faces, normals):
    """The height of the highest vertex above each facet's plane (≤ 0: none above it)."""
    out = np.empty(faces.shape[0])
    for k in range(faces.shape[0]):
        a = faces[k, 0]
        nx, ny, nz = normals[k, 0], normals[k, 1], normals[k, 2]
        offset = nx * vertices[a, 0] + ny * vertices[a, 1] + nz * vertices[a, 2]
        highest = -math.inf
        for i in range(vertices.shape[0]):
            highest = max(highest, nx * vertices[i, 0] + ny * vertices[i, 1] + nz * vertices[i, 2] - offset)
        out[k] = highest
    return out


def shadow_candidates(vertices, faces):
    """Facets that some vertex rises above: the only ones another part of the surface can shadow.

    Returns
    -------
    ndarray (m,) bool
        All False exactly when the surface is convex (to :data:`CONVEXITY_TOLERANCE` of its size).
    """
    normals, _, _ = face_geometry(vertices, faces)
    scale = float(np.ptp(vertices, axis=0).max())
    return _heights(vertices, faces, normals) > CONVEXITY_TOLERANCE * scale


def _build_hierarchy(vertices, faces):
    """Median-split bounding-volume hierarchy of the triangles, flattened (depth-first node order)."""
    corners = vertices[faces]                       # (m, 3, 3)
    low_t, high_t = corners.min(axis=1), corners.max(axis=1)
    centre = corners.mean(axis=1)
    order = np.arange(faces.shape[0])
    lows, highs, children, leaves = [], [], [], []
    stack = [(0, faces.shape[0], -1, 0)]           # (first, end, parent, which child)
    while stack:
        first, end, parent, which = stack.pop()
        node = len(lows)
        if parent >= 0:
            children[parent][which] = node
        members = order[first:end]
        lows.append(low_t[members].min(axis=0))
        highs.append(high_t[members].max(axis=0))
        if end - first <= LEAF_SIZE:
            children.append([first, end - first])
            leaves.append(True)
            continue
        children.append([-1, -1])
        leaves.append(False)
        axis = int(np.argmax(np.ptp(centre[members], axis=0)))
        order[first:end] = members[np.argsort(centre[members, axis], kind="stable")]
        middle = (first + end) // 2
        stack.append((middle, end, node, 1))
        stack.append((first, middle, node, 0))
    return (np.array(lows), np.array(highs), np.array(children, dtype=np.int64), np.array(leaves, dtype=np.bool_),
            order.astype(np.int64))


def shadow_geometry(vertices, faces, samples=1):
    """Prepare a closed surface for shadow rays: the culling mask, the sample points and the hierarchy.

    Parameters
    ----------
    vertices : array_like (n, 3)
        Vertex positions (any length unit; the torque arms are measured from their origin).
    faces : array_like of int (m, 3)
        Counter-clockwise seen from outside.
    samples : int
        q: q² sample points per facet (1: the centroid).

    Returns
    -------
    ShadowGeometry
        ``.convex`` is True when no facet can be shadowed; the hierarchy is then not built.

    Raises
    ------
    InvalidMeshError
        The surface is not closed, two-manifold and outward oriented: "above" and "behind" have no
        meaning on it, so neither has a shadow.
    """
    points = subdivision_points(samples)
    try:
        vertices, faces = check_closed_mesh(vertices, faces)
    except InvalidMeshError as error:
        raise InvalidMeshError(f"self-shadowing needs a closed, outward-oriented surface (a ray's way out must be "
                               f"defined): {error}") from None
    normals, areas, _ = face_geometry(vertices, faces)
    scale = float(np.ptp(vertices, axis=0).max())
    heights = _heights(vertices, faces, normals)
    candidates = heights > CONVEXITY_TOLERANCE * scale
    heights = np.where(candidates, heights, 0.0)
    if not candidates.any():  # convex: no ray is ever cast, so no hierarchy is needed
        empty = np.zeros((0, 3))
        return ShadowGeometry(vertices, faces, normals, areas, candidates, heights, points, empty, empty,
                              np.zeros((0, 2), dtype=np.int64), np.zeros(0, dtype=np.bool_), np.zeros(0, dtype=np.int64))
    return ShadowGeometry(vertices, faces, normals, areas, candidates, heights, points, *_build_hierarchy(vertices, faces))


@jit
def _hits_triangle(ox, oy, oz, dx, dy, dz, vertices, faces, f):
    """Möller–Trumbore: does the ray o + t d, t > 0, cross triangle f (its interior or edges)?"""
    a, b, c = faces[f, 0], faces[f, 1], faces[f, 2]
    e1x, e1y, e1z = vertices[b, 0] - vertices[a, 0], vertices[b, 1] - vertices[a, 1], vertices[b, 2] - vertices[a, 2]
    e2x, e2y, e2z = vertices[c, 0] - vertices[a, 0], vertices[c, 1] - vertices[a, 1], vertices[c, 2] - vertices[a, 2]
    px, py, pz = dy * e2z - dz * e2y, dz * e2x - dx * e2z, dx * e2y - dy * e2x
    det = e1x * px + e1y * py + e1z * pz
    if det == 0.0:
        return False  # the ray runs parallel to the triangle's plane: it cannot cross it
    inv = 1.0 / det
    tx, ty, tz = ox - vertices[a, 0], oy - vertices[a, 1], oz - vertices[a, 2]
    u = (tx * px + ty * py + tz * pz) * inv
    if u < 0.0 or u > 1.0:
        return False
    qx, qy, qz = ty * e1z - tz * e1y, tz * e1x - tx * e1z, tx * e1y - ty * e1x
    v = (dx * qx + dy * qy + dz * qz) * inv
    if v < 0.0 or u + v > 1.0:
        return False
    return (e2x * qx + e2y * qy + e2z * qz) * inv > 0.0


@jit
def _slab(o, inv, low, high, t0, t1):
    """Clip [t0, t1] to the slab low ≤ o + t d ≤ high of one axis (inv = 1/d, ±inf for d = 0)."""
    a, b = (low - o) * inv, (high - o) * inv
    if a > b:
        a, b = b, a
    if not (a <= b):  # 0 · inf: the ray runs in the slab's boundary plane; keep the interval
        return t0, t1
    return max(t0, a), min(t1, b)


@jit
def _hits_box(ox, oy, oz, ix, iy, iz, t_max, box_low, box_high, node):
    """Slab test of the segment o + t d, 0 < t ≤ t_max, against the node's box."""
    t0, t1 = _slab(ox, ix, box_low[node, 0], box_high[node, 0], 0.0, t_max)
    if t0 > t1:
        return False
    t0, t1 = _slab(oy, iy, box_low[node, 1], box_high[node, 1], t0, t1)
    if t0 > t1:
        return False
    t0, t1 = _slab(oz, iz, box_low[node, 2], box_high[node, 2], t0, t1)
    return t0 <= t1


@jit
def ray_blocked(ox, oy, oz, dx, dy, dz, t_max, source, vertices, faces, box_low, box_high, children, leaf, order, stack):
    """Does the ray o + t d, 0 < t ≤ t_max, cross a triangle other than ``source``? (the hierarchy's descent)

    ``d`` is a unit vector; ``stack`` is scratch of :data:`STACK_DEPTH` int64. Used for the Sun's rays
    here and for the Sun's and the observer's in :mod:`spinorbit.core.photometry.visibility`.
    """
    ix, iy, iz = 1.0 / dx, 1.0 / dy, 1.0 / dz
    top = 0
    stack[0] = 0
    while top >= 0:
        node = stack[top]
        top -= 1
        if not _hits_box(ox, oy, oz, ix, iy, iz, t_max, box_low, box_high, node):
            continue
        if leaf[node]:
            for i in range(children[node, 0], children[node, 0] + children[node, 1]):
                f = order[i]
                if f != source and _hits_triangle(ox, oy, oz, dx, dy, dz, vertices, faces, f):
                    return True
        else:
            stack[top + 1] = children[node, 1]
            stack[top + 2] = children[node, 0]
            top += 2
    return False


@jit
def _shadowed_sums(vertices, faces, normals, areas, candidates, heights, points, box_low, box_high, children, leaf, order,
                   directions, out):
    stack = np.empty(STACK_DEPTH, dtype=np.int64)
    weight = 1.0 / points.shape[0]
    for d in range(directions.shape[0]):
        sx, sy, sz = directions[d, 0], directions[d, 1], directions[d, 2]
        inv = 1.0 / math.sqrt(sx * sx + sy * sy + sz * sz)
        sx, sy, sz = sx * inv, sy * inv, sz * inv
        fx = fy = fz = tx = ty = tz = 0.0
        for k in range(faces.shape[0]):
            nx, ny, nz = normals[k, 0], normals[k, 1], normals[k, 2]
            cosine = nx * sx + ny * sy + nz * sz
            if cosine <= 0.0:
                continue
            a, b, c = faces[k, 0], faces[k, 1], faces[k, 2]
            # Nothing rises more than heights[k] above the facet's plane: the ray is done when it gets there.
            t_max = heights[k] / cosine
            lit = 0.0
            ax = ay = az = 0.0  # Σ over the lit sample points of p (the lit part's arm, times its count)
            for j in range(points.shape[0]):
                u, v = points[j, 0], points[j, 1]
                px = vertices[a, 0] + u * (vertices[b, 0] - vertices[a, 0]) + v * (vertices[c, 0] - vertices[a, 0])
                py = vertices[a, 1] + u * (vertices[b, 1] - vertices[a, 1]) + v * (vertices[c, 1] - vertices[a, 1])
                pz = vertices[a, 2] + u * (vertices[b, 2] - vertices[a, 2]) + v * (vertices[c, 2] - vertices[a, 2])
                if candidates[k] and ray_blocked(px, py, pz, sx, sy, sz, t_max, k, vertices, faces, box_low, box_high,
                                               children, leaf, order, stack):
                    continue
                lit += 1.0
                ax += px
                ay += py
                az += pz
            if lit == 0.0:
                continue
            w = areas[k] * cosine * weight
            fx += w * lit * nx
            fy += w * lit * ny
            fz += w * lit * nz
            tx += w * (ay * nz - az * ny)
            ty += w * (az * nx - ax * nz)
            tz += w * (ax * ny - ay * nx)
        out[d, 0], out[d, 1], out[d, 2], out[d, 3], out[d, 4], out[d, 5] = fx, fy, fz, tx, ty, tz


def shadowed_recoil_sums(geometry, directions):
    """The shadowed facet sums F/P and T/P (module docstring) for each Sun direction.

    Parameters
    ----------
    geometry : ShadowGeometry
    directions : array_like (k, 3)
        Body-frame directions to the Sun (need not be unit).

    Returns
    -------
    force, torque : ndarray (k, 3)
        Σ A max(0, n·ŝ) (lit share) n (length²) and the torque sum (length³) about the vertices'
        origin; multiply by −P(d) for the recoil. On a convex surface they equal the unshadowed
        sums of :func:`spinorbit.core.model.thermal.facet_force_torque` (to rounding).
    """
    directions = np.ascontiguousarray(np.atleast_2d(np.asarray(directions, dtype=float)))
    if directions.ndim != 2 or directions.shape[1] != 3 or not np.all(np.isfinite(directions)):
        raise ValueError(f"directions: expected a finite (k, 3) array of Sun directions; got shape {directions.shape}.")
    if np.any(np.linalg.norm(directions, axis=1) == 0.0):
        raise ValueError("directions: a zero vector has no direction; give the body-frame vector to the Sun.")
    out = np.empty((directions.shape[0], 6))
    g = geometry
    _shadowed_sums(g.vertices, g.faces, g.normals, g.areas, g.candidates, g.heights, g.points, g.box_low, g.box_high,
                   g.children, g.leaf, g.order, directions, out)
    return out[:, :3], out[:, 3:]
